"""A run in numbers: per body and degree of freedom, the statistics of its motion and of each
load on it, with units (``Result.summary``), and their response spectra.

Every figure is computed over the whole record of the points with t ≥ ``transient`` (n of
them), one column at a time: a run streamed to a file (``cosim.stream.FileResult``) reads each
column back whole, so its figures are those of the same run held in memory.  Per row:
mean = Σx/n, std = √(Σ(x − mean)²/n), min, max, and the analyst's figures of
``cosim.statistics`` (the low- and wave-frequency parts split at a period, their std, the
expected extremes of the record, each with its method named in ``statistics.METHODS``).
Motion is the dynamics partner's position [m] and attitude [rad] (global axes, as in the
CSV; the plot shows the attitude in deg), the wave elevation η [m] at the body's mean
position when the scene has waves; loads are each effect, coupling and joint force on
the body and their total [N, N.m] (global axes, moments about the body's reference point), as
`report.load_sources` names them.
"""
import csv
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import statistics

MOTION = {"position": (("x", "y", "z"), ("m",) * 3),
          "attitude": (("roll", "pitch", "yaw"), ("rad",) * 3)}
LOAD = (("Fx", "Fy", "Fz", "Mx", "My", "Mz"), ("N",) * 3 + ("N.m",) * 3)
STATS = ("mean", "std", "min", "max")
ANALYST = ("lf_std", "wf_std", "wf_tz", "wf_mpm", "lf_mpm", "mpm_max", "mpm_min")
COUNTS = ("lf_peaks", "peaks")
# the analyst's table: column heads of ANALYST
HEADS = ("LF std", "WF std", "WF Tz [s]", "WF MPM", "LF MPM", "MPM max", "MPM min")
_FLAVOURS = {"python": "Python", "c": "compiled"}


@dataclass
class Summary:
    """Statistics of a run; ``rows`` are dicts with body, quantity, dof, unit, the figures of
    ``STATS`` and ``ANALYST`` and the peak counts of ``COUNTS``.  ``str(summary)`` is the
    table ``hydrofmu run`` prints; ``to_json`` writes ``<folder>.summary.json``;
    ``spectra`` ({'omega': ω [rad/s], (body, quantity, dof): S(ω)}) and ``write_spectra``
    the response spectra."""
    scene: str
    start: float
    stop: float
    points: int
    rows: list
    notes: list = field(default_factory=list)
    flavour: str = None   # the FMUs that ran: 'python' or 'c' (None: not recorded)
    split: dict = None    # {'period': s or None, 'from': what chose it}
    spectra: dict = None

    def to_dict(self) -> dict:
        """Nested: ``bodies[body][quantity][dof] = {unit, mean, std, min, max, lf_std, …}``;
        ``split`` and ``methods`` say how the analyst's figures were made (a figure that
        cannot be made is null)."""
        bodies = {}
        for r in self.rows:
            bodies.setdefault(r["body"], {}).setdefault(r["quantity"], {})[r["dof"]] = {
                k: _plain(r[k]) for k in ("unit",) + STATS + ANALYST + COUNTS}
        return {"scene": self.scene, "flavour": _FLAVOURS.get(self.flavour), "from": self.start, "to": self.stop,
                "points": self.points,
                "statistics": "over the recorded points with from <= t <= to; std = population (1/n)",
                "split": self.split, "methods": {k: statistics.METHODS[k] for k in STATS + ANALYST},
                "notes": self.notes, "bodies": bodies}

    def to_json(self, path) -> Path:
        path = Path(path)
        path.write_text(json.dumps(self.to_dict(), indent=1))
        return path

    def to_pandas(self):
        """A DataFrame, one row per (body, quantity, dof)."""
        import pandas as pd
        return pd.DataFrame(self.rows).set_index(["body", "quantity", "dof"])

    def row(self, body, quantity, dof) -> dict:
        """The row of one body, quantity ('position', 'attitude', an effect, 'total') and dof."""
        for r in self.rows:
            if (r["body"], r["quantity"], r["dof"]) == (body, quantity, dof):
                return r
        raise KeyError(f"no row {body}/{quantity}/{dof} (rows: "
                       + ", ".join(sorted({f"{r['body']}/{r['quantity']}" for r in self.rows})) + ")")

    def write_spectra(self, path) -> Path:
        """The response spectra as CSV: ``f [Hz]``, ``omega [rad/s]``, then one column
        ``<body>.<quantity>.<dof> [<unit>2.s/rad]`` per row of the summary (S(ω), one-sided,
        ∫S dω = the variance); written whole or not at all."""
        path = Path(path)
        units = {(r["body"], r["quantity"], r["dof"]): r["unit"] for r in self.rows}
        keys = [k for k in self.spectra if k != "omega"]
        omega = self.spectra["omega"]
        tmp = path.with_name(f".{path.name}.tmp")
        try:
            with open(tmp, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow(["f [Hz]", "omega [rad/s]"] + [f"{'.'.join(k)} [{_squared(units[k])}.s/rad]" for k in keys])
                for i, om in enumerate(omega):
                    w.writerow([repr(float(om / (2 * np.pi))), repr(float(om))]
                               + [repr(float(self.spectra[k][i])) for k in keys])
            tmp.replace(path)
        finally:
            tmp.unlink(missing_ok=True)
        return path

    def __str__(self):
        """Two tables, one line per body, quantity and dof that is not zero throughout (those
        are named in one line per body below them): mean, std, min, max; then the LF and WF
        parts and the expected extremes, with the split and the methods said above it."""
        kind = _FLAVOURS.get(self.flavour)
        head = (f"summary of {self.scene or 'the run'}" + (f" ({kind} flavour)" if kind else "")
                + f", t = {self.start:g}–{self.stop:g} s ({self.points} points; "
                f"global axes, moments about each body's reference point, attitude in rad)")
        shown = [r for r in self.rows if not all(r[k] == 0 for k in STATS)]
        zero = {}
        for r in self.rows:
            if r not in shown:
                zero.setdefault(r["body"], {}).setdefault(r["quantity"], []).append(r["dof"])
        period = (self.split or {}).get("period")
        if period:
            lines = [head] + _table(shown, STATS, STATS)
            lines += [f"low-frequency (LF) and wave-frequency (WF) parts split at {period:g} s ({self.split['from']}); "
                      "MPM: the most probable extreme of this record (WF: Rayleigh from its std and zero "
                      "up-crossing period; LF, max, min: Weibull fitted to the peaks; docs/running.md)"]
            lines += _table(shown, ANALYST, HEADS)
        else:   # no LF/WF parts: the extremes beside the other figures
            lines = [head, f"no LF/WF split ({(self.split or {}).get('from', 'none')}); MPM: the most probable "
                           "extreme of this record, Weibull fitted to the peaks (docs/running.md)"]
            lines += _table(shown, STATS + ("mpm_max", "mpm_min"), STATS + ("MPM max", "MPM min"))
        lines += [f"{body}: zero throughout: " + "; ".join(f"{q} {', '.join(d)}" for q, d in qs.items())
                  for body, qs in zero.items()]
        return "\n".join(lines + self.notes)

    def __repr__(self):
        return (f"Summary({self.scene}: {len({r['body'] for r in self.rows})} bodies, {len(self.rows)} rows, "
                f"t = {self.start:g}–{self.stop:g} s)")


def _table(rows, keys, heads):
    cells = [("body", "quantity", "dof", "unit") + tuple(heads)]
    cells += [(r["body"], r["quantity"], r["dof"], r["unit"]) + tuple(_cell(r[k]) for k in keys) for r in rows]
    width = [max(len(c[i]) for c in cells) for i in range(len(cells[0]))]
    return ["  ".join(c[i].ljust(width[i]) if i < 4 else c[i].rjust(width[i]) for i in range(len(c))).rstrip()
            for c in cells]


def _cell(value):
    return "—" if value is None or not math.isfinite(value) else f"{value + 0.0:.4g}"   # + 0.0: no "-0"


def _plain(value):
    """A JSON value: non-finite numbers as null."""
    return None if isinstance(value, float) and not math.isfinite(value) else value


def _squared(unit):
    return f"{unit}2" if "." not in unit else "(" + unit + ")2"


def split_period(manifest, split=None):
    """The split period [s] of the analyst's figures and what chose it: ``split`` when given,
    else the scene's ``[run] split``, else ``statistics.SPLIT_TP`` × the peak period of its
    sea; {'period': None, …} without any (no LF/WF parts)."""
    if split is not None:
        if isinstance(split, bool) or not isinstance(split, (int, float)) or not (math.isfinite(split) and split > 0):
            raise ValueError(f"split must be a period > 0 [s], found {split!r}")
        return {"period": float(split), "from": "given"}
    run = (manifest or {}).get("run", {})
    if run.get("split"):
        return {"period": float(run["split"]), "from": "[run] split"}
    sea = run.get("waves")
    if sea and sea.get("period"):
        return {"period": statistics.SPLIT_TP * sea["period"],
                "from": f"{statistics.SPLIT_TP:g}·Tp, Tp = {sea['period']:g} s of the scene's sea"}
    return {"period": None, "from": "no sea and no [run] split"}


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


def body_series(result, manifest, body):
    """(quantity, dof, unit, values) of every row of ``body``, each over the whole record, one
    column read at a time (a load's total summed component by component): motion first, the
    wave elevation at the body (``elevation``, ``eta``) when the scene has waves, then each
    load in `report.load_sources`' order and their total."""
    from .report import TOTAL, load_sources, wave_elevation
    for quantity, (dofs, units) in MOTION.items():
        values = result.motion(body, quantity, 3)
        for i, (d, u) in enumerate(zip(dofs, units)):
            yield quantity, d, u, values[:, i]
    eta = wave_elevation(result, manifest, body)
    if eta is not None:
        yield "elevation", "eta", "m", eta
    sources = load_sources(result, manifest, body)
    if not sources:
        return
    by_effect = {e: [] for e in list(sources) + [TOTAL]}
    for i, (d, u) in enumerate(zip(*LOAD)):
        total = 0.0
        for effect, (instance, name) in sources.items():
            x = result[f"{instance}.{name}[{i + 1}]"]
            total = total + x
            by_effect[effect].append((effect, d, u, x))
        by_effect[TOTAL].append((TOTAL, d, u, total))
    for rows in by_effect.values():   # effect by effect, as the table reads
        yield from rows


def summarize(result, transient=0.0, split=None) -> Summary:
    """The `Summary` of a Result over t ≥ ``transient`` [s], split at ``split`` [s]
    (`split_period`: default the scene's [run] split or 2·Tp of its sea)."""
    if not (math.isfinite(transient) and transient >= 0):
        raise ValueError(f"transient must be a finite time ≥ 0 [s], found {transient!r}")
    time = result.time
    keep = time >= time[0] + transient if len(time) else np.zeros(0, bool)
    if len(time) and not keep.any():
        raise ValueError(f"transient {transient:g} s leaves no point: the run ends at {time[-1]:g} s")
    manifest, notes = result.layout()
    how = split_period(manifest, split)
    t = time[keep]
    rows, spectra = [], {}
    uneven = False
    for body in sorted(manifest["dynamics"]):
        for quantity, dof, unit, x in body_series(result, manifest, body):
            dt, xu = statistics.uniform(t, x[keep])
            uneven = uneven or xu.size != t.size
            row = statistics.describe(xu, dt, how["period"])
            rows.append({"body": body, "quantity": quantity, "dof": dof, "unit": unit,
                         **{k: row[k] for k in STATS + ANALYST + COUNTS}})
            if xu.size > 1 and np.isfinite(xu).all():
                omega, s = statistics.spectrum(xu, dt)
                spectra.setdefault("omega", omega)
                spectra[(body, quantity, dof)] = s
    if uneven:
        notes = list(notes) + ["the run's own time points (ECCO) are resampled at their median step for the "
                               "LF/WF parts, the extremes and the spectra"]
    notes = list(notes) + linear_range(result, manifest)
    return Summary(manifest.get("scene", ""), float(t[0]) if t.size else 0.0, float(t[-1]) if t.size else 0.0,
                   int(t.size), rows, notes, manifest.get("flavour"), how, spectra)
