"""Frequency-domain radiation coefficients → infinite-frequency added mass and retardation kernels.

Input: added mass A(ω) and radiation damping B(ω) (n×n matrices per frequency, element [i, j] =
load in dof i per motion of dof j, SI: kg, kg·m, kg·m², N·s/m, N·s, N·m·s), on a grid
0 < ω₁ < … < ω_N [rad/s], and optionally A∞ from the file.  Output (Cummins):

    F(t) = −A∞·a(t) − ∫₀^∞ K(s)·v(t − s) ds,   K(t) = (2/π)·∫₀^∞ B(ω)·cos(ωt) dω,

the kernels sampled at t = 0, TIMDEL, 2·TIMDEL, … (``memory.Convolution``'s convention: linear
between samples, zero after the last).  Method (stated in the README):

- B between the grid points: the cubic spline (not-a-knot at 0, natural at ω_N) through B(0) = 0 and the grid
  values; above ω_N: a power tail B_ij(ω) = B_ij(ω_N)·(ω_N/ω)^((p_i + p_j)/2) (the tail matrix
  is D·B(ω_N)·D with D = diag((ω_N/ω)^(p_i/2)): positive semi-definite when B(ω_N) is),
  integrated on a geometric grid up to TAIL_SPAN·ω_N.  Each dof's exponent p_i (P_MIN…P_MAX
  by P_STEP) is the one whose rebuilt A_ii(ω) agrees best with the database over the grid (the
  smallest mean |error|)
  (A in the band carries B beyond it, Kramers–Kronig).  Between dofs of different bodies
  (``groups``) the tail decays faster, by (ω_N/ω)^q more: the cross-body B oscillates with
  ω (the waves travel between the bodies, a phase k·d), so beyond the grid its integral mostly
  cancels, while a plain power tail carried B_ij(ω_N)'s sign to infinity (on two cylinders 20 m
  apart cut at 3.5 rad/s: a 1.3 % offset of the cross-surge A(ω) over the whole band).  One q
  (CROSS_Q) for all cross-body pairs, the one whose rebuilt cross-body A_ij(ω) agree best with
  the database; the tail matrix stays positive semi-definite (the Schur product of B(ω_N)'s
  D·B·D with the body-level matrix c·J + (1 − c)·I, c = (ω_N/ω)^q ≤ 1).  The cosine transform of the spline
  (closed form per interval) and of the piecewise-linear tail is exact, so K carries no
  quadrature error of its own.
- TIMDEL = π/(TIMDEL_FACTOR·ω_N) unless asked; an asked TIMDEL above π/(TIMDEL_LIMIT·ω_N) cannot
  represent the grid's highest frequencies and is refused.
- Kernel length: the shortest whose cut changes no rebuilt A(ω), B(ω) at the grid frequencies
  by more than DECAY of the curve's peak (searched up to the 2π/Δω the grid's spacing
  resolves), unless asked.
- A∞: Ogilvie's relation A∞ = A(ω) + (1/ω)·∫₀^L K(t)·sin(ωt) dt with the sampled kernel, the
  midrange over all grid frequencies (the constant that makes the worst A error smallest) when
  those values spread by at most BALANCE of √(A_ii·A_jj), else their median (a resonance
  between grid points made a few frequencies miss by tens of %, and the midrange moved A∞ by
  half that everywhere), so A∞ and K are consistent; the file's infinite-frequency value is reported against it, and used
  instead only when asked (``a_inf_from="file"``): with a grid that stops at ω_N, the kernel
  misses what B does beyond, and the file's A∞ then shifts the rebuilt A(ω) by that.
- Symmetry: A∞, A(ω) and B(ω) are symmetrised; an A∞ asymmetry |A_ij − A_ji| above
  ``symmetry_tol``·√(|A_ii|·|A_jj|) is an error (``AsymmetryError``).
- Negligible dofs and pairs (below NEGLIGIBLE of their diagonal scale) are set to zero.

Quality: A(ω) = A∞ − (1/ω)·∫K̃(t)·sin(ωt) dt and B(ω) = ∫K̃(t)·cos(ωt) dt rebuilt from the
sampled kernel K̃ exactly as the FMU convolves it, compared with the database at its own
frequencies: worst error in % of each curve's peak, and in % of the pair's scale
√(peak_ii·peak_jj) (the diagonal curves' peaks); ``tail_share`` = ∫|B_ij| dω beyond ω_N over
√(∫|B_ii| dω·∫|B_jj| dω) (a pair against its two dofs' whole damping: noise is not a share).
"""
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import CubicSpline

TIMDEL_FACTOR = 12.0     # default TIMDEL = π/(12·ω_N): 24 samples per period of ω_N
TIMDEL_LIMIT = 8.0       # asked TIMDEL must be ≤ π/(8·ω_N)
DECAY = 0.002            # kernel ends where its cut changes no A(ω), B(ω) by more than 0.2 % of the peak
P_MIN, P_MAX = 2.0, 8.0  # tail exponent bounds
TAIL_SPAN = 50.0         # the tail is integrated up to 50·ω_N (its rest: (1/50)^(p−1) of it)
TAIL_WARN = 0.05         # warn when the tail carries more than 5 % of ∫|B| dω
NEGLIGIBLE = 1e-6        # pairs below 1e-6·√(s_i·s_j) are zero
P_STEP = 0.25            # tail exponents tried
CROSS_Q = (0.0, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0, 128.0)   # extra tail exponents tried between bodies
TAIL_NODES = 400         # geometric nodes of the tail, ω_N…TAIL_SPAN·ω_N
SYMMETRY_TOL = 0.01      # default A∞ asymmetry tolerance (relative to √(|A_ii|·|A_jj|))
STRAY = 0.01             # a frequency whose Ogilvie A∞ strays more than this (of √(A_ii·A_jj)) is named
BALANCE = 0.02           # Ogilvie's A∞: the midrange over the grid when it spreads ≤ 2 % of √(A_ii·A_jj), else the median


class AsymmetryError(ValueError):
    """A∞ asymmetric beyond the tolerance: ``pair`` (i, j) 0-based, values and the tolerance."""

    def __init__(self, pair, a_ij, a_ji, ratio, tol):
        self.pair, self.a_ij, self.a_ji, self.ratio, self.tol = pair, a_ij, a_ji, ratio, tol
        super().__init__(f"A∞[{pair[0]}, {pair[1]}] = {a_ij:.6g} but A∞[{pair[1]}, {pair[0]}] = {a_ji:.6g}: "
                         f"asymmetry {100 * ratio:.3g} % of √(A_ii·A_jj) exceeds {100 * tol:g} %")


class GridError(ValueError):
    """The frequency grid cannot give what was asked (``field``: 'timdel' or 'omega')."""

    def __init__(self, field, message):
        self.field = field
        super().__init__(message)


@dataclass
class Radiation:
    """Result of ``transform`` (n dofs, SI units).

    a_inf (n, n) [kg, kg·m, kg·m²]; kernels (n, n, nt) [N·s/m², …] at t = k·timdel [s];
    active (n, n) bool: the pairs kept; omega, a_db, b_db: the (symmetrised) database;
    a_fit, b_fit: the same rebuilt from (a_inf, kernels); err_a, err_b (n, n): worst error in %
    of each curve's peak; pair_a, pair_b (n, n): the same in % of √(peak_ii·peak_jj);
    tail_share (n, n): ∫|B_ij| beyond ω_N / √(∫|B_ii|·∫|B_jj|); tail_exponents (n,); notes: what the transform decided (text lines).
    """
    a_inf: np.ndarray
    timdel: float
    kernels: np.ndarray
    active: np.ndarray
    omega: np.ndarray
    a_db: np.ndarray
    b_db: np.ndarray
    a_fit: np.ndarray
    b_fit: np.ndarray
    err_a: np.ndarray
    err_b: np.ndarray
    tail_share: np.ndarray
    tail_exponents: np.ndarray
    a_inf_source: str
    asymmetry: float
    seconds: float
    pair_a: np.ndarray = None
    pair_b: np.ndarray = None
    notes: list = field(default_factory=list)
    warnings: list = field(default_factory=list)

    @property
    def tail_exponent(self):
        """The median tail exponent of the active dofs."""
        on = np.diag(self.active)
        return float(np.median(self.tail_exponents[on])) if on.any() else P_MIN

    def rebuilt(self, omega):
        """A(ω), B(ω) (len(omega), n, n) rebuilt from (a_inf, kernels) exactly as the convolution
        sees them: A = A∞ − (1/ω)·∫K̃(t)·sin ωt dt, B = ∫K̃(t)·cos ωt dt, K̃ linear between samples."""
        return _rebuild(self.a_inf, self.kernels, self.timdel, omega)

    @property
    def length(self):
        """Kernel length [s] (time of the last sample)."""
        return self.timdel * (self.kernels.shape[-1] - 1)


def _sinc_g(y):
    """sin(y)/y and g(y) = (sin y − y·cos y)/y³ without cancellation (series for small y)."""
    sy, cy = np.sin(y), np.cos(y)
    small = np.abs(y) < 1e-2
    with np.errstate(invalid="ignore", divide="ignore"):
        sinc = sy / y
        g = (sy - y * cy) / y ** 3
    if small.any():
        y2 = y[small] ** 2
        sinc[small] = 1 - y2 / 6 + y2 ** 2 / 120
        g[small] = 1 / 3 - y2 / 30 + y2 ** 2 / 840
    return sinc, g


def hat_transform(nodes, x, kind="cos"):
    """W (len(x), len(nodes)) with W @ f = ∫ f(s)·cos(x·s) ds (or sin) over [nodes[0], nodes[-1]]
    for f linear between its values at ``nodes`` (exact, closed form per segment:
    ∫ over [m − h, m + h] of (f_m + f'·(s − m))·cos(xs) ds = 2h·f_m·cos(xm)·sinc(xh)
    − 2h³·x·f'·sin(xm)·g(xh), g(y) = (sin y − y·cos y)/y³; likewise for sin)."""
    nodes, x = np.asarray(nodes, float), np.asarray(x, float)[:, None]
    m, h = 0.5 * (nodes[1:] + nodes[:-1]), 0.5 * (nodes[1:] - nodes[:-1])
    sinc, g = _sinc_g(x * h)
    xm = x * m
    cm, sm = np.cos(xm), np.sin(xm)
    if kind == "cos":
        c0, c1 = 2 * h * cm * sinc, -2 * h ** 3 * x * sm * g
    else:
        c0, c1 = 2 * h * sm * sinc, 2 * h ** 3 * x * cm * g
    # f on a segment = f_m + f'·(s − m): f_m = (f_a + f_b)/2, f' = (f_b − f_a)/(2h)
    w = np.zeros((x.shape[0], nodes.size))
    w[:, :-1] += 0.5 * c0 - c1 / (2 * h)
    w[:, 1:] += 0.5 * c0 + c1 / (2 * h)
    return w


def _rebuild(a_inf, kernels, timdel, omega):
    """(A(ω), B(ω)) from A∞ (n, n) and kernels (n, n, nt) sampled at k·timdel (``Radiation.rebuilt``)."""
    omega = np.asarray(omega, float)
    n = kernels.shape[0]
    t = timdel * np.arange(kernels.shape[-1])
    flat = kernels.reshape(n * n, -1).T
    c = (hat_transform(t, omega) @ flat).reshape(omega.size, n, n)
    s = (hat_transform(t, omega, "sin") @ flat).reshape(omega.size, n, n)
    return a_inf[None] - s / omega[:, None, None], c


def _tail_exponent(omega, b, active):
    """Common decay exponent p of B ~ ω^−p from the diagonals over the top fifth of the grid."""
    top = omega >= omega[-1] - 0.2 * (omega[-1] - omega[0])
    if top.sum() < 2:
        top[-2:] = True
    slopes = []
    for i in range(b.shape[1]):
        y = np.abs(b[top, i, i])
        if active[i, i] and np.all(y > 0):
            slopes.append(-np.polyfit(np.log(omega[top]), np.log(y), 1)[0])
    p = float(np.median(slopes)) if slopes else P_MIN
    return float(np.clip(p, P_MIN, P_MAX))


def _moments(y):
    """½∫₋₁¹ of cos(yv), v·sin(yv), v²·cos(yv), v³·sin(yv) dv: sin y/y, (sin y − y cos y)/y²,
    ((y² − 2)·sin y + 2y·cos y)/y³, (3y²·sin y − y³·cos y + 6y·cos y − 6 sin y)/y⁴; their power
    series below |y| = 1, where the closed forms cancel."""
    y = np.asarray(y, float)
    small = np.abs(y) < 1.0
    z = np.where(small, 1.0, y)
    sz, cz = np.sin(z), np.cos(z)
    out = [sz / z, (sz - z * cz) / z ** 2, ((z * z - 2) * sz + 2 * z * cz) / z ** 3,
           (3 * z * z * sz - z ** 3 * cz + 6 * z * cz - 6 * sz) / z ** 4]
    if small.any():
        ys = y[small]
        y2 = ys * ys
        series = [np.zeros_like(ys) for _ in range(4)]
        term_c, term_s = np.ones_like(ys), ys.copy()          # y^2k/(2k)!, y^(2k+1)/(2k+1)!
        for k in range(10):
            sign = -1.0 if k % 2 else 1.0
            series[0] += sign * term_c / (2 * k + 1)
            series[1] += sign * term_s / (2 * k + 3)
            series[2] += sign * term_c / (2 * k + 3)
            series[3] += sign * term_s / (2 * k + 5)
            term_c = term_c * y2 / ((2 * k + 1) * (2 * k + 2))
            term_s = term_s * y2 / ((2 * k + 2) * (2 * k + 3))
        for o, sr in zip(out, series):
            o[small] = sr
    return out


def cubic_transform(breaks, coefs, x):
    """∫ f(s)·cos(x·s) ds over [breaks[0], breaks[-1]] for f cubic on each interval, given as
    scipy's PPoly coefficients (coefs (4, N, …): f = Σ_k coefs[k]·(s − breaks[i])^(3−k));
    returns (len(x), …).  Exact, closed form per interval (about its middle m, half-width h,
    u = s − m: ∫(c₀ + c₁u + c₂u² + c₃u³)·cos(x(m + u)) du, the moments of ``_moments``)."""
    breaks, x = np.asarray(breaks, float), np.asarray(x, float)[:, None]
    m, h = 0.5 * (breaks[1:] + breaks[:-1]), 0.5 * (breaks[1:] - breaks[:-1])
    shape = coefs.shape[2:]
    c = coefs.reshape(4, m.size, -1)
    hh = h[:, None]
    # the cubic about the interval's middle: r = s − breaks[i] = u + h
    c3 = c[0]
    c2 = 3 * hh * c[0] + c[1]
    c1 = 3 * hh ** 2 * c[0] + 2 * hh * c[1] + c[2]
    c0 = hh ** 3 * c[0] + hh ** 2 * c[1] + hh * c[2] + c[3]
    q0, q1, q2, q3 = _moments(x * h)
    cm, sm = np.cos(x * m), np.sin(x * m)
    out = (2 * h * cm * q0) @ c0 + (2 * h ** 3 * cm * q2) @ c2 - (2 * h ** 2 * sm * q1) @ c1 \
        - (2 * h ** 4 * sm * q3) @ c3
    return out.reshape((x.shape[0],) + shape)


def _band(omega, b):
    """B on [0, ω_N]: the cubic spline through B(0) = 0 and the grid values, a scipy PPoly
    (breaks at 0 and the grid); not-a-knot at 0, natural (B'' = 0) at ω_N: not-a-knot there made
    the last interval carry on the curvature of the one before, and on an oscillating B (two
    bodies 20 m apart, the grid cut at 3.5 rad/s) overshot by 1.4 % of the peak between the last
    two grid points."""
    x = np.concatenate([[0.0], omega])
    return CubicSpline(x, np.concatenate([np.zeros((1,) + b.shape[1:]), b]), axis=0,
                       bc_type=("not-a-knot", "natural"))


def _tail_exponents(omega, a, b, k_band, w_tail, sin_all, tail, a_inf, active):
    """Per dof i the exponent p_i of the tail B_ii(ω_N)·(ω_N/ω)^p_i (P_MIN…P_MAX by P_STEP) that
    makes the rebuilt A_ii(ω) = A∞ − (1/ω)·∫K_ii(t)·sin ωt dt agree best (smallest worst error)
    with the database over the grid, with the file's A∞ or the best constant (A in the band
    carries B beyond it: Kramers–Kronig).  Near ties go to the log-log slope of the top fifth.
    k_band (nt, n, n): the kernels of B up to ω_N; w_tail (nt, T): the kernel per unit tail node
    value; sin_all (N, nt): ∫·sin ωt dt / ω on the same time grid."""
    ps = np.arange(P_MIN, P_MAX + 1e-9, P_STEP)
    s_tail = sin_all @ (w_tail @ (tail[0] / tail[:, None]) ** ps[None, :])        # (N, P) per unit B(ω_N)
    slope = _tail_exponent(omega, b, active)
    p = np.full(b.shape[1], slope)
    for i in np.nonzero(np.diag(active))[0]:
        est = (a[:, i, i] + sin_all @ k_band[:, i, i])[:, None] + b[-1, i, i] * s_tail
        miss = _miss(est, np.abs(a[:, i, i]).max(), None if a_inf is None else a_inf[i, i])
        near = miss <= miss.min() + 1e-6 * max(np.abs(a[:, i, i]).max(), 1e-300)
        p[i] = ps[near][np.argmin(np.abs(ps[near] - slope))]
    return p


def _cross_exponent(omega, a, b, k_band, w_tail, sin_all, tail, pij, cross, a_inf, active):
    """The extra tail exponent q (from CROSS_Q) of the cross-body pairs whose rebuilt A_ij(ω)
    agree best with the database (the worst error over those pairs, in % of √(A_ii·A_jj) peaks,
    with the file's A∞ or each pair's best constant); 0 without cross-body pairs."""
    pairs = np.argwhere(np.triu(cross & active))
    if not pairs.size:
        return 0.0
    i, j = pairs[:, 0], pairs[:, 1]
    d = np.abs(np.diagonal(a, axis1=1, axis2=2)).max(axis=0)
    scale = np.sqrt(d[i] * d[j])
    base = a[:, i, j] + sin_all @ k_band[:, i, j]                      # (N, P)
    ratio = tail[0] / tail[:, None]
    miss = []
    for q in CROSS_Q:
        est = base + (sin_all @ (w_tail @ ratio ** (pij[i, j] + q)[None, :])) * b[-1, i, j]
        m = _miss(est, scale, None if a_inf is None else a_inf[i, j])
        miss.append(np.max(m / np.where(scale > 0, scale, 1.0)))
    return float(CROSS_Q[int(np.argmin(miss))])


def _centre(est, scale):
    """The A∞ the grid frequencies agree on, from Ogilvie's per-frequency values ``est`` (N, …)
    with ``scale`` (…, broadcast): their midrange (the constant that makes the worst rebuilt A
    error smallest) when that spreads by at most BALANCE of the scale, else their median.
    Where B changes faster than the grid resolves (a gap resonance between two bodies, a
    sharp peak between grid points), a few frequencies miss by tens of % of the peak whatever
    the kernels, and the midrange moved A∞ by half of that at every frequency; on clean data
    the midrange spreads the misfit next to ω_N evenly over the band."""
    mid = 0.5 * (est.max(axis=0) + est.min(axis=0))
    return np.where(est.max(axis=0) - mid <= BALANCE * scale, mid, np.median(est, axis=0))


def _miss(est, scale, a_inf=None):
    """How far Ogilvie's per-frequency values ``est`` (N, …) stray from A∞ (the given one, or
    ``_centre``'s): their mean |est − A∞| over the grid.  The mean, not the worst: the tail is
    chosen by what the bulk of the band says of it, not by the one frequency no tail can fix."""
    return np.mean(np.abs(est - (_centre(est, scale) if a_inf is None else a_inf)), axis=0)


def _where(omega, idx):
    """Grid frequencies ``omega[idx]`` as runs of neighbours: '1.6…1.8, 2.95'."""
    runs, start = [], idx[0]
    for k, nxt in zip(idx, list(idx[1:]) + [None]):
        if nxt != k + 1:
            runs.append(f"{omega[start]:g}" + (f"…{omega[k]:g}" if k > start else ""))
            start = nxt
    return ", ".join(runs[:4]) + (", …" if len(runs) > 4 else "")


def _scales(mats):
    """Per dof: the largest |diagonal| over the matrices (mats: (..., n, n))."""
    return np.max(np.abs(np.diagonal(mats, axis1=-2, axis2=-1)).reshape(-1, mats.shape[-1]), axis=0)


def _negligible(a, b, a_inf, units):
    """Active dofs and pairs: a dof is inactive when its diagonal scale is below NEGLIGIBLE of the
    largest of its kind (``units``: 0 translation, 1 rotation); a pair when A and B both are."""
    sa = _scales(np.concatenate([a, a_inf[None]]) if a_inf is not None else a)
    sb = _scales(b)
    on = np.ones(sa.size, bool)
    for u in (0, 1):
        k = units == u
        if k.any():
            on[k] &= (sa[k] > NEGLIGIBLE * sa[k].max()) | (sb[k] > NEGLIGIBLE * max(sb[k].max(), 1e-300))
    scale_a, scale_b = np.sqrt(np.outer(sa, sa)), np.sqrt(np.outer(sb, sb))
    peak_a = np.max(np.abs(np.concatenate([a, a_inf[None]]) if a_inf is not None else a), axis=0)
    peak_b = np.max(np.abs(b), axis=0)
    pairs = (peak_a > NEGLIGIBLE * scale_a) | (peak_b > NEGLIGIBLE * scale_b)
    return pairs & np.outer(on, on), scale_a


def _decay_length(k, dt, omega, a, b, active, cap, dw, warnings):
    """The shortest kernel length L [s] whose cut changes no rebuilt A(ω) or B(ω) at the grid
    frequencies by more than DECAY of that curve's peak: the parts ∫_L K(t)·cos ωt dt and
    (1/ω)·∫_L K(t)·sin ωt dt are small for every pair (k: the kernels (nt, n, n) at t = m·dt up
    to 2π/Δω or beyond).  Measured in the frequency domain because A at low ω weighs the
    kernel's tail by t."""
    t = dt * np.arange(k.shape[0])
    pairs = np.argwhere(np.triu(active))
    if not pairs.size:
        return t[1]
    k = k[:, pairs[:, 0], pairs[:, 1]]                       # (nt, P)
    worst = np.zeros(t.size)
    for kind, db in (("cos", b), ("sin", a)):
        w = hat_transform(t, omega, kind)
        if kind == "sin":
            w = w / omega[:, None]
        part = np.cumsum((w[:, :, None] * k[None])[:, ::-1], axis=1)[:, ::-1]   # ∫ from t_m on
        peak = np.max(np.abs(db[:, pairs[:, 0], pairs[:, 1]]), axis=0)
        with np.errstate(invalid="ignore", divide="ignore"):
            rel = np.where(peak > 0, np.abs(part) / peak, 0.0)
        worst = np.maximum(worst, rel.max(axis=(0, 2)))
    ok = np.nonzero(worst > DECAY)[0]
    last = int(ok[-1]) + 1 if ok.size else 1
    if last >= t.size - 1:
        warnings.append(f"the kernels' tails still change A or B by more than {100 * DECAY:g} % of a peak at "
                        f"2π/Δω = {cap:.4g} s, the longest memory the frequency spacing Δω = {dw:.4g} rad/s "
                        f"resolves: refine the grid")
    return t[min(last, t.size - 1)]


def symmetrise(a_inf, scale, tol):
    """(A∞ + A∞ᵀ)/2 and the largest asymmetry ratio; AsymmetryError beyond ``tol``."""
    with np.errstate(invalid="ignore", divide="ignore"):
        ratio = np.where(scale > 0, np.abs(a_inf - a_inf.T) / scale, 0.0)
    i, j = np.unravel_index(np.argmax(ratio), ratio.shape)
    if ratio[i, j] > tol:
        raise AsymmetryError((int(min(i, j)), int(max(i, j))), a_inf[min(i, j), max(i, j)],
                             a_inf[max(i, j), min(i, j)], float(ratio[i, j]), tol)
    return 0.5 * (a_inf + a_inf.T), float(ratio[i, j])


def transform(omega, added_mass, damping, a_inf=None, units=None, timdel=None, length=None,
              symmetry_tol=SYMMETRY_TOL, labels=None, a_inf_from="ogilvie", groups=None):
    """A∞ and K(t) from A(ω), B(ω) (see the module docstring).

    omega (N,) [rad/s], finite, > 0, increasing; added_mass, damping (N, n, n); a_inf (n, n) or
    None (then extrapolated); units (n,) 0 for a translation dof, 1 for a rotation (default: dof
    index mod 6 ≥ 3); timdel [s], length [s]: asked values or None; labels: dof names for the
    messages; groups (n,): the body of each dof (default: index // 6).  Raises AsymmetryError,
    GridError.  Returns a ``Radiation``.
    """
    t0 = time.perf_counter()
    omega = np.asarray(omega, float)
    a, b = np.asarray(added_mass, float), np.asarray(damping, float)
    n = a.shape[-1]
    names = list(labels) if labels is not None else [str(k) for k in range(n)]
    units = np.asarray(units if units is not None else (np.arange(n) % 6 >= 3), int)
    notes, warnings = [], []
    if omega.size < 3 or np.any(np.diff(omega) <= 0) or omega[0] <= 0 or not np.isfinite(omega[-1]):
        raise GridError("omega", "frequencies must be finite, > 0, increasing, at least 3")
    active, scale = _negligible(a, b, None if a_inf is None else np.asarray(a_inf, float), units)
    asym = 0.0
    if a_inf is not None:
        a_inf, asym = symmetrise(np.asarray(a_inf, float), scale, symmetry_tol)
    for name, m in (("A(ω)", a), ("B(ω)", b)):
        d = _scales(m)
        ref = np.sqrt(np.outer(d, d))
        with np.errstate(invalid="ignore", divide="ignore"):
            r = np.where(active & (ref > 0), np.max(np.abs(m - m.transpose(0, 2, 1)), axis=0) / ref, 0.0)
        notes.append(f"database {name} symmetrised: largest |M_ij − M_ji| {100 * np.nan_to_num(r).max():.3g} % "
                     f"of √(M_ii·M_jj) (peaks)")
    a = 0.5 * (a + a.transpose(0, 2, 1))
    b = 0.5 * (b + b.transpose(0, 2, 1))
    a, b = a * active, b * active

    w_top = omega[-1]
    limit = np.pi / (TIMDEL_LIMIT * w_top)
    if timdel is None:
        timdel = np.pi / (TIMDEL_FACTOR * w_top)
    elif timdel > limit * (1 + 1e-9):
        raise GridError("timdel", f"TIMDEL = {timdel:g} s is too coarse for the frequency grid: its highest "
                                  f"frequency {w_top:g} rad/s needs TIMDEL ≤ π/({TIMDEL_LIMIT:g}·ω_N) = {limit:.4g} s")
    dw = np.max(np.diff(np.concatenate([[0.0], omega])))
    cap = 2 * np.pi / dw
    spline = _band(omega, b)
    tail = w_top * np.geomspace(1.0, TAIL_SPAN, TAIL_NODES)
    # one time grid for every use (the fit of the tails, the length search, the kernels)
    t_all = timdel * np.arange(int(np.ceil(max(length or 0.0, cap) / timdel - 1e-9)) + 1)
    k_band = (2 / np.pi) * cubic_transform(spline.x, spline.c, t_all).reshape(t_all.size, -1)
    w_tail = (2 / np.pi) * hat_transform(tail, t_all)
    sin_all = hat_transform(t_all, omega, "sin") / omega[:, None]
    keep_file = a_inf is not None and a_inf_from == "file"
    p = _tail_exponents(omega, a, b, k_band.reshape(-1, n, n), w_tail, sin_all, tail,
                        a_inf if keep_file else None, active)
    pij = 0.5 * (p[:, None] + p[None, :])
    groups = np.asarray(groups if groups is not None else np.arange(n) // 6)
    cross = ~np.equal.outer(groups, groups)
    q = _cross_exponent(omega, a, b, k_band.reshape(-1, n, n), w_tail, sin_all, tail, pij, cross,
                        a_inf if keep_file else None, active)
    pij = pij + q * cross
    k_all = (k_band + w_tail @ (b[-1] * (w_top / tail[:, None, None]) ** pij).reshape(tail.size, -1)
             ).reshape(-1, n, n)

    fine = np.linspace(0.0, w_top, 8 * omega.size + 1)
    band = np.trapezoid(np.abs(spline(fine)), fine, axis=0)
    beyond = np.abs(b[-1]) * w_top / (pij - 1)
    total = np.diagonal(band + beyond)
    with np.errstate(invalid="ignore", divide="ignore"):   # a pair's tail against its dofs' whole ∫|B_ii|
        share = np.where(active, beyond / np.sqrt(np.outer(total, total)), 0.0)
    share = np.nan_to_num(share)

    if length is None:
        length = _decay_length(k_all[::4], 4 * timdel, omega, a, b, active, cap, dw, warnings)
    m = int(np.ceil(length / timdel - 1e-9)) + 1
    t = t_all[:m]
    kernels = np.ascontiguousarray(k_all[:m].transpose(1, 2, 0))

    # rebuild A(ω), B(ω) from the sampled kernels, as the convolution sees them
    rebuilt_a, b_fit = _rebuild(np.zeros((n, n)), kernels, timdel, omega)
    est = a - rebuilt_a                           # Ogilvie: A∞ at each grid frequency
    fitted = _centre(est, scale) * active
    rel = lambda m: 100 * np.max(np.where(active, m, 0) / np.where(scale > 0, scale, 1))
    ref = a_inf * active if keep_file else fitted
    with np.errstate(invalid="ignore", divide="ignore"):
        stray = np.where(active, np.abs(est - ref), 0.0) / np.where(scale > 0, scale, np.inf)
    off = np.nonzero(stray.max(axis=(1, 2)) > STRAY)[0]
    if off.size:
        notes.append(f"Ogilvie's A∞ of {off.size} of the {omega.size} frequencies stray more than {100 * STRAY:g} % "
                     f"of √(A_ii·A_jj) from the A∞ used, up to {100 * stray.max():.3g} % at {_where(omega, off)} "
                     f"rad/s: the rebuilt A(ω) misses the database there (B changing faster than the grid "
                     f"resolves, or next to ω_N: refine the grid there)")
    if keep_file:
        a_inf, src = a_inf * active, "file"
        notes.append(f"A∞ from the file; the kernels' own (Ogilvie's relation, the median over the frequencies) "
                     f"differs by ≤ {rel(np.abs(a_inf - fitted)):.3g} % of √(A_ii·A_jj): a_inf = \"ogilvie\" "
                     f"would move the rebuilt A(ω) by that")
    else:
        src = "Ogilvie"
        notes.append(f"A∞ from Ogilvie's relation A∞ = A(ω) + (1/ω)·∫K(t)·sin ωt dt: the median over the "
                     f"{omega.size} frequencies"
                     + (f"; the file's ω = ∞ value differs by ≤ {rel(np.abs(a_inf * active - fitted)):.3g} % of "
                        f"√(A_ii·A_jj): a_inf = \"file\" would move the rebuilt A(ω) by that"
                        if a_inf is not None else ""))
        a_inf = fitted
    a_fit = a_inf[None] + rebuilt_a

    def worst(fit, db, pair=False):
        peak = np.max(np.abs(db), axis=0)
        if pair:
            d = np.diagonal(peak)
            peak = np.sqrt(np.outer(d, d))
        with np.errstate(invalid="ignore", divide="ignore"):
            e = np.where(active & (peak > 0), 100 * np.max(np.abs(fit - db), axis=0) / peak, 0.0)
        return np.nan_to_num(e)

    on = np.diag(active)
    pr = f"{np.min(p[on]):.3g}…{np.max(p[on]):.3g}" if on.any() else "-"
    notes.insert(0, f"TIMDEL {timdel:.4g} s, kernel length {t[-1]:.4g} s ({t.size} samples), B a cubic spline, "
                    f"tail B ~ ω^-p beyond {w_top:g} rad/s with p {pr} per dof, A∞ from "
                    + ("the file" if src == "file" else "Ogilvie's relation")
                    + (f"; between bodies (ω_N/ω)^{q:g} more" if cross.any() else ""))
    big = np.triu(share > TAIL_WARN)
    if big.any():
        order = np.argsort(share[big])[::-1]
        pairs = np.argwhere(big)[order]
        named = ", ".join(f"({names[i]}, {names[j]}) {100 * share[i, j]:.3g} %" for i, j in pairs[:3])
        warnings.append(f"the tail beyond the last frequency {w_top:g} rad/s carries more than {100 * TAIL_WARN:g} % "
                        f"of √(∫|B_ii|dω·∫|B_jj|dω) for {len(pairs)} dof pair(s): {named}"
                        + (", …" if len(pairs) > 3 else "") + "; the kernels rely there on the fitted tail "
                        "(exponents chosen so that the rebuilt A(ω) agrees with the database's): check the rebuilt "
                        "A(ω), B(ω) in the quality report and plot, and solve the BEM to higher frequencies to "
                        "remove the doubt")
    return Radiation(a_inf=a_inf, timdel=float(timdel), kernels=kernels, active=active, omega=omega,
                     a_db=a, b_db=b, a_fit=a_fit, b_fit=b_fit, err_a=worst(a_fit, a), err_b=worst(b_fit, b),
                     pair_a=worst(a_fit, a, True), pair_b=worst(b_fit, b, True),
                     tail_share=share, tail_exponents=p, a_inf_source=src, asymmetry=asym,
                     seconds=time.perf_counter() - t0, notes=notes, warnings=warnings)
