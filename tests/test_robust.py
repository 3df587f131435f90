"""Robustness: linear-time error paths of the deck readers, the admissibility checks, the
CLI's one-line errors (tests/test_fuzz_inputs.py mutates every input at random)."""
import re

import numpy as np
import pytest

from hydrofmu import admissible
from hydrofmu.bench.robust import deck_error_time, spoil_near_end, write_big_deck
from hydrofmu.decks.simo import read_couplings
from hydrofmu.errors import InputError


def test_bad_number_near_the_end_of_a_big_deck_is_reported_in_linear_time(tmp_path):
    """5 MB here (the 50 MB figure is `hydrofmu bench --part errors`): the error costs
    about what reading the good deck costs, and names the physical line and the sample."""
    r = deck_error_time(tmp_path, megabytes=5.0)
    assert r["megabytes"] > 4.5
    assert f"bad_big.sys:{r['bad_line']}:" in str(r["error"]) and "RETij(" in str(r["error"])
    assert r["ratio"] < 3.0, r      # the quadratic locator took > 100× at this size


@pytest.mark.parametrize("bad", ["nan", "inf", "-1e400", "1.0x-02"])
def test_kernel_value_names_its_physical_line(tmp_path, bad):
    good = write_big_deck(tmp_path / "d.sys", 0.05)
    path, line = spoil_near_end(good, bad)
    with pytest.raises(InputError) as err:
        read_couplings(path, {"A"})
    assert err.value.line == line and err.value.field.startswith("RETij(")


# -- admissibility: one kernel, checked against hand computations ----------------------
def test_self_added_mass_symmetry_is_unit_consistent():
    """The issue's case: AM12 = 5e5 against AM21 = 0 passed a test relative to the
    largest entry (1.2e10, rotational). √(AM11·AM22) = √(1.3e6·1e7) = 3.6e6: allowed 3.6e3."""
    am = np.diag([1.3e6, 1.0e7, 2.0e7, 3.0e8, 1.2e10, 6.0e9])
    am[0, 1] = 5e5
    (field, message), = admissible.symmetric(am, lambda i, j: f"AM{i + 1}{j + 1}")
    assert field == "AM12" and "AM12 = 500000 but AM21 = 0" in message and "3605.55" in message
    am[1, 0] = 5e5 + 0.9e-3 * np.sqrt(1.3e6 * 1.0e7)      # within tol·√(A11·A22)
    assert admissible.symmetric(am, str) == []


@pytest.mark.parametrize("inertia, words", [
    (np.diag([1.0, 2.0, 5.0]), "triangle inequality"),   # 5 > 1 + 2
    (np.diag([1.0, -1.0, 1.0]), "positive definite"),
    ([[1.0, 0.5, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], "symmetric"),
])
def test_bad_inertia(inertia, words):
    (field, message), = admissible.inertia(inertia)
    assert field.startswith("inertia") and words in message


def test_good_inertia_flat_plate_and_rotated_body():
    assert admissible.inertia(np.diag([1e8, 2e8, 3e8])) == []          # flat plate: equality
    r = np.linalg.qr(np.random.default_rng(1).normal(size=(3, 3)))[0]
    assert admissible.inertia(r @ np.diag([7.74e8, 1.078e10, 1.134e10]) @ r.T) == []


def test_pose_near_gimbal_lock():
    assert admissible.attitude([0.0, np.radians(89.9), 0.0]) == []
    (field, message), = admissible.attitude([0.0, np.pi / 2, 0.0])
    assert field == "attitude" and "singularity" in message


# -- every reader and the scene: same text rules, finite numbers -----------------------
from conftest import ROOT, write_scene                        # noqa: E402
from hydrofmu.decks.aqwa import read_viscous_drag             # noqa: E402
from hydrofmu.decks.deeplines import read_current_polars      # noqa: E402
from hydrofmu.decks.riflex import read_components             # noqa: E402
from hydrofmu.errors import InputWarning                      # noqa: E402
from hydrofmu.scene import load_scene                         # noqa: E402

DATA = ROOT / "tests" / "data"
READERS = {  # reader, a deck of tests/data, a number in it to spoil
    "aqwa": (read_viscous_drag, DATA / "aqwa" / "viscous_drag_manual.dat", "2.2E5"),
    "deeplines": (read_current_polars, DATA / "deeplines" / "currentpol_manual.dat", None),
    "riflex": (read_components, DATA / "riflex" / "body_manual.inp", "120.0"),
    "simo": (lambda p: read_couplings(p, {"barge1"}), DATA / "simo" / "two_barges.sys", "4.0e5"),
}


def _same(a, b):
    a, b = (a.keys(), b.keys()) if isinstance(a, dict) else (a, b)
    return list(a) == list(b)


@pytest.mark.parametrize("kind", READERS)
def test_bom_and_crlf_read_like_the_plain_file(tmp_path, kind):
    reader, deck, _ = READERS[kind]
    plain = reader(deck)
    raw = deck.read_bytes()
    for name, data in (("bom", b"\xef\xbb\xbf" + raw), ("crlf", raw.replace(b"\n", b"\r\n")),
                       ("both", b"\xef\xbb\xbf" + raw.replace(b"\n", b"\r\n"))):
        path = tmp_path / f"{name}{deck.suffix}"
        path.write_bytes(data)
        assert _same(reader(path), plain), name     # RIFLEX dropped the first component behind a BOM


@pytest.mark.parametrize("kind", list(READERS) + ["scene"])
def test_not_utf8_is_one_error_naming_line_and_column(tmp_path, kind):
    if kind == "scene":
        reader, raw = load_scene, b'[bodies.b]\nmass = 1.0\n# caf\xe9\n'
    else:
        reader, deck, _ = READERS[kind]
        raw = deck.read_bytes().replace(b"\n", b"\n' caf\xe9 \n", 1)
    path = tmp_path / "latin1.txt"
    path.write_bytes(raw)
    with pytest.raises(InputError) as err:
        reader(path)
    assert err.value.line == (3 if kind == "scene" else 2) and err.value.field == "encoding"
    assert "not UTF-8" in str(err.value) and "0xe9" in str(err.value)


@pytest.mark.parametrize("kind", ["aqwa", "riflex", "simo"])
@pytest.mark.parametrize("bad", ["NaN", "inf", "-Infinity", "1e400"])
def test_non_finite_numbers_are_refused_where_read(tmp_path, kind, bad):
    reader, deck, number = READERS[kind]
    text = deck.read_text()
    line = text[:text.index(number)].count("\n") + 1
    path = tmp_path / f"bad{deck.suffix}"
    path.write_text(text.replace(number, bad, 1))
    with pytest.raises(InputError) as err:
        reader(path)
    assert err.value.line == line and "finite" in str(err.value)


def test_deeplines_non_finite(tmp_path):
    path = tmp_path / "p.dat"
    path.write_text("*CURRENTPOL,NAME=S\n0 0 0 10\n0 1 0 0\n180 nan 0 0\n")
    with pytest.raises(InputError, match=r"p.dat:4: CXC\(2\): expected a finite number"):
        read_current_polars(path)


def test_aqwa_empty_comma_field_is_an_error(tmp_path):
    """Seven comma-separated fields with one empty were read as six numbers."""
    path = tmp_path / "v.dat"
    path.write_text("*Viscous Drag\nFLOATING BODY=B\n" + "1, 0,, 0, 0, 0, 0\n" + "0, 1, 0, 0, 0, 0\n" * 5)
    with pytest.raises(InputError, match=r"v.dat:3: V13: empty field"):
        read_viscous_drag(path)


def test_negative_drag_diagonal_warns_with_line(tmp_path):
    path = tmp_path / "v.dat"
    rows = [["0"] * 6 for _ in range(6)]
    for k in range(6):
        rows[k][k] = "1.0"
    rows[2][2] = "-5.0"
    path.write_text("*Viscous Drag\nFLOATING BODY=B\n" + "".join(", ".join(r) + "\n" for r in rows))
    with pytest.warns(InputWarning, match=r"v.dat:5: V33: .*negative diagonal drag coefficient -5"):
        read_viscous_drag(path)


SCENE = """
[bodies.barge]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
"""


def test_inline_negative_drag_warns_with_key_path(tmp_path):
    path = write_scene(tmp_path, SCENE + """
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
matrix = [1.0, -2.0, 1.0, 1.0, 1.0, 1.0]
""")
    with pytest.warns(InputWarning, match=r"bodies.barge.effects\[0\].matrix\[2,2\]: negative"):
        load_scene(path)


@pytest.mark.parametrize("body, key, words", [
    ("inertia = [1.0, 2.0, 5.0]", "bodies.barge.inertia", "triangle inequality"),
    ("inertia = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, -1.0]]", "bodies.barge.inertia", "positive definite"),
    ("inertia = [[1.0, 0.1, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]", "bodies.barge.inertia[1,2]", "symmetric"),
    ("inertia = [1.0, 1.0, 1.0]\nattitude = [0.0, 1.5707963267948966, 0.0]", "bodies.barge.attitude", "singularity"),
    ("inertia = [1.0, 1.0, 1.0]\nmass = nan", "bodies.barge.mass", "finite"),
])
def test_scene_mass_properties_checked_at_build_time(tmp_path, body, key, words):
    path = write_scene(tmp_path, "[bodies.barge]\nmass = 1.0\n".replace("mass = 1.0\n", "" if "mass" in body
                                                                        else "mass = 1.0\n") + body + "\n")
    with pytest.raises(InputError) as err:
        load_scene(path)
    assert err.value.field == key and words in str(err.value)


def test_scene_errors_name_each_key_path_once(tmp_path):
    path = write_scene(tmp_path, "[environment]\ncurent_speed = 1.0\n" + SCENE)
    with pytest.raises(InputError) as err:
        load_scene(path)
    assert str(err.value).count("environment.curent_speed") == 1


def test_deck_error_reported_once_per_scene(tmp_path):
    """A RIFLEX deck used by a body effect and a joint: its error once, not once per use."""
    deck = tmp_path / "d.inp"
    deck.write_text("NEW COMPONENT BODY\nclump\n1.0 1.0\nGLOBAL NaN 0 0 0 0 0\n"
                    "NEW COMPONENT CONB\nhitch\n1.0 0.0\nLOCAL 0 0 0 0 0 0\n")
    path = write_scene(tmp_path, SCENE + """
[[bodies.barge.effects]]
type = "riflex_body"
deck = "d.inp"
component = "clump"
offset = [0.0, 0.0, 0.0]
[joints.j]
a = "barge"
a_point = [1.0, 0.0, 0.0]
deck = "d.inp"
component = "hitch"
""")
    with pytest.raises(InputError) as err:
        load_scene(path)
    assert str(err.value).count("d.inp:4: CDX: expected a finite number") == 1


# -- the CLI: one error line, exit 2 (bad input) or 1 (a failed run), nothing left behind --
import contextlib  # noqa: E402
import io          # noqa: E402

from hydrofmu.cli import main  # noqa: E402

DRAG = """
[run]
step = 1.0
stop = 50.0
[bodies.hull]
mass = 1.0
inertia = [1.0, 1.0, 1.0]
velocity = [100.0, 0.0, 0.0, 0.0, 0.0, 0.0]
[[bodies.hull.effects]]
type = "aqwa_viscous_drag"
matrix = [1.0e4, 1.0, 1.0, 1.0, 1.0, 1.0]
"""


def cli(*args):
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    errors = [line for line in err.getvalue().splitlines() if line.startswith("error:")]
    assert "Traceback" not in err.getvalue()
    assert len(errors) == (code != 0) and (code == 0 or err.getvalue().splitlines()[-1] == errors[0])
    return code, errors[0] if errors else None


def test_cli_output_at_a_file(tmp_path):
    target = tmp_path / "afile"
    target.write_text("keep me")
    code, line = cli("build", ROOT / "models" / "moored_barge.toml", "-o", target)
    assert code == 2 and "afile: output folder: is a file" in line and target.read_text() == "keep me"


def test_cli_reserved_dynamics_name_leaves_no_folder(tmp_path):
    path = write_scene(tmp_path, SCENE + SCENE.replace("barge", "barge_dynamics"))
    code, line = cli("build", path, "-o", tmp_path / "new" / "out")
    assert code == 2 and "bodies.barge_dynamics: body names ending in '_dynamics' are reserved" in line
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("args, words", [
    (["--step", "0"], "--step: must be a positive finite number, found 0"),
    (["--step", "-0.1"], "--step: must be a positive finite number"),
    (["--stop", "nan"], "--stop: must be a positive finite number"),
])
def test_cli_bad_run_arguments_before_anything_is_built(tmp_path, args, words):
    code, line = cli("run", ROOT / "models" / "moored_barge.toml", "-o", tmp_path / "out", *args)
    assert code == 2 and words in line and not (tmp_path / "out").exists()


def test_cli_run_missing_folder(tmp_path):
    code, line = cli("run", tmp_path / "nowhere")
    assert code == 2 and "nowhere: scene: not a scene .toml nor a built scene folder" in line
    code, line = cli("validate", tmp_path / "nowhere.fmu")
    assert code == 2 and "nowhere.fmu: path: no such FMU or folder" in line


@pytest.mark.filterwarnings("ignore::RuntimeWarning")
@pytest.mark.parametrize("engine", ["fmpy", "libcosim"])
def test_cli_fmu_error_during_run_is_one_line(tmp_path, engine):
    """Quadratic drag far beyond its step limit overflows: the load FMU refuses the
    non-finite motion with fmi2Error and the run ends in one line, exit 1.  The fmpy run
    keeps the rows it computed up to the failure (streamed into the CSV, said in the line);
    libcosim holds its run in memory and writes nothing."""
    path = write_scene(tmp_path, DRAG)
    code, line = cli("run", path, "-o", tmp_path / "out", "--engine", engine, "--csv", tmp_path / "r.csv",
                     *(["--algorithm", "jacobi"] if engine == "libcosim" else []))
    assert code == 1 and (tmp_path / "r.csv").exists() == (engine == "fmpy")
    if engine == "fmpy":
        t = float(re.search(r"failed at t = ([0-9.e+-]+) s", line).group(1))
        assert f"the results up to t = {t:g} s are kept in {tmp_path / 'r.csv'}" in line
        from hydrofmu.cosim.result import read_csv
        assert read_csv(tmp_path / "r.csv").time[-1] == pytest.approx(t)
        # the overflow shows first in an output: fmi2GetReal (or fmi2DoStep) returns fmi2Error
        assert re.search(r"fmi2(GetReal|DoStep) failed at t = ", line) and "(error)" in line
        assert "is not finite" in line
    else:
        assert "libcosim stopped" in line


CYCLES = """
import json, sys
from hydrofmu.bench.robust import instantiate_cycles
entries = len(sys.path)
r = instantiate_cycles(sys.argv[1], cycles=2000, warmup=1000, every=250)
print(json.dumps({**r, "new_path_entries": len(sys.path) - entries}))
"""


def test_instantiate_free_memory(tmp_path):
    """fmi2Instantiate/fmi2FreeInstance cycles through fmpy, which also loads and unloads the
    library every time: pythonfmu 0.7 leaks ~1.5 kB per fmi2Instantiate (and once put one
    sys.path entry per instance); the shim's instance pool hands the freed instance back, so
    after a warm-up memory is flat (FLAT_KB, ARENA_KB; 10⁴ cycles: test_native and
    `hydrofmu bench --part robust`).  Measured in a process of its own, away from the test
    session's allocations."""
    import json
    import subprocess
    import sys
    from hydrofmu.bench.robust import ARENA_KB, FLAT_KB, growth
    from hydrofmu.fmi.build import build_scene
    folder = build_scene(load_scene(ROOT / "models" / "moored_barge.toml"), tmp_path, log=lambda *_: None)
    run = subprocess.run([sys.executable, "-c", CYCLES, str(folder / "moored_barge_barge.fmu")],
                         capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-3000:]
    r = json.loads(run.stdout.splitlines()[-1])
    steady, total = growth(r["rss_kB"])
    assert steady < FLAT_KB and total < ARENA_KB, r
    assert r["new_path_entries"] <= 1          # the resources folder once, not once per instance
