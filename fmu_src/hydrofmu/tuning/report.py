"""What ``hydrofmu tune`` found: ``Tuning`` (the choice, the points, the report and the
``[run]`` block), the Pareto front and the plot of every point."""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable, Sequence

from .settings import ALGORITHMS, ECCO_MIN, HOLDS, MEMORY, Point, Setting


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
    confirm: float | None = None    # length of the confirmation runs [s] (None: not confirmed)
    stop: float | None = None       # the scene's stop [s]
    confirmed: list = field(default_factory=list)   # lines: each candidate's confirmation run

    def holds(self, p) -> bool:
        """Meets the tolerance over the window, and over the confirmation when it was run."""
        return self.feasible(p) and (p.confirmed is None
                                     or max(p.confirmed, p.drift or 0.0) + self.uncertainty <= self.tolerance)

    def measured(self) -> str:
        """Over what time the choice's error was measured."""
        c = self.choice
        text = f"{100 * c.error:.3g} % over the first {self.window:g} s"
        if c.confirmed is not None and self.confirm and self.confirm > self.window + 1e-9:
            text += f", {100 * c.confirmed:.3g} % over {self.confirm:g} s"
            if self.stop and self.confirm < self.stop - 1e-9:
                text += f" (its last quarter {100 * c.drift:.3g} %; the stop is {self.stop:g} s)"
        return text

    def run_block(self, stop: float | None = None, keep: Sequence[str] = ()) -> str:
        """The ``[run]`` block of the choice (with ``stop`` when given, and ``[run.ecco]`` for
        an ECCO choice, and the lines ``keep``); per-coupling orders as comments naming the
        ``[[couplings]]`` keys."""
        if self.choice is None:
            raise ValueError("no setting met the tolerance")
        s = self.choice.setting
        lines = [f"# hydrofmu tune: error {self.measured()} <= {100 * self.tolerance:g} %, "
                 f"{self.choice.cost:.3g} s per simulated second",
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
        long = f"{self.confirm:g} s %" if self.confirm else "confirmed %"
        out = [f"{'':<16} {'error %':>8} {long:>10} {'meets':>5} {'cost s/s':>9} {'spread':>7}  settings"]
        for name, p in rows:
            spread = f"{100 * p.spread:.0f} %" if p.spread is not None else "once"
            over = f"{100 * p.confirmed:.3g}" if p.confirmed is not None else "-"
            out.append(f"{name:<16} {100 * p.error:>8.3g} {over:>10} {'yes' if self.holds(p) else 'no':>5} "
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
        if self.confirmed:
            lines += [f"confirmed over {self.confirm:g} s (the scene's stop is {self.stop:g} s), cheapest first:"]
            lines += self.confirmed
        if self.choice is None:
            lines.append("no setting met the tolerance over the window and the confirmation: loosen it, or "
                         "lengthen the window")
        else:
            lines.append(f"choice: {self.choice.setting.label()}; error {self.measured()}")
            cheaper = [p for p in self.points if p is not self.choice and p.source != "search" and self.holds(p)]
            if cheaper:
                best = min(cheaper, key=lambda p: p.cost)
                ratio = best.cost / self.choice.cost
                noisy = self.choice.spread is not None and best.spread is not None and \
                    abs(ratio - 1) < max(self.choice.spread, best.spread)
                lines.append(f"choice vs {best.source}: {ratio:.2f}x cheaper"
                             + (" (within the timing spread: too noisy to call)" if noisy else "")
                             + (f" ({best.source} not confirmed over {self.confirm:g} s)"
                                if best.confirmed is None and self.confirm and self.confirm > self.window else ""))
        lines += ["not tried:"] + [f"  - {n}" for n in self.not_tried]
        return lines


def _short(names, show=6):
    return ", ".join(names[:show]) + (f", … ({len(names) - show} more)" if len(names) > show else "")



def pareto(points):
    """The points no other point beats in both cost and error, cheapest first."""
    return sorted((p for p in points if not any(o.cost < p.cost and o.error < p.error for o in points)),
                  key=lambda p: p.cost)


def plot(tuning: Tuning, path) -> Path:
    """Error against cost of every point run, the Pareto front, the tolerance, the choice and presets."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ..cosim.report import plain_log_ticks
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

