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
3. The presets and the scene's own settings, run the same way, and the final candidates
   re-timed in ``repeats`` interleaved rounds: cost = median seconds of stepping per
   simulated second (initialisation excluded), spread = (max − min) / median.

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
import re
import time
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from .admissible import whole_steps
from .errors import InputError

# communication steps searched [s]: multiples of the reference's 0.005 s
STEPS = (0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
SUBSTEPS = (0.005, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
# memory evaluator of every coupling, by the preset that sets it (cheapest first)
MEMORY = {"screening": "state-space tol 0.05", "design": "state-space tol 0.01", "reference": "convolution"}
ALGORITHMS = ("gauss-seidel", "jacobi")
HOLDS = ("linear", "constant")
WINDOW = 60.0   # default tuning window [s]: the first minute of the scene's run
ORDERS = (1, 2, 4, 8)               # per-coupling state-space orders tried (ERA order per kernel element)
ECCO_TOLERANCES = (10.0, 1.0, 0.1)  # ECCO's abs_tolerance [J] tried, loosest (fewest steps) first
ECCO_MIN, ECCO_FIRST = 0.005, 0.05  # ECCO's smallest and first step [s]


@dataclass(frozen=True)
class Setting:
    """One combination of run knobs; ``memory``: the preset whose memory evaluator every
    coupling uses (None: the scene has no coupling to tune); ``orders``: ((coupling index,
    state-space order), …) over it; ``ecco``: ECCO's abs_tolerance [J] when ``algorithm`` is
    'ecco' (``step`` is then its largest step)."""
    step: float
    algorithm: str
    load_hold: str
    substep: float
    memory: str | None
    orders: tuple = ()
    ecco: float | None = None

    def label(self) -> str:
        how = (f"ECCO steps {ECCO_MIN:g}–{self.step:g} s, abs tol {self.ecco:g} J" if self.algorithm == "ecco"
               else f"step {self.step:g} s, {self.algorithm}")
        return (f"{how}, {self.load_hold} hold, substep {self.substep:g} s"
                + (f", {MEMORY[self.memory]}" if self.memory else "")
                + "".join(f", couplings[{i}] order {n}" for i, n in self.orders))

    def first_step(self) -> float:
        """The run's ``step``: ECCO's first step, else the communication step."""
        return min(ECCO_FIRST, self.step) if self.algorithm == "ecco" else self.step

    def overrides(self, stop: float) -> dict:
        out = {"run.step": self.first_step(), "run.algorithm": self.algorithm, "run.load_hold": self.load_hold,
               "run.substep": self.substep, "run.stop": stop}
        if self.memory:
            out["run.preset"] = self.memory
        if self.algorithm == "ecco":
            out["run.ecco"] = {"min_step": ECCO_MIN, "max_step": self.step, "abs_tolerance": self.ecco}
        for i, n in self.orders:
            out[f"couplings[{i}].method"] = "state_space"
            out[f"couplings[{i}].order"] = n
        return out

    def proxy(self, window: float, instances: int, time_=None) -> float:
        """Deterministic cost proxy: FMU steps plus the dynamics' Runge–Kutta steps over the
        window (an ECCO run: over the steps it took, ``time_``)."""
        if time_ is not None and len(time_) > 1:
            h = np.diff(time_)
            return float(np.sum(instances + np.maximum(1, np.ceil(h / self.substep - 1e-9))))
        return window / self.step * (instances + max(1, round(self.step / self.substep)))


@dataclass
class Point:
    setting: Setting
    error: float
    cost: float                 # stepping seconds per simulated second (median of the timings)
    proxy: float
    spread: float | None = None  # (max − min) / median of repeated timings, None: timed once
    source: str = "search"       # 'search', a preset name, 'scene'
    times: list = field(default_factory=list)


@dataclass
class Tuning:
    """The result of ``tune``: the choice, every point run, and what the search left out."""
    scene: str
    tolerance: float
    window: float
    reference: Setting
    uncertainty: float          # difference of the reference and its halving (same measure)
    outputs: list               # the columns the error is measured on
    columns: list               # every column recorded (outputs and those left out)
    still: list                 # outputs left out: they do not move
    points: list                # every Point run (search, presets, the scene's own)
    choice: Point | None
    not_tried: list
    equivalence: str
    feasible: Callable = None
    couplings: list = field(default_factory=list)   # coupling names, by index
    searched: list = field(default_factory=list)    # lines: what the order and ECCO searches ran

    def run_block(self, stop: float | None = None, keep: Sequence[str] = ()) -> str:
        """The ``[run]`` block of the choice (with ``stop`` when given, and ``[run.ecco]`` for
        an ECCO choice, and the lines ``keep``); per-coupling orders as comments naming the
        ``[[couplings]]`` keys."""
        if self.choice is None:
            raise ValueError("no setting met the tolerance")
        s = self.choice.setting
        lines = [f"# hydrofmu tune: error {100 * self.choice.error:.3g} % <= {100 * self.tolerance:g} % "
                 f"over the first {self.window:g} s, {self.choice.cost:.3g} s per simulated second",
                 "[run]"]
        if s.memory:
            lines.append(f'preset = "{s.memory}"   # memory evaluator: {MEMORY[s.memory]}')
        lines += [f"step = {s.first_step()!r}" + ("   # ECCO's first step" if s.algorithm == "ecco" else ""),
                  f'algorithm = "{s.algorithm}"', f'load_hold = "{s.load_hold}"', f"substep = {s.substep!r}"]
        if stop is not None:
            lines.append(f"stop = {stop!r}")
        lines += list(keep)
        if s.algorithm == "ecco":
            lines += ["[run.ecco]", f"min_step = {ECCO_MIN!r}", f"max_step = {s.step!r}",
                      f"abs_tolerance = {s.ecco!r}"]
        for i, n in s.orders:
            lines.append(f'# [[couplings]] #{i} ({self.couplings[i]}): method = "state_space", order = {n}'
                         + ("" if stop is None else "   (written into that table)"))
        return "\n".join(lines) + "\n"

    def table(self) -> str:
        """The choice, the presets and the scene's own settings: error, cost, spread."""
        rows = [("choice", self.choice)] if self.choice else []
        rows += [(p.source, p) for p in self.points if p.source != "search"]
        out = [f"{'':<16} {'error %':>8} {'meets':>5} {'cost s/s':>9} {'spread':>7}  settings"]
        for name, p in rows:
            spread = f"{100 * p.spread:.0f} %" if p.spread is not None else "once"
            out.append(f"{name:<16} {100 * p.error:>8.3g} {'yes' if self.feasible(p) else 'no':>5} "
                       f"{p.cost:>9.3g} {spread:>7}  {p.setting.label()}")
        return "\n".join(out)

    def report(self) -> list[str]:
        lines = [f"tune {self.scene}: tolerance {100 * self.tolerance:g} % over the first {self.window:g} s; "
                 f"reference {self.reference.label()} (converged: one halving changes it by "
                 f"{100 * self.uncertainty:.2g} %, counted against every point)",
                 f"outputs ({len(self.outputs)}): {_short(self.outputs)}"
                 + (f"; left out (not moving): {_short(self.still)}" if self.still else ""),
                 f"searched {sum(p.source == 'search' for p in self.points)} points; {self.equivalence}"]
        lines += self.searched + [self.table()]
        if self.choice is None:
            lines.append("no setting met the tolerance: loosen it or lengthen the window")
        else:
            cheaper = [p for p in self.points if p is not self.choice and p.source != "search" and self.feasible(p)]
            if cheaper:
                best = min(cheaper, key=lambda p: p.cost)
                ratio = best.cost / self.choice.cost
                noisy = self.choice.spread is not None and best.spread is not None and \
                    abs(ratio - 1) < max(self.choice.spread, best.spread)
                lines.append(f"choice vs {best.source}: {ratio:.2f}x cheaper"
                             + (" (within the timing spread: too noisy to call)" if noisy else ""))
        lines += ["not tried:"] + [f"  - {n}" for n in self.not_tried]
        return lines


def _short(names, show=6):
    return ", ".join(names[:show]) + (f", … ({len(names) - show} more)" if len(names) > show else "")


class _Runner:
    """Runs settings of one scene in this process over the window (ECCO: in libcosim, on FMUs
    built for it once)."""

    def __init__(self, path, window, outputs, log):
        self.path, self.window, self.log = Path(path), window, log
        self.outputs, self.manifest, self.instances = outputs, None, 0
        self.builds, self.ratios, self._tmp, self.joints = {}, [], None, True

    def run(self, setting: Setting):
        """(times, values of the columns, seconds of stepping)."""
        if setting.algorithm == "ecco":
            return self.run_ecco(setting)
        from .cosim import inprocess
        from .cosim.master import run
        from .scene import load_scene
        scene = load_scene(self.path, setting.overrides(self.window))
        system = inprocess.system(scene)
        if self.manifest is None:
            from .cosim.stream import select
            self.manifest, self.instances = system.manifest, len(system.instances)
            valid = [f"{n}.{v}" for n, inst in system.instances.items() for v in inst.outputs()]
            self.columns = select(system.manifest, self.outputs or list(system.manifest["dynamics"]), valid,
                                  self.path, "outputs")
        marks = {}
        n = int(round(self.window / setting.step))

        def mark(k):
            if k in (1, n):
                marks[k] = time.perf_counter()
        try:
            # every communication point compared, whatever the scene's [run] interval
            result = run(system, stop=self.window, step=setting.step, algorithm=setting.algorithm,
                         record=self.columns, progress=False, on_step=mark, interval=setting.step)
        except RuntimeError as exc:   # the run failed (diverged): a point that meets nothing
            return None, str(exc), float("nan")
        finally:
            system.free()
        seconds = marks[n] - marks[1] if n > 1 else float("nan")
        return result.time, result.values, seconds * n / max(n - 1, 1)

    def built(self, setting: Setting):
        """The FMUs of an ECCO setting: one build per setting but its abs_tolerance (a run knob)
        and, in a scene without joints, its largest step (a run knob too; a joint's default
        spring follows it)."""
        import tempfile
        from .fmi.build import build_scene
        from .scene import load_scene
        key = replace(setting, ecco=1.0, step=setting.step if self.joints else STEPS[-1])
        if key not in self.builds:
            if self._tmp is None:
                self._tmp = tempfile.TemporaryDirectory(prefix="hydrofmu-tune-")
            scene = load_scene(self.path, key.overrides(self.window))
            scene.run["interval"] = None   # every point ECCO takes is compared
            self.builds[key] = build_scene(scene, Path(self._tmp.name) / str(len(self.builds)), log=lambda *_: None)
        return self.builds[key]

    def run_ecco(self, setting: Setting):
        """An ECCO run in libcosim: (its time points up to the window, values, seconds of
        stepping converted to this process's by the latest Jacobi calibration ``ratios``)."""
        from .cosim import libcosim
        clock = {}
        try:
            r = libcosim.run(self.built(setting), stop=self.window, step=setting.first_step(), algorithm="ecco",
                             record=self.columns, timing=clock,
                             ecco={"abs_tolerance": setting.ecco, "min_step": ECCO_MIN, "max_step": setting.step})
        except RuntimeError as exc:
            return None, str(exc), float("nan")
        keep = r.time <= self.window + 1e-9
        return r.time[keep], r.values[keep, :len(self.columns)], clock["stepping"] * self.ratios[-1]

    def calibrate(self, ecco: Setting, jacobi: Setting):
        """A fixed-step Jacobi run of ``jacobi`` (ECCO's hold, substep and memory) in libcosim on
        the build of ``ecco`` and in this process, timed back to back: appends the ratio of
        their seconds of stepping (this process / libcosim)."""
        from .cosim import libcosim
        clock = {}
        libcosim.run(self.built(ecco), stop=self.window, step=jacobi.step, algorithm="jacobi", record=self.columns,
                     timing=clock)
        self.ratios.append(self.run(jacobi)[2] / clock["stepping"])


def _error(time_, values, ref_time, ref_values, scale):
    """Largest normalised RMS difference at ``time_`` (the reference linear between its points:
    exact at a fixed-step run's points, which lie on its grid)."""
    ref = np.column_stack([np.interp(time_, ref_time, col) for col in ref_values.T])
    return float(np.max(np.sqrt(np.mean((values - ref) ** 2, axis=0)) / scale))


def tune(scene: str | Path, tolerance: float = 0.005, *, outputs: Sequence[str] | None = None,
         window: float | None = None, repeats: int = 3, png: str | Path | None = None,
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
        Simulated time of each run [s]; default: the scene's stop, at most 60 s.
    repeats : int
        Interleaved timing rounds of the final candidates (cost = median).
    png : str or Path, optional
        Where to draw every point run (error against cost) with the Pareto front.

    Returns
    -------
    Tuning
        ``choice`` (None when nothing met the tolerance), ``points``, ``run_block()``,
        ``report()``.
    """
    from threadpoolctl import threadpool_limits
    from .scene import load_scene
    if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not 0 < tolerance < 1:
        raise InputError("tune", None, "tolerance", f"must be a fraction in (0, 1) (0.005 = 0.5 %), found {tolerance!r}")
    own = load_scene(scene)
    stop = own.run["stop"]
    window = min(stop, WINDOW) if window is None else window
    if not (math.isfinite(window) and window > 0) or window > stop:
        raise InputError("tune", None, "window", f"must be positive and at most the scene's stop ({stop:g} s), "
                                                 f"found {window!r}")
    # one BLAS thread: the state-space fits (SVDs) are 20x slower threaded on a shared machine
    with threadpool_limits(1):
        return _tune(scene, own, tolerance, outputs, window, repeats, png, log, _cache)


def _tune(path, own, tolerance, outputs, window, repeats, png, log, cache):
    cache = {} if cache is None else cache
    key = (str(path), window, tuple(outputs or ()))
    runner = cache.setdefault(("runner",) + key, _Runner(path, window, outputs, log))
    runner.joints = bool(own.joints)
    stop = own.run["stop"]
    fits = lambda step: (not whole_steps(window, step)[1] and not whole_steps(stop, step)[1]) and step <= window / 2
    runs = cache.setdefault(("runs",) + key, {})

    def get(setting):
        if setting not in runs:
            runs[setting] = runner.run(setting)
        return runs[setting]

    # 1. the reference, converged by one halving
    has_memory = bool(own.couplings)
    ref = Setting(0.01, "gauss-seidel", "linear", 0.005, "reference" if has_memory else None)
    t0, y0, _ = get(ref)
    scale_all = np.ptp(y0, axis=0)
    kind = [("attitude" in c) for c in runner.columns]
    top = {k: max([s for s, kk in zip(scale_all, kind) if kk == k] or [0]) for k in (True, False)}
    moving = np.array([s > 1e-9 * top[k] and s > 0 for s, k in zip(scale_all, kind)])
    if not moving.any():
        raise InputError(path, None, "outputs", "none of the outputs moves over the window: nothing to tune against")
    still = [c for c, m in zip(runner.columns, moving) if not m]
    halvings = 0
    while True:
        half = replace(ref, step=ref.step / 2, substep=ref.substep / 2)
        t1, y1, _ = get(half)
        scale = np.ptp(y1[:, moving], axis=0)
        u = _error(t0, y0[:, moving], t1, y1[:, moving], scale)
        if u <= tolerance / 4 or halvings == 2:
            break
        ref, t0, y0, halvings = half, t1, y1, halvings + 1
    if u > tolerance / 2:
        raise InputError(path, None, "tolerance", f"{100 * tolerance:g} % is below what the reference resolves "
                                                  f"(its halving changes it by {100 * u:.2g} %): loosen it")
    ref_time, ref_values = t1, y1[:, moving]
    log(f"tune {own.name}: reference {half.label()}, uncertainty {100 * u:.2g} %")

    points = {}

    def point(setting, source="search"):
        if setting not in points:
            t, y, sec = get(setting)
            err = math.inf if t is None else _error(t, y[:, moving], ref_time, ref_values, scale)
            if not math.isfinite(err):
                err = math.inf
            points[setting] = Point(setting, err, sec / window,
                                    setting.proxy(window, runner.instances, t if setting.algorithm == "ecco" else None),
                                    source=source)
        elif source != "search":
            old = points[setting].source
            points[setting].source = source if old == "search" else f"{old} = {source}"
        return points[setting]

    feasible = lambda p: p.error + u <= tolerance
    memories = list(MEMORY) if has_memory else [None]
    exact = "reference" if has_memory else None
    steps = [s for s in STEPS if fits(s)]
    sub = lambda s: max([x for x in SUBSTEPS if x <= min(s, 0.01) and _divides(x, s)] or [s])
    best = None
    pruned = []
    for algorithm in ALGORITHMS:
        for hold in HOLDS:
            # 1. largest step meeting the tolerance, fine substep and exact memory
            at = lambda k: point(Setting(steps[k], algorithm, hold, sub(steps[k]), exact))
            i = min(range(len(steps)), key=lambda k: abs(steps[k] - 0.05)) if steps else None
            found = None
            if i is not None and feasible(at(i)):   # double while the tolerance holds
                found = i
                while found + 1 < len(steps) and feasible(at(found + 1)):
                    found += 1
            elif i is not None:                     # halve until it holds
                found = next((k for k in range(i - 1, -1, -1) if feasible(at(k))), None)
            if found is None:
                continue
            step = steps[found]
            floor = Setting(step, algorithm, hold, step, None).proxy(window, runner.instances)
            if best is not None and floor >= best.proxy:
                pruned.append(f"{algorithm}/{hold} (best step {step:g} s cannot beat {best.setting.label()})")
                continue
            chosen = point(Setting(step, algorithm, hold, sub(step), exact))
            # 2. the largest substep
            for s in sorted((x for x in SUBSTEPS if x <= step and _divides(x, step) and x > chosen.setting.substep),
                            reverse=True):
                p = point(replace(chosen.setting, substep=s))
                if feasible(p):
                    chosen = p
                    break
            # 3. the cheapest memory evaluator
            for m in memories[:-1]:
                p = point(replace(chosen.setting, memory=m))
                if feasible(p):
                    chosen = p
                    break
            if best is None or chosen.proxy < best.proxy or (chosen.proxy == best.proxy and chosen.cost < best.cost):
                best = chosen
    searched = []
    if best is not None and has_memory:
        best = _search_orders(own, path, window, best, point, feasible, searched)
    ecco_pruned = None
    if best is not None:
        ecco_pruned = _search_ecco(runner, window, best, point, feasible, searched)
    # the presets and the scene's own settings
    from .scene import PRESETS
    for name in ("screening", "design", "reference"):
        pr = PRESETS[name]
        if fits(pr["step"]) and pr["step"] > 0:
            point(Setting(pr["step"], pr["algorithm"], pr["load_hold"], pr["substep"], name if has_memory else None), name)
    mine = own.run
    if mine["algorithm"] != "ecco" and fits(mine["step"]):
        memory = _memory_preset(own) if has_memory else None
        if memory is not None or not has_memory:
            point(Setting(mine["step"], mine["algorithm"], mine["load_hold"], mine["substep"], memory), "scene")
    # re-time the final candidates, interleaved
    ok = [p for p in points.values() if feasible(p)]
    choice = None
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
        choice = min((p for p in finalists if feasible(p)), key=lambda p: (p.cost, p.proxy))
    not_tried = ([ecco_pruned] if ecco_pruned else []) + [
                 "ECCO's min_step, rel_tolerance and controller gains (kept at "
                 f"{ECCO_MIN:g} s and libcosim's defaults), and the 'adaptive' preset as a point of its own",
                 f"state-space orders other than {', '.join(map(str, ORDERS))}, orders on any point but the best, "
                 "and memory lengths",
                 f"steps outside {', '.join(f'{s:g}' for s in steps)} s (steps must divide the window "
                 f"{window:g} s and the scene's stop {stop:g} s)"]
    if own.couplings and any(c.set for c in own.couplings):
        not_tried.append("the memory of couplings that set their own method (kept)")
    not_tried += [f"pruned: {p}" for p in pruned]
    tuning = Tuning(own.name, tolerance, window, half, u, list(np.array(runner.columns)[moving]), runner.columns, still,
                    list(points.values()), choice, not_tried,
                    "runs in this process (cosim.inprocess: the FMUs' slaves and the fmpy master's loop, "
                    "the same numbers as the built FMUs without the FMI calls; costs are this process's)"
                    + ("; ECCO in libcosim on built FMUs, its cost in this process's seconds" if runner.ratios else ""),
                    feasible, [c.name for c in own.couplings], searched)
    if png:
        plot(tuning, png)
    return tuning


def _search_orders(scene, path, window, best, point, feasible, searched):
    """Per coupling that does not set its own method, on the best point: a state-space order of
    ``ORDERS``, lowest first, with fewer states than the coupling's evaluator there (its
    tolerance fit's largest element order; any order in place of the full convolution); the
    first that meets the tolerance is kept.  Returns the best point, with the orders kept."""
    from .scene import load_scene
    tuned = [i for i, c in enumerate(scene.couplings) if not c.set and c.kernels]
    fitted = load_scene(path, {"run.preset": best.setting.memory, "run.stop": window}) if tuned else None
    for i in tuned:
        c = fitted.couplings[i]
        if c.method == "state_space":
            largest = max(f.order for f in c.model().fits.values())
            ladder = [n for n in ORDERS if n < largest]
            why = f"tol {c.tolerance:g} fit, largest element order {largest}"
        else:
            ladder, why = list(ORDERS), "full convolution"
        tried = []
        for n in ladder:
            p = point(replace(best.setting, orders=best.setting.orders + ((i, n),)))
            tried.append(f"{n}: {100 * p.error:.3g} %" + ("" if feasible(p) else " (fails)"))
            if feasible(p):
                best = p
                break
        searched.append(f"order of couplings[{i}] ({c.name}; {why}): "
                        + ("; ".join(tried) if tried else "no smaller order to try"))
    return best


def _search_ecco(runner, window, best, point, feasible, searched):
    """ECCO on the best point's hold, substep and memory, where it can pay: abs_tolerance of
    ``ECCO_TOLERANCES``, loosest first, until one meets the tolerance or takes more steps
    than the best point.  Returns why it was not tried, or None."""
    from .cosim.bonds import power_bonds
    if not power_bonds(runner.manifest):
        return "ECCO: not applicable (no power bonds: a load FMU's force to a dynamics FMU and its velocity back)"
    # ECCO's largest step: the largest searched one up to 4x the best point's (a joint's default
    # spring follows the largest step: one for 1 s steps is another joint than the reference's)
    top = max([s for s in STEPS if s <= min(window / 2, 4 * best.setting.step)] or [best.setting.step])
    floor = Setting(top, "jacobi", best.setting.load_hold, top, None).proxy(window, runner.instances)
    if floor >= best.proxy:
        return (f"ECCO: pruned, it cannot pay (its fewest steps, all {top:g} s with one Runge–Kutta step each, "
                f"cost {floor:.0f} step units, the best point {best.proxy:.0f}: {best.setting.label()})")
    try:
        import libcosimpy  # noqa: F401  (the test extra)
    except ImportError:
        return "ECCO: needs libcosimpy (pip install libcosimpy), not installed"
    base = replace(best.setting, step=top, algorithm="ecco", ecco=ECCO_TOLERANCES[0])
    runner.calibration = replace(best.setting, algorithm="jacobi")
    try:
        runner.calibrate(base, runner.calibration)
    except RuntimeError as exc:   # libcosim could not run the FMUs built for it
        return f"ECCO: not run, libcosim failed on the FMUs built for it ({exc})"
    tried = []
    for tol in ECCO_TOLERANCES:
        p = point(replace(base, ecco=tol))
        tried.append(f"abs_tolerance {tol:g} J: {100 * p.error:.3g} %{'' if feasible(p) else ' (fails)'}, "
                     f"{p.proxy:.0f} step units")
        if feasible(p):
            break
        if p.proxy >= best.proxy and tol != ECCO_TOLERANCES[-1]:
            tried.append("tighter tolerances take more steps than the best point: stopped")
            break
    searched.append(f"ECCO (libcosim, steps {ECCO_MIN:g}–{top:g} s; best fixed point {best.proxy:.0f} step units; "
                    f"its cost × {runner.ratios[-1]:.2g}, this process's over libcosim's seconds for "
                    f"{runner.calibration.label()}): " + "; ".join(tried))
    return None


def _divides(small, big):
    return abs(big / small - round(big / small)) < 1e-9


def _memory_preset(scene):
    """The preset whose memory evaluator the scene's couplings use, or None."""
    from .scene import MEMORY_DEFAULTS, PRESETS
    used = {(c.method, c.tolerance if c.method == "state_space" else None, c.order, c.memory_length)
            for c in scene.couplings}
    for name in MEMORY:
        m = PRESETS[name]["memory"]
        if used == {(m["method"], m["tolerance"] if m["method"] == "state_space" else None, None, m["memory_length"])}:
            return name
    return None


def pareto(points):
    """The points no other point beats in both cost and error, cheapest first."""
    return sorted((p for p in points if not any(o.cost < p.cost and o.error < p.error for o in points)),
                  key=lambda p: p.cost)


def plot(tuning: Tuning, path) -> Path:
    """Error against cost of every point run, the Pareto front, the tolerance, the choice and presets."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .cosim.report import plain_log_ticks
    fig, ax = plt.subplots(figsize=(9.5, 5))
    marker = {"gauss-seidel": "o", "jacobi": "s", "ecco": "^"}
    color = {"linear": "C0", "constant": "C1"}
    pts = [p for p in tuning.points if p.cost > 0 and p.error > 0]
    for alg in ALGORITHMS + ("ecco",):
        for hold in HOLDS:
            rs = [p for p in pts if p.setting.algorithm == alg and p.setting.load_hold == hold]
            if rs:
                ax.loglog([p.cost for p in rs], [100 * p.error for p in rs], marker[alg], color=color[hold],
                          alpha=0.7, label=f"{alg}, {hold} hold")
    ordered = [p for p in pts if p.setting.orders]
    if ordered:
        ax.loglog([p.cost for p in ordered], [100 * p.error for p in ordered], "o", mfc="none", mec="k", ms=11,
                  label="with per-coupling orders")
    front = pareto(pts)
    ax.loglog([p.cost for p in front], [100 * p.error for p in front], "k:", lw=1.5, label="Pareto front")
    ax.axhline(100 * (tuning.tolerance - tuning.uncertainty), color="C3", lw=1,
               label=f"tolerance {100 * tuning.tolerance:g} % − reference uncertainty")
    for p in pts:
        if p.source != "search":
            ax.annotate(p.source, (p.cost, 100 * p.error), textcoords="offset points", xytext=(6, 4), fontsize=8)
    if tuning.choice:
        ax.loglog([tuning.choice.cost], [100 * tuning.choice.error], "*", ms=16, color="C2", mec="k",
                  label="choice", ls="none")
    ax.set_xlabel("cost [s of stepping per simulated s]\n(median of the final timings; search points: one run)")
    ax.set_ylabel("error vs reference [% of range]")
    ax.set_title(f"hydrofmu tune {tuning.scene}: {len(pts)} runs over {tuning.window:g} s", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1), borderaxespad=0)
    plain_log_ticks(ax)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return Path(path)


RUN_TABLE = re.compile(r"^\s*\[\s*run\s*\]\s*(#.*)?$")
RUN_ECCO = re.compile(r"^\s*\[\s*run\s*\.\s*ecco\s*\]\s*(#.*)?$")
COUPLING = re.compile(r"^\s*\[\[\s*couplings\s*\]\]\s*(#.*)?$")
TABLE = re.compile(r"^\s*\[")


def _table_end(lines, start):
    """Index of the first line of the table after the one whose header is ``lines[start]``."""
    return next((i for i in range(start + 1, len(lines)) if TABLE.match(lines[i])), len(lines))


def write_run_block(scene_path, tuning: Tuning) -> Path:
    """Replace the scene's ``[run]`` table by the choice (its ``stop``, ``outputs`` and
    ``interval`` kept; ``[run.ecco]`` replaced by an ECCO choice's, else removed) and set the ``method``/``order`` of each coupling the choice
    gives an order, in its ``[[couplings]]`` table; the rest of the file untouched.  The file
    is checked to load before it is replaced."""
    from .scene import load_scene
    path = Path(scene_path)
    lines = path.read_text().splitlines(keepends=True)
    import json
    run = load_scene(path).run
    # what the run writes is no run knob: kept
    block = tuning.run_block(stop=run["stop"], keep=[f"{k} = {json.dumps(run[k])}" for k in ("outputs", "interval")
                                                     if run.get(k) is not None])
    setting = tuning.choice.setting
    heads = [i for i, line in enumerate(lines) if COUPLING.match(line)]
    for i, n in sorted(setting.orders, reverse=True):   # from the end: the earlier heads stay put
        h = heads[i]
        end = _table_end(lines, h)
        rest = [line for line in lines[h + 1:end] if not re.match(r"^\s*(method|order|tolerance)\s*=", line)]
        lines[h + 1:end] = ['method = "state_space"   # hydrofmu tune\n', f"order = {n}\n"] + rest
    e = next((i for i, line in enumerate(lines) if RUN_ECCO.match(line)), None)
    if e is not None:   # ECCO settings are the choice's (as the tune ran them), or none
        del lines[e:_table_end(lines, e)]
    start = next((i for i, line in enumerate(lines) if RUN_TABLE.match(line)), None)
    if start is None:
        first = next((i for i, line in enumerate(lines) if TABLE.match(line) and not line.strip().startswith("[scene")
                      and not line.strip().startswith("[environment")), len(lines))
        new = lines[:first] + [block + "\n"] + lines[first:]
    else:
        end = _table_end(lines, start)
        trailing = [line for line in lines[start + 1:end] if not line.strip()]
        new = lines[:start] + [block] + (["\n"] if trailing else []) + lines[end:]
    tmp = path.with_name(f".{path.name}.tune")
    tmp.write_text("".join(new))
    try:
        load_scene(tmp)
    except InputError:
        tmp.unlink()
        raise
    tmp.replace(path)
    return path
