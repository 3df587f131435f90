"""The FMUs in native hosts: processes with no Python of their own.

Two C programs of tests/native/ are compiled here with the system C compiler: a libcosim
host (libcosimc.so from the installed libcosimpy wheel) and a minimal generic FMI 2.0
host (dlopen + the fmi2 functions, one thread per instance).  Each runs as a subprocess
with a clean environment (no PYTHONPATH, LD_PRELOAD, PYTHONHOME, VIRTUAL_ENV): the FMU's
shim has to find, start and check Python itself.  Results are compared with our fmpy
master (libcosim's fixed-step algorithm is a Jacobi scheme) and with the same FMU driven
in-process by fmpy.
"""
import os
import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from conftest import MODELS

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
        "fmi": compile_c("fmi_host.c", d / "fmi_host", "-ldl", "-lpthread"),
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


def assert_equals_jacobi(tables, folder, stop, step):
    """Every output column libcosim's file observer wrote equals our fmpy Jacobi run to
    the 6 significant digits the observer prints."""
    from hydrofmu.cosim import master
    ours = master.run(folder, stop=stop, step=step, algorithm="jacobi", progress=False)
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


@pytest.mark.parametrize("name", SCENES)
def test_libcosim_native_host_runs_osp_system_structure(name, scenes, hosts, tmp_path):
    folder = scenes[name]
    step = __import__("json").loads((folder / "manifest.json").read_text())["run"]["step"]
    stop = STEPS * step
    tables = run_cosim(hosts, folder / "OspSystemStructure.xml", stop, step, tmp_path / "out")
    ours = assert_equals_jacobi(tables, folder, stop, step)
    assert np.ptp(ours.values, axis=0).max() > 0  # something moves


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
