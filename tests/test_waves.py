"""Waves: the excitation readers' conventions against known answers, the sea states against
their spectra, the per-step kernel against the transfer functions (physics/waves.py,
decks/bem_waves.py).  Data: tests/data/bem/wave_*.nc (make_waves_data.py there)."""
import math
from pathlib import Path

import numpy as np
import pytest
from scipy import signal

pytest.importorskip("xarray")

from hydrofmu.decks.bem_waves import read_excitation, read_hydrostatics  # noqa: E402
from hydrofmu.errors import InputError  # noqa: E402
from hydrofmu.physics import waves  # noqa: E402
from hydrofmu.physics.waves import SeaState, TransferFunction, WaveError, WaveLoad  # noqa: E402

DATA = Path(__file__).parent / "data" / "bem"
ONE, PAIR = DATA / "wave_cylinder.nc", DATA / "wave_pair.nc"
RHO, G, RADIUS, DRAFT = 1025.0, 9.81, 2.0, 4.0
AWP = math.pi * RADIUS ** 2


def long_wave_heave(omega, x=0.0, beta=0.0):
    """Long-wave limit of the heave force on a vertical cylinder at (x, 0): ρ·g·A_wp times the
    elevation at its axis, e^{−ik·x·cos β} referred to the origin (k·R → 0; the pressure on the
    bottom decays as e^{−k·T}, a correction of k·T that the tolerance below allows for)."""
    k = omega ** 2 / G
    return RHO * G * AWP * np.exp(-k * DRAFT) * np.exp(-1j * k * x * np.cos(np.radians(beta)))


def test_capytaine_long_wave_heave_at_origin_and_away():
    one = read_excitation(ONE)
    pair = read_excitation(PAIR)
    assert one.kind == "Capytaine" and one.bodies == ["cyl"]
    # ω = 0.1 rad/s: kR = 0.002, kT = 0.004 (the e^{−kT} and inertia corrections < 0.5 %);
    # A_wp of the 32-sided mesh (0.6 % below πR²) from its own hydrostatics, C33 = ρ g A_wp
    awp = read_hydrostatics(ONE).stiffness["cyl"][2, 2] / (RHO * G)
    x = one.body("cyl")[0, 0, 2]
    want = long_wave_heave(one.omega[0]) * awp / AWP
    assert abs(x / want - 1) < 0.005 and abs(np.angle(x, deg=True)) < 0.2   # in phase with η at the body
    # the pair at x = ∓10 m: each carries its own k·x phase (5.3° at ω = 0.3 rad/s), per direction
    i = np.searchsorted(pair.omega, 0.3)
    for j, beta in enumerate(pair.directions):
        for name, xb in (("cyl1", -10.0), ("cyl2", 10.0)):
            got = pair.body(name)[i, j, 2]
            want = long_wave_heave(pair.omega[i], xb, beta) * awp / AWP
            assert abs(got / want - 1) < 0.03, (name, beta)     # O(kT) = 4 % inertia terms, partly in e^{−kT}
            assert abs(np.angle(got / want, deg=True)) < 0.3, (name, beta)


def test_capytaine_surge_leads_elevation_by_quarter_period():
    """Long waves: surge force = (ρV + A11)·∂u/∂t at the body, u = aω·cos(ωt) at the surface
    → F leads η by 90° (X purely imaginary, positive)."""
    one = read_excitation(ONE)
    i = np.searchsorted(one.omega, 0.3)
    x = one.body("cyl")[i, 0, 0]
    assert np.angle(x, deg=True) == pytest.approx(90.0, abs=1.0)


def wamit_files(tmp_path, ulen=2.0):
    """WAMIT .3 and .hst written from the Capytaine pair dataset with WAMIT's documented
    conventions: e^{+iωt} (Capytaine's values conjugated), X̄ = X/(ρ g L^m), m = 2 / 3,
    C̄ = C/(ρ g L^k), k = 2 + rotations; periods decreasing, headings in degrees."""
    import xarray as xr
    ds = xr.load_dataset(PAIR)
    f = ds["excitation_force"].sel(complex="re").values + 1j * ds["excitation_force"].sel(complex="im").values
    omega = ds["omega"].values
    lines = []
    for i in np.argsort(omega)[::-1]:
        if not np.isfinite(omega[i]):
            continue
        for j, beta in enumerate(np.degrees(ds["wave_direction"].values)):
            for d in range(12):
                x = np.conj(f[i, j, d]) / (RHO * G * ulen ** (2 if d % 6 < 3 else 3))
                lines.append(f"{2 * np.pi / omega[i]:.8E} {beta:.4f} {d + 1} {abs(x):.8E} "
                             f"{np.angle(x, deg=True):.6f} {x.real:.8E} {x.imag:.8E}")
    three = tmp_path / "pair.3"
    three.write_text("\n".join(lines) + "\n")
    c = ds["hydrostatic_stiffness"].values
    hst = tmp_path / "pair.hst"
    hst.write_text("".join(f"{i + 1} {j + 1} {c[i, j] / (RHO * G * ulen ** (2 + (i % 6 >= 3) + (j % 6 >= 3))):.10E}\n"
                           for i in range(12) for j in range(12) if i // 6 == j // 6))
    return three, hst


def test_wamit_files_read_as_capytaine(tmp_path):
    three, hst = wamit_files(tmp_path)
    w = read_excitation(three, ulen=2.0, rho=RHO, g=G)
    c = read_excitation(PAIR)
    # a Haskind .2 has the .3's layout and conventions: the same lines read the same
    two = three.with_suffix(".2")
    two.write_text(three.read_text())
    haskind = read_excitation(two, ulen=2.0, rho=RHO, g=G)
    assert haskind.bodies == w.bodies
    np.testing.assert_array_equal(haskind.body("body2"), w.body("body2"))
    assert w.bodies == ["body1", "body2"]
    np.testing.assert_allclose(w.omega, c.omega, rtol=1e-7)
    for wb, cb in (("body1", "cyl1"), ("body2", "cyl2")):
        scale = np.abs(c.body(cb)).max(axis=(0, 1))
        assert np.all(np.abs(w.body(wb) - c.body(cb)) <= 1e-6 * scale + 1e-9)
    i = np.searchsorted(w.omega, 0.3)                # WAMIT's convention pinned by the same known answer
    ratio = w.body("body2")[i, 0, 2] / long_wave_heave(w.omega[i], 10.0)
    assert abs(abs(ratio) - 1) < 0.03 and abs(np.angle(ratio, deg=True)) < 0.3
    h = read_hydrostatics(hst, ulen=2.0, rho=RHO, g=G)
    hc = read_hydrostatics(PAIR)
    np.testing.assert_allclose(h.stiffness["body2"], hc.stiffness["cyl2"], rtol=1e-8, atol=1e-6)
    assert h.weight and hc.weight


def test_capytaine_hydrostatics_hold_the_weight_moment():
    """C33 = ρ g A_wp; C55 = ρ g (I_wp + V z_B) − m g z_G with m = ρV (z_B = −T/2, z_G = −3 m)."""
    h = read_hydrostatics(ONE)
    c = h.stiffness["cyl"]
    volume = AWP * DRAFT
    assert c[2, 2] == pytest.approx(RHO * G * AWP, rel=0.02)
    c55 = RHO * G * (math.pi * RADIUS ** 4 / 4 - volume * DRAFT / 2) - RHO * volume * G * (-3.0)
    assert c[4, 4] == pytest.approx(c55, rel=0.02) and c[3, 3] == pytest.approx(c55, rel=0.02)
    assert h.mass["cyl"] == pytest.approx(RHO * volume, rel=0.02) and h.center_of_mass["cyl"] == [0, 0, -3]


def test_direction_interpolation_and_wrap():
    one = read_excitation(ONE)
    x = one.body("cyl")
    keep = [0, 2, 3, 4, 5, 6]                         # 0, 30, …, 90: 15° left out
    tf = TransferFunction(one.omega, one.directions[keep], x[:, keep])
    got = tf.at(one.omega, np.full(one.omega.size, 15.0))
    exact = x[:, 1]
    # heave does not depend on the heading; surge ∝ cos β: linear interpolation at the middle
    # of 0…30° gives cos 15°·cos 15° instead of cos 15° (the interpolation error, exactly)
    np.testing.assert_allclose(got[:, 2], exact[:, 2], rtol=0, atol=2e-3 * np.abs(exact[:, 2]).max())
    np.testing.assert_allclose(got[:, 0], exact[:, 0] * math.cos(math.radians(15)), rtol=5e-3,
                               atol=1e-3 * np.abs(exact[:, 0]).max())
    with pytest.raises(WaveError) as err:
        tf.at([1.0], [120.0])
    assert err.value.field == "direction" and "0…90" in str(err.value)
    # the pair's directions go round the circle: 350° interpolates between 330° and 0°, and
    # mirrors 10° (both bodies on the x axis: y → −y flips sway, roll and yaw)
    pair = read_excitation(PAIR)
    mirror = np.array([1, -1, 1, -1, 1, -1])
    for name in ("cyl1", "cyl2"):
        tf = TransferFunction(pair.omega, pair.directions, pair.body(name),
                              position=(-10.0 if name == "cyl1" else 10.0, 0.0))
        assert tf.closed
        a, b = tf.at(pair.omega, np.full(pair.omega.size, 350.0)), tf.at(pair.omega, np.full(pair.omega.size, 10.0))
        scale = np.abs(pair.body(name)).max(axis=(0, 1))
        scale = np.maximum(scale, 1e-6 * scale.max())       # yaw: zero (round-off) on a cylinder
        # (the BEM mesh is symmetric to ~0.6 % of the peak at the shortest waves, 3.75 rad/s)
        assert np.all(np.abs(a - b * mirror) <= 1e-2 * scale)
        np.testing.assert_allclose(tf.at(pair.omega, np.full(pair.omega.size, 370.0)), b)
        # a file that solved 360° as well as 0° (Capytaine's 2π, WAMIT's 360): one direction
        x = pair.body(name)
        both = TransferFunction(pair.omega, np.append(pair.directions, 360.0), np.concatenate((x, x[:, :1]), axis=1),
                                position=tf.position)
        np.testing.assert_allclose(both.at(pair.omega, np.full(pair.omega.size, 350.0)), a)
        # directions round the circle that do not start at 0°: 5° lies between 335° and 15°
        # (the wrap), not on the extension of 15° … 45°
        # (the same values turned by 15°, referred to the origin: no phase shift to turn)
        at0 = TransferFunction(pair.omega, pair.directions, x)
        turned = TransferFunction(pair.omega, pair.directions + 15.0, x)
        assert turned.closed
        np.testing.assert_allclose(turned.at(pair.omega, np.full(pair.omega.size, 5.0)),
                                   at0.at(pair.omega, np.full(pair.omega.size, 350.0)), rtol=1e-12, atol=0)


def test_jonswap_and_pm_spectra():
    for gamma in (1.0, 3.3, 7.0):
        w = np.linspace(0.05, 20, 200000)
        s = waves.spectrum(w, 3.0, 9.0, gamma)
        assert 4 * math.sqrt(np.trapezoid(s, w)) == pytest.approx(3.0, rel=1e-3)
        assert w[np.argmax(s)] == pytest.approx(2 * math.pi / 9.0, rel=1e-3)
    # Pierson–Moskowitz in closed form: S = 5/16·Hs²·ωp⁴·ω⁻⁵·exp(−5/4 (ωp/ω)⁴)
    w, wp = np.linspace(0.3, 3, 50), 2 * math.pi / 9.0
    pm = 5 / 16 * 9.0 * wp ** 4 * w ** -5 * np.exp(-1.25 * (wp / w) ** 4)
    np.testing.assert_allclose(waves.spectrum(w, 3.0, 9.0, 1.0), pm, rtol=2e-3)


def elevation_record(sea, point, duration, dt, window=(0.0, math.inf)):
    load = WaveLoad(waves.components(sea, window), None, point, sea.ramp)
    t = np.arange(0.0, duration, dt)
    return t, np.array([load(x)[6] for x in t])


def test_irregular_elevation_matches_spectrum_and_hs():
    sea = SeaState("jonswap", hs=2.5, tp=9.0, gamma=3.3, components=300, seed=7)
    sea.check()
    t, eta = elevation_record(sea, (0.0, 0.0), 3 * 3600.0, 0.5)
    assert 4 * eta.std() == pytest.approx(2.5, rel=0.03)
    f, p = signal.welch(eta, fs=2.0, nperseg=512)
    w, s = 2 * np.pi * f, p / (2 * np.pi)
    # the energy in bands of 0.1 rad/s (4 Welch bins, ~12 components each) where the target
    # holds more than 5 % of its peak: each within 10 % of the target's
    edges = np.arange(0.4, 2.0, 0.1)
    fine = np.linspace(0.3, 2.1, 5000)
    target = waves.spectrum(fine, 2.5, 9.0, 3.3)
    checked = 0
    for lo, hi in zip(edges[:-1], edges[1:]):
        inside, tin = (w >= lo) & (w < hi), (fine >= lo) & (fine < hi)
        want = np.trapezoid(target[tin], fine[tin])
        if target[tin].max() < 0.05 * target.max():
            continue
        got = s[inside].sum() * (w[1] - w[0])
        assert got == pytest.approx(want, rel=0.10), (lo, hi)
        checked += 1
    assert checked >= 8
    # no repeat: the record's second half is not its first half again
    half = eta.size // 2
    assert np.corrcoef(eta[:half], eta[half:2 * half])[0, 1] < 0.1


def test_two_points_see_the_phase_lag():
    """Long-crested irregular sea going to β: the elevation at x2 lags the one at x1 by
    k·Δx·cos β at each frequency (cross-spectrum phase), the sign of a wave going from 1 to 2."""
    beta = 30.0
    sea = SeaState("jonswap", hs=2.0, tp=8.0, direction=beta, components=200, seed=3)
    _, e1 = elevation_record(sea, (-10.0, 0.0), 3600.0, 0.25)
    _, e2 = elevation_record(sea, (10.0, 0.0), 3600.0, 0.25)
    f, pxy = signal.csd(e1, e2, fs=4.0, nperseg=4096)
    w = 2 * np.pi * f
    _, p11 = signal.welch(e1, fs=4.0, nperseg=4096)
    sel = p11 > 0.2 * p11.max()
    lag = -np.angle(pxy[sel])                    # csd: conj(E1)·E2 → phase of 2 relative to 1
    want = (w[sel] ** 2 / G) * 20.0 * math.cos(math.radians(beta))
    assert np.all(np.abs(np.angle(np.exp(1j * (lag - want)))) < math.radians(3))


def test_spreading_and_regular_components():
    sea = SeaState("jonswap", hs=2.0, tp=8.0, direction=45.0, spreading=4.0, components=4000, seed=1)
    c = waves.components(sea)
    # cos-2s with s = 4: mean direction 45°, circular spread √(2/(s+1)) rad = 36.2°
    offsets = np.radians(c.direction - 45.0)
    assert np.degrees(np.angle(np.mean(np.exp(1j * offsets)))) == pytest.approx(0.0, abs=2.0)
    assert np.degrees(math.sqrt(2 * (1 - abs(np.mean(np.exp(1j * offsets)))))) == pytest.approx(
        np.degrees(math.sqrt(2 / 5)), rel=0.05)
    again = waves.components(sea)
    np.testing.assert_array_equal(c.omega, again.omega)     # the same seed: the same field
    reg = waves.components(SeaState("regular", height=2.0, period=8.0, phase=30.0, direction=10.0))
    assert reg.amplitude.tolist() == [1.0] and reg.omega[0] == pytest.approx(2 * math.pi / 8)


def test_regular_load_equals_transfer_function_times_amplitude():
    pair = read_excitation(PAIR)
    tf = TransferFunction(pair.omega, pair.directions, pair.body("cyl2"), position=(10.0, 0.0))
    sea = SeaState("regular", height=3.0, period=2 * math.pi / 0.8, phase=40.0, direction=60.0, ramp=20.0)
    load = WaveLoad(waves.components(sea, tf.window), tf, (10.0, 0.0), sea.ramp)
    j = int(np.argmin(np.abs(pair.directions - 60.0)))
    x = pair.body("cyl2")[np.searchsorted(pair.omega, 0.8), j]
    for t in (25.0, 31.3, 47.9):
        want = 1.5 * np.real(x * np.exp(1j * (0.8 * t + math.radians(40))))
        np.testing.assert_allclose(load(t)[:6], want, rtol=1e-9, atol=1e-9 * np.abs(x).max())
        eta = 1.5 * math.cos(0.8 * t - 0.8 ** 2 / G * 10.0 * 0.5 + math.radians(40))
        assert load(t)[6] == pytest.approx(eta, abs=1e-12)
    assert load(10.0)[6] == pytest.approx(0.5 * 1.5 * math.cos(8.0 - 0.8 ** 2 / G * 5 + math.radians(40)))


def test_bad_inputs_are_one_error(tmp_path):
    for sea, field in ((SeaState(hs=-1.0), "hs"), (SeaState(gamma=0.8), "gamma"),
                       (SeaState("regular", period=0.0), "period"), (SeaState(spreading=-1.0), "spreading")):
        with pytest.raises(WaveError) as err:
            sea.check()
        assert err.value.field == field
    # Tp where the dataset has no frequencies: the share outside is stated, above MAX_OUTSIDE refused
    one = read_excitation(ONE)
    with pytest.raises(WaveError) as err:
        waves.components(SeaState(hs=2.0, tp=2.0), (one.omega[0], one.omega[-1]))
    assert err.value.field == "tp" and "% of the spectrum" in str(err.value)
    assert waves.share_outside(2.0, 3.3, one.omega[0], one.omega[-1]) > 0.1
    # NaN in the transfer function; a dataset without excitation
    import xarray as xr
    ds = xr.load_dataset(ONE)
    ds["excitation_force"][0, 3, 1, 2] = np.nan
    bad = tmp_path / "nan.nc"
    ds.to_netcdf(bad)
    with pytest.raises(InputError) as err:
        read_excitation(bad)
    assert "non-finite" in str(err.value) and "excitation_force" in str(err.value) and "nan.nc" in str(err.value)
    radiation_only = DATA / "cylinders.nc"
    with pytest.raises(InputError) as err:
        read_excitation(radiation_only)
    assert "excitation_force" in str(err.value) and "missing" in str(err.value)


def test_capytaine_regenerates_the_wave_data():
    """The committed wave_cylinder.nc is what make_waves_data.py makes: the cylinder solved
    again at one frequency (1.4 rad/s, next to its resonances) and one heading, added mass,
    damping, excitation and hydrostatics equal to the file's (needs capytaine: the bem-solve
    extra, installed in CI)."""
    pytest.importorskip("capytaine")
    import importlib.util
    import xarray as xr
    spec = importlib.util.spec_from_file_location("make_waves_data", DATA / "make_waves_data.py")
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    new = make.solve(make.cylinder("cyl", 0.0), [30.0], omega=[1.4])
    old = xr.load_dataset(ONE).sel(omega=[1.4], wave_direction=np.radians([30.0]), method="nearest")
    for var in ("added_mass", "radiation_damping", "excitation_force", "hydrostatic_stiffness", "inertia_matrix"):
        b = old[var]
        a = new[var]
        if "complex" in b.dims and "complex" not in a.dims:
            a = xr.concat([a.real, a.imag], dim="complex").assign_coords(complex=["re", "im"])
        a = a.transpose(*b.dims).values
        np.testing.assert_allclose(a, b.values, rtol=1e-6, atol=1e-9 * np.abs(b.values).max(), err_msg=var)


def test_a_sea_made_on_a_host_worker_thread_lets_the_process_exit():
    """A host (libcosimpy) steps FMUs on its own worker threads: the sea's components made
    there must not import threading for the first time (numpy.random did), or the interpreter
    hangs at exit in threading._shutdown.  A fresh process makes them on a bare _thread and
    exits while that thread is still alive."""
    import subprocess
    import sys
    code = ("import _thread, sys, time\n"
            "from hydrofmu.physics.waves import SeaState, components\n"
            "done = []\n"
            "def work():\n"
            "    components(SeaState(hs=2.0, tp=8.0), (0.05, 4.0))\n"
            "    done.append(1)\n"
            "    while True:\n"          # alive, as a host's worker pool is, when the process exits
            "        time.sleep(1)\n"
            "_thread.start_new_thread(work, ())\n"
            "while not done:\n"
            "    time.sleep(0.01)\n"
            "print('made')\n")
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=30)
    assert run.returncode == 0 and run.stdout.strip() == "made", run.stderr
