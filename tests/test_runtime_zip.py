"""The Python FMUs' runtime in one zip (fmi/runtime_zip.py): an FMU unpacks 10 files, and
several FMUs share a process safely — FMUs of different scenes, one FMU twice, an FMU of the
same name from another hydrofmu version (another runtime hash), instances freed and their
folders deleted while others run, instantiate-free-instantiate, and the runtime's modules
dropped from sys.modules between instances (what a build in the process does to the modules
it loaded) — in fmpy and in one libcosim execution, under PYTHONMALLOC=debug, and in a C host."""
import io
import json
import os
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from hydrofmu.fmi import build
from hydrofmu.fmi.build import build_scene
from hydrofmu.scene import load_scene

from conftest import MODELS
from test_native import fmpy_reference, hosts, run_fmi_host, unzip  # noqa: F401 (hosts: a fixture)

quiet = lambda *_: None  # noqa: E731


@pytest.fixture(scope="module")
def builds(demo_build, tmp_path_factory):
    """{label: FMU}: the moored barge's load and dynamics FMUs, a load FMU of the joined
    barges, and the moored barge's load FMU built by 'another hydrofmu version' (the same
    model identifier, another runtime hash)."""
    out = tmp_path_factory.mktemp("zipped")
    joined = build_scene(load_scene(MODELS / "joined_barges.toml"), out / "now", log=quiet)
    mp = pytest.MonkeyPatch()
    mp.setattr(build, "RUNTIME_INIT", build.RUNTIME_INIT + "# another hydrofmu version\n")
    try:
        other = build_scene(load_scene(MODELS / "moored_barge.toml"), out / "other", log=quiet)
    finally:
        mp.undo()
    return {"barge": demo_build / "moored_barge_barge.fmu", "dynamics": demo_build / "moored_barge_barge_dynamics.fmu",
            "joined": joined / "joined_barges_barge_a.fmu", "other": other / "moored_barge_barge.fmu"}


def runtime_of(fmu):
    with zipfile.ZipFile(fmu) as z:
        return next(n[len("resources/"):-4] for n in z.namelist() if n.endswith(".zip"))


def test_an_fmu_unpacks_ten_files(demo_build, builds):
    fmus = sorted(demo_build.glob("*.fmu")) + [builds["joined"]]
    for fmu in fmus:
        with zipfile.ZipFile(fmu) as z:
            names = z.namelist()
            rt = runtime_of(fmu)
            inner = zipfile.ZipFile(io.BytesIO(z.read(f"resources/{rt}.zip")))
        assert len(names) <= 10, names
        model_id = fmu.stem
        assert sorted(n for n in names if n.startswith("resources/")) == sorted(
            f"resources/{f}" for f in [f"{model_id}.py", "slavemodule.txt", "hydrofmu.json", "hydrofmu_python.txt",
                                       f"{rt}.zip", f"{rt}/physics/_rigid.so"])
        # the zip: the runtime (hash-named) and pythonfmu's slave API, sources with bytecode, no builder
        held = set(inner.namelist())
        tag = sys.implementation.cache_tag
        for module in [f"{rt}/__init__", f"{rt}/fmi/slave", f"{rt}/physics/memory", f"{rt}/description",
                       "pythonfmu/fmi2slave", "pythonfmu/__init__"]:
            folder, _, base = module.rpartition("/")
            assert {f"{module}.py", f"{folder}/__pycache__/{base}.{tag}.pyc"} <= held
        assert {n.split("/")[0] for n in held} == {rt, "pythonfmu"}
        assert not any(n.startswith(("pythonfmu/builder", f"{rt}/scene", f"{rt}/cosim")) for n in held)
        assert {i.compress_type for i in inner.infolist()} == {zipfile.ZIP_STORED}
    assert runtime_of(builds["other"]) != runtime_of(builds["barge"])


FMPY = r"""
import gc, json, shutil, sys
import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave
fmus = json.loads(sys.argv[1])
STEPS = 4

class Instance:
    def __init__(self, label, name):
        self.md = read_model_description(fmus[label])
        self.folder = extract(fmus[label])
        self.s = FMU2Slave(guid=self.md.guid, unzipDirectory=self.folder, instanceName=name,
                           modelIdentifier=self.md.coSimulation.modelIdentifier)
        self.s.instantiate()
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()
        self.out = [v.valueReference for v in self.md.modelVariables if v.causality == "output"]
        ins = [v for v in self.md.modelVariables if v.causality == "input"]
        self.s.setReal([v.valueReference for v in ins], [0.01 * (k + 1) for k in range(len(ins))])
        self.t = 0.0

    def steps(self, n=STEPS):
        rows = []
        for _ in range(n):
            self.s.doStep(self.t, 0.05)
            self.t += 0.05
            rows.append(self.s.getReal(self.out))
        return rows

    def free(self):
        self.s.terminate()
        self.s.freeInstance()
        shutil.rmtree(self.folder)   # as fmpy's simulate_fmu does

runtime = json.loads(sys.argv[2]).get
a1, joined, a2, dyn, other = (Instance("barge", "a1"), Instance("joined", "j"), Instance("barge", "a2"),
                              Instance("dynamics", "d"), Instance("other", "v"))
ref = a1.steps()
assert a2.steps() == ref and other.steps() == ref          # the same FMU twice, and from another runtime
joined.steps(); dyn.steps()
a1.free()                                                  # its folder deleted; the others run on
assert a2.steps() == other.steps()
a3 = Instance("barge", "a3")                               # instantiate again, from a new folder
assert a3.steps() == ref
# two runtimes side by side, each FMU's slave from its own
rts = {runtime("barge"), runtime("other")}
assert len(rts) == 2 and all(f"{rt}.fmi.slave" in sys.modules for rt in rts)
# ... with its compiled rigid-body kernel (found in resources/<runtime>/physics/, not the Python fallback)
assert all(sys.modules[f"{rt}.physics.rigid_kernel"].library() is not None for rt in rts)
# the runtime's modules dropped (as a build in this process drops those it loaded), every
# folder of this runtime's earlier instances deleted: a new instance imports it again
for inst in (a2, a3, joined, dyn):
    inst.free()
rt = runtime("barge")
for name in [m for m in sys.modules if m.split(".")[0] == rt]:
    del sys.modules[name]
a4 = Instance("barge", "a4")
assert a4.steps() == ref
assert sys.modules[f"{rt}.fmi.slave"].__file__.startswith(str(a4.folder))   # its kernels' folder exists
for k in range(3):                                         # instantiate, free, instantiate
    again = Instance("barge", f"cycle{k}")
    assert again.steps() == ref
    again.free()
assert other.steps(1) and a4.steps(1)
a4.free(); other.free()
gc.collect()
print("OK")
"""

LIBCOSIM = r"""
import gc, json, sys
from libcosimpy.CosimExecution import CosimExecution
from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
from libcosimpy.CosimObserver import CosimObserver
from libcosimpy.CosimSlave import CosimLocalSlave
log_output_level(CosimLogLevel.ERROR)
fmus, runtimes = json.loads(sys.argv[1]), json.loads(sys.argv[2]).values()

def run(labels, steps=4):
    ex = CosimExecution.from_step_size(step_size=50_000_000)
    seen = CosimObserver.create_last_value()
    ex.add_observer(seen)
    index, outs = {}, {}
    for k, label in enumerate(labels):
        name = f"{label}{k}"
        index[name] = ex.add_local_slave(CosimLocalSlave(fmu_path=fmus[label], instance_name=name))
        assert index[name] >= 0, f"libcosim could not load {label}"
        outs[name] = [v.reference for v in ex.slave_variables(index[name]) if v.causality == 2]
    rows = {name: [] for name in index}
    for _ in range(steps):
        assert ex.step()
        for name, i in index.items():
            rows[name].append(seen.last_real_values(i, outs[name]))
    ex.stop()
    del ex
    gc.collect()
    return rows

first = run(["barge", "barge", "joined", "dynamics", "other"])
assert first["barge0"] == first["barge1"] == first["other4"]
again = run(["barge", "other", "joined"])                   # a new execution: instantiate again
assert again["barge0"] == again["other1"] == first["barge0"] and again["joined2"] == first["joined2"]
# each runtime with its compiled kernel, and nothing that starts threads imported on libcosim's
# worker threads (Python would take the first to import threading for its main thread, and
# wait for it at exit for ever)
assert all(sys.modules[f"{rt}.physics.rigid_kernel"].library() is not None for rt in runtimes)
threading = sys.modules.get("threading")
assert threading is None or threading.main_thread().ident == threading.get_ident()
gc.collect()
print("OK")
"""


def in_debug_python(script, fmus):
    """Run a host ``script`` on ``fmus`` ({label: FMU}) in a fresh Python under PYTHONMALLOC=debug."""
    env = dict(os.environ, PYTHONMALLOC="debug")
    run = subprocess.run([sys.executable, "-c", script, json.dumps({k: str(v) for k, v in fmus.items()}),
                          json.dumps({k: runtime_of(v) for k, v in fmus.items()})],
                         capture_output=True, text=True, timeout=120, env=env)
    assert run.returncode == 0 and run.stdout.strip().endswith("OK"), run.stdout[-3000:] + run.stderr[-3000:]


def test_several_fmus_in_one_fmpy_process(builds):
    in_debug_python(FMPY, builds)


def test_several_fmus_in_one_libcosim_execution(builds):
    pytest.importorskip("libcosimpy")
    in_debug_python(LIBCOSIM, builds)


def test_two_runtimes_in_one_native_host(hosts, builds, tmp_path):
    """The moored barge's load FMU and its build by 'another version' (another runtime, the
    same model identifier) in one C host (no Python of its own: the shim starts it), four
    instances at once from four threads, instance k on build k mod 2: each equals the FMU
    stepped alone by fmpy with its inputs."""
    now, other = unzip(builds["barge"], tmp_path / "now"), unzip(builds["other"], tmp_path / "other")
    both = (Path(f"{now[0]},{other[0]}"),) + now[1:]
    vr = now[3]
    assert other[1:] != now[1:] and other[3] == vr   # another GUID, the same variables
    inputs = {vr["position[1]"]: 2.0, vr["velocity[1]"]: 0.3, vr["velocity[6]"]: 0.01}
    outputs = [vr[f"force[{i}]"] for i in (1, 2, 6)]
    run, got = run_fmi_host(hosts, both, 4, 5, 0.1, inputs, outputs)
    assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout[-2000:] + run.stderr
    assert "LOG" not in run.stdout and "NULL" not in run.stdout, run.stdout[-2000:]
    for k in range(4):
        want = fmpy_reference(now, 5, 0.1, {v: x * (k + 1) for v, x in inputs.items()}, outputs)
        assert {(n, o): got[k, n, o] for n, o in want} == want
