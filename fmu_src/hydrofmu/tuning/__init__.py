"""``hydrofmu tune``: the cheapest run settings of a scene whose error stays within a tolerance.

1. A reference of the scene itself: the ``reference`` preset (step 0.01 s, Gauss–Seidel, linear
   hold, substep 0.005 s, full convolution), checked converged by one halving of step and
   substep; the halved run is the reference and the difference of the two its uncertainty u
   (halved again, at most twice, while u > tolerance / 4).
2. A search over communication step × algorithm (Gauss–Seidel, Jacobi) × load hold (linear,
   constant), then substep, then memory evaluator; every point is one run of the scene in
   this process (``cosim.inprocess``: the slaves the FMUs hold, driven by the fmpy master's
   own loop, ``cosim.master.run``: the same numbers as the built FMUs, without the FMI
   transport).  Per algorithm and hold: the largest step of ``STEPS`` that meets the
   tolerance (doubling from the design step while it does, halving while it does not), with
   a fine substep and the exact memory; then the largest substep (one RK4 step per
   communication step first), then the cheapest memory evaluator (the presets' state-space
   fits, coarsest first).  A branch whose best possible cost (its largest step, one substep,
   no memory) cannot beat the best point found so far is not refined (pruned).
   Then, on the best point only: per coupling, a state-space order of ``ORDERS`` (fewer
   states than its tolerance fit's largest element order; any order where the point uses the
   full convolution), lowest first; and ECCO (libcosim's adaptive Jacobi step, steps
   ``ECCO_MIN`` s up to the largest searched step within 4× the best point's, abs_tolerance
   of ``ECCO_TOLERANCES``, loosest first), only where it can pay: the scene has power bonds and ECCO's fewest steps
   (all at its largest) cost less than the best point.  ECCO runs in libcosim on FMUs built
   for it (once per tune); its cost is converted to this process's by a fixed-step Jacobi
   run of the same step in both (median ratio of the timing rounds).
   A step is kept ``search.MARGIN`` (3) times below the smallest step of the same algorithm
   and hold that diverged over the window (the stability margin).
3. The presets and the scene's own settings, run the same way, and the final candidates
   re-timed in ``repeats`` interleaved rounds: cost = median seconds of stepping per
   simulated second (initialisation excluded), spread = (max − min) / median.
4. The choice confirmed over the run it is tuned for (``confirm``): the candidates, cheapest
   first, run over the scene's ``stop`` (or ``confirm`` seconds, with the drift check of
   ``confirm.py``: the last quarter's error meets the tolerance too) against the reference over
   the same length; the first that meets the tolerance there is the choice, one that does not
   is reported, not offered.

Modules, by step: ``settings`` (the knobs searched, ``Setting``, ``Point``), ``runner`` (runs in
this process or libcosim, the error), ``search`` (reference, search, presets), ``confirm``,
``report`` (``Tuning``, the plot), ``write`` (``--write``).

Error of a run: the largest, over the named outputs (default: every body's position and
attitude), of the RMS difference to the reference (linear between its points, 2.5 ms or
finer) at the run's communication points over the reference's range (max − min):
``√mean((y − y_ref)²) / ptp(y_ref)``; outputs whose range
is below 1e-9 of the largest of the same unit do not move and are left out (listed).  A
point meets the tolerance when error + u ≤ tolerance.

What is searched is what a scene's ``[run]`` block (with ``[run.ecco]``) and its
``[[couplings]]`` tables can say: ``step``, ``algorithm`` (ECCO with ``max_step`` and
``abs_tolerance``), ``load_hold``, ``substep``, for the memory of every coupling the
evaluator of a preset (``preset = "reference"``: full convolution; ``"design"``: state-space
tol 0.01; ``"screening"``: tol 0.05), and per coupling a state-space ``order``.  Not
searched (listed in every report): memory lengths, couplings that set their own ``method``
(kept as they are), ECCO's other settings (min_step, rel_tolerance, gains) and the
``adaptive`` preset as a point of its own.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from ..errors import InputError
from .confirm import confirm as _confirm
from .report import Tuning, pareto, plot
from .search import DIVERGED, MARGIN, Search
from .settings import (ALGORITHMS, ECCO_MIN, ECCO_TOLERANCES, HOLDS, MEMORY, ORDERS, STEPS, SUBSTEPS, WINDOW, Point,
                       Setting)
from .write import write_run_block

__all__ = ["tune", "Tuning", "Setting", "Point", "write_run_block", "plot", "pareto", "STEPS", "SUBSTEPS", "MEMORY",
           "ALGORITHMS", "HOLDS", "WINDOW", "ORDERS", "ECCO_TOLERANCES", "ECCO_MIN", "MARGIN", "DIVERGED"]


def tune(scene: str | Path, tolerance: float = 0.005, *, outputs: Sequence[str] | None = None,
         window: float | None = None, confirm: float | None = None, repeats: int = 3, png: str | Path | None = None,
         log: Callable[[str], object] = print, _cache: dict | None = None) -> Tuning:
    """The cheapest run settings of a scene whose error stays within ``tolerance``.

    Parameters
    ----------
    scene : str or Path
        The scene file (``.toml``).
    tolerance : float
        Largest error allowed, as a fraction (0.005 = 0.5 %): normalised RMS difference to
        the reference over each output's range (see the module docstring).
    outputs : sequence of str, optional
        What the error is measured on: body names (position and attitude),
        ``body.position``/``attitude``/``velocity``/``acceleration``, or recorded columns
        ``instance.variable``; default: every body's position and attitude.
    window : float, optional
        Simulated time of each search run [s]; default: the scene's stop, at most 60 s.
    confirm : float, optional
        Length of the confirmation runs [s], a whole number of windows, at most the scene's
        stop; default: the scene's stop (shorter: the error's drift is checked, ``confirm.py``).
    repeats : int
        Interleaved timing rounds of the final candidates (cost = median).
    png : str or Path, optional
        Where to draw every point run (error against cost) with the Pareto front.

    Returns
    -------
    Tuning
        ``choice`` (None when nothing met the tolerance over the window and the confirmation),
        ``points``, ``run_block()``, ``report()``.
    """
    from threadpoolctl import threadpool_limits
    from ..scene import load_scene
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not 0 < tolerance < 1:
        raise InputError("tune", None, "tolerance", f"must be a fraction in (0, 1) (0.005 = 0.5 %), found {tolerance!r}")
    own = load_scene(scene)
    stop = own.run["stop"]
    window = min(stop, WINDOW) if window is None else window
    if not (math.isfinite(window) and window > 0) or window > stop:
        raise InputError("tune", None, "window", f"must be positive and at most the scene's stop ({stop:g} s), "
                                                 f"found {window!r}")
    confirm = stop if confirm is None else confirm
    if (isinstance(confirm, bool) or not isinstance(confirm, (int, float)) or not math.isfinite(confirm)
            or not window <= confirm <= stop or abs(confirm / window - round(confirm / window)) > 1e-9):
        raise InputError("tune", None, "confirm", f"must be a whole number of windows ({window:g} s) up to the "
                                                  f"scene's stop ({stop:g} s), found {confirm!r}")
    # one BLAS thread: the state-space fits (SVDs) are 20x slower threaded on a shared machine
    with threadpool_limits(1):
        return _tune(scene, own, tolerance, outputs, window, float(confirm), repeats, png, log,
                     {} if _cache is None else _cache)


def _tune(path, own, tolerance, outputs, window, length, repeats, png, log, cache):
    s = Search(path, own, tolerance, outputs, window, log, cache)
    s.reference()
    s.search()
    s.presets()
    runner, points, feasible = s.runner, s.points, s.feasible
    # re-time the final candidates, interleaved
    ok = [p for p in points.values() if feasible(p)]
    choice, confirmed = None, []
    if ok:
        cheapest = min(p.proxy for p in ok)
        finalists = sorted((p for p in ok if p.proxy <= 2 * cheapest), key=lambda p: p.proxy)[:4]
        finalists += [p for p in points.values() if p.source != "search" and p not in finalists]
        eccos = [p for p in finalists if p.setting.algorithm == "ecco"]
        for _ in range(max(1, repeats)):
            if eccos:   # ECCO's cost in this process's seconds: a calibration pair per round
                runner.calibrate(eccos[0].setting, runner.calibration)
            for p in finalists:
                if math.isfinite(p.error):
                    p.times.append(runner.run(p.setting)[2] / window)
        for p in finalists:
            if not p.times:
                continue
            p.cost = float(np.median(p.times))
            p.spread = float(np.ptp(p.times) / p.cost) if len(p.times) > 1 and p.cost > 0 else None
        order = sorted((p for p in finalists if feasible(p)), key=lambda p: (p.cost, p.proxy))
        if length > window + 1e-9:
            choice, confirmed = _confirm(s, order, length, outputs, cache)
        elif order:   # the window is the whole run: the search's error is the run's
            choice = order[0]
            choice.confirmed = choice.drift = choice.error
    stop = s.stop
    not_tried = ([s.ecco_pruned] if s.ecco_pruned else []) + [
                 "ECCO's min_step, rel_tolerance and controller gains (kept at "
                 f"{ECCO_MIN:g} s and libcosim's defaults), and the 'adaptive' preset as a point of its own",
                 f"state-space orders other than {', '.join(map(str, ORDERS))}, orders on any point but the best, "
                 "and memory lengths",
                 f"steps outside {', '.join(f'{x:g}' for x in s.steps)} s (steps must divide the window "
                 f"{window:g} s and the scene's stop {stop:g} s)"]
    if own.couplings and any(c.set for c in own.couplings):
        not_tried.append("the memory of couplings that set their own method (kept)")
    not_tried += [f"pruned: {p}" for p in s.pruned]
    tuning = Tuning(own.name, tolerance, window, s.ref_setting, s.u, list(np.array(runner.columns)[s.moving]),
                    runner.columns, s.still, list(points.values()), choice, not_tried,
                    "runs in this process (cosim.inprocess: the FMUs' slaves and the fmpy master's loop, "
                    "the same numbers as the built FMUs without the FMI calls; costs are this process's)"
                    + ("; ECCO in libcosim on built FMUs, its cost in this process's seconds" if runner.ratios else ""),
                    feasible, [c.name for c in own.couplings], s.searched + s.margins, length, stop, confirmed)
    if png:
        plot(tuning, png)
    return tuning
