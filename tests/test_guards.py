"""Issue 22 guards: runs, batches, BEM input and every CLI command refuse bad input with one
clear error (exit 2, file and field named, nothing written) or say suspicious data out loud."""
import pytest

from hydrofmu.names import closest, did_you_mean, unknown
from hydrofmu.scene import load_scene
from hydrofmu.errors import InputError


def test_closest_names_rank_by_similarity_ignoring_case():
    valid = ["current_speed", "current_direction", "rho", "g"]
    assert closest("current_sped", valid)[0] == "current_speed"
    assert closest("CURRENT_SPEED", valid)[0] == "current_speed"
    assert closest("xyz", valid) == []
    assert did_you_mean("rh", ["rho", "g"]) == " (did you mean 'rho'?)"
    assert did_you_mean("zzz", ["rho"]) == ""
    msg = unknown("column", "barge.forse[1]", [f"barge.force[{i}]" for i in range(1, 7)] + ["time"], show=3)
    assert msg.startswith("unknown column 'barge.forse[1]' (did you mean 'barge.force[1]'")
    assert "… (4 more)" in msg


def test_unknown_scene_key_suggests_the_closest(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text("[environment]\ncurrent_sped = 1.0\n[bodies.barge]\nmass = 1e6\ninertia = [1e8, 1e8, 1e8]\n")
    with pytest.raises(InputError) as err:
        load_scene(scene)
    assert err.value.field == "environment.current_sped"
    assert "did you mean 'current_speed'" in str(err.value)
    assert err.value.unknown == {"environment.current_sped": sorted(err.value.unknown["environment.current_sped"])}


# --- shared helpers for the rest ------------------------------------------------------

import contextlib
import io
import json
from pathlib import Path

import numpy as np

import hydrofmu
from hydrofmu import cli as cli_module
from hydrofmu import writable
from hydrofmu.batch import check_knobs, load_cases, run_batch
from hydrofmu.errors import InputWarning

from conftest import MODELS, ROOT, write_scene

BARGE = MODELS / "moored_barge.toml"   # step 0.1 s
SMALL = """
[run]
step = 0.1
stop = 1.0
[bodies.hull]
mass = 1.0e5
inertia = [1.0e6, 1.0e6, 1.0e6]
stiffness = [1e4, 1e4, 1e5, 1e6, 1e6, 1e4]
[[bodies.hull.effects]]
type = "aqwa_viscous_drag"
matrix = [1.0e3, -1.0, 1.0e3, 1.0, 1.0, 1.0]
"""


def cli(*args):
    """(exit code, the one error line or None, stderr) of the command line run in-process:
    never a traceback, never exit 3 ('internal error')."""
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = cli_module.main([str(a) for a in args])
    text = err.getvalue()
    errors = [line for line in text.splitlines() if line.startswith("error:")]
    assert "Traceback" not in text and "internal error" not in text and code != 3, text
    assert len(errors) <= 1, text
    return code, (errors[0] if errors else None), text


def files_under(folder):
    return sorted(p for p in folder.rglob("*") if p.is_file()) if folder.exists() else []


# --- runs: stop a whole number of steps -------------------------------------------------

@pytest.mark.parametrize("stop, words", [
    (0.05, "stop 0.05 s is shorter than one step (0.1 s)"),
    (1.05, "stop 1.05 s is not a whole number of steps of 0.1 s (10.5 steps): use stop 1 or 1.1 s"),
])
def test_run_stop_not_whole_steps_refused_before_anything_is_built(tmp_path, stop, words):
    code, line, _ = cli("run", BARGE, "-o", tmp_path / "out", "--stop", stop)
    assert code == 2 and "command line: --stop: " + words in line
    assert not (tmp_path / "out").exists()


def test_run_stop_rule_in_the_scene_the_api_and_the_masters(tmp_path, demo_build):
    bad = write_scene(tmp_path, SMALL.replace("stop = 1.0", "stop = 1.05"))
    with pytest.raises(InputError) as err:
        load_scene(bad)
    assert err.value.path == str(bad) and err.value.field == "run.stop" and "10.5 steps" in str(err.value)
    # ECCO's step is its first one: any stop
    load_scene(write_scene(tmp_path, SMALL.replace("stop = 1.0", 'stop = 1.05\nalgorithm = "ecco"'), "ecco.toml"))
    # the API: a scene file is refused before it is built, a built folder before it runs
    good = write_scene(tmp_path, SMALL, "good.toml")
    with pytest.raises(InputError, match=r"run: stop: stop 0.05 s is shorter than one step"):
        hydrofmu.run(good, stop=0.05, out=tmp_path / "api")
    assert not (tmp_path / "api").exists()
    from hydrofmu.cosim import libcosim, master
    for run in (hydrofmu.run, master.run, lambda f, **kw: libcosim.run(f, algorithm="jacobi", **kw)):
        with pytest.raises(InputError, match=r"stop: stop 1.05 s is not a whole number of steps of 0.1 s"):
            run(demo_build, stop=1.05)
    code, line, _ = cli("run", demo_build, "--stop", "0.3", "--step", "0.2", "--csv", tmp_path / "r.csv")
    assert code == 2 and "--stop: stop 0.3 s is not a whole number of steps of 0.2 s" in line
    assert not (tmp_path / "r.csv").exists()
    # 0.3 / 0.1 is 2.9999999999999996 in floating point: a whole number of steps
    assert master.check_steps(0.3, 0.1, "jacobi", "run") == 3
    # more steps than memory holds: refused, not a MemoryError after the build
    code, line, _ = cli("run", BARGE, "-o", tmp_path / "o", "--step", "1e-300")
    assert code == 2 and "--step: 6e+302 steps of 1e-300 s to 600 s: more than 1e+08" in line


def test_run_record_and_parameters_names_suggest_the_closest(demo_build):
    with pytest.raises(InputError, match=r"algorithm: unknown algorithm 'jacoby' \(did you mean 'jacobi'"):
        hydrofmu.run(demo_build, stop=0.2, algorithm="jacoby")
    with pytest.raises(InputError, match=r"record: unknown 'instance.variable' 'barge.forse\[1\]' "
                                         r"\(did you mean 'barge.force\[1\]'"):
        hydrofmu.run(demo_build, stop=0.2, record=["barge.forse[1]"])
    with pytest.raises(InputError, match=r"parameters: unknown parameter or unconnected input 'barge.rhoo' "
                                         r"\(did you mean 'barge.rho'"):
        hydrofmu.run(demo_build, stop=0.2, parameters={"barge.rhoo": 1000.0})


# --- runs: outputs writable first, results kept after --------------------------------

def test_outputs_checked_writable_before_the_run(tmp_path, demo_build, monkeypatch):
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    cases = [
        (["--csv", tmp_path / "none" / "r.csv"], "r.csv: output file: folder", "does not exist"),
        (["--csv", tmp_path], f"{tmp_path}: output file: is a folder, not a file", ""),
        (["--png", afile / "r.png"], "r.png: output file:", "afile is a file, not a folder"),
    ]
    for args, words, more in cases:
        code, line, _ = cli("run", demo_build, "--stop", "0.2", *args)
        assert code == 2 and words in line and more in line
    code, line, _ = cli("run", BARGE, "--stop", "0.2", "-o", afile)
    assert code == 2 and "afile: output folder: is a file, not a folder" in line
    # no permission (as root every folder takes files: the probe's answer is forced)
    locked = tmp_path / "locked"
    locked.mkdir()
    real = writable._probe
    monkeypatch.setattr(writable, "_probe", lambda f: "Permission denied" if f == locked else real(f))
    code, line, _ = cli("run", demo_build, "--stop", "0.2", "--csv", locked / "r.csv", "--png", tmp_path / "r.png")
    assert code == 2 and "r.csv: output file: cannot write in folder" in line and "Permission denied" in line
    assert afile.read_text() == "keep me" and files_under(locked) == [] and not (tmp_path / "r.png").exists()


def test_a_write_failing_after_the_run_keeps_the_results(tmp_path, demo_build, monkeypatch):
    """The CSV, streamed during the run, cannot be put in its folder after it (the folder
    filled up): it goes to the current folder, the warning says where, the exit code is 1
    (not where asked), never 3."""
    from hydrofmu.cosim import stream
    asked = tmp_path / "out" / "r.csv"
    asked.parent.mkdir()
    real = stream._move

    def full(part, target):
        if Path(target) == asked:
            raise OSError(28, "No space left on device", str(target))
        return real(part, target)
    monkeypatch.setattr(stream, "_move", full)
    here = tmp_path / "here"
    here.mkdir()
    monkeypatch.chdir(here)
    code, line, err = cli("run", demo_build, "--stop", "0.2", "--csv", asked, "--png", tmp_path / "r.png")
    assert code == 1 and line is None
    assert f"warning: cannot write {asked} (No space left on device); wrote {here / 'r.csv'} instead" in err
    rows = (here / "r.csv").read_text().splitlines()
    assert len(rows) == 4 and rows[0].startswith("time [s],") and (tmp_path / "r.png").is_file()


# --- batches: every knob checked against the scene first ----------------------------

def cases_file(folder, body, scene=BARGE, stop=1.0):
    path = Path(folder) / "cases.toml"
    path.write_text(f'scene = "{scene}"\nstop = {stop}\noutputs = ["barge.force[1]"]\n{body}')
    return path


@pytest.mark.parametrize("body, field, words", [
    ('[matrix]\n"environment.current_sped" = [0.5, 1.0]\n', "environment.current_sped",
     "unknown knob: moored_barge.toml has no key environment.current_sped (did you mean 'environment.current_speed'"),
    ('[matrix]\n"bodies.bargee.mass" = [1.0e6]\n', "bodies.bargee.mass",
     "not in scene moored_barge.toml: bodies has no table 'bargee' (did you mean 'bodies.barge'?)"),
    ('[set]\n"run.stop" = 2.0\n', "set.run.stop", "given twice: also stop (top level)"),
    ('[set]\nrun.step = 0.2\n"run.step" = 0.1\n', "set.run.step", "given twice: also set.run.step"),
    ('[set]\n"run.algorithm" = "jacobi"\n[matrix]\nalgorithm = ["jacobi"]\n', "matrix.algorithm",
     "given twice: also set.run.algorithm"),
    ('[matrix]\n"run.step" = [0.1, 0.3]\n', "run.stop", "stop 1 s is not a whole number of steps of 0.3 s"),
    ('[[cases]]\nstop = 0.05\n', "run.stop", "stop 0.05 s is shorter than one step (0.1 s)"),
])
def test_batch_knobs_checked_before_any_case(tmp_path, body, field, words):
    path = cases_file(tmp_path, body)
    with pytest.raises(InputError) as err:
        check_knobs(load_cases(path))
    assert err.value.path == str(path) and err.value.field == field and words in err.value.message
    code, line, _ = cli("batch", path, "-o", tmp_path / "out")
    assert code == 2 and line == f"error: {err.value}" and not (tmp_path / "out").exists()


def test_batch_names_of_a_built_scene(tmp_path, demo_build):
    """Outputs and instance variables against the FMUs (a built folder: nothing to build),
    and one FMU variable given under two spellings."""
    for body, outputs, field, words in [
        ("", '["barge.forse[1]"]', "outputs", "unknown output 'barge.forse[1]' (did you mean 'barge.force[1]'"),
        ('[matrix]\n"barge.rhoo" = [1000.0]\n', '["barge.force[1]"]', "barge.rhoo",
         "unknown parameter or unconnected input 'barge.rhoo' (did you mean 'barge.rho'"),
        ('[set]\n"environment.rho" = 1000.0\n"barge.rho" = 1000.0\n', '["barge.force[1]"]', "barge.rho",
         "given twice: environment.rho sets rho of every FMU, barge.rho too"),
        ('[set]\n"run.substep" = 0.01\n', '["barge.force[1]"]', "run.substep",
         "a built folder runs with stop, step and algorithm only"),
    ]:
        path = tmp_path / "cases.toml"
        path.write_text(f'scene = "{demo_build}"\nstop = 0.2\noutputs = {outputs}\n{body}')
        with pytest.raises(InputError) as err:
            run_batch(path, tmp_path / "out", progress=False)
        assert err.value.path == str(path) and err.value.field == field and words in err.value.message
        assert not (tmp_path / "out").exists()


# --- BEM input: refused or said out loud -----------------------------------------------

xr = pytest.importorskip("xarray")
CYL = ROOT / "tests" / "data" / "bem" / "cylinders.nc"
TWO = """
[run]
step = 0.05
stop = 1.0
[bodies.a]
position = [0.0, -4.0, 0.0]
mass = 5.0e4
inertia = [2.0e5, 2.0e5, 1.0e5]
[bodies.b]
position = [0.0, 4.0, 0.0]
mass = 5.0e4
inertia = [2.0e5, 2.0e5, 1.0e5]
[[couplings]]
bem = "{path}"
bodies = {bodies}
{extra}
"""


def dataset(tmp_path, change, name="v.nc"):
    ds = change(xr.load_dataset(CYL))
    ds.to_netcdf(tmp_path / name)
    return tmp_path / name


def bem_scene(tmp_path, path=CYL, bodies='{ cyl1 = "a", cyl2 = "b" }', extra="", name="bem.toml"):
    return write_scene(tmp_path, TWO.format(path=path, bodies=bodies, extra=extra), name)


def scene_error(path):
    with pytest.raises(InputError) as err:
        load_scene(path)
    return str(err.value)


def test_bem_datasets_refused_with_file_and_field(tmp_path):
    from hydrofmu.decks.bem import read_capytaine
    # two dataset bodies mapped to one scene body
    msg = scene_error(bem_scene(tmp_path, bodies='{ cyl1 = "a", cyl2 = "a" }'))
    assert "couplings[0].bodies: expected a table BEM body = scene body (distinct)" in msg
    # rotation centres given for bodies the dofs do not name: they would go unchecked
    path = dataset(tmp_path, lambda ds: ds.assign_coords(body=["hull1", "hull2"]), "renamed.nc")
    with pytest.raises(InputError) as err:
        read_capytaine(path)
    assert (err.value.path, err.value.field) == (str(path), "rotation_center")
    assert "given for bodies hull1, hull2 but the dofs name bodies cyl1, cyl2" in err.value.message
    # two ω = ∞ rows
    def two_inf(ds):
        return xr.concat([ds, ds.sel(omega=[np.inf])], dim="omega")
    path = dataset(tmp_path, two_inf, "inf.nc")
    with pytest.raises(InputError, match=r"inf.nc: omega: 2 rows at ω = inf"):
        read_capytaine(path)
    # a negative frequency (dropped without a word before)
    path = dataset(tmp_path, lambda ds: ds.assign_coords(omega=np.where(ds.omega == ds.omega[3], -ds.omega[3],
                                                                         ds.omega)), "neg.nc")
    with pytest.raises(InputError, match=r"neg.nc: omega: negative frequency -"):
        read_capytaine(path)
    # a value that is not a number
    def text(ds):
        ds["rho"] = xr.DataArray("sea water")
        return ds
    path = dataset(tmp_path, text, "text.nc")
    with pytest.raises(InputError, match=r"text.nc: rho: not a number: 'sea water'"):
        read_capytaine(path)


def test_bem_warnings_in_the_scene_the_build_and_the_manifest(tmp_path):
    path = dataset(tmp_path, lambda ds: ds.drop_vars(["rho", "g"]), "norho.nc")
    with pytest.warns(InputWarning) as said:
        scene = load_scene(bem_scene(tmp_path, path, bodies='{ cyl1 = "a" }', extra="kernel_length = 0.1"))
    text = "\n".join(str(w.message) for w in said)
    assert scene.warnings == list(dict.fromkeys(str(w.message) for w in said))
    assert f"couplings[0].bodies: {path} has bodies cyl2 not mapped to scene bodies" in text
    assert f"couplings[0].bem: {path}: rho, g not in the dataset" in text
    assert "radiation_damping[a__Heave, a__Heave] is negative at" in text   # the cylinders' heave at high ω
    assert "kernel length 0.1" in text and "TIMDEL" in text and "the memory is cut after" in text
    # the manifest keeps what the build said
    from hydrofmu.fmi.build import build_scene
    with pytest.warns(InputWarning):
        folder = build_scene(load_scene(write_scene(tmp_path, SMALL, "small.toml")), tmp_path / "fmus",
                             log=lambda *_: None)
    manifest = json.loads((folder / "manifest.json").read_text())
    said = manifest["warnings"]
    assert len(said) == 1 and "small.toml: bodies.hull.effects[0].matrix[2,2]: negative diagonal drag" in said[0]
    assert manifest["warning_count"] == 1


def test_each_warning_is_said_once_per_command(tmp_path, monkeypatch):
    """A command that reads the scene many times (tune: once per candidate; batch: per variant)
    says each warning once; a run that reuses the build says the build's warnings again, once."""
    path = write_scene(tmp_path, SMALL, "small.toml")
    from hydrofmu.scene import load_scene as real_load
    import hydrofmu.scene as scene_module
    calls = []

    def load_three_times(*args, **kw):   # as tune and batch do: the same scene read again and again
        calls.append(1)
        for _ in range(2):
            real_load(*args, **kw)
        return real_load(*args, **kw)

    monkeypatch.setattr(scene_module, "load_scene", load_three_times)
    code, line, text = cli("run", path, "-o", tmp_path / "out", "--stop", "0.2")
    assert code == 0 and calls and text.count("negative diagonal drag") == 1, text
    code, line, text = cli("run", path, "-o", tmp_path / "out", "--stop", "0.2")   # reused: said from the manifest
    assert code == 0 and text.count("negative diagonal drag") == 1 and text.count("warning:") == 1, text


def wamit(tmp_path, rows, name="w.1"):
    (tmp_path / name).write_text("".join(f"{r}\n" for r in rows))
    return tmp_path / name


def test_wamit_truncated_refused_missing_pairs_said(tmp_path):
    from hydrofmu.decks.bem import read_wamit
    full = [f"{per} {i} {i} 1.0 0.5" for per in (10.0, 5.0, 2.0) for i in (1, 3)]
    d = read_wamit(wamit(tmp_path, full), 1.0, 1025.0)
    assert d.warnings == [f"{tmp_path / 'w.1'}: 2 pair(s) of its dofs missing at every period, read as zeros: "
                          "(1, 3), (3, 1)"]
    with pytest.raises(InputError) as err:   # the last period cut short
        read_wamit(wamit(tmp_path, full[:5], "cut.1"), 1.0, 1025.0)
    assert (err.value.path, err.value.line, err.value.field) == (str(tmp_path / "cut.1"), 5, "I J")
    assert "1 pair(s) given at other periods are missing at period 2 s, first (3, 3)" in err.value.message
    # the infinite-frequency rows (PER = 0) must hold every pair too
    with pytest.raises(InputError, match=r"missing at the infinite-frequency rows \(PER = 0\), first \(3, 3\)"):
        read_wamit(wamit(tmp_path, ["0 1 1 2.0"] + full, "inf.1"), 1.0, 1025.0)


# --- every command, plain bad input: exit 2, one line naming the file and the field ----------

def test_bem2simo_options_and_outputs(tmp_path):
    afile = tmp_path / "afile"
    afile.write_text("keep me")
    out = tmp_path / "x.sim"
    for args, words in [
        (["--symmetry-tolerance", "nan"], "command line: --symmetry-tolerance: must be a positive finite number, found nan"),
        (["--kernel-length", "0"], "command line: --kernel-length: must be a positive finite number, found 0"),
        (["--timdel", "-0.1"], "command line: --timdel: must be a positive finite number, found -0.1"),
        (["--kernel-length", "1e9"], "cylinders.nc: kernel_length: 1.91e+10 kernel samples"),   # not a MemoryError
    ]:
        code, line, _ = cli("bem2simo", CYL, "-o", out, *args)
        assert code == 2 and words in line and not out.exists()
    for target, words in [(afile / "x.sim", "x.sim: output file:"), (tmp_path / "no" / "x.sim", "does not exist"),
                          (tmp_path, "output file: is a folder")]:
        code, line, _ = cli("bem2simo", CYL, "-o", target)
        assert code == 2 and words in line
    code, line, _ = cli("bem2simo", CYL, "-o", out, "--png", afile / "q.png")
    assert code == 2 and "q.png: output file:" in line and not out.exists()
    # what the transform's report says out loud, in bem2simo's report too
    printed = io.StringIO()
    with contextlib.redirect_stdout(printed):
        assert cli_module.main(["bem2simo", str(CYL), "-o", str(out), "--kernel-length", "30"]) == 0
    assert out.is_file() and "  WARNING: " in printed.getvalue()
    assert "radiation_damping[cyl1__Heave, cyl1__Heave] is negative" in printed.getvalue()
    out.unlink()
    # the API guards the same options
    from hydrofmu.bem import couplings
    from hydrofmu.decks.bem import read_bem
    with pytest.raises(InputError, match=r"cylinders.nc: symmetry_tolerance: must be a positive finite number"):
        couplings(read_bem(CYL), {"cyl1": "cyl1"}, symmetry_tol=float("nan"))
    assert afile.read_text() == "keep me"


def test_every_command_refuses_plain_bad_input(tmp_path, monkeypatch):
    """A table of ordinary slips, one or more per command: each ends in exit 2 and one
    error line naming the file (or the command line) and the field, never exit 3."""
    monkeypatch.chdir(tmp_path)
    # no models/ here, nor a repository's to fall back on (test_newcomer: the fallback)
    monkeypatch.setattr(cli_module, "REPO_MODELS", tmp_path / "no_repository" / "models")
    afile = tmp_path / "afile"
    afile.write_text("x")
    junk = tmp_path / "junk.fmu"
    junk.write_text("not a zip")
    (tmp_path / "bad.toml").write_text("[bodies\n")
    (tmp_path / "empty").mkdir()
    scene = write_scene(tmp_path, SMALL, "small.toml")
    cases = cases_file(tmp_path, '[matrix]\n"environment.current_sped" = [1.0]\n')
    table = [
        (["build", tmp_path / "none.toml"], "none.toml: file: cannot read scene"),
        (["build", tmp_path / "bad.toml"], "bad.toml:1: toml:"),
        (["build", scene, "-o", afile], "afile: output folder: is a file, not a folder"),
        (["build"], "models: scenes: no scene files (*.toml) here"),
        (["run", tmp_path / "none.toml"], "none.toml: file: cannot read scene"),
        (["run", scene, "--stop", "1.05", "-o", tmp_path / "o"], "--stop: stop 1.05 s is not a whole number of steps"),
        (["run", scene, "--png", tmp_path / "empty"], "empty: output file: is a folder"),
        (["run", tmp_path / "empty"], "empty: scene: not a scene .toml nor a built scene folder"),
        (["batch", tmp_path / "none.toml"], "none.toml: file: cannot read case file"),
        (["batch", tmp_path / "bad.toml"], "bad.toml:1: toml:"),
        (["batch", cases, "-o", afile], "afile: output folder: is a file, not a folder"),
        (["batch", cases, "-o", tmp_path / "b"], "cases.toml: environment.current_sped: unknown knob"),
        (["batch", cases, "--workers", "0"], "--workers: expected a positive whole number"),
        (["validate", tmp_path / "none.fmu"], "none.fmu: path: no such FMU or folder"),
        (["validate", junk], "junk.fmu: FMU: not an FMU (an FMU is a zip archive)"),
        (["validate", tmp_path / "empty"], "empty: path: no FMU (*.fmu) in the folder"),
        (["bem2simo", tmp_path / "none.nc", "-o", tmp_path / "x.sim"], "none.nc: bem: cannot read"),
        (["bem2simo", junk, "-o", tmp_path / "x.sim"], "junk.fmu: bem: expected a Capytaine NetCDF dataset"),
        (["bem2simo", tmp_path / "none.1", "-o", tmp_path / "x.sim"], "none.1: ulen:"),
        (["bench", "-o", afile, "--part", "overhead"], "afile: output folder: is a file, not a folder"),
        (["demo", "-o", tmp_path / "d"], "models: scenes: no scene files (*.toml) here"),
    ]
    for args, words in table:
        code, line, _ = cli(*args)
        assert code == 2 and line is not None and words in line, (args, line)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "bad.toml", "cases.toml", "empty", "junk.fmu",
                                                         "small.toml"]
    # demo: a scene name that is not in models/ (with the closest), before anything is built
    monkeypatch.chdir(ROOT)
    code, line, _ = cli("demo", "-o", tmp_path / "d", "--scene", "moored_barg")
    assert code == 2 and "--scene: no scene 'moored_barg' in models/ (did you mean 'moored_barge'" in line
    assert not (tmp_path / "d").exists()


def test_batch_results_kept_when_its_folder_refuses_them(tmp_path, demo_build, monkeypatch):
    """cases/ stops taking files mid-batch: the rows are kept for the table, one warning says so."""
    distributed = pytest.importorskip("distributed")
    from hydrofmu import batch as batch_module

    def full(path, obj):
        raise OSError(28, "No space left on device", str(path))
    monkeypatch.setattr(batch_module, "_write_json", full)
    path = tmp_path / "cases.toml"
    path.write_text(f'scene = "{demo_build}"\nstop = 0.2\noutputs = ["barge.force[1]"]\n'
                    '[matrix]\n"environment.current_speed" = [0.5, 1.0]\n')
    said = []
    with distributed.Client(processes=False, n_workers=1, threads_per_worker=1, dashboard_address=":0") as client:
        table = run_batch(path, tmp_path / "out", client=client, progress=False, log=said.append)
    assert list(table["status"]) == ["ok", "ok"] and table["barge.force[1].max"].notna().all()
    assert len(said) == 1 and said[0].startswith(f"warning: cannot write in {tmp_path / 'out'} (No space left")
    assert table.attrs["written"][tmp_path / "out" / "cases.csv"] == tmp_path / "out" / "cases.csv"


def test_two_deck_bodies_mapped_to_one_scene_body(tmp_path):
    deck = ROOT / "tests" / "data" / "simo" / "two_barges.sys"
    path = write_scene(tmp_path, f"""
        [bodies.a]
        mass = 1.0e6
        inertia = [1.0e8, 1.0e8, 1.0e8]
        [[couplings]]
        deck = "{deck}"
        coupling = "cpl12"
        bodies = {{ barge1 = "a", barge2 = "a" }}
        """)
    assert "couplings[0].bodies: SIMO bodies barge1, barge2 are all mapped to scene body 'a'" in scene_error(path)


def test_a_broken_build_folder_is_named_not_an_internal_error(tmp_path, demo_build):
    import shutil
    folder = tmp_path / "copy"
    shutil.copytree(demo_build, folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    for text, words in [("{", "manifest.json:1: json: not a manifest"),
                        (json.dumps({**manifest, "run": {"step": 0.1}}), "manifest.json: run.stop: missing"),
                        (json.dumps({**manifest, "order": manifest["order"] + ["ghost"]}),
                         "manifest.json: instances.ghost.fmu: None is not in the folder")]:
        (folder / "manifest.json").write_text(text)
        code, line, _ = cli("run", folder, "--csv", tmp_path / "r.csv")
        assert code == 2 and words in line and not (tmp_path / "r.csv").exists()
        with pytest.raises(InputError, match=words.split(": ", 1)[1]):
            hydrofmu.run(folder)


def test_one_mismatch_is_stated_once_with_plain_numbers(tmp_path):
    """The buoy of models/ 1 m below the rotation centre of its BEM file, which a coupling and
    two effects read: one statement of that mismatch (not one per reader, nor the centre of
    mass that moved with it), numbers printed as numbers (no np.float64 reprs)."""
    text = (MODELS / "buoy_in_waves.toml").read_text().replace(
        '"decks/buoy.nc"', f'"{(MODELS / "decks" / "buoy.nc").as_posix()}"').replace(
        "position = [0.0, 0.0, 0.0]", "position = [0.0, 0.0, -1.0]")
    path = write_scene(tmp_path, text, "moved.toml")
    code, line, _ = cli("build", "--check", path)
    assert code == 2 and line.count("rotation_center") == 1 and line.count("; ") == 0, line
    assert "np.float64" not in line and "center_of_mass" not in line
    assert "rotation_center[buoy]: [0, 0, 0] m in the file but the reference point of scene body 'buoy' is at " \
           "[0, 0, -1] m (bodies.buoy.position)" in line
    assert len(line) < 400, len(line)
