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
  by their offset d = j − i: a step costs (D + 1)·N·6 complex products, D the largest offset
  within the cut-off (N²/2·6 without one).  Long-crested seas need unidirectional pairs
  (β, β) around the sea's direction; a spread sea needs the bidirectional grid (every
  (β1, β2) of the file's headings): a unidirectional QTF in a spread sea is refused (the
  cross-direction pairs are not in the data, and no rule makes them up defensibly: use
  ``newman``, which says its approximation).

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


class MeanDrift:
    """Mean drift per unit amplitude squared Q(ω, ω; β, β) [N/m², N·m/m²] of one body.

    omega (nω,) [rad/s] increasing; directions (nβ,) [deg]; values (nω, nβ, 6) real.
    ``at(ω, β)`` interpolates linearly in ω and β (physics.waves.TransferFunction's rules:
    across 360° when the directions go round the circle, an error outside the data)."""

    def __init__(self, omega, directions, values):
        values = np.asarray(values, dtype=float)
        self.table = TransferFunction(omega, directions, values.astype(complex))
        self.omega = self.table.omega

    @property
    def window(self):
        return self.table.window

    def at(self, omega, beta):
        """(n, 6) real for n components ω [rad/s], β [deg]."""
        return self.table.at(omega, beta).real

    def c_params(self):
        """drift.c's data: [nω, ω, nβ, closed, directions, values (nω, nβ, 6)]."""
        t = self.table
        return ([t.omega.size] + t.omega.tolist() + [t.directions.size, float(t.closed)] + t.directions.tolist()
                + t.values.real.ravel().tolist())


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
        self.local = grid * np.exp(1j * (kd[:, None, :, None, None] - kd[None, :, None, :, None]))

    @property
    def window(self):
        return float(self.omega[0]), float(self.omega[-1])

    def c_params(self):
        """drift.c's data: [nω, ω, nh, closed, bidirectional, nu, closed (unidirectional), the
        unidirectional headings' indices (nu), headings (nh), x, y, Re Q, Im Q (nω, nω, nh, nh, 6)
        referred to the origin, 0 where the file has no pair]."""
        m = np.flatnonzero(self.uni)
        sub = _headings(self._dir.directions[m]) if m.size else None
        q = np.nan_to_num(self.grid)
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
        ki = wave_number(wi, self.g, self.depth)
        kj = wave_number(wj, self.g, self.depth)
        x, y = self.position
        di = x * np.cos(np.radians(bi)) + y * np.sin(np.radians(bi))
        dj = x * np.cos(np.radians(bj)) + y * np.sin(np.radians(bj))
        return out * np.exp(-1j * (ki * di - kj * dj))[:, None]


class DriftLoad:
    """The per-step drift kernel of one body: F [N, N·m] (6,) from the components' complex
    amplitudes z (N,) at a step (``phasors``; global axes, about the reference point).

    Built once per sea state from the components (any order), the method (METHODS) and the
    data: ``mean`` a MeanDrift (or a QTF's diagonal), ``newman`` likewise, ``qtf`` a QTF;
    ``cutoff`` [rad/s] the largest |ω_i − ω_j| kept by ``qtf`` (inf: all); position (x, y) [m]
    the body's mean position (Newman's phases), g, depth the wave numbers'.  Cost per step:
    mean N·6, newman 2·N·6, qtf (D + 1)·N·6 complex products (module docstring)."""

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
        self._pad = np.zeros(n + d, complex)

    def __call__(self, z) -> np.ndarray:
        """(6,) [Fx, Fy, Fz, Mx, My, Mz] for the components' complex amplitudes z (N,)."""
        z = np.ascontiguousarray(np.asarray(z, dtype=complex)[self.order])
        if self.method == "mean":
            v = z.view(np.float64)
            return (v * v) @ self.table
        if self.method == "newman":
            p = z.view(np.float64) @ self.table               # Re, Im of Σ z·√Q⁺ and of Σ z·√Q⁻
            p *= p
            return p[:6] + p[6:12] - p[12:18] - p[18:]
        n, d = self.n, self.offsets
        self._pad[:n] = np.conj(z)
        pairs = z[:, None] * np.lib.stride_tricks.sliding_window_view(self._pad, d + 1)   # [i, off] z_i·conj(z_{i+off})
        # (einsum: one pass over the table; a BLAS gemv of this tall shape was 10× slower on a
        # busy 2-core machine, its threads fighting for the cores)
        return np.einsum("i,ij->j", np.ascontiguousarray(pairs).ravel().view(np.float64), self.table)
