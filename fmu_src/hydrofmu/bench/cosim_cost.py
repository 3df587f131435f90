"""Whole co-simulations through fmpy: communication step against accuracy and cost per step
along simulated time (cost against the number of coupled bodies: ``floor``).

All runs use ``fleet.Fleet`` (bodies coupled by SIMO interaction) in export mode; the
error is the largest normalised RMS (``fleet.nrms``) over the moving translations against
the monolithic scipy solution of the same Cummins equations.
"""
import time
from pathlib import Path

import numpy as np

from ..cosim.master import run
from ..fmi.build import build_scene
from ..scene import load_scene
from .fleet import Fleet, nrms

# translations that really move: body 1 surge, sway, heave; body 2 sway, heave (body 2's
# surge is driven by nothing)
MOVING = [0, 1, 2, 7, 8]


def _build(path, folder):
    return build_scene(load_scene(path), folder, log=lambda *_: None)


def step_sweep(folder, steps=(0.2, 0.1, 0.05, 0.02, 0.01), algorithms=("jacobi", "gauss-seidel"),
               holds=("constant", "linear"), stop=60.0, method="convolution", workers=1):
    """Rows {algorithm, load_hold, step, error, wall_s, pareto} of the two-body scene;
    ``pareto``: no other run is both faster and more accurate.  The runs are one load-case
    batch (``hydrofmu.batch``) on ``workers`` local workers (1: runs one after the other,
    so the wall times compare); ``wall_s`` is each run's time on its worker."""
    import json
    import shutil
    from ..batch import read_series, run_batch
    from ..cosim.master import Result
    fleet, folder = Fleet(2), Path(folder)
    scene = fleet.scene(folder, run=f"stop = {stop}\nsubstep = 0.01", coupling=f'method = "{method}"')
    dynamics = json.loads((_build(scene, folder / "fmus") / "manifest.json").read_text())["dynamics"]
    outputs = [f"{inst}.{prefix}{group}[{i}]" for b in fleet.names for inst, prefix in [dynamics[b]]
               for group in ("position", "attitude") for i in (1, 2, 3)]
    out = folder / "batch"
    shutil.rmtree(out, ignore_errors=True)   # fresh timings, nothing taken from an earlier run
    table = run_batch({"scene": str(scene), "outputs": outputs, "series": True,
                       "matrix": {"run.load_hold": list(holds), "algorithm": list(algorithms), "step": list(steps)}},
                      out, workers=workers, progress=False, log=lambda *_: None)
    rows, refs = [], {}
    for _, case in table.iterrows():
        if case["status"] != "ok":
            raise RuntimeError(f"step sweep case {case['case']} failed: {case['error']}")
        series, dt = read_series(out, case["case"]), case["step"]   # columns as the knobs were written
        result = Result(series["time"].to_numpy(), outputs, series[outputs].to_numpy(), case["algorithm"],
                        dt, dynamics)
        if dt not in refs:
            refs[dt] = fleet.monolithic(result.time)
        err = nrms(fleet.displacements(result)[:, MOVING], refs[dt][:, MOVING]).max()
        rows.append({"algorithm": case["algorithm"], "load_hold": case["run.load_hold"], "step": dt,
                     "error": float(err), "wall_s": float(case["wall_s"])})
    return pareto(rows)


def pareto(rows, cost="wall_s", error="error"):
    """Mark each row ``pareto``: no other row is at least as cheap and as accurate and better in
    one (the same step count with twice the error is dominated)."""
    for r in rows:
        r["pareto"] = not any(o[cost] <= r[cost] and o[error] <= r[error] and (o[cost] < r[cost] or o[error] < r[error])
                              for o in rows)
    return rows


def _per_step(built, stop, step, chunks=1):
    """Seconds per step of a run, in ``chunks`` equal parts of it."""
    n = int(round(stop / step))
    marks = [time.perf_counter()]
    every = max(1, n // chunks)
    run(built, stop=stop, step=step, progress=False, record=[],
        on_step=lambda k: marks.append(time.perf_counter()) if k % every == 0 else None)
    return np.diff(marks) / every


def flatness(folder, stop=1000.0, step=0.05, chunks=10, method="convolution"):
    """Rows {t_start, t_end, us_per_step} along one long two-body run (memory fills within
    the kernel length, 40 s, then the cost per step must stay flat)."""
    fleet = Fleet(2)
    built = _build(fleet.scene(Path(folder) / "long", run=f"stop = {stop}", coupling=f'method = "{method}"'),
                   Path(folder) / "long" / "fmus")
    cost = _per_step(built, stop, step, chunks)
    span = stop / chunks
    return [{"t_start": k * span, "t_end": (k + 1) * span, "us_per_step": 1e6 * c} for k, c in enumerate(cost)]
