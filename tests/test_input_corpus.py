"""A bad-input corpus tried as a new user would (issue 22's hidden corpus, played again):
each slip here once ran to the end without a word or ended in exit 3; now it is one clear
error (exit 2, the file and the field named, nothing written) before any work starts."""
import shutil

import pytest

from hydrofmu import cli
from hydrofmu.batch import check_knobs, load_cases
from hydrofmu.errors import InputError

from conftest import MODELS, ROOT

BEM = ROOT / "tests" / "data" / "bem" / "cylinders.nc"


@pytest.fixture
def barge(tmp_path):
    """The demo scene and its decks in a scratch folder (outputs may land beside them)."""
    shutil.copytree(MODELS, tmp_path / "models")
    return tmp_path / "models" / "moored_barge.toml"


def refused(capsys, argv):
    """Run the CLI; it must exit 2 with one ``error:`` line; returns that line."""
    code = cli.main([str(a) for a in argv])
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.startswith("error:")]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# --- outputs: never over an input, never two in one file, a plot in a format it can be ----

def test_run_output_over_the_scene_or_a_deck_is_refused_before_the_build(barge, capsys):
    scene, deck = barge.read_bytes(), (barge.parent / "decks" / "barge_viscous.aqwa").read_bytes()
    out = barge.parent / "out"
    for target in (barge, barge.parent / "decks" / "barge_viscous.aqwa"):
        line = refused(capsys, ["run", barge, "-o", out, "--csv", target])
        assert f"{target.name}: output file: is the input file" in line
    assert barge.read_bytes() == scene and (barge.parent / "decks" / "barge_viscous.aqwa").read_bytes() == deck
    assert not out.exists()   # nothing built


def test_run_output_inside_the_built_folder_is_refused(barge, capsys):
    out = barge.parent / "out"
    line = refused(capsys, ["run", barge, "-o", out, "--csv", out / "moored_barge" / "manifest.json"])
    assert "output file: lies inside the input folder" in line and not out.exists()


def test_run_plot_suffix_is_checked_before_the_run(barge, capsys):
    out = barge.parent / "out"
    for png, said in (("plot.txt", "suffix '.txt'"), ("plot", "no suffix")):
        line = refused(capsys, ["run", barge, "-o", out, "--png", barge.parent / png])
        assert f"{png}: plot file: {said}" in line and ".png" in line and ".pdf" in line
    assert not out.exists()


def test_run_two_outputs_in_one_file_are_refused(barge, capsys):
    same = barge.parent / "same.png"
    line = refused(capsys, ["run", barge, "-o", barge.parent / "out", "--csv", same, "--png", same])
    assert "same.png: output file: two outputs of the command go to this one file" in line


def test_bem2simo_never_writes_over_its_bem_result(tmp_path, capsys):
    result = tmp_path / "cylinders.nc"
    shutil.copy(BEM, result)
    before = result.read_bytes()
    line = refused(capsys, ["bem2simo", result, "-o", result])
    assert "cylinders.nc: output file: is the input file" in line
    line = refused(capsys, ["bem2simo", result, "-o", tmp_path / "c.sim", "--png", tmp_path / "c.sim"])
    assert "plot file: suffix '.sim'" in line
    assert result.read_bytes() == before and not (tmp_path / "c.sim").exists()


def test_result_plot_refuses_a_format_it_cannot_write(tmp_path):
    from hydrofmu.cosim.result import Result
    import numpy as np
    r = Result(np.array([0.0, 0.1]), ["a.b"], np.zeros((2, 1)), "jacobi", 0.1, manifest={"fmus": []})
    with pytest.raises(InputError, match=r"plot file: suffix '\.csv'"):
        r.plot(tmp_path / "x.csv")


# --- batches: what every case would trip over is said once, up front --------------------

BASE = f"""scene = "{(MODELS / 'moored_barge.toml').as_posix()}"
stop = 30.0
outputs = ["barge_dynamics.position[1]", "barge.force[1]"]
"""


@pytest.mark.parametrize("extra, field, said", [
    ("transient = 30.0\n", "transient", "30 s leaves nothing of a case that ends at 30 s"),
    ('transient = 20.0\n[[cases]]\n"run.stop" = 10.0\n', "transient", "leaves nothing of a case that ends at 10 s"),
    ('[matrix]\n"environment.current_speed" = [0.5, 1.0, 0.5]\n', "matrix.environment.current_speed",
     "value 0.5 given twice"),
    ('[set]\n"run.algorithm" = "ecco"\n', "set.run.algorithm", "found 'ecco'"),
    ('[[cases]]\n"run.algorithm" = "ecco"\n', "cases[0].run.algorithm", "found 'ecco'"),
])
def test_batch_slips_refused_before_any_case(tmp_path, extra, field, said):
    cases = tmp_path / "cases.toml"
    cases.write_text(BASE + extra)
    with pytest.raises(InputError) as err:
        check_knobs(load_cases(cases))
    assert err.value.path == str(cases) and err.value.field == field and said in err.value.message


def test_batch_output_given_twice_is_refused(tmp_path):
    cases = tmp_path / "cases.toml"
    cases.write_text(BASE.replace('"barge.force[1]"]', '"barge.force[1]", "barge.force[1]"]'))
    with pytest.raises(InputError, match=r"outputs: 'barge.force\[1\]' given twice"):
        load_cases(cases)
