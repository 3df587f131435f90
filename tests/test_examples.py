"""The scripts of examples/ run (short stop times) and say what they should."""
import importlib.util
import math

import numpy as np
import pytest

from conftest import ROOT


def example(name):
    """The example script as a module (its ``main(argv)`` is what ``python examples/<name>.py`` runs)."""
    spec = importlib.util.spec_from_file_location(f"example_{name}", ROOT / "examples" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def built(tmp_path_factory):
    out = tmp_path_factory.mktemp("examples")
    result = example("build_and_run").main(["--stop", "3", "--out", str(out)])
    return out, result


def test_build_and_run_writes_csv_and_plot(built, capsys):
    out, result = built
    assert (out / "moored_barge" / "manifest.json").is_file()
    assert (out / "moored_barge.png").read_bytes()[:4] == b"\x89PNG"
    assert len(result.time) == 31 and result.time[-1] == pytest.approx(3.0)


def test_read_results_reads_the_csv_back(built, capsys):
    out, result = built
    back, summary = example("read_results").main([str(out / "moored_barge.csv"), "--settle", "0.5"])
    np.testing.assert_array_equal(back.values, result.values)
    text = capsys.readouterr().out
    assert "barge_dynamics.position [m]" in text and "barge.force [N, N.m]" in text
    pos = result.motion("barge", "position", 3)
    np.testing.assert_allclose(summary["barge"], (pos[result.time >= 1.5] - pos[0]).mean(axis=0))


def test_own_master_agrees_with_hydrofmus_master(built):
    out, _ = built
    # an independent master and vessel model (surge/sway RK4) around the same load FMU,
    # against hydrofmu's master with its 6-DOF dynamics partner FMU
    mine, theirs = example("own_master").main(["--stop", "20", "--out", str(out)])
    assert np.abs(theirs).max() > 0.05                       # the barge moved (current load)
    assert np.abs(mine - theirs).max() < 1e-3 * np.abs(theirs).max()


def test_step_sweep_converges(built):
    out, _ = built
    rows = example("step_sweep").main(["--stop", "6", "--steps", "0.4", "0.2", "--out", str(out)])
    assert (out / "step_sweep.png").is_file() and (out / "step_sweep.csv").is_file()
    err = {(r["algorithm"], r["step_s"]): r["error"] for r in rows}
    for algorithm in ("jacobi", "gauss-seidel"):
        # constant hold is first order: halving the step about halves the error
        assert 1.5 < err[(algorithm, 0.4)] / err[(algorithm, 0.2)] < 3.0
    assert err[("gauss-seidel", 0.2)] < err[("jacobi", 0.2)]


def test_waves_statistics_match_the_frequency_domain(tmp_path, capsys):
    """The buoy of models/buoy_in_waves.toml in its JONSWAP sea (Hs 2 m, Tp 8 s, heading 30°),
    300 s: the heave, roll and pitch standard deviations of the time-domain run (FMUs: radiation
    memory, BEM hydrostatics and excitation) within 3 % of the linear response to the same wave
    components computed in the script from the BEM dataset, X = [−ω²(M + A) + iω(B + D) + C + K]⁻¹F
    (measured: 0.4 %, 1.1 %, 1.0 %); roll/pitch = tan 30° (a round body in waves going to 30°);
    the spectral estimate √∫|X|²S dω within 10 % (a 210 s record is one sample of the sea: 7 %)."""
    stats = example("waves_statistics").main(["--stop", "300", "--out", str(tmp_path)])
    for dof, (td, same, spectral) in stats.items():
        assert td == pytest.approx(same, rel=0.03), dof
        assert spectral == pytest.approx(same, rel=0.10), dof
    assert stats["roll"][0] / stats["pitch"][0] == pytest.approx(math.tan(math.radians(30.0)), rel=0.02)
    assert 0.3 < stats["heave"][0] < 1.0 and stats["pitch"][0] < 15.0   # metres and degrees: in the linear range
    text = capsys.readouterr().out
    assert "time domain / same sea" in text and (tmp_path / "buoy_in_waves_spectra.png").stat().st_size > 10000


def test_capytaine_regenerates_the_buoy_data():
    """models/decks/buoy.nc is what models/decks/make_buoy.py makes: the buoy solved again at one
    frequency (1.4 rad/s, between its heave and pitch resonances) and one heading (30°), added
    mass, damping, excitation, hydrostatics and inertia equal to the file's (needs capytaine:
    the bem-solve extra, installed in CI)."""
    pytest.importorskip("capytaine")
    import xarray as xr
    spec = importlib.util.spec_from_file_location("make_buoy", ROOT / "models" / "decks" / "make_buoy.py")
    make = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(make)
    new = make.solve(omega=[1.4], directions=[30.0])
    old = xr.load_dataset(ROOT / "models" / "decks" / "buoy.nc").sel(omega=[1.4], wave_direction=[math.radians(30.0)],
                                                                    method="nearest")
    for var in ("added_mass", "radiation_damping", "excitation_force", "hydrostatic_stiffness", "inertia_matrix"):
        b, a = old[var], new[var]
        if "complex" in b.dims and "complex" not in a.dims:
            a = xr.concat([a.real, a.imag], dim="complex").assign_coords(complex=["re", "im"])
        a = a.transpose(*b.dims).values
        np.testing.assert_allclose(a, b.values, rtol=1e-6, atol=1e-9 * np.abs(b.values).max(), err_msg=var)


def test_wave_probe_gives_a_second_fmu_the_same_sea(tmp_path):
    # barge A's load FMU's named point read by a pythonfmu sphere through our own fmpy loop:
    # the velocity it got is Airy of the scene's components (Wheeler, ramped) written in the example
    worst, rows = example("wave_probe").main(["--stop", "8", "--out", str(tmp_path)])
    assert worst < 1e-12 and np.abs(rows[:, 1:4]).max() > 0.05
    u, a, f = rows[:, 1:4], rows[:, 4:7], rows[:, 8:11]
    rho, r = 1025.0, 0.5   # the sphere's Morison force on what it was given
    want = 0.5 * rho * np.pi * r * r * np.linalg.norm(u, axis=1)[:, None] * u + rho * 2 * 4 / 3 * np.pi * r ** 3 * a
    np.testing.assert_allclose(f, want, rtol=1e-12, atol=1e-9)
    assert (tmp_path / "wave_probe" / "probe.csv").is_file()


@pytest.mark.parametrize("name", ["build_and_run", "step_sweep", "own_master", "read_results", "waves_statistics",
                                  "wave_probe"])
def test_examples_are_scripts(name):
    import subprocess
    import sys
    done = subprocess.run([sys.executable, str(ROOT / "examples" / f"{name}.py"), "--help"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and f"python examples/{name}.py" in done.stdout, done.stderr
