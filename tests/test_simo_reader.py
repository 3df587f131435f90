"""SIMO `HYDRodynamic COUPling DATA` reader: values as the manual lays them out, and errors
that name the file, the line and the field."""
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks.simo import read_couplings
from hydrofmu.errors import InputError

DATA = Path(__file__).parent / "data" / "simo"


def test_reads_two_couplings_as_printed():
    out = read_couplings(DATA / "two_barges.sys", bodies=["barge1"])
    assert list(out) == ["cpl12", "cpl22"]
    c = out["cpl12"]
    assert (c.body_a, c.body_b, c.timdel, c.line) == ("barge1", "barge2", 0.5, 7)
    assert c.text == ("Coupling barge1 - barge2", "coefficients from a panel-code run at zero speed")
    assert c.added_mass.shape == (6, 6)
    assert c.added_mass[0, 4] == 3.0e5 and c.added_mass[4, 0] == 3.5e5      # row i, column j
    assert c.added_mass[3, 5] == -1.5e6 and c.added_mass[5, 3] == -1.2e6
    assert c.added_mass[4, 4] == 9.0e8
    assert sorted(c.kernels) == [(1, 1), (2, 6), (3, 3)]
    np.testing.assert_array_equal(c.kernels[(1, 1)], [1.0e4, 8.0e3, 5.0e3, 2.0e3, 0.5e3])   # '&'
    np.testing.assert_array_equal(c.kernels[(3, 3)], [2.0e4, 1.0e4, 0.0])                   # D, commas
    np.testing.assert_array_equal(c.kernels[(2, 6)], [-3.0e5, -2.0e5, -1.0e5, -4.0e4])     # comment inside
    s = out["cpl22"]                                   # lower case, four-letter keywords, self-coupling
    assert (s.body_a, s.body_b, s.timdel) == ("barge2", "barge2", 0.25)
    assert not s.added_mass.any()
    assert set(s.kernels) == {(3, 3), (4, 2)}


DECK = """\
' test deck
BODY DATA
B
HYDR COUP DATA
C1
text one
text two
A
B
COUP ADDE MASS
1 0 0 0 0 0
0 2 0 0 0 0
0 0 3 0 0 0
0 0 0 4 0 0
0 0 0 0 5 0
0 0 0 0 0 6
COUP RETA FUNC
0.1
RETA ELEM DATA
3 1 2
1.0 0.5 &
0.25
2 3 3
4.0 2.0
"""


def deck(tmp_path, text, name="deck.sys"):
    path = tmp_path / name
    path.write_text(text)
    return path


def raises(tmp_path, text, line, field, bodies=("A",), match=None):
    path = deck(tmp_path, text)
    with pytest.raises(InputError) as err:
        read_couplings(path, bodies=bodies)
    e = err.value
    assert (Path(e.path), e.line, e.field) == (path, line, field), str(e)
    if match:
        assert match in e.message, e.message
    return e


def test_template_deck_reads(tmp_path):
    c = read_couplings(deck(tmp_path, DECK), bodies=["A"])["C1"]
    np.testing.assert_array_equal(c.added_mass, np.diag([1.0, 2, 3, 4, 5, 6]))
    np.testing.assert_array_equal(c.kernels[(1, 2)], [1.0, 0.5, 0.25])


def test_added_mass_only_and_retardation_only(tmp_path):
    am_only = DECK.split("COUP RETA FUNC")[0]
    c = read_couplings(deck(tmp_path, am_only), bodies=["A"])["C1"]
    assert c.timdel is None and c.kernels == {} and c.added_mass[5, 5] == 6
    ret_only = DECK.replace("".join(DECK.splitlines(True)[9:16]), "")
    c = read_couplings(deck(tmp_path, ret_only), bodies=["A"])["C1"]
    assert not c.added_mass.any() and c.timdel == 0.1


def test_body_not_defined(tmp_path):
    raises(tmp_path, DECK, 8, "CHBDY_A", bodies=(), match="'A' is not defined before")
    raises(tmp_path, DECK.replace("\nB\nCOUP ADDE", "\nX\nCOUP ADDE"), 9, "CHBDY_B")
    # declared, but only after the coupling
    late = DECK.replace("BODY DATA\nB\n", "") + "BODY DATA\nB\n"
    raises(tmp_path, late, 7, "CHBDY_B", match="not defined before the coupling")


def test_dof_outside_1_to_6(tmp_path):
    raises(tmp_path, DECK.replace("3 1 2\n", "3 7 2\n"), 20, "IDOF_A", match="1…6")
    raises(tmp_path, DECK.replace("2 3 3\n", "2 3 0\n"), 23, "IDOF_B")


def test_fewer_and_more_values_than_nret(tmp_path):
    raises(tmp_path, DECK.replace("3 1 2\n", "4 1 2\n"), 22, "RETij(4)",
           match="NRETij = 4 but 3 values given")
    raises(tmp_path, DECK.replace("2 3 3\n", "1 3 3\n"), 24, "RETij(2)", match="NRETij = 1 but 2")
    # values over several lines without '&'
    raises(tmp_path, DECK.replace("1.0 0.5 &\n", "1.0 0.5\n"), 21, "RETij(3)", match="'&'")


def test_non_number(tmp_path):
    raises(tmp_path, DECK.replace("0.25\n2 3", "0.2x5\n2 3"), 22, "RETij(3)", match="number")
    raises(tmp_path, DECK.replace("0 0 3 0 0 0", "0 0 three 0 0 0"), 13, "AM33")
    raises(tmp_path, DECK.replace("\n0.1\n", "\nfast\n"), 18, "TIMDEL")
    raises(tmp_path, DECK.replace("3 1 2\n", "3.5 1 2\n"), 20, "NRETij", match="integer")


def test_duplicate_chcpl(tmp_path):
    second = DECK.split("HYDR COUP DATA")[1]
    raises(tmp_path, DECK + "HYDR COUP DATA" + second, 26, "CHCPL",
           match="duplicate coupling identifier 'C1'")


def test_pair_coupled_twice(tmp_path):
    second = "HYDR COUP DATA\nC2\nt\nt\nB\nA\nCOUP RETA FUNC\n0.1\nRETA ELEM DATA\n2 1 1\n1 0\n"
    raises(tmp_path, DECK + second, 30, "CHBDY_B", match="already coupled by 'C1'")


@pytest.mark.parametrize("value", ["0", "-0.1", "0.0E0"])
def test_timdel_not_positive(tmp_path, value):
    raises(tmp_path, DECK.replace("\n0.1\n", f"\n{value}\n"), 18, "TIMDEL", match="> 0")


def test_duplicate_block(tmp_path):
    raises(tmp_path, DECK + "2 1 2\n1 1\n", 25, "IDOF_A IDOF_B", match="first at line 20")


def test_structure_errors(tmp_path):
    raises(tmp_path, DECK.replace("HYDR COUP DATA", "HYDR COUPLING"), 4, "data group")
    raises(tmp_path, DECK.replace("text two\n", ""), 9, "CHBDY_B", match="TEXT")
    raises(tmp_path, DECK.replace("RETA ELEM DATA\n", "RETA ELEM\n"), 19, "RETArdation ELEment DATA")
    raises(tmp_path, DECK.split("COUP ADDE MASS")[0], 9, "COUPled ADDEd MASS", match="end of file")
    raises(tmp_path, DECK.split("3 1 2")[0], 19, "NRETij", match="at least one")
    raises(tmp_path, DECK.replace("0 0 0 0 5 0\n", "0 0 0 0 5\n"), 15, "AM56")
    raises(tmp_path, DECK[: DECK.index("4.0 2.0")], 23, "RETij(1)", match="end of file")
    raises(tmp_path, DECK.replace("BODY DATA\nB\n", "BODY DATA\nB\nBODY DATA\nB\n"), 5, "CHBDY",
           match="declared twice")


def test_self_coupling_added_mass_must_be_symmetric(tmp_path):
    self_deck = DECK.replace("\nA\nB\nCOUP", "\nB\nB\nCOUP")
    c = read_couplings(deck(tmp_path, self_deck))["C1"]          # diagonal: fine, no scene bodies
    assert c.body_a == c.body_b == "B"
    raises(tmp_path, self_deck.replace("0 2 0 0 0 0", "0 2 0 0 0 7"), 10, "AM26", bodies=(),
           match="symmetric")


def test_writer_round_trip(tmp_path):
    """decks.simo.format_coupling/write_couplings write what read_couplings reads back."""
    from hydrofmu.decks.simo import format_coupling, write_couplings
    rng = np.random.default_rng(5)
    am = rng.normal(size=(6, 6)) * 1e5
    kernels = {(1, 1): rng.normal(size=13), (2, 6): rng.normal(size=7) * 1e3}
    path = write_couplings(tmp_path / "w.sim", [format_coupling("AB", "A", "B", am, kernels, 0.25)])
    got = read_couplings(path, bodies={"A", "B"})["AB"]
    np.testing.assert_allclose(got.added_mass, am, rtol=1e-9)
    assert got.timdel == 0.25 and set(got.kernels) == set(kernels)
    for ij, h in kernels.items():
        np.testing.assert_allclose(got.kernels[ij], h, rtol=1e-9)
