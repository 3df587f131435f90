"""Plots of a run: per body, its motion from the initial pose and every load on it (forces
and moments, one colour per effect in the whole figure); per joint, its gap, relative
rotation and force.

Data choices, kept in plain functions (tested on synthetic series):
- motion is shown relative to the initial pose (`relative_motion`): a body moored at
  x = 100 m moves by metres, which an absolute axis from 0 to 100 m hides;
- load axes follow the settled part of the run (`robust_limits`): a start transient many
  times larger than the rest is clipped, and the panel says so and gives its range.
"""
from pathlib import Path

import numpy as np

LINESTYLES = ("-", "--", ":")   # component x / y / z (Fx / Fy / Fz, Mx / My / Mz, roll / pitch / yaw)
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


def body_loads(result, manifest, body):
    """Effect name -> (n, 6) load on ``body`` [N, N·m] (global axes, about its reference
    point): every effect and coupling of its load FMU, each joint's force on it, and
    ``total`` (their sum)."""
    cols = set(result.columns)
    loads = {}
    for name, inst in manifest["instances"].items():
        if inst["kind"] == "load" and inst["body"] == body:
            groups = sorted({c[len(name) + 1:-len(".force[1]")] for c in cols
                             if c.startswith(f"{name}.") and c.endswith(".force[1]")})
            for g in filter(None, groups):   # "" is the load FMU's own total
                loads[g] = result.vector(name, f"{g}.force", 6)
    for joint, (a, b) in joint_sides(manifest).items():
        for side, who in (("A", a), ("B", b)):
            if who == body and f"{joint}.{side}.force[1]" in cols:
                loads[joint] = result.vector(joint, f"{side}.force", 6)
    if loads:
        loads[TOTAL] = sum(loads.values())
    return loads


DOF_COLOURS = ("#1b9e77", "#d95f02", "#7570b3")   # motion panels: x / roll, y / pitch, z / yaw (not effect colours)
ELEVATION = "0.45"                  # the wave elevation at the body, in the translation panel
ROUND_OFF = 1e-9                    # a panel whose values are all below this share of its scale holds round-off only


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


def round_off(curves, scale, floor=0.0):
    """The largest |value| of ``curves`` [(effect, component, values)] when it is no more than
    ``ROUND_OFF`` of ``scale`` (the largest value of the same kind on the body) or than
    ``floor`` (an absolute bound), and not zero: the panel holds round-off only.  Else None."""
    peak = _peak(curves)
    if not np.isfinite(peak) or peak == 0.0:
        return None
    return peak if peak <= max(ROUND_OFF * scale, floor) else None


def _peak(curves):
    """The largest |value| of (effect, component, values) curves (0 when there are none)."""
    return max((float(np.nanmax(np.abs(y))) for _, _, y in curves if np.size(y)), default=0.0)


def _panel(ax, t, curves, title, colours, robust=True, scale=0.0, floor=0.0, unit="", legend=None):
    """Plot (effect or colour, component, values) curves; limits from `robust_limits`.  A panel
    of zeros says "zero throughout"; one whose values are round-off (`round_off` against
    ``scale`` or ``floor``) says so with their size in ``unit`` instead of magnifying them.
    ``legend``: labels of the curves, drawn in the panel."""
    noise = round_off(curves, scale, floor)
    lines = {}
    # a legend's curves drawn widest first: the smaller ones stay on top (roll under pitch hid)
    order = (sorted(range(len(curves)), key=lambda k: -float(np.nanmax(curves[k][2]) - np.nanmin(curves[k][2])))
             if legend is not None and curves and all(np.size(y) for _, _, y in curves) else range(len(curves)))
    for k in order:
        effect, comp, y = curves[k]
        lines[k], = ax.plot(t, y, color=colours.get(effect, effect if effect in DOF_COLOURS + (ELEVATION,) else "black"),
                            ls=LINESTYLES[comp] if legend is None else "-",
                            lw=2.0 if effect == TOTAL else 1.0 if legend is not None else 1.2,
                            label=legend[k] if legend is not None else None)
    ax.grid(True, alpha=0.3)
    if curves and (noise is not None or all(np.all(np.asarray(y) == 0) for _, _, y in curves)):
        # nothing to see: say so instead of an empty ±1 axis or magnified round-off
        ax.set_ylim(-1, 1)
        ax.set_yticks([0])
        ax.text(0.5, 0.62, "zero throughout" if noise is None else
                f"round-off only: |value| ≤ {noise:.2g}{' ' + unit if unit else ''}",
                transform=ax.transAxes, ha="center", va="center", fontsize=9, color="0.35")
    elif curves and robust:
        lo, hi, clipped = robust_limits(t, [y for _, _, y in curves])
        ax.set_ylim(lo, hi)
        if clipped:   # in the title, where it covers no data and no tick label
            title += f"\naxis clipped to the settled run; data span {clipped[0]:.3g} … {clipped[1]:.3g}"
    if legend is not None and curves:
        ax.legend(handles=[lines[k] for k in range(len(curves))], fontsize=7, loc="upper right", ncol=len(curves),
                  framealpha=0.7, handlelength=1.5)
    ax.set_title(title, fontsize=9)


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


def plot(result, manifest, path):
    """Write a PNG of a run.

    Per body two rows: translation from the initial pose [m] (x, y, z one colour each, with
    the wave elevation at the body in grey when the scene has waves), horizontal forces Fx, Fy
    and vertical force Fz [kN]; rotation from the initial pose [deg] (roll, pitch, yaw one
    colour each), yaw moment Mz and roll/pitch moments Mx, My [kN·m] (global axes, about the
    reference point).  Per joint one row: gap [mm], relative rotation [deg], force on side A
    [kN].  In the load panels colour = effect (the same in every panel, ``total`` black) and
    line style = component (x solid, y dashed, z dotted).  A panel of round-off (a moment of
    1e-13 kN·m beside thousands) says so instead of magnifying it; the time axis is in
    minutes past 15 minutes of record, in hours past 3 hours.
    """
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    t, time_label = time_axis(result.time)
    bodies = sorted(manifest["dynamics"])
    sides = joint_sides(manifest)
    loads = {b: body_loads(result, manifest, b) for b in bodies}
    colours = effect_colours({e for ld in loads.values() for e in ld} | set(sides))
    rows = 2 * len(bodies) + len(sides)
    fig, axes = plt.subplots(rows, 3, figsize=(15, 2.9 * rows + 0.9), squeeze=False)
    r = 0
    for body in bodies:
        pos, att = result.motion(body, "position", 3), result.motion(body, "attitude", 3)
        dpos, datt = relative_motion(pos, att)
        x0 = ", ".join(f"{v:g}" for v in pos[0])
        a0 = ", ".join(f"{v:.3g}" for v in np.degrees(att[0]))
        ld = loads[body]
        kn = lambda i: [(e, i % 3, v[:, i] / 1e3) for e, v in ld.items()]
        forces, moments = kn(0) + kn(1) + kn(2), kn(3) + kn(4) + kn(5)
        fscale, mscale = _peak(forces), _peak(moments)
        move = [(DOF_COLOURS[i], i, dpos[:, i]) for i in range(3)]
        labels = ["x", "y", "z"]
        eta = wave_elevation(result, manifest, body)
        if eta is not None:
            move.append((ELEVATION, 0, np.asarray(eta, float)))
            labels.append("η at the body")
        _panel(axes[r, 0], t, move, f"{body}: translation from ({x0}) m"
               + (" and wave elevation η" if eta is not None else "") + " [m]",
               colours, robust=False, floor=1e-9, unit="m", legend=labels)
        _panel(axes[r, 1], t, kn(0) + kn(1), f"{body}: horizontal force Fx, Fy [kN]", colours, scale=fscale,
               unit="kN")
        _panel(axes[r, 2], t, kn(2), f"{body}: vertical force Fz [kN]", colours, scale=fscale, unit="kN")
        _panel(axes[r + 1, 0], t, [(DOF_COLOURS[i], i, np.degrees(datt[:, i])) for i in range(3)],
               f"{body}: rotation from ({a0}) deg [deg; the CSV has rad]", colours, robust=False, floor=1e-9,
               unit="deg", legend=["roll", "pitch", "yaw"])
        _panel(axes[r + 1, 1], t, kn(5), f"{body}: yaw moment Mz [kN·m]", colours, scale=mscale, unit="kN·m")
        _panel(axes[r + 1, 2], t, kn(3) + kn(4), f"{body}: roll, pitch moments Mx, My [kN·m]", colours,
               scale=mscale, unit="kN·m")
        r += 2
    for joint, (a, b) in sorted(sides.items()):
        gap = result.vector(joint, "gap", 3) * 1e3
        rot = np.degrees(result.vector(joint, "rotation", 3))
        force = result.vector(joint, "A.force", 6) / 1e3
        between = f"{a}–{b or 'earth'}"
        _panel(axes[r, 0], t, [(joint, i, gap[:, i]) for i in range(3)],
               f"joint {joint} ({between}): gap x, y, z [mm]", colours)
        _panel(axes[r, 1], t, [(joint, i, rot[:, i]) for i in range(3)],
               f"joint {joint}: relative rotation about A's x, y, z [deg]", colours)
        _panel(axes[r, 2], t, [(joint, i, force[:, i]) for i in range(3)],
               f"joint {joint}: force on {a} Fx, Fy, Fz [kN]", colours)
        r += 1
    for ax in axes[-1]:
        ax.set_xlabel(time_label)
    handles = ([Line2D([], [], color=c, lw=2.0 if e == TOTAL else 1.2, label=e) for e, c in colours.items()]
               + [Line2D([], [], color="0.3", ls=ls, label=lab)
                  for ls, lab in zip(LINESTYLES, ("Fx / Mx", "Fy / My", "Fz / Mz"))])
    fig.legend(handles=handles, loc="upper center", ncol=min(len(handles), 8), fontsize=8, frameon=False,
               bbox_to_anchor=(0.5, 1 - 0.4 / fig.get_figheight()))
    kind = flavour(manifest)
    fig.suptitle(f"{manifest['scene']} ({kind + ' flavour, ' if kind else ''}{result.algorithm}, "
                 f"step {result.step:g} s): loads on each body, "
                 f"global axes, moments about its reference point", fontsize=11, y=1 - 0.1 / fig.get_figheight())
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.6 / fig.get_figheight()))
    fig.savefig(Path(path), dpi=100)
    plt.close(fig)


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
