"""DeepLines *CURRENTPOL reader: the manual's example, several structures, and bad decks."""
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks.deeplines import read_current_polars
from hydrofmu.errors import InputError

DATA = Path(__file__).parent / "data" / "deeplines"


def test_manual_example():
    polars = read_current_polars(DATA / "currentpol_manual.dat")
    assert list(polars) == ["FPSO"]
    d = polars["FPSO"]
    assert (d.xc, d.yc, d.zc, d.surfc) == (0.0, 0.0, 10.0, 1000.0)
    np.testing.assert_array_equal(d.angles, [1.0, 45.0, 90.0])
    np.testing.assert_array_equal(d.cx, [0.0, 1.14, 0.0])
    np.testing.assert_array_equal(d.cy, [0.0, 1.14, -1.0])
    np.testing.assert_array_equal(d.cmz, [0.0, 0.2, 0.0])
    assert (d.line, d.rows) == (1, [3, 4, 5])


def test_several_structures_other_keywords_and_comments():
    polars = read_current_polars(DATA / "currentpol_multi.dat")
    assert list(polars) == ["BARGE", "SPAR"]
    barge, spar = polars["BARGE"], polars["SPAR"]
    assert (barge.zc, barge.surfc, barge.line) == (-2.0, 500.0, 5)
    np.testing.assert_array_equal(barge.angles, np.arange(0.0, 360.0, 30.0))
    assert barge.cx[6] == -0.85 and barge.cy[3] == 1.0 and barge.cmz[-1] == -3.0
    np.testing.assert_array_equal(spar.angles, [0, 90, 180, 270, 360])
    np.testing.assert_array_equal(spar.cy, [0, 0.9, 0, -0.9, 0])
    assert spar.rows[-1] == 25


def _check(tmp_path, text, line, field):
    path = tmp_path / "bad_pol.dat"
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        read_current_polars(path)
    err = exc.value
    assert (err.line, err.field) == (line, field), str(err)
    assert f"bad_pol.dat:{line}: {field}:" in str(err)
    return err


HEAD = "*CURRENTPOL,NAME=FPSO\n 0 0 10 1000\n"
OK_ROWS = " 0 1 0 0\n 90 0 1 0\n 180 -1 0 0\n"
BAD = {
    "first line 3 numbers": ("*CURRENTPOL,NAME=FPSO\n 0 0 10\n" + OK_ROWS, 2, "XC"),
    "first line 8 numbers": ("*CURRENTPOL,NAME=FPSO\n 0 0 10 1000 0 1 0 0\n" + OK_ROWS, 2, "XC"),
    "first line non-number": ("*CURRENTPOL,NAME=FPSO\n 0 0 ten 1000\n" + OK_ROWS, 2, "ZC"),
    "surface not positive": ("*CURRENTPOL,NAME=FPSO\n 0 0 10 0\n" + OK_ROWS, 2, "SURFC"),
    "no data": ("*CURRENTPOL,NAME=FPSO\n*CURRENT\n", 1, "XC"),
    "row with 3 values": (HEAD + " 0 1 0 0\n 90 0 1\n", 4, "CMZC(2)"),
    "row with 5 values": (HEAD + " 0 1 0 0 7\n 90 0 1 0\n", 3, "CMZC(1)"),
    "non-number": (HEAD + " 0 1 0 0\n 90 O 1 0\n", 4, "CXC(2)"),
    "not increasing": (HEAD + " 0 1 0 0\n 90 0 1 0\n 90 0 1 0\n", 5, "ANGC(3)"),
    "decreasing": (HEAD + " 0 1 0 0\n 90 0 1 0\n 45 0 1 0\n", 5, "ANGC(3)"),
    "above 360": (HEAD + " 0 1 0 0\n 370 0 1 0\n", 4, "ANGC(2)"),
    "negative angle": (HEAD + " -10 1 0 0\n 90 0 1 0\n", 3, "ANGC(1)"),
    "one row": (HEAD + " 0 1 0 0\n*CURRENT\n 1 0\n", 3, "ANGC"),
    "name too long": ("*CURRENTPOL,NAME=FPSO_HULL\n 0 0 10 1000\n" + OK_ROWS, 1, "NAME"),
    "name with blank": ("*CURRENTPOL,NAME=MY FPSO\n 0 0 10 1000\n" + OK_ROWS, 1, "NAME"),
    "no name": ("*CURRENTPOL\n 0 0 10 1000\n" + OK_ROWS, 1, "NAME"),
    "other parameter": ("*CURRENTPOL,NAME=A,UNIT=SI\n 0 0 10 1000\n" + OK_ROWS, 1, "NAME"),
    "missing comma": ("*CURRENTPOL NAME=FPSO\n 0 0 10 1000\n" + OK_ROWS, 1, "NAME"),
    "duplicate name": (HEAD + OK_ROWS + "# again\n*currentpol, name = fpso\n 0 0 10 1000\n" + OK_ROWS, 7, "NAME"),
}


@pytest.mark.parametrize("case", BAD)
def test_bad_decks(tmp_path, case):
    _check(tmp_path, *BAD[case])


def test_row_error_names_row(tmp_path):
    err = _check(tmp_path, HEAD + " 0 1 0 0\n 90 0 1 0\n 180 -1 x 0\n", 5, "CYC(3)")
    assert "'x'" in str(err)


def test_no_currentpol(tmp_path):
    path = tmp_path / "model.dat"
    path.write_text("*CURRENT\n 1.0 0.\n")
    with pytest.raises(InputError) as exc:
        read_current_polars(path)
    assert exc.value.field == "*CURRENTPOL" and "model.dat" in str(exc.value)
