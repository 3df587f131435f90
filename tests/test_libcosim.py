"""libcosim (Open Simulation Platform) runs the same FMUs with the same results as our
fmpy master in Jacobi mode (libcosim's fixed-step algorithm is a Jacobi scheme)."""
import numpy as np
import pytest

from hydrofmu.cosim import libcosim, master

pytest.importorskip("libcosimpy")


def test_libcosim_equals_fmpy_jacobi(demo_build):
    kw = dict(stop=60.0, step=0.1)
    ours = master.run(demo_build, algorithm="jacobi", progress=False, **kw)
    theirs = libcosim.run(demo_build, algorithm="jacobi", **kw)
    assert theirs.columns == ours.columns
    np.testing.assert_array_equal(theirs.time, ours.time)
    moving = ours["barge_dynamics.position[1]"]
    assert np.ptp(moving) > 0.05  # the barge really moves
    np.testing.assert_allclose(theirs.values, ours.values, rtol=1e-9, atol=1e-9)


def test_osp_system_structure_runs_in_libcosim(demo_build):
    """The OspSystemStructure.xml written by the build is a valid libcosim configuration."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    log_output_level(CosimLogLevel.WARNING)
    execution = CosimExecution.from_osp_config_file(str(demo_build / "OspSystemStructure.xml"))
    assert execution.num_slaves() == 2
    assert execution.simulate_until(target_time=int(2e9))


def test_gauss_seidel_is_refused_not_switched(demo_build, capsys):
    """libcosim's master is Jacobi: a Gauss–Seidel run (the scene's default or asked for)
    is a clear error (exit 2, one line), not a Jacobi run under the wrong name."""
    from hydrofmu.cli import main
    from hydrofmu.errors import InputError
    for given in (None, "gauss-seidel"):
        with pytest.raises(InputError, match="Jacobi scheme"):
            libcosim.run(demo_build, stop=0.2, algorithm=given)
    code = main(["run", str(demo_build), "--engine", "libcosim", "--algorithm", "gauss-seidel", "--stop", "0.2"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: --algorithm: algorithm:") and "--algorithm jacobi" in err
    assert main(["run", str(demo_build), "--engine", "libcosim", "--algorithm", "jacobi", "--stop", "0.2"]) == 0


def test_libcosim_honours_the_scenes_outputs_and_interval(tmp_path):
    """A scene's [run] outputs and interval: libcosim records the same columns at the same
    times as our master (Jacobi: the same numbers), the CLI writes them the same way, and an
    ECCO run asked for an interval is refused naming the scene file and key."""
    from hydrofmu.cli import main
    from hydrofmu.errors import InputError
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    from conftest import MODELS
    scene = tmp_path / "thin.toml"
    scene.write_text((MODELS / "moored_barge.toml").read_text().replace('"decks/', f'"{MODELS}/decks/').replace(
        'substep = 0.02', 'substep = 0.02\noutputs = ["barge.position", "barge.force[1]"]\ninterval = 0.5'))
    built = build_scene(load_scene(scene), tmp_path / "fmus", log=lambda *_: None)
    ours = master.run(built, stop=20.0, algorithm="jacobi", progress=False)
    theirs = libcosim.run(built, stop=20.0, algorithm="jacobi")
    assert theirs.columns == ours.columns and len(ours.columns) == 4, ours.columns
    np.testing.assert_array_equal(theirs.time, np.arange(41) * 0.5)
    np.testing.assert_array_equal(theirs.time, ours.time)
    assert theirs.step == ours.step == 0.5
    assert np.ptp(ours["barge_dynamics.position[1]"]) > 0.01
    np.testing.assert_allclose(theirs.values, ours.values, rtol=1e-9, atol=1e-9)
    # the run's own outputs/interval win over the scene's, as in our master
    got = libcosim.run(built, stop=2.0, algorithm="jacobi", outputs=["barge_dynamics.position[3]"], interval=0.2)
    assert got.columns == ["barge_dynamics.position[3]"] and np.allclose(got.time, np.arange(11) * 0.2)
    # the CLI writes the same CSV layout from either engine
    for engine in ("fmpy", "libcosim"):
        assert main(["run", str(built), "--engine", engine, "--algorithm", "jacobi", "--stop", "2",
                     "--csv", str(tmp_path / f"{engine}.csv")]) == 0
    assert (tmp_path / "fmpy.csv").read_text().splitlines()[0] == (tmp_path / "libcosim.csv").read_text().splitlines()[0]
    assert len((tmp_path / "libcosim.csv").read_text().splitlines()) == 1 + 5
    # and the same Parquet file beside it (columns, units, rows: Jacobi in both masters)
    from hydrofmu.cosim.stream import read_parquet
    mine, theirs = read_parquet(tmp_path / "fmpy.parquet"), read_parquet(tmp_path / "libcosim.parquet")
    assert theirs.columns == mine.columns and theirs.units == mine.units and len(theirs) == 5
    assert theirs.manifest["scene"] == "moored_barge" and theirs.settings["algorithm"] == "jacobi"

    np.testing.assert_allclose(theirs.values, mine.values, rtol=1e-9, atol=1e-9)
    with pytest.raises(InputError, match=r"thin.toml.*run.interval.*ECCO chooses its own time points"):
        libcosim.run(built, stop=2.0, algorithm="ecco")
    with pytest.raises(InputError, match="interval: the output interval must be a whole number of steps"):
        libcosim.run(built, stop=2.0, algorithm="jacobi", interval=0.25)


def test_each_engine_writes_its_own_files(demo_build, tmp_path):
    """`hydrofmu run --engine libcosim` beside an fmpy run of the same build: its CSV, Parquet,
    PNG, summary and spectra are <folder>.libcosim.* and leave the fmpy run's <folder>.* alone."""
    import json
    import shutil
    from hydrofmu.cli import main
    from hydrofmu.cosim.result import read_csv
    folder = tmp_path / demo_build.name
    shutil.copytree(demo_build, folder)
    suffixes = (".csv", ".parquet", ".png", ".summary.json", ".spectra.csv", ".spectra.png")
    for suffix in suffixes:   # an fmpy run's files, as `hydrofmu run` left them
        folder.with_name(folder.name + suffix).write_text("the fmpy run's")
    assert main(["run", str(folder), "--engine", "libcosim", "--algorithm", "jacobi", "--stop", "2"]) == 0
    for suffix in suffixes:
        assert folder.with_name(folder.name + suffix).read_text() == "the fmpy run's", suffix
        assert folder.with_name(folder.name + ".libcosim" + suffix).stat().st_size > 0, suffix
    assert read_csv(folder.with_name(folder.name + ".libcosim.csv")).manifest["scene"] == "moored_barge"
    summary = json.loads(folder.with_name(folder.name + ".libcosim.summary.json").read_text())
    assert summary["points"] == 21 and "lf_std" in summary["bodies"]["barge"]["position"]["x"]
