"""Memory evaluation: cost per step against force error, and cost against kernel length.

The load is a full 6×6 interaction kernel matrix (``kernels.coupling_kernels``) driven by
an irregular-sea velocity (``kernels.irregular_velocity``) at a communication step equal to
TIMDEL (the step most favourable to convolution).  The reference is the full convolution,
which is exact for the piecewise-linear kernel and velocity; error = the largest per-
component normalised RMS √mean((F − F_ref)²) / √mean(F_ref²).
"""
import numpy as np

from ..physics.memory import Convolution, StateSpace
from .kernels import coupling_kernels, irregular_velocity
from .timing import per_call, per_round


def _forces(ev, dt, v):
    return np.array([ev.advance(dt, vk) for vk in v])


def error(got, ref):
    """Largest per-component normalised RMS error (components with a zero reference skipped)."""
    scale = np.sqrt(np.mean(ref ** 2, axis=0))
    live = scale > 0
    return float(np.max(np.sqrt(np.mean((got - ref) ** 2, axis=0))[live] / scale[live]))


def _timed(evaluators, dt, v, calls, rounds, every_round=False):
    """Per-step cost of each evaluator, warmed past its memory, measured interleaved (the
    median; ``every_round``: each round's)."""
    for ev in evaluators.values():
        for vk in v[:calls]:
            ev.advance(dt, vk)

    def make(ev):
        return lambda k: ev.advance(dt, v[k])
    makers = {name: (lambda ev=ev: make(ev)) for name, ev in evaluators.items()}
    return per_round(makers, calls, rounds) if every_round else per_call(makers, calls, rounds)


def tradeoff(lags=2000, timdel=0.05, duration=300.0, lengths=(5.0, 10.0, 20.0, 40.0),
             tolerances=(0.1, 0.03, 0.01, 0.003), orders=(2, 4), calls=400, rounds=5, dt=None):
    """Rows {evaluator, knob, states, cost_us, cheaper, error, dt} for the full convolution,
    truncated convolutions (memory_length [s]) and state-space fits (tolerance, or a fixed
    ERA order per element); ``cheaper`` = cost of the full convolution / cost.
    dt [s]: the communication step (default TIMDEL)."""
    kernels = coupling_kernels(timdel, lags)
    dt = timdel if dt is None else dt
    t = dt * np.arange(int(round(duration / dt)) + 1)
    v = irregular_velocity(t)
    cands = {"convolution full": Convolution(kernels, timdel, shape=(6, 6), v0=v[0])}
    knob = {"convolution full": f"{(lags - 1) * timdel:g} s"}
    for length in lengths:
        name = f"convolution {length:g} s"
        cands[name] = Convolution(kernels, timdel, shape=(6, 6), v0=v[0], memory_length=length)
        knob[name] = f"memory_length {length:g} s"
    for tol in tolerances:
        name = f"state_space tol {tol:g}"
        cands[name] = StateSpace(kernels, timdel, shape=(6, 6), v0=v[0], tol=tol)
        knob[name] = f"tolerance {tol:g}"
    for order in orders:
        name = f"state_space order {order}"
        cands[name] = StateSpace(kernels, timdel, shape=(6, 6), v0=v[0], order=order)
        knob[name] = f"order {order} per element"
    forces = {name: _forces(ev, dt, v[1:]) for name, ev in cands.items()}
    ref = forces["convolution full"]
    cost = _timed(cands, dt, v, calls, rounds)
    return [{"evaluator": name, "knob": knob[name], "states": getattr(ev, "order", 0) or ev.nodes,
             "cost_us": 1e6 * cost[name], "cheaper": cost["convolution full"] / cost[name],
             "error": error(forces[name], ref), "dt": dt}
            for name, ev in cands.items()]


def growth(lag_counts=(100, 300, 1000, 3000, 10000), timdel=0.05, tol=0.01, calls=300, rounds=5):
    """Rows {lags, memory_s, convolution_us, state_space_us, states}: cost per step of
    each evaluator as the kernel grows (the 6×6 kernel family stretched in time so that it
    decays within the window as the 2000-lag one does: the same shape, more samples)."""
    rows = []
    for lags in lag_counts:
        kernels = coupling_kernels(timdel, lags, stretch=lags / 2000)
        v = irregular_velocity(timdel * np.arange(lags + calls + 1))
        cands = {"convolution": Convolution(kernels, timdel, shape=(6, 6)),
                 "state_space": StateSpace(kernels, timdel, shape=(6, 6), tol=tol)}
        for ev in cands.values():             # fill the whole memory before timing
            for vk in v[:lags]:
                ev.advance(timdel, vk)
        times = _timed(cands, timdel, v[lags:], calls, rounds, every_round=True)
        cost = {name: float(np.median(t)) for name, t in times.items()}
        rows.append({"lags": lags, "memory_s": (lags - 1) * timdel,
                     "convolution_us": 1e6 * cost["convolution"], "state_space_us": 1e6 * cost["state_space"],
                     "states": cands["state_space"].order,
                     **{f"{name}_spread": float(np.ptp(t) / np.median(t)) for name, t in times.items()}})
    return rows


def filling(lags=2000, timdel=0.05, steady=200, repeats=3):
    """{lags, filling_us, steady_us, ratio}: the full convolution's cost per step while its
    history fills (the first memory length, each step's offsets new: the node weights come
    from the grid's half hats, ``Convolution._weights_of``) against once it is full (the same
    offsets every step: cached weights), medians over the steps, the best of ``repeats``
    fresh evaluators."""
    import time
    kernels = coupling_kernels(timdel, lags)
    v = irregular_velocity(timdel * np.arange(lags + steady + 2))
    Convolution(kernels, timdel, shape=(6, 6)).advance(timdel, v[1])   # (imports and first calls)
    fill, full = [], []
    for _ in range(repeats):
        ev, t = Convolution(kernels, timdel, shape=(6, 6), v0=v[0]), []
        for vk in v[1:]:
            t0 = time.perf_counter()
            ev.advance(timdel, vk)
            t.append(time.perf_counter() - t0)
        fill.append(np.median(t[1:lags])), full.append(np.median(t[lags + 1:]))
    return {"lags": lags, "filling_us": 1e6 * min(fill), "steady_us": 1e6 * min(full), "ratio": min(fill) / min(full)}
