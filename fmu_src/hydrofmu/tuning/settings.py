"""What ``hydrofmu tune`` searches: the ladders of steps, holds, algorithms and memory
evaluators, one combination of knobs (``Setting``) and one run of it (``Point``)."""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

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
    confirmed: float | None = None   # error over the confirmation run (None: not confirmed)
    drift: float | None = None       # the last quarter's error (the drift check)
