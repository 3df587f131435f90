"""A run in numbers: per body and degree of freedom, the mean, standard deviation, minimum
and maximum of its motion and of each load on it, with units (``Result.summary``).

Statistics over the recorded points with t ≥ ``transient`` (n of them): mean = Σx/n,
std = √(Σ(x − mean)²/n), min, max.  Motion is the dynamics partner's position [m] and
attitude [rad] (global axes, as in the CSV; the plot shows the attitude in deg); loads are
each effect, coupling and joint force on the body and their total [N, N.m] (global axes,
moments about the body's reference point), as `report.body_loads` gathers them.
"""
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

MOTION = {"position": (("x", "y", "z"), ("m",) * 3),
          "attitude": (("roll", "pitch", "yaw"), ("rad",) * 3)}
LOAD = (("Fx", "Fy", "Fz", "Mx", "My", "Mz"), ("N",) * 3 + ("N.m",) * 3)
STATS = ("mean", "std", "min", "max")
_FLAVOURS = {"python": "Python", "c": "compiled"}


@dataclass
class Summary:
    """Statistics of a run; ``rows`` are dicts with body, quantity, dof, unit, mean, std,
    min, max.  ``str(summary)`` is the table ``hydrofmu run`` prints; ``to_json`` writes
    ``<folder>.summary.json``."""
    scene: str
    start: float
    stop: float
    points: int
    rows: list
    notes: list = field(default_factory=list)
    flavour: str = None   # the FMUs that ran: 'python' or 'c' (None: not recorded)

    def to_dict(self) -> dict:
        """Nested: ``bodies[body][quantity][dof] = {unit, mean, std, min, max}``."""
        bodies = {}
        for r in self.rows:
            bodies.setdefault(r["body"], {}).setdefault(r["quantity"], {})[r["dof"]] = {
                k: r[k] for k in ("unit",) + STATS}
        return {"scene": self.scene, "flavour": _FLAVOURS.get(self.flavour), "from": self.start, "to": self.stop,
                "points": self.points,
                "statistics": "over the recorded points with from <= t <= to; std = population (1/n)",
                "notes": self.notes, "bodies": bodies}

    def to_json(self, path) -> Path:
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1, allow_nan=True))
        return path

    def to_pandas(self):
        """A DataFrame, one row per (body, quantity, dof)."""
        import pandas as pd
        return pd.DataFrame(self.rows).set_index(["body", "quantity", "dof"])

    def __str__(self):
        """The table: one line per body, quantity and dof that is not zero throughout (those
        are named in one line per body below the table)."""
        kind = _FLAVOURS.get(self.flavour)
        head = (f"summary of {self.scene or 'the run'}" + (f" ({kind} flavour)" if kind else "")
                + f", t = {self.start:g}–{self.stop:g} s ({self.points} points; "
                f"global axes, moments about each body's reference point, attitude in rad)")
        cells = [("body", "quantity", "dof", "unit") + STATS]
        zero = {}
        for r in self.rows:
            if all(r[k] == 0 for k in STATS):
                zero.setdefault(r["body"], {}).setdefault(r["quantity"], []).append(r["dof"])
                continue
            cells.append((r["body"], r["quantity"], r["dof"], r["unit"])
                         + tuple(f"{r[k] + 0.0:.4g}" for k in STATS))   # + 0.0: no "-0"
        width = [max(len(c[i]) for c in cells) for i in range(len(cells[0]))]
        lines = ["  ".join(c[i].ljust(width[i]) if i < 4 else c[i].rjust(width[i]) for i in range(len(c))).rstrip()
                 for c in cells]
        lines += [f"{body}: zero throughout: " + "; ".join(f"{q} {', '.join(d)}" for q, d in qs.items())
                  for body, qs in zero.items()]
        return "\n".join([head] + lines + self.notes)

    def __repr__(self):
        return (f"Summary({self.scene}: {len({r['body'] for r in self.rows})} bodies, {len(self.rows)} rows, "
                f"t = {self.start:g}–{self.stop:g} s)")


def _row(body, quantity, dof, unit, x):
    x = x[np.isfinite(x)]
    stats = (float(x.mean()), float(x.std()), float(x.min()), float(x.max())) if x.size else (math.nan,) * 4
    return {"body": body, "quantity": quantity, "dof": dof, "unit": unit, **dict(zip(STATS, stats))}


def linear_range(result, manifest) -> list[str]:
    """One line: the largest |roll| and |pitch| of every body over the whole run [deg], and
    whether they stayed within the range the loads assume (rigid_body.LINEAR_RANGE)."""
    from ..physics.rigid_body import LINEAR_RANGE
    worst = []
    for body in sorted(manifest["dynamics"]):
        att = np.abs(result.motion(body, "attitude", 2))
        if att.size:
            worst.append((body, float(np.degrees(np.nanmax(att[:, 0]))), float(np.degrees(np.nanmax(att[:, 1])))))
    if not worst:
        return []
    limit = math.degrees(LINEAR_RANGE)
    out = [f"{b} |roll| ≤ {r:.3g}°, |pitch| ≤ {p:.3g}°" for b, r, p in worst]
    past = [b for b, r, p in worst if max(r, p) > limit]
    return [f"linear range ({limit:g}° roll/pitch, docs/running.md): " + "; ".join(out)
            + (f": {', '.join(past)} left it (linear_range = false)" if past else ": within it")]


def summarize(result, transient=0.0) -> Summary:
    """The `Summary` of a Result over t ≥ ``transient`` [s]."""
    from .report import body_loads
    if not (math.isfinite(transient) and transient >= 0):
        raise ValueError(f"transient must be a finite time ≥ 0 [s], found {transient!r}")
    keep = result.time >= result.time[0] + transient if len(result.time) else np.zeros(0, bool)
    if len(result.time) and not keep.any():
        raise ValueError(f"transient {transient:g} s leaves no point: the run ends at {result.time[-1]:g} s")
    manifest, notes = result.layout()
    rows = []
    for body in sorted(manifest["dynamics"]):
        for quantity, (dofs, units) in MOTION.items():
            values = result.motion(body, quantity, 3)[keep]
            rows += [_row(body, quantity, d, u, values[:, i]) for i, (d, u) in enumerate(zip(dofs, units))]
        for effect, load in body_loads(result, manifest, body).items():
            rows += [_row(body, effect, d, u, load[keep, i]) for i, (d, u) in enumerate(zip(*LOAD))]
    notes = list(notes) + linear_range(result, manifest)
    t = result.time[keep]
    return Summary(manifest.get("scene", ""), float(t[0]) if t.size else 0.0, float(t[-1]) if t.size else 0.0,
                   int(t.size), rows, notes, manifest.get("flavour"))
