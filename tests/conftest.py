"""Shared test helpers: write a scene, build its FMUs, find the repository's files."""
import os
import shutil
from pathlib import Path
import textwrap

import pytest

ROOT = Path(__file__).resolve().parents[1]
MODELS = ROOT / "models"

# script lines for a fresh interpreter: FMU (a path) loaded with fmpy, instantiated,
# initialised and stepped once as ``s`` (extracted to ``unzipped``)
STEP_ONCE = """
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
md = read_model_description(FMU)
unzipped = extract(FMU)
s = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, instanceName="x",
              modelIdentifier=md.coSimulation.modelIdentifier)
s.instantiate()
s.setupExperiment(startTime=0.0)
s.enterInitializationMode()
s.exitInitializationMode()
s.doStep(0.0, 0.05)
"""


def in_ci() -> bool:
    """True in CI (the environment variable CI=true, set by .ci/run and most CI services)."""
    return os.environ.get("CI", "").strip().lower() in ("true", "1", "yes")


def tools(*names: str, why: str) -> list:
    """The paths of the programs ``names``.  One missing: the test is skipped with the reason in
    one line (a fresh machine has Python and cc only, as the README says), except in CI, which
    installs them (.ci/run) and where the test fails instead: nothing is skipped there."""
    found = [shutil.which(n) for n in names]
    missing = [n for n, f in zip(names, found) if f is None]
    if missing:
        reason = f"needs {' and '.join(missing)} ({why}; .ci/run installs them)"
        if in_ci():
            pytest.fail(f"CI=true but {reason}: not installed", pytrace=False)
        pytest.skip(reason)
    return found


def open_fmus(folder, manifest):
    """Every FMU of a built scene (its ``manifest``) on fmpy's FMU2Slave, instantiated and
    initialised with no input set; returns ({instance: slave}, {instance: {variable: value
    reference}}, {instance: {variable: declared start}})."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave
    fmus, vrs, starts = {}, {}, {}
    for name, inst in manifest["instances"].items():
        path = str(Path(folder) / inst["fmu"])
        md = read_model_description(path)
        s = FMU2Slave(guid=md.guid, unzipDirectory=extract(path), modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=name)
        s.instantiate()
        s.setupExperiment(startTime=0.0)
        s.enterInitializationMode()
        s.exitInitializationMode()
        fmus[name], vrs[name] = s, {v.name: v.valueReference for v in md.modelVariables}
        starts[name] = {v.name: float(v.start) for v in md.modelVariables if v.start is not None}
    return fmus, vrs, starts


def write_scene(folder, text, name="scene.toml"):
    path = Path(folder) / name
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(textwrap.dedent(text))
    return path


def build(folder, text, name="scene.toml"):
    """Write a scene into ``folder``, build it into folder/fmus; returns the built scene folder."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    scene = load_scene(write_scene(folder, text, name))
    return build_scene(scene, Path(folder) / "fmus", log=lambda *_: None)


@pytest.fixture(scope="session", autouse=True)
def scratch(tmp_path_factory):
    """Temporary files of the session (fmpy extracts every FMU it loads, and not every test
    frees it) under pytest's own base folder, which keeps only the last three sessions;
    TMPDIR too, for the fresh interpreters the tests start."""
    import os
    import tempfile
    folder = str(tmp_path_factory.mktemp("scratch"))
    saved = tempfile.tempdir, os.environ.get("TMPDIR")
    tempfile.tempdir, os.environ["TMPDIR"] = folder, folder
    yield folder
    tempfile.tempdir = saved[0]
    if saved[1] is None:
        os.environ.pop("TMPDIR", None)
    else:
        os.environ["TMPDIR"] = saved[1]


@pytest.fixture(scope="session")
def demo_build(tmp_path_factory):
    """The demo scene of models/, built once per session."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    out = tmp_path_factory.mktemp("demo")
    return build_scene(load_scene(MODELS / "moored_barge.toml"), out, log=lambda *_: None)


def coupled_pair_scene(deck, bodies, mode="explicit", stop=4.0, extra=""):
    """Scene text of the coupled-body tests (test_inprocess, test_start_values): ``bodies``
    [(name, y, acceleration_loads, velocity, attitude or None, z)], each of mass 1e6 kg; body
    'a' in a 1.5 m/s current with drag and a massive soft ball joint to the earth (its
    acceleration loads ``mode``); SIMO couplings SA (convolution), SB (state space) and AB
    (convolution) of the pair deck ``deck``; ``extra``: more tables (TOML)."""
    text = f"""
[environment]
current_speed = 1.5
current_direction = 30.0
[run]
step = 0.05
stop = {stop}
substep = 0.01
"""
    for name, y, loads, velocity, attitude, z in bodies:
        text += f"""
[bodies.{name}]
position = [0.0, {y}, {z}]
{f"attitude = {attitude}" if attitude else ""}
velocity = {velocity}
mass = 1.0e6
inertia = [1e8, 1.2e8, 1.5e8]
stiffness = [1e5, 1e5, 1e6, 1e8, 1e8, 1e8]
acceleration_loads = "{loads}"
"""
    text += f"""
[[bodies.a.effects]]
type = "aqwa_viscous_drag"
matrix = [2e4, 3e4, 1e4, 0.0, 0.0, 1e6]
option = "RELATIVE"
[joints.pin]
a = "a"
a_point = [10.0, 0.0, -2.0]
stiffness = 2.0e5
damping = 2.0e5
am = 2.0e4
cd = [1e3, 1e3, 1e3]
added_mass = [1e4, 1e4, 1e4]
acceleration_loads = "{mode}"
""" + extra
    return text + "".join(f"""
[[couplings]]
deck = "{deck}"
coupling = "{c}"
method = "{method}"
""" for c, method in (("SA", "convolution"), ("SB", "state_space"), ("AB", "convolution")))
