"""BEM radiation results → hydrodynamic couplings between bodies (the same data a SIMO deck gives).

``couplings`` reads nothing: it takes a ``decks.bem.BemData``, keeps the dofs asked for, runs
``physics.radiation.transform`` once for all bodies together and cuts the result into one
``decks.simo.CouplingData`` per body (self) and per pair of bodies (cross): for bodies P, Q
(P before Q in the file) AM_ij = A∞[(P, i), (Q, j)] and the kernel of block (IDOF_A = i,
IDOF_B = j) is K[(P, i), (Q, j)], i.e. the SIMO element convention with A = P, B = Q.
``write_simo`` writes them as a SIMO deck (BODY DATA groups first), ``plot_quality`` draws A(ω)
and B(ω) rebuilt from (A∞, K) against the database.
"""
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .decks.bem import DOF_NAMES, BemData
from .decks.simo import BODY, CouplingData, format_coupling, write_couplings
from .errors import InputError
from .physics.radiation import SYMMETRY_TOL, TIMDEL_FACTOR, AsymmetryError, GridError, Radiation, transform


@dataclass
class BemCouplings:
    """``couplings``' result: the couplings, the transform behind them, the dofs kept
    [(BEM body, k)] in the transform's order and the names the bodies were given."""
    data: BemData
    couplings: list
    radiation: Radiation
    dofs: list
    names: dict
    checks: list = field(default_factory=list)

    @property
    def labels(self):
        return [label(self.names[b], k) for b, k in self.dofs]

    def report(self):
        """Build-time report lines: the transform's choices, then per coupling the worst rebuilt
        A and B errors (% of each curve's peak, and % of the pair's √(peak_ii·peak_jj)) with their
        dof pair, then warnings."""
        r = self.radiation
        lines = [f"BEM {self.data.kind} {self.data.path}: {len(self.labels)} dofs, {r.omega.size} frequencies "
                 f"{r.omega[0]:g}…{r.omega[-1]:g} rad/s, transform {r.seconds:.2f} s"]
        d = self.data
        env = ", ".join(f"{k} {v:g}" for k, v in (("rho", d.rho), ("g", d.g), ("water depth", d.water_depth))
                        if v is not None)
        centres = [b for b in self.names if b in d.rotation_centers]
        lines.append(f"  {env or 'no rho, g or depth in the file (the scene rho makes it dimensional)'}; "
                     + ("rotation centres (the scene's reference points, checked) "
                        + ", ".join(f"{b} {[float(x) for x in d.rotation_centers[b]]} m" for b in centres)
                        if centres else "rotation centres not in the file: the scene's reference points assumed"))
        lines += [f"  {n}" for n in r.notes]
        if r.asymmetry:
            lines.append(f"  A∞ symmetrised (largest asymmetry {100 * r.asymmetry:.3g} % of √(A_ii·A_jj))")
        for c, rows, cols in self._blocks():
            worst = []
            for e in (r.err_a, r.err_b, r.pair_a, r.pair_b):
                e = e[np.ix_(rows, cols)]
                i, j = np.unravel_index(np.argmax(e), e.shape)
                worst.append(f"{e[i, j]:.3g} % ({self.labels[rows[i]]}, {self.labels[cols[j]]})")
            lines.append(f"  coupling {c.name} ({c.body_a}, {c.body_b}): {len(c.kernels)} kernels; rebuilt A worst "
                         f"{worst[0]}, B worst {worst[1]} of each curve's peak; A {worst[2]}, B {worst[3]} "
                         f"of the pair's √(peak_ii·peak_jj)")
        lines += [f"  WARNING: {w}" for w in self.warnings]
        return lines

    @property
    def warnings(self):
        """What a reviewer would query, legal all the same: the file's (``BemData.warnings``),
        negative radiation damping, a short kernel, the transform's own."""
        return list(self.data.warnings) + self.checks + list(self.radiation.warnings)

    def _blocks(self):
        """(coupling, its rows, its columns in the transform's matrices)."""
        for c in self.couplings:
            rows = [k for k, (b, _) in enumerate(self.dofs) if self.names[b] == c.body_a]
            cols = [k for k, (b, _) in enumerate(self.dofs) if self.names[b] == c.body_b]
            yield c, rows, cols


def label(body, k):
    return f"{body}__{DOF_NAMES[k - 1]}"


def couplings(data, bodies, dofs=None, timdel=None, length=None, symmetry_tol=SYMMETRY_TOL, prefix=None,
              a_inf_from="ogilvie"):
    """Couplings of the BEM bodies mapped in ``bodies`` ({BEM body: name to use}).

    dofs: dof names to keep ("Surge", …; default every dof in the file), each must be in the
    file for every mapped body.  timdel, length [s]: asked kernel spacing and length.
    prefix: coupling names are ``<prefix>_<a>`` (self) and ``<prefix>_<a>_<b>`` (cross), or
    ``<a>`` and ``<a>_<b>`` without one.  a_inf_from: "ogilvie" (A∞ consistent with the
    kernels, the default) or "file" (the file's ω = ∞ value; an error when it has none).
    Raises InputError naming the file and the field.
    """
    path = data.path
    for name, value in (("timdel", timdel), ("kernel_length", length), ("symmetry_tolerance", symmetry_tol)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                  or not math.isfinite(value) or value <= 0):
            raise InputError(path, None, name, f"must be a positive finite number, found {value!r}")
    if symmetry_tol is not None and symmetry_tol >= 1:
        raise InputError(path, None, "symmetry_tolerance", f"{symmetry_tol:g} would accept any matrix (it is "
                                                           "relative to the diagonal): use a value below 1, e.g. 0.01")
    for b in bodies:
        if b not in data.bodies:
            raise InputError(path, None, "body", f"{b!r} is not a body of the result (it has: {', '.join(data.bodies)})")
    want = list(DOF_NAMES) if dofs is None else list(dofs)
    for k, name in enumerate(want):
        if name not in DOF_NAMES:
            raise InputError(path, None, "dofs", f"{name!r} is not a dof name ({', '.join(DOF_NAMES)})")
        if name in want[:k]:
            raise InputError(path, None, "dofs", f"{name!r} given twice")
    keep = []
    for b in data.bodies:
        if b not in bodies:
            continue
        for name in want:
            k = DOF_NAMES.index(name) + 1
            i = data.index(b, k)
            if i is None:
                if dofs is not None:
                    raise InputError(path, None, label(b, k), "missing dof: the scene asks for it, the file has "
                                                              + ", ".join(label(*d) for d in data.dofs if d[0] == b))
                continue
            keep.append(i)
    if a_inf_from == "file" and data.a_inf is None:
        raise InputError(path, None, "a_inf", "a_inf = \"file\" but the file has no infinite-frequency added mass "
                                              "(Capytaine: omega = inf; WAMIT: PER = 0)")
    # the kernels are kept in memory: refuse a length/TIMDEL that could not be (defaults as the transform's)
    w = data.omega
    top = max(length or 0.0, 2 * np.pi / np.max(np.diff(np.concatenate([[0.0], w]))))   # the transform's time grid
    dt = timdel if timdel is not None else np.pi / (TIMDEL_FACTOR * w[-1])
    if top / dt > MAX_KERNEL_SAMPLES:
        raise InputError(path, None, "kernel_length" if length is not None and length >= top else "timdel",
                         f"{top / dt:.3g} kernel samples (length {top:g} s / TIMDEL {dt:g} s): more than "
                         f"{MAX_KERNEL_SAMPLES:.0e}; shorten the kernel or coarsen TIMDEL")
    sel = np.ix_(range(data.omega.size), keep, keep)
    kept = [data.dofs[i] for i in keep]
    try:
        rad = transform(data.omega, data.added_mass[sel], data.damping[sel],
                        None if data.a_inf is None else data.a_inf[np.ix_(keep, keep)],
                        units=[k >= 4 for _, k in kept], timdel=timdel, length=length, symmetry_tol=symmetry_tol,
                        labels=[label(bodies[b], k) for b, k in kept], a_inf_from=a_inf_from,
                        groups=[data.bodies.index(b) for b, _ in kept])
    except AsymmetryError as exc:
        i, j = exc.pair
        raise InputError(path, None, f"added_mass[inf][{label(*kept[i])}, {label(*kept[j])}]",
                         f"infinite-frequency added mass asymmetric beyond the tolerance: {exc.a_ij:.6g} but "
                         f"{exc.a_ji:.6g} for [{label(*kept[j])}, {label(*kept[i])}], {100 * exc.ratio:.3g} % of "
                         f"√(A_ii·A_jj) > {100 * exc.tol:g} % (symmetry_tolerance)") from None
    except GridError as exc:
        raise InputError(path, None, exc.field, str(exc)) from None
    checks = _negative_damping(data, [i for r, i in enumerate(keep) if rad.active[r, r]],
                               [label(bodies[b], k) for r, (b, k) in enumerate(kept) if rad.active[r, r]])
    samples = rad.kernels.shape[-1] - 1
    if samples < KERNEL_MIN_STEPS:
        checks.append(f"{path}: kernel length {samples * rad.timdel:g} s is only {samples} TIMDEL ({rad.timdel:g} s): "
                      f"the memory is cut after {samples} steps; fewer than {KERNEL_MIN_STEPS} rarely holds a "
                      "retardation function's decay")
    out = []
    order = [b for b in data.bodies if b in bodies]
    for p, bp in enumerate(order):
        for bq in order[p:]:
            am = np.zeros((6, 6))
            kernels = {}
            for r, (b1, i) in enumerate(kept):
                for c, (b2, j) in enumerate(kept):
                    if b1 != bp or b2 != bq:
                        continue
                    am[i - 1, j - 1] = rad.a_inf[r, c]
                    if rad.active[r, c] and np.any(rad.kernels[r, c]):
                        kernels[(i, j)] = rad.kernels[r, c].copy()
            na, nb = bodies[bp], bodies[bq]
            name = "_".join(([prefix] if prefix else []) + ([na] if bp == bq else [na, nb]))
            out.append(CouplingData(name, ("from BEM", path), na, nb, am, rad.timdel, kernels, path, None))
    return BemCouplings(data, out, rad, kept, dict(bodies), checks)


MAX_KERNEL_SAMPLES = 10 ** 5   # per dof pair (the defaults give a few thousand): the transform holds them for every pair
KERNEL_MIN_STEPS = 5      # a kernel of fewer TIMDEL than this is said out loud
NEGATIVE_DAMPING = 1e-3   # B_ii(ω) below −this × max|B_ii| is said out loud (noise near zero is not)


def _negative_damping(data, keep, labels):
    """Warnings for diagonal radiation damping B_ii(ω) < 0 beyond noise: energy flowing into
    the body from the waves it radiates, unphysical for a radiation problem.  ``keep``: the
    dofs the transform kept (a dof it found negligible, e.g. an axisymmetric body's yaw at
    1e-26, is noise whatever its sign)."""
    out = []
    for r, i in enumerate(keep):
        b = data.damping[:, i, i]
        peak = np.max(np.abs(b))
        low = int(np.argmin(b))
        if peak > 0 and b[low] < -NEGATIVE_DAMPING * peak:
            out.append(f"{data.path}: radiation_damping[{labels[r]}, {labels[r]}] is negative at "
                       f"{int(np.sum(b < -NEGATIVE_DAMPING * peak))} frequencies, down to {b[low]:.4g} at ω = "
                       f"{data.omega[low]:g} rad/s ({100 * b[low] / peak:.3g} % of its peak)")
    return out


def write_simo(result, path):
    """Write ``couplings``' result as a SIMO deck: one BODY DATA group per body, then the
    HYDRodynamic COUPling DATA groups (``decks.simo`` reads it back)."""
    names = list(dict.fromkeys(n for c in result.couplings for n in (c.body_a, c.body_b)))
    for n in names:
        if len(n.split()) != 1:
            raise InputError(path, None, "CHBDY", f"body name {n!r} must be one word")
    groups = [[BODY, n] for n in names]
    groups += [format_coupling(c.name, c.body_a, c.body_b, c.added_mass, c.kernels, c.timdel,
                               text=(f"from {c.text[1]}", "written by hydrofmu bem2simo, SI units"))
               for c in result.couplings]
    return write_couplings(path, groups)


def plot_quality(result, path, most=16):
    """PNG: A(ω) and B(ω) of the database (dots) and rebuilt from (A∞, K) (lines) for the
    diagonal pairs and the largest cross pairs (at most ``most`` pairs)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    r = result.radiation
    n = len(result.labels)
    scale = np.sqrt(np.outer(*(2 * [np.abs(np.diagonal(r.b_db, axis1=1, axis2=2)).max(axis=0)])))
    size = np.max(np.abs(r.b_db), axis=0) / np.where(scale > 0, scale, 1)
    pairs = [(i, i) for i in range(n) if r.active[i, i]]
    cross = sorted(((size[i, j], i, j) for i in range(n) for j in range(i + 1, n) if r.active[i, j]), reverse=True)
    pairs = (pairs + [(i, j) for _, i, j in cross])[:most]
    per_row = 2   # pairs side by side: A, B, A, B
    rows = -(-len(pairs) // per_row)
    fig, axes = plt.subplots(rows, 2 * per_row, figsize=(17, 2.7 * rows + 1.0), squeeze=False)
    w = r.omega
    for k, (i, j) in enumerate(pairs):
        row, col = divmod(k, per_row)
        rot = _rotations(result.labels[i]) + _rotations(result.labels[j])   # 0, 1 or 2 rotational dofs
        units = {"A": ("kg", "kg·m", "kg·m²")[rot], "B": ("kg/s", "kg·m/s", "kg·m²/s")[rot]}
        for ax, db, fit, err, what in ((axes[row, 2 * col], r.a_db, r.a_fit, r.err_a, "A"),
                                       (axes[row, 2 * col + 1], r.b_db, r.b_fit, r.err_b, "B")):
            ax.plot(w, db[:, i, j], ".", ms=4, label="database")
            ax.plot(w, fit[:, i, j], "-", lw=1.2, label="rebuilt from A∞, K(t)")
            ax.set_title(f"{what}: {result.labels[i]}, {result.labels[j]}\nworst {err[i, j]:.2g} % of peak",
                         fontsize=10)
            ax.set_ylabel(f"{what} [{units[what]}]", fontsize=9)
            ax.tick_params(labelsize=8)
            ax.grid(True, alpha=0.3)
    for k in range(len(pairs), rows * per_row):   # an odd count leaves one pair's place empty
        row, col = divmod(k, per_row)
        axes[row, 2 * col].set_visible(False)
        axes[row, 2 * col + 1].set_visible(False)
    for ax in axes[-1]:
        ax.set_xlabel("ω [rad/s]", fontsize=9)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="upper right", fontsize=9, frameon=False, ncol=2)
    fig.suptitle(f"{Path(result.data.path).name}: radiation A(ω), B(ω) of the database and rebuilt from the "
                 f"kernels (diagonal pairs, then the largest cross pairs)", fontsize=11, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.5 / fig.get_figheight()))
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def _rotations(label):
    """1 when a dof label (``Roll``, ``cyl1__Pitch``, …) names a rotation, else 0."""
    return int(label.rsplit("__", 1)[-1].lower() in ("roll", "pitch", "yaw"))
