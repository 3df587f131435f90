"""Closed loop in fmpy: load FMU + dynamics partner against independent answers."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

from hydrofmu.cosim.master import run

from conftest import build

RHO = 1025.0
# current polar (angle, CX, CY, CMZ) of the test barge, port/starboard symmetric
POLAR = np.array([[0, 0.6, 0.0, 0.0], [30, 0.5, 0.9, 4.0], [60, 0.25, 2.4, 5.0], [90, 0.0, 3.2, 0.0],
                  [120, -0.25, 2.4, -5.0], [150, -0.5, 0.9, -4.0], [180, -0.6, 0.0, 0.0]])
S, V11, V22, V66 = 125.0, 6.4e4, 2.56e5, 8.0e9
K = np.array([2.0e5, 2.0e5, 2.5e7, 1.0e9, 2.0e10, 2.0e7])
MASS, INERTIA = 1.28e7, [7.7e8, 1.08e10, 1.13e10]


def barge_scene(direction, speed=1.0):
    rows = ", ".join(f"[{a}, {cx}, {cy}, {cm}]" for a, cx, cy, cm in POLAR)
    crit = 2 * np.sqrt(K * np.array([MASS] * 3 + INERTIA))  # critical damping: settle fast
    return f"""
        [scene]
        name = "steady"
        [environment]
        rho = {RHO}
        current_speed = {speed}
        current_direction = {direction}
        [run]
        step = 0.2
        stop = 500.0
        algorithm = "gauss-seidel"
        substep = 0.05
        [bodies.barge]
        mass = {MASS}
        inertia = {INERTIA}
        stiffness = {K.tolist()}
        damping = {crit.tolist()}
        [[bodies.barge.effects]]
        type = "aqwa_viscous_drag"
        matrix = [{V11}, {V22}, 1e6, 0, 0, {V66}]
        option = "RELATIVE"
        [[bodies.barge.effects]]
        type = "deeplines_current_polar"
        point = [0.0, 0.0, 0.0]
        surface = {S}
        symmetry = "xz"
        table = [{rows}]
        """


def current_load(yaw, direction, speed):
    """Hand computation of the steady current load (body at rest, yawed by ``yaw``):
    polar ½ρ·S·C(α)·V² plus relative viscous drag V·u|u|, in body axes, then to global."""
    beta = np.radians(direction) - yaw                     # current direction in body axes
    u = speed * np.array([np.cos(beta), np.sin(beta)])
    alpha = np.degrees(beta) % 360.0
    full = np.vstack([POLAR, (POLAR * [-1, 1, -1, -1] + [360, 0, 0, 0])[1:-1]])
    full = full[np.argsort(full[:, 0])]
    c = [np.interp(alpha, full[:, 0], full[:, k], period=360) for k in (1, 2, 3)]
    q = 0.5 * RHO * S * speed ** 2
    fx, fy, mz = q * c[0] + V11 * u[0] * abs(u[0]), q * c[1] + V22 * u[1] * abs(u[1]), q * c[2]
    cy, sy = np.cos(yaw), np.sin(yaw)
    return np.array([cy * fx - sy * fy, sy * fx + cy * fy, mz])


@pytest.mark.parametrize("direction", [0.0, 30.0, 350.0])
def test_steady_offset_is_static_equilibrium(tmp_path, direction):
    folder = build(tmp_path, barge_scene(direction))
    result = run(folder, progress=False)
    x = result.vector("barge_dynamics", "position", 3)[-1]
    yaw = result.vector("barge_dynamics", "attitude", 3)[-1, 2]
    # static equilibrium: restoring stiffness × offset = current load at that yaw
    eq = fsolve(lambda q: K[[0, 1, 5]] * q - current_load(q[2], direction, 1.0), np.zeros(3), xtol=1e-13)
    np.testing.assert_allclose([x[0], x[1], yaw], eq, rtol=1e-3, atol=1e-9 * max(abs(eq)))
    assert abs(x[0]) > 0.3  # a real offset, not a trivial zero
    if direction:
        assert abs(yaw) > 1e-3


def test_free_decay_under_quadratic_drag(tmp_path):
    """m·ẍ + c·ẋ|ẋ| + k·x = 0 from x = 0, ẋ = v0.  Analytic (harmonic balance) envelope:
    1/A(t) = 1/A0 + 4·c·ω·t / (3π·m); and a tight scipy solution of the same ODE."""
    m, k, c, v0 = 1.0e6, 1.0e5, 2.0e4, 1.0
    folder = build(tmp_path, f"""
        [scene]
        name = "decay"
        [run]
        step = 0.05
        stop = 200.0
        substep = 0.01
        [bodies.buoy]
        mass = {m}
        inertia = [1e8, 1e8, 1e8]
        velocity = [{v0}, 0, 0, 0, 0, 0]
        stiffness = [{k}, {k}, {k}, 1e9, 1e9, 1e9]
        [[bodies.buoy.effects]]
        type = "aqwa_viscous_drag"
        matrix = [{c}, 0, 0, 0, 0, 0]
        option = "ABSOLUTE"
        """)
    result = run(folder, progress=False)
    t, x = result.time, result["buoy_dynamics.position[1]"]
    w = np.sqrt(k / m)
    # peaks of |x| against the analytic envelope
    i = np.where((np.abs(x[1:-1]) > np.abs(x[:-2])) & (np.abs(x[1:-1]) >= np.abs(x[2:])))[0] + 1
    envelope = 1.0 / (w / v0 + 4 * c * w * t[i] / (3 * np.pi * m))
    assert len(i) > 10
    np.testing.assert_allclose(np.abs(x[i]), envelope, rtol=0.02)
    assert np.abs(x[i[-1]]) < 0.5 * np.abs(x[i[0]])  # it really decays
    ref = solve_ivp(lambda _, y: [y[1], -(c * y[1] * abs(y[1]) + k * y[0]) / m], (0, t[-1]), [0, v0],
                    t_eval=t, rtol=1e-10, atol=1e-12)
    nrms = np.sqrt(np.mean((x - ref.y[0]) ** 2)) / np.ptp(ref.y[0])
    assert nrms < 2e-3
