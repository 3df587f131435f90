"""Issue 22 (deck half): every deck is read as written or refused.  Each of the issue's
deck examples ends in one error naming the file, the line and the keyword or field; the
keyword rule is the manuals' (capitals required, lower-case letters optional); what a build
read and skipped is printed and kept in the manifest; suspicious but legal data warns.
The mutation suite over every valid test deck is tests/test_deck_mutations.py."""
import json
import re
import warnings

import numpy as np
import pytest

from hydrofmu.cli import main
from hydrofmu.decks.aqwa import read_viscous_drag
from hydrofmu.decks.deeplines import read_current_polars
from hydrofmu.decks.lines import Keyword
from hydrofmu.decks.riflex import read_components, read_current_states
from hydrofmu.decks.simo import read_couplings, read_current_profile
from hydrofmu.errors import InputError, InputWarning

from conftest import write_scene
from test_current_files import RIFLEX as RIFLEX_CURRENT
from test_whole_files import AQWA_WHOLE, DRAG, RIFLEX_BARE, SIMO_BARE, write


def error(read, path, *args, **kw):
    with pytest.raises(InputError) as err:
        read(path, *args, **kw)
    return err.value


@pytest.mark.parametrize("written, ok", [
    ("UNIT NAMe SPECification", True), ("UNIT NAM SPEC", True), ("unit nam spec", True),
    ("Unit Names Specification", True), ("UNIT NA SPEC", False), ("UNIT NAM", False),
    ("UNIT NAM SPEC 1", False), ("UNIT NAMS SPEC", False),
])
def test_keyword_rule_of_the_manuals(written, ok):
    """Capitals required, lower-case letters optional, any case, no extra words; a near miss
    is recognised as resembling the keyword (so the readers refuse it)."""
    key = Keyword("UNIT NAMe SPECification")
    assert key.matches(written.split()) is ok
    assert (key.resembles(written.split()) is None) is ok


def test_values_on_a_keyword_line_are_refused(tmp_path):
    """Issue: `COUPled RETArdation FUNCtion 0.1` dropped the whole retardation block."""
    deck = write(tmp_path, SIMO_BARE.replace("COUP RETA FUNC\n0.1\n", "COUPled RETArdation FUNCtion 0.1\n"), "d.sys")
    e = error(read_couplings, deck, bodies=["A"])
    assert (e.line, e.field) == (16, "COUPled ADDEd MASS") or (e.line, e.field) == (16, "data group")
    assert "COUPled RETArdation FUNCtion" in e.message and "extra words" in e.message and "'0.1'" in e.message


def test_more_current_levels_than_nculev_are_refused(tmp_path):
    """Issue: NCULEV = 3 followed by four level lines dropped the deepest level."""
    text = RIFLEX_CURRENT.format(units="/ / / / / /", level1="0.0, 0.0, 1.0")
    text = text.replace("-1.0D2, 90.0, 0.1\n", "-1.0D2, 90.0, 0.1\n-150.0 90.0 0.05\n")
    e = error(read_current_states, write(tmp_path, text, "c.inp"))
    assert e.line == 39 and "-150.0 90.0 0.05" in e.message and "count exceeded" in e.message


def riflex_kn(tmp_path, declaration):
    """The bare components in kg-kN (drag coefficients / 1000) under a unit declaration."""
    text = RIFLEX_BARE.replace("GLOBAL 120.0 130.0 300.0", "GLOBAL 0.12 0.13 0.3").replace(
        "LOCAL 10.0 10.0 0.0", "LOCAL 0.01 0.01 0.0")
    return write(tmp_path, f"{declaration}\ns m kg kN 9.81 0.001\n" + text, "kn.inp")


def test_unit_declaration_by_its_capitals(tmp_path):
    """Issue: `unit nam spec` was skipped, so a kN file read as SI got drag 1000x too small."""
    e = error(read_components, riflex_kn(tmp_path, "unit nam spec"), units="SI")
    assert (e.line, e.field) == (2, "UM") and 'set units = "kg-kN"' in e.message
    kn = read_components(riflex_kn(tmp_path, "unit nam spec"), units="kg-kN")
    si = read_components(write(tmp_path, RIFLEX_BARE, "si.inp"))
    assert kn["buoy1"].cd == pytest.approx(si["buoy1"].cd, rel=1e-12)
    e = error(read_components, riflex_kn(tmp_path, "UNIT NA SPEC"), units="kg-kN")
    assert (e.line, e.field) == (1, "data group") and "'UNIT NAMe SPECification'" in e.message


@pytest.mark.parametrize("reader, text, line, match", [
    # a data group given once, given twice
    (read_components, "UNIT NAM SPEC\ns m kg N 9.81 1.0\nUNIT NAM SPEC\ns m kg kN 9.81 0.001\n" + RIFLEX_BARE,
     3, "given twice (first at line 1)"),
    (read_couplings, "SYST DESC SIMO\nx\nx\nx\nm s kg 9.81 1025.0\nSYST DESC SIMO\nx\nx\nx\nm s Mg 9.81 1.025\n"
     + SIMO_BARE, 6, "given twice (first at line 1)"),
    # a sub-group out of the manual's order (read as zeros before)
    (read_couplings, SIMO_BARE.replace("COUP ADDE MASS\n", "COUP ADDX MASS\n", 1).split("COUP ADDX MASS")[0]
     + "COUP RETA FUNC\n0.1\nRETA ELEM DATA\n2 1 1\n1 0\nCOUP ADDE MASS\n" + "0 0 0 0 0 0\n" * 6,
     14, "out of the manual's order"),
    # rows beyond a matrix
    (read_couplings, SIMO_BARE.split("COUP RETA FUNC")[0] + "0 0 0 0 0 1\n", 16, "a row too many"),
    (read_viscous_drag, DRAG + "0.0, 0.0, 0.0, 0.0, 0.0, 1.0\n", 11, "expected FLOATING BODY"),
    # a keyword misspelt or cut below its capitals, between groups
    (read_components, "NEW COMP BOD\nb\n1 1\nGLOBAL 0 0 0 0 0 0\n", 1, "'NEW COMPonent BODY'"),
    (read_couplings, SIMO_BARE.replace("HYDR COUP DATA", "HYD COUP DATA"), 3, "'HYDRodynamic COUPling DATA'"),
    (read_viscous_drag, AQWA_WHOLE.replace("*Viscous Drag", "*Viscous Drg"), 8, "'*Viscous Drag'"),
    (read_current_polars, "*CURRENTPL,NAME=A\n0 0 0 1\n0 1 0 0\n90 0 1 0\n", 1, "'*CURRENTPOL'"),
    # an unknown group inside one of ours whose lines read as more of it
    (read_couplings, SIMO_BARE.replace("2 3 3\n", "UNKNown GROUp\n2 3 3\n"), 21, "stray or misplaced line"),
    (read_components, RIFLEX_BARE.replace("1 1 0\n", "OTHEr GROUp\n1 1 0\n"), 9, "IRX IRY IRZ"),
    (read_current_polars, "*CURRENTPOL,NAME=A\n0 0 0 1\n0 1 0 0\n90 0 1 0\n*ALIEN\n180 -1 0 0\n", 5, "more of"),
    (read_viscous_drag, DRAG.replace("0.0, 2.2E5", "*Mass\n0.0, 2.2E5").replace("OPTION=RELATIVE\n", "")
     + "*Other\nFLOATING BODY=B\n" + "1 0 0 0 0 0\n" * 6, 5, "6 rows"),
])
def test_each_kind_of_silent_misreading_is_one_error(tmp_path, reader, text, line, match):
    path = write(tmp_path, text, "deck.txt")
    kw = {"bodies": ["A"]} if reader is read_couplings else {}
    e = error(reader, path, **kw)
    assert (e.path, e.line) == (str(path), line) and match in e.message, str(e)


def test_other_groups_are_still_skipped_and_listed(tmp_path):
    """Lenient between groups: groups that start like none of ours are skipped, by name and
    line, and the reading says so."""
    found = read_viscous_drag(write(tmp_path, AQWA_WHOLE, "a.dat"))
    assert found.reading.used == [("*Viscous Drag: FLOATING BODY=FPSO", 9)]
    assert [(n, k) for n, k, _ in found.reading.skipped] == [
        ("an AQWA input: lines before the first section and other sections are skipped", 1),
        ("*Structure", 2), ("*Mass", 5), ("*Current", 18)]


def test_direction_of_370_degrees_warns(tmp_path):
    """Legal (370° is 10°) but worth a look: one warning naming file, line and field."""
    path = write(tmp_path, "2\n0.0 370.0 1.0\n-20.0 90.0 0.5\n", "c.txt")
    with pytest.warns(InputWarning, match=r"c.txt:2: CURDIR\(1\): direction 370°"):
        rows = read_current_profile(path)
    assert rows == [[0.0, 1.0, 370.0], [-20.0, 0.5, 90.0]] and len(rows.reading.warnings) == 1


SCENE = """\
[scene]
name = "strict"
[environment]
current_deck = "c.txt"
current_format = "sima"
[bodies.barge]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
deck = "a.dat"
body = "FPSO"
"""


def test_build_prints_and_records_what_each_deck_gave(tmp_path, capsys):
    """`hydrofmu build --check` prints per deck the groups used and skipped (name, line) and
    the warnings; the manifest records the same."""
    from hydrofmu.assembly import assemble
    from hydrofmu.fmi.build import manifest
    from hydrofmu.scene import load_scene
    write(tmp_path, AQWA_WHOLE, "a.dat")
    write(tmp_path, "2\n0.0 370.0 1.0\n-20.0 90.0 0.5\n", "c.txt")
    scene_path = write_scene(tmp_path, SCENE)
    assert main(["build", "--check", str(scene_path), "-o", str(tmp_path / "out")]) == 0
    out, err = capsys.readouterr()
    assert f"deck {tmp_path / 'a.dat'} (AQWA): used *Viscous Drag: FLOATING BODY=FPSO (line 9)" in out
    assert "skipped 'an AQWA input" in out and "'*Structure' (line 2, 3 lines)" in out and "'*Current' (line 18" in out
    assert f"deck {tmp_path / 'c.txt'} (SIMA current): used NCUR = 2 levels (line 1)" in out
    assert "warning:" in err and "c.txt:2: CURDIR(1): direction 370°" in err
    assert not (tmp_path / "out").exists()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = load_scene(scene_path)
    decks = json.loads(json.dumps(manifest(scene, assemble(scene), [])))["decks"]
    aqwa = next(d for d in decks if d["reader"] == "AQWA")
    assert aqwa["used"] == [{"group": "*Viscous Drag: FLOATING BODY=FPSO", "line": 9}]
    assert {"group": "*Mass", "line": 5, "lines": 3} in aqwa["skipped"]
    sima = next(d for d in decks if d["reader"] == "SIMA current")
    assert len(sima["warnings"]) == 1 and "370" in sima["warnings"][0]


def test_legal_variants_still_read_the_same(tmp_path):
    """The keyword forms the manuals allow (capitals only, full words, lower case, a plural)
    read the same data as the printed form."""
    base = read_couplings(write(tmp_path, SIMO_BARE, "a.sys"), bodies=["A"])["C1"]
    for form in ("HYDRodynamic COUPling DATA", "hydrodynamic coupling data", "Hydr Coupl Data"):
        got = read_couplings(write(tmp_path, SIMO_BARE.replace("HYDR COUP DATA", form), "b.sys"), bodies=["A"])
        np.testing.assert_array_equal(got["C1"].added_mass, base.added_mass)
        assert all(np.array_equal(got["C1"].kernels[k], base.kernels[k]) for k in base.kernels)


def test_direction_of_370_degrees_in_the_scene_warns(tmp_path):
    """The same in a scene: the uniform current and an inline profile's levels."""
    from hydrofmu.scene import load_scene
    base = SCENE.replace('current_deck = "c.txt"\ncurrent_format = "sima"', "{current}")
    write(tmp_path, AQWA_WHOLE, "a.dat")
    for current, key in (("current_speed = 1.0\ncurrent_direction = 370.0", "environment.current_direction"),
                         ("current_profile = [[0.0, 1.0, 10.0], [-20.0, 0.5, -30.0]]", "environment.current_profile[1]")):
        with pytest.warns(InputWarning, match=rf"{re.escape(key)}: direction .* is outside 0…360°") as said:
            scene = load_scene(write_scene(tmp_path, base.format(current=current)))
        assert len([w for w in said if "outside 0…360" in str(w.message)]) == 1
        assert any("outside 0…360" in w for w in scene.warnings)
