"""Wave kinematics in a scene: [waves.points] outputs on the load FMU against Airy derived
from its potential (tests/airy.py; fixed and on-body points), a RIFLEX body's load in the FMU
against the kernel at the same time, the scene's errors (file and key path), the compiled build's refusal."""
import math
import re
from pathlib import Path

import numpy as np
import pytest

from airy import Airy
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
ramp = 0.0
{extra}

[waves.points.fixed]
position = [30.0, 4.0, -6.0]

[waves.points.stern]
body = "barge"
offset = [-20.0, 0.0, -8.0]
"""


def airy_regular(t, x, y, z, depth=math.inf):
    """[u (3), a (3), p_d, η] of the scene's regular wave (a 1 m, T 8 s, going to 30°, phase
    20°), from its potential (tests/airy.py)."""
    return Airy(1.0, 2 * math.pi / 8.0, 30.0, math.radians(20.0), depth).at(x, y, z, t)


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
        assert np.all(np.abs(fixed - airy_regular(t, 30.0, 4.0, -6.0, depth=d)) <= 1e-11 * scale)
        assert np.all(np.abs(on_body - airy_regular(t, *stern, depth=d)) <= 1e-11 * scale)
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


def test_fmu_state_with_kinematics_continues_exactly(tmp_path):
    """The joined barges in waves (compiled): a state of the load FMU (clump, points) and of the
    connector (the node) taken mid-run and restored, into the same instance and into a fresh
    one, continues bit for bit (the phasors are in the state); the Python flavour's slave too."""
    import zipfile
    from test_compiled import compiled_slave, python_slave
    from hydrofmu.fmi.build import build_scene
    scene = load_scene(joined_barges_in_waves(tmp_path, 'spectrum = "jonswap"\nhs = 3.0\ntp = 9.0\n'
                                                         'components = 30\nramp = 5.0'))
    folder = build_scene(scene, tmp_path / "fmus", log=lambda *_: None, runtime="c")
    for fmu in (folder / "joined_barges_barge_a.fmu", folder / "joined_barges_hitch.fmu"):
        unzipped = tmp_path / fmu.stem
        with zipfile.ZipFile(fmu) as z:
            z.extractall(unzipped)
        md, c = compiled_slave(fmu, unzipped)
        ins = [v.valueReference for v in md.modelVariables if v.causality == "input"]
        outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
        start = [float(v.start or 0.0) for v in md.modelVariables if v.causality == "input"]

        def run(step, get, first, n):
            rows = []
            for k in range(first, first + n):
                u = [x + 0.1 * np.sin(0.3 * k + j) for j, x in enumerate(start)]
                step(k, u)
                rows.append(get())
            return np.array(rows)
        c.setupExperiment(startTime=0.0)
        c.enterInitializationMode()
        c.exitInitializationMode()
        cstep = lambda k, u: (c.setReal(ins, u), c.doStep(0.1 * k, 0.1))   # noqa: E731
        run(cstep, lambda: c.getReal(outs), 0, 30)
        blob = c.serializeFMUState(c.getFMUState())
        later = run(cstep, lambda: c.getReal(outs), 30, 30)
        c.setFMUState(c.deserializeFMUState(blob))
        assert np.array_equal(run(cstep, lambda: c.getReal(outs), 30, 30), later), fmu.name
        _, fresh = compiled_slave(fmu, unzipped, "fresh")
        fresh.setFMUState(fresh.deserializeFMUState(blob))
        fstep = lambda k, u: (fresh.setReal(ins, u), fresh.doStep(0.1 * k, 0.1))   # noqa: E731
        assert np.array_equal(run(fstep, lambda: fresh.getReal(outs), 30, 30), later), fmu.name
        py = python_slave(unzipped)
        py.setup_experiment(0.0)
        py.enter_initialization_mode()
        py.exit_initialization_mode()
        pstep = lambda k, u: (py.set_real(ins, u), py.do_step(0.1 * k, 0.1))   # noqa: E731
        run(pstep, lambda: py.get_real(outs), 0, 30)
        state = py._get_fmu_state()
        plater = run(pstep, lambda: py.get_real(outs), 30, 30)
        py._set_fmu_state(py._fmu_state_from_bytes(py._fmu_state_to_bytes(state)))
        assert np.array_equal(run(pstep, lambda: py.get_real(outs), 30, 30), plater), fmu.name
        span = np.ptp(plater, axis=0)
        assert np.all(np.abs(plater - later) <= 1e-10 * np.where(span > 0, span, 1.0) + 1e-300)


@pytest.mark.parametrize("extra, key, said", [
    ('depth = 50.0\n[waves.points.bad]\nposition = [0.0, 0.0, -60.0]', "waves.points.bad.position",
     r"z = -60 m is below the sea bed \(waves.depth = 50 m\)"),
    ('[waves.points.bad]\nposition = [0.0, 0.0, 50.0]', "waves.points.bad.position",
     r"z = 50 m is above the highest crest of the scene's sea \(1 m: the sum of the components' amplitudes"),
    ('[waves.points.bad]\nbody = "barge"\noffset = [0.0, 0.0, 1.5]', "waves.points.bad.offset",
     r"z = 1.5 m at the initial pose of body 'barge' is above the highest crest"),
    ('depth = 50.0\n[waves.points.bad]\nbody = "barge"\noffset = [0.0, 0.0, -51.0]', "waves.points.bad.offset",
     r"z = -51 m at the initial pose of body 'barge' is below the sea bed"),
])
def test_point_never_in_the_water_is_a_warning_naming_it(tmp_path, extra, key, said):
    """A named point below the bed or above every crest the scene's sea reaches (Σ a_k: a
    regular wave's H/2 = 1 m here) never gets wet: its outputs stay 0, said once naming it;
    points at the bed itself and under the crest (z = 0.9 m) are left alone."""
    path = tmp_path / "s.toml"
    path.write_text(SCENE.format(extra=extra))
    with pytest.warns(Warning) as caught:
        scene = load_scene(path)
    said_here = [str(w.message) for w in caught if key in str(w.message)]
    assert len(said_here) == 1 and re.search(said, said_here[0]) and "never in the water" in said_here[0]
    assert sum(key in w for w in scene.warnings) == 1
    quiet = extra.replace("-60.0", "-50.0").replace("50.0]", "0.9]").replace("1.5]", "0.9]").replace("-51.0]", "-50.0]")
    path.write_text(SCENE.format(extra=quiet))
    assert not [w for w in load_scene(path).warnings if "never in the water" in w]


def test_spectrum_point_far_above_the_crests_is_a_warning():
    """A spectrum of many components: Σ a_k (here 3.4·Hs) would let a point at 3.2·Hs pass;
    3·Hs, which a Rayleigh crest passes with probability e^{−72} per wave, is the limit then."""
    import warnings
    from hydrofmu.scene.problems import Problems
    from hydrofmu.scene.waves import read_wave_points
    sea = waves.SeaState("jonswap", hs=2.0, tp=8.0, components=200, seed=1)
    assert np.sum(waves.components(sea).amplitude) > 3.3 * 2.0
    for z, warned in ((6.4, True), (5.9, False)):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            read_wave_points(Problems("s.toml"), {"points": {"p": {"position": [0.0, 0.0, z]}}}, {}, sea)
        said = [str(w.message) for w in caught]
        assert bool(said) == warned and (not said or "3·Hs" in said[0] and "waves.points.p.position" in said[0])
