"""Robustness figures: how long a deck reader takes to report one bad number near the end
of a big deck, against reading the same deck without it (both ways linear, so the ratio
should stay near 1 whatever the size), and resident memory over fmi2Instantiate/
fmi2FreeInstance cycles with and without the shim's instance pool."""
import gc
import os
import shutil
import time
from pathlib import Path

import numpy as np

from ..decks.simo import format_coupling, read_couplings, write_couplings
from ..errors import InputError

POOL_ENV = "HYDROFMU_POOL"   # "0": the shim frees every instance (shim.c)
# Flat memory over instantiate/free cycles, from resident memory sampled every k cycles: the
# median growth between samples, times their number, stays below FLAT_KB (a leak grows at
# every sample), and the whole growth below ARENA_KB: pymalloc may take one more 1 MiB arena
# in a rare step (measured: steps of 0.17-0.65 MB, at most one per run after the warm-up).
# Measured with the shim's instance pool: 0-20 kB besides that step over 9000 (native host)
# and 18000 (fmpy) cycles; without it (HYDROFMU_POOL=0) pythonfmu 0.7 leaks 1.1-1.6 kB at
# every cycle, 10-14 MB over 9000 cycles.
FLAT_KB = 50
ARENA_KB = 1100


def write_big_deck(path, megabytes):
    """A SIMO self-coupling deck of ~``megabytes`` MB: one kernel continued over many lines."""
    n = int(megabytes * 1e6 / 16.3)   # ~16.3 bytes per sample as written
    h = 1e5 * np.exp(-np.arange(n) * 1e-6)
    return write_couplings(path, [format_coupling("C", "A", "A", kernels={(1, 1): h}, timdel=0.1)])


def spoil_near_end(path, bad="1.0x-02", out=None):
    """A copy of the deck with its last-but-one number replaced by ``bad``; returns
    (path, the 1-based line of the bad number)."""
    text = Path(path).read_text()
    lines = text.split("\n")
    k = len(lines) - 2 if lines[-1] == "" else len(lines) - 1   # the deck's last line
    words = lines[k].split()
    words[-1] = bad
    lines[k] = " ".join(words)
    out = Path(out or Path(path).with_name("bad_" + Path(path).name))
    out.write_text("\n".join(lines))
    return out, k + 1


def deck_error_time(folder, megabytes=50.0, rounds=2):
    """Seconds to read a good deck and to report the bad number in the spoilt one (best
    of ``rounds``, side by side); returns a dict with both, their ratio and the message."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    good = write_big_deck(folder / "big.sys", megabytes)
    bad, line = spoil_near_end(good)
    t_good = t_bad = float("inf")
    message = None
    for _ in range(rounds):
        t0 = time.perf_counter()
        read_couplings(good, {"A"})
        t_good = min(t_good, time.perf_counter() - t0)
        t0 = time.perf_counter()
        try:
            read_couplings(bad, {"A"})
        except InputError as exc:
            message = exc
        t_bad = min(t_bad, time.perf_counter() - t0)
    return {"megabytes": good.stat().st_size / 1e6, "good_s": t_good, "bad_s": t_bad,
            "ratio": t_bad / t_good, "error": message, "bad_line": line}


def instantiate_cycles(fmu, cycles=10_000, warmup=1000, every=1000, pool=True):
    """``cycles`` fmi2Instantiate/fmi2FreeInstance pairs of one FMU through fmpy (which loads
    and unloads the library every time), after ``warmup`` pairs; ``pool=False`` runs a copy
    of the FMU with the shim's instance pool off (HYDROFMU_POOL=0).  Returns a dict: resident
    memory growth over the measured cycles [kB] and per cycle, seconds per cycle, and the
    resident memory [kB] after the warm-up and then every ``every`` cycles, each sample after
    a full garbage collection: fmpy's FMU2Slave and the slave objects hold reference cycles,
    which a process with a large heap (a test session) collects only now and then."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    folder = extract(str(fmu))   # a copy of its own: the shim reads HYDROFMU_POOL when it loads
    saved = os.environ.get(POOL_ENV)
    if not pool:
        os.environ[POOL_ENV] = "0"

    def cycle():
        s = FMU2Slave(guid=md.guid, unzipDirectory=folder, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName="cycle")
        s.instantiate()
        s.freeInstance()

    try:
        for _ in range(warmup):
            cycle()
        rss, t0 = [_rss()], time.perf_counter()
        for k in range(1, cycles + 1):
            cycle()
            if k % every == 0 or k == cycles:
                rss.append(_rss())
        seconds = time.perf_counter() - t0
    finally:
        if saved is None:
            os.environ.pop(POOL_ENV, None)
        else:
            os.environ[POOL_ENV] = saved
        shutil.rmtree(folder, ignore_errors=True)
    growth = rss[-1] - rss[0]
    return {"cycles": cycles, "growth_kB": growth, "kB_per_cycle": growth / cycles,
            "cycle_s": seconds / cycles, "rss_kB": rss}


def growth(rss):
    """(steady, total) growth [kB] of resident memory samples ``rss`` [kB]: the median growth
    between samples times their number (blind to a rare allocator step), and last - first."""
    steps = np.diff(np.asarray(rss, dtype=float))
    return float(np.median(steps) * len(steps)) if len(steps) else 0.0, float(rss[-1] - rss[0])


def _rss():
    """Resident memory [kB] after a full garbage collection."""
    gc.collect()
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 1e3
