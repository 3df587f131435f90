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
    return {name: float(np.median(t)) for name, t in per_round(candidates, calls, rounds).items()}


def per_round(candidates, calls, rounds=5):
    """As `per_call`, the seconds per call of every round: {name: [round 1, round 2, …]}."""
    times = {name: [] for name in candidates}
    for _ in range(rounds):
        for name, make in candidates.items():
            f = make()
            t0 = time.perf_counter()
            for k in range(calls):
                f(k)
            times[name].append((time.perf_counter() - t0) / calls)
    return times


def wall(f, *args, **kw):
    """(result of f, wall time [s])."""
    t0 = time.perf_counter()
    out = f(*args, **kw)
    return out, time.perf_counter() - t0


def over(spread, limit):
    """``'spread 25.3 % > 25 %'``: a spread above ``limit`` (fractions), with as many digits as
    it takes for the printed spread to be above the printed limit."""
    for digits in range(0, 4):
        shown = f"{100 * spread:.{digits}f}"
        if float(shown) > 100 * limit:
            return f"spread {shown} % > {100 * limit:g} %"
    return f"spread {100 * spread:.12g} % > {100 * limit:g} %"
