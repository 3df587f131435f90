"""Side-by-side timing on a shared, noisy machine.

Absolute times drift with the load of the machine, so every comparison is measured in one
run with the candidates interleaved (A, B, C, A, B, C, …) and reported as ratios of
medians: a slow spell hits all candidates alike.
"""
import time

import numpy as np


def per_call(candidates, calls, rounds=5):
    """Median seconds per call of each candidate.

    candidates: {name: make}, where make() returns a fresh callable f(k) doing call k (so
    every round starts from the same state); calls: calls per round; rounds: interleaved
    rounds.  Returns {name: seconds per call}.
    """
    times = {name: [] for name in candidates}
    for _ in range(rounds):
        for name, make in candidates.items():
            f = make()
            t0 = time.perf_counter()
            for k in range(calls):
                f(k)
            times[name].append((time.perf_counter() - t0) / calls)
    return {name: float(np.median(t)) for name, t in times.items()}


def wall(f, *args, **kw):
    """(result of f, wall time [s])."""
    t0 = time.perf_counter()
    out = f(*args, **kw)
    return out, time.perf_counter() - t0
