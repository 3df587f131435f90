"""Stability at the extremes (bench/stability.py): explicit added mass, explicit cross-body
added mass and quadratic drag at large steps — linear theory against in-process runs of
the real kernels, and a few points through the FMUs and the fmpy master."""
import json
import math
import re

import numpy as np
import pytest

from hydrofmu.bench import stability as st
from hydrofmu.cosim.master import run
from hydrofmu.physics.coupling import stability_indicator
from hydrofmu.physics.rigid_body import RigidBody

from conftest import build
from simo_decks import coupling_group, write_deck

M = st.MASS
PERIOD = 20.0
OMEGA = 2 * math.pi / PERIOD
K = M * OMEGA ** 2


# -- 1. explicit added mass -----------------------------------------------------------
@pytest.fixture(scope="module")
def amap():
    # 250 steps: at dt = 1e-4 s the A/M = 1.1 mode still grows ~1e5-fold (seed ~ω·dt)
    return st.added_mass_map(n_steps=250)


def test_map_divergence_equals_theory(amap):
    """On every grid point: simulated divergence (growth > 1e3 or non-finite) ⇔ ρ > 1,
    with no point in an ambiguous band around ρ = 1."""
    for mode in ("explicit", "export"):
        rho, growth = amap[f"rho_{mode}"], amap[f"growth_{mode}"]
        unstable, stable = rho > 1.01, rho < 1.0 + 1e-9
        assert np.all(unstable | stable), rho
        np.testing.assert_array_equal(st.diverged(growth), unstable)
        assert np.all(growth[stable] < 1.5), growth           # bounded: near the free amplitude


def test_explicit_diverges_above_one_export_stable(amap):
    ratios = amap["ratios"]
    above = ratios > 1
    assert above.any() and (~above).any()
    assert np.all(st.diverged(amap["growth_explicit"][above]))          # every step
    assert not np.any(st.diverged(amap["growth_explicit"][~above]))
    assert not np.any(st.diverged(amap["growth_export"]))                # whole map
    # small-step limit of the map: F_k+1 ≈ −(A/M)·F_k, so ρ → A/M above 1
    small = amap["steps"] <= 1e-2
    np.testing.assert_allclose(amap["rho_explicit"][above][:, small],
                               np.repeat(ratios[above, None], small.sum(), 1), rtol=1e-4)


def test_theory_export_is_damped_oscillator():
    """Export: ρ = exp(−ζ'·ω'·dt) of the oscillator with mass M + A (ζ' = C/(2√(K(M+A))))."""
    zeta, ratio, dt = 0.02, 3.0, 0.7
    c = 2 * zeta * math.sqrt(K * M)
    w = math.sqrt(K / (M + ratio * M))
    z = c / (2 * math.sqrt(K * (M + ratio * M)))
    expected = math.exp(-z * w * dt)
    assert st.added_mass_theory(ratio, dt, PERIOD, zeta, "export") == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("ratio, dt, n1, n2", [(1.1, 1e-3, 200, 300), (1.1, 1.0, 200, 300),
                                                (2.0, 0.1, 30, 60), (10.0, 1.0, 8, 16)])
def test_simulated_growth_rate_is_spectral_radius(ratio, dt, n1, n2):
    g1 = st.added_mass_run(ratio, dt, "explicit", n_steps=n1)
    g2 = st.added_mass_run(ratio, dt, "explicit", n_steps=n2)
    rate = (g2 / g1) ** (1.0 / (n2 - n1))
    assert rate == pytest.approx(st.added_mass_theory(ratio, dt, PERIOD), rel=2e-3)


def test_plot_map(amap, tmp_path):
    path = st.plot_added_mass_map(amap, tmp_path / "map.png")
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000


def point_scene(name, ratio, mode, step=0.1, stop=20.0):
    a = ratio * M
    return f"""
        [scene]
        name = "{name}"
        [run]
        step = {step}
        stop = {stop}
        substep = {min(step, PERIOD / 50)}
        [bodies.hull]
        mass = {M}
        inertia = [{100 * M}, {100 * M}, {100 * M}]
        velocity = [0.0, 0.0, 1.0, 0.0, 0.0, 0.0]
        stiffness = [{K}, {K}, {K}, {100 * K}, {100 * K}, {100 * K}]
        acceleration_loads = "{mode}"
        [[bodies.hull.effects]]
        type = "riflex_body"
        offset = [0.0, 0.0, 0.0]
        added_mass = [{a}, {a}, {a}]
        """


def fmu_growth(result, ratio):
    """added_mass_run's growth from an fmpy result: F sampled at t_k is held over
    [t_k, t_k+1], so it pairs with the state at t_k+1."""
    x, v = result["hull_dynamics.position[3]"], result["hull_dynamics.velocity[3]"]
    f = result["hull.force[3]"]
    scale = math.sqrt((M + ratio * M) / K)
    norm = np.maximum.reduce([np.abs(x[1:]) / scale, np.abs(v[1:]), np.abs(f[:-1]) / (K * scale)])
    n = len(norm)
    return norm[n - n // 4:].max()


@pytest.mark.filterwarnings("ignore::RuntimeWarning")   # the FMU runtime overflowing, in process
def test_fmu_explicit_added_mass(tmp_path):
    """A/M = 0.5 bounded, A/M = 2 diverges: through the FMUs and the fmpy master, equal to
    the in-process run; a long diverging run ends in fmi2Error on a non-finite input."""
    low = run(build(tmp_path / "low", point_scene("am_low", 0.5, "explicit")), progress=False)
    g = fmu_growth(low, 0.5)
    assert g < 1.5
    assert g == pytest.approx(st.added_mass_run(0.5, 0.1, "explicit", n_steps=200), rel=1e-9)
    folder = build(tmp_path / "high", point_scene("am_high", 2.0, "explicit"))
    g = fmu_growth(run(folder, stop=5.0, progress=False), 2.0)
    assert g > 1e3
    assert g == pytest.approx(st.added_mass_run(2.0, 0.1, "explicit", n_steps=50), rel=1e-6)
    with pytest.raises(Exception, match=r"fmi2(DoStep|GetReal) failed .*\(error\).* is not finite"):
        run(folder, stop=100.0, progress=False)


def test_fmu_export_large_added_mass(tmp_path):
    """A/M = 100 exported: the heave of mass M + A, x = v0/ω'·sin(ω'·t), ω' = √(K/(M + A))."""
    r = run(build(tmp_path, point_scene("am_export", 100.0, "export")), progress=False)
    w = math.sqrt(K / (101 * M))
    expected = np.sin(w * r.time) / w
    np.testing.assert_allclose(r["hull_dynamics.position[3]"], expected, atol=1e-8 / w)


# -- 2. explicit cross-body added mass ------------------------------------------------
SELF_A = np.diag([0.1, 0.3, 0.5, 0, 0, 0]) * M
SELF_B = np.diag([0.2, 0.2, 0.4, 0, 0, 0]) * M
SHAPE = np.zeros((6, 6))
SHAPE[0, 0], SHAPE[1, 1], SHAPE[2, 2], SHAPE[1, 2], SHAPE[2, 1] = 1.0, 0.6, 0.8, 0.3, -0.2


def rigid(m):
    return RigidBody(m, m * 100 * np.eye(3)).mass_matrix()


def cross_for(rho):
    """A_AB (shape SHAPE, bodies M and 2M with SELF_A/B) scaled to stability indicator ρ."""
    r1 = stability_indicator(rigid(M), SELF_A, SHAPE * M, rigid(2 * M), SELF_B, SHAPE.T * M)
    cross = SHAPE * M * math.sqrt(rho / r1)
    assert stability_indicator(rigid(M), SELF_A, cross, rigid(2 * M), SELF_B, cross.T) == pytest.approx(rho)
    return cross


@pytest.mark.parametrize("rho", [0.5, 0.8, 1.2, 2.0])
def test_cross_indicator_predicts_divergence(rho):
    """Short step (h = 5 ms, 2 % damping): bounded for ρ(G) < 1, diverging above; the
    exact linear map agrees."""
    cross = cross_for(rho)
    kw = dict(mass_b=2 * M, self_a=SELF_A, self_b=SELF_B, dt=0.005, zeta=0.02)
    g = st.cross_body_run(cross, n_steps=600, **kw)
    exact = st.cross_body_theory(cross, **kw)
    if rho < 1:
        assert g < 10 and exact < 1.0
    else:
        assert st.diverged(g) and exact > 1.0
        assert exact == pytest.approx(math.sqrt(rho), rel=1e-3)  # √ρ(G) per step


@pytest.mark.parametrize("dt", [1e-3, 0.1, 1.0])
@pytest.mark.parametrize("rho", [1.2, 2.0])
def test_cross_above_one_diverges_at_every_step(rho, dt):
    g = st.cross_body_run(cross_for(rho), mass_b=2 * M, self_a=SELF_A, self_b=SELF_B, dt=dt, n_steps=200)
    assert st.diverged(g)


@pytest.mark.parametrize("rho, dt, n1, n2", [(0.5, 0.1, 200, 400), (0.8, 0.1, 200, 400),
                                             (0.5, 1.0, 100, 200), (0.8, 1.0, 100, 200)])
def test_cross_below_one_grows_slowly_at_finite_steps(rho, dt, n1, n2):
    """Undamped, ρ(G) < 1 still grows at finite steps (the late cross load damps the
    anti-phase mode negatively): the simulated rate is the exact map's."""
    kw = dict(mass_b=2 * M, self_a=SELF_A, self_b=SELF_B, dt=dt)
    cross = cross_for(rho)
    exact = st.cross_body_theory(cross, **kw)
    assert exact > 1.0
    g1, g2 = (st.cross_body_run(cross, n_steps=n, **kw) for n in (n1, n2))
    assert math.log(g2 / g1) == pytest.approx((n2 - n1) * math.log(exact), rel=0.1)


def test_cross_h_max_estimate_is_conservative():
    """Equal bodies: the exact map is stable at the estimate ζ(1 − √ρ)T/(π√ρ) and unstable
    at 2× the estimate (module docstring: the exact limit is 1.01–1.45× the estimate)."""
    for rho in (0.2, 0.5, 0.8):
        cross = np.zeros((6, 6))
        cross[1, 1] = math.sqrt(rho) * M
        h = 0.02 * (1 - math.sqrt(rho)) * PERIOD / (math.pi * math.sqrt(rho))
        assert st.cross_body_theory(cross, dt=0.99 * h, zeta=0.02) < 1.0
        assert st.cross_body_theory(cross, dt=2.0 * h, zeta=0.02) > 1.0


def pair_scene(tmp_path, cross_sway, step=0.01, stop=10.0):
    tmp_path.mkdir(parents=True, exist_ok=True)
    deck = write_deck(tmp_path / "pair.sim", [
        coupling_group("AB", "A", "B", np.diag([0, cross_sway, 0, 0, 0, 0]), {}, 0.1, 1.0)])
    d = 2 * 0.02 * M * OMEGA
    body = lambda n, y, v: f"""
        [bodies.{n}]
        position = [0.0, {y}, 0.0]
        velocity = [0.0, {v}, 0.0, 0.0, 0.0, 0.0]
        mass = {M}
        inertia = [{100 * M}, {100 * M}, {100 * M}]
        stiffness = [{K}, {K}, {K}, {100 * K}, {100 * K}, {100 * K}]
        damping = [{d}, {d}, {d}, {100 * d}, {100 * d}, {100 * d}]
        acceleration_loads = "explicit"
        """
    return build(tmp_path, f"""
        [scene]
        name = "cross"
        [run]
        step = {step}
        stop = {stop}
        substep = {step}
        """ + body("a", 0.0, 1.0) + body("b", 40.0, 0.0) + f"""
        [[couplings]]
        deck = "{deck}"
        coupling = "AB"
        bodies = {{ A = "a", B = "b" }}
        """)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
def test_cross_fmu_pair(tmp_path):
    """Two equal bodies, explicit sway cross added mass c, 2 % damping, h = 10 ms:
    ρ(G) = c²/M² = 0.64 stays bounded over 10 s, 1.44 diverges."""
    x_free = 1.0 / OMEGA
    folder = pair_scene(tmp_path / "low", 0.8 * M)
    rho = json.loads((folder / "manifest.json").read_text())["stability_indicators"]["AB"]
    assert rho == pytest.approx(0.64, rel=1e-12)
    r = run(folder, progress=False)
    sway = np.column_stack([r.motion(b, "position", 3)[:, 1] - y for b, y in (("a", 0), ("b", 40))])
    assert np.abs(sway).max() < 3 * x_free
    assert np.abs(sway[-len(sway) // 4:]).max() < np.abs(sway).max()    # not growing
    assert np.abs(sway[:, 1]).max() > 0.1 * x_free                       # b moves through the coupling
    folder = pair_scene(tmp_path / "high", 1.2 * M, stop=2.0)
    try:
        r = run(folder, progress=False)
        grown = np.abs(r.motion("a", "velocity", 6)[:, 1]).max()
        assert grown > 1e3
    except Exception as exc:         # overflow to a non-finite input: the FMU reports fmi2Error
        assert re.search(r"fmi2(DoStep|GetReal) failed", str(exc))
        assert "not finite" in str(exc)           # the FMU's log line, in the one RunError


# -- 3. quadratic drag ----------------------------------------------------------------
def test_drag_step_limit_formula():
    assert st.drag_step_limit(2.0e6, 1.0e4, 50.0) == pytest.approx(2 * 2.0e6 / (1.0e4 * 50.0))
    assert st.drag_step_limit(2.0e6, 1.0e4, -50.0, "jacobi") == pytest.approx(2.0e6 / (1.0e4 * 50.0))


@pytest.mark.parametrize("kernel", ["aqwa", "riflex"])
@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
@pytest.mark.parametrize("speed", [1.0, 100.0, 1.0e4])
def test_drag_each_side_of_the_limit(speed, algorithm, kernel):
    limit = st.drag_step_limit(M, 1.0e4, speed, algorithm)
    assert st.drag_run(speed, 0.8 * limit, algorithm, kernel=kernel) < 0.1     # decayed
    assert st.diverged(st.drag_run(speed, 1.25 * limit, algorithm, kernel=kernel))


@pytest.mark.parametrize("current", [2.0, 50.0, -30.0])
def test_drag_relative_uses_relative_speed(current):
    """Relative drag: the limit takes |u_c − v0| (= 100 m/s here), not |v0|; with
    current = 50 m/s, |v0| = 50 m/s would allow twice the step."""
    limit = st.drag_step_limit(M, 1.0e4, 100.0)
    for kernel in ("aqwa", "riflex"):
        assert st.drag_run(100.0, 0.8 * limit, current=current, kernel=kernel) < 0.1
        assert st.diverged(st.drag_run(100.0, 1.25 * limit, current=current, kernel=kernel))


def test_drag_limit_counts_exported_added_mass():
    """RIFLEX BODY with drag and added mass A = M in export mode: limit 2(M + A)/(c·|v|);
    0.8× of it is 1.6× the dry-mass limit and still decays."""
    limit = st.drag_step_limit(2 * M, 1.0e4, 100.0)
    assert st.drag_run(100.0, 0.8 * limit, kernel="riflex", added=M) < 0.1
    assert st.diverged(st.drag_run(100.0, 1.25 * limit, kernel="riflex", added=M))


def step_map(prev, u, algorithm):
    """u = k·h·w of the exact held-load drag map (hand-written): Gauss–Seidel
    u' = u − u|u|; Jacobi u_n+1 = u_n − u_n−1|u_n−1|."""
    f = u if algorithm == "gauss-seidel" else prev
    return u, u - f * abs(f)


def recurrence(u0, algorithm, n):
    """|u_n| from u_−1 = u_0 (the master's start), inf once it passes 1e6."""
    prev, u = u0, u0
    for _ in range(n):
        prev, u = step_map(prev, u, algorithm)
        if abs(u) > 1e6:
            return math.inf
    return abs(u)


@pytest.mark.parametrize("algorithm, expected", [("gauss-seidel", 2.0), ("jacobi", 1.0)])
def test_drag_threshold_of_the_nonlinear_map(algorithm, expected):
    """Bisection on the nonlinear recurrence gives the linearised limit k·h·|w0| = 2 (GS),
    1 (Jacobi); exactly at it the map cycles (period 2, resp. 6)."""
    lo, hi = 0.1, 4.0
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if math.isfinite(recurrence(mid, algorithm, 4000)) else (lo, mid)
    assert lo == pytest.approx(expected, abs=1e-3)
    limit = st.drag_step_limit(M, 1.0e4, 1.0, algorithm) * 1.0e4 / M   # k·h·|w0| at the limit
    assert limit == pytest.approx(expected)
    states, prev, u = [], expected, expected
    for _ in range(6):
        prev, u = step_map(prev, u, algorithm)
        states.append((prev, u))
    period = {"gauss-seidel": 2, "jacobi": 6}[algorithm]   # Jacobi: 1, 1, 0, −1, −1, 0, 1, 1
    first = states.index((expected, expected)) + 1 if algorithm == "jacobi" else \
        [s_[1] for s_ in states].index(expected) + 1
    assert first == period


def drag_scene(tmp_path):
    return build(tmp_path, f"""
        [scene]
        name = "drag"
        [environment]
        current_speed = 2.0
        current_direction = 0.0
        [run]
        step = 1.0
        stop = 40.0
        substep = 0.5
        [bodies.hull]
        mass = {M}
        inertia = [{100 * M}, {100 * M}, {100 * M}]
        velocity = [-98.0, 0.0, 0.0, 0.0, 0.0, 0.0]
        [[bodies.hull.effects]]
        type = "aqwa_viscous_drag"
        matrix = [1.0e4, 0.0, 0.0, 0.0, 0.0, 0.0]
        option = "RELATIVE"
        """)


def hand_drag(w0, kh, n, algorithm):
    """Relative speed w = u − v of the held-load map, written out by hand."""
    w, prev = [w0], w0
    for _ in range(n):
        last = w[-1] if algorithm == "gauss-seidel" else prev
        prev = w[-1]
        w.append(w[-1] - kh * last * abs(last))
    return np.array(w)


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_drag_fmu_pair(tmp_path, algorithm):
    """AQWA RELATIVE drag, current 2 m/s, v0 = −98 m/s (|u − v0| = 100 m/s), c = 1e4,
    M = 1e6 through the FMUs: at 0.8× the limit the run is the hand map and decays, at
    1.25× it diverges (overflow ends in fmi2Error)."""
    folder = drag_scene(tmp_path)
    limit = st.drag_step_limit(M, 1.0e4, 100.0, algorithm)
    h = 0.8 * limit
    r = run(folder, step=h, stop=round(30 * h, 9), algorithm=algorithm, progress=False)
    w = 2.0 - r["hull_dynamics.velocity[1]"]
    np.testing.assert_allclose(w, hand_drag(100.0, 1.0e4 / M * h, len(w) - 1, algorithm), rtol=1e-9, atol=1e-9)
    assert abs(w[-1]) < 0.1 * 100.0
    h = 1.25 * limit
    try:
        r = run(folder, step=h, stop=round(30 * h, 9), algorithm=algorithm, progress=False)
        assert np.abs(2.0 - r["hull_dynamics.velocity[1]"]).max() > 1e3 * 100.0
    except Exception as exc:
        assert re.search(r"fmi2(DoStep|GetReal) failed", str(exc))
        assert "not finite" in str(exc)           # the FMU's log line, in the one RunError
