"""FMUs in a native host against the same FMUs under fmpy.

A native FMI host (a C program, ``native_host.c``, compiled here with the system compiler,
no Python of its own: the FMU's shim starts the interpreter) and fmpy in a fresh Python
process each do the same thing with one FMU: load and initialise it (the startup), then
``steps`` times fmi2SetReal of every input + fmi2DoStep + fmi2GetReal of every output
(the cost per step), then free it.  Each round runs fmpy, then the native host, back to
back; the ratio native/fmpy of each round, its median over the rounds and its spread
((max − min)/median, ``floor.NOISY`` and above: too noisy to trust) are reported.
"""
from __future__ import annotations

import json
import subprocess
import sys
import tempfile
import zipfile
from pathlib import Path

import numpy as np

from .floor import NOISY, spread

SOURCE = Path(__file__).with_name("native_host.c")

FMPY = '''import json, sys, time
import numpy, fmpy
from fmpy import read_model_description
from fmpy.fmi2 import FMU2Slave
folder, mid, guid, steps, dt, ins, outs = sys.argv[1:]
steps, dt = int(steps), float(dt)
ins = [tuple(map(float, p.split(":"))) for p in ins.split(",") if p]
vin, xin = [int(v) for v, _ in ins], [x for _, x in ins]
vout = [int(v) for v in outs.split(",") if v]
t0 = time.perf_counter()
s = FMU2Slave(guid=guid, unzipDirectory=folder, modelIdentifier=mid, instanceName="timed")
s.instantiate()
s.setupExperiment(startTime=0.0)
s.enterInitializationMode()
s.exitInitializationMode()
t1 = time.perf_counter()
for n in range(steps):
    s.setReal(vin, xin)
    s.doStep(n * dt, dt)
    s.getReal(vout)
t2 = time.perf_counter()
s.terminate()
s.freeInstance()
print(json.dumps({"startup_s": t1 - t0, "step_s": (t2 - t1) / max(steps, 1), "free_s": time.perf_counter() - t2}))
'''


SCENE = '''import json, sys, time
from hydrofmu.cosim import libcosim, master
engine, folder, step, n1, n2 = sys.argv[1], sys.argv[2], float(sys.argv[3]), int(sys.argv[4]), int(sys.argv[5])
record = sys.argv[6].split(",") if len(sys.argv) > 6 else None   # default: every output
run = libcosim.run if engine == "libcosim" else lambda *a, **k: master.run(*a, progress=False, **k)
run(folder, stop=step, step=step, algorithm="jacobi", record=record)   # the process's first load: imports, unzipping
t = []
for n in (n1, n2):
    t0 = time.perf_counter()
    run(folder, stop=n * step, step=step, algorithm="jacobi", record=record)
    t.append(time.perf_counter() - t0)
per_step = (t[1] - t[0]) / (n2 - n1)
print(json.dumps({"step_s": per_step, "startup_s": t[0] - n1 * per_step}))
'''


def host(folder) -> Path:
    """native_host.c compiled into ``folder``."""
    from ..cc import compiler
    out = Path(folder) / "native_host"
    subprocess.run(compiler() + ["-O2", f"-I{SOURCE.parent}", "-o", str(out), str(SOURCE), "-ldl"], check=True,
                   capture_output=True)
    return out


def unpack(fmu, folder, inputs=None, outputs=None):
    """Unzip ``fmu`` into ``folder``; returns (folder, model identifier, guid, inputs "vr:value,…",
    outputs "vr,…"): every Real input at its start value (0 without one), every Real output, or
    only those whose names start with one of ``inputs`` / ``outputs`` (the ports a master
    connects)."""
    from fmpy import read_model_description
    md = read_model_description(str(fmu))
    with zipfile.ZipFile(fmu) as z:
        z.extractall(folder)
    chosen = lambda v, names: names is None or v.name.startswith(tuple(names))   # noqa: E731
    ins = ",".join(f"{v.valueReference}:{float(v.start or 0.0)!r}" for v in md.modelVariables
                   if v.causality == "input" and v.type == "Real" and chosen(v, inputs))
    outs = ",".join(str(v.valueReference) for v in md.modelVariables
                    if v.causality == "output" and v.type == "Real" and chosen(v, outputs))
    return str(Path(folder).resolve()), md.coSimulation.modelIdentifier, md.guid, ins, outs


_exit_crashes = []   # children that printed their figures, then died at exit (counted, reported)


def _json(cmd, env=None):
    out = subprocess.run(cmd, capture_output=True, text=True, timeout=600, env=env)
    lines = out.stdout.strip().splitlines()
    if out.returncode != 0 and not (lines and lines[-1].startswith("{")):
        raise RuntimeError(f"{cmd[0]} failed: {out.stdout[-2000:]}{out.stderr[-2000:]}")
    got = json.loads(lines[-1])
    if got.get("failed"):
        raise RuntimeError(f"{cmd[0]}: an FMI call failed: {out.stderr[-2000:]}")
    if out.returncode != 0:
        _exit_crashes.append(f"{Path(cmd[0]).name} {Path(cmd[-7]).name} exit {out.returncode}: {out.stderr.strip()[-200:]}")
    return got


def exit_crashes():
    """What the children that died after printing their figures said (and forget them)."""
    got = list(_exit_crashes)
    _exit_crashes.clear()
    return got


def compare(fmus, rounds=5, steps=10_000, dt=0.05, work=None):
    """{label: FMU path} stepped alone in the native host and under fmpy, ``rounds`` rounds
    back to back.  Rows {label, step_us, step_fmpy_us, step_x (native/fmpy), step_spread,
    step_noisy, startup_s, startup_fmpy_s, startup_x, startup_spread, startup_noisy}: medians
    over the rounds, each multiple the median of the rounds' ratios."""
    with tempfile.TemporaryDirectory(dir=work) as tmp:
        exe = host(tmp)
        unpacked = {label: unpack(f, Path(tmp) / label) for label, f in fmus.items()}
        got = {label: [] for label in fmus}
        for _ in range(rounds):
            for label, args in unpacked.items():
                args = list(map(str, args[:3])) + [str(steps), repr(dt)] + list(args[3:])
                py = _json([sys.executable, "-c", FMPY, *args])
                c = _json([str(exe), *args])
                got[label].append([py["step_s"], c["step_s"], py["startup_s"], c["startup_s"]])
    return [_row(label, t) for label, t in got.items()]


def _row(label, t):
    """The row of one candidate from its rounds [fmpy step, native step, fmpy startup, native startup]."""
    t = np.array(t)
    step_x, start_x = t[:, 1] / t[:, 0], t[:, 3] / t[:, 2]
    # a marginal cost per step (the difference of a short and a long run) at or below zero in
    # some round: the difference drowned in noise, and a ratio or spread of it means nothing
    lost = bool(np.any(t[:, :2] <= 0))
    return {"label": label, "step_us": 1e6 * float(np.median(t[:, 1])),
            "step_fmpy_us": 1e6 * float(np.median(t[:, 0])), "step_x": float(np.median(step_x)),
            "step_lost": lost,
            "step_spread": spread(step_x), "step_noisy": lost or spread(step_x) > NOISY,
            "startup_s": float(np.median(t[:, 3])), "startup_fmpy_s": float(np.median(t[:, 2])),
            "startup_x": float(np.median(start_x)), "startup_spread": spread(start_x),
            "startup_noisy": spread(start_x) > NOISY}


def step_figure(r, text):
    """``text``, the per-step figure of a row of ``compare``/``compare_scene``, unless it is
    noise: then what to say instead (no ratio or spread of a difference lost in noise)."""
    from .timing import over
    if r.get("step_lost"):
        return "per step too noisy (a round measured no cost per step: below the noise of its runs), no figure"
    if r["step_noisy"]:
        return f"per step too noisy ({over(r['step_spread'], NOISY)}), no figure"
    return text


def compare_scene(folder, rounds=5, steps=2000, record=None):
    """A built scene (its folder) run with Jacobi exchanges by libcosim (libcosimpy: the FMUs
    are called from libcosim's C++ worker threads, which Python does not know) and by our fmpy
    master, every output recorded by both, in rounds of fresh processes.  The cost per step is
    the marginal cost between runs of 10 and ``steps`` steps, the startup what is left of the
    short run (a run after the process's first).  ``record``: the 'instance.variable' columns
    both record (default every output).  Row {label, step_us, step_fmpy_us, step_x,
    step_spread, step_noisy, startup_s, startup_fmpy_s, startup_x, startup_spread, startup_noisy}."""
    step = json.loads((Path(folder) / "manifest.json").read_text())["run"]["step"]
    t = []
    for _ in range(rounds):
        got = [_json([sys.executable, "-c", SCENE, engine, str(folder), repr(step), "10", str(steps)]
                     + ([",".join(record)] if record else [])) for engine in ("fmpy", "libcosim")]
        t.append([got[0]["step_s"], got[1]["step_s"], got[0]["startup_s"], got[1]["startup_s"]])
    return _row(f"{Path(folder).name} in libcosim", t)
