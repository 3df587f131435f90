"""Rigid-body dynamics partner against independent references: analytic oscillators,
a quaternion Newton–Euler model about the CoG solved with scipy, conservation laws,
and the exact rotation of a spherical top.  Every test runs twice: through the C kernel
(physics/rigid.c, the default where it compiles) and through the Python equations."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import eigh, expm
from scipy.spatial.transform import Rotation

from hydrofmu.errors import InputError
from hydrofmu.physics.kinematics import rotation
from hydrofmu.physics.rigid_body import GimbalLockError, RigidBody

ZERO6 = np.zeros(6)


@pytest.fixture(autouse=True, params=["c", "python"])
def kernel(request, monkeypatch):
    """Which implementation steps the bodies of the test."""
    from hydrofmu.physics import rigid_kernel
    if request.param == "python":
        monkeypatch.setattr(rigid_kernel, "library", lambda: None)
    elif rigid_kernel.library() is None:
        pytest.skip("no C compiler for the rigid-body kernel")
    return request.param


def msd(t, m, k, c, x0, v0, force=0.0):
    """Underdamped m·x'' + c·x' + k·x = F: position, velocity and acceleration."""
    wn = np.sqrt(k / m)
    zeta = c / (2.0 * np.sqrt(k * m))
    wd = wn * np.sqrt(1.0 - zeta ** 2)
    xs = force / k
    a0, sig = x0 - xs, zeta * wn
    b0 = (v0 + sig * a0) / wd
    e, cs, sn = np.exp(-sig * t), np.cos(wd * t), np.sin(wd * t)
    x = xs + e * (a0 * cs + b0 * sn)
    v = e * ((-sig * a0 + wd * b0) * cs + (-sig * b0 - wd * a0) * sn)
    return x, v, (force - c * v - k * x) / m


def run(body, dt, n, load=ZERO6):
    """States (n+1, 12) and accelerations (n+1, 6) at the communication points."""
    body.step(0.0, load)  # dt = 0 only sets the held load, so the t = 0 acceleration sees it
    ys, accs = [body.state()[:12]], [body.acceleration]
    for _ in range(n):
        body.step(dt, load)
        ys.append(body.state()[:12])
        accs.append(body.acceleration)
    return np.array(ys), np.array(accs)


def surge_body(m, k, c, added=0.0, **kw):
    K, D, A = np.zeros((6, 6)), np.zeros((6, 6)), np.zeros((6, 6))
    K[0, 0], D[0, 0], A[0, 0] = k, c, added
    return RigidBody(m, np.diag([1e6, 2e6, 3e6]), stiffness=K, damping=D, added_mass=A,
                     position0=[10.0, -3.0, 2.0], attitude0=[0.1, 0.2, 0.3], **kw)


# --- mass–spring–damper in surge -----------------------------------------------------------
@pytest.mark.parametrize("x0, v0", [(0.0, 0.8), (1.5, -0.4)])
def test_surge_damped_oscillation_matches_analytic(x0, v0):
    m, k, c = 2e5, 8e5, 8e4  # ωn = 2 rad/s, ζ = 0.1
    body = surge_body(m, k, c, velocity0=[v0, 0, 0, 0, 0, 0], max_substep=0.01)
    if x0:  # η0 is the initial pose, so a displaced start goes through set_state
        s = body.state()
        s[0] += x0
        body.set_state(s)
    dt, n = 0.1, 150  # ~5 periods
    ys, accs = run(body, dt, n)
    t = dt * np.arange(n + 1)
    x, v, a = msd(t, m, k, c, x0, v0)
    assert np.max(np.abs(ys[:, 0] - 10.0 - x)) <= 1e-6 * np.max(np.abs(x))
    assert np.max(np.abs(ys[:, 6] - v)) <= 1e-6 * np.max(np.abs(v))
    assert np.max(np.abs(accs[:, 0] - a)) <= 1e-6 * np.max(np.abs(a))
    # nothing else moves: the other dofs stay at the initial pose, at rest
    np.testing.assert_allclose(ys[:, 1:6], np.tile([-3.0, 2.0, 0.1, 0.2, 0.3], (n + 1, 1)), rtol=0, atol=1e-14)
    np.testing.assert_allclose(ys[:, 7:], 0.0, rtol=0, atol=1e-14)


def test_constant_force_gives_static_offset():
    m, k, c, f = 2e5, 8e5, 4e5, 3e5  # ζ = 0.5: settles within the run
    body = surge_body(m, k, c, max_substep=0.02)
    load = np.array([f, 0, 0, 0, 0, 0])
    ys, accs = run(body, 0.1, 300, load)
    t = 0.1 * np.arange(301)
    x, _, _ = msd(t, m, k, c, 0.0, 0.0, f)
    assert np.max(np.abs(ys[:, 0] - 10.0 - x)) <= 1e-6 * f / k
    assert ys[-1, 0] - 10.0 == pytest.approx(f / k, rel=1e-6)
    assert abs(ys[-1, 6]) < 1e-6 and abs(accs[-1, 0]) < 1e-6


def test_added_mass_enters_period():
    m, a, k = 2e5, 1.5e5, 8e5
    body = surge_body(m, k, 0.0, added=a, velocity0=[0.5, 0, 0, 0, 0, 0], max_substep=0.01)
    ys, _ = run(body, 0.1, 150)
    t = 0.1 * np.arange(151)
    x_ma, _, _ = msd(t, m + a, k, 0.0, 0.0, 0.5)
    x_m, _, _ = msd(t, m, k, 0.0, 0.0, 0.5)
    err = np.max(np.abs(ys[:, 0] - 10.0 - x_ma))
    assert err <= 1e-6 * np.max(np.abs(x_ma))
    assert np.max(np.abs(x_m - x_ma)) > 1e4 * err  # the test tells m from m + A


def test_acceleration_element_convention_with_nonsymmetric_matrices():
    """a from (M_rb + A)·a = F − K·(η − η0) − D·ν at ω = 0, CoG at O, written out by hand:
    A_ij, K_ij, D_ij take dof j of the motion to dof i of the load."""
    rng = np.random.default_rng(7)
    ig = np.diag([4e3, 5e3, 6e3])
    A, K, D = (rng.uniform(-1.0, 1.0, (6, 6)) * s for s in (300.0, 1e4, 1e3))
    att0 = np.array([0.3, -0.2, 0.5])
    body = RigidBody(1e3, ig, stiffness=K, damping=D, added_mass=A, attitude0=att0)
    deta = rng.uniform(-0.1, 0.1, 6)
    nu = np.r_[rng.uniform(-1.0, 1.0, 3), 0.0, 0.0, 0.0]
    load = rng.uniform(-1e3, 1e3, 6)
    body.set_state(np.concatenate([deta + np.r_[0, 0, 0, att0], nu, load]))
    rot = Rotation.from_euler("ZYX", (att0 + deta[3:])[::-1]).as_matrix()
    mass = np.zeros((6, 6))
    mass[:3, :3] = 1e3 * np.eye(3)
    mass[3:, 3:] = rot @ ig @ rot.T
    expected = np.linalg.solve(mass + A, load - K @ deta - D @ nu)
    np.testing.assert_allclose(body.acceleration, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


# --- roll / pitch with stiffness -------------------------------------------------------------
def zero_crossing_period(t, y):
    i = np.nonzero((y[:-1] < 0.0) & (y[1:] >= 0.0))[0]
    tc = t[i] - y[i] * (t[i + 1] - t[i]) / (y[i + 1] - y[i])
    return np.mean(np.diff(tc))


@pytest.mark.parametrize("dof, inertia, cog", [
    (3, np.diag([2e7, 3e7, 4e7]), [5.0, 0.0, 0.0]),   # roll; CoG offset along x leaves I_xx
    (4, np.diag([2e7, 3e7, 4e7]), [0.0, 3.0, 0.0]),   # pitch; CoG offset along y leaves I_yy
])
def test_small_angle_period(dof, inertia, cog):
    kk, aa = {3: (1e7, 5e6), 4: (4e7, 1e7)}[dof]
    K, A = np.zeros((6, 6)), np.zeros((6, 6))
    K[dof, dof], A[dof, dof] = kk, aa
    v0 = np.zeros(6)
    v0[dof] = -0.01  # starts downward so the first up-crossing is a full period in
    body = RigidBody(1e6, inertia, cog=cog, stiffness=K, added_mass=A, velocity0=v0, max_substep=0.05)
    ys, _ = run(body, 0.05, 700)
    ii = inertia[dof - 3, dof - 3]
    expected = 2 * np.pi * np.sqrt((ii + aa) / kk)
    assert zero_crossing_period(0.05 * np.arange(701), ys[:, dof]) == pytest.approx(expected, rel=1e-3)


@pytest.mark.parametrize("j", range(6))
def test_coupled_small_motion_follows_generalized_eigenmodes(j):
    """Small motion started along a mode of (M_rb + A, K) stays on it with that period."""
    m, ig, cog = 1e5, np.diag([3e6, 5e6, 6e6]), np.array([0.5, -0.3, -1.0])
    rng = np.random.default_rng(3)
    b = rng.normal(size=(6, 6))
    scale = np.sqrt([1.0, 1.0, 1.0, 30.0, 50.0, 60.0])  # kg, kg·m, kg·m² blocks
    A = 0.1 * m / 6 * (b @ b.T) * np.outer(scale, scale)  # full, symmetric, positive definite
    K = np.diag([2e5, 3e5, 4e6, 2e7, 3e7, 1e7])
    # M_rb at rest written out by hand: [[m·1, −m[c]×], [m[c]×, I_g + m(|c|²1 − c·cᵀ)]]
    cx = np.array([[0, -cog[2], cog[1]], [cog[2], 0, -cog[0]], [-cog[1], cog[0], 0]])
    mrb = np.block([[m * np.eye(3), -m * cx], [m * cx, ig + m * (cog @ cog * np.eye(3) - np.outer(cog, cog))]])
    w2, modes = eigh(K, mrb + A)
    period = 2 * np.pi / np.sqrt(w2[j])
    v0 = 1e-5 * modes[:, j] / np.max(np.abs(modes[:, j]))
    body = RigidBody(m, ig, cog=cog, stiffness=K, added_mass=A, velocity0=-v0, max_substep=period / 200)
    dt = period / 100
    ys, _ = run(body, dt, 250)
    t = dt * np.arange(251)
    expected = -np.outer(np.sin(np.sqrt(w2[j]) * t) / np.sqrt(w2[j]), v0)
    assert np.max(np.abs(ys[:, :6] - expected)) <= 1e-3 * np.max(np.abs(expected))


# --- 3-D motion against a quaternion Newton–Euler model about the CoG -------------------------
M3 = 5e3
IG3 = np.array([[8e3, 1.2e3, -6e2], [1.2e3, 1.1e4, 4e2], [-6e2, 4e2, 1.5e4]])
COG3 = np.array([1.2, -0.7, 0.9])
P03, ATT03 = np.array([3.0, -2.0, 1.0]), np.array([0.15, -0.1, 0.4])
V03 = np.array([0.4, -0.3, 0.2, 0.25, -0.35, 0.9])


def quat_matrix(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def reference_3d(times, load):
    """CoG position/velocity (global), unit quaternion and body-axis ω, Newton–Euler
    about the CoG; the load [F; M about the reference point] is moved to the CoG."""
    x, y, z, w = Rotation.from_euler("ZYX", ATT03[::-1]).as_quat()  # intrinsic Rz·Ry·Rx
    q0 = np.array([w, x, y, z])
    r0 = quat_matrix(q0)
    wb0 = r0.T @ V03[3:]
    xg0 = P03 + r0 @ COG3
    vg0 = V03[:3] + np.cross(V03[3:], r0 @ COG3)
    force, moment = load[:3], load[3:]

    def f(_, s):
        q, wb = s[6:10], s[10:]
        rot = quat_matrix(q)
        mg_body = rot.T @ (moment - np.cross(rot @ COG3, force))
        dq = 0.5 * np.concatenate([[-q[1:] @ wb], q[0] * wb + np.cross(q[1:], wb)])
        dwb = np.linalg.solve(IG3, mg_body - np.cross(wb, IG3 @ wb))
        return np.concatenate([s[3:6], force / M3, dq, dwb])

    sol = solve_ivp(f, (0, times[-1]), np.concatenate([xg0, vg0, q0, wb0]), method="DOP853",
                    t_eval=times, rtol=1e-12, atol=1e-13)
    assert sol.success
    return sol.y.T, f


def body_3d(max_substep=0.005):
    return RigidBody(M3, IG3, cog=COG3, position0=P03, attitude0=ATT03, velocity0=V03,
                     max_substep=max_substep)


@pytest.mark.parametrize("load", [ZERO6, np.array([800.0, -500.0, 1200.0, 900.0, -400.0, 1500.0])])
def test_3d_motion_matches_quaternion_reference(load):
    dt, n = 0.1, 60
    times = dt * np.arange(n + 1)
    ref, f = reference_3d(times, load)
    ys, accs = run(body_3d(), dt, n, load)
    assert np.max(np.abs(ys[:, 4])) < 1.2  # stays clear of gimbal lock
    for k in range(n + 1):
        xg, vg, q, wb = ref[k, :3], ref[k, 3:6], ref[k, 6:10], ref[k, 10:]
        rot = quat_matrix(q)
        rc, w = rot @ COG3, rot @ wb
        np.testing.assert_allclose(rotation(ys[k, 3:6]), rot, atol=1e-8)
        np.testing.assert_allclose(ys[k, :3], xg - rc, atol=1e-8)
        np.testing.assert_allclose(ys[k, 9:], w, atol=1e-8)
        np.testing.assert_allclose(ys[k, 6:9], vg - np.cross(w, rc), atol=1e-8)
        # acceleration of the reference point and α from the CoG model: dω/dt = R·dω_b/dt
        d = f(0.0, ref[k])
        alpha = rot @ d[10:]
        a_ref = d[3:6] - np.cross(alpha, rc) - np.cross(w, np.cross(w, rc))
        np.testing.assert_allclose(accs[k], np.concatenate([a_ref, alpha]), atol=1e-7)


def test_3d_free_motion_conserves_energy_and_angular_momentum():
    body = body_3d()
    ys, _ = run(body, 0.1, 100)

    def invariants(y):
        rot = rotation(y[3:6])
        rc, w = rot @ COG3, y[9:]
        vg = y[6:9] + np.cross(w, rc)
        ig = rot @ IG3 @ rot.T
        return 0.5 * M3 * vg @ vg + 0.5 * w @ ig @ w, ig @ w

    e0, h0 = invariants(ys[0])
    for y in ys[1:]:
        e, h = invariants(y)
        assert abs(e - e0) <= 1e-8 * e0
        assert np.linalg.norm(h - h0) <= 1e-8 * np.linalg.norm(h0)


def test_spherical_top_rotates_about_fixed_axis():
    """Isotropic inertia, CoG at O: ω stays constant, R(t) = exp(t·[ω]×)·R0 exactly,
    which checks the Euler-angle rate inversion on its own."""
    w = np.array([0.3, -0.4, 0.5])
    wx = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    att0 = np.array([0.2, 0.3, -0.5])
    body = RigidBody(1e3, 2e3 * np.eye(3), attitude0=att0, velocity0=np.r_[0, 0, 0, w], max_substep=0.01)
    for k in range(1, 31):
        body.step(0.1, ZERO6)
        np.testing.assert_allclose(rotation(body.attitude), expm(0.1 * k * wx) @ rotation(att0), atol=1e-9)
        np.testing.assert_allclose(body.velocity[3:], w, atol=1e-12)


# --- stepping ---------------------------------------------------------------------------------
def coupled_body(max_substep):
    K = np.diag([2e3, 3e3, 4e4, 3e4, 5e4, 2e4])
    A = np.diag([1e3, 2e3, 4e3, 2e3, 3e3, 4e3])
    return RigidBody(M3, IG3, cog=COG3, stiffness=K, damping=0.05 * K, added_mass=A, position0=P03,
                     attitude0=ATT03, velocity0=V03, max_substep=max_substep)


@pytest.mark.parametrize("max_substep", [0.01, 0.003])  # divides both steps / does not
def test_one_long_step_equals_ten_short_steps(max_substep):
    load = np.array([300.0, -200.0, 500.0, 400.0, -100.0, 600.0])
    one, ten = coupled_body(max_substep), coupled_body(max_substep)
    one.step(1.0, load)
    for _ in range(10):
        ten.step(0.1, load)
    scale = np.max(np.abs(one.state()[:12] - coupled_body(max_substep).state()[:12]))
    np.testing.assert_allclose(one.state(), ten.state(), rtol=0, atol=1e-9 * scale)
    np.testing.assert_allclose(one.acceleration, ten.acceleration, rtol=1e-8, atol=1e-12)


def test_state_round_trip():
    load = np.array([300.0, -200.0, 500.0, 400.0, -100.0, 600.0])
    body = coupled_body(0.01)
    body.step(0.3, load)
    saved = body.state()
    acc = body.acceleration
    mo = body.motion()  # the load kernels' view of the same state
    np.testing.assert_array_equal(np.concatenate([mo.position, mo.attitude, mo.velocity, mo.acceleration]),
                                  np.concatenate([saved[:12], acc]))
    body.step(0.2, load)
    after = body.state()
    saved_copy = saved.copy()
    body.set_state(saved)
    saved[:] = 0.0  # the body holds its own copy
    np.testing.assert_array_equal(body.state(), saved_copy)
    np.testing.assert_array_equal(body.acceleration, acc)
    body.step(0.2, load)
    np.testing.assert_array_equal(body.state(), after)


def test_pitch_through_90_degrees_raises_gimbal_lock():
    body = RigidBody(1e3, np.diag([1e3, 1e3, 1e3]), velocity0=[0, 0, 0, 0, 1.0, 0])
    body.step(1.5, ZERO6)  # θ = 1.5 rad: still fine
    assert body.attitude[1] == pytest.approx(1.5, rel=1e-9)
    with pytest.raises(GimbalLockError, match="90"):
        body.step(0.2, ZERO6)
    s = body.state()
    s[4] = np.pi / 2
    with pytest.raises(GimbalLockError):
        body.set_state(s)


@pytest.mark.parametrize("kwargs, field", [
    (dict(mass=-1.0), "mass"),
    (dict(inertia=[[1, 0.5, 0], [0, 1, 0], [0, 0, 1]]), "inertia[1,2]"),
    (dict(inertia=np.diag([1.0, -1.0, 1.0])), "inertia"),
    (dict(stiffness=np.zeros((3, 3))), "stiffness"),
    (dict(damping=np.full((6, 6), np.nan)), "damping"),
    (dict(attitude0=[0.0, np.pi / 2, 0.0]), "attitude0"),
    (dict(max_substep=0.0), "max_substep"),
])
def test_bad_input_names_the_field(kwargs, field):
    args = dict(mass=1.0, inertia=np.eye(3), source="scene.yaml:bodies.barge") | kwargs
    with pytest.raises(InputError) as err:
        RigidBody(**args)
    assert err.value.field == field and err.value.path == "scene.yaml:bodies.barge"


def test_bad_step_arguments():
    body = RigidBody(1.0, np.eye(3))
    with pytest.raises(InputError, match="dt"):
        body.step(-0.1, ZERO6)
    with pytest.raises(InputError, match="external_load"):
        body.step(0.1, np.zeros(3))


@pytest.mark.parametrize("periods_in_substeps, bound", [(100, 5e-6), (300, 80 / 300 ** 4), (1000, 80 / 1000 ** 4)])
def test_phase_error_per_period_against_sine(periods_in_substeps, bound):
    """Undamped oscillator against its sine: the phase error per period stays within the
    documented bound: at most classic RK4's 80/N⁴ (N = T/substep, RK4 in substeps) from
    N = 300, 5e-6 at N = 100 (module docstring)."""
    h = 0.01
    period = periods_in_substeps * h
    w = 2 * np.pi / period
    body = surge_body(1e3, 1e3 * w ** 2, 0.0, velocity0=[1.0, 0, 0, 0, 0, 0], max_substep=h)
    n = int(round(10 * period / 0.05))
    for _ in range(n):
        body.step(0.05, ZERO6)
    t = 0.05 * n
    assert abs(body.position[0] - 10.0 - np.sin(w * t) / w) * w / 10 <= bound


@pytest.mark.parametrize("periods_in_steps", [100, 300, 1000])
def test_one_rk4_step_when_the_communication_step_is_within_max_substep(periods_in_steps):
    """dt ≤ max_substep: one classic RK4 step per communication step.  Its amplification
    factor on the undamped oscillator, R = 1 + z + z²/2 + z³/6 + z⁴/24 at z = −iωdt (q = x + iv/ω
    obeys q' = −iωq; computed here), gives position and velocity after n steps to round-off; the phase error per period
    stays within 5 % of RK4's leading term (2π)⁵/(120·N⁴) ≈ 82/N⁴ (N = T/dt)."""
    dt = 0.05
    period = periods_in_steps * dt
    w = 2 * np.pi / period
    body = surge_body(1e3, 1e3 * w ** 2, 0.0, velocity0=[1.0, 0, 0, 0, 0, 0], max_substep=dt)
    n = int(round(10 * period / dt))
    for _ in range(n):
        body.step(dt, ZERO6)
    z = -1j * w * dt
    expected = (1j / w) * (1 + z + z ** 2 / 2 + z ** 3 / 6 + z ** 4 / 24) ** n   # q from i/ω at t = 0
    np.testing.assert_allclose([body.position[0] - 10.0, body.velocity[0] / w],
                               [expected.real, expected.imag], rtol=0, atol=1e-9 / w)
    t = dt * n
    assert abs(body.position[0] - 10.0 - np.sin(w * t) / w) * w / 10 <= 1.05 * (2 * np.pi) ** 5 / (120 * periods_in_steps ** 4)


def test_singular_mass_matrix_is_an_input_error():
    """M_rb + A singular (an added mass of −m in surge): the step and the acceleration name
    the added mass, whatever path found it (the published acceleration, a stage)."""
    added = np.zeros((6, 6))
    added[0, 0] = -1e3
    body = RigidBody(1e3, np.eye(3), added_mass=added, source="scene.toml:bodies.b")
    for call in (lambda: body.acceleration, lambda: body.step(0.1, ZERO6)):
        with pytest.raises(InputError, match="singular") as err:
            call()
        assert err.value.field == "added_mass" and err.value.path == "scene.toml:bodies.b"
