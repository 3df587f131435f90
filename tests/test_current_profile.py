"""Current profiles: each effect takes the current at its own point (hand-computed loads at
two depths), one level is exactly today's uniform current, the FMU inputs scale and turn
the profile as documented, and every malformed profile is one error naming file, line (or
key path) and field, with nothing written."""
import math
import subprocess
import sys

import numpy as np
import pytest

from hydrofmu.decks.deeplines import read_current_profile
from hydrofmu.decks.simo import read_current_profile as read_sima
from hydrofmu.errors import InputError
from hydrofmu.physics.current import CurrentProfile
from hydrofmu.physics.current_polar import CurrentPolar
from hydrofmu.physics.lumped import LumpedBody
from hydrofmu.physics.state import Env, Motion
from hydrofmu.physics.viscous_drag import ViscousDrag
from hydrofmu.scene import load_scene

from conftest import build, write_scene
from test_fmu import Fmu

RHO = 1025.0
# From the top down: 1.0 m/s going to 0° at the surface, 0.4 m/s going to 90° at 20 m,
# 0.1 m/s at 100 m.
ROWS = [[0.0, 1.0, 0.0], [-20.0, 0.4, 90.0], [-100.0, 0.1, 90.0]]
PROFILE = CurrentProfile.from_rows(ROWS)
# Hand interpolation at the two depths used below:
#   z = -5:  t = 5/20 between 0 and -20   → U = 1.0 + 0.25·(0.4 − 1.0) = 0.85, β = 22.5°
#   z = -30: t = 10/80 between -20 and -100 → U = 0.4 + 0.125·(0.1 − 0.4) = 0.3625, β = 90°
HAND = {-5.0: (0.85, 22.5), -30.0: (0.3625, 90.0)}


def u(speed, beta):
    b = math.radians(beta)
    return np.array([speed * math.cos(b), speed * math.sin(b), 0.0])


def env(profile=PROFILE, speed=1.0, direction=0.0):
    return Env(RHO, 9.81, speed, direction, profile)


def at_rest(z=0.0):
    return Motion(np.array([3.0, -4.0, z]))


@pytest.mark.parametrize("z", HAND)
def test_riflex_body_takes_the_current_at_its_point(z):
    """Body at the surface, lumped point 'z' below it: drag from the current there."""
    cd = np.array([100.0, 200.0, 50.0])
    body = LumpedBody("b", [2.0, 1.0, z], cd=cd)
    uc = u(*HAND[z])
    force = cd * uc * np.abs(uc)
    moment = np.cross([2.0, 1.0, z], force)
    np.testing.assert_allclose(body.load(at_rest(), env()), np.concatenate([force, moment]), rtol=1e-12, atol=1e-12)
    # the same point reached by the body's own depth: the current follows the point
    below = LumpedBody("b", [2.0, 1.0, 0.0], cd=cd).load(at_rest(z), env())
    np.testing.assert_allclose(below[:3], force, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("z", HAND)
def test_conb_node_takes_the_current_at_the_joint_point(z):
    from hydrofmu.physics.joint import BallJoint
    node = LumpedBody("n", [0.0, 0.0, z], cd=[80.0, 80.0, 0.0])
    joint = BallJoint("j", point_a=[0.0, 0.0, z], point_b=[3.0, -4.0, z], k_lin=1e6, c_lin=0.0, node=node)
    load_a, _ = joint.loads(at_rest(), None, env())
    uc = u(*HAND[z])
    np.testing.assert_allclose(load_a[:3], 80.0 * np.array([1, 1, 0]) * uc * np.abs(uc), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("z", HAND)
def test_currentpol_takes_the_current_at_its_centre(z):
    """Table CXC = cos α, CYC = sin α (linear between 0°, 90°, 180°, 270°), CMZC = 2 m;
    centre (XC, YC, ZC) = (10, 0, z) on a body at rest at the surface."""
    polar = CurrentPolar("p", np.array([0.0, 90.0, 180.0, 270.0]), np.array([1.0, 0.0, -1.0, 0.0]),
                         np.array([0.0, 1.0, 0.0, -1.0]), np.full(4, 2.0), 10.0, 0.0, z, 500.0)
    speed, beta = HAND[z]
    q = 0.5 * RHO * 500.0 * speed ** 2
    cx, cy = (1.0 - beta / 90.0, beta / 90.0)            # linear in α between 0° and 90°
    force = q * np.array([cx, cy, 0.0])
    moment = np.cross([10.0, 0.0, z], force) + [0.0, 0.0, 2.0 * q]
    np.testing.assert_allclose(polar.load(at_rest(), env()), np.concatenate([force, moment]), rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("z", HAND)
def test_aqwa_relative_drag_takes_the_current_at_the_reference_point(z):
    v = np.diag([1e4, 2e4, 3e4, 1e6, 1e6, 1e6])
    uc = u(*HAND[z])
    got = ViscousDrag("d", v, relative=True).load(at_rest(z), env())
    np.testing.assert_allclose(got, np.concatenate([np.diag(v)[:3] * uc * np.abs(uc), np.zeros(3)]),
                               rtol=1e-12, atol=1e-9)


def test_inputs_scale_and_turn_the_profile():
    """current.speed = 2 × the surface speed and current.direction = surface + 40°: every
    level doubles and turns by 40°."""
    for z, (speed, beta) in HAND.items():
        np.testing.assert_allclose(env(speed=2.0, direction=40.0).current_at(z), u(2.0 * speed, beta + 40.0),
                                   rtol=1e-12, atol=1e-15)
    assert env().current_at(7.0).tolist() == env().current_at(0.0).tolist()            # constant above the top
    np.testing.assert_allclose(env().current_at(-500.0), u(0.1, 90.0), rtol=1e-12)      # and below the deepest


def test_directions_interpolate_along_the_shorter_arc():
    p = CurrentProfile.from_rows([[0.0, 1.0, 350.0], [-10.0, 1.0, 10.0]])
    np.testing.assert_allclose(Env(profile=p, current_speed=1.0, current_direction=350.0).current_at(-5.0),
                               u(1.0, 0.0), atol=1e-15)


def test_zero_profile_takes_the_inputs_as_uniform():
    p = CurrentProfile.from_rows([[0.0, 0.0, 10.0], [-30.0, 0.0, 10.0]])
    assert (p.surface_speed, p.surface_direction) == (0.0, 10.0) and p.ratio == (1.0, 1.0)
    np.testing.assert_allclose(Env(profile=p, current_speed=0.5, current_direction=10.0).current_at(-15.0),
                               u(0.5, 10.0), atol=1e-15)


def test_one_level_is_exactly_the_uniform_current():
    one = CurrentProfile.from_rows([[-3.0, 1.2, 30.0]])
    effects = [LumpedBody("b", [1.0, 2.0, -8.0], cd=[10.0, 20.0, 5.0]),
               CurrentPolar("p", np.array([0.0, 120.0, 240.0]), np.array([1.0, -0.5, 0.2]),
                            np.array([0.0, 0.7, -0.6]), np.array([1.0, 2.0, 3.0]), 5.0, 1.0, -4.0, 300.0),
               ViscousDrag("d", np.diag([1e4, 2e4, 3e4, 1e6, 1e6, 1e6]), relative=True)]
    rng = np.random.default_rng(3)
    for _ in range(20):
        m = Motion(rng.normal(size=3) * 5, rng.normal(size=3) * 0.2, rng.normal(size=6))
        speed, direction = rng.uniform(0, 3), rng.uniform(-360, 360)
        for e in effects:
            assert e.load(m, Env(RHO, 9.81, speed, direction, one)).tolist() == \
                e.load(m, Env(RHO, 9.81, speed, direction)).tolist()


# --- through built FMUs ------------------------------------------------------------------
SCENE = """\
[scene]
name = "{name}"
[environment]
{current}
[bodies.barge]
mass = 1.0e6
inertia = [1.0e8, 1.0e8, 1.0e8]
[[bodies.barge.effects]]
type = "riflex_body"
name = "clump"
offset = [0.0, 0.0, -30.0]
cd = [100.0, 200.0, 0.0]
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
matrix = [1.0e4, 2.0e4, 3.0e4, 1.0e6, 1.0e6, 1.0e6]
option = "RELATIVE"
"""


def _loads(folder, name, speed=None, direction=None):
    fmu = Fmu(folder / f"{name}_barge.fmu")
    start = (fmu.get("current.speed", 1)[0], fmu.get("current.direction", 1)[0])
    fmu.set("position", [0.0, 0.0, -5.0])
    fmu.set("velocity", [0.1, -0.2, 0.0, 0.0, 0.0, 0.01])
    if speed is not None:
        fmu.set("current.speed", speed)
        fmu.set("current.direction", direction)
    out = {k: fmu.get(f"{k}.force") for k in ("clump", "viscous_drag")}
    fmu.close()
    return out, start


def test_fmus_one_level_equals_uniform_and_inputs_scale_the_profile(tmp_path):
    uniform = build(tmp_path / "u", SCENE.format(name="uni", current="current_speed = 1.2\ncurrent_direction = 30.0"))
    one = build(tmp_path / "o", SCENE.format(name="one", current="current_profile = [[0.0, 1.2, 30.0]]"))
    prof = build(tmp_path / "p", SCENE.format(name="pro", current=f"current_profile = {ROWS}"))
    a, start_a = _loads(uniform, "uni", 2.0, 75.0)
    b, start_b = _loads(one, "one", 2.0, 75.0)
    assert start_a == start_b == (1.2, 30.0)
    for k in a:
        assert a[k].tolist() == b[k].tolist()                    # bit for bit
    got, start = _loads(prof, "pro")
    assert start == (1.0, 0.0)                                   # the profile's surface values
    scaled, _ = _loads(prof, "pro", 2.0, 40.0)
    hand_loads(got, 1.0, 0.0)
    hand_loads(scaled, 2.0, 40.0)


def hand_loads(out, k, turn):
    """SCENE's loads of ``_loads`` by hand, with the inputs scaling the profile by ``k`` and
    turning it by ``turn``: body at z = -5 (AQWA's reference point), the clump at z = -35
    (t = 15/80 → U = 0.4 − 0.1875·0.3 = 0.34375, β = 90°)."""
    v = np.array([0.1, -0.2, 0.0])
    uc = u(k * 0.34375, 90.0 + turn) - (v + np.cross([0, 0, 0.01], [0, 0, -30.0]))
    np.testing.assert_allclose(out["clump"][:3], [100.0 * uc[0] * abs(uc[0]), 200.0 * uc[1] * abs(uc[1]), 0.0],
                               rtol=1e-12)
    w = v - u(k * 0.85, 22.5 + turn)
    np.testing.assert_allclose(out["viscous_drag"][:2], -np.array([1e4, 2e4]) * w[:2] * np.abs(w[:2]), rtol=1e-12)


# --- vendor files -------------------------------------------------------------------------
def test_profiles_from_deeplines_and_sima_files(tmp_path):
    dl = tmp_path / "model.dat"
    dl.write_text("*UNITS\n SI\n*CURPROF\n 0. -20. -100\n*CURRENT\n 0.  0. 1.0  90. 0.4 &\n 90 0.1\n*LINE\n x\n")
    sima = tmp_path / "current.txt"
    sima.write_text("' number of current levels\n3\n' zlevel direction current\n0.0 0.0 1.0\n"
                    "-20.0, 90.0, 0.4\n-1.0D2 90.0 0.1\n")
    assert read_current_profile(dl) == ROWS
    assert read_sima(sima) == ROWS
    uniform = tmp_path / "uniform.dat"
    uniform.write_text("*CURRENT\n 0. 120. 0.7\n")
    assert read_current_profile(uniform) == [[0.0, 0.7, 120.0]]
    for deck, fmt in ((dl, "deeplines"), (sima, "sima")):
        scene = load_scene(write_scene(tmp_path, SCENE.format(
            name="s", current=f'current_deck = "{deck.name}"\ncurrent_format = "{fmt}"')))
        assert scene.current_profile == ROWS and (scene.current_speed, scene.current_direction) == (1.0, 0.0)


BAD_DEEPLINES = {
    "level above the surface": ("*CURPROF\n 2.0 -20.\n*CURRENT\n 0. 0. 1.0 0. 0.4\n", 2, "ZCUR(1)", "above"),
    "levels not ordered": ("*CURPROF\n 0. -50. -20.\n*CURRENT\n 0. 0. 1. 0. .4 0. .2\n", 2, "ZCUR(3)", "ordered"),
    "missing value": ("*CURPROF\n 0. -20.\n*CURRENT\n 0. 0. 1.0 0.\n", 4, "VCUR(1,2)", "missing"),
    "missing heading": ("*CURRENT\n 0.\n", 2, "TETC(1,1)", "missing"),
}
BAD_SIMA = {
    "level above the surface": ("2\n0.5 0.0 1.0\n-20. 90. 0.4\n", 2, "CURLEV(1)", "above"),
    "levels not ordered": ("3\n0. 0. 1.0\n-50. 90. 0.4\n-20. 90. 0.2\n", 4, "CURLEV(3)", "ordered"),
    "missing value": ("2\n0. 0. 1.0\n-20. 90.\n", 3, "CURVEL(2)", "missing"),
    "missing level": ("3\n0. 0. 1.0\n-20. 90. 0.4\n", 3, "CURLEV(3)", "end of file"),
    "extra level": ("1\n0. 0. 1.0\n-20. 90. 0.4\n", 3, "CURLEV(2)", "more levels"),
}


@pytest.mark.parametrize("reader, case", [("deeplines", c) for c in BAD_DEEPLINES] + [("sima", c) for c in BAD_SIMA])
def test_malformed_profile_files(tmp_path, reader, case):
    text, line, field, match = (BAD_DEEPLINES if reader == "deeplines" else BAD_SIMA)[case]
    path = tmp_path / "current.dat"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        (read_current_profile if reader == "deeplines" else read_sima)(path)
    e = err.value
    assert (e.path, e.line, e.field) == (str(path), line, field), str(e)
    assert match in e.message


BAD_SCENE = {
    "level above the surface": ("current_profile = [[1.0, 1.0, 0.0], [-20.0, 0.4, 90.0]]",
                                "environment.current_profile[0]", "z: level z = 1 m is above"),
    "levels not ordered": ("current_profile = [[0.0, 1.0, 0.0], [-50.0, 0.4, 90.0], [-20.0, 0.2, 90.0]]",
                           "environment.current_profile[2]", "z: levels must be strictly ordered"),
    "missing value": ("current_profile = [[0.0, 1.0, 0.0], [-20.0, 0.4]]",
                      "environment.current_profile[1]", "missing value"),
    "deck level above the surface": ('current_deck = "bad.dat"\ncurrent_format = "deeplines"',
                                     "environment.current_deck", "bad.dat:2: ZCUR(1):"),
    "zero at the surface only": ("current_profile = [[0.0, 0.0, 0.0], [-20.0, 0.4, 90.0]]",
                                 "environment.current_profile[0]", "speed: the speed at the top level is 0"),
    "negative speed": ("current_profile = [[0.0, 1.0, 0.0], [-20.0, -0.4, 90.0]]",
                       "environment.current_profile[1]", "speed: speed must not be negative"),
    "profile and uniform": ("current_speed = 1.0\ncurrent_profile = [[0.0, 1.0, 0.0]]",
                            "environment.current_speed", "give the current once"),
}


@pytest.mark.parametrize("case", BAD_SCENE)
def test_malformed_scene_profile_is_one_error_and_nothing_is_written(tmp_path, case):
    current, key, match = BAD_SCENE[case]
    (tmp_path / "bad.dat").write_text(BAD_DEEPLINES["level above the surface"][0])
    one_scene_error(write_scene(tmp_path, SCENE.format(name="bad", current=current)), key, match)


def one_scene_error(path, key, match):
    """Loading the scene ``path`` is one error at ``key`` saying ``match``; the CLI build
    exits with 2, prints that one error line, no traceback, and writes nothing."""
    with pytest.raises(InputError) as err:
        load_scene(path)
    assert err.value.field == key and match in err.value.message and ";" not in err.value.message, str(err.value)
    out = path.parent / "out"
    run = subprocess.run([sys.executable, "-m", "hydrofmu.cli", "build", str(path), "-o", str(out)],
                         capture_output=True, text=True)
    assert run.returncode == 2 and key in run.stderr and match in run.stderr, run.stderr
    assert "Traceback" not in run.stderr and run.stderr.count("error:") == 1
    assert not out.exists()
