"""Incident-wave kinematics (physics/wave_kinematics.py) against Airy theory derived from its
potential (tests/airy.py, itself checked against the linear boundary-value problem), the
stretching options at a crest by hand, the velocity spectrum at depth; the shared per-step
phasors (physics/waves.py Phasors) against the exact phases over a 3-hour record."""
import math

import numpy as np
import pytest

from airy import Airy, check_potential
from hydrofmu.physics import waves
from hydrofmu.physics.wave_kinematics import WaveKinematics
from hydrofmu.physics.waves import Components, Phasors, SeaState, WaveLoad

G, RHO = 9.81, 1025.0


def some_components():
    rng = np.random.default_rng(4)
    n = 7
    return Components(rng.uniform(0.3, 1.5, n), rng.uniform(0.1, 1.0, n), rng.uniform(-180, 180, n),
                      rng.uniform(0, 2 * math.pi, n))


@pytest.mark.parametrize("depth", [math.inf, 40.0, 8.0])
def test_reference_potential_solves_the_linear_problem(depth):
    """tests/airy.py's potential obeys Laplace's equation, the bed condition and the linear
    kinematic surface condition with its dispersion relation (the dynamic one defines it)."""
    airy = Airy.of(some_components(), depth)
    check_potential(airy, [(1.0, 2.0, -0.5), (-3.0, 4.0, -min(depth, 30.0) + 1.0)], (0.0, 3.7, 51.2))


@pytest.mark.parametrize("depth", [math.inf, 40.0, 8.0])
def test_kinematics_against_airy(depth):
    comps = some_components()
    kin = WaveKinematics(comps, G, depth)
    ph = Phasors(comps, ramp_length=30.0)
    reference = Airy.of(comps, depth)
    rng = np.random.default_rng(1)
    for t in (0.0, 7.3, 12.0, 55.5, 300.25):
        pts = np.column_stack((rng.uniform(-50, 50, 6), rng.uniform(-50, 50, 6), rng.uniform(-min(depth, 30.0), -0.5, 6)))
        got = kin.at(ph.at(t), ph.ramp_factor, pts, RHO)
        for pt, row in zip(pts, got):
            want = reference.at(*pt, t, waves.ramp(t, 30.0))
            if want[7] < pt[2]:
                continue
            # each output's scale: ω a, ω² a, ρ g a, a summed (ω < 1.5 rad/s; F ≤ coth kh ≤ 1.2)
            scale = np.array([1.5, 1.5, 1.5, 2.25, 2.25, 2.25, RHO * G, 1.0]) * 1.5 * comps.amplitude.sum()
            assert np.all(np.abs(row - want) <= 1e-11 * scale), (t, pt, row - want)


def crest(depth):
    """A regular wave a = 2 m, T = 8 s going to +x, its crest at x = 0 at t = 0."""
    comps = Components(np.array([2 * math.pi / 8.0]), np.array([2.0]), np.array([0.0]), np.array([0.0]))
    return comps, float(waves.wave_number(comps.omega, G, depth)[0]), comps.omega[0]


@pytest.mark.parametrize("depth", [math.inf, 20.0])
def test_stretching_at_a_crest_by_hand(depth):
    comps, k, w = crest(depth)
    a, h = 2.0, depth
    ph = Phasors(comps)
    p = ph.at(0.0)
    if math.isinf(depth):
        fh = lambda z: math.exp(k * z)                              # noqa: E731
        fv = fh
        fh0, dfh, fv0, dfv = 1.0, k, 1.0, k
    else:
        fh = lambda z: math.cosh(k * (z + h)) / math.sinh(k * h)    # noqa: E731
        fv = lambda z: math.sinh(k * (z + h)) / math.sinh(k * h)    # noqa: E731
        fh0, dfh = 1 / math.tanh(k * h), k
        fv0, dfv = 1.0, k / math.tanh(k * h)
    # at the crest: u = ω a F_h, w = 0, a_x = 0, a_z = −ω² a F_v (the water decelerates downward)
    for z in (1.0, -3.0):
        wheeler_z = z - a if math.isinf(depth) else h * (z - a) / (h + a)
        want = {"none": (fh(z), fv(z)),
                "vertical": (fh(min(z, 0.0)), fv(min(z, 0.0))),
                "extrapolation": (fh0 + dfh * z, fv0 + dfv * z) if z > 0 else (fh(z), fv(z)),
                "wheeler": (fh(wheeler_z), fv(wheeler_z))}
        for name, (h_, v_) in want.items():
            row = WaveKinematics(comps, G, depth, name).at(p, 1.0, [(0.0, 0.0, z)])[0]
            assert row[0] == pytest.approx(w * a * h_, rel=1e-12), (name, z)
            assert row[5] == pytest.approx(-w * w * a * v_, rel=1e-12), (name, z)
            assert abs(row[2]) < 1e-12 and abs(row[3]) < 1e-12 and row[7] == pytest.approx(a, rel=1e-14)
    # Wheeler at the surface itself: the z = 0 values; above it, out of the water
    row = WaveKinematics(comps, G, depth, "wheeler").at(p, 1.0, [(0.0, 0.0, a)])[0]
    assert row[0] == pytest.approx(w * a * fh0, rel=1e-12) and row[6] == pytest.approx(RHO * G * a, rel=1e-12)
    for name in ("none", "vertical", "extrapolation", "wheeler"):
        row = WaveKinematics(comps, G, depth, name).at(p, 1.0, [(0.0, 0.0, a + 0.01)])[0]
        assert np.all(row[:7] == 0.0) and row[7] == pytest.approx(a)
    # in a trough (t = T/2, η = −a) a point at z = −1 is dry
    row = WaveKinematics(comps, G, depth).at(ph.at(4.0), 1.0, [(0.0, 0.0, -1.0)])[0]
    assert row[7] == pytest.approx(-a) and np.all(row[:7] == 0.0)


def test_velocity_spectrum_at_depth():
    """Deep water, long-crested JONSWAP: the horizontal velocity at z has the spectrum
    ω²·e^{2kz}·S(ω); its energy in bands of 0.1 rad/s from a 3-hour record (Welch) within 10 %
    of the target's integral where the target holds more than 5 % of its peak (as the
    elevation's test in test_waves.py)."""
    from scipy import signal
    sea = SeaState("jonswap", hs=2.5, tp=9.0, gamma=3.3, components=300, seed=7)
    comps = waves.components(sea)
    kin = WaveKinematics(comps, G)
    ph = Phasors(comps)
    z, dt = -6.0, 0.5
    t = np.arange(0.0, 3 * 3600.0, dt)
    u = np.array([kin.at(ph.at(x), 1.0, [(0.0, 0.0, z)])[0, 0] for x in t])
    f, pu = signal.welch(u, fs=1 / dt, nperseg=512)
    w, s = 2 * np.pi * f, pu / (2 * np.pi)
    fine = np.linspace(0.3, 2.1, 5000)
    target = fine ** 2 * np.exp(2 * fine ** 2 / G * z) * waves.spectrum(fine, 2.5, 9.0, 3.3)
    checked = 0
    edges = np.arange(0.4, 2.0, 0.1)
    for lo, hi in zip(edges[:-1], edges[1:]):
        inside, tin = (w >= lo) & (w < hi), (fine >= lo) & (fine < hi)
        if target[tin].max() < 0.05 * target.max():
            continue
        want = np.trapezoid(target[tin], fine[tin])
        got = np.sum(s[inside]) * (w[1] - w[0])
        assert got == pytest.approx(want, rel=0.10), (lo, hi)
        checked += 1
    assert checked >= 6


def test_phasors_round_off_over_three_hours():
    """The phasors advanced by one complex multiply a step stay within the stated bound
    (4·ε·resync + ω_k·GRID_ULPS·ulp(t) + 2ε·(ω_k t + 2π))·|a_k| of a_k e^{i(ω_k t + φ_k)} over a
    3-hour record,
    with the master's times t = n·h; a variable step is exact; the trigonometry runs once per
    ``resync`` steps."""
    sea = SeaState("jonswap", hs=4.0, tp=10.0, components=200, seed=3)
    comps = waves.components(sea)
    ph = Phasors(comps)
    h, n = 0.05, int(3 * 3600 / 0.05)
    worst = 0.0
    for i in range(n + 1):
        t = i * h
        p = ph.at(t)
        if i % 997 == 0 or i > n - 3:
            exact = comps.amplitude * np.exp(1j * (comps.omega * t + comps.phase))
            # rotations, the grid's time tolerance, and the rounding of the phase argument
            # ω t + φ that the exact evaluations (the resync's and this reference) both carry
            bound = comps.amplitude * (4 * 2.2e-16 * waves.RESYNC + comps.omega * waves.GRID_ULPS * math.ulp(t)
                                       + 2 * 2.2e-16 * (comps.omega * t + 2 * math.pi))
            err = np.abs(p - exact)
            assert np.all(err <= bound + 1e-300), (t, (err / bound).max())
            worst = max(worst, (err / comps.amplitude).max())
    assert ph.exact <= n / waves.RESYNC + 2 and ph.rotations >= n - n / waves.RESYNC - 2
    # without resynchronisation the error grows: the bound is the resynchronisation's doing
    free = Phasors(comps, resync=10 ** 9)
    for i in range(n + 1):
        free.at(i * h)
    exact = comps.amplitude * np.exp(1j * (comps.omega * n * h + comps.phase))
    assert (np.abs(free.p - exact) / comps.amplitude).max() > worst
    # variable steps, a jump back and a repeated time: exact whatever the sequence
    rng = np.random.default_rng(0)
    t = 0.0
    for i in range(3000):
        t = t + (h if i % 7 else rng.uniform(0.01, 0.2)) if i != 2000 else 12.5
        p = ph.at(t).copy()
        assert np.all(ph.at(t) == p)
        exact = comps.amplitude * np.exp(1j * (comps.omega * t + comps.phase))
        assert np.all(np.abs(p - exact) <= comps.amplitude * 1e-12)


def test_wave_load_with_shared_phasors_equals_the_direct_sum():
    """WaveLoad's elevation through the shared phasors against the direct cosine sum, and two
    effects on one Phasors advance it once per step."""
    sea = SeaState("jonswap", hs=2.0, tp=8.0, components=50, seed=2, ramp=10.0, direction=30.0)
    comps = waves.components(sea)
    ph = Phasors(comps, sea.ramp)
    load = WaveLoad(comps, None, (12.0, -4.0), sea.ramp, phasors=ph)
    kin = WaveKinematics(comps, G)
    k = comps.omega ** 2 / G
    b = np.radians(comps.direction)
    for i in range(400):
        t = 0.1 * i
        eta = load(t)[6]
        row = kin.at(ph.at(t), ph.ramp_factor, [(12.0, -4.0, -1.0)])[0]
        want = waves.ramp(t, 10.0) * np.sum(comps.amplitude * np.cos(
            comps.omega * t - k * (12.0 * np.cos(b) - 4.0 * np.sin(b)) + comps.phase))
        assert eta == pytest.approx(want, abs=1e-12 * comps.amplitude.sum())
        assert row[7] == pytest.approx(want, abs=1e-12 * comps.amplitude.sum())
    assert ph.exact + ph.rotations == 400


def test_compiled_kinematics_equal_the_python_ones():
    """physics/wave_kinematics.c (compiled alone with waves.c) against the Python kernel: every
    stretching, deep and finite depth, points below, above the mean level and out of the water,
    moving and fixed, through the compiled phasors, to 1e-12 of each output's range."""
    import ctypes
    from pathlib import Path
    from hydrofmu.cc import cached_many
    from hydrofmu.physics.wave_kinematics import STRETCHING
    physics = Path(waves.__file__).parent
    lib = ctypes.CDLL(str(cached_many([physics / "waves.c", physics / "wave_kinematics.c"], "kin_kernel",
                                      libs=["-lm"], flags=["-O2", "-shared", "-fPIC", "-std=c99"])))
    lib.hf_kin_build.restype = ctypes.POINTER(ctypes.c_double)
    for name in ("hf_phasors_new", "hf_kin_point_new"):
        getattr(lib, name).restype = ctypes.c_void_p
    lib.hf_phasors_at.restype = ctypes.POINTER(ctypes.c_double)
    lib.hf_phasors_ramp.restype = ctypes.c_double
    D = ctypes.c_double
    sea = SeaState("jonswap", hs=3.0, tp=9.0, components=40, seed=5, spreading=3.0, ramp=8.0)
    comps = waves.components(sea)
    n = comps.omega.size
    arr = lambda x: (D * len(x))(*x)   # noqa: E731
    omega, amp = arr(comps.omega.tolist()), arr((comps.amplitude * np.exp(1j * comps.phase)).view(float).tolist())
    rng = np.random.default_rng(2)
    for depth in (math.inf, 25.0):
        for code, name in enumerate(STRETCHING):
            kin = WaveKinematics(comps, G, depth, name)
            ph = Phasors(comps, sea.ramp)
            params = lib.hf_kin_build(omega, arr(comps.direction.tolist()), n, D(G), D(depth), code)
            cph = ctypes.c_void_p(lib.hf_phasors_new(omega, amp, n, D(sea.ramp), waves.RESYNC))
            cache = ctypes.c_void_p(lib.hf_kin_point_new(n))
            out = (D * 8)()
            got, ref = [], []
            fixed = (3.0, -2.0, -4.0)
            for i in range(300):
                t = 0.1 * i
                x = fixed if i % 3 else (rng.uniform(-20, 20), rng.uniform(-20, 20), rng.uniform(-6.0, 2.5))
                p = lib.hf_phasors_at(cph, D(t))
                lib.hf_kin_at(params, cache, p, D(lib.hf_phasors_ramp(cph)), arr(list(x)), D(RHO), out)
                got.append(list(out))
                ref.append(kin.at(ph.at(t), ph.ramp_factor, [x], RHO)[0])
            got, ref = np.array(got), np.array(ref)
            span = ref.max(axis=0) - ref.min(axis=0)
            assert (span > 0).all() and np.all(np.abs(got - ref) <= 1e-12 * span), (depth, name)
            assert (ref[:, 0] == 0).sum() > 5   # some points were out of the water
            lib.hf_kin_point_delete(cache), lib.hf_phasors_delete(cph)
            ctypes.CDLL(None).free(params)

