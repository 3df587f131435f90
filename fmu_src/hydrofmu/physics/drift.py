"""Second-order wave drift: mean drift, Newman's approximation and the full difference-frequency
QTF, evaluated from the sea's per-step complex component amplitudes.

Convention (DESIGN.md, Waves (second order); docs/waves.md)
------------------------------------------------------------
- Components k of the one wave field (physics.waves.Components): amplitude a_k [m],
  ω_k [rad/s], direction β_k [deg, going to], phase φ_k [rad]; their complex amplitude at
  time t, referred to the global origin and ramped:
  z_k(t) = r(t)·a_k·e^{i(ω_k·t + φ_k)}  (``phasors``; the first-order wave field shares it).
- Difference-frequency load [N, N·m] (global axes, moments about the reference point):
  F(t) = Σ_i Σ_j Re{Q(ω_i, ω_j; β_i, β_j)·z_i·conj(z_j)}, Q per unit amplitude squared
  [N/m², N·m/m²], Hermitian: Q(ω_j, ω_i; β_j, β_i) = conj Q(ω_i, ω_j; β_i, β_j); in a regular
  wave of amplitude a the mean drift is a²·Q(ω, ω; β, β) (real).  The ramp enters squared
  (the load is quadratic in the ramped wave).
- Q is referred to the global origin like the first-order X: a body at (x, y) carries the
  factor e^{−i(k_i·d_i − k_j·d_j)}, d = x·cos β + y·sin β.  Interpolation is done on the
  value at the body's own place, Q·e^{+i(k_i·d_i − k_j·d_j)}, which varies slowly, and the
  phase put back exactly.

Methods (``DriftLoad``)
-----------------------
- ``mean``: F̄ = Σ_k |z_k|²·Q(ω_k, ω_k; β_k, β_k) — after the ramp the constant
  Σ a_k²·Q_kk.  Exact for the mean of a random-phase sea with any spreading (the cross
  terms of two components average to zero): each component with its own direction's
  unidirectional diagonal.
- ``newman``: Q_ij ≈ s·√(Q_ii·Q_jj) when Q_ii and Q_jj have the same sign s, 0 when they
  differ (the geometric form of OrcaFlex and HydroDyn), evaluated in O(N) per step as
  F = |Σ_k z_k·√Q⁺_k·e^{−ik_k d_k}|² − |Σ_k z_k·√Q⁻_k·e^{−ik_k d_k}|², Q⁺ = max(Q_kk, 0),
  Q⁻ = max(−Q_kk, 0), per dof; no sum-frequency terms.  With spreading each component uses its
  own direction's diagonal and a pair of two directions is approximated by the same geometric
  mean (as OrcaFlex and HydroDyn do): it takes the two components' drift as fully correlated,
  an approximation on top of Newman's, said here and in the docs.
- ``qtf``: the full double sum with Q interpolated bilinearly in (ω_i, ω_j) and in the
  headings; pairs with |ω_i − ω_j| > ``cutoff`` [rad/s] are left out (they do not excite the
  slow drift of a moored body).  Components are sorted by frequency and the kept pairs stored
  by their offset d = j − i: the direct sum costs (D + 1)·N·6 complex products, D the largest
  offset within the cut-off (N²/2·6 without one).  In time the load is a sum of
  difference-frequency lines |μ| ≤ μ_max (the cut-off, or the sea's bandwidth), so on a
  block of length L = 2·BLOCK_X/μ_max of absolute time it is a Chebyshev series of K terms
  (Jacobi–Anger: e^{iμt} = e^{iμt_c}·Σ_n ε_n iⁿ J_n(μL/2)·T_n(τ)): ``DriftLoad.at`` evaluates
  the direct sum at the K Chebyshev nodes of the block once, and each step in the block is the
  series at τ (6·K products).  Truncation: |F_block − F| ≤ 4·S·Σ_{n≥K}(x/2)ⁿ/n!, x = BLOCK_X,
  S = Σ_pairs |c_ij|·a_i·a_j (which bounds |F|), K chosen for BLOCK_TOL; what remains is
  round-off, chiefly that of the phases ω·t, which any evaluation at t has (≤ 2ε·ω_max·t of
  S: 1.5e-13 of S at 3 h, tests/test_drift.py).  Blocks pay when a block holds many steps:
  with K·h > L/2 (h the last step length) the step is the direct sum.  Long-crested seas
  need unidirectional pairs (β, β) around the sea's direction; a spread sea needs the
  bidirectional grid (every (β1, β2) of the file's headings): a unidirectional QTF in a
  spread sea is refused (the cross-direction pairs are not in the data, and no rule makes
  them up defensibly: use ``newman``, which says its approximation).

Headings
--------
Mean drift and QTF are interpolated in heading in the frame that turns with the wave: the
horizontal pairs (F_x, F_y) and (M_x, M_y) of each data heading β_h are taken as components
along and across it (F_L = F_x cos β_h + F_y sin β_h, F_T = −F_x sin β_h + F_y cos β_h),
interpolated, and turned back to the sea's direction; heave and yaw are interpolated as they
are.  For a body that is the same seen from every heading (an axisymmetric buoy or spar about
its reference point) these components do not depend on the heading, so the interpolation is
exact (the Cartesian components' interpolation is not: 7 % low between 0° and 45°).  A QTF
pair (β_1, β_2) uses the frame of its mean direction.  ``heading_error`` estimates the
interpolation's error for a sea: this linear scheme against a cubic (Lagrange through the
four nearest headings, periodic across 360°) on the sea's mean drift.

Not modelled: sum-frequency loads, wave-drift damping (the drift's dependence on the body's
slow velocity), the current's effect on drift (encounter frequency, Doppler-shifted QTF).
"""
from __future__ import annotations

import math

import numpy as np

from .waves import DIRECTION_TOL, Components, TransferFunction, WaveError, ramp, wave_number

METHODS = ("mean", "newman", "qtf")
SPREAD_REFUSED = ("the full QTF in a spread sea needs bidirectional data (every heading pair (β1, β2) of the "
                  "file's headings); this QTF holds unidirectional pairs only: use method = \"newman\" or "
                  "\"mean\", or a long-crested sea")


def phasors(comps: Components, t: float, ramp_length: float = 0.0) -> np.ndarray:
    """z_k = r(t)·a_k·e^{i(ω_k·t + φ_k)} (N,) complex [m]: the components' complex amplitudes
    at time t [s], referred to the global origin, ramp r(t) (physics.waves.ramp) applied."""
    z = comps.amplitude * np.exp(1j * (comps.omega * t + comps.phase))
    return z * ramp(t, ramp_length) if t < ramp_length else z


def _locate(grid, x, what):
    """(i0, i1, frac) of linear interpolation on an increasing grid; outside is a WaveError."""
    x = np.asarray(x, dtype=float)
    if x.min() < grid[0] * (1 - 1e-9) or x.max() > grid[-1] * (1 + 1e-9):
        bad = x[(x < grid[0] * (1 - 1e-9)) | (x > grid[-1] * (1 + 1e-9))].flat[0]
        raise WaveError("omega", f"ω = {bad:g} rad/s is outside the {what}'s frequencies "
                                 f"{grid[0]:g}…{grid[-1]:g} rad/s")
    if grid.size == 1:
        z = np.zeros(x.shape, int)
        return z, z, np.zeros(x.shape)
    i = np.clip(np.searchsorted(grid, x, side="right") - 1, 0, grid.size - 2)
    return i, i + 1, np.clip((x - grid[i]) / (grid[i + 1] - grid[i]), 0.0, 1.0)


def _headings(directions):
    """A direction interpolator over ``directions`` [deg] (waves.TransferFunction's rule:
    across 360° when they go round the circle, an error outside otherwise)."""
    return TransferFunction([0.0, 1.0], directions, np.zeros((2, len(directions), 6)))


def turn(values, beta, back=False):
    """``values`` (..., 6) with the horizontal pairs (dofs 1, 2) and (4, 5) turned into the
    frame of the heading ``beta`` [deg] (broadcast against values[..., 0]): components along
    and across it; ``back``: from that frame to the global axes.  Heave and yaw unchanged."""
    b = np.radians(np.asarray(beta, dtype=float))
    c, s = np.cos(b), (-1.0 if back else 1.0) * np.sin(b)
    out = np.array(values, copy=True)
    for i, j in ((0, 1), (3, 4)):
        x, y = values[..., i], values[..., j]
        out[..., i], out[..., j] = c * x + s * y, c * y - s * x
    return out


def mean_heading(a, b):
    """The direction [deg] halfway between a and b on the circle (the pair's frame)."""
    return np.asarray(a, dtype=float) + 0.5 * ((np.asarray(b, dtype=float) - a + 180.0) % 360.0 - 180.0)


class MeanDrift:
    """Mean drift per unit amplitude squared Q(ω, ω; β, β) [N/m², N·m/m²] of one body.

    omega (nω,) [rad/s] increasing; directions (nβ,) [deg]; values (nω, nβ, 6) real, global
    axes.  ``at(ω, β)`` interpolates linearly in ω and in β in the frame turning with the
    heading (module docstring, Headings; physics.waves.TransferFunction's rules: across 360°
    when the directions go round the circle, an error outside the data)."""

    def __init__(self, omega, directions, values):
        values = np.asarray(values, dtype=float)
        self.values = values
        self.directions = np.asarray(directions, dtype=float)
        framed = turn(values, np.asarray(directions, float)[None, :])
        self.table = TransferFunction(omega, directions, framed.astype(complex))
        self.omega = self.table.omega

    @property
    def window(self):
        return self.table.window

    def at(self, omega, beta):
        """(n, 6) real for n components ω [rad/s], β [deg]."""
        omega = np.atleast_1d(np.asarray(omega, dtype=float))
        beta = np.broadcast_to(np.asarray(beta, dtype=float), omega.shape)
        return turn(self.table.at(omega, beta).real, beta, back=True)

    def c_params(self):
        """drift.c's data: [nω, ω, nβ, closed, directions, values (nω, nβ, 6) in each heading's
        frame (drift.c turns the interpolated value back)]."""
        t = self.table
        return ([t.omega.size] + t.omega.tolist() + [t.directions.size, float(t.closed)] + t.directions.tolist()
                + t.values.real.ravel().tolist())


def _cubic_weights(directions, closed, beta):
    """(indices (n, m), weights (n, m)) of Lagrange interpolation in heading through the (up
    to) four computed directions nearest each β [deg] (periodic when ``closed``); None with
    fewer than three directions."""
    d = np.asarray(directions, float)
    nd = d.size
    if nd < 3:
        return None
    beta = np.mod(np.asarray(beta, float), 360.0)
    if closed:
        ext = np.concatenate((d, [d[0] + 360.0]))
        b = np.where(beta < d[0], beta + 360.0, beta)
        j = np.clip(np.searchsorted(ext, b, side="right") - 1, 0, nd - 1)
        m = min(4, nd)
        start = j - (m // 2 - 1)
        idx = (start[:, None] + np.arange(m)[None, :])
        x = d[idx % nd] + 360.0 * np.floor_divide(idx, nd)
        idx = idx % nd
    else:
        b = beta
        m = min(4, nd)
        j = np.clip(np.searchsorted(d, b, side="right") - 1, 0, nd - 2)
        start = np.clip(j - (m // 2 - 1), 0, nd - m)
        idx = start[:, None] + np.arange(m)[None, :]
        x = d[idx]
    w = np.ones(idx.shape)
    for a in range(m):
        for c in range(m):
            if a != c:
                w[:, a] *= (b - x[:, c]) / (x[:, a] - x[:, c])
    return idx, w


def heading_error(mean: MeanDrift, comps: Components):
    """The heading interpolation's error estimate on this sea's mean drift: (error (6,), n)
    with error_k = |F̄_lin − F̄_cubic| / Σ_c a_c²·max_β |Q_k(ω_c, β)| per dof (0 where the dof
    is zero everywhere; dofs 1–2 and 4–5 scaled by their horizontal magnitude), F̄ = Σ_c a_c²·Q
    with the linear scheme of ``MeanDrift.at`` and the cubic of ``_cubic_weights``, both in the
    turning frame and linear in ω; n the number of components between two computed headings.
    None when no component lies between headings; (None, n) when the data have fewer than
    three headings (nothing to compare with)."""
    t = mean.table
    beta = np.mod(np.asarray(comps.direction, float), 360.0)
    gap = np.abs((beta[:, None] - t.directions[None, :] + 180.0) % 360.0 - 180.0)
    between = gap.min(axis=1) > DIRECTION_TOL
    if not between.any():
        return None
    cubic = _cubic_weights(t.directions, t.closed, beta)
    if cubic is None:
        return None, int(between.sum())
    w, a2 = np.asarray(comps.omega, float), np.asarray(comps.amplitude, float) ** 2
    v = t.values.real                                         # (nω, nβ, 6) in each heading's frame
    i0, i1, fw = _locate(t.omega, w, "mean drift")
    rows = (1 - fw)[:, None, None] * v[i0] + fw[:, None, None] * v[i1]      # (n, nβ, 6) at each ω
    idx, wc = cubic
    lin = mean.at(w, beta)
    cub = turn(np.einsum("nm,nmk->nk", wc, np.take_along_axis(rows, idx[:, :, None], axis=1)), beta, back=True)
    err = np.abs(a2 @ (lin - cub))
    mag = np.abs(rows).max(axis=1)
    for i, j in ((0, 1), (3, 4)):
        mag[:, i] = mag[:, j] = np.hypot(rows[:, :, i], rows[:, :, j]).max(axis=1)
    scale = a2 @ mag
    return np.where(scale > 0, err / np.where(scale > 0, scale, 1.0), 0.0), int(between.sum())


class QTF:
    """Difference-frequency QTF Q(ω_i, ω_j; β_i, β_j) [N/m², N·m/m²] of one body.

    omega (nω,) [rad/s] increasing; pairs [(β1, β2)] [deg]; values (nω, nω, nP, 6) complex,
    Hermitian (both triangles), referred to the global origin; position (x, y) [m] the body's
    mean position; g, depth for the wave numbers.  The headings of the pairs form a grid
    H × H when the file is bidirectional; unidirectional files hold the diagonal (β, β)."""

    def __init__(self, omega, pairs, values, position=(0.0, 0.0), g=9.81, depth=math.inf):
        self.omega = np.asarray(omega, dtype=float)
        values = np.asarray(values, dtype=complex)
        if not np.all(np.isfinite(values)):
            raise WaveError("values", "non-finite QTF value")
        pairs = [(float(np.mod(a, 360.0)), float(np.mod(b, 360.0))) for a, b in pairs]
        heads = sorted({round(h, 6) for p in pairs for h in p})
        self.headings = np.array(heads)
        self._dir = _headings(heads)     # sorted, deduplicated: self._dir.directions
        h = self._dir.directions
        index = {round(x, 6): n for n, x in enumerate(h)}
        n, nh = self.omega.size, h.size
        grid = np.full((n, n, nh, nh, 6), np.nan, complex)
        for p, (a, b) in enumerate(pairs):
            grid[:, :, index[round(a, 6)], index[round(b, 6)]] = values[:, :, p]
        self.grid = grid
        self.uni = np.array([not np.isnan(grid[0, 0, m, m, 0].real) for m in range(nh)])
        self.bidirectional = nh > 1 and not np.isnan(grid[0, 0, :, :, 0].real).any()
        self.position = np.asarray(position, dtype=float)[:2]
        self.g, self.depth = g, depth
        k = wave_number(self.omega, g, depth)
        b = np.radians(h)
        d = self.position[0] * np.cos(b) + self.position[1] * np.sin(b)     # (nh,)
        kd = k[:, None] * d[None, :]                                         # (nω, nh)
        self.frame = mean_heading(h[:, None], h[None, :])                    # (nh, nh): each pair's frame
        self.local = turn(grid * np.exp(1j * (kd[:, None, :, None, None] - kd[None, :, None, :, None])), self.frame)

    @property
    def window(self):
        return float(self.omega[0]), float(self.omega[-1])

    def c_params(self):
        """drift.c's data: [nω, ω, nh, closed, bidirectional, nu, closed (unidirectional), the
        unidirectional headings' indices (nu), headings (nh), x, y, Re Q, Im Q (nω, nω, nh, nh, 6)
        referred to the origin, in each pair's frame (module docstring, Headings), 0 where the
        file has no pair]."""
        m = np.flatnonzero(self.uni)
        sub = _headings(self._dir.directions[m]) if m.size else None
        q = turn(np.nan_to_num(self.grid), self.frame)
        return ([self.omega.size] + self.omega.tolist()
                + [self._dir.directions.size, float(self._dir.closed), float(self.bidirectional), m.size,
                   float(sub.closed) if sub is not None else 0.0] + m.tolist() + self._dir.directions.tolist()
                + self.position.tolist() + q.real.ravel().tolist() + q.imag.ravel().tolist())

    def diagonal(self) -> MeanDrift:
        """The mean drift Q(ω, ω; β, β) of the unidirectional headings."""
        m = np.flatnonzero(self.uni)
        idx = np.arange(self.omega.size)
        vals = self.grid[idx, idx][:, m, m, :].real
        return MeanDrift(self.omega, self._dir.directions[m], vals)

    def _heading_corners(self, bi, bj):
        """[(index β1, index β2, weight)] arrays of the heading corners for each pair."""
        bi, bj = np.atleast_1d(bi), np.atleast_1d(bj)
        if not self.bidirectional:
            same = np.abs((bi - bj + 180.0) % 360.0 - 180.0) <= DIRECTION_TOL
            if not same.all():
                raise WaveError("spreading", SPREAD_REFUSED)
            m = np.flatnonzero(self.uni)
            if m.size == 0:
                raise WaveError("direction", "the QTF has no unidirectional heading pair (β, β)")
            sub = _headings(self._dir.directions[m])
            j0, j1, f = sub._direction_weights(bi)
            return [(m[j0], m[j0], 1 - f), (m[j1], m[j1], f)]
        a0, a1, fa = self._dir._direction_weights(bi)
        b0, b1, fb = self._dir._direction_weights(bj)
        return [(a0, b0, (1 - fa) * (1 - fb)), (a0, b1, (1 - fa) * fb), (a1, b0, fa * (1 - fb)), (a1, b1, fa * fb)]

    def at(self, wi, wj, bi, bj):
        """Q (n, 6) complex for n pairs (ω_i, ω_j) [rad/s], (β_i, β_j) [deg]."""
        wi, wj = np.atleast_1d(np.asarray(wi, float)), np.atleast_1d(np.asarray(wj, float))
        bi = np.broadcast_to(np.asarray(bi, float), wi.shape)
        bj = np.broadcast_to(np.asarray(bj, float), wi.shape)
        i0, i1, fi = _locate(self.omega, wi, "QTF")
        j0, j1, fj = _locate(self.omega, wj, "QTF")
        out = np.zeros(wi.shape + (6,), complex)
        for hi, hj, wh in self._heading_corners(bi, bj):
            for ii, wa in ((i0, 1 - fi), (i1, fi)):
                for jj, wb in ((j0, 1 - fj), (j1, fj)):
                    out += (wh * wa * wb)[:, None] * self.local[ii, jj, hi, hj]
        out = turn(out, mean_heading(bi, bj), back=True)
        ki = wave_number(wi, self.g, self.depth)
        kj = wave_number(wj, self.g, self.depth)
        x, y = self.position
        di = x * np.cos(np.radians(bi)) + y * np.sin(np.radians(bi))
        dj = x * np.cos(np.radians(bj)) + y * np.sin(np.radians(bj))
        return out * np.exp(-1j * (ki * di - kj * dj))[:, None]


BLOCK_X = 40.0     # μ_max·L/2 of a block: L = 80/μ_max (133 s at a 0.6 rad/s cut-off)
BLOCK_TOL = 1e-15  # the Chebyshev truncation's bound, of S = Σ_pairs |c|·a_i·a_j


def block_plan(mu_max):
    """(L [s], K) of the Chebyshev blocks of a load whose lines lie within |μ| ≤ ``mu_max``
    [rad/s]: L = 2·BLOCK_X/μ_max, K the fewest terms with 4·Σ_{n≥K}(x/2)ⁿ/n! ≤ BLOCK_TOL
    (|J_n(y)| ≤ (y/2)ⁿ/n!; the tail after n > x/2 falls faster than a geometric series of
    ratio x/(2(n + 1))); None when there is no line but the mean (μ_max = 0)."""
    if not mu_max > 0:
        return None
    x, term, n = BLOCK_X, 1.0, 0
    while not (n + 1 > x / 2 and 4 * term / (1 - x / (2 * (n + 1))) <= BLOCK_TOL):
        n += 1
        term *= x / (2 * n)
    return 2 * BLOCK_X / mu_max, n


class DriftLoad:
    """The per-step drift kernel of one body: F [N, N·m] (6,) from the components' complex
    amplitudes z (N,) at a step (``phasors``; global axes, about the reference point).

    Built once per sea state from the components (any order), the method (METHODS) and the
    data: ``mean`` a MeanDrift (or a QTF's diagonal), ``newman`` likewise, ``qtf`` a QTF;
    ``cutoff`` [rad/s] the largest |ω_i − ω_j| kept by ``qtf`` (inf: all); position (x, y) [m]
    the body's mean position (Newman's phases), g, depth the wave numbers'.  Cost per step:
    mean N·6, newman 2·N·6, qtf (D + 1)·N·6 complex products by the direct sum
    (``__call__``), 6·K plus (D + 1)·N·6·K/(steps in a block) by the blocks (``at``; module
    docstring)."""

    def __init__(self, method, comps: Components, data, cutoff=math.inf, position=(0.0, 0.0), g=9.81,
                 depth=math.inf):
        if method not in METHODS:
            raise WaveError("method", f"expected one of {', '.join(METHODS)}, found {method!r}")
        if not cutoff > 0:
            raise WaveError("cutoff", f"must be positive (inf: every pair), found {cutoff:g} rad/s")
        self.method = method
        w = np.asarray(comps.omega, float)
        beta = np.asarray(comps.direction, float)
        self.order = np.argsort(w, kind="stable")
        w, beta = w[self.order], beta[self.order]
        self.n = w.size
        if method == "qtf":
            if not isinstance(data, QTF):
                raise WaveError("method", "method = \"qtf\" needs a difference-frequency QTF (WAMIT .10d/.11d/.12d)")
            self._band(data, w, beta, cutoff)
            self._amplitude = np.asarray(comps.amplitude, float)[self.order]
            self._omega, self._phase = w, np.asarray(comps.phase, float)[self.order]
            self.plan = block_plan(min(cutoff, w[-1] - w[0]) if w.size > 1 else 0.0)
            if self.plan is not None:
                length, k = self.plan
                theta = (2 * np.arange(k) + 1) * math.pi / (2 * k)
                self._nodes = 0.5 * length * (1 + np.cos(theta))           # the first-kind nodes on [0, L]
                self._dct = (2.0 / k) * np.cos(np.outer(np.arange(k), theta))
                self._dct[0] *= 0.5                                      # F ≈ Σ_n c_n T_n(τ), c = dct @ F(nodes)
                self._degrees = np.arange(k)
            self._block, self._last = None, None
            return
        mean = data.diagonal() if isinstance(data, QTF) else data
        q = mean.at(w, beta)                                  # (N, 6) real
        # the tables act on z's floats [Re z_0, Im z_0, Re z_1, …] (one real product a step)
        if method == "mean":
            self.table = np.repeat(q, 2, axis=0)              # |z_k|² = Re² + Im²
            return
        k = wave_number(w, g, depth)
        b = np.radians(beta)
        shift = np.exp(-1j * k * (position[0] * np.cos(b) + position[1] * np.sin(b)))[:, None]
        table = np.empty((2 * w.size, 24))
        for col, s in ((0, np.sqrt(np.maximum(q, 0.0)) * shift), (12, np.sqrt(np.maximum(-q, 0.0)) * shift)):
            table[0::2, col:col + 6], table[1::2, col:col + 6] = s.real, -s.imag      # Re(z·s)
            table[0::2, col + 6:col + 12], table[1::2, col + 6:col + 12] = s.imag, s.real   # Im(z·s)
        self.table = table

    def _band(self, qtf, w, beta, cutoff):
        n = w.size
        if not qtf.bidirectional and np.any(np.abs((beta - beta[0] + 180.0) % 360.0 - 180.0) > DIRECTION_TOL):
            raise WaveError("spreading", SPREAD_REFUSED)
        if n > 1 and math.isfinite(cutoff):
            # the largest offset d with ω[k + d] − ω[k] ≤ cutoff for some k (ω sorted)
            d = max(int(np.max(np.searchsorted(w, w + cutoff * (1 + 1e-12), side="right") - 1 - np.arange(n))), 0)
        else:
            d = n - 1
        band = np.zeros((n, d + 1, 6), complex)              # [i, j − i]: Q(ω_i, ω_j), zero past the cut-off
        for off in range(d + 1):
            i = np.arange(n - off)
            j = i + off
            keep = (w[j] - w[i]) <= cutoff * (1 + 1e-12)
            if keep.any():
                band[i[keep], off] = qtf.at(w[i[keep]], w[j[keep]], beta[i[keep]], beta[j[keep]])
        band[:, 1:] *= 2.0                                    # the pair (j, i) is the conjugate: 2·Re
        flat = band.reshape(-1, 6)
        self.table = np.empty((2 * flat.shape[0], 6))          # rows [Re Q; −Im Q] interleaved like a complex
        self.table[0::2], self.table[1::2] = flat.real, -flat.imag   # array's floats: Re(p·Q) in one product
        self.offsets = d

    def __call__(self, z) -> np.ndarray:
        """(6,) [Fx, Fy, Fz, Mx, My, Mz] for the components' complex amplitudes z (N,): the
        direct sum."""
        z = np.ascontiguousarray(np.asarray(z, dtype=complex)[self.order])
        if self.method == "mean":
            v = z.view(np.float64)
            return (v * v) @ self.table
        if self.method == "newman":
            p = z.view(np.float64) @ self.table               # Re, Im of Σ z·√Q⁺ and of Σ z·√Q⁻
            p *= p
            return p[:6] + p[6:12] - p[12:18] - p[18:]
        return self._sums(z[None, :])[0]

    def _sums(self, z):
        """The QTF's direct sums Σ_i Σ_{d ≤ D} Re{band[i, d]·z_i·conj(z_{i+d})} (m, 6) for m rows
        of sorted complex amplitudes z (m, N)."""
        m, n, d = z.shape[0], self.n, self.offsets
        pad = np.zeros((m, n + d), complex)
        pad[:, :n] = np.conj(z)
        pairs = z[:, :, None] * np.lib.stride_tricks.sliding_window_view(pad, d + 1, axis=1)   # [., i, off]
        # einsum, not a matrix product: BLAS's threads fight for the cores of a busy machine (a
        # product of this shape was 10 to 50× slower on a loaded 2-core machine, as a batch's
        # workers load it), einsum's loop does not
        return np.einsum("mi,ij->mj", np.ascontiguousarray(pairs).reshape(m, -1).view(np.float64), self.table)

    def at(self, t, p) -> np.ndarray:
        """(6,) the un-ramped load at time t [s], ``p`` the components' phasors there (the
        direct sum's input): ``qtf`` by its Chebyshev block when the steps are short enough
        (module docstring; a pure function of t to BLOCK_TOL), the others directly."""
        if self.method != "qtf" or self.plan is None:
            return self(p)
        length, k = self.plan
        step, self._last = (abs(t - self._last) if self._last is not None else math.inf), t
        b = math.floor(t / length)
        if self._block is None or self._block[0] != b:
            if not (0 < step and k * step <= 0.5 * length):
                return self(p)                                   # long steps: a block would not pay
            times = b * length + self._nodes
            z = self._amplitude * np.exp(1j * (np.outer(times, self._omega) + self._phase))
            values = np.concatenate([self._sums(z[c:c + 16]) for c in range(0, k, 16)])
            self._block = (b, self._dct @ values)
        tau = min(max(2 * (t - b * length) / length - 1, -1.0), 1.0)
        return np.cos(self._degrees * math.acos(tau)) @ self._block[1]


def slow_drift_std(comps: Components, qtf: QTF, cutoff=math.inf):
    """(σ_qtf, σ_newman) (6,) [N, N·m]: the standard deviation about the mean of the full
    QTF's load and of Newman's on these components, in the frequency domain: for independent
    random phases the pairs i < j are uncorrelated lines of amplitude 2·a_i·a_j·|Q_ij|, so
    σ² = 2·Σ_{i<j} a_i²·a_j²·|Q_ij|², with Q_ij the QTF (``QTF.at``) or Newman's s·√(Q_ii·Q_jj)
    (0 for opposite signs; Q_kk the diagonal as ``DriftLoad`` reads it), over the pairs with
    |ω_i − ω_j| ≤ ``cutoff`` [rad/s] for both; a record's std tends to it when its lines are
    apart by more than 1/duration."""
    w, beta = np.asarray(comps.omega, float), np.asarray(comps.direction, float)
    order = np.argsort(w, kind="stable")
    w, beta, a2 = w[order], beta[order], np.asarray(comps.amplitude, float)[order] ** 2
    diag = qtf.diagonal().at(w, beta)                             # (N, 6) real
    var_q, var_n = np.zeros(6), np.zeros(6)
    for off in range(1, w.size):
        i = np.arange(w.size - off)
        j = i + off
        keep = (w[j] - w[i]) <= cutoff * (1 + 1e-12)
        if not keep.any():
            break
        i, j = i[keep], j[keep]
        weight = (a2[i] * a2[j])[:, None]
        var_q += 2 * np.sum(weight * np.abs(qtf.at(w[i], w[j], beta[i], beta[j])) ** 2, axis=0)
        same = np.sign(diag[i]) == np.sign(diag[j])
        var_n += 2 * np.sum(weight * np.where(same, np.abs(diag[i] * diag[j]), 0.0), axis=0)
    return np.sqrt(var_q), np.sqrt(var_n)
