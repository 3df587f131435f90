"""Batches on Dask: speed-up from 1 to 2 local workers and the dispatch overhead per case.

The same n cases (the two-body fleet at the design preset; each case sets its own water
density, which shares one build and changes no load, so every case does the same work)
run on a LocalCluster of 1 and of 2 single-threaded worker processes, started and warmed
up before the clock starts.  Per batch: wall time of ``run_batch`` (dispatch, results
written, table and plot) and the sum of the cases' own run times on their workers.

- speed-up = wall(1 worker) / wall(2 workers)
- fixed cost: the same batch again, every case then taken from the first run (planning,
  reading the results back, table and plot);
- dispatch overhead per case = (wall(1 worker) − Σ case run times − fixed cost) / n, also
  as a share of the mean case run time: what the batch machinery adds to each co-simulation
  (submission, shipping, the worker's bookkeeping, writing its result).

Each measurement is repeated ``rounds`` times, interleaved (1, 2, 1, 2, …), the best is
kept; a spread above 25 % between rounds marks the figure as noisy.
"""
import logging
import time
from pathlib import Path

from ..batch import run_batch
from .fleet import Fleet

NOISY = 0.25


def measure(folder, cases=16, stop=60.0, counts=(1, 2), rounds=2):
    """Rows {workers, round, cases, wall_s, cases_s, fixed_s} and a summary dict."""
    from distributed import Client, LocalCluster
    folder = Path(folder)
    scene = Fleet(2).scene(folder / "scene", run=f'preset = "design"\nstop = {stop}')
    spec = {"scene": str(scene), "outputs": ["b1_b2_dynamics.b1.position[2]", "b1_b2_dynamics.b2.position[2]"]}
    out = folder / "batch"
    quiet = dict(progress=False, log=lambda *_: None)
    run_batch({**spec, "stop": 1.0}, out, workers=1, **quiet)   # build once, outside the clock
    rows, tag = [], iter(range(10 ** 6))
    logging.getLogger("distributed").setLevel(logging.ERROR)   # no INFO lines as the clusters close
    clusters = {n: LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=":0",
                                silence_logs=logging.ERROR) for n in counts}
    clients = {n: Client(c) for n, c in clusters.items()}
    try:
        for n, client in clients.items():   # warm-up: imports and the FMUs on every worker
            run_batch({**spec, "stop": 1.0, "matrix": {"environment.rho": [1000.0 + next(tag) for _ in range(2 * n)]}},
                      out, client=client, **quiet)
        for r in range(rounds):
            for n, client in clients.items():
                # fresh knobs every batch: nothing is taken from an earlier run
                matrix = {"environment.rho": [1000.0 + next(tag) for _ in range(cases)]}
                t0 = time.perf_counter()
                table = run_batch({**spec, "matrix": matrix}, out, client=client, **quiet)
                t1 = time.perf_counter()
                run_batch({**spec, "matrix": matrix}, out, client=client, **quiet)   # all done: fixed cost
                t2 = time.perf_counter()
                if not (table["status"] == "ok").all():
                    raise RuntimeError(f"batch cases failed: {table['error'].dropna().unique()}")
                rows.append({"workers": n, "round": r, "cases": cases, "wall_s": t1 - t0,
                             "cases_s": float(table["wall_s"].sum()), "fixed_s": t2 - t1})
    finally:
        for c in list(clients.values()) + list(clusters.values()):
            c.close()
    best = {n: min((r for r in rows if r["workers"] == n), key=lambda r: r["wall_s"]) for n in counts}
    spread = max(max(r["wall_s"] for r in rows if r["workers"] == n) / best[n]["wall_s"] - 1 for n in counts)
    one = best[counts[0]]
    overhead = (one["wall_s"] - one["cases_s"] - one["fixed_s"]) / cases
    return rows, {"speedup": one["wall_s"] / best[counts[-1]]["wall_s"], "overhead_s": overhead,
                  "fixed_s": one["fixed_s"],
                  "case_s": one["cases_s"] / cases, "share": overhead / (one["cases_s"] / cases),
                  "spread": spread, "noisy": spread > NOISY, "workers": counts}
