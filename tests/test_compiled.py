"""The compiled flavour (``hydrofmu build --runtime c``) against the Python one.

Every FMU kind is driven twice, identically: its Python slave (fmi/slave.py, in this process,
built from the typed description the compiled FMU carries) and the compiled FMU (loaded by
fmpy), every input a sinusoid of its own about its start value, for 1000 communication
steps; every output must agree to 1e-10 of its range.  The scenes of models/ and randomised
scenes (bodies, attitudes, CoG offsets, every effect inline, current profiles, couplings
with both memory methods, joints to a body and to the earth, both acceleration modes).
"""
import os
import shutil
import subprocess
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np
import pytest

from conftest import MODELS, build, tools

SCENES = sorted(p.stem for p in MODELS.glob("*.toml"))
SIMO = MODELS / "decks" / "side_by_side.sim"
NATIVE = Path(__file__).with_name("native")
STEPS = 1000
# input amplitudes by unit: motions a barge sees, loads a 1e7 kg barge answers mildly
AMPLITUDE = {"m": 2.0, "rad": 0.1, "m/s": 0.5, "rad/s": 0.05, "m/s2": 0.3, "rad/s2": 0.02, "deg": 30.0,
             "N": 1e5, "N.m": 1e7}


def python_slave(unzipped):
    """The Python flavour's slave of an unzipped compiled FMU (its resources' description)."""
    from hydrofmu import description
    from hydrofmu.fmi import slave
    from hydrofmu.fmi.build import SLAVES
    res = Path(unzipped) / "resources"
    return getattr(slave, SLAVES[type(description.read(res))])(instance_name="python", resources=str(res))


def compiled_slave(fmu, unzipped, name="compiled"):
    from fmpy import read_model_description
    from fmpy.fmi2 import FMU2Slave
    md = read_model_description(str(fmu))
    s = FMU2Slave(guid=md.guid, unzipDirectory=str(unzipped), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName=name)
    s.instantiate()
    return md, s


def drive(fmu, tmp, steps=STEPS, dt=0.1, seed=0, params=None, hold=1, load_scale=1.0):
    """(Python outputs, compiled outputs, output names) of both flavours of ``fmu`` driven
    by the same inputs (and the parameters ``params`` {name: value} it has, set in
    initialization mode): rows are communication points, columns outputs.  ``hold`` > 1: the
    inputs change every ``hold`` steps only (set every step: the compiled FMU keeps its outputs
    when the values set are those it holds; ``load_scale``: the load inputs' amplitudes times this,
    for bodies lighter than the 1e7 kg barge AMPLITUDE is made for)."""
    unzipped = Path(tmp) / Path(fmu).stem
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    md, c = compiled_slave(fmu, unzipped)
    py = python_slave(unzipped)
    ins = [v for v in md.modelVariables if v.causality == "input"]
    outs = [v for v in md.modelVariables if v.causality == "output"]
    rng = np.random.default_rng(seed)
    # loads about zero: a dynamics partner's load inputs start at its sources' loads at t = 0,
    # which held open-loop for 100 s would spin a random scene's body over
    start = np.array([0.0 if v.unit in ("N", "N.m") else float(v.start or 0.0) for v in ins])
    amp = np.array([AMPLITUDE.get(v.unit, 1.0) * (load_scale if v.unit in ("N", "N.m") else 1.0) for v in ins])
    freq, phase = rng.uniform(0.02, 0.3, len(ins)), rng.uniform(0.0, 2 * np.pi, len(ins))
    vin, vout = [v.valueReference for v in ins], [v.valueReference for v in outs]
    refs = {v.name: v.valueReference for v in md.modelVariables}
    pars = {refs[k]: float(v) for k, v in (params or {}).items() if k in refs}
    py.setup_experiment(0.0)
    py.enter_initialization_mode()
    py.set_real(list(pars), list(pars.values()))
    py.exit_initialization_mode()
    c.setupExperiment(startTime=0.0)
    c.enterInitializationMode()
    c.setReal(list(pars), list(pars.values()))
    c.exitInitializationMode()
    p_rows, c_rows = [], []
    for n in range(steps):
        t = n * dt
        u = (start + amp * np.sin(2 * np.pi * freq * (n // hold * hold * dt) + phase)).tolist()
        py.set_real(vin, u)
        c.setReal(vin, u)
        if n % 2 == 0:   # the outputs read before the step (feedthrough) and, every other step, after it
            p_rows.append(py.get_real(vout))
            c_rows.append(c.getReal(vout))
        assert py.do_step(t, dt) is not False, f"{Path(fmu).name}: the Python slave failed at t={t}"
        c.doStep(t, dt)
        if n % 2 == 1:
            p_rows.append(py.get_real(vout))
            c_rows.append(c.getReal(vout))
    c.terminate()
    c.freeInstance()
    return np.array(p_rows), np.array(c_rows), [v.name for v in outs]


def assert_equal_flavours(folder, tmp, steps=STEPS, dt=0.1, seed=0, params=None, loads_only=False, hold=1,
                          load_scale=1.0):
    """Every output of every FMU (``loads_only``: of every load FMU) of a built scene folder:
    compiled = Python to 1e-10 of its range."""
    fmus = [f for f in sorted(Path(folder).glob("*.fmu")) if not (loads_only and f.stem.endswith("_dynamics"))]
    assert fmus
    worst = 0.0
    for fmu in fmus:
        p, c, names = drive(fmu, tmp, steps, dt, seed, params, hold, load_scale)
        assert np.isfinite(p).all()
        span = p.max(axis=0) - p.min(axis=0)
        scale = np.where(span > 0, span, np.abs(p).max(axis=0))
        err = np.abs(p - c).max(axis=0)
        for k, name in enumerate(names):
            assert err[k] <= 1e-10 * scale[k] + 1e-300, f"{fmu.name} {name}: {err[k]:.3g} of range {scale[k]:.3g}"
        worst = max(worst, float(np.max(err / np.where(scale > 0, scale, 1.0))))
    return worst


@pytest.fixture(scope="module")
def compiled(tmp_path_factory):
    """Every scene of models/, compiled flavour: {name: folder}."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    out = tmp_path_factory.mktemp("compiled")
    return {n: build_scene(load_scene(MODELS / f"{n}.toml"), out, log=lambda *_: None, runtime="c") for n in SCENES}


@pytest.mark.parametrize("name", SCENES)
def test_models_scene_compiled_equals_python(name, compiled, tmp_path):
    import json
    from hydrofmu.scene import load_scene
    step = json.loads((compiled[name] / "manifest.json").read_text())["run"]["step"]
    # open-loop loads a light body answers mildly too (the buoy: 3.2e5 kg; (m / 1e7)² of the barge's)
    lightest = min(b.mass for b in load_scene(MODELS / f"{name}.toml").bodies.values())
    scale = min(1.0, lightest / 1e7) ** 2
    assert assert_equal_flavours(compiled[name], tmp_path, dt=step, load_scale=scale) <= 1e-10


def random_scene(seed):
    """A scene of two bodies with every effect inline, a current profile, SIMO couplings
    (memory method per coupling), a joint between the bodies and one to the earth."""
    rng = np.random.default_rng(seed)
    u = rng.uniform
    mode = ["export", "explicit"][seed % 2]
    method = ["convolution", "state_space"]

    def vec(lo, hi, n=3):
        return "[" + ", ".join(f"{x:.6g}" for x in u(lo, hi, n)) + "]"

    def body(name, y):
        m = u(5e6, 2e7)
        ixx, iyy = m * u(40, 80), m * u(600, 900)
        return f"""
        [bodies.{name}]
        position = [{u(-5, 5):.4g}, {y + u(-2, 2):.4g}, {u(-0.5, 0.5):.4g}]
        attitude = {vec(-0.05, 0.05)}
        velocity = {vec(-0.2, 0.2, 6)}
        mass = {m:.6g}
        inertia = [{ixx:.6g}, {iyy:.6g}, {(ixx + iyy) * u(0.9, 0.99):.6g}]
        cog = {vec(-3, 3)}
        stiffness = [{u(1e5, 3e5):.6g}, {u(1e5, 3e5):.6g}, {u(2e7, 3e7):.6g}, {u(8e8, 1e9):.6g}, {u(1e10, 2e10):.6g}, {u(3e8, 6e8):.6g}]
        damping = [{u(1e5, 3e5):.6g}, {u(1e5, 3e5):.6g}, {u(2e6, 4e6):.6g}, {u(1e8, 3e8):.6g}, {u(2e9, 4e9):.6g}, {u(5e8, 1e9):.6g}]
        acceleration_loads = "{mode}"
        [[bodies.{name}.effects]]
        type = "aqwa_viscous_drag"
        option = "{["RELATIVE", "ABSOLUTE"][int(u() < 0.3)]}"
        matrix = {np.diag(u(1e4, 1e6, 6)).__add__(u(-1e3, 1e3, (6, 6))).round(1).tolist()}
        [[bodies.{name}.effects]]
        type = "deeplines_current_polar"
        point = {vec(-10, 10)}
        surface = {u(500, 3000):.6g}
        table = {np.column_stack([np.arange(0, 360, 45.0), u(-1, 1, (8, 3))]).round(4).tolist()}
        [[bodies.{name}.effects]]
        type = "riflex_body"
        offset = {vec(-30, 30)}
        am = {u(1e4, 1e5):.6g}
        ae = {u(5, 50):.6g}
        icoo = "{["GLOBAL", "LOCAL"][int(u() < 0.5)]}"
        cd = {vec(1e3, 1e4)}
        added_mass = {vec(1e3, 5e4)}
        """
    couplings = "".join(f"""
        [[couplings]]
        deck = "{SIMO.as_posix()}"
        coupling = "{c}"
        bodies = {{ BARGEA = "a", BARGEB = "b" }}
        method = "{method[(seed + k) % 2]}"
        memory_length = {u(5, 15):.3g}
        """ for k, c in enumerate(("SELFA", "SELFB", "AB")))
    return f"""
        [scene]
        name = "random{seed}"
        [environment]
        current_profile = [[0.0, {u(0.5, 1.5):.3g}, {u(0, 360):.4g}], [-8.0, {u(0.3, 1):.3g}, {u(0, 360):.4g}], [-40.0, 0.2, {u(0, 360):.4g}]]
        [run]
        step = 0.1
        substep = {u(0.01, 0.05):.3g}
        load_hold = "{["constant", "linear"][seed % 2]}"
        {body("a", 0.0)}
        {body("b", 40.0)}
        [joints.hitch]
        a = "a"
        a_point = [0.0, 20.0, 0.0]
        b = "b"
        b_point = [0.0, -20.0, 0.0]
        codes = [1, {int(u() < 0.5)}, 0]
        am = {u(1e3, 1e4):.6g}
        cd = {vec(100, 1000)}
        added_mass = {vec(100, 1000)}
        acceleration_loads = "{mode}"
        rot_stiffness = {u(1e7, 1e8):.6g}
        rot_damping = {u(1e6, 1e7):.6g}
        [joints.anchor]
        a = "b"
        a_point = [10.0, 0.0, -5.0]
        b = "earth"
        codes = [0, 0, 0]
        {couplings}
        """


@pytest.mark.parametrize("seed", [1, 2])
def test_random_scene_compiled_equals_python(seed, tmp_path):
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    from conftest import write_scene
    scene = load_scene(write_scene(tmp_path, random_scene(seed)))
    folder = build_scene(scene, tmp_path / "fmus", log=lambda *_: None, runtime="c")
    fmus = {f.stem for f in folder.glob("*.fmu")}
    # two load FMUs, two joints; the dynamics: one group (export: cross added mass) or one each
    dynamics = {f"random{seed}_a_b_dynamics"} if seed % 2 == 0 else {f"random{seed}_a_dynamics", f"random{seed}_b_dynamics"}
    assert fmus == {f"random{seed}_{n}" for n in ("a", "b", "hitch", "anchor")} | dynamics
    assert assert_equal_flavours(folder, tmp_path, seed=seed, hold=seed) <= 1e-10   # seed 2: inputs held 2 steps


def variables(md_text):
    """(name, value reference, causality, variability, initial, unit, start) of every variable,
    and the ModelStructure, of a modelDescription.xml text."""
    root = ET.fromstring(md_text)
    rows = []
    for sv in root.find("ModelVariables"):
        real = sv.find("Real")
        rows.append((sv.get("name"), sv.get("valueReference"), sv.get("causality"), sv.get("variability"),
                     sv.get("initial"), real.get("unit"), real.get("start")))
    return rows, ET.tostring(root.find("ModelStructure")), ET.tostring(root.find("UnitDefinitions"))


def test_model_description_is_the_python_flavours(compiled, demo_build):
    """Names, value references, causalities, units, start values and dependencies: the two
    flavours are interchangeable in OspSystemStructure.xml and the .ssp."""
    for fmu in sorted(demo_build.glob("*.fmu")):
        twin = compiled["moored_barge"] / fmu.name
        with zipfile.ZipFile(fmu) as a, zipfile.ZipFile(twin) as b:
            assert variables(a.read("modelDescription.xml")) == variables(b.read("modelDescription.xml"))
            cs = ET.fromstring(b.read("modelDescription.xml")).find("CoSimulation")
            assert cs.get("needsExecutionTool") == "false"
            files = [f.get("name") for f in cs.find("SourceFiles")]
            assert all(f"sources/{f}" in b.namelist() for f in files) and "fmi/fmu.c" in files
            assert not any(n.endswith((".py", ".pyc")) for n in b.namelist())   # no Python inside
    assert (demo_build / "OspSystemStructure.xml").read_text() == \
        (compiled["moored_barge"] / "OspSystemStructure.xml").read_text()
    import json
    python, c = (json.loads((f / "manifest.json").read_text()) for f in (demo_build, compiled["moored_barge"]))
    assert (python.pop("flavour"), c.pop("flavour")) == ("python", "c")   # the one line that says which
    assert python == c


def test_fmpy_validates_compiled_fmus_of_every_kind(compiled, wave_builds):
    """A load FMU with couplings, one with waves and hydrostatics, a joint and a dynamics
    group: 0 problems."""
    from fmpy.validation import validate_fmu
    for fmu in (compiled["side_by_side"] / "side_by_side_barge_a.fmu", compiled["joined_barges"] / "joined_barges_hitch.fmu",
                compiled["side_by_side"] / "side_by_side_barge_a_barge_b_dynamics.fmu",
                wave_builds["irregular"] / "waves_cyl1.fmu"):
        assert validate_fmu(str(fmu)) == [], fmu.name


# -- no Python: native hosts ----------------------------------------------------------------

@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """The generic FMI host and the libcosim host of tests/native, compiled."""
    import libcosimpy
    from hydrofmu.bench import native
    from test_native import compile_c
    lib = Path(libcosimpy.__file__).parent / "libcosimc"
    d = tmp_path_factory.mktemp("chosts")
    return {"fmi": compile_c("fmi_host.c", d / "fmi_host", f"-I{native.SOURCE.parent}", "-ldl", "-lpthread"),
            "cosim": compile_c("cosim_run.c", d / "cosim_run", f"-L{lib}", "-lcosimc", f"-Wl,-rpath,{lib}")}


def no_python_env(tmp_path):
    """An environment in which no Python can be found: PATH and LD_LIBRARY_PATH an empty
    folder, no PYTHON* variables; the dynamic loader reports every library it loads."""
    empty = tmp_path / "empty"
    empty.mkdir(exist_ok=True)
    assert shutil.which("python3", path=str(empty)) is None and shutil.which("python", path=str(empty)) is None
    return {"PATH": str(empty), "LD_LIBRARY_PATH": str(empty), "LD_DEBUG": "libs", "HOME": str(tmp_path)}


def assert_no_python_loaded(run):
    """The loader's report (LD_DEBUG=libs, on stderr) names no Python library."""
    loaded = [line for line in run.stderr.splitlines() if "calling init:" in line]
    assert loaded, "LD_DEBUG reported no library: the check would see nothing"
    assert not [line for line in run.stderr.splitlines() if "python" in line.lower()], run.stderr[-2000:]


def built(name, compiled, wave_builds):
    """A compiled scene folder: one of models/ or, as "waves: <name>", of WAVE_SCENES."""
    return wave_builds[name.split(": ", 1)[1]] if name.startswith("waves: ") else compiled[name]


@pytest.mark.parametrize("name", ["side_by_side", "joined_barges", "waves: irregular"])
def test_compiled_fmus_run_in_a_c_host_without_python(name, compiled, wave_builds, hosts, tmp_path):
    """Every FMU of the scene in the generic C host with no Python to be found: ``ldd`` of
    the binary names no libpython, the loader loads none, and the outputs equal fmpy's run
    of the same FMU in this process (same inputs).  The wave scene: JONSWAP with spreading on
    two bodies, BEM hydrostatics."""
    from test_native import fmpy_reference, run_fmi_host, unzip
    env = no_python_env(tmp_path)
    for fmu in sorted(built(name, compiled, wave_builds).glob("*.fmu")):
        unzipped = unzip(fmu, tmp_path / fmu.stem)
        folder, mid, _, refs = unzipped
        binary = folder / "binaries" / "linux64" / f"{mid}.so"
        ldd = subprocess.run(["ldd", str(binary)], capture_output=True, text=True, check=True).stdout
        assert "python" not in ldd.lower() and "libm" in ldd
        md = ET.fromstring((folder / "modelDescription.xml").read_text())
        ins = {int(sv.get("valueReference")): float(sv.find("Real").get("start") or 0.0) + 0.01 * (k + 1)
               for k, sv in enumerate(md.iter("ScalarVariable")) if sv.get("causality") == "input"}
        outs = [int(sv.get("valueReference")) for sv in md.iter("ScalarVariable") if sv.get("causality") == "output"]
        run, values = run_fmi_host(hosts, unzipped, 1, 20, 0.1, ins, outs[:64], env=env)
        assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout[-2000:]
        assert "failed" not in run.stdout and "LOG" not in run.stdout, run.stdout[-2000:]
        assert_no_python_loaded(run)
        ref = fmpy_reference(unzipped, 20, 0.1, ins, outs[:64])
        assert len(values) == len(ref) > 0
        for (_, n, vr), v in values.items():
            assert v == pytest.approx(ref[n, vr], rel=1e-12, abs=1e-9), (fmu.name, n, vr)


@pytest.mark.parametrize("name", ["joined_barges", "waves: irregular"])
def test_compiled_scene_runs_in_libcosim_c_api_without_python(name, compiled, wave_builds, hosts, tmp_path):
    """joined_barges compiled (load, joint and dynamics FMUs), and the irregular-sea pair
    (wave excitation, hydrostatics), in libcosim's C API from a process with no Python to be
    found equals our fmpy Jacobi master on the same FMUs."""
    import json
    from hydrofmu.cosim import master
    from test_native import assert_equals_jacobi, run_cosim
    folder = built(name, compiled, wave_builds)
    step = json.loads((folder / "manifest.json").read_text())["run"]["step"]
    env = no_python_env(tmp_path)
    tables = run_cosim(hosts, folder / "OspSystemStructure.xml", 30 * step, step, tmp_path / "out", env=env)
    ours = master.run(folder, stop=30 * step, step=step, algorithm="jacobi", progress=False)
    assert_equals_jacobi(tables, ours)


def test_nonfinite_input_is_an_error_with_a_log_line_not_a_crash(compiled, hosts, tmp_path):
    from test_native import run_fmi_host, unzip
    unzipped = unzip(compiled["moored_barge"] / "moored_barge_barge.fmu", tmp_path / "u")
    refs = unzipped[3]
    run, values = run_fmi_host(hosts, unzipped, 1, 3, 0.1, {refs["velocity[2]"]: float("nan")},
                               [refs["force[1]"]], env=no_python_env(tmp_path))
    assert run.returncode == 0 and "host exits normally" in run.stdout
    assert "LOG 3 logStatusError: instance0: at t=0: input velocity[2] = nan is not finite" in run.stdout, run.stdout
    assert "an FMI call failed" in run.stdout and not values


# -- FMU state, reset and guards (fmpy) -----------------------------------------------------

def test_state_serialize_and_reset_continue_exactly(compiled, wave_builds, tmp_path):
    """A state taken mid-run, serialized and restored (into the same instance and into a fresh
    one, which draws its waves from the restored waves.* values) continues with the same
    outputs; fmi2Reset starts again from the start values.  Memories of both kinds (state
    space: side_by_side; convolution: a random scene), waves."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    from conftest import write_scene
    conv = build_scene(load_scene(write_scene(tmp_path / "s", random_scene(2))), tmp_path / "f",
                       log=lambda *_: None, runtime="c")
    for fmu in [compiled["side_by_side"] / "side_by_side_barge_a.fmu", conv / "random2_a.fmu",
                conv / "random2_a_b_dynamics.fmu", conv / "random2_hitch.fmu", wave_builds["irregular"] / "waves_cyl2.fmu"]:
        unzipped = tmp_path / fmu.stem
        with zipfile.ZipFile(fmu) as z:
            z.extractall(unzipped)
        md, s = compiled_slave(fmu, unzipped)
        ins = [v.valueReference for v in md.modelVariables if v.causality == "input"]
        outs = [v.valueReference for v in md.modelVariables if v.causality == "output"]
        start = [float(v.start or 0.0) for v in md.modelVariables if v.causality == "input"]

        # the dynamics FMU alone, its loads held near their start values, rolls a random body
        # past 90° (capsized: the step fails) at 3.5 s: its 60 steps cover 3 s
        h = 0.05 if "dynamics" in fmu.name else 0.1

        def run(slave, first, n):
            rows = []
            for k in range(first, first + n):
                slave.setReal(ins, [x + 0.1 * np.sin(0.3 * k + j) for j, x in enumerate(start)])
                slave.doStep(h * k, h)
                rows.append(slave.getReal(outs))
            return np.array(rows)

        def init(slave):
            slave.setupExperiment(startTime=0.0)
            slave.enterInitializationMode()
            slave.exitInitializationMode()

        init(s)
        first = run(s, 0, 30)
        state = s.getFMUState()
        blob = s.serializeFMUState(state)
        later = run(s, 30, 30)
        s.setFMUState(state)
        assert np.array_equal(run(s, 30, 30), later), fmu.name
        _, fresh = compiled_slave(fmu, unzipped, "fresh")
        fresh.setFMUState(fresh.deserializeFMUState(blob))
        assert np.array_equal(run(fresh, 30, 30), later), fmu.name
        s.reset()
        init(s)
        assert np.array_equal(run(s, 0, 30), first), fmu.name
        s.freeFMUState(state)
        for x in (s, fresh):
            x.terminate()
            x.freeInstance()


def guarded_slave(fmu, tmp, guid=None, lines=None):
    """(slave, {name: value reference}, log lines [(status, message)]) of a compiled FMU
    instantiated by fmpy (as ``guid``: default the FMU's) with a logger that keeps its lines
    (appended to ``lines`` if given)."""
    from fmpy import calloc, free, read_model_description
    from fmpy.fmi2 import FMU2Slave, fmi2CallbackFunctions, fmi2CallbackLoggerTYPE
    from fmpy.fmi2 import fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE
    unzipped = Path(tmp) / "u"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    md = read_model_description(str(fmu))
    lines = [] if lines is None else lines
    cb = fmi2CallbackFunctions()
    cb.logger = fmi2CallbackLoggerTYPE(lambda env, name, status, cat, msg: lines.append((status, msg.decode())))
    cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
    cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
    s = FMU2Slave(guid=guid or md.guid, unzipDirectory=str(unzipped), modelIdentifier=md.coSimulation.modelIdentifier,
                  instanceName="g")
    s.instantiate(callbacks=cb)
    s._keep = cb   # (the callbacks must outlive the instance)
    return s, {v.name: v.valueReference for v in md.modelVariables}, lines


def test_guards_return_error_never_crash(compiled, tmp_path):
    """Bad calls are fmi2Error with a log line: a parameter set after initialization, a value
    reference out of range, a time jump, bytes that are not a state, a wrong GUID."""
    from fmpy.fmi1 import FMICallException
    fmu = compiled["moored_barge"] / "moored_barge_barge.fmu"
    s, refs, lines = guarded_slave(fmu, tmp_path)
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    bad = [(lambda: s.setReal([refs["rho"]], [1000.0]), "cannot set rho: a parameter, fixed after initialization"),
           (lambda: s.getReal([10 ** 6]), "value reference 1000000 out of range"),
           (lambda: s.doStep(5.0, 0.1), "communication point 5 is not where the last step ended (0)"),
           (lambda: s.deserializeFMUState(b"\x00" * 40), "not a serialized state of this FMU")]
    for call, message in bad:
        with pytest.raises(FMICallException):
            call()
        assert lines and lines[-1][0] == 3 and message in lines[-1][1], (message, lines[-1:])
    s.doStep(0.0, 0.1)   # still usable
    s.terminate()
    s.freeInstance()
    with pytest.raises(Exception, match="Failed to instantiate"):
        guarded_slave(fmu, tmp_path / "w", guid="not-the-guid", lines=lines)
    assert "does not match this FMU's" in lines[-1][1]


def test_fast_paths_keep_every_guard(compiled, tmp_path):
    """What fmu.c skips on the hot path is skipped only when it is known: the references a
    master set last (not once initialization has fixed a parameter among them), the inputs'
    finiteness (a NaN set again, or left in place while another input is set, still fails
    every step), the outputs read after a checked step (a parameter made NaN before
    initialization is still refused when read)."""
    from fmpy.fmi1 import FMICallException
    s, refs, lines = guarded_slave(compiled["side_by_side"] / "side_by_side_barge_a.fmu", tmp_path)
    both, force = [refs["rho"], refs["velocity[2]"]], [refs["force[2]"]]
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal(both, [1025.0, 0.1])   # a parameter may be set before initialization ...
    s.exitInitializationMode()
    with pytest.raises(FMICallException):   # ... the same references after it may not
        s.setReal(both, [1025.0, 0.2])
    assert "cannot set rho: a parameter, fixed after initialization" in lines[-1][1]
    s.setReal([refs["velocity[2]"]], [0.2])
    s.doStep(0.0, 0.1)
    t = 0.1
    for k in range(2):   # the same NaN twice: two failed steps
        s.setReal([refs["velocity[2]"]], [float("nan")])
        with pytest.raises(FMICallException):
            s.doStep(t, 0.1)
        assert "input velocity[2] = nan is not finite" in lines[-1][1], (k, lines[-1])
    s.setReal([refs["velocity[1]"]], [0.1])   # another input set: the NaN is still there
    with pytest.raises(FMICallException):
        s.doStep(t, 0.1)
    assert "input velocity[2] = nan is not finite" in lines[-1][1]
    s.setReal([refs["velocity[2]"]], [0.2])
    s.doStep(t, 0.1)
    assert np.isfinite(s.getReal(force)).all()
    s.terminate()
    s.freeInstance()

    s, refs, lines = guarded_slave(compiled["side_by_side"] / "side_by_side_barge_a.fmu", tmp_path / "nan")
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.setReal([refs["g"]], [float("nan")])
    s.exitInitializationMode()
    try:
        s.doStep(0.0, 0.1)
    except FMICallException:
        pass
    with pytest.raises(FMICallException):
        s.getReal([refs["g"]])
    assert "g = nan is not finite" in lines[-1][1], lines[-1]
    s.terminate()
    s.freeInstance()


# -- sources and other platforms ---------------------------------------------------------------

def test_fmu_sources_alone_compile_into_the_same_fmu(compiled, tmp_path):
    """A host on another platform compiles the FMU from its sources/ (the <SourceFiles> of
    modelDescription.xml) and the FMI headers: the library built from the unzipped FMU alone
    runs as the shipped one."""
    from hydrofmu.cc import compiler
    from hydrofmu.fmi.cbuild import fmi_headers
    fmu = compiled["side_by_side"] / "side_by_side_barge_a.fmu"
    unzipped = tmp_path / "u"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    md = ET.fromstring((unzipped / "modelDescription.xml").read_text())
    sources = [unzipped / "sources" / f.get("name") for f in md.find("CoSimulation").find("SourceFiles")]
    lib = unzipped / "binaries" / "linux64" / "side_by_side_barge_a.so"
    lib.unlink()
    subprocess.run(compiler() + ["-shared", "-fPIC", "-O2", "-std=c99", f"-I{fmi_headers()}", *map(str, sources),
                                 "-o", str(lib), "-lm"], check=True)
    rebuilt = tmp_path / "rebuilt.fmu"
    with zipfile.ZipFile(rebuilt, "w") as z:
        for f in unzipped.rglob("*"):
            if f.is_file():
                z.write(f, f.relative_to(unzipped).as_posix())
    p, c, _ = drive(rebuilt, tmp_path / "d", steps=100)
    assert np.abs(p - c).max() <= 1e-10 * np.abs(p).max()


def test_win64_binary_exports_every_fmi2_function(compiled):
    """The mingw-w64 cross-compiled win64 DLL (not run here: no Windows host in the tests)
    is an x86-64 PE library exporting the FMI 2.0 co-simulation functions and needing no
    runtime DLL beyond Windows' own."""
    objdump, _ = tools("x86_64-w64-mingw32-objdump", "x86_64-w64-mingw32-gcc",
                       why="the mingw-w64 cross compiler, Debian gcc-mingw-w64-x86-64, makes the win64 DLL")
    fmu = compiled["moored_barge"] / "moored_barge_barge.fmu"
    with zipfile.ZipFile(fmu) as z:
        names = z.namelist()
        assert "binaries/win64/moored_barge_barge.dll" in names
        dll = Path(z.extract("binaries/win64/moored_barge_barge.dll", fmu.parent / "win64"))
    dump = subprocess.run([objdump, "-p", str(dll)], capture_output=True, text=True, check=True).stdout
    assert "pei-x86-64" in subprocess.run([objdump, "-f", str(dll)], capture_output=True, text=True).stdout
    for fn in ("fmi2Instantiate", "fmi2DoStep", "fmi2GetReal", "fmi2SetReal", "fmi2GetFMUstate",
               "fmi2SerializeFMUstate", "fmi2DeSerializeFMUstate", "fmi2Reset", "fmi2FreeInstance"):
        assert f"] {fn}\n" in dump, fn
    dlls = {line.split(":")[1].strip().lower() for line in dump.splitlines() if "DLL Name:" in line}
    assert dlls <= {"kernel32.dll", "msvcrt.dll"} | {d for d in dlls if d.startswith("api-ms-win-crt")}, dlls


def test_win64_binary_runs_under_wine_as_the_linux_one(compiled, tmp_path):
    """A Windows host (tests/native/win_host.c, cross-compiled) runs the win64 DLL of a load
    FMU with state-space memories under wine: its outputs equal the linux64 binary's under
    fmpy, same inputs."""
    from test_native import fmpy_reference, unzip
    wine, cc = tools("wine", "x86_64-w64-mingw32-gcc", why="the win64 DLL run under wine, Debian wine64")
    host = tmp_path / "win_host.exe"
    from hydrofmu.bench import native
    subprocess.run([cc, "-O1", f"-I{native.SOURCE.parent}", "-o", str(host), str(NATIVE / "win_host.c")], check=True)
    fmu = compiled["side_by_side"] / "side_by_side_barge_a.fmu"
    unzipped = unzip(fmu, tmp_path / "u")
    folder, mid, guid, refs = unzipped
    ins = {refs["velocity[2]"]: 0.3, refs["velocity[3]"]: -0.1, refs["barge_b.velocity[2]"]: 0.2, refs["position[1]"]: 1.0}
    outs = [refs[n] for n in ("force[2]", "force[3]", "SELFA.force[2]", "AB.force[3]", "current_polar.force[6]")]
    run = subprocess.run([wine, str(host), str(folder / "binaries" / "win64" / f"{mid}.dll"), guid,
                          "file:///Z:" + (folder / "resources").as_posix(), "20", "0.1",
                          ",".join(f"{vr}:{v!r}" for vr, v in ins.items()), ",".join(map(str, outs))],
                         capture_output=True, text=True, timeout=240, env={**os.environ, "WINEDEBUG": "-all"})
    assert "host exits normally" in run.stdout, run.stdout[-2000:] + run.stderr[-2000:]
    values = {(int(n), int(vr)): float(v) for n, vr, v in (line.split() for line in run.stdout.splitlines()
                                                           if line[:1].isdigit())}
    ref = fmpy_reference(unzipped, 20, 0.1, ins, outs)
    assert values.keys() == ref.keys()
    for key, v in values.items():
        assert v == pytest.approx(ref[key], rel=1e-12, abs=1e-6), key


def test_native_floor_copies_its_inputs_and_times_in_the_c_host(tmp_path):
    """The native floor of the bench does what it claims (after a step y = u) and the C
    timing host measures it: positive startup and step times."""
    from hydrofmu.bench import compiled as bench
    fmu = bench.build_floor(tmp_path)
    unzipped = tmp_path / "u"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    md, s = compiled_slave(fmu, unzipped)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    u = [1.5, -2.0, 3.25, 0.0, 7.0, -0.5]
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([refs[f"u[{i}]"] for i in range(1, 7)], u)
    assert s.getReal([refs[f"y[{i}]"] for i in range(1, 7)]) == [0.0] * 6
    s.doStep(0.0, 0.1)
    assert s.getReal([refs[f"y[{i}]"] for i in range(1, 7)]) == u
    s.terminate()
    s.freeInstance()
    (row,) = bench.compare({"floor": fmu}, fmu, tmp_path / "t", rounds=1, steps=1000, best_of=1)
    assert 0.0 < row["startup_ms"] < 1e3 and 0.0 < row["step_us"] < 1e3 and row["step_x"] > 0.0
    assert row["ports"] == (6, 6)
    # a copy FMU of other port counts (y[k] = u[k mod 3]), and a candidate stepped on some ports only
    copy = bench.build_floor(tmp_path / "copy", 3, 5)
    with zipfile.ZipFile(copy) as z:
        z.extractall(tmp_path / "c")
    md, s = compiled_slave(copy, tmp_path / "c")
    refs = {v.name: v.valueReference for v in md.modelVariables}
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.setReal([refs[f"u[{i}]"] for i in range(1, 4)], [1.0, 2.0, 3.0])
    s.doStep(0.0, 0.1)
    assert s.getReal([refs[f"y[{i}]"] for i in range(1, 6)]) == [1.0, 2.0, 3.0, 1.0, 2.0]
    s.terminate()
    s.freeInstance()
    (row,) = bench.compare({"some ports": (copy, True, (["u[1]", "u[2]"], ["y[5]"]))}, fmu, tmp_path / "t2",
                           rounds=1, steps=1000, best_of=1)
    assert row["ports"] == (2, 1) and row["step_us"] > 0.0


def test_every_effect_kernel_has_a_compiled_twin(tmp_path):
    """A load FMU holding one effect of every kernel type a scene reaches (explicit mode, a
    current profile, hydrostatics about a tilted and yawed initial pose): compiled = Python to
    1e-10 of each output's range."""
    from hydrofmu import description as d
    from hydrofmu.physics.loads import KERNELS
    from hydrofmu.assembly import Instance
    from hydrofmu.fmi.cbuild import build_c_fmu
    rng = np.random.default_rng(5)
    data = {
        "aqwa_viscous_drag": {"matrix": (np.diag(rng.uniform(1e4, 1e6, 6)) + rng.uniform(-1e3, 1e3, (6, 6))).tolist(),
                              "relative": True},
        "deeplines_current_polar": {"angles": list(range(0, 360, 30)), "cx": rng.uniform(-1, 1, 12).tolist(),
                                    "cy": rng.uniform(-1, 1, 12).tolist(), "cmz": rng.uniform(-5, 5, 12).tolist(),
                                    "point": [3.0, -2.0, -4.0], "surface": 1500.0},
        "riflex_body": {"offset": [10.0, -5.0, -3.0], "am": 2e5, "ae": 150.0, "icoo": "LOCAL", "cd": [3e3, 4e3, 5e3],
                        "added_mass": [1e4, 2e4, 3e4]},
        "bem_hydrostatics": {"stiffness": (np.diag([0, 0, 3e7, 9e8, 2e10, 0.0]) + rng.uniform(-1e5, 1e5, (6, 6))).tolist(),
                             "position0": [1.0, 2.0, 0.0], "attitude0": [0.01, -0.02, 0.3]},
    }
    assert set(data) == set(KERNELS)   # a kernel added without its C twin fails here
    env = d.Environment(1025.0, 9.81, 1.1, 30.0, np.array([[0.0, 1.1, 30.0], [-20.0, 0.5, 60.0]]))

    def load_fmu(effects):
        return d.LoadFMU("every effect", "hull", np.array([1.0, 2.0, 0.0]), np.array([0.01, -0.02, 0.3]),
                         "explicit", [d.Effect(t, f"e{k}", v) for k, (t, v) in enumerate(effects.items())], [], env)

    build_c_fmu(Instance("hull", "every_effect", "load", "hull", load_fmu(data), {}, []), tmp_path)
    assert assert_equal_flavours(tmp_path / "fmus", tmp_path) <= 1e-10


def test_scene_build_runtime_and_cli_flag_choose_the_flavour(tmp_path):
    """``[build] runtime = "c"`` in a scene and ``hydrofmu build --runtime c`` build compiled
    FMUs (a binary of their own, no Python inside); a runtime that does not exist is an input
    error naming the key."""
    from hydrofmu import InputError
    from hydrofmu.cli import main
    from hydrofmu.scene import load_scene
    from conftest import write_scene
    text = (MODELS / "moored_barge.toml").read_text().replace('deck = "decks/', f'deck = "{MODELS.as_posix()}/decks/')
    scene = write_scene(tmp_path, text + '\n[build]\nruntime = "c"\n')

    def flavour(folder):
        with zipfile.ZipFile(folder / "moored_barge_barge.fmu") as z:
            names = z.namelist()
        return "c" if "resources/model.bin" in names and not any(n.endswith(".py") for n in names) else "python"

    assert main(["build", str(scene), "-o", str(tmp_path / "a")]) in (0, None)
    assert flavour(tmp_path / "a" / "moored_barge") == "c"
    plain = write_scene(tmp_path, text, "plain.toml")
    assert main(["build", str(plain), "-o", str(tmp_path / "c"), "--runtime", "c"]) in (0, None)
    assert flavour(tmp_path / "c" / "moored_barge") == "c"
    with pytest.raises(InputError, match=r"build\.runtime.*'python', 'c'.*'fortran'"):
        load_scene(write_scene(tmp_path, text + '\n[build]\nruntime = "fortran"\n', "bad.toml"))


def test_wave_kernel_equals_the_python_one(tmp_path):
    """physics/waves.c (compiled alone here) against physics.waves: the components it draws
    (numpy's default_rng reproduced: seeds below and above 2**32) and the excitation and
    elevation through a random transfer function (directions round the circle, a direction
    across 360 deg; and directions that are not), inside and after the start ramp, to 1e-12 of
    each output's range."""
    import ctypes
    from hydrofmu.cc import cached_many
    from hydrofmu.physics.waves import SeaState, TransferFunction, WaveLoad, components
    physics = Path(__import__("hydrofmu").__file__).parent / "physics"
    lib = ctypes.CDLL(str(cached_many([physics / "waves.c"], "waves_kernel", libs=["-lm"],
                                      flags=["-O2", "-shared", "-fPIC", "-std=c99"])))
    lib.hf_wave_build.restype = ctypes.POINTER(ctypes.c_double)

    class Sea(ctypes.Structure):
        _fields_ = [("spectrum", ctypes.c_int)] + [(k, ctypes.c_double) for k in (
            "height", "period", "phase", "hs", "tp", "gamma", "direction", "spreading", "components", "seed", "ramp",
            "depth")]

    rng = np.random.default_rng(3)
    omega = np.linspace(0.2, 2.0, 19)
    cases = [(np.array([0.0, 90.0, 180.0, 270.0]), SeaState("jonswap", hs=3.0, tp=9.0, spreading=4.0, components=60,
                                                             seed=7, ramp=20.0, direction=350.0)),
             (np.array([0.0, 30.0, 60.0]), SeaState("pierson_moskowitz", hs=2.0, tp=11.0, components=40,
                                                    seed=2 ** 40 + 3, direction=45.0, depth=30.0)),
             (np.array([90.0, 30.0, 60.0]), SeaState("regular", height=2.0, period=6.0, phase=30.0, direction=70.0,
                                                     ramp=5.0))]
    for directions, sea in cases:
        values = 1e5 * (rng.normal(size=(19, directions.size, 6)) + 1j * rng.normal(size=(19, directions.size, 6)))
        tf = TransferFunction(omega, directions, values, (12.0, -5.0), 9.81, sea.depth)
        wave = WaveLoad(components(sea, (0.2, 2.0)), tf, (12.0, -5.0), sea.ramp, 9.81, sea.depth)
        spec = {"regular": 0, "jonswap": 1, "pierson_moskowitz": 2}[sea.spectrum]
        c_sea = Sea(spec, *(float(getattr(sea, f)) for f, _ in Sea._fields_[1:]))
        record = tf.c_params((0.2, 2.0))
        field, message = ctypes.create_string_buffer(16), ctypes.create_string_buffer(400)
        params = lib.hf_wave_build(ctypes.byref(c_sea), (ctypes.c_double * len(record))(*record),
                                   ctypes.c_double(9.81), field, message, ctypes.c_size_t(400))
        assert params, message.value
        n = wave.omega.size
        assert int(params[0]) == n and np.allclose(params[2:2 + n], wave.omega, rtol=1e-13, atol=0)
        out = (ctypes.c_double * 7)()
        ref, got = [], []
        lib.hf_wave_phasors.restype = ctypes.c_void_p
        phasors = ctypes.c_void_p(lib.hf_wave_phasors(params))
        # fixed steps (the phasors rotate), then variable ones and a jump back (exact)
        times = np.r_[np.linspace(-1.0, 200.0, 2011), np.cumsum(rng.uniform(0.01, 0.3, 300)), 7.0, 7.1]
        for t in times:
            lib.hf_waves(params, phasors, ctypes.c_double(t), out)
            got.append(list(out))
            ref.append(wave(t))
        lib.hf_phasors_delete(phasors)
        ref, got = np.array(ref), np.array(got)
        span = ref.max(axis=0) - ref.min(axis=0)
        assert (span > 0).all() and np.all(np.abs(got - ref).max(axis=0) <= 1e-12 * span), sea
        ctypes.CDLL(None).free(params)


# -- waves and hydrostatics -------------------------------------------------------------------

def wave_scene(tmp, bem, bodies, waves, method=None):
    """A scene of floating cylinders of the BEM test datasets (tests/test_waves_fmu.py):
    wave excitation, BEM hydrostatics, radiation memory by ``method`` (None: no radiation; the
    memories are held against the Python flavour on the other scenes, and a state-space fit and
    the BEM report cost seconds); ``bodies`` {name: x}."""
    from test_waves_fmu import scene_text
    shutil.copy(bem, Path(tmp) / bem.name)
    text = scene_text(bem, bodies, [1e4, 1e4, 2e4, 1e6, 1e6, 1e6], waves, step=0.1, method=method or "convolution",
                      radiation=method is not None)
    (Path(tmp) / "waves.toml").write_text(text)
    return Path(tmp) / "waves.toml"


WAVE_SCENES = {
    # one cylinder (its BEM directions 0...90 deg do not go round the circle)
    "regular": ("wave_cylinder.nc", {"cyl": 0.0}, 'spectrum = "regular"\nheight = 2.0\nperiod = 7.0\n'
                'direction = 30.0\nphase = 10.0\nramp = 10.0', None,
                {"waves.period": 8.5, "waves.direction": 60.0, "waves.phase": -40.0, "waves.height": 1.5}),
    # the pair 10 m either side of the origin (directions all round: a direction across 360 deg)
    "irregular": ("wave_pair.nc", {"cyl1": -10.0, "cyl2": 10.0}, 'spectrum = "jonswap"\nhs = 3.0\ntp = 9.0\n'
                  'gamma = 2.0\ndirection = 200.0\nspreading = 6.0\ncomponents = 80\nseed = 5\nramp = 15.0',
                  None, {"waves.hs": 2.5, "waves.seed": 11, "waves.direction": 355.0, "waves.gamma": 3.3,
                                  "waves.components": 120, "waves.tp": 10.0}),
}


@pytest.fixture(scope="module")
def wave_builds(tmp_path_factory):
    """The WAVE_SCENES, compiled flavour: {name: folder}."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    out = {}
    for name, (bem, bodies, waves, method, _) in WAVE_SCENES.items():
        tmp = tmp_path_factory.mktemp(name)
        scene = load_scene(wave_scene(tmp, Path(__file__).parent / "data" / "bem" / bem, bodies, waves, method))
        out[name] = build_scene(scene, tmp / "fmus", log=lambda *_: None, runtime="c")
    return out


@pytest.mark.parametrize("name", sorted(WAVE_SCENES))
def test_wave_scene_compiled_equals_python(name, wave_builds, tmp_path):
    """Wave excitation (regular; JONSWAP with spreading), BEM hydrostatics and radiation memory,
    bodies away from the origin, the sea state changed through the waves.* parameters at
    initialization (a new draw of the components in both flavours): every output of the load
    FMUs compiled = Python to 1e-10 of its range over 1000 steps (their dynamics partners,
    which hold no wave kernel, are held so on the other scenes)."""
    params = WAVE_SCENES[name][-1]
    assert assert_equal_flavours(wave_builds[name], tmp_path, params=params, loads_only=True) <= 1e-10


def random_wave_scene(seed, tmp):
    """The BEM pair (10 m either side of the origin) and a random sea state."""
    rng = np.random.default_rng(seed)
    u = rng.uniform
    spectrum = ["regular", "jonswap", "pierson_moskowitz"][seed % 3]
    knobs = (f"height = {u(0.5, 3):.4g}\nperiod = {u(5, 12):.4g}\nphase = {u(-180, 180):.4g}" if spectrum == "regular"
             else f"hs = {u(1, 5):.4g}\ntp = {u(7, 12):.4g}\nspreading = {u(0, 10):.3g}\ncomponents = "
                  f"{int(u(20, 150))}\nseed = {int(u(0, 2 ** 40))}" + ("\ngamma = %.3g" % u(1, 5) if spectrum == "jonswap" else ""))
    waves = f'spectrum = "{spectrum}"\ndirection = {u(0, 360):.4g}\nramp = {u(0, 20):.3g}\n{knobs}'
    return wave_scene(tmp, Path(__file__).parent / "data" / "bem" / "wave_pair.nc", {"cyl1": -10.0, "cyl2": 10.0}, waves)


@pytest.mark.parametrize("seed", [3, 5])
def test_random_wave_scene_compiled_equals_python(seed, tmp_path):
    """Randomised wave scenes (regular, Pierson-Moskowitz; JONSWAP is the named irregular scene):
    the load FMUs compiled = Python to 1e-10 of each output's range."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    folder = build_scene(load_scene(random_wave_scene(seed, tmp_path)), tmp_path / "fmus", log=lambda *_: None,
                         runtime="c")
    assert assert_equal_flavours(folder, tmp_path, seed=seed, loads_only=True, hold=3) <= 1e-10


def test_bad_sea_state_fails_initialization_naming_the_knob(wave_builds, tmp_path, capfd):
    """A waves.* value that is not a usable sea state: fmi2ExitInitializationMode is fmi2Error
    with a log line naming the parameter, the Python flavour's line; a host that steps on
    anyway gets fmi2Error from the step in either flavour, never loads without the waves."""
    from fmpy.fmi1 import FMICallException
    fmu = wave_builds["irregular"] / "waves_cyl1.fmu"
    unzipped = tmp_path / "u"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    for knob, value, message in (("waves.hs", -1.0, "waves.hs: significant wave height must not be negative"),
                                 ("waves.tp", 1.5, "waves.tp: Tp = 1.5 s: "),
                                 ("waves.seed", 1.5, "waves.seed: must be a non-negative integer, found 1.5")):
        md, s = compiled_slave(fmu, unzipped)
        refs = {v.name: v.valueReference for v in md.modelVariables}
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.setReal([refs[knob]], [value])
        capfd.readouterr()
        with pytest.raises(FMICallException):
            s.exitInitializationMode()
        assert message in capfd.readouterr().out
        with pytest.raises(FMICallException):
            s.doStep(0.0, 0.1)
        assert "the waves.* parameters are not a usable sea state" in capfd.readouterr().out
        s.freeInstance()
        py, lines = python_slave(unzipped), []
        py.log = lambda text, *args, **kwargs: lines.append(text)
        py.setup_experiment(0.0)
        py.enter_initialization_mode()
        py.set_real([refs[knob]], [value])
        py.exit_initialization_mode()
        assert any(message in line for line in lines), lines
        del lines[:]
        assert py.do_step(0.0, 0.1) is False
        assert any("the waves.* parameters are not a usable sea state" in line and message in line
                   for line in lines), lines


def test_nonfinite_output_fails_the_step_that_made_it(compiled, tmp_path, capfd):
    """Finite inputs whose loads overflow (a drag on 1e200 m/s): the fmi2DoStep that evaluates
    them is fmi2Error with a log line naming the output (the outputs at a step's end are
    checked there, not only when read); inputs back to sane values, the FMU goes on."""
    from fmpy.fmi1 import FMICallException
    fmu = compiled["moored_barge"] / "moored_barge_barge.fmu"
    unzipped = tmp_path / "u"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    md, s = compiled_slave(fmu, unzipped)
    refs = {v.name: v.valueReference for v in md.modelVariables}
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    s.doStep(0.0, 0.1)
    s.setReal([refs["velocity[1]"]], [1e200])
    capfd.readouterr()
    with pytest.raises(FMICallException):
        s.doStep(0.1, 0.1)
    assert "is not finite" in capfd.readouterr().out
    s.setReal([refs["velocity[1]"]], [0.1])
    s.doStep(0.2, 0.1)
    assert np.isfinite(s.getReal([refs["force[1]"]])).all()
    s.terminate()
    s.freeInstance()


def test_wave_fmus_model_description_is_the_python_flavours(wave_builds, tmp_path):
    """A load FMU with waves and hydrostatics (and its dynamics partner): the same variables
    (the waves.* parameters included), units, start values and dependencies in both flavours."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    bem, bodies, waves, method, _ = WAVE_SCENES["regular"]
    scene = load_scene(wave_scene(tmp_path, Path(__file__).parent / "data" / "bem" / bem, bodies, waves, method))
    python = build_scene(scene, tmp_path / "py", log=lambda *_: None, runtime="python")
    for fmu in sorted(python.glob("*.fmu")):
        with zipfile.ZipFile(fmu) as a, zipfile.ZipFile(wave_builds["regular"] / fmu.name) as b:
            ours, theirs = variables(a.read("modelDescription.xml")), variables(b.read("modelDescription.xml"))
            assert ours == theirs, fmu.name
            if "dynamics" not in fmu.name:
                assert {"waves.height", "waves.period", "waves.phase", "waves.direction"} <= {r[0] for r in ours[0]}
