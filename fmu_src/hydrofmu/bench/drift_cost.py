"""Cost and accuracy of the wave drift (``hydrofmu bench --part drift``).

The full QTF at the peer's case (``semisub_cost``): the issue's semisubmersible (its QTF's
grid, 200 components, cut-off 0.6 rad/s, HydroDyn's driver step 0.05 s), per step in both
flavours: the first-order excitation, Newman, the full QTF's direct sum and its Chebyshev
blocks (``DriftLoad.at``), and the peer's step as the issue's compiled ratios place it.

Cost: seconds per step of each drift method (``physics.drift.DriftLoad`` with its phasors
z_k(t), in-process, no FMI) beside the first-order kernel (``physics.waves.WaveLoad``) at
50, 200 and 1000 components of a JONSWAP sea (Hs 2 m, Tp 9 s), interleaved rounds; ``qtf``
(its direct sum) with every pair and with a 0.3 rad/s cut-off.

Accuracy: Newman's approximation against the full QTF on the test's QTF (tests/test_drift.py:
Q(ω1, ω2) = 8e3·(1 + 0.4·(ω1 + ω2)) + 2e3i·(ω1 − ω2) N/m² in surge, a smooth wall-like
drift whose off-diagonal differs from √(Q11·Q22) by its growth and its imaginary part):
the slow-drift force's std and the surge std of a moored body (natural period 100 s, 10 %
of critical damping) in the same 2-hour record, and the rms difference of the force.
"""
from __future__ import annotations

import math

import numpy as np

from . import timing

COUNTS = (50, 200, 1000)
W_LO, W_HI = 0.2, 2.4


def bench_qtf():
    """The test's QTF on a 45-frequency grid (a QTF object, surge only)."""
    from ..physics.drift import QTF
    w = np.linspace(W_LO, W_HI, 45)
    q = np.zeros((w.size, w.size, 1, 6), complex)
    q[:, :, 0, 0] = 8e3 * (1 + 0.4 * (w[:, None] + w[None, :])) + 2e3j * (w[:, None] - w[None, :])
    return QTF(w, [(0.0, 0.0)], q)


def sea(n, seed=1):
    from ..physics.waves import SeaState, components
    return components(SeaState(hs=2.0, tp=9.0, components=n, seed=seed), (W_LO, W_HI))


def cost(counts=COUNTS, calls=300, rounds=5):
    """Rows per component count: µs per step of waves (first order), mean, newman, qtf with
    a 0.3 rad/s cut-off and qtf with every pair (phasors included)."""
    from ..physics.drift import DriftLoad, phasors
    from ..physics.waves import TransferFunction, WaveLoad
    data = bench_qtf()
    flat = TransferFunction(data.omega, [0.0], np.ones((data.omega.size, 1, 6), complex))
    rows = []
    for n in counts:
        comps = sea(n)
        loads = {"waves": WaveLoad(comps, flat, (0.0, 0.0))}
        for label, method, cut in (("mean", "mean", math.inf), ("newman", "newman", math.inf),
                                   ("qtf_cut", "qtf", 0.3), ("qtf", "qtf", math.inf)):
            loads[label] = DriftLoad(method, comps, data, cut)
        dt = 0.05

        def make(label):
            load = loads[label]
            if label == "waves":
                return lambda: (lambda k: load(dt * k))
            return lambda: (lambda k: load(phasors(comps, dt * k)))
        got = timing.per_round({label: make(label) for label in loads}, max(20, calls // (1 + n // 200)), rounds)
        per = {k: float(np.median(v)) for k, v in got.items()}
        row = {"components": n, **{f"{k}_us": 1e6 * v for k, v in per.items()},
               "qtf_cut_offsets": loads["qtf_cut"].offsets, "noisy": noisy(got)}
        row.update({f"{k}_x_waves": per[k] / per["waves"] for k in loads if k != "waves"})
        rows.append(row)
    return rows


def noisy(times, limit=0.25):
    """True when a candidate's rounds spread by more than ``limit`` of their median (a busy
    machine: the ratios are then not to be trusted)."""
    return any((max(v) - min(v)) > limit * float(np.median(v)) for v in times.values())


def _c_lib():
    """(the compiled waves.c + drift.c + drift_timing.c, its Sea structure)."""
    import ctypes
    from pathlib import Path
    from ..cc import cached_many
    here = Path(__file__).resolve().parent
    lib = ctypes.CDLL(str(cached_many([here.parent / "physics" / "waves.c", here.parent / "physics" / "drift.c",
                                       here / "drift_timing.c"], "drift_bench", libs=["-lm"],
                                      flags=["-O3", "-shared", "-fPIC", "-std=c99"])))
    lib.hf_wave_build.restype = ctypes.POINTER(ctypes.c_double)
    lib.hf_drift_build.restype = ctypes.POINTER(ctypes.c_double)
    lib.hf_bench_per_call.restype = ctypes.c_double
    lib.hf_bench_per_call.argtypes = [ctypes.POINTER(ctypes.c_double), ctypes.POINTER(ctypes.c_double), ctypes.c_int,
                                      ctypes.c_double]

    class Sea(ctypes.Structure):
        _fields_ = [("spectrum", ctypes.c_int)] + [(k, ctypes.c_double) for k in (
            "height", "period", "phase", "hs", "tp", "gamma", "direction", "spreading", "components", "seed", "ramp",
            "depth")]
    return lib, Sea


def _c_kernels(lib, Sea, sea, window, data, loads):
    """{label: params}: waves.c's first order (a flat transfer function over ``window``) and
    drift.c's kernels ``loads`` {label: (method, cut-off, blocks)} of the QTF ``data`` on the
    components waves.c draws for ``sea`` (physics.waves.SeaState); blocks False: K = 0 in the
    parameters (drift.c's direct sum at every step)."""
    import ctypes
    from ..description import Drift
    from ..physics.waves import TransferFunction
    flat = TransferFunction(data.omega, [0.0], np.ones((data.omega.size, 1, 6), complex)).c_params(window)
    code = {"regular": 0, "jonswap": 1, "pierson_moskowitz": 2}[sea.spectrum]
    c_sea = Sea(code, 0.0, 10.0, 0.0, sea.hs, sea.tp, sea.gamma, 0.0, 0.0, float(sea.components), float(sea.seed),
                0.0, math.inf)
    f, m = ctypes.create_string_buffer(16), ctypes.create_string_buffer(400)
    wave = lib.hf_wave_build(ctypes.byref(c_sea), (ctypes.c_double * len(flat))(*flat), ctypes.c_double(9.81), f, m,
                             ctypes.c_size_t(400))
    assert wave, m.value
    pairs = np.array([[0.0, 0.0]])
    q = data.grid[:, :, 0, 0][:, :, None, :]
    out = {"waves": wave}
    for label, (method, cut, blocks) in loads.items():
        if method == "qtf":
            rec = Drift("drift", method, cut, data.omega, np.zeros(2), pairs=pairs, re=q.real, im=q.imag).c_params()
        else:
            mean = data.diagonal()
            rec = Drift("drift", method, cut, mean.omega, np.zeros(2), directions=mean.directions,
                        values=mean.values).c_params()
        p = lib.hf_drift_build(wave, (ctypes.c_double * len(rec))(*rec), len(rec), ctypes.c_double(9.81),
                               ctypes.c_double(math.inf), f, m, ctypes.c_size_t(400))
        assert p, m.value
        if not blocks:
            p[10] = 0.0          # K = 0: no blocks
        out[label] = p
    return out


def _c_times(lib, params, steps, rounds, dt):
    """{label: [seconds per step of each round]} of interleaved rounds of the C loop."""
    times = {k: [] for k in params}
    for _ in range(rounds):
        for k, p in params.items():
            n = steps[k] if isinstance(steps, dict) else steps
            times[k].append(lib.hf_bench_per_call(params["waves"], None if k == "waves" else p, n, dt))
    return times


def _free(params):
    import ctypes
    for p in params.values():
        ctypes.CDLL(None).free(p)


def c_cost(counts=COUNTS, rounds=5, steps=2000):
    """Rows per component count: µs per step of the compiled kernels, each with the shared
    phasors' advance (physics/waves.c's hf_waves; physics/drift.c's hf_drift per method, the
    full QTF by its direct sum), timed in a C loop (bench/drift_timing.c), median of
    interleaved rounds."""
    lib, Sea = _c_lib()
    from ..physics.waves import SeaState
    data = bench_qtf()
    rows = []
    for n in counts:
        params = _c_kernels(lib, Sea, SeaState(hs=2.0, tp=9.0, components=n, seed=1), (W_LO, W_HI), data,
                            {"mean": ("mean", math.inf, False), "newman": ("newman", math.inf, False),
                             "qtf_cut": ("qtf", 0.3, False), "qtf": ("qtf", math.inf, False)})
        times = _c_times(lib, params, max(50, steps // (1 + n // 100)), rounds, 0.05)
        per = {k: float(np.median(v)) for k, v in times.items()}
        row = {"components": n, **{f"c_{k}_us": 1e6 * v for k, v in per.items()}, "c_noisy": noisy(times)}
        row.update({f"c_{k}_x_waves": per[k] / per["waves"] for k in per if k != "waves"})
        rows.append(row)
        _free(params)
    return rows


# the issue's semisubmersible case (OC4 DeepCwind, marin_semi.12d: 56 frequencies 0.25…3 rad/s,
# 6 dofs, one heading) as its shape: the cost depends on the grid, N and the cut-off, not on the
# values; the sea within the window 0.481…2 rad/s the issue's run had, HydroDyn's driver step
ISSUE_DIRECT, ISSUE_NEWMAN = 2.2, 0.47      # × the peer's step (compiled): the full QTF, excitation + Newman
SEMI_CUTOFF, SEMI_WINDOW, SEMI_DT = 0.6, (0.481, 2.0), 0.05


def semisub_qtf():
    """A smooth Hermitian 6-dof QTF [N/m², N·m/m²] on the semisubmersible's grid."""
    from ..physics.drift import QTF
    w = np.linspace(0.25, 3.0, 56)
    rng = np.random.default_rng(2)
    c = rng.normal(size=(6, 2)) + 1j * rng.normal(size=(6, 2))
    wi, wj = w[:, None, None], w[None, :, None]
    q = 1e5 * (c[:, 0] * (1 + 0.3 * (wi + wj)) + c[:, 1] * 0.5 * (wi - wj))
    q = 0.5 * (q + np.conj(np.transpose(q, (1, 0, 2))))
    return QTF(w, [(0.0, 0.0)], q[:, :, None, :])


def semisub_cost(n=200, rounds=5, dt=SEMI_DT):
    """The full QTF at the peer's case: µs per step of the first-order excitation, Newman, the
    full QTF's direct sum and its blocks (cut-off 0.6 rad/s), Python (in-process, phasors
    included) and compiled (the C loop), each × the excitation of its flavour; the blocks timed
    over whole blocks (two per round), so their node sums are in the figure.  The peer's step P
    from the issue's compiled ratios on this run's figures: P = (qtf direct − newman)/(2.2 −
    0.47) (the FMU's other costs per step, 0.47·P − waves − newman, are the same for both)."""
    from ..physics.drift import DriftLoad, phasors
    from ..physics.waves import SeaState, TransferFunction, WaveLoad, components
    data = semisub_qtf()
    sea = SeaState("jonswap", hs=6.0, tp=9.0, gamma=3.3, components=n, seed=1)
    comps = components(sea, SEMI_WINDOW)
    flat = TransferFunction(data.omega, [0.0], np.ones((data.omega.size, 1, 6), complex))
    loads = {"newman": DriftLoad("newman", comps, data), "qtf": DriftLoad("qtf", comps, data, SEMI_CUTOFF)}
    length, k = loads["qtf"].plan
    per_block = int(math.ceil(length / dt))
    wave = WaveLoad(comps, flat, (0.0, 0.0))

    def make(label):
        load = loads.get(label)
        if label == "waves":
            return lambda: (lambda s: wave(dt * s))
        if label == "qtf_direct":
            return lambda: (lambda s: load(phasors(comps, dt * s)))
        if label == "qtf":
            return lambda: (lambda s: load.at(dt * s, phasors(comps, dt * s)))
        return lambda: (lambda s: load(phasors(comps, dt * s)))
    loads["qtf_direct"] = loads["qtf"]
    py = timing.per_round({label: make(label) for label in ("waves", "newman", "qtf")}, 2 * per_block, rounds)
    py.update(timing.per_round({"qtf_direct": make("qtf_direct")}, 40, rounds))
    lib, Sea = _c_lib()
    params = _c_kernels(lib, Sea, sea, SEMI_WINDOW, data, {"newman": ("newman", math.inf, False),
                                                            "qtf_direct": ("qtf", SEMI_CUTOFF, False),
                                                            "qtf": ("qtf", SEMI_CUTOFF, True)})
    c = _c_times(lib, params, {"waves": 2 * per_block, "newman": 2 * per_block, "qtf": 2 * per_block,
                               "qtf_direct": 400}, rounds, dt)
    _free(params)
    p_us = {k: 1e6 * float(np.median(v)) for k, v in py.items()}
    c_us = {k: 1e6 * float(np.median(v)) for k, v in c.items()}
    peer = (c_us["qtf_direct"] - c_us["newman"]) / (ISSUE_DIRECT - ISSUE_NEWMAN)
    return {"components": n, "cutoff": SEMI_CUTOFF, "dt": dt, "offsets": loads["qtf"].offsets, "block_s": length,
            "block_terms": k, **{f"py_{k}_us": v for k, v in p_us.items()}, **{f"c_{k}_us": v for k, v in c_us.items()},
            **{f"py_{k}_x_waves": v / p_us["waves"] for k, v in p_us.items() if k != "waves"},
            **{f"c_{k}_x_waves": v / c_us["waves"] for k, v in c_us.items() if k != "waves"},
            "peer_us": peer, "c_blocks_x_peer": ISSUE_NEWMAN + (c_us["qtf"] - c_us["newman"]) / peer,
            "py_kernels_x_peer": (p_us["waves"] + p_us["qtf"]) / peer, "noisy": noisy(py) or noisy(c)}


def newman_error(n=200, hours=2.0, dt=2.0, data=None):
    """Newman against the full QTF in one record: {force_std_ratio, force_rms_error (of the
    QTF's std), surge_std_ratio, mean_ratio} (Newman / QTF, surge); ``data``: a
    physics.drift.QTF (default the test QTF), long-crested along its first heading."""
    from scipy.signal import lsim
    from ..physics.drift import DriftLoad, phasors
    data = data if data is not None else bench_qtf()
    comps = sea(n, seed=7)
    comps.direction[:] = data.headings[0]
    full, newman = DriftLoad("qtf", comps, data), DriftLoad("newman", comps, data)
    t = np.arange(0.0, hours * 3600.0, dt)
    fq = np.empty(t.size)
    fn = np.empty(t.size)
    for k, s in enumerate(t):
        z = phasors(comps, s)
        fq[k], fn[k] = full(z)[0], newman(z)[0]
    mass, period, zeta = 2.0e6, 100.0, 0.1
    wn = 2 * math.pi / period
    system = ([1.0], [mass, 2 * zeta * mass * wn, mass * wn ** 2])
    settle = t > 10 / (zeta * wn)
    xq = lsim(system, fq, t)[1][settle]
    xn = lsim(system, fn, t)[1][settle]
    return {"components": n, "record_h": hours, "mean_ratio": fn.mean() / fq.mean(),
            "force_std_ratio": fn.std() / fq.std(), "force_rms_error": float(np.sqrt(np.mean((fn - fq) ** 2)) / fq.std()),
            "surge_std_ratio": xn.std() / xq.std()}


def lines(rows, err, crows=None, semi=None):
    """The part's summary lines; '(noisy)': the rounds of that count spread by more than 25 %."""
    out = []
    if semi:
        r = semi
        out.append(f"the full QTF at the peer's case (semisubmersible grid, {r['components']} components, cut-off "
                   f"{r['cutoff']:g} rad/s: {r['offsets']} offsets; step {r['dt']:g} s; blocks of {r['block_s']:.0f} s, "
                   f"{r['block_terms']} terms), µs per step and × the first-order excitation of the same flavour: "
                   f"compiled waves {r['c_waves_us']:.2f}, newman {r['c_newman_us']:.2f} "
                   f"({r['c_newman_x_waves']:.2f}×), qtf direct {r['c_qtf_direct_us']:.1f} "
                   f"({r['c_qtf_direct_x_waves']:.1f}×), qtf blocks {r['c_qtf_us']:.2f} ({r['c_qtf_x_waves']:.2f}×); "
                   f"Python waves {r['py_waves_us']:.1f}, newman {r['py_newman_us']:.1f} ({r['py_newman_x_waves']:.2f}×), "
                   f"qtf direct {r['py_qtf_direct_us']:.0f} ({r['py_qtf_direct_x_waves']:.1f}×), qtf blocks "
                   f"{r['py_qtf_us']:.1f} ({r['py_qtf_x_waves']:.2f}×)" + (" (noisy)" if r["noisy"] else ""))
        out.append(f"  the peer's step from the issue's ratios (qtf direct 2.2×, excitation + newman 0.47×, compiled) on "
                   f"this run: {r['peer_us']:.1f} µs; with the blocks a compiled step is {r['c_blocks_x_peer']:.2f}× "
                   f"the peer's (target ≤ 1), the Python kernels (waves + qtf blocks) {r['py_kernels_x_peer']:.2f}× "
                   f"(target ≤ 3; pythonfmu's own step cost comes on top, the same for every method)")
    out.append("cost per step in-process (phasors included; the full QTF by its direct sum), × the first-order "
               "waves kernel: " + "; ".join(
        f"{r['components']} components: waves {r['waves_us']:.0f} µs, mean {r['mean_x_waves']:.2f}×, newman "
        f"{r['newman_x_waves']:.2f}×, qtf cut 0.3 rad/s ({r['qtf_cut_offsets']} offsets) {r['qtf_cut_x_waves']:.1f}×, "
        f"qtf all pairs {r['qtf_x_waves']:.1f}×" + (" (noisy)" if r["noisy"] else "") for r in rows))
    if crows:
        out.append("compiled kernels (physics/drift.c against waves.c's hf_waves, a C loop; the full QTF by its direct "
                   "sum): " + "; ".join(
            f"{r['components']} components: waves {r['c_waves_us']:.2f} µs, mean {r['c_mean_x_waves']:.2f}×, newman "
            f"{r['c_newman_x_waves']:.2f}×, qtf cut 0.3 rad/s {r['c_qtf_cut_x_waves']:.1f}×, qtf all pairs "
            f"{r['c_qtf_x_waves']:.1f}×" + (" (noisy)" if r["c_noisy"] else "") for r in crows))
    out.append(f"Newman against the full QTF (test QTF, {err['components']} components, {err['record_h']:g} h): mean "
               f"{err['mean_ratio']:.3f}, slow-drift force std {err['force_std_ratio']:.3f}, rms difference "
               f"{100 * err['force_rms_error']:.0f} % of the QTF force's std, moored surge std (100 s, 10 % damping) "
               f"{err['surge_std_ratio']:.3f}")
    return out
