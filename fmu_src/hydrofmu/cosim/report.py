"""Plots of a run: per body, its wave elevation, each dof of its motion from the initial pose
and each load component with every effect on it (one colour per effect in the whole
figure); per joint, its gap, relative rotation and force; the response spectra.

Data choices, kept in plain functions (tested on synthetic series):
- motion is shown relative to the initial pose (`relative_motion`): a body moored at
  x = 100 m moves by metres, which an absolute axis from 0 to 100 m hides;
- a long record is its whole-run min–max envelope (every sample) under its mean and slow
  part, beside its last peak periods (`plot`); each quantity on its own axis, the small loads
  of a component on one of their own (`by_scale`), negligible ones named, not drawn
  (`negligible`);
- load axes follow the settled part of the run (`robust_limits`): a start transient many
  times larger than the rest is clipped, and the panel says so and gives its range.
"""
from pathlib import Path

import numpy as np

TOTAL = "total"


def relative_motion(position, attitude):
    """Translation [m] and rotation [rad] from the first sample.

    Parameters
    ----------
    position : (n, 3) array
        Reference-point position, global axes [m].
    attitude : (n, 3) array
        Roll, pitch, yaw [rad]; unwrapped in time first, so a yaw going through ±π
        gives a continuous rotation.

    Returns
    -------
    (n, 3) array, (n, 3) array
        ``position - position[0]`` and ``unwrap(attitude) - attitude[0]``.
    """
    position, attitude = np.asarray(position, float), np.asarray(attitude, float)
    return position - position[0], np.unwrap(attitude, axis=0) - attitude[0]


def robust_limits(t, series, settle=5.0, q=1.0, factor=3.0, pad=0.1):
    """Axis limits that a start transient does not set.

    The spread of the settled run is the ``q``..``100 - q`` percentile range of every series
    after the first ``settle`` seconds (at most the first 10 % of the run).  If the whole data span is more than ``factor``
    times that spread, the limits are the spread widened by ``pad`` of it on each side and
    the data are clipped; otherwise the limits are the whole data span widened by ``pad``.

    Parameters
    ----------
    t : (n,) array
        Times [s].
    series : sequence of (n,) arrays
        The curves of one panel.
    settle, q, factor, pad : float
        Start skipped [s], percentile [%], clipping threshold and padding (fractions of
        the span).

    Returns
    -------
    lo, hi : float
        Axis limits.
    clipped : tuple or None
        ``(min, max)`` of all data when they exceed the limits, else None.
    """
    t = np.asarray(t, float)
    data = np.array([np.asarray(s, float) for s in series])
    data = data.reshape(len(data), -1)
    finite = np.isfinite(data)
    if not finite.any():
        return -1.0, 1.0, None
    lo_all, hi_all = float(data[finite].min()), float(data[finite].max())
    late = data[:, t >= t[0] + min(settle, 0.1 * (t[-1] - t[0]))]
    late = late[np.isfinite(late)]
    lo, hi = (np.percentile(late, [q, 100 - q]) if late.size else (lo_all, hi_all))
    clip = hi_all - lo_all > factor * (hi - lo)
    if not clip:
        lo, hi = lo_all, hi_all
    width = hi - lo
    margin = pad * width if width > 0 else (0.1 * abs(hi) or 1.0)   # a flat line: ±10 %, or ±1 at 0
    lo, hi = float(lo - margin), float(hi + margin)
    return lo, hi, ((lo_all, hi_all) if clip and (lo_all < lo or hi_all > hi) else None)


def effect_colours(names):
    """One colour per effect name, the same in every panel: ``total`` black, the others
    from matplotlib's tab10 cycle in sorted order."""
    palette = ["C0", "C1", "C2", "C3", "C4", "C5", "C6", "C8", "C9", "C7"]
    others = sorted(set(names) - {TOTAL})
    out = {name: palette[i % len(palette)] for i, name in enumerate(others)}
    out[TOTAL] = "black"
    return out


def joint_sides(manifest):
    """Joint instance -> (body A, body B or None for the earth), from the manifest's
    connections (side B's motion comes from B's dynamics)."""
    by_dyn = {(inst, prefix): body for body, (inst, prefix) in manifest["dynamics"].items()}
    sides = {}
    for name, inst in manifest["instances"].items():
        if inst["kind"] != "joint":
            continue
        b = None
        for src, svar, dst, dvar in manifest["connections"]:
            if dst == name and dvar.startswith("B.position"):
                prefix = svar[:len(svar) - len("position[1]")]
                b = by_dyn.get((src, prefix))
        sides[name] = (inst["body"], b)
    return sides


def load_sources(result, manifest, body):
    """Effect name -> (instance, variable) of every 6-component load on ``body`` that
    ``result`` recorded (``result.vector(instance, variable, 6)``, global axes, about its
    reference point [N, N·m]): each effect and coupling of its load FMU, each joint's force on it."""
    cols = set(result.columns)
    out = {}
    for name, inst in manifest["instances"].items():
        if inst["kind"] == "load" and inst["body"] == body:
            groups = sorted({c[len(name) + 1:-len(".force[1]")] for c in cols
                             if c.startswith(f"{name}.") and c.endswith(".force[1]")})
            for g in filter(None, groups):   # "" is the load FMU's own total
                out[g] = (name, f"{g}.force")
    for joint, (a, b) in joint_sides(manifest).items():
        for side, who in (("A", a), ("B", b)):
            if who == body and f"{joint}.{side}.force[1]" in cols:
                out[joint] = (joint, f"{side}.force")
    return out


def body_loads(result, manifest, body):
    """Effect name -> (n, 6) load on ``body`` [N, N·m] (global axes, about its reference
    point): every load of `load_sources` and ``total`` (their sum)."""
    loads = {e: result.vector(inst, name, 6) for e, (inst, name) in load_sources(result, manifest, body).items()}
    if loads:
        loads[TOTAL] = sum(loads.values())
    return loads


DOF_COLOURS = ("#1b9e77", "#d95f02", "#7570b3")   # motion panels: x / roll, y / pitch, z / yaw (not effect colours)
ELEVATION = "#3b75af"               # the wave elevation at the body
BINS = 500                # a long record's whole-run panel: the min–max envelope in this many bins
WINDOW_PERIODS = 8        # its window panel: the last 8 peak periods of the sea, every sample
LONG_PERIODS = 40         # a record longer than 40 peak periods plots as envelope + window
SHORT_ROWS = 8000         # a short record's line: at most this many samples (every k-th)
SMALL = 0.05              # loads under 5 % of a panel's largest get a panel of their own scale
NEGLIGIBLE = 1e-3         # a dof or load at most 0.1 % of the body's largest of its kind is listed, not drawn
FLOOR = 1e-9              # ... as is one at most 1e-9 (m, deg, kN, kN·m) whatever the others
DOFS = (("surge x", "sway y", "heave z"), ("roll", "pitch", "yaw"))
LOAD_NAMES = ("Fx", "Fy", "Fz", "Mx", "My", "Mz")


def time_axis(t):
    """(times in the plot's unit, its label): seconds up to 15 minutes, minutes up to 3 hours,
    then hours (a 30-minute record reads 0–30 min, not 0–1800 s)."""
    t = np.asarray(t, float)
    span = float(t[-1] - t[0]) if t.size else 0.0
    if span > 3 * 3600:
        return t / 3600, "time [h]"
    if span > 900:
        return t / 60, "time [min]"
    return t, "time [s]"


def negligible(peak, scale):
    """True when a curve's largest |value| ``peak`` is at most ``NEGLIGIBLE`` of ``scale``
    (the body's largest of the same kind) or at most ``FLOOR``: drawn on its own axis it
    would magnify numerical noise into a signal (a round body's 6e-4 kN·m yaw moment beside
    300 kN·m of pitch, a 0.002° yaw beside 13° of pitch)."""
    return not peak > max(NEGLIGIBLE * scale, FLOOR)


def by_scale(curves, ratio=SMALL):
    """(large, small): the curves [(label, colour, values, band)] whose largest |value| is at
    least ``ratio`` of the largest one's (and ``total``), and the others, which get their own
    axis (a 0.26 kN drift force beside ±100 kN of wave load)."""
    peak = {c[0]: float(np.nanmax(np.abs(c[2]))) for c in curves}
    top = max(peak.values(), default=0.0)
    large = [c for c in curves if c[0] == TOTAL or peak[c[0]] >= ratio * top]
    return large, [c for c in curves if c not in large]


class Block:
    """One quantity of the figure: its curves [(label, colour, values in the plot's unit,
    band)] over the run; ``band``: its min–max envelope is drawn in a long record's
    whole-run panel (else only its mean + LF line); ``stats``: a single motion-like curve,
    its figures written in the panel and its axis never clipped."""

    def __init__(self, title, unit, curves, stats=False):
        self.title, self.unit, self.curves, self.stats = title, unit, curves, stats


def _envelope(t, x, bins):
    """(t, lo, hi) of ``x`` in ``bins`` equal bins: the whole record's min and max in each."""
    edges = np.linspace(0, x.size, min(bins, x.size) + 1).astype(int)[:-1]
    return t[edges], np.minimum.reduceat(x, edges), np.maximum.reduceat(x, edges)


def _stride(x, rows):
    return x[::max(1, -(-x.size // rows))]


def _whole(ax, t, block, split, long):
    """The whole run: every sample as a line (a short record), or each curve's min–max
    envelope (``band`` curves) under its mean (dashed) and mean + LF part (a long one).
    The axis follows the settled run (`robust_limits`)."""
    from .statistics import parts
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    scale = time_axis(t)[0][-1] / t[-1] if t.size and t[-1] else 1.0   # seconds -> the axis' unit
    drawn = []   # (t [s], values) of every line and envelope edge: what the axis must show
    for name, colour, x, band in block.curves:
        if not long:
            ts, xs = _stride(t, SHORT_ROWS), _stride(x, SHORT_ROWS)
            ax.plot(ts * scale, xs, color=colour, lw=1.0, label=name)
            drawn.append((ts, xs))
            continue
        if band:
            te, lo, hi = _envelope(t, x, BINS)
            ax.fill_between(te * scale, lo, hi, step="post", color=colour, alpha=0.25 if name != TOTAL else 0.18, lw=0)
            drawn += [(te, lo), (te, hi)]
        mean, low, _ = parts(x, dt, split)
        inner = (t >= t[0] + (split or 0)) & (t <= t[-1] - (split or 0))   # a split period from each end: the
        ts, slow = _stride(t[inner], 4 * BINS), _stride(mean + low[inner], 4 * BINS)   # filter sees one side only
        ax.plot(ts * scale, slow, color=colour, lw=1.6 if band else 1.2, label=name)
        ax.axhline(mean, color=colour, lw=0.8, ls="--", alpha=0.8)
        drawn.append((ts, slow))
    grid = np.linspace(t[0], t[-1], 2 * BINS) if t.size else t
    # loads: a start transient does not set the axis; motion: its largest value is the news
    lo, hi, clipped = robust_limits(grid, [np.interp(grid, ts, y) for ts, y in drawn], factor=3.0 if not block.stats
                                    else np.inf)
    ax.set_ylim(lo, hi)
    title = block.title
    if clipped:
        title += f"\naxis clipped to the settled run; data span {clipped[0]:.3g} … {clipped[1]:.3g}"
    ax.set_title(title, fontsize=9, loc="left")
    ax.set_xlabel(time_axis(t)[1], fontsize=8)
    ax.set_ylabel(f"[{block.unit}]", fontsize=8)


def _window(ax, t, block, seconds):
    """The last ``seconds`` of the run, every sample of every curve."""
    keep = t >= t[-1] - seconds
    for name, colour, x, _ in block.curves:
        ax.plot(t[keep], x[keep], color=colour, lw=1.0)
    ax.set_title(f"last {seconds:g} s", fontsize=9, loc="left")
    ax.set_xlabel("time [s]", fontsize=8)


def _stats_text(ax, x, dt, split, unit):
    from .statistics import describe
    d = describe(x, dt, split)
    parts = [f"mean {d['mean']:.3g}"] + ([f"LF σ {d['lf_std']:.3g}", f"WF σ {d['wf_std']:.3g}"] if split
                                         else [f"σ {d['std']:.3g}"])
    if np.isfinite(d["mpm_min"]) and np.isfinite(d["mpm_max"]):   # a record of too few peaks has none
        parts += [f"MPM {d['mpm_min']:.3g} … {d['mpm_max']:.3g}"]
    parts[-1] += f" {unit}"
    ax.text(0.01, 0.97, ", ".join(parts), transform=ax.transAxes, va="top", ha="left", fontsize=7.5,
            bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="0.8", alpha=0.85))


def wave_elevation(result, manifest, body):
    """The wave elevation [m] at ``body``'s mean position (its load FMU's ``waves.elevation``),
    or None when the scene has no waves acting on it."""
    for name, inst in manifest["instances"].items():
        if inst["kind"] == "load" and inst["body"] == body and f"{name}.waves.elevation" in result:
            return result[f"{name}.waves.elevation"]
    return None


def flavour(manifest):
    """'Python' or 'compiled': the FMUs' flavour a built folder holds (None when its manifest
    predates the record)."""
    return {"python": "Python", "c": "compiled"}.get((manifest or {}).get("flavour"))


def blocks(result, manifest):
    """(blocks, not drawn): the figure's `Block` per body — wave elevation at the body, each
    dof of its motion from the initial pose (translation [m], rotation [deg]), each load
    component [kN, kN·m] (its effects, the smaller ones on an axis of their own) — and per
    joint its gap [mm], rotation [deg] and force on side A [kN]; and the lines naming what
    is negligible (`negligible`) and so left out."""
    sides = joint_sides(manifest)
    colours = effect_colours({e for b in manifest["dynamics"] for e in load_sources(result, manifest, b)} | set(sides))
    out, left = [], []
    for body in sorted(manifest["dynamics"]):
        eta = wave_elevation(result, manifest, body)
        if eta is not None:
            out.append(Block(f"{body}: wave elevation η at the body", "m", [("η", ELEVATION, np.asarray(eta, float), True)],
                             stats=True))
        pos, att = result.motion(body, "position", 3), result.motion(body, "attitude", 3)
        dpos, datt = relative_motion(pos, att)
        motion = ((dpos, "m", pos[0], "{:.4g}"), (np.degrees(datt), "deg", np.degrees(att[0]), "{:.3g}"))
        skipped = []
        for k, (values, unit, start, fmt) in enumerate(motion):
            scale = float(np.nanmax(np.abs(values))) if values.size else 0.0
            for i in range(3):
                peak = float(np.nanmax(np.abs(values[:, i]))) if values.size else 0.0
                if negligible(peak, scale):
                    skipped.append(f"{DOFS[k][i]} ≤ {peak:.2g} {unit}")
                    continue
                out.append(Block(f"{body}: {DOFS[k][i]} from {fmt.format(start[i])} {unit}", unit,
                                 [(DOFS[k][i].split()[0], DOF_COLOURS[i], values[:, i], True)], stats=True))
        sources = load_sources(result, manifest, body)
        for first, unit in ((0, "kN"), (3, "kN·m")):   # forces, then moments: each kind its own scale
            comps = {}
            for i in range(first, first + 3):
                loads = {e: result[f"{inst}.{name}[{i + 1}]"] / 1e3 for e, (inst, name) in sources.items()}
                if loads:
                    loads[TOTAL] = sum(loads.values())
                comps[i] = loads
            scale = max((float(np.nanmax(np.abs(x))) for loads in comps.values() for x in loads.values()), default=0.0)
            for i, loads in comps.items():
                peaks = {e: float(np.nanmax(np.abs(x))) for e, x in loads.items()}
                if not loads:
                    continue
                if all(negligible(p, scale) for p in peaks.values()):
                    skipped.append(f"{LOAD_NAMES[i]} ≤ {max(peaks.values()):.2g} {unit}")
                    continue
                curves = [(e, colours[e], x, e == TOTAL) for e, x in loads.items() if not negligible(peaks[e], scale)]
                skipped += [f"{LOAD_NAMES[i]} of {e} ≤ {p:.2g} {unit}" for e, p in peaks.items()
                            if negligible(p, scale)]
                large, rest = by_scale(curves)
                out.append(Block(f"{body}: {LOAD_NAMES[i]}", unit, large))
                if rest:   # one curve alone on its axis: its envelope too
                    rest = [(e, c, x, len(rest) == 1) for e, c, x, _ in rest]
                    out.append(Block(f"{body}: {LOAD_NAMES[i]}, the smaller loads on their own scale", unit, rest))
        if skipped:
            left.append(f"{body}: " + ", ".join(skipped))
    for joint, (a, b) in sorted(sides.items()):
        gap = result.vector(joint, "gap", 3) * 1e3
        rot = np.degrees(result.vector(joint, "rotation", 3))
        force = result.vector(joint, "A.force", 6) / 1e3
        between = f"{a}–{b or 'earth'}"
        for what, unit, values in (("gap", "mm", gap), ("rotation about A's axes", "deg", rot),
                                   (f"force on {a}", "kN", force[:, :3])):
            out.append(Block(f"joint {joint} ({between}): {what}", unit,
                             [("xyz"[i], DOF_COLOURS[i], values[:, i], True) for i in range(3)]))
    return out, left


def plot(result, manifest, path, split=None):
    """Write a PNG of a run: one panel per `blocks` quantity, three to a row (a long record: a
    pair of panels per quantity, two pairs to a row).

    A record longer than ``LONG_PERIODS`` peak periods of the scene's sea draws, per quantity,
    the whole run as each curve's min–max envelope (every sample counted, in ``BINS`` bins)
    under its mean (dashed) and its mean + low-frequency part (split at ``split`` [s], default
    as ``Result.summary``), and beside it the last ``WINDOW_PERIODS`` peak periods at every
    sample; a shorter record draws every sample.  Motion is from the initial pose (translation
    [m], rotation [deg]), each dof on its own axis with its mean, LF and WF std and expected
    extremes written in it; loads [kN, kN·m] per component, colour = effect (the same in every
    panel, ``total`` black), the loads under ``SMALL`` of a panel's largest on an axis of their
    own; dofs and loads that are `negligible` are named below the panels instead of drawn.
    The time axis is in minutes past 15 minutes of record, in hours past 3 hours.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from .summary import split_period

    t = np.asarray(result.time, float)
    sea = (manifest.get("run") or {}).get("waves") or {}
    tp = sea.get("period")
    period = split_period(manifest, split)["period"]
    long = bool(tp) and t.size > 1 and t[-1] - t[0] > LONG_PERIODS * tp
    window = WINDOW_PERIODS * tp if long else None
    dt = float(t[1] - t[0]) if t.size > 1 else 1.0
    items, left = blocks(result, manifest)
    per_row = 2 if long else 3   # a long record's quantities take two panels each
    rows = max(1, -(-len(items) // per_row))
    width = [2.3, 1.0] * per_row if long else [1.0] * per_row
    fig = plt.figure(figsize=(16, (2.5 if long else 2.8) * rows + 1.3 + 0.18 * len(left)))
    grid = fig.add_gridspec(rows, len(width), width_ratios=width, hspace=0.7 if long else 0.55, wspace=0.28)
    for k, block in enumerate(items):
        r, c = divmod(k, per_row)
        ax = fig.add_subplot(grid[r, c * (2 if long else 1)])
        _whole(ax, t, block, period, long)
        if block.stats:
            _stats_text(ax, block.curves[0][2], dt, period, block.unit)
        else:
            ax.legend(fontsize=7, loc="upper right", ncol=min(len(block.curves), 4), framealpha=0.7, handlelength=1.5)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=8)
        if long:
            win = fig.add_subplot(grid[r, c * 2 + 1], sharey=ax)
            _window(win, t, block, window)
            win.grid(True, alpha=0.3)
            win.tick_params(labelsize=8, labelleft=False)
    kind = flavour(manifest)
    how = (f"; LF/WF split at {period:g} s" if period else "")
    fig.suptitle(f"{manifest['scene']} ({kind + ' flavour, ' if kind else ''}{result.algorithm}, "
                 f"step {result.step:g} s{how}): motion from the initial pose and loads on each body, "
                 "global axes, moments about its reference point"
                 + ("\nleft: the whole run, min–max envelope (every sample), mean (dashed) and mean + LF part; "
                    f"right: the last {WINDOW_PERIODS} peak periods" if long else ""),
                 fontsize=11, y=1 - 0.1 / fig.get_figheight())
    if left:
        fig.text(0.01, 0.1 / fig.get_figheight(), "not drawn (at most 0.1 % of the body's largest of its kind, "
                 "or 1e-9): " + "; ".join(left), fontsize=8, color="0.3", wrap=True)
    fig.subplots_adjust(left=0.05, right=0.99, top=1 - (1.0 if long else 0.75) / fig.get_figheight(),
                        bottom=(0.6 + 0.18 * len(left)) / fig.get_figheight())
    fig.savefig(Path(path), dpi=100)
    plt.close(fig)


def plot_spectra(summary, manifest, path):
    """Write a PNG of the response spectra of a `Summary` (Welch, S(ω) [unit²·s/rad], log
    scale): per body its wave elevation and each dof of its motion that is not negligible,
    with the split frequency and the sea's peak marked.  Returns the path, or None when the
    summary holds no spectra."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    spectra = summary.spectra or {}
    if "omega" not in spectra:
        return None
    omega = spectra["omega"]
    rows = [r for r in summary.rows if r["quantity"] in ("elevation", "position", "attitude")
            and (r["body"], r["quantity"], r["dof"]) in spectra]
    scale = {}
    for r in rows:
        scale[(r["body"], r["quantity"])] = max(scale.get((r["body"], r["quantity"]), 0.0), r["std"])
    rows = [r for r in rows if r["std"] > max(NEGLIGIBLE * scale[(r["body"], r["quantity"])], FLOOR)]
    rows.sort(key=lambda r: (r["body"], r["quantity"] != "elevation"))   # per body: the sea first
    if not rows:
        return None
    sea = (manifest.get("run") or {}).get("waves") or {}
    period = (summary.split or {}).get("period")
    cols = 3
    n = -(-len(rows) // cols)
    fig, axes = plt.subplots(n, cols, figsize=(15, 3.2 * n + 0.6), squeeze=False)
    top = 4 * (2 * np.pi / sea["period"]) if sea.get("period") else omega[-1]
    for ax, r in zip(axes.flat, rows):
        s = spectra[(r["body"], r["quantity"], r["dof"])]
        deg = r["unit"] == "rad"
        s = s * (180 / np.pi) ** 2 if deg else s
        unit = "deg" if deg else r["unit"]
        keep = (omega > 0) & (omega <= top)
        ax.semilogy(omega[keep], s[keep], color="black", lw=1.0)
        peak = float(s[keep].max()) if keep.any() and s[keep].max() > 0 else 1.0
        ax.set_ylim(peak * 1e-5, peak * 3)
        if period:
            ax.axvline(2 * np.pi / period, color="C3", ls="--", lw=1, label=f"split {period:g} s")
        if sea.get("period"):
            ax.axvline(2 * np.pi / sea["period"], color="C0", ls=":", lw=1, label=f"sea peak Tp {sea['period']:g} s")
        names = {"elevation": {"eta": "wave elevation η"}, "position": dict(zip("xyz", DOFS[0])),
                 "attitude": dict(zip(("roll", "pitch", "yaw"), DOFS[1]))}
        what = names[r["quantity"]][r["dof"]]
        ax.set_title(f"{r['body']}: {what}", fontsize=9, loc="left")
        ax.set_xlabel("ω [rad/s]", fontsize=8)
        ax.set_ylabel(f"S(ω) [{unit}²·s/rad]", fontsize=8)
        ax.grid(True, alpha=0.3)
        ax.tick_params(labelsize=8)
        if period or sea.get("period"):
            ax.legend(fontsize=7, loc="upper right")
    for ax in list(axes.flat)[len(rows):]:
        ax.set_visible(False)
    fig.suptitle(f"{summary.scene}: response spectra (Welch, t = {summary.start:g}–{summary.stop:g} s; "
                 "one-sided, ∫S dω = variance)", fontsize=11, y=1 - 0.12 / fig.get_figheight())
    fig.subplots_adjust(left=0.06, right=0.99, bottom=0.55 / fig.get_figheight(), top=1 - 0.6 / fig.get_figheight(),
                        hspace=0.55, wspace=0.25)
    fig.savefig(Path(path), dpi=100)
    plt.close(fig)
    return Path(path)


# label offsets [points] tried in turn: right above, right below, left above, left below, farther out
OFFSETS = [(5, 3), (5, -10), (-5, 3), (-5, -10), (5, 12), (5, -19), (-5, 12), (-5, -19), (5, 21), (5, -28),
           (-5, 21), (-5, -28)]


def annotate_apart(ax, xs, ys, labels, fontsize=7, avoid=()):
    """Label points so that no label covers another label, a point or an artist of
    ``avoid`` (texts, legends): each label takes the
    first offset of ``OFFSETS`` whose box is free and inside the axes (else the first one,
    with a leader line).  Call after the axes' scales, limits and layout are final.
    Returns the annotations."""
    fig = ax.figure
    fig.canvas.draw()
    renderer = fig.canvas.get_renderer()
    frame = ax.get_window_extent(renderer)
    points = ax.transData.transform(np.column_stack([xs, ys]))
    r = 4 * fig.dpi / 72   # marker half-size [px]
    from matplotlib.transforms import Bbox
    taken = [Bbox([[px - r, py - r], [px + r, py + r]]) for px, py in points]
    taken += [a.get_window_extent(renderer) for a in avoid]
    placed = []
    for x, y, label in zip(xs, ys, labels):
        for i, (dx, dy) in enumerate(OFFSETS + [OFFSETS[0]]):
            last = i == len(OFFSETS)
            ann = ax.annotate(label, (x, y), xytext=(dx, dy), textcoords="offset points", fontsize=fontsize,
                              ha="left" if dx > 0 else "right",
                              arrowprops=dict(arrowstyle="-", color="0.5", lw=0.5) if last else None)
            box = ann.get_window_extent(renderer)
            free = (frame.contains(box.x0, box.y0) and frame.contains(box.x1, box.y1)
                    and not any(box.overlaps(b) for b in taken))
            if free or last:
                break
            ann.remove()
        taken.append(box)
        placed.append(ann)
    return placed


def plain_log_ticks(ax):
    """Log axes labelled with plain numbers (0.2, 0.5, 1, 2 …), not 2×10⁻¹."""
    from matplotlib.ticker import FormatStrFormatter, LogLocator
    for axis, scale in ((ax.xaxis, ax.get_xscale()), (ax.yaxis, ax.get_yscale())):
        if scale == "log":
            axis.set_major_formatter(FormatStrFormatter("%g"))
            axis.set_minor_locator(LogLocator(subs=(2, 5)))
            axis.set_minor_formatter(FormatStrFormatter("%g"))
