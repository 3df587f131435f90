"""RIFLEX BODY / CONB reader: the manual's layouts parse, each malformed deck gives one
error naming file, line and field."""
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks.riflex import BodyData, ConbData, read_components
from hydrofmu.errors import InputError
from hydrofmu.physics.lumped import LumpedBody

DATA = Path(__file__).parent / "data" / "riflex"


def test_body_layouts_from_manual():
    comps = read_components(DATA / "body_manual.inp")
    assert list(comps) == ["buoy1", "clump"]
    b = comps["buoy1"]
    assert isinstance(b, BodyData) and not isinstance(b, ConbData)
    assert (b.am, b.ae, b.icoo) == (2500.0, 4.0, "GLOBAL")
    assert b.cd == (120.0, 120.0, 300.0) and b.added_mass == (1000.0, 1000.0, 2500.0)
    assert b.path == str(DATA / "body_manual.inp") and b.line == 4
    c = comps["clump"]  # lower case, abbreviated, commas, E and D exponents
    assert (c.am, c.ae, c.icoo) == (12000.0, 0.0, "LOCAL")
    assert c.cd == (150.0, 200.0, 0.0) and c.added_mass == (0.0, 0.0, 5000.0)


def test_conb_layouts_from_manual():
    comps = read_components(DATA / "conb_manual.inp")
    assert list(comps) == ["hinge", "ball", "univ", "endball"]
    assert all(isinstance(c, ConbData) for c in comps.values())
    h = comps["hinge"]
    assert (h.am, h.ae, h.icoo, h.codes) == (100.0, 0.05, "LOCAL", (1, 1, 0))
    assert h.free == (False, False, True)
    assert h.cd == (10.0, 10.0, 0.0) and h.added_mass == (20.0, 20.0, 0.0)
    assert comps["ball"].codes == (0, 0, 0) and comps["ball"].icoo == "GLOBAL"  # IRX line left out
    assert comps["univ"].codes == (1, 0, 0)  # IRY, IRZ default to 0
    assert comps["endball"].codes == (0, 0, 0) and comps["endball"].cd == (5.0, 5.0, 5.0)  # file ends


def test_other_data_groups_are_skipped():
    comps = read_components(DATA / "inpmod_mixed.inp")
    assert list(comps) == ["float", "joint"]
    assert comps["float"].added_mass == (0.0, 0.0, 1500.0)
    assert isinstance(comps["joint"], ConbData) and comps["joint"].codes == (0, 0, 0)


def test_to_lumped_body():
    b = read_components(DATA / "body_manual.inp")["clump"]
    lb = b.lumped([1.0, 2.0, 3.0])
    assert isinstance(lb, LumpedBody) and lb.name == "clump" and lb.icoo == "LOCAL"
    np.testing.assert_array_equal(lb.offset, [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(lb.cd, [150.0, 200.0, 0.0])
    assert lb.am == 12000.0


def _deck(tmp_path, text):
    p = tmp_path / "deck.inp"
    p.write_text(text)
    return p


def _error(tmp_path, text):
    p = _deck(tmp_path, text)
    with pytest.raises(InputError) as info:
        read_components(p)
    assert info.value.path == str(p)
    return info.value


GOOD = "NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 1 2 3 4 5 6\n"


@pytest.mark.parametrize("text, line, field", [
    # missing lines: end of file, or the next group where a data line belongs
    ("NEW COMPONENT BODY\n", 1, "CMPTYP-ID"),
    ("NEW COMPONENT BODY\nb1\n' comment\n", 2, "AM"),
    ("NEW COMPONENT BODY\nb1\n10 1\n", 3, "ICOO"),
    ("NEW COMPONENT BODY\nb1\n10 1\nNEW COMPONENT BODY\nb2\n1 1\nGLOBAL 0 0 0 0 0 0\n", 4, "ICOO"),
    ("NEW COMPONENT BODY\nNEW COMPONENT BODY\n", 2, "CMPTYP-ID"),
    # non-numbers and wrong counts
    ("NEW COMPONENT BODY\nb1\nten 1\nGLOBAL 0 0 0 0 0 0\n", 3, "AM"),
    ("NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 1 x 3 0 0 0\n", 4, "CDY"),
    ("NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 1 2 3 0 0 zero\n", 4, "AMZ"),
    ("NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 1 2 3 0 0\n", 4, "AMZ"),
    ("NEW COMPONENT BODY\nb1\n10 1 5\nGLOBAL 1 2 3 0 0 0\n", 3, "AE"),
    # coordinate system code: only GLOBAL / LOCAL, four letters count
    ("NEW COMPONENT BODY\nb1\n10 1\nGLO 1 2 3 0 0 0\n", 4, "ICOO"),
    ("NEW COMPONENT BODY\nb1\n10 1\nBODY 1 2 3 0 0 0\n", 4, "ICOO"),
    # freedom codes
    ("NEW COMPONENT CONB\nj1\n0 0\nGLOBAL 0 0 0 0 0 0\n1 2 0\n", 5, "IRY"),
    ("NEW COMPONENT CONB\nj1\n0 0\nGLOBAL 0 0 0 0 0 0\n0 0 -1\n", 5, "IRZ"),
    ("NEW COMPONENT CONB\nj1\n0 0\nGLOBAL 0 0 0 0 0 0\n0.5\n", 5, "IRX"),
    ("NEW COMPONENT CONB\nj1\n0 0\nGLOBAL 0 0 0 0 0 0\n1 1 0 1\n", 5, "IRZ"),
    # identifiers
    (GOOD + "NEW COMPONENT CONB\nb1\n0 0\nGLOBAL 0 0 0 0 0 0\n", 6, "CMPTYP-ID"),
    ("NEW COMPONENT BODY\nbuoyancy1\n10 1\nGLOBAL 0 0 0 0 0 0\n", 2, "CMPTYP-ID"),
    ("NEW COMPONENT BODY\nb 1\n10 1\nGLOBAL 0 0 0 0 0 0\n", 2, "CMPTYP-ID"),
    # negative mass, volume, coefficients
    ("NEW COMPONENT BODY\nb1\n-10 1\nGLOBAL 0 0 0 0 0 0\n", 3, "AM"),
    ("NEW COMPONENT BODY\nb1\n10 -1\nGLOBAL 0 0 0 0 0 0\n", 3, "AE"),
    ("NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 0 0 -3 0 0 0\n", 4, "CDZ"),
    ("NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 0 0 0 -1 0 0\n", 4, "AMX"),
    # a stray data line after a complete group (a BODY has no IRX line)
    (GOOD + "1 1 0\n", 5, "data group identifier"),
])
def test_malformed(tmp_path, text, line, field):
    err = _error(tmp_path, text)
    assert (err.line, err.field) == (line, field), str(err)


def test_error_message_names_file_line_field(tmp_path):
    err = _error(tmp_path, "NEW COMPONENT BODY\nb1\n10 1\nGLOBAL 1 x 3 0 0 0\n")
    assert str(err).startswith(f"{tmp_path / 'deck.inp'}:4: CDY:") and "'x'" in str(err)


def test_duplicate_names_first_line(tmp_path):
    err = _error(tmp_path, GOOD + GOOD)
    assert err.line == 6 and "first at line 1" in err.message


def test_missing_file(tmp_path):
    with pytest.raises(InputError) as info:
        read_components(tmp_path / "nope.inp")
    assert info.value.line is None and info.value.field == "file"


def test_keywords_four_letters_any_case(tmp_path):
    p = _deck(tmp_path, "new compONENTS body\nb1\n10 1\nglobAL 0 0 0 0 0 0\n"
                        "NEW COMP CONB\nj1\n0 0\nLocalized 0 0 0 0 0 0\n1,1,1\nEND\n")
    comps = read_components(p)
    assert comps["b1"].icoo == "GLOBAL" and comps["j1"].icoo == "LOCAL" and comps["j1"].codes == (1, 1, 1)


def test_comment_lines_and_empty_file(tmp_path):
    assert read_components(_deck(tmp_path, "' only a comment\n\n")) == {}
    p = _deck(tmp_path, "  ' indented comment\nNEW COMPONENT BODY\n'id\nb1\n'\n10 1\n' x\nGLOBAL 0 0 0 0 0 0\n")
    assert read_components(p)["b1"].line == 2
