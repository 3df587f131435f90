"""ViscousDrag kernel against hand computations of F_body = −V·(w∘|w|) (README, Conventions: AQWA `*Viscous Drag`)."""
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hydrofmu.decks.aqwa import read_viscous_drag
from hydrofmu.physics.state import Env, Motion
from hydrofmu.physics.viscous_drag import ViscousDrag

DATA = Path(__file__).parent / "data" / "aqwa"
RNG = np.random.default_rng(7)
FULL = RNG.uniform(-1.0, 1.0, (6, 6)) * 1e4 + np.diag([5e4, 6e4, 7e4, 8e6, 9e6, 1e7])


def rot(att):
    """Body-to-global R = Rz(ψ)·Ry(θ)·Rx(φ): intrinsic z-y'-x'' Euler angles (scipy)."""
    return Rotation.from_euler("ZYX", att[::-1]).as_matrix()


def expected(matrix, att, vel, current=None):
    """Formula of the README (AQWA `*Viscous Drag`) written out: w in body axes, optional relative linear part."""
    r = rot(att)
    lin = np.asarray(vel[:3], float) - (0.0 if current is None else np.asarray(current))
    w = np.concatenate([r.T @ lin, r.T @ np.asarray(vel[3:], float)])
    f = -matrix @ (w * np.abs(w))
    return np.concatenate([r @ f[:3], r @ f[3:]])


def test_yawed_body_surging_in_global_x():
    # Yaw 90°: global +x is body −y. w = (0, −2, 0 | 0, −0.1, 0) → w|w| = (0, −4, 0 | 0, −0.01, 0).
    # F_body = (0, 200·4, 0 | 0, 500·0.01, 0) = (0, 800, 0 | 0, 5, 0); R maps body y to global −x.
    drag = ViscousDrag("d", np.diag([100.0, 200, 300, 400, 500, 600]), relative=False)
    motion = Motion(attitude=np.array([0.0, 0.0, np.pi / 2]), velocity=np.array([2.0, 0, 0, 0.1, 0, 0]))
    np.testing.assert_allclose(drag.load(motion, Env()), [-800, 0, 0, -5, 0, 0], atol=1e-9)


def test_relative_vs_absolute_body_at_rest():
    # Current 1.5 m/s going to 30°, body yawed 30°: the current is along body +x, so the
    # relative body velocity is w = (−1.5, 0, ...), w|w| = (−2.25, 0, ...), F_body = 2.25·V[:, 0].
    att = np.array([0.0, 0.0, np.radians(30.0)])
    env = Env(current_speed=1.5, current_direction=30.0)
    motion = Motion(attitude=att)
    c, s = np.cos(np.radians(30)), np.sin(np.radians(30))
    r = np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])
    f = 2.25 * FULL[:, 0]
    rel = ViscousDrag("rel", FULL, relative=True)
    np.testing.assert_allclose(rel.load(motion, env), np.concatenate([r @ f[:3], r @ f[3:]]), rtol=1e-12)
    absolute = ViscousDrag("abs", FULL, relative=False)
    np.testing.assert_array_equal(absolute.load(motion, env), np.zeros(6))
    assert rel.uses_current and not absolute.uses_current and not rel.uses_acceleration


@pytest.mark.parametrize("relative", [False, True])
def test_general_motion_roll_pitch_yaw(relative):
    att = np.array([0.2, -0.15, 1.1])
    vel = np.array([1.2, -0.7, 0.3, 0.05, -0.08, 0.12])
    env = Env(current_speed=0.9, current_direction=200.0)
    u = 0.9 * np.array([np.cos(np.radians(200)), np.sin(np.radians(200)), 0.0])
    drag = ViscousDrag("d", FULL, relative=relative)
    got = drag.load(Motion(attitude=att, velocity=vel), env)
    np.testing.assert_allclose(got, expected(FULL, att, vel, u if relative else None), rtol=1e-12)


def test_relative_body_drifting_with_current_has_only_rotational_drag():
    env = Env(current_speed=1.3, current_direction=-40.0)
    att = np.array([0.1, 0.2, -0.3])
    vel = np.concatenate([env.current, [0.0, 0.0, 0.02]])
    got = ViscousDrag("d", np.diag([1e5, 1e5, 1e5, 0, 0, 2e9]), True).load(Motion(attitude=att, velocity=vel), env)
    # Only yaw-rate drag remains: w_rot = Rᵀ·(0, 0, 0.02), M = R·(−2e9·w∘|w| on the z entry).
    r = rot(att)
    w = r.T @ np.array([0, 0, 0.02])
    np.testing.assert_allclose(got[:3], 0.0, atol=1e-6)
    np.testing.assert_allclose(got[3:], r @ np.array([0, 0, -2e9 * w[2] * abs(w[2])]), rtol=1e-12)


def test_from_manual_deck_and_protocol():
    data = read_viscous_drag(DATA / "viscous_drag_manual.dat")["FPSO"]
    drag = ViscousDrag("FPSO.drag", data.matrix, data.relative)
    att, vel = np.array([0.05, 0.02, 0.4]), np.array([0.5, 0.2, -0.1, 0.01, 0.02, -0.03])
    env = Env(current_speed=0.5, current_direction=90.0)
    np.testing.assert_allclose(drag.load(Motion(attitude=att, velocity=vel), env),
                               expected(data.matrix, att, vel, env.current), rtol=1e-12)
    np.testing.assert_array_equal(drag.mass_matrix(Motion()), np.zeros((6, 6)))
    with pytest.raises(ValueError):
        ViscousDrag("bad", np.eye(5))
