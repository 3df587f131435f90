"""RIFLEX BODY kernel against hand computations from the manual's formulas."""
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hydrofmu.physics.lumped import LumpedBody
from hydrofmu.physics.state import Env, Motion

ATT = np.array([0.2, -0.3, 1.1])  # roll, pitch, yaw [rad]
RNG = np.random.default_rng(7)


def rot_ref(att):
    """R = Rz(ψ)·Ry(θ)·Rx(φ), built by scipy (intrinsic z-y'-x'')."""
    return Rotation.from_euler("ZYX", att[::-1]).as_matrix()


def body(**kw):
    args = dict(name="b", offset=[4.0, -2.0, 1.5], am=0.0, ae=0.0, icoo="GLOBAL", cd=[0, 0, 0], added_mass=[0, 0, 0])
    args.update(kw)
    return LumpedBody(**args)


def test_weight_buoyancy_and_moment():
    b = body(am=2000.0, ae=3.0)
    env = Env(rho=1025.0, g=9.81)
    load = b.load(Motion(position=np.array([1.0, 2.0, -5.0]), attitude=ATT), env)
    fz = -2000.0 * 9.81 + 1025.0 * 9.81 * 3.0
    r = rot_ref(ATT) @ np.array([4.0, -2.0, 1.5])
    np.testing.assert_allclose(load[:3], [0.0, 0.0, fz], atol=1e-9)
    # r × (0, 0, fz) = (r_y·fz, −r_x·fz, 0)
    np.testing.assert_allclose(load[3:], [r[1] * fz, -r[0] * fz, 0.0], atol=1e-9)


def test_drag_global_numbers():
    # body at rest, current 2 m/s going to +y: F_y = CDY·2·|2|, only y.
    b = body(offset=[0, 0, 0], cd=[10.0, 20.0, 30.0])
    load = b.load(Motion(attitude=ATT), Env(current_speed=2.0, current_direction=90.0))
    np.testing.assert_allclose(load, [0, 80.0, 0, 0, 0, 0], atol=1e-9)


def test_drag_local_yawed_numbers():
    # yaw 90°: body y axis points along global −x, so a current going to +x is
    # (0, −1, 0) in body axes → F_body = (0, −CDY, 0) → global (+CDY, 0, 0).
    b = body(offset=[0, 0, 0], icoo="LOCAL", cd=[10.0, 20.0, 30.0])
    load = b.load(Motion(attitude=np.array([0, 0, np.pi / 2])), Env(current_speed=1.0))
    np.testing.assert_allclose(load, [20.0, 0, 0, 0, 0, 0], atol=1e-9)


def test_drag_from_rotation_numbers():
    # no current, spin ω_z = 2 rad/s, point at r = (3, 0, 0): v_p = (0, 6, 0),
    # vrel = (0, −6, 0), F_y = −CDY·36, M_z = 3·F_y.
    b = body(offset=[3.0, 0, 0], cd=[0.0, 5.0, 0.0])
    load = b.load(Motion(velocity=np.array([0, 0, 0, 0, 0, 2.0])), Env())
    np.testing.assert_allclose(load, [0, -180.0, 0, 0, 0, -540.0], atol=1e-9)


@pytest.mark.parametrize("icoo", ["GLOBAL", "LOCAL"])
def test_drag_general_motion(icoo):
    cd = np.array([30.0, 70.0, 110.0])
    off = np.array([4.0, -2.0, 1.5])
    vel = np.array([0.3, -0.4, 0.2, 0.05, -0.08, 0.12])
    env = Env(current_speed=1.3, current_direction=35.0)
    b = body(offset=off, icoo=icoo, cd=cd)
    load = b.load(Motion(position=np.array([10.0, -3.0, 0.0]), attitude=ATT, velocity=vel), env)

    rot = rot_ref(ATT)
    r = rot @ off
    u = 1.3 * np.array([np.cos(np.radians(35.0)), np.sin(np.radians(35.0)), 0.0])
    vrel = u - (vel[:3] + np.cross(vel[3:], r))
    if icoo == "GLOBAL":
        force = np.array([cd[i] * vrel[i] * abs(vrel[i]) for i in range(3)])
    else:
        vb = rot.T @ vrel
        force = rot @ np.array([cd[i] * vb[i] * abs(vb[i]) for i in range(3)])
    np.testing.assert_allclose(load[:3], force, rtol=1e-12)
    np.testing.assert_allclose(load[3:], np.cross(r, force), rtol=1e-12, atol=1e-12)


def test_flags():
    assert not body().uses_current and not body().uses_acceleration
    assert body(cd=[0, 0, 1.0]).uses_current
    assert body(am=1.0).uses_acceleration and body(added_mass=[0, 2.0, 0]).uses_acceleration
    assert not body(ae=5.0).uses_acceleration and not body(ae=5.0).uses_current
    assert body(icoo="loca").icoo == "LOCAL"
    with pytest.raises(ValueError):
        body(icoo="BODY")


@pytest.mark.parametrize("icoo", ["GLOBAL", "LOCAL"])
def test_point_mass(icoo):
    b = body(am=500.0, icoo=icoo, added_mass=[100.0, 200.0, 300.0])
    rot = rot_ref(ATT)
    q = rot if icoo == "LOCAL" else np.eye(3)
    np.testing.assert_allclose(b.point_mass(Motion(attitude=ATT)),
                               500.0 * np.eye(3) + q @ np.diag([100.0, 200.0, 300.0]) @ q.T, atol=1e-12)


@pytest.mark.parametrize("icoo", ["GLOBAL", "LOCAL"])
def test_mass_matrix_and_velocity_load_give_the_point_inertia(icoo):
    b = body(am=500.0, icoo=icoo, added_mass=[100.0, 200.0, 300.0])
    rot = rot_ref(ATT)
    r = rot @ b.offset
    q = rot if icoo == "LOCAL" else np.eye(3)
    mp = 500.0 * np.eye(3) + q @ np.diag([100.0, 200.0, 300.0]) @ q.T
    for _ in range(5):
        vel, acc = RNG.normal(size=6), RNG.normal(size=6)
        m = Motion(attitude=ATT, velocity=vel, acceleration=acc)
        m6 = b.mass_matrix(m)
        # inertia load of the point: F = −M_p·a_p at the point, moment r × F
        a_p = acc[:3] + np.cross(acc[3:], r) + np.cross(vel[3:], np.cross(vel[3:], r))
        f = -mp @ a_p
        np.testing.assert_allclose(-m6 @ acc + b.velocity_load(m), np.concatenate([f, np.cross(r, f)]),
                                   rtol=1e-10, atol=1e-9)
        # ω = 0: the mass matrix alone is exact
        f0 = -mp @ (acc[:3] + np.cross(acc[3:], r))
        np.testing.assert_allclose(-m6 @ acc, np.concatenate([f0, np.cross(r, f0)]), rtol=1e-10, atol=1e-9)
    np.testing.assert_allclose(m6, m6.T, atol=1e-9)
    assert np.linalg.eigvalsh(m6).min() > -1e-8  # a point mass: positive semi-definite (rank 3)
    np.testing.assert_allclose(b.velocity_load(Motion(attitude=ATT, velocity=np.array([1.0, 2, 3, 0, 0, 0]))), 0.0)
