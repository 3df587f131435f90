"""Startup in a running process: what a master or a batch worker pays for each run after its
first, against the pythonfmu floor; and what fmpy's ``simulate_fmu`` pays, which unzips every
FMU at each call and deletes it after (``fmpy_compare``).

In one Python process, a scene's FMUs are loaded, instantiated and initialised
(``cosim.master.load`` + ``initialize``) and freed again, ``rounds`` times (each figure the
best of ``best`` such cycles), each time right after as many trivial pythonfmu FMUs
(``floor.build_floor``, in a ring) went through the same; the process's first load of each is made before the rounds and reported apart (it
imports the runtimes and, with an empty cache, unzips).  Each figure is a median over the
rounds, the multiple the median of each round's ratio, with its spread and noise verdict
(``floor.NOISY``).
"""
from __future__ import annotations

import json
import subprocess
import sys

import numpy as np

from .floor import NOISY, floor_system, fmu_count, spread

SCRIPT = '''import json, sys, time
from hydrofmu.cosim.master import load
folders, rounds, best = sys.argv[1:-2], int(sys.argv[-2]), int(sys.argv[-1])
def once(folder):
    t0 = time.perf_counter()
    system = load(folder)
    system.initialize()
    t1 = time.perf_counter()
    system.free()
    return [t1 - t0, time.perf_counter() - t1]
def best_of(folder):
    return min((once(folder) for _ in range(best)), key=sum)
first = [once(f) for f in folders]
print(json.dumps({"first": first, "rounds": [[best_of(f) for f in folders] for _ in range(rounds)]}))
'''
BEST = 3   # loads per figure of a round, the best kept (a slow spell only adds time)


def compare(candidates, floor_fmu, out, rounds=10, best=BEST, env=None):
    """Rows {label, fmus, startup_s, startup_floor_s, startup_x, startup_spread, startup_noisy,
    free_s, free_floor_s, cycle_x (load, initialise and free against the floor's), cycle_spread,
    cycle_noisy, first_s, first_floor_s} for each run folder of ``candidates`` ({label:
    folder}), measured in one fresh process per candidate (floor and candidate alternating)."""
    rows = []
    for label, folder in candidates.items():
        floor = floor_system(out, floor_fmu, fmu_count(folder))
        run = subprocess.run([sys.executable, "-c", SCRIPT, str(floor), str(folder), str(rounds), str(best)],
                             capture_output=True, text=True, check=True, timeout=900, env=env)
        got = json.loads(run.stdout.strip().splitlines()[-1])
        t = np.array(got["rounds"])   # round, (floor, candidate), (load, free)
        x = t[:, 1, 0] / t[:, 0, 0]
        cycle = t.sum(axis=2)
        cx = cycle[:, 1] / cycle[:, 0]
        rows.append({"label": label, "fmus": fmu_count(folder), "startup_s": float(np.median(t[:, 1, 0])),
                     "startup_floor_s": float(np.median(t[:, 0, 0])), "startup_x": float(np.median(x)),
                     "startup_spread": spread(x), "startup_noisy": spread(x) > NOISY,
                     "free_s": float(np.median(t[:, 1, 1])), "free_floor_s": float(np.median(t[:, 0, 1])),
                     "cycle_x": float(np.median(cx)), "cycle_spread": spread(cx), "cycle_noisy": spread(cx) > NOISY,
                     "first_s": got["first"][1][0], "first_floor_s": got["first"][0][0]})
    return rows


FMPY_SCRIPT = '''import json, sys, time
from fmpy import simulate_fmu
fmus, rounds, best, step = json.loads(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), float(sys.argv[4])
def once(paths):
    t0 = time.perf_counter()
    for p in paths:
        simulate_fmu(p, stop_time=step, step_size=step, output_interval=step)
    return time.perf_counter() - t0
def one_round():   # every candidate once, best times over, interleaved: a slow spell hits them alike
    times = [{k: once(v) for k, v in fmus.items()} for _ in range(best)]
    return {k: min(t[k] for t in times) for k in fmus}
first = {k: once(v) for k, v in fmus.items()}
print(json.dumps({"first": first, "rounds": [one_round() for _ in range(rounds)]}))
'''


def fmpy_compare(candidates, floor_fmu, rounds=10, best=BEST, step=0.05, env=None):
    """Rows {label, fmus, simulate_s, simulate_floor_s, simulate_x, simulate_spread, simulate_noisy}
    for each run folder (or list of FMUs) of ``candidates`` ({label: folder or [FMU]}): one
    ``fmpy.simulate_fmu`` of one step per FMU (model description read and validated, FMU
    unzipped, instantiated, initialised, stepped, freed and its folder deleted), against as
    many of the floor FMU, all in one Python process after a first call of each; each figure
    of a round the best of ``best``, medians over ``rounds``."""
    fmus = {label: [str(p) for p in (c if isinstance(c, (list, tuple)) else _fmus_of(c))]
            for label, c in candidates.items()}
    floors = {f"floor{len(v)}": [str(floor_fmu)] * len(v) for v in fmus.values()}
    run = subprocess.run([sys.executable, "-c", FMPY_SCRIPT, json.dumps({**floors, **fmus}), str(rounds), str(best),
                          repr(step)], capture_output=True, text=True, check=True, timeout=900, env=env)
    got = json.loads(run.stdout.strip().splitlines()[-1])["rounds"]
    rows = []
    for label, paths in fmus.items():
        t = np.array([r[label] for r in got])
        f = np.array([r[f"floor{len(paths)}"] for r in got])
        x = t / f
        rows.append({"label": label, "fmus": len(paths), "simulate_s": float(np.median(t)),
                     "simulate_floor_s": float(np.median(f)), "simulate_x": float(np.median(x)),
                     "simulate_spread": spread(x), "simulate_noisy": spread(x) > NOISY})
    return rows


def _fmus_of(folder):
    manifest = json.loads((folder / "manifest.json").read_text())
    return [folder / manifest["instances"][name]["fmu"] for name in manifest["order"]]
