"""AQWA *Viscous Drag reader: the manual's layout, the named-matrix layout, and bad decks."""
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks.aqwa import read_viscous_drag
from hydrofmu.errors import InputError

DATA = Path(__file__).parent / "data" / "aqwa"

ROWS6 = "\n".join(" ".join(str(10 * r + c) for c in range(1, 7)) for r in range(1, 7))


def test_manual_layout_two_bodies():
    bodies = read_viscous_drag(DATA / "viscous_drag_manual.dat")
    assert list(bodies) == ["FPSO", "Buoy"]
    fpso, buoy = bodies["FPSO"], bodies["Buoy"]
    assert fpso.option == "RELATIVE" and fpso.relative and fpso.table is None
    expected = np.diag([1.1e5, 2.2e5, 3.3e5, 4.4e8, 5.5e9, 6.6e9])
    expected[1, 5] = expected[5, 1] = 1.5e4
    np.testing.assert_array_equal(fpso.matrix, expected)
    assert buoy.option == "ABSOLUTE" and not buoy.relative
    # Blank-separated rows: V_rc = 10·r + c as written in the file.
    np.testing.assert_array_equal(buoy.matrix, [[10 * r + c for c in range(1, 7)] for r in range(1, 7)])
    assert (fpso.line, buoy.line) == (2, 11)


def test_named_matrices_defaults_and_case():
    bodies = read_viscous_drag(DATA / "viscous_drag_named.dat")
    assert list(bodies) == ["Hull A", "Hull B", "Tug"]
    barge = np.diag([5.0e4, 8.0e4, 9.0e4, 1.0e7, 2.0e8, 3.0e8])
    barge[1, 5] = barge[5, 1] = 2.0e3
    a, b, tug = bodies["Hull A"], bodies["Hull B"], bodies["Tug"]
    np.testing.assert_array_equal(a.matrix, barge)
    np.testing.assert_array_equal(b.matrix, barge)
    assert a.matrix is not b.matrix  # each body owns its copy
    assert a.option == "ABSOLUTE"  # OPTION left out
    assert b.option == "RELATIVE" and b.table == "barge DRAG"
    np.testing.assert_array_equal(tug.matrix, np.diag([1.0, 2, 3, 4, 5, 6]))


def _deck(tmp_path, text, name="deck.dat"):
    path = tmp_path / name
    path.write_text(text)
    return path


def _body(name="B1", extra="TYPE=MATRIX\nOPTION=ABSOLUTE\n", rows=ROWS6):
    return f"FLOATING BODY={name}\n{extra}{rows}\n"


FIVE_ROWS = "\n".join(ROWS6.splitlines()[:5])
BAD = {
    "five rows at end of file": ("*Viscous Drag\n" + _body(rows=FIVE_ROWS), 9, "V61"),
    "five rows then next body": ("*Viscous Drag\n" + _body(rows=FIVE_ROWS) + _body("B2"), 10, "V61"),
    "five rows then keyword": ("*Viscous Drag\n" + _body(rows=FIVE_ROWS) + "*Viscous Drag Coefficients\n", 10, "V61"),
    "row with 5 values": ("*Viscous Drag\n" + _body(rows=ROWS6.replace("31 32 33 34 35 36", "31 32 33 34 35")),
                          7, "V36"),
    "row with 7 values": ("*Viscous Drag\n" + _body(rows=ROWS6.replace("21 22 23 24 25 26", "21 22 23 24 25 26 27")),
                          6, "V26"),
    "non-number": ("*Viscous Drag\n" + _body(rows=ROWS6.replace("34", "3x4")), 7, "V34"),
    "nan": ("*Viscous Drag\n" + _body(rows=ROWS6.replace("52", "nan")), 9, "V52"),
    "unknown option": ("*Viscous Drag\n" + _body(extra="TYPE=MATRIX\nOPTION=ABSOLUT\n"), 4, "OPTION"),
    "type not matrix": ("*Viscous Drag\n" + _body(extra="TYPE=DIAGONAL\n"), 3, "TYPE"),
    "option twice": ("*Viscous Drag\n" + _body(extra="OPTION=ABSOLUTE\noption=relative\n"), 4, "OPTION"),
    "duplicate body": ("*Viscous Drag\n" + _body("Barge") + _body("BARGE"), 11, "FLOATING BODY"),
    "undefined named matrix": ("*Viscous Drag Coefficients\nNAME=X\n" + ROWS6 + "\n*Viscous Drag\n"
                               + _body(extra="VISCOUS DRAG=Y\n", rows="").rstrip() + "\n", 11, "VISCOUS DRAG"),
    "rows after reference": ("*Viscous Drag\n" + _body(extra="VISCOUS DRAG=X\n"), 4, "FLOATING BODY"),
    "duplicate named matrix": ("*Viscous Drag Coefficients\nNAME=X\n" + ROWS6 + "\nname = x\n" + ROWS6
                               + "\n*Viscous Drag\n" + _body(), 9, "NAME"),
    "misspelt keyword": ("*Viscous Drag\n" + _body() + "*Viscous Drg\n", 11, "*Viscous Drag"),
    "unknown setting": ("*Viscous Drag\n" + _body(extra="COLOUR=red\n"), 3, "COLOUR"),
    "empty section": ("*Viscous Drag\n*Viscous Drag Coefficients\nNAME=X\n" + ROWS6 + "\n", 1, "FLOATING BODY"),
    "other viscous keyword": ("*Viscous Damping\n" + _body(), 1, "*Viscous Drag"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_decks(tmp_path, case):
    text, line, field = BAD[case]
    path = _deck(tmp_path, text, "bad_drag.dat")
    with pytest.raises(InputError) as exc:
        read_viscous_drag(path)
    err = exc.value
    assert (err.line, err.field) == (line, field), str(err)
    assert f"bad_drag.dat:{line}: {field}:" in str(err)


def test_no_viscous_drag_keyword(tmp_path):
    path = _deck(tmp_path, "*Viscous Drag Coefficients\nNAME=X\n" + ROWS6 + "\n", "only_table.dat")
    with pytest.raises(InputError) as exc:
        read_viscous_drag(path)
    assert exc.value.field == "*Viscous Drag" and exc.value.line is None
    assert "only_table.dat" in str(exc.value)


def test_missing_file(tmp_path):
    with pytest.raises(InputError) as exc:
        read_viscous_drag(tmp_path / "nope.dat")
    assert "nope.dat" in str(exc.value)
