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
3. The presets and the scene's own settings, run the same way, and the final candidates
   re-timed in ``repeats`` interleaved rounds: cost = median seconds of stepping per
   simulated second (initialisation excluded), spread = (max − min) / median.

Error of a run: the largest, over the named outputs (default: every body's position and
attitude), of the RMS difference to the reference at the run's communication points over
the reference's range (max − min): ``√mean((y − y_ref)²) / ptp(y_ref)``; outputs whose range
is below 1e-9 of the largest of the same unit do not move and are left out (listed).  A
point meets the tolerance when error + u ≤ tolerance.

What is searched is what a scene's ``[run]`` block can say: ``step``, ``algorithm``,
``load_hold``, ``substep`` and, for the memory of every coupling, the evaluator of a preset
(``preset = "reference"``: full convolution; ``"design"``: state-space tol 0.01;
``"screening"``: tol 0.05).  Not searched: per-coupling orders and memory lengths, couplings
that set their own ``method`` (kept as they are), and ECCO (libcosim's adaptive step runs
only through the built FMUs; use ``hydrofmu bench --part ecco``).
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


@dataclass(frozen=True)
class Setting:
    """One combination of run knobs; ``memory``: the preset whose memory evaluator every
    coupling uses (None: the scene has no coupling to tune)."""
    step: float
    algorithm: str
    load_hold: str
    substep: float
    memory: str | None

    def label(self) -> str:
        return (f"step {self.step:g} s, {self.algorithm}, {self.load_hold} hold, substep {self.substep:g} s"
                + (f", {MEMORY[self.memory]}" if self.memory else ""))

    def overrides(self, stop: float) -> dict:
        out = {"run.step": self.step, "run.algorithm": self.algorithm, "run.load_hold": self.load_hold,
               "run.substep": self.substep, "run.stop": stop}
        if self.memory:
            out["run.preset"] = self.memory
        return out

    def proxy(self, window: float, instances: int) -> float:
        """Deterministic cost proxy: FMU steps plus the dynamics' Runge–Kutta steps over the window."""
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

    def run_block(self) -> str:
        """The ``[run]`` block of the choice (the scene's ``stop`` kept)."""
        if self.choice is None:
            raise ValueError("no setting met the tolerance")
        s = self.choice.setting
        lines = [f"# hydrofmu tune: error {100 * self.choice.error:.3g} % <= {100 * self.tolerance:g} % "
                 f"over the first {self.window:g} s, {self.choice.cost:.3g} s per simulated second",
                 "[run]"]
        if s.memory:
            lines.append(f'preset = "{s.memory}"   # memory evaluator: {MEMORY[s.memory]}')
        lines += [f"step = {s.step!r}", f'algorithm = "{s.algorithm}"', f'load_hold = "{s.load_hold}"',
                  f"substep = {s.substep!r}"]
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
                 f"searched {sum(p.source == 'search' for p in self.points)} points; {self.equivalence}",
                 self.table()]
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
    """Runs settings of one scene in this process over the window; caches errors."""

    def __init__(self, path, window, outputs, log):
        from .scene import load_scene
        self.path, self.window, self.log = Path(path), window, log
        self.outputs, self.manifest, self.instances = outputs, None, 0

    def run(self, setting: Setting):
        """(times, values of the columns, seconds of stepping)."""
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


def _error(time_, values, ref_time, ref_values, scale):
    idx = np.rint(time_ / (ref_time[1] - ref_time[0])).astype(int)
    ref = ref_values[idx]
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
            points[setting] = Point(setting, err, sec / window, setting.proxy(window, runner.instances), source=source)
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
        for _ in range(max(1, repeats)):
            for p in finalists:
                if math.isfinite(p.error):
                    p.times.append(runner.run(p.setting)[2] / window)
        for p in finalists:
            if not p.times:
                continue
            p.cost = float(np.median(p.times))
            p.spread = float(np.ptp(p.times) / p.cost) if len(p.times) > 1 and p.cost > 0 else None
        choice = min((p for p in finalists if feasible(p)), key=lambda p: (p.cost, p.proxy))
    not_tried = ["ECCO (libcosim's adaptive step runs only through the built FMUs: hydrofmu bench --part ecco)",
                 "per-coupling state-space orders and memory lengths",
                 f"steps outside {', '.join(f'{s:g}' for s in steps)} s (steps must divide the window "
                 f"{window:g} s and the scene's stop {stop:g} s)"]
    if own.couplings and any(c.set for c in own.couplings):
        not_tried.append("the memory of couplings that set their own method (kept)")
    not_tried += [f"pruned: {p}" for p in pruned]
    tuning = Tuning(own.name, tolerance, window, half, u, list(np.array(runner.columns)[moving]), runner.columns, still,
                    list(points.values()), choice, not_tried,
                    "runs in this process (cosim.inprocess: the FMUs' slaves and the fmpy master's loop, "
                    "the same numbers as the built FMUs without the FMI calls; costs are this process's)",
                    feasible)
    if png:
        plot(tuning, png)
    return tuning


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
    marker = {"gauss-seidel": "o", "jacobi": "s"}
    color = {"linear": "C0", "constant": "C1"}
    pts = [p for p in tuning.points if p.cost > 0 and p.error > 0]
    for alg in ALGORITHMS:
        for hold in HOLDS:
            rs = [p for p in pts if p.setting.algorithm == alg and p.setting.load_hold == hold]
            if rs:
                ax.loglog([p.cost for p in rs], [100 * p.error for p in rs], marker[alg], color=color[hold],
                          alpha=0.7, label=f"{alg}, {hold} hold")
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
TABLE = re.compile(r"^\s*\[")


def write_run_block(scene_path, tuning: Tuning) -> Path:
    """Replace the scene's ``[run]`` table (its ``stop`` and ``[run.ecco]`` kept out: stop kept,
    the rest of the file untouched) by the choice; the file is checked to load before it is
    replaced."""
    from .scene import load_scene
    path = Path(scene_path)
    lines = path.read_text().splitlines(keepends=True)
    start = next((i for i, l in enumerate(lines) if RUN_TABLE.match(l)), None)
    block = tuning.run_block()
    stop_line = f"stop = {load_scene(path).run['stop']!r}\n"
    if start is None:
        first = next((i for i, l in enumerate(lines) if TABLE.match(l) and not l.strip().startswith("[scene")
                      and not l.strip().startswith("[environment")), len(lines))
        new = lines[:first] + [block + stop_line + "\n"] + lines[first:]
    else:
        end = next((i for i in range(start + 1, len(lines)) if TABLE.match(lines[i])), len(lines))
        kept = [l for l in lines[start + 1:end] if re.match(r"^\s*stop\s*=", l)]
        trailing = [l for l in lines[start + 1:end] if not l.strip()]
        new = lines[:start] + [block] + (kept or [stop_line]) + (["\n"] if trailing else []) + lines[end:]
    tmp = path.with_name(f".{path.name}.tune")
    tmp.write_text("".join(new))
    try:
        load_scene(tmp)
    except InputError:
        tmp.unlink()
        raise
    tmp.replace(path)
    return path
