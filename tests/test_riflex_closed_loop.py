"""RIFLEX BODY and CONB in closed loop (fmpy, load/joint FMUs + dynamics partners)."""
import numpy as np
import pytest

from hydrofmu.cosim.master import run
from hydrofmu.physics.kinematics import rotation

from conftest import MODELS, build

RHO = 1025.0


def body_with_point_mass(mode):
    return f"""
        [scene]
        name = "point_{mode}"
        [run]
        step = 0.02
        stop = 30.0
        substep = 0.005
        [bodies.hull]
        mass = 1.0e6
        inertia = [1.0e8, 2.0e8, 3.0e8]
        velocity = [0.1, 0.05, 0.02, 0.002, 0.001, 0.004]
        stiffness = [1e5, 2e5, 3e6, 4e8, 6e8, 2e8]
        acceleration_loads = "{mode}"
        [[bodies.hull.effects]]
        type = "riflex_body"
        offset = [10.0, 5.0, -3.0]
        am = 2.0e5
        ae = {2.0e5 / RHO}   # buoyancy cancels the weight: only inertia is tested
        """


def combined_body():
    """The same body with the point mass folded into its mass properties (by hand)."""
    m, mp, r = 1.0e6, 2.0e5, np.array([10.0, 5.0, -3.0])
    i_o = np.diag([1.0e8, 2.0e8, 3.0e8]) + mp * (r @ r * np.eye(3) - np.outer(r, r))
    mt = m + mp
    c = mp * r / mt
    i_g = i_o - mt * (c @ c * np.eye(3) - np.outer(c, c))
    return f"""
        [scene]
        name = "combined"
        [run]
        step = 0.02
        stop = 30.0
        substep = 0.005
        [bodies.hull]
        mass = {mt}
        cog = {c.tolist()}
        inertia = {i_g.tolist()}
        velocity = [0.1, 0.05, 0.02, 0.002, 0.001, 0.004]
        stiffness = [1e5, 2e5, 3e6, 4e8, 6e8, 2e8]
        """


def motion(result):
    return np.hstack([result.vector("hull_dynamics", "position", 3), result.vector("hull_dynamics", "attitude", 3)])


@pytest.mark.parametrize("mode, tol", [("export", 2e-3), ("explicit", 2e-2)])
def test_point_mass_equals_combined_body(tmp_path, mode, tol):
    ref = motion(run(build(tmp_path / "ref", combined_body()), progress=False))
    got = motion(run(build(tmp_path / "pm", body_with_point_mass(mode)), progress=False))
    scale = np.ptp(ref, axis=0)
    assert np.all(scale > 0)
    nrms = np.sqrt(np.mean((got - ref) ** 2, axis=0)) / scale
    assert nrms.max() < tol, nrms


def test_exported_mass_is_the_rigid_transfer(tmp_path):
    """The load FMU's mass_matrix calculated parameters = the point mass moved to the
    reference point, M6 = [[M, −M[r]×], [[r]×M, −[r]×M[r]×]] (hand-built here)."""
    from test_fmu import Fmu
    folder = build(tmp_path, body_with_point_mass("export").replace("[0.1, 0.05", "[0.0, 0.0"))
    fmu = Fmu(folder / "point_export_hull.fmu")
    try:
        got = np.array([[fmu.get(f"mass_matrix[{i},{j}]") for j in range(1, 7)] for i in range(1, 7)])[..., 0]
    finally:
        fmu.close()
    mp, (x, y, z) = 2.0e5, (10.0, 5.0, -3.0)
    rx = np.array([[0, -z, y], [z, 0, -x], [-y, x, 0]])
    expected = np.block([[mp * np.eye(3), -mp * rx], [mp * rx, -mp * rx @ rx]])
    np.testing.assert_allclose(got, expected, rtol=1e-12, atol=1e-6)


def test_pendulum_period(tmp_path):
    """A body hanging from an earth-fixed ball joint (default spring and damper): compound
    pendulum, small-angle period T = 2π·sqrt((I_cg + M·L²)/(M·g·L))."""
    L, m_point, i_cg, g = 10.0, 1000.0, 1600.0, 9.81
    folder = build(tmp_path, f"""
        [scene]
        name = "pendulum"
        [environment]
        g = {g}
        [run]
        step = 0.005
        stop = 20.0
        substep = 0.005
        [bodies.bob]
        mass = 1.0                     # the point mass below carries mass and weight
        inertia = [{i_cg}, {i_cg}, {i_cg}]
        velocity = [0.2, 0.0, 0.0, 0.0, 0.0, 0.0]
        [[bodies.bob.effects]]
        type = "riflex_body"
        offset = [0.0, 0.0, 0.0]
        am = {m_point}
        [joints.pivot]
        a = "bob"
        a_point = [0.0, 0.0, {L}]
        b = "earth"
        """)
    result = run(folder, progress=False)
    t, x = result.time, result["bob_dynamics.position[1]"]
    gap = np.abs(result.vector("pivot", "gap", 3)).max()
    up = np.where((x[:-1] < 0) & (x[1:] >= 0))[0]
    crossings = t[up] - x[up] * (t[up + 1] - t[up]) / (x[up + 1] - x[up])
    period = np.diff(crossings).mean()
    mass = m_point + 1.0
    expected = 2 * np.pi * np.sqrt((i_cg + mass * L ** 2) / (mass * g * L))
    assert len(crossings) >= 2
    assert period == pytest.approx(expected, rel=0.01)
    assert gap < 0.02 * L  # the joint spring sags by M·g/k under the weight


def test_joined_barges_stay_joined_in_current(tmp_path):
    """models/joined_barges.toml (default joint spring): the gap stays below 1 mm."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    folder = build_scene(load_scene(MODELS / "joined_barges.toml"), tmp_path, log=lambda *_: None)
    result = run(folder, stop=200.0, progress=False)
    gap = np.linalg.norm(result.vector("hitch", "gap", 3), axis=1)
    assert gap.max() < 1e-3
    drift = result.vector("barge_b_dynamics", "position", 3)[-1] - [100, 0, 0]
    assert np.linalg.norm(drift) > 0.3  # the current really moved them


def test_joined_barges_energy_does_not_grow(tmp_path):
    """No damping, no current: kinetic + spring energy of two barges joined by a ball
    joint (default spring–damper) never grows over 1000 s."""
    m, inertia = 1.28e7, np.array([7.7e8, 1.08e10, 1.13e10])
    k = np.array([2.0e5, 2.0e5, 2.5e7, 1.0e9, 2.0e10, 5.0e8])
    body = lambda name, x, v: f"""
        [bodies.{name}]
        position = [{x}, 0.0, 0.0]
        velocity = {v}
        mass = {m}
        inertia = {inertia.tolist()}
        stiffness = {k.tolist()}
        """
    folder = build(tmp_path, """
        [scene]
        name = "energy"
        [run]
        step = 0.1
        stop = 1000.0
        substep = 0.02
        """ + body("a", 0.0, [0.3, 0.2, 0.1, 0.01, 0.002, 0.004]) + body("b", 100.0, [0.0] * 6) + """
        [joints.hitch]
        a = "a"
        a_point = [50.0, 0.0, 0.0]
        b = "b"
        b_point = [-50.0, 0.0, 0.0]
        """)
    r = run(folder, progress=False)
    energy = 0.0
    for name, x0 in (("a", 0.0), ("b", 100.0)):
        v = r.vector(f"{name}_dynamics", "velocity", 6)
        eta = np.hstack([r.vector(f"{name}_dynamics", "position", 3) - [x0, 0, 0],
                         r.vector(f"{name}_dynamics", "attitude", 3)])
        rots = [rotation(a) for a in eta[:, 3:]]
        w_body = np.array([R.T @ w for R, w in zip(rots, v[:, 3:])])
        energy = energy + 0.5 * m * (v[:, :3] ** 2).sum(1) + 0.5 * (inertia * w_body ** 2).sum(1) \
            + 0.5 * (k * eta ** 2).sum(1)
    assert energy.max() <= energy[0] * (1 + 1e-3)
    assert energy[-1] > 0.01 * energy[0]  # still moving: a real check, not a dead system
