"""Wave kinematics in a scene: [waves.points] outputs on the load FMU against Airy written
here (fixed and on-body points), a RIFLEX body's load in the FMU against the kernel at the same
time, the scene's errors (file and key path), the compiled build's refusal."""
import math
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.errors import InputError
from hydrofmu.physics import waves
from hydrofmu.physics.kinematics import rotation
from hydrofmu.scene import load_scene

G, RHO = 9.81, 1025.0

SCENE = """
[run]
step = 0.1
stop = 5.0

[bodies.barge]
position = [10.0, -5.0, 0.0]
mass = 1.0e6
inertia = [1e8, 1e8, 1e8]
stiffness = [1e5, 1e5, 1e7, 1e9, 1e9, 1e8]

[[bodies.barge.effects]]
type = "riflex_body"
name = "clump"
offset = [-20.0, 0.0, -8.0]
am = 2.0e4
ae = 3.0
cd = [2.0e3, 2.0e3, 4.0e3]
added_mass = [3.0e3, 3.0e3, 5.0e3]

[waves]
spectrum = "regular"
height = 2.0
period = 8.0
direction = 30.0
phase = 20.0
{extra}

[waves.points.fixed]
position = [30.0, 4.0, -6.0]

[waves.points.stern]
body = "barge"
offset = [-20.0, 0.0, -8.0]
"""


def airy_regular(t, x, y, z, a=1.0, period=8.0, beta=30.0, phi=20.0, depth=math.inf):
    """[u (3), a (3), p_d, η] of a regular Airy wave (textbook formulas)."""
    w = 2 * math.pi / period
    k = float(waves.wave_number(w, G, depth))
    if math.isinf(depth):
        fh = fv = fp = math.exp(k * z)
    else:
        fh = math.cosh(k * (z + depth)) / math.sinh(k * depth)
        fv = math.sinh(k * (z + depth)) / math.sinh(k * depth)
        fp = math.cosh(k * (z + depth)) / math.cosh(k * depth)
    b = math.radians(beta)
    th = w * t - k * (x * math.cos(b) + y * math.sin(b)) + math.radians(phi)
    c, s = math.cos(th), math.sin(th)
    return np.array([w * a * fh * c * math.cos(b), w * a * fh * c * math.sin(b), w * a * fv * s,
                     -w * w * a * fh * s * math.cos(b), -w * w * a * fh * s * math.sin(b), w * w * a * fv * c,
                     RHO * G * a * fp * c, a * c])


@pytest.mark.parametrize("depth", [None, 50.0])
def test_points_and_clump_in_the_load_fmu(tmp_path, depth):
    from hydrofmu.cosim import inprocess
    from hydrofmu.physics.lumped import LumpedBody
    from hydrofmu.physics.state import Env, Motion
    from hydrofmu.physics.wave_kinematics import Water, WaveKinematics
    path = tmp_path / "s.toml"
    # (no stretching: Airy as it stands below z = 0; the default Wheeler moves every depth by η)
    path.write_text(SCENE.format(extra='stretching = "none"\n' + (f"depth = {depth}" if depth else "")))
    scene = load_scene(path)
    slave = inprocess.system(scene).instances["barge"].slave
    vr = {v.name: k for k, v in slave.vars.items()}
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    pos, att = np.array([10.5, -4.0, 0.3]), np.array([0.05, -0.03, 0.2])
    vel = np.array([0.2, -0.1, 0.05, 0.01, 0.02, -0.01])
    names = [f"position[{i}]" for i in (1, 2, 3)] + [f"attitude[{i}]" for i in (1, 2, 3)] + \
        [f"velocity[{i}]" for i in range(1, 7)]
    slave.set_real([vr[n] for n in names], np.r_[pos, att, vel].tolist())
    cols = [f"velocity[{i}]" for i in (1, 2, 3)] + [f"acceleration[{i}]" for i in (1, 2, 3)] + ["pressure", "elevation"]
    d = depth or math.inf
    sea = scene.waves
    comps = waves.components(sea)
    ph = waves.Phasors(comps)
    water = Water(WaveKinematics(comps, G, d, sea.stretching), ph, RHO)
    clump = LumpedBody("clump", [-20.0, 0.0, -8.0], 2.0e4, 3.0, "GLOBAL", [2.0e3, 2.0e3, 4.0e3], [3.0e3, 3.0e3, 5.0e3])
    stern = pos + rotation(att) @ np.array([-20.0, 0.0, -8.0])
    for i in range(40):
        t = 0.1 * (i + 1)
        slave.do_step(0.1 * i, 0.1)
        fixed = np.array(slave.get_real([vr[f"waves.fixed.{c}"] for c in cols]))
        on_body = np.array(slave.get_real([vr[f"waves.stern.{c}"] for c in cols]))
        scale = np.array([1, 1, 1, 1, 1, 1, RHO * G, 1.0])
        assert np.all(np.abs(fixed - airy_regular(t, 30.0, 4.0, -6.0, depth=d)) <= 1e-12 * scale)
        assert np.all(np.abs(on_body - airy_regular(t, *stern, depth=d)) <= 1e-12 * scale)
        ph.at(t)
        want = clump.load(Motion(pos, att, vel), Env(RHO, G, water=water)) + clump.velocity_load(Motion(pos, att, vel))
        got = np.array(slave.get_real([vr[f"clump.force[{j}]"] for j in range(1, 7)]))
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("extra, key", [
    ('stretching = "cosine"', "waves.stretching"),
    ('[waves.points.bad]\nposition = [0.0, 0.0, -1.0]\nbody = "barge"', "waves.points.bad"),
    ('[waves.points.bad]\nbody = "ship"', "waves.points.bad.body"),
    ('[waves.points.bad]\nbody = "barge"\noffset = [1.0, 2.0]', "waves.points.bad.offset"),
    ('[waves.points.bad]\nposition = [0.0, 0.0, -1.0]\nspeed = 2', "waves.points.bad"),
])
def test_scene_errors_name_the_key(tmp_path, extra, key):
    path = tmp_path / "s.toml"
    path.write_text(SCENE.format(extra=extra))
    with pytest.raises(InputError) as exc:
        load_scene(path)
    assert key in str(exc.value) and "s.toml" in str(exc.value)


def test_drag_waves_needs_relative(tmp_path):
    text = SCENE.format(extra="") + """
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
matrix = [1e4, 1e4, 1e4, 0.0, 0.0, 0.0]
waves = true
"""
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(InputError, match=r"bodies\.barge\.effects\[1\]\.waves.*RELATIVE"):
        load_scene(path)
    path.write_text(text.replace("waves = true", 'option = "RELATIVE"\nwaves = true'))
    assert load_scene(path).bodies["barge"].effects[1].data["waves"] is True


def joined_barges_in_waves(tmp, waves):
    """models/joined_barges.toml (clump under barge A, CONB hitch, AQWA drag, DeepLines polar)
    in a sea state ``waves`` (the [waves] table's lines), with named points, the polar of barge
    B and an extra RELATIVE drag on it opting in to the waves."""
    from conftest import MODELS
    text = (MODELS / "joined_barges.toml").read_text().replace('"decks/', f'"{(MODELS / "decks").as_posix()}/')
    polar_b = 'structure = "BARGE"\nsymmetry = "xz"\n\n[joints.hitch]'
    assert polar_b in text
    text = text.replace(polar_b, 'structure = "BARGE"\nsymmetry = "xz"\nwaves = true\n\n'
                        '[[bodies.barge_b.effects]]\ntype = "aqwa_viscous_drag"\nname = "wave_drag"\n'
                        'matrix = [3e4, 3e4, 6e4, 0.0, 0.0, 0.0]\noption = "RELATIVE"\nwaves = true\n\n[joints.hitch]')
    text += "\n[waves]\n" + waves + """
[waves.points.mooring]
position = [20.0, 5.0, -10.0]

[waves.points.stern]
body = "barge_a"
offset = [-40.0, 0.0, -8.0]
"""
    path = Path(tmp) / "jb_waves.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("waves, params", [
    ('spectrum = "jonswap"\nhs = 3.0\ntp = 9.0\ncomponents = 60\nseed = 3\nramp = 10.0\nspreading = 4.0\n'
     'depth = 60.0\nstretching = "wheeler"', {"waves.hs": 4.0, "waves.seed": 8}),
    ('spectrum = "regular"\nheight = 3.0\nperiod = 8.0\ndirection = 200.0\nstretching = "extrapolation"',
     {"waves.period": 9.0}),
    ('spectrum = "pierson_moskowitz"\nhs = 2.0\ntp = 8.0\ncomponents = 40\nstretching = "vertical"', {}),
])
def test_compiled_kinematics_equal_the_python_flavour(tmp_path, waves, params):
    """The joined barges in waves, compiled: every output of the load and connector FMUs (the
    clump, the hitch's node, the polar and drag with waves = true, the named points) equal to
    the Python flavour's to 1e-10 of its range, driven by the same moving inputs, with the sea
    state changed through the waves.* parameters."""
    from test_compiled import assert_equal_flavours
    from hydrofmu.fmi.build import build_scene
    scene = load_scene(joined_barges_in_waves(tmp_path, waves))
    folder = build_scene(scene, tmp_path / "fmus", log=lambda *_: None, runtime="c")
    assert assert_equal_flavours(folder, tmp_path, steps=400, dt=0.05, params=params, loads_only=True) <= 1e-10
