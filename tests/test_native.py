"""The FMUs in native hosts: processes with no Python of their own.

Two C programs of tests/native/ are compiled here with the system C compiler: a libcosim
host (libcosimc.so from the installed libcosimpy wheel) and a minimal generic FMI 2.0
host (dlopen + the fmi2 functions, one thread per instance).  Each runs as a subprocess
with a clean environment (no PYTHONPATH, LD_PRELOAD, PYTHONHOME, VIRTUAL_ENV): the FMU's
shim has to find, start and check Python itself.  Results are compared with our fmpy
master (libcosim's fixed-step algorithm is a Jacobi scheme) and with the same FMU driven
in-process by fmpy.
"""
import ast
import json
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from conftest import MODELS, open_fmus
from hydrofmu.bench import native as native_timing
from hydrofmu.bench.robust import ARENA_KB, FLAT_KB, growth

pytest.importorskip("libcosimpy")
NATIVE = Path(__file__).with_name("native")
SCENES = sorted(p.stem for p in MODELS.glob("*.toml"))
STEPS = 30  # communication steps per native run: short, but past every memory's first nodes


def clean_env(**extra):
    """This process's environment without anything that would put Python in reach."""
    env = {k: v for k, v in os.environ.items()
           if k not in ("PYTHONPATH", "LD_PRELOAD", "PYTHONHOME", "VIRTUAL_ENV", "HYDROFMU_PYTHON")}
    env.update(extra)
    return env


def compile_c(source, out, *flags):
    cc = shutil.which("cc") or shutil.which("gcc")
    if cc is None:
        pytest.fail("no C compiler on PATH (the native-host tests need `cc`)")
    subprocess.run([cc, "-O1", "-o", str(out), str(NATIVE / source), *flags], check=True)
    return out


@pytest.fixture(scope="session")
def hosts(tmp_path_factory):
    """{'cosim': libcosim host, 'fmi': generic FMI host}, compiled once per session."""
    import libcosimpy
    lib = Path(libcosimpy.__file__).parent / "libcosimc"
    d = tmp_path_factory.mktemp("hosts")
    return {
        "cosim": compile_c("cosim_run.c", d / "cosim_run", f"-L{lib}", "-lcosimc", f"-Wl,-rpath,{lib}"),
        "fmi": compile_c("fmi_host.c", d / "fmi_host", f"-I{Path(native_timing.SOURCE).parent}", "-ldl", "-lpthread"),
    }


@pytest.fixture(scope="session")
def scenes(tmp_path_factory):
    """Every scene of models/, built once: {name: folder}."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    out = tmp_path_factory.mktemp("scenes")
    return {name: build_scene(load_scene(MODELS / f"{name}.toml"), out, log=lambda *_: None) for name in SCENES}


def run_cosim(hosts, config, stop, step, out, env=None):
    """The libcosim host on ``config``; returns {instance file prefix: (header, rows)}."""
    out.mkdir(parents=True, exist_ok=True)
    run = subprocess.run([str(hosts["cosim"]), str(config), repr(stop), repr(step), str(out)],
                         env=env or clean_env(), capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    tables = {}
    for csv in out.glob("*.csv"):
        instance = re.match(r"(.+)_\d{8}_\d{6}_\d+\.csv$", csv.name).group(1)
        # names like added_mass[1,2] hold commas: split only outside brackets
        header = re.split(r",(?![^\[]*\])", csv.open().readline().strip())
        tables[instance] = (header, np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2))
    return tables


@pytest.fixture(scope="session")
def jacobi(scenes):
    """name -> our fmpy Jacobi run of that scene over STEPS steps (run once, on demand)."""
    from hydrofmu.cosim import master
    runs = {}

    def get(name):
        if name not in runs:
            step = json.loads((scenes[name] / "manifest.json").read_text())["run"]["step"]
            runs[name] = master.run(scenes[name], stop=STEPS * step, step=step, algorithm="jacobi", progress=False)
        return runs[name]
    return get


def assert_equals_jacobi(tables, ours):
    """Every output column libcosim's file observer wrote equals our fmpy Jacobi run to
    the 6 significant digits the observer prints."""
    compared = 0
    for col in ours.columns:
        instance, var = col.split(".", 1)
        header, rows = tables[instance]
        theirs = rows[:, header.index(var)]
        assert len(theirs) == len(ours.time), col
        np.testing.assert_allclose(rows[:, 0], ours.time, atol=1e-9)
        scale = np.max(np.abs(ours[col]))
        np.testing.assert_allclose(theirs, ours[col], rtol=6e-6, atol=1e-9 * scale + 1e-30, err_msg=col)
        compared += 1
    assert compared == len(ours.columns) > 0
    return ours


HOST_PACKAGES = ("numpy",)  # what the README says a host's Python needs for the FMUs of models/


@pytest.fixture(scope="session")
def host_venv(tmp_path_factory):
    """A fresh venv holding exactly HOST_PACKAGES (linked from this environment's
    installation, which is what pip would unpack: no index needed, no time spent)."""
    import importlib.metadata as meta
    venv = tmp_path_factory.mktemp("hostvenv") / "venv"
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(venv)], check=True)
    site = next(venv.glob("lib/python3*/site-packages"))
    for name in HOST_PACKAGES:
        dist = meta.distribution(name)
        tops = {Path(str(f)).parts[0] for f in dist.files if not str(f).startswith("..")}
        for top in tops:  # the package, its bundled libraries (numpy.libs) and its dist-info
            src = Path(dist.locate_file(top))
            if src.exists() and not (site / top).exists():
                (site / top).symlink_to(src)
    return venv / "bin" / "python"


def test_host_venv_holds_exactly_the_readme_packages(host_venv):
    check = subprocess.run([str(host_venv), "-c", "import numpy, pkgutil, sys; "
                            "print(sorted(m.name for m in pkgutil.iter_modules(sys.path[-1:])))"],
                           capture_output=True, text=True, env=clean_env())
    assert check.returncode == 0, check.stderr
    assert sorted(ast.literal_eval(check.stdout)) == sorted(HOST_PACKAGES)


@pytest.mark.parametrize("name", SCENES)
def test_libcosim_native_host_runs_osp_system_structure(name, scenes, hosts, host_venv, jacobi, tmp_path):
    """Every scene from its OspSystemStructure.xml, every FMU's Python being a fresh venv
    with exactly the packages the README names (HYDROFMU_PYTHON)."""
    folder = scenes[name]
    ours = jacobi(name)
    tables = run_cosim(hosts, folder / "OspSystemStructure.xml", float(ours.time[-1]), ours.step, tmp_path / "out",
                       env=clean_env(HYDROFMU_PYTHON=str(host_venv)))
    assert_equals_jacobi(tables, ours)
    assert np.ptp(ours.values, axis=0).max() > 0  # something moves


def test_every_fmu_of_models_validates(scenes):
    from fmpy.validation import validate_fmu
    problems = {f.name: validate_fmu(str(f)) for folder in scenes.values() for f in folder.glob("*.fmu")}
    assert len(problems) >= 7 and not any(problems.values()), problems


# -- SSP ----------------------------------------------------------------------------------

@pytest.mark.parametrize("name", SCENES)
def test_ssp_validates_and_runs_in_libcosim_native(name, scenes, hosts, jacobi, tmp_path):
    """<scene>.ssp passes fmpy's SSP schema validation and, loaded by libcosim's SSP
    loader in the native host (step from the file's annotation, the Python recorded at
    build time), equals our Jacobi run."""
    from fmpy.ssp.ssd import read_ssd
    folder = scenes[name]
    ssp = folder / f"{name}.ssp"
    ssd = read_ssd(str(ssp), validate=True)
    manifest = json.loads((folder / "manifest.json").read_text())
    assert sorted(c.name for c in ssd.system.elements) == sorted(manifest["instances"])
    assert len(ssd.system.connections) == len(manifest["connections"])
    ours = jacobi(name)
    tables = run_cosim(hosts, ssp, float(ours.time[-1]), 0, tmp_path / "out")
    assert_equals_jacobi(tables, ours)


def test_ssp_contents(scenes):
    """Units with their SI exponents, parameters and inputs bound to their start values
    (the build's, the FMUs' own), and the default experiment: what an SSP importer reads
    without opening the FMUs."""
    from xml.etree import ElementTree as ET
    from fmpy import read_model_description
    from hydrofmu.fmi.ssp import SSC, SSD, SSV, base_unit
    folder = scenes["moored_barge"]
    with zipfile.ZipFile(folder / "moored_barge.ssp") as z:
        root = ET.fromstring(z.read("SystemStructure.ssd"))
        assert sorted(n for n in z.namelist() if n.endswith(".fmu")) == sorted(
            f"resources/{p.name}" for p in folder.glob("*.fmu"))
    ns = {"ssd": SSD, "ssc": SSC, "ssv": SSV}
    exp = root.find("ssd:DefaultExperiment", ns)
    assert float(exp.get("stopTime")) == 600.0 and 'baseStepSize="0.1"' in ET.tostring(exp, encoding="unicode")
    units = {u.get("name"): u.find("ssc:BaseUnit", ns).attrib for u in root.iter(f"{{{SSC}}}Unit")}
    assert units["N.m"] == {"kg": "1", "m": "2", "s": "-2"} and units["kg.m2"] == {"kg": "1", "m": "2"}
    assert units["m/s2"] == {"m": "1", "s": "-2"} and units["kg/m3"] == {"kg": "1", "m": "-3"}
    assert base_unit("deg") == {"rad": "1", "factor": repr(np.pi / 180)}
    for comp in root.iter(f"{{{SSD}}}Component"):
        md = read_model_description(str(folder / Path(comp.get("source")).name))
        kinds = {c.get("name"): c.get("kind") for c in comp.iter(f"{{{SSD}}}Connector")}
        start = {v.name: float(v.start) for v in md.modelVariables
                 if v.causality == "parameter" or kinds.get(v.name) == "input"}
        bound = {p.get("name"): float(p.find("ssv:Real", ns).get("value")) for p in comp.iter(f"{{{SSV}}}Parameter")}
        assert bound == start and bound  # rho, g, added mass, every connected input …
        assert {kinds[p] for p in bound} <= {"parameter", "input"}
    assert "rho" in bound or any("added_mass" in p for p in bound)


@pytest.mark.parametrize("name", SCENES)
def test_ssp_runs_in_fmpy(name, scenes):
    """fmpy's SSP simulator runs the .ssp.  Its master starts every connector at 0 (no
    initial exchange) and records each row after the step, so its numbers are compared
    with a Jacobi loop of the same convention written here over the manifest."""
    from fmpy.ssp.simulation import simulate_ssp
    folder = scenes[name]
    manifest = json.loads((folder / "manifest.json").read_text())
    step = manifest["run"]["step"]
    theirs = simulate_ssp(str(folder / f"{name}.ssp"), stop_time=10 * step, step_size=step)
    assert len(theirs) in (10, 11)  # fmpy accumulates time += step: a last step may follow
    ours = zero_start_jacobi(folder, manifest, len(theirs), step)
    for column, values in ours.items():
        np.testing.assert_allclose(theirs[column], values, rtol=1e-12, atol=1e-12, err_msg=column)


def zero_start_jacobi(folder, manifest, steps, step):
    """Every connected output after each step, with every connected input 0 at the first
    step and each step's inputs the outputs of the step before (fmpy's SSP convention)."""
    fmus, vrs, _ = open_fmus(folder, manifest)
    conns = manifest["connections"]
    value = {(d, dv): 0.0 for _, _, d, dv in conns}
    out = {f"{s}.{sv}": [] for s, sv, _, _ in conns}
    for k in range(steps):
        got = {}
        for name, s in fmus.items():
            ins = [(dv, value[d, dv]) for _, _, d, dv in conns if d == name]
            s.setReal([vrs[name][v] for v, _ in ins], [x for _, x in ins])
            s.doStep(k * step, step)
            for src, sv, _, _ in conns:
                if src == name:
                    got[src, sv] = s.getReal([vrs[name][sv]])[0]
        for src, sv, d, dv in conns:
            value[d, dv] = got[src, sv]
        for (src, sv), v in got.items():
            out[f"{src}.{sv}"].append(v)
    for s in fmus.values():
        s.terminate()
        s.freeInstance()
    return out


# -- the generic FMI host -----------------------------------------------------------------

def unzip(fmu, where):
    """Unzip an FMU; returns (folder, model identifier, guid, {variable name: vr})."""
    from fmpy import read_model_description
    md = read_model_description(str(fmu))
    with zipfile.ZipFile(fmu) as z:
        z.extractall(where)
    return (Path(where), md.coSimulation.modelIdentifier, md.guid,
            {v.name: v.valueReference for v in md.modelVariables})


def run_fmi_host(hosts, unzipped, threads, steps, dt, inputs, outputs, env=None):
    """The generic host; returns (completed process, {(instance, step, vr): value})."""
    folder, mid, guid, _ = unzipped
    run = subprocess.run([str(hosts["fmi"]), str(folder), mid, guid, str(threads), str(steps), repr(dt),
                          ",".join(f"{vr}:{v!r}" for vr, v in inputs.items()), ",".join(map(str, outputs))],
                         env=env or clean_env(), capture_output=True, text=True, timeout=120)
    values = {}
    for line in run.stdout.splitlines():
        parts = line.split()
        if len(parts) == 4 and parts[0].isdigit():
            values[int(parts[0]), int(parts[1]), int(parts[2])] = float(parts[3])
    return run, values


@pytest.fixture(scope="module")
def load_fmu(scenes, tmp_path_factory):
    """moored_barge's load FMU, unzipped: it has a memory-free damping and a mooring."""
    return unzip(scenes["moored_barge"] / "moored_barge_barge.fmu", tmp_path_factory.mktemp("load"))


def fmpy_reference(unzipped, steps, dt, inputs, outputs):
    """The same FMU, same inputs, stepped in this process by fmpy: {(step, vr): value}."""
    from fmpy.fmi2 import FMU2Slave
    folder, mid, guid, _ = unzipped
    s = FMU2Slave(guid=guid, unzipDirectory=str(folder), modelIdentifier=mid, instanceName="ref")
    s.instantiate()
    s.setupExperiment(startTime=0.0)
    s.enterInitializationMode()
    s.exitInitializationMode()
    out = {}
    for n in range(steps):
        s.setReal(list(inputs), list(inputs.values()))
        s.doStep(n * dt, dt)
        for vr, v in zip(outputs, s.getReal(outputs)):
            out[n + 1, vr] = v
    s.terminate()
    s.freeInstance()
    return out


def test_two_threads_two_instances(hosts, load_fmu):
    """One load FMU, two instances stepped at once from two threads of a C host, each
    with its own inputs: each equals the FMU run alone in this process with its inputs."""
    vr = load_fmu[3]
    inputs = {vr["position[1]"]: 2.0, vr["position[2]"]: -1.0, vr["velocity[1]"]: 0.3,
              vr["velocity[2]"]: -0.2, vr["velocity[6]"]: 0.01}
    outputs = [vr[f"force[{i}]"] for i in range(1, 7)]
    steps, dt = 40, 0.1
    run, got = run_fmi_host(hosts, load_fmu, 2, steps, dt, inputs, outputs)
    assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout + run.stderr
    assert "LOG" not in run.stdout
    for k in (0, 1):
        ref = fmpy_reference(load_fmu, steps, dt, {v: x * (k + 1) for v, x in inputs.items()}, outputs)
        theirs = np.array([got[k, n, o] for n, o in ref])
        np.testing.assert_array_equal(theirs, np.array(list(ref.values())))
    assert got[0, steps, outputs[0]] != got[1, steps, outputs[0]]  # the instances differ


def cycled(hosts, unzipped, cycles, every, inputs, outputs, steps=5, dt=0.1):
    """The generic host after FMI_HOST_CYCLES: ({cycle: RSS kB}, {(instance, step, vr): value}),
    and the same run in a fresh process (no cycles before): its values."""
    run, got = run_fmi_host(hosts, unzipped, 1, steps, dt, inputs, outputs,
                            env=clean_env(FMI_HOST_CYCLES=f"{cycles}:{every}"))
    assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout[-2000:] + run.stderr
    assert "LOG" not in run.stdout and "failed" not in run.stdout, run.stdout[-2000:]
    rss = {int(p[1]): int(p[2]) for p in (line.split() for line in run.stdout.splitlines()) if p[:1] == ["rss"]}
    assert sorted(rss) == list(range(every, cycles + 1, every))
    return rss, got, run_fmi_host(hosts, unzipped, 1, steps, dt, inputs, outputs)[1]


def test_ten_thousand_instantiate_free_cycles_at_flat_memory(hosts, load_fmu):
    """10⁴ fmi2Instantiate … fmi2FreeInstance cycles of one load FMU in a native host, each
    initialised and stepped once: resident memory is flat over the last 9000 (bench/robust.py:
    FLAT_KB and ARENA_KB, and what they rest on; without the pool it grows 12 MB).  The
    run's instance then (a pooled one, reset) steps bit for bit like a fresh process's."""
    vr = load_fmu[3]
    inputs = {vr["position[1]"]: 2.0, vr["position[2]"]: -1.0, vr["velocity[1]"]: 0.3, vr["velocity[6]"]: 0.01}
    outputs = [vr[f"force[{i}]"] for i in range(1, 7)]
    rss, got, fresh = cycled(hosts, load_fmu, 10_000, 1000, inputs, outputs)
    steady, total = growth([rss[k] for k in sorted(rss)])
    assert steady < FLAT_KB and total < ARENA_KB, rss
    assert got == fresh and len(got) == 30


def test_dynamics_fmu_cycles_at_flat_memory(hosts, scenes, tmp_path):
    """The same for a dynamics FMU (a state that integrates), 3000 cycles, flat after 1000
    (sampled every 250: under a loaded machine a few 16 kB allocator steps came after the
    first 1000 cycles, which a median over five 500-cycle samples could not see past);
    the pooled instance, stepped with other forces in every cycle, restarts from rest."""
    dyn = unzip(scenes["moored_barge"] / "moored_barge_barge_dynamics.fmu", tmp_path)
    vr = dyn[3]
    inputs = {vr["force[1]"]: 1e3, vr["force[3]"]: -5e2, vr["force[5]"]: 2e3}
    outputs = [vr[f"position[{i}]"] for i in range(1, 4)] + [vr[f"attitude[{i}]"] for i in range(1, 4)]
    rss, got, fresh = cycled(hosts, dyn, 3000, 250, inputs, outputs)
    steady, total = growth([rss[k] for k in sorted(rss) if k >= 1000])
    assert steady < FLAT_KB and total < ARENA_KB, rss
    assert got == fresh and len(got) == 30 and got[0, 5, outputs[0]] != 0.0


def test_two_fmus_start_python_at_once(hosts, load_fmu, tmp_path):
    """Two copies of the FMU (two libraries, two shims) instantiated at the same moment
    from four threads: one of them starts Python, the other waits for it and uses it
    (unguarded, the two started Python together and the host crashed)."""
    vr = load_fmu[3]
    copy = tmp_path / "copy"
    shutil.copytree(load_fmu[0], copy)
    both = (Path(f"{load_fmu[0]},{copy}"),) + load_fmu[1:]
    inputs, outputs = {vr["velocity[1]"]: 0.3}, [vr["force[1]"]]
    want = {k: fmpy_reference(load_fmu, 3, 0.1, {v: x * (k + 1) for v, x in inputs.items()}, outputs)
            for k in range(4)}
    for _ in range(3):  # a race: a few tries
        run, got = run_fmi_host(hosts, both, 4, 3, 0.1, inputs, outputs)
        assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout + run.stderr
        assert "LOG" not in run.stdout
        assert got == {(k, n, o): v for k, ref in want.items() for (n, o), v in ref.items()}


def test_python_without_numpy_fails_instantiate_not_the_host(hosts, load_fmu, tmp_path):
    """HYDROFMU_PYTHON names a bare venv (no numpy): fmi2Instantiate returns NULL with
    one log message saying what was tried and how to fix it; the host exits normally."""
    subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(tmp_path / "bare")], check=True)
    bare = tmp_path / "bare" / "bin" / "python"
    run, got = run_fmi_host(hosts, load_fmu, 1, 3, 0.1, {0: 0.0}, [0], env=clean_env(HYDROFMU_PYTHON=str(bare)))
    assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout + run.stderr
    assert "instantiate: NULL" in run.stdout and not got
    logs = [line for line in run.stdout.splitlines() if line.startswith("LOG")]
    assert len(logs) == 1, logs
    assert "NULL-CATEGORY" not in logs[0]
    for said in ("cannot import numpy", str(bare), "HYDROFMU_PYTHON", "No module named 'numpy'"):
        assert said in logs[0]


def test_missing_interpreter_fails_instantiate_with_one_message(hosts, load_fmu):
    run, got = run_fmi_host(hosts, load_fmu, 1, 3, 0.1, {0: 0.0}, [0],
                            env=clean_env(HYDROFMU_PYTHON="/nonexistent/bin/python"))
    assert run.returncode == 0 and "instantiate: NULL" in run.stdout and not got
    logs = [line for line in run.stdout.splitlines() if line.startswith("LOG")]
    assert len(logs) == 1 and "/nonexistent/bin/python" in logs[0] and "HYDROFMU_PYTHON" in logs[0], logs


def test_hydrofmu_python_selects_the_interpreter(hosts, load_fmu):
    """HYDROFMU_PYTHON pointing at this interpreter works like the recorded one."""
    vr = load_fmu[3]
    inputs, outputs = {vr["velocity[1]"]: 0.5}, [vr["force[1]"]]
    plain = run_fmi_host(hosts, load_fmu, 1, 5, 0.1, inputs, outputs)[1]
    chosen = run_fmi_host(hosts, load_fmu, 1, 5, 0.1, inputs, outputs, env=clean_env(HYDROFMU_PYTHON=sys.executable))[1]
    assert plain == chosen and len(plain) == 5


def test_exception_with_no_category_reaches_the_host_as_text(hosts, load_fmu, tmp_path):
    """pythonfmu reports a Python exception in the constructor with a NULL log category;
    the host must get a string.  A config file the slave cannot parse makes one."""
    broken = tmp_path / "broken"
    shutil.copytree(load_fmu[0], broken)
    (broken / "resources" / "hydrofmu.json").write_text("{not json")
    run, got = run_fmi_host(hosts, (broken,) + load_fmu[1:], 1, 3, 0.1, {0: 0.0}, [0])
    assert run.returncode == 0 and "instantiate: NULL" in run.stdout, run.stdout + run.stderr
    logs = [line for line in run.stdout.splitlines() if line.startswith("LOG")]
    assert logs and not any("NULL-CATEGORY" in line or "NULL-MESSAGE" in line for line in logs), logs
    assert "JSONDecodeError" in run.stdout  # the message's second line


# -- Python thread states and BLAS threads in a native host ---------------------------------

def probed(run):
    """{instance: [the Python thread state its thread held after each step]} and the
    process's thread count once the instances ended, from an FMI_HOST_PROBE run."""
    states, threads = {}, None
    for p in (line.split() for line in run.stdout.splitlines()):
        if p[:1] == ["tstate"]:
            states.setdefault(int(p[1]), []).append(int(p[3], 16) if p[3] != "(nil)" else 0)
        elif p[:1] == ["threads"]:
            threads = int(p[1])
    return states, threads


def test_host_threads_keep_one_python_thread_state(hosts, load_fmu):
    """Two host threads Python does not know, one instance each: between FMI calls each
    thread still holds the same Python thread state (the shim keeps it: no call creates or
    deletes one), and once they ended the process runs no BLAS threads (the host's main
    thread and Python's own only: numpy's OpenBLAS starts one per core unless told, and the
    host's environment does not tell it); the outputs equal fmpy's here bit for bit."""
    vr = load_fmu[3]
    inputs = {vr["position[1]"]: 2.0, vr["velocity[1]"]: 0.3, vr["velocity[6]"]: 0.01}
    outputs = [vr[f"force[{i}]"] for i in (1, 2, 6)]
    env = {k: v for k, v in clean_env(FMI_HOST_PROBE="1").items()
           if k not in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")}
    run, got = run_fmi_host(hosts, load_fmu, 2, 20, 0.1, inputs, outputs, env=env)
    assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout + run.stderr
    states, threads = probed(run)
    assert sorted(states) == [0, 1] and all(len(s) == 20 for s in states.values())
    assert all(s[0] != 0 and set(s) == {s[0]} for s in states.values()), states
    assert states[0][0] != states[1][0]
    assert threads == 2
    for k in (0, 1):
        ref = fmpy_reference(load_fmu, 20, 0.1, {v: x * (k + 1) for v, x in inputs.items()}, outputs)
        assert {(n, o): got[k, n, o] for n, o in ref} == ref


def test_every_call_from_a_thread_of_its_own(hosts, scenes, tmp_path):
    """A host that makes each step of an instance in a new thread, ended after the step, and
    frees the instance from yet another: every thread's Python state is deleted as the
    thread ends (while Python runs on), nothing crashes, and both instances of the dynamics
    FMU step as fmpy steps them, bit for bit."""
    dyn = unzip(scenes["moored_barge"] / "moored_barge_barge_dynamics.fmu", tmp_path)
    vr = dyn[3]
    inputs = {vr["force[1]"]: 1e3, vr["force[3]"]: -5e2, vr["force[5]"]: 2e3}
    outputs = [vr[f"position[{i}]"] for i in range(1, 4)]
    run, got = run_fmi_host(hosts, dyn, 2, 30, 0.1, inputs, outputs, env=clean_env(FMI_HOST_HOP="1"))
    assert run.returncode == 0 and "host exits normally" in run.stdout, run.stdout[-2000:] + run.stderr
    assert "LOG" not in run.stdout and "failed" not in run.stdout
    for k in (0, 1):
        ref = fmpy_reference(dyn, 30, 0.1, {v: x * (k + 1) for v, x in inputs.items()}, outputs)
        assert {(n, o): got[k, n, o] for n, o in ref} == ref
    assert got[1, 30, outputs[0]] != 0.0
