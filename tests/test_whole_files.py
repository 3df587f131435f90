"""Whole vendor input files: each reader picks its groups out of a file full of other data
groups (written here from the manuals' layouts), follows each FREAD convention, and gives
the same loads as the bare group.  Unit systems: converted when the scene says, a wrong
declaration is one error."""
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks.aqwa import read_viscous_drag
from hydrofmu.decks.deeplines import read_current_polars
from hydrofmu.decks.riflex import read_components
from hydrofmu.decks.simo import read_couplings
from hydrofmu.errors import InputError
from hydrofmu.physics.coupling import Coupling
from hydrofmu.physics.current_polar import CurrentPolar
from hydrofmu.physics.state import Env, Motion
from hydrofmu.physics.viscous_drag import ViscousDrag

MOTION = Motion(np.array([1.0, -2.0, 0.5]), np.array([0.05, -0.03, 0.4]),
                np.array([0.3, -0.2, 0.1, 0.02, -0.01, 0.05]), np.array([0.1, 0.2, -0.3, 0.01, 0.02, -0.03]))
ENV = Env(current_speed=0.8, current_direction=30.0)


def write(tmp_path, text, name):
    path = tmp_path / name
    path.write_text(text)
    return path


# --- SIMO ------------------------------------------------------------------------------
SIMO_BARE = """\
BODY DATA
B
HYDR COUP DATA
C1
text one
text two
A
B
COUP ADDE MASS
1 0 0 0 0 0.5
0 2 0 0 0 0
0 0 3 0 0 0
0 0 0 4 0 0
0 0 0 0 5 0
0.25 0 0 0 0 6
COUP RETA FUNC
0.1
RETA ELEM DATA
3 1 2
1.0 0.5 0.25
2 3 3
4.0 2.0
"""

# A system description file: the manual's file heading (SYSTem DESCription SIMO, three
# TXSYS lines, the units line, DEPTH DIRSLO SLOPE), a body, an environment with regular
# and irregular waves, the coupling written with the FREAD conventions, END and beyond.
SIMO_WHOLE = """\
SYSTem DESCription SIMO
Two barges side by side
written in the test from the SIMO manual's layouts
'   LENUNI TIMUNI MASUNI GRAV RHOW RHOA WAKIVI AIRKIVI
{units}
' DEPTH DIRSLO SLOPE
300.0 / /
'
BODY DATA SPECification
B
'
ENVIronment DATA SPECification
calm sea
with some waves
and a current
REGUlar WAVE SPECification
reg1
2
1.0 8.0 0.0 90.0
0.5, 6.0, 45.0, 180.0
IRREgular WAVE SPECification
irr1
21 0 0 0
'
hydrodynamic coupling data            ' full words, lower case
C1
text one
text two
A
B
COUPLED ADDED MASS
' AMi1 AMi2 AMi3 AMi4 AMi5 AMi6
{am1}, /, /, /, /, {am16}            ' slash: no term
/ {am2} / / / /
0 0 {am3}D0 0 0 0
0	0	0	{am4}	0	0
0 0 0 &
0 {am5} 0
{am61} 0 0 0 0 {am6}
COUP RETA FUNC
0.1
RETA ELEM DATA
3 1 2
{r1} &
{r2}, {r3}   ' continued
RETArdation ELEment DATA                 ' again before the next block
2 3 3
{r4}D+00 {r5}
'
END
anything after END is not read: HYDR COUP DATA
"""


def simo_whole(tmp_path, scale=1.0, units="m s kg 9.81 1025.0 0.00125 1.188e-6 1.516e-5", name="whole.sys"):
    """The whole file with every mass and kernel value divided by ``scale``."""
    v = dict(am1=1, am16=0.5, am2=2, am3=3, am4=4, am5=5, am61=0.25, am6=6, r1=1.0, r2=0.5, r3=0.25, r4=4.0, r5=2.0)
    text = SIMO_WHOLE.format(units=units, **{k: repr(x / scale) for k, x in v.items()})
    return write(tmp_path, text, name)


def simo_loads(data):
    """Acceleration load and memory loads of both sides over a few steps."""
    c = Coupling.from_deck(data)
    out = [c.acceleration_load(s, MOTION.acceleration) for s in c.sides]
    for k in range(5):
        v = MOTION.velocity * np.cos(0.3 * k)
        out += [c.memory[s].advance(0.07, v) for s in c.sides]
    return np.array(out)


def test_simo_whole_file_equals_bare_group(tmp_path):
    bare = read_couplings(write(tmp_path, SIMO_BARE, "bare.sys"), bodies=["A"])["C1"]
    whole = read_couplings(simo_whole(tmp_path), bodies=["A"])
    assert list(whole) == ["C1"]
    w = whole["C1"]
    np.testing.assert_array_equal(w.added_mass, bare.added_mass)
    assert w.added_mass[0, 5] == 0.5 and w.added_mass[5, 0] == 0.25 and w.added_mass[1, 0] == 0.0
    assert w.timdel == bare.timdel and sorted(w.kernels) == sorted(bare.kernels) == [(1, 2), (3, 3)]
    for ij in bare.kernels:
        np.testing.assert_array_equal(w.kernels[ij], bare.kernels[ij])
    np.testing.assert_array_equal(simo_loads(w), simo_loads(bare))
    assert np.abs(simo_loads(bare)).max() > 0


def test_simo_file_in_mg_kn_is_converted(tmp_path):
    """The same coupling in Mg and kN (values / 1000, RHOW 1.025, MASUNI Mg or the default
    '/'): read with units = "Mg-kN" it gives the SI loads."""
    bare = read_couplings(write(tmp_path, SIMO_BARE, "bare.sys"), bodies=["A"])["C1"]
    for units in ("m s Mg 9.81 1.025", "/ / / / /"):
        w = read_couplings(simo_whole(tmp_path, 1000.0, units), bodies=["A"], units="Mg-kN")["C1"]
        np.testing.assert_allclose(simo_loads(w), simo_loads(bare), rtol=1e-12)


@pytest.mark.parametrize("units_line, scene, field, match", [
    ("m s Mg 9.81 1.025", "SI", "MASUNI", 'set units = "Mg-kN"'),       # file in Mg read as SI
    ("m s kg 9.81 1025.0", "Mg-kN", "MASUNI", 'set units = "SI"'),
    ("m s kg 9.81 1.025", "SI", "RHOW", "does not fit MASUNI"),          # declared kg, density in Mg
    ("ft s kg 32.2 1025.0", "SI", "LENUNI", "unsupported unit"),
])
def test_simo_wrong_declaration_is_one_error(tmp_path, units_line, scene, field, match):
    path = simo_whole(tmp_path, units=units_line)
    with pytest.raises(InputError) as err:
        read_couplings(path, bodies=["A"], units=scene)
    e = err.value
    assert (Path(e.path), e.line, e.field) == (path, 5, field), str(e)
    assert match in e.message


# One FREAD convention at a time on the bare group: each reads the same data.
SIMO_CONVENTIONS = {
    "keywords in full and lower case": [("HYDR COUP DATA", "Hydrodynamic Coupling Data"),
                                        ("COUP ADDE MASS", "coupled added masses")],
    "slash for a value": [("0 0 3 0 0 0", "/ / 3 / / /")],
    "ampersand": [("0 0 0 4 0 0", "0 0 &\n0 4 &\n0 0"), ("1.0 0.5 0.25", "1.0 &\n 0.5 &\n 0.25")],
    "comments": [("C1\n", "' identifier next\nC1   ' CHCPL\n"), ("0.1\n", "0.1 ' TIMDEL [s]\n'\n")],
    "fortran D exponent": [("0 2 0 0 0 0", "0 2.0D0 0 0 0 0"), ("4.0 2.0", "0.4D+1 200.0d-2")],
    "commas and blanks": [("0 0 0 0 5 0", "0, 0,0 ,0,   5 , 0"), ("3 1 2", "3,1,2")],
    "tabs": [("0.25 0 0 0 0 6", "0.25\t0\t0\t0\t0\t6")],
    "element identifier before each block": [("2 3 3", "RETA ELEM DATA\n2 3 3")],
    "END ends the input": [("4.0 2.0\n", "4.0 2.0\nEND\nHYDR COUP DATA\nnot read\n")],
}


@pytest.mark.parametrize("case", SIMO_CONVENTIONS)
def test_simo_fread_conventions(tmp_path, case):
    bare = read_couplings(write(tmp_path, SIMO_BARE, "bare.sys"), bodies=["A"])["C1"]
    text = SIMO_BARE
    for old, new in SIMO_CONVENTIONS[case]:
        assert old in text
        text = text.replace(old, new, 1)
    got = read_couplings(write(tmp_path, text, "conv.sys"), bodies=["A"])["C1"]
    np.testing.assert_array_equal(got.added_mass, bare.added_mass)
    assert got.kernels.keys() == bare.kernels.keys()
    for ij in bare.kernels:
        np.testing.assert_array_equal(got.kernels[ij], bare.kernels[ij])


def test_slash_without_a_default_is_an_error(tmp_path):
    path = write(tmp_path, SIMO_BARE.replace("\n0.1\n", "\n/\n"), "slash.sys")
    with pytest.raises(InputError) as err:
        read_couplings(path, bodies=["A"])
    assert (err.value.line, err.value.field) == (17, "TIMDEL") and "has none" in err.value.message
    # a truncated row is not filled with defaults: only '/' asks for one
    path = write(tmp_path, SIMO_BARE.replace("0 0 0 0 5 0", "0 0 0 0 5"), "short.sys")
    with pytest.raises(InputError) as err:
        read_couplings(path, bodies=["A"])
    assert (err.value.line, err.value.field) == (14, "AM56")


# --- RIFLEX ----------------------------------------------------------------------------
RIFLEX_BARE = """\
NEW COMPonent BODY
buoy1
2500.0 4.0
GLOBAL 120.0 130.0 300.0 1000.0 1100.0 2500.0
NEW COMPonent CONB
joint
100.0 0.05
LOCAL 10.0 10.0 0.0 20.0 20.0 0.0
1 1 0
"""

# An INPMOD file: identification, unit names, a riser, cross-section and flex-joint
# components around ours, an environment, END and beyond.
RIFLEX_WHOLE = """\
INPMod IDENtification TEXT 4.0
Two components among other INPMOD data groups
written in the test from the RIFLEX manual's layouts

UNIT NAMe SPECification
' UT UL UM UF GRAV GCONS
{units}
'
NEW SINGle RISEr
AR riser1
NEW COMPonent CRS0
riser 20.
120.0 0.05 0.0 0.0 1
'
new component body               ' lower case, full words
buoy1
{am1}, {ae1}
GLOBAL {cd1} &
{cd2} {cd3} {amx1}D0 {amy1} {amz1}
NEW COMPonent FLEX
flexj
1.0E6 1.0E6 0.0
NEW COMP CONB
joint
{am2} {ae2}   ' AM AE
LOCAL {cd4} {cd4} / {amx2} {amx2} /
1 1 /
ENVIronment IDENtification
calm
END
NEW COMPonent BODY
notread
"""


def riflex_whole(tmp_path, mass=1.0, force=1.0, units="s m kg N 9.81 1.0"):
    v = dict(am1=(2500.0, mass), ae1=(4.0, 1.0), cd1=(120.0, force), cd2=(130.0, force), cd3=(300.0, force),
             amx1=(1000.0, mass), amy1=(1100.0, mass), amz1=(2500.0, mass), am2=(100.0, mass), ae2=(0.05, 1.0),
             cd4=(10.0, force), amx2=(20.0, mass))
    text = RIFLEX_WHOLE.format(units=units, **{k: repr(x / f) for k, (x, f) in v.items()})
    return write(tmp_path, text, "whole.inp")


def lumped_loads(comp):
    lb = comp.lumped([2.0, -1.0, -3.0])
    return np.concatenate([lb.load(MOTION, ENV), lb.mass_matrix(MOTION).ravel(), lb.velocity_load(MOTION)])


def test_riflex_whole_file_equals_bare_group(tmp_path):
    bare = read_components(write(tmp_path, RIFLEX_BARE, "bare.inp"))
    whole = read_components(riflex_whole(tmp_path))
    assert list(whole) == ["buoy1", "joint"]
    for name in bare:
        np.testing.assert_array_equal(lumped_loads(whole[name]), lumped_loads(bare[name]))
    assert whole["joint"].codes == bare["joint"].codes == (1, 1, 0)


@pytest.mark.parametrize("units, line, mass, force", [
    ("Mg-kN", "s m Mg kN 9.81 1.0", 1000.0, 1000.0),
    ("kg-kN", "/ / / / / /", 1.0, 1000.0),             # RIFLEX's default unit names: s m kg kN, GCONS 0.001
])
def test_riflex_file_in_other_units_is_converted(tmp_path, units, line, mass, force):
    bare = read_components(write(tmp_path, RIFLEX_BARE, "bare.inp"))
    whole = read_components(riflex_whole(tmp_path, mass, force, line), units=units)
    for name in bare:
        np.testing.assert_allclose(lumped_loads(whole[name]), lumped_loads(bare[name]), rtol=1e-12)


@pytest.mark.parametrize("units_line, scene, field, match", [
    ("s m Mg kN 9.81 1.0", "SI", "UM", 'set units = "Mg-kN"'),
    ("s m kg N 9.81 1.0", "Mg-kN", "UM", 'set units = "SI"'),
    ("s m Mg kN 9.81 0.001", "Mg-kN", "GCONS", "expected 1"),
    ("s m kg lbf 9.81 1.0", "SI", "UF", "unsupported force unit"),
])
def test_riflex_wrong_declaration_is_one_error(tmp_path, units_line, scene, field, match):
    path = riflex_whole(tmp_path, units=units_line)
    with pytest.raises(InputError) as err:
        read_components(path, units=scene)
    e = err.value
    assert (Path(e.path), e.line, e.field) == (path, 7, field), str(e)
    assert match in e.message


RIFLEX_CONVENTIONS = {
    "keywords": [("NEW COMPonent BODY", "NEW COMPONENTS BODY"), ("NEW COMPonent CONB", "new comp conb")],
    "slash for a value": [("1 1 0", "1 1 /"), ("LOCAL 10.0 10.0 0.0", "LOCAL 10.0 10.0 /")],
    "ampersand": [("GLOBAL 120.0 130.0", "GLOBAL 120.0 &\n130.0")],
    "comments": [("buoy1\n", "' CMPTYP-ID\nbuoy1   ' the buoy\n")],
    "fortran D exponent": [("2500.0 4.0", "2.5D3 4.0d0")],
    "commas and blanks": [("1 1 0", "1,1 , 0"), ("100.0 0.05", "100.0,0.05")],
    "tabs": [("2500.0 4.0", "2500.0\t4.0")],
    "END ends the input": [("1 1 0\n", "1 1 0\nEND\nNEW COMPonent BODY\n")],
}


@pytest.mark.parametrize("case", RIFLEX_CONVENTIONS)
def test_riflex_fread_conventions(tmp_path, case):
    bare = read_components(write(tmp_path, RIFLEX_BARE, "bare.inp"))
    text = RIFLEX_BARE
    for old, new in RIFLEX_CONVENTIONS[case]:
        assert old in text
        text = text.replace(old, new, 1)
    got = read_components(write(tmp_path, text, "conv.inp"))
    assert list(got) == list(bare) and got["joint"].codes == bare["joint"].codes
    for name in bare:
        np.testing.assert_array_equal(lumped_loads(got[name]), lumped_loads(bare[name]))


# --- DeepLines -------------------------------------------------------------------------
POLAR = """\
*CURRENTPOL,NAME=FPSO
  0.    0.    -5.   1000.
  0.    1.0   0.0   0.0
  90.   0.0   1.0   2.0
  180. -1.0   0.0   0.0
  270.  0.0  -1.0  -2.0
"""

DEEPLINES_WHOLE = """\
! a DeepLines data file: other keywords around ours
*UNITS
 SI
*CURRENT
 1.2  45.
*CURPROF
 0.  1.0
 -100. 0.5
*LINE,NAME=RISER1
 not numbers, and not ours
""" + POLAR + """\
*WIND
 10.0 90.0
"""


def test_deeplines_whole_file_equals_bare_block(tmp_path):
    bare = read_current_polars(write(tmp_path, POLAR, "bare.dat"))["FPSO"]
    whole = read_current_polars(write(tmp_path, DEEPLINES_WHOLE, "whole.dat"))
    assert list(whole) == ["FPSO"]
    loads = [CurrentPolar.from_deck(d, "none").load(MOTION, ENV) for d in (bare, whole["FPSO"])]
    np.testing.assert_array_equal(loads[0], loads[1])
    assert np.abs(loads[0]).max() > 0


# --- AQWA ------------------------------------------------------------------------------
DRAG = """\
*Viscous Drag
FLOATING BODY=FPSO
TYPE=MATRIX
OPTION=RELATIVE
1.1E5, 0.0, 0.0, 0.0, 0.0, 0.0
0.0, 2.2E5, 0.0, 0.0, 0.0, 1.5E4
0.0, 0.0, 3.3E5, 0.0, 0.0, 0.0
0.0, 0.0, 0.0, 4.4E8, 0.0, 0.0
0.0, 0.0, 0.0, 0.0, 5.5E9, 0.0
0.0, 1.5E4, 0.0, 0.0, 0.0, 6.6E9
"""

AQWA_WHOLE = """\
an AQWA input: lines before the first section and other sections are skipped
*Structure
FLOATING BODY=FPSO
1 2 3
*Mass
FLOATING BODY=FPSO
2.0E8
""" + DRAG + """\
*Current
SPEED=1.0
DIRECTION=90
"""


def test_aqwa_whole_input_equals_bare_section(tmp_path):
    bare = read_viscous_drag(write(tmp_path, DRAG, "bare.dat"))["FPSO"]
    whole = read_viscous_drag(write(tmp_path, AQWA_WHOLE, "whole.dat"))
    assert list(whole) == ["FPSO"]
    loads = [ViscousDrag("d", d.matrix, d.relative).load(MOTION, ENV) for d in (bare, whole["FPSO"])]
    np.testing.assert_array_equal(loads[0], loads[1])
    assert np.abs(loads[0]).max() > 0


# --- scenes name the file's unit system --------------------------------------------------
SCENE = """\
[bodies.barge]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
[[bodies.barge.effects]]
type = "riflex_body"
deck = "whole.inp"
component = "buoy1"
offset = [0.0, 0.0, -5.0]
{units}
"""


def test_scene_converts_a_file_it_names_the_units_of(tmp_path):
    from hydrofmu.scene import load_scene
    riflex_whole(tmp_path, 1000.0, 1000.0, "s m Mg kN 9.81 1.0")
    scene = load_scene(write(tmp_path, SCENE.format(units='units = "Mg-kN"'), "s.toml"))
    data = scene.bodies["barge"].effects[0].data
    assert data["am"] == pytest.approx(2500.0, rel=1e-12) and data["cd"] == pytest.approx([120.0, 130.0, 300.0])
    with pytest.raises(InputError) as err:           # the scene forgets: the file's declaration catches it
        load_scene(write(tmp_path, SCENE.format(units=""), "s.toml"))
    assert "whole.inp:7: UM:" in str(err.value) and 'units = "Mg-kN"' in str(err.value)
    with pytest.raises(InputError) as err:
        load_scene(write(tmp_path, SCENE.format(units='units = "tons"'), "s.toml"))
    assert err.value.field == "bodies.barge.effects[0].units"
