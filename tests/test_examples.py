"""The scripts of examples/ run (short stop times) and say what they should."""
import importlib.util

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


@pytest.mark.parametrize("name", ["build_and_run", "step_sweep", "own_master", "read_results", "wave_probe"])
def test_examples_are_scripts(name):
    import subprocess
    import sys
    done = subprocess.run([sys.executable, str(ROOT / "examples" / f"{name}.py"), "--help"],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0 and f"python examples/{name}.py" in done.stdout, done.stderr
