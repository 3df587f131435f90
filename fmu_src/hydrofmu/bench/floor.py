"""FMU figures against the pythonfmu floor: startup and cost per step of whole scenes.

The floor is what an FMU built with pythonfmu cannot beat: a trivial pythonfmu FMU (6 inputs,
6 outputs, ``do_step`` copies the inputs to the outputs; other sizes for ``bench.overhead``),
built on the fly.  For a scene of
n FMUs, the floor is n of them connected in a ring and run by the same master
(``cosim.master``, Gauss–Seidel, every output recorded), so every figure below is a multiple
of what the same master pays for the same number of FMUs that do nothing:

- startup: load, instantiate and initialise every FMU (``master.load`` + ``initialize``)
  in a fresh Python process that has imported fmpy and numpy (a host's first FMU pays the
  runtime's imports, as it would), the best of ``STARTUP_BEST`` such processes in each
  round (a ~0.1 s process start on a shared machine varied by half between rounds);
- cost per step: the stepping loop of ``master.run`` (startup excluded), also in a process
  of its own.

Each candidate is timed right after its floor, in ``rounds`` rounds (floor, scene, floor,
scene, …; all the startups first, then all the stepping loops); each multiple is the median of the rounds' ratios, and a multiple whose spread
between rounds, (max − min)/median, is above ``NOISY`` is reported as too noisy instead of
as a number.
"""
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

NOISY = 0.25   # spread between rounds above which a figure is not trusted
STARTUP_BEST = 3   # fresh processes per startup figure of a round, the best kept

FLOOR_SCRIPT = '''"""The pythonfmu floor: {n_in} inputs, {n_out} outputs, do_step copies inputs to outputs."""
from pythonfmu import Fmi2Causality, Fmi2Slave, Real


class {name}(Fmi2Slave):
    author = "hydrofmu bench"
    description = "trivial FMU: do_step copies u to y"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.u, self.y = [0.0] * {n_in}, [0.0] * {n_out}
        for i in range({n_in}):
            self.register_variable(Real(f"u[{{i + 1}}]", causality=Fmi2Causality.input,
                                        getter=lambda i=i: self.u[i],
                                        setter=lambda v, i=i: self.u.__setitem__(i, v)))
        for i in range({n_out}):
            self.register_variable(Real(f"y[{{i + 1}}]", causality=Fmi2Causality.output,
                                        getter=lambda i=i: self.y[i]))

    def do_step(self, current_time, step_size):
        self.y[:] = (self.u * {n_out})[:{n_out}]
        return True
'''

STARTUP = '''import json, sys, time
import numpy, fmpy
from hydrofmu.cosim.master import load
t0 = time.perf_counter()
system = load(sys.argv[1])
system.initialize()
t1 = time.perf_counter()
system.free()
print(json.dumps(t1 - t0))
'''


STEPPING = '''import json, sys
from hydrofmu.bench.floor import per_step
print(json.dumps(per_step(sys.argv[1], int(sys.argv[2]), float(sys.argv[3]))))
'''


def build_floor(folder, n_in=6, n_out=6):
    """Build the trivial FMU (``n_in`` inputs, ``n_out`` outputs) into ``folder``; returns its path."""
    from pythonfmu.builder import FmuBuilder
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    name = "hydrofmu_floor" if (n_in, n_out) == (6, 6) else f"hydrofmu_floor_{n_in}_{n_out}"
    with tempfile.TemporaryDirectory() as tmp:
        script = Path(tmp) / f"{name}.py"
        script.write_text(FLOOR_SCRIPT.format(name=name, n_in=n_in, n_out=n_out))
        saved = list(sys.path)
        try:
            return Path(FmuBuilder.build_FMU(script, dest=folder))
        finally:
            sys.path[:] = saved


def floor_system(folder, fmu, n, step=0.05):
    """A run folder (manifest.json for ``cosim.master``) of n floor FMUs in a ring: y of
    instance k feeds u of instance k + 1."""
    folder = Path(folder) / f"floor{n}"
    folder.mkdir(parents=True, exist_ok=True)
    names = [f"f{k}" for k in range(n)]
    conns = [[a, f"y[{i}]", b, f"u[{i}]"] for a, b in zip(names, names[1:] + names[:1]) for i in range(1, 7)]
    manifest = {"scene": f"floor{n}", "order": names, "connections": conns, "dynamics": {},
                "instances": {k: {"fmu": str(Path(fmu).resolve()), "kind": "floor", "body": ""} for k in names},
                "run": {"step": step, "stop": 1.0, "algorithm": "gauss-seidel", "preset": None,
                        "substep": step, "load_hold": "constant", "set": []}}
    (folder / "manifest.json").write_text(json.dumps(manifest))
    return folder


def fmu_count(folder):
    return len(json.loads((Path(folder) / "manifest.json").read_text())["order"])


def _child(script, *args):
    """The number a ``script`` prints last, run in a fresh Python process with ``args``."""
    out = subprocess.run([sys.executable, "-c", script, *map(str, args)], capture_output=True, text=True, check=True)
    return float(out.stdout.strip().splitlines()[-1])


def startup(folder, best_of=1):
    """Seconds to load, instantiate and initialise every FMU of a run folder, in a fresh
    process; the best of ``best_of`` processes (a process start's noise only adds time)."""
    return min(_child(STARTUP, folder) for _ in range(best_of))


def per_step(folder, steps, step, fresh=False):
    """Seconds per communication step of ``master.run`` (its stepping loop only); ``fresh``:
    in a process of its own, so that no loop inherits the heap and caches of those before."""
    if fresh:
        return _child(STEPPING, folder, steps, step)
    from ..cosim.master import run
    marks = {}

    def mark(k):
        if k in (1, steps):
            marks[k] = time.perf_counter()
    run(folder, stop=steps * step, step=step, progress=False, on_step=mark)
    return (marks[steps] - marks[1]) / (steps - 1)


def spread(values):
    """(max − min)/median of the rounds of one figure."""
    v = np.asarray(values, float)
    return float((v.max() - v.min()) / np.median(v))


def compare(candidates, floor_fmu, out, rounds=5, steps=400, step=0.05, best_of=STARTUP_BEST):
    """Startup and cost per step of each run folder in ``candidates`` ({label: folder})
    against n floor FMUs (n = its FMU count), measured back to back in each of ``rounds``
    rounds (each startup the best of ``best_of`` processes), so that a slow spell of the
    machine hits both.  Rows {label, fmus, startup_s,
    startup_floor_s, startup_x, step_us, step_floor_us, step_x (medians over the rounds;
    the multiples are medians of each round's ratio), startup_spread and step_spread: the
    relative spread of each multiple between rounds, startup_noisy and step_noisy: that
    spread > NOISY}.  The two verdicts are apart: a fresh process's start varies far more
    than a long stepping loop, and one must not hide the other."""
    floors = {n: floor_system(out, floor_fmu, n, step) for n in sorted({fmu_count(f) for f in candidates.values()})}
    got = {label: [] for label in candidates}
    # the startups in rounds of their own, then the stepping loops, each in a process of its
    # own: a loop timed in the process that ran the others varied by a third between rounds
    for _ in range(rounds):
        for label, folder in candidates.items():
            got[label].append([startup(floors[fmu_count(folder)], best_of), startup(folder, best_of)])
    for k in range(rounds):
        for label, folder in candidates.items():
            got[label][k] += [per_step(f, steps, step, fresh=True) for f in (floors[fmu_count(folder)], folder)]
    rows = []
    for label, folder in candidates.items():
        t = np.array(got[label])
        start_x, step_x = t[:, 1] / t[:, 0], t[:, 3] / t[:, 2]
        rows.append({"label": label, "fmus": fmu_count(folder),
                     "startup_s": float(np.median(t[:, 1])), "startup_floor_s": float(np.median(t[:, 0])),
                     "startup_x": float(np.median(start_x)),
                     "step_us": 1e6 * float(np.median(t[:, 3])), "step_floor_us": 1e6 * float(np.median(t[:, 2])),
                     "step_x": float(np.median(step_x)),
                     "startup_spread": spread(start_x), "startup_noisy": spread(start_x) > NOISY,
                     "step_spread": spread(step_x), "step_noisy": spread(step_x) > NOISY})
    return rows


def linearity(rows, pairs):
    """Marginal cost per coupled pair between consecutive body counts [µs per pair] and
    the ratio last/first (1: the cost per step is linear in the pairs)."""
    c = [r["step_us"] for r in rows]
    marginal = [(c[k + 1] - c[k]) / (pairs[k + 1] - pairs[k]) for k in range(len(c) - 1)]
    return marginal, marginal[-1] / marginal[0] if len(marginal) > 1 and marginal[0] > 0 else float("nan")
