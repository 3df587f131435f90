"""Current profiles read from the vendors' own files: a RIFLEX INPMOD file's environment
(``NEW CURRENT STATE`` among the groups the reader skips) and a DeepLines data file's
``*CURPROF``/``*CURRENT``, each written here from the manuals' layouts with every FREAD (or
DeepLines) convention; the profile read gives bit for bit the loads of the same profile
given in the scene; hand-computed loads at two depths from the file's profile; every
malformed current group is one error naming file, line and field, exit 2, nothing written."""
import numpy as np
import pytest

from hydrofmu.decks.deeplines import read_current_polars, read_current_profile
from hydrofmu.decks.riflex import read_components, read_current_states
from hydrofmu.errors import InputError
from hydrofmu.physics.current import CurrentProfile
from hydrofmu.physics.lumped import LumpedBody
from hydrofmu.physics.state import Env, Motion
from hydrofmu.scene import load_scene

from conftest import build, write_scene
from test_current_profile import ROWS, SCENE, _loads, hand_loads, one_scene_error

# ROWS, from the top down: 1.0 m/s going to 0° at the surface, 0.4 m/s going to 90° at
# 20 m, 0.1 m/s at 100 m (tests/test_current_profile.py, with its scene and hand values).

# An INPMOD file written from the RIFLEX manual's layouts: identification, unit names (all
# defaults by '/': s m kg kN 9.81 0.001), a riser and a BODY component, then data group D:
# two environments, the first with waves, constants and two current states, the second
# with a blank text line and no current; END and what follows is not read.  State 1 uses
# the FREAD conventions: '/' for L_EXT's default, commas, a tab, '&' continuation, comments,
# a D exponent, and lower-case full words for the group identifier.
RIFLEX = """\
INPMod IDENtification TEXT 4.0
current states among other data groups, from the RIFLEX manual's layouts


UNIT NAMe SPECification
' all defaults by '/': s m kg kN 9.81 0.001
{units}
NEW SINGle RISEr
AR riser1
NEW COMPonent BODY
buoy1
2.5 4.0
GLOBAL 0.12 0.13 0.3 1000.0 1100.0 2500.0
'
ENVIronment IDENtification
North Sea, 100-year current
NS100
WATErdepth AND WAVEtype
' WDEPTH NOIRW NORW NCUSTA (NWISTA left to its default)
350.0 1 1 2
ENVIronment CONStants
1.3 1025.0
NEW IRREgular SEAState
1 3 0 0 0
WAVE SPECtrum WIND
0.6 / / / / /
DIRECTION PARAMETERS
0.0 2.0
REGULAR WAVE DATA
1 2.0 10.0 0.0
new current state                ' full words, lower case
' ICUSTA NCULEV L_EXT
1 3 /
' CURLEV CURDIR CURVEL
{level1}
-20.0	90.0 &
 0.4                             ' continued
-1.0D2, 90.0, 0.1
NEW CURRent STATe
2 1
0.0 45.0 0.5
'
ENVIronment IDENtification

CALM
WATErdepth AND WAVEtype
350.0 0 0 0
ENVIronment CONStants
1.3 1025.0
END
NEW CURRENT STATE
9 1
5.0 0.0 1.0
"""


def riflex_file(tmp_path, units="/ / / / / /", level1="0.0, 0.0, 1.0", name="riser.inp", text=RIFLEX):
    path = tmp_path / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text.format(units=units, level1=level1))
    return path


def test_riflex_current_states_among_other_groups(tmp_path):
    path = riflex_file(tmp_path)
    states = read_current_states(path)
    assert list(states) == ["NS100", "CALM"] and list(states["NS100"]) == [1, 2] and states["CALM"] == {}
    assert states["NS100"][1].rows == ROWS                                  # bit for bit
    assert states["NS100"][2].rows == [[0.0, 0.5, 45.0]]
    assert (states["NS100"][1].line, states["NS100"][2].line) == (33, 40)   # the ICUSTA lines
    # the component reader skips the whole data group D (and reads its units line)
    assert list(read_components(path, units="kg-kN")) == ["buoy1"]


def test_riflex_units_line_is_checked(tmp_path):
    """CURLEV [L] and CURVEL [L/T] are m and m/s in every system hydrofmu reads: the units
    line is checked (length and time must be m and s, and a scene's current_units must
    match), no value is scaled."""
    path = riflex_file(tmp_path, units="s m Mg kN 9.81 1.0")
    assert read_current_states(path)["NS100"][1].rows == ROWS
    assert read_current_states(path, "Mg-kN")["NS100"][1].rows == ROWS
    with pytest.raises(InputError) as err:
        read_current_states(path, "SI")
    assert (err.value.line, err.value.field) == (7, "UM") and 'current_units = "Mg-kN"' in err.value.message
    with pytest.raises(InputError) as err:
        read_current_states(riflex_file(tmp_path, units="s ft kg kN 32.2 0.001", name="ft.inp"))
    assert (err.value.line, err.value.field) == (7, "UL")


# The same current as DeepLines keywords (principia-support.com keyword list): *CURPROF's
# levels on two lines, *CURRENT's one time line 'TCUR TETC(1) VCUR(1) ...' continued with
# '&' and with commas as the manual prints them; other keywords skipped, *CURRENTPOL too.
DEEPLINES = """\
*UNITS
 SI
*CURRENTPOL,NAME=FPSO
 0. 0. -10. 1000.
 0. 1. 0. 0.
 90. 0. 1. 0.
! levels ZCUR [m], z up
*CURPROF
 0.  -20.
 -100.
*CURRENT
 0. &
 0. 1.0 , 90.,0.4 &
 90. 0.1
*LINE
 x
"""


def test_deeplines_profile_among_other_keywords(tmp_path):
    path = tmp_path / "model.dat"
    path.write_text(DEEPLINES)
    assert read_current_profile(path) == ROWS
    assert list(read_current_polars(path)) == ["FPSO"]
    # no *CURPROF: NZCUR = 1, a uniform current (the manual's example a), data on the
    # keyword line continued); heading 180 = towards −x
    uniform = tmp_path / "uniform.dat"
    uniform.write_text("*CURRENT 1. &\n 180 1.34\n")
    assert read_current_profile(uniform) == [[0.0, 1.34, 180.0]]


# --- scenes name the file; the loads equal those of the profile given inline ------------
FROM_RIFLEX = ('current_deck = "riser.inp"\ncurrent_format = "riflex"\ncurrent_environment = "NS100"\n'
               'current_state = 1\ncurrent_units = "kg-kN"')


def test_scene_profiles_from_files_equal_the_inline_profile(tmp_path):
    riflex_file(tmp_path)
    (tmp_path / "model.dat").write_text(DEEPLINES)
    inline = load_scene(write_scene(tmp_path, SCENE.format(name="i", current=f"current_profile = {ROWS}")))
    motions = [Motion(np.array([1.0, 2.0, z]), np.array([0.0, 0.05, 0.3]), np.array([0.1, -0.2, 0.0, 0, 0, 0.01]))
               for z in (0.0, -5.0, -40.0, -150.0)]
    for current in (FROM_RIFLEX, 'current_deck = "model.dat"\ncurrent_format = "deeplines"'):
        scene = load_scene(write_scene(tmp_path, SCENE.format(name="f", current=current)))
        assert scene.current_profile == inline.current_profile == ROWS
        assert (scene.current_speed, scene.current_direction) == (1.0, 0.0)
        envs = [Env(1025.0, 9.81, s.current_speed, s.current_direction, CurrentProfile.from_rows(s.current_profile))
                for s in (scene, inline)]
        body = LumpedBody("b", [2.0, 1.0, -30.0], cd=[100.0, 200.0, 50.0])
        for m in motions:
            assert body.load(m, envs[0]).tolist() == body.load(m, envs[1]).tolist()
    # one environment with one state: both keys may be left out
    one = riflex_file(tmp_path, name="one.inp", text=RIFLEX.split("NEW CURRent STATe")[0] + "END\n")
    scene = load_scene(write_scene(tmp_path, SCENE.format(
        name="f", current=f'current_deck = "{one.name}"\ncurrent_format = "riflex"')))
    assert scene.current_profile == ROWS


def test_fmus_from_the_riflex_file_equal_inline_and_hand_loads_at_two_depths(tmp_path):
    """Built FMUs: the RIFLEX file's current gives bit for bit the loads of the inline
    profile; by hand at the two depths of the two effects (the AQWA reference point at
    z = −5 and the clump 30 m below it), also with the inputs scaling and turning it."""
    riflex_file(tmp_path / "f")
    from_file = build(tmp_path / "f", SCENE.format(name="fil", current=FROM_RIFLEX))
    inline = build(tmp_path / "i", SCENE.format(name="inl", current=f"current_profile = {ROWS}"))
    for speed, turn in ((None, 0.0), (2.0, 40.0)):
        got, _ = _loads(from_file, "fil", speed, None if speed is None else turn)
        ref, _ = _loads(inline, "inl", speed, None if speed is None else turn)
        for k in got:
            assert got[k].tolist() == ref[k].tolist()
        hand_loads(got, 1.0 if speed is None else speed, turn)


# --- malformed current groups: one error naming file, line and field -------------------
def _riflex_bad(state):
    """RIFLEX with current state 1 (from its ICUSTA line, line 33 on) replaced by ``state``."""
    return RIFLEX[:RIFLEX.index("1 3 /\n")] + state + RIFLEX[RIFLEX.index("NEW CURRent STATe"):]


BAD_RIFLEX = {
    "level above the surface": ("1 2\n0.5 0.0 1.0\n-20.0 90.0 0.4\n", 34, "CURLEV(1)", "above"),
    "levels not ordered": ("1 3\n0.0 0.0 1.0\n-50.0 90.0 0.4\n-20.0 90.0 0.2\n", 36, "CURLEV(3)", "decreasing z"),
    "missing value": ("1 2\n0.0 0.0 1.0\n-20.0 90.0\n", 35, "CURVEL(2)", "missing value"),
    "missing level line": ("1 3\n0.0 0.0 1.0\n-20.0 90.0 0.4\n", 36, "CURLEV(3)", "NCULEV = 3 but 2"),
    "slash without a default": ("1 2\n0.0 0.0 1.0\n-20.0 90.0 /\n", 35, "CURVEL(2)", "has none"),
    "no levels": ("1 0\n", 33, "NCULEV", "1 ... 30"),
    "levels on an external file": ("1 3 1\ncurrent.dat\n", 33, "L_EXT", "CURMOD"),
    "states out of order": ("2 1\n0.0 0.0 1.0\n", 33, "ICUSTA", "expected 1"),
    "negative speed": ("1 2\n0.0 0.0 1.0\n-20.0 90.0 -0.4\n", 35, "CURVEL(2)", "negative"),
}


@pytest.mark.parametrize("case", BAD_RIFLEX)
def test_malformed_riflex_current_is_one_error(tmp_path, case):
    state, line, field, match = BAD_RIFLEX[case]
    path = riflex_file(tmp_path, text=_riflex_bad(state))
    with pytest.raises(InputError) as err:
        read_current_states(path)
    e = err.value
    assert (e.path, e.line, e.field) == (str(path), line, field), str(e)
    assert match in e.message, e.message


BAD_DEEPLINES = {
    "level above the surface": ("*CURPROF\n 5. -20.\n*CURRENT\n 0. 0. 1.0 90. 0.4\n", 2, "ZCUR(1)", "above"),
    "levels not ordered": ("*CURPROF\n 0. -50. &\n -20.\n*CURRENT\n 0. 0. 1.0 90. 0.4 90. 0.2\n", 3, "ZCUR(3)",
                           "ordered"),
    "missing value": ("*CURPROF\n 0. -20.\n*CURRENT\n 0. 0. 1.0 &\n 90.\n", 5, "VCUR(1,2)", "missing value"),
    "too many values": ("*CURPROF\n 0. -20.\n*CURRENT\n 0. 0. 1.0 90. 0.4 90.\n", 4, "TETC(1,3)", "too many"),
    "a current changing in time": ("*CURRENT\n 0. 0. 1.0\n 10. 0. 2.0\n", 3, "TCUR(2)", "changing in time"),
    "*CURPROF after *CURRENT": ("*CURRENT\n 0. 0. 1.0 90. 0.4\n*CURPROF\n 0. -20.\n", 3, "*CURPROF", "precede"),
}


@pytest.mark.parametrize("case", BAD_DEEPLINES)
def test_malformed_deeplines_current_is_one_error(tmp_path, case):
    text, line, field, match = BAD_DEEPLINES[case]
    path = tmp_path / "bad.dat"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        read_current_profile(path)
    e = err.value
    assert (e.path, e.line, e.field) == (str(path), line, field), str(e)
    assert match in e.message, e.message


BAD_SCENE = {
    "file: levels not ordered": (FROM_RIFLEX, "environment.current_deck", "riser.inp:36: CURLEV(3):"),
    "no such environment": (FROM_RIFLEX.replace('"NS100"', '"GOM"'), "environment.current_environment",
                            "it has: NS100"),
    "no such state": (FROM_RIFLEX.replace("current_state = 1", "current_state = 5"), "environment.current_state",
                      "it has: 1, 2"),
    "state not named": (FROM_RIFLEX.replace("current_state = 1\n", ""), "environment.current_state", "name one"),
    "wrong units": (FROM_RIFLEX.replace("kg-kN", "SI"), "environment.current_deck", 'current_units = "kg-kN"'),
    "riflex key for another format": ('current_deck = "riser.inp"\ncurrent_format = "sima"\ncurrent_state = 1',
                                      "environment.current_state", 'only for current_format = "riflex"'),
    "key without a file": ("current_state = 1", "environment.current_state", "goes with current_deck"),
}


@pytest.mark.parametrize("case", BAD_SCENE)
def test_malformed_current_in_a_scene_is_one_error_exit_2_nothing_written(tmp_path, case):
    current, key, match = BAD_SCENE[case]
    riflex_file(tmp_path, text=_riflex_bad(BAD_RIFLEX["levels not ordered"][0]) if case.startswith("file") else RIFLEX)
    one_scene_error(write_scene(tmp_path, SCENE.format(name="bad", current=current)), key, match)
