"""Incident-wave kinematics: the undisturbed first-order (Airy) wave field at any point.

Not to be confused with physics/kinematics.py (rigid-body point kinematics).

Conventions (DESIGN.md, Waves; docs/waves.md, Kinematics)
---------------------------------------------------------
Global frame, z up from the mean water level, the components (a_k, ω_k, β_k, φ_k) of the scene's
one wave field (physics/waves.py ``Components``) and their per-step phasors p_k = a_k·e^{i(ω_k t + φ_k)}
(``waves.Phasors``, shared with the excitation), ramped: z_k = r(t)·p_k.  At a point (x, y, z)

    E_k = z_k·e^{−i k_k (x cos β_k + y sin β_k)}          (η = Σ Re E_k, in phase with the elevation)
    velocity      u_h = Σ ω_k·F_h,k(z)·Re E_k·(cos β_k, sin β_k)      w = −Σ ω_k·F_v,k(z)·Im E_k
    acceleration  a_h = −Σ ω_k²·F_h,k(z)·Im E_k·(cos β_k, sin β_k)   a_z = −Σ ω_k²·F_v,k(z)·Re E_k
    dynamic pressure  p_d = ρ·g·Σ F_p,k(z)·Re E_k          (total pressure p_d − ρ·g·z)

(local acceleration ∂u/∂t, linear theory: ∂η/∂t = −Σ ω_k·Im E_k, so w(0) = ∂η/∂t, the water rising
under a rising surface, and a_z < 0 under a crest), with the depth factors (depth h, ω² = g k tanh kh)

    F_h = cosh k(z+h) / sinh kh,  F_v = sinh k(z+h) / sinh kh,  F_p = cosh k(z+h) / cosh kh
    deep water (h = inf): F_h = F_v = F_p = e^{kz}

(evaluated as (e^{kz} ± e^{−k(z+2h)}) / (1 ∓ e^{−2kh}): no overflow for large kh).

Above the mean water level (``stretching``), for a point below the instantaneous surface z ≤ η:

- ``none``: the formulas above as they stand, F(z) at z > 0 (exponential growth);
- ``vertical``: the values at z = 0 (F(0)) for every 0 < z ≤ η;
- ``extrapolation``: linear from z = 0, F(z) = F(0) + z·F'(0):
  F_h = coth kh + k·z, F_v = 1 + k·z·coth kh, F_p = 1 + k·z·tanh kh (deep: 1 + k·z for all three);
- ``wheeler``: the whole column stretched to the instantaneous surface: F evaluated at
  z' = h·(z − η)/(h + η) (deep water: z' = z − η), for every z ≤ η (also below z = 0).

A point above the instantaneous surface (z > η), or below the sea bed (z < −h), is out of the
water: velocity, acceleration and pressure 0 (its elevation still η).  Outputs are ramped with
the excitation (z_k carries r(t)).

Cost per point per step: the horizontal factor e^{−ik·x} and the depth factors are N complex
exponentials and N exponentials, kept while the point does not move (a fixed point costs the
8 sums of N terms only); Wheeler's factors move with η every step.
"""
from __future__ import annotations

import math

import numpy as np

from .waves import STRETCHING, Components, wave_number
# the columns of ``WaveKinematics.at``'s rows
COLUMNS = ("velocity[1]", "velocity[2]", "velocity[3]", "acceleration[1]", "acceleration[2]", "acceleration[3]",
           "pressure", "elevation")


class WaveKinematics:
    """Airy kinematics of the components ``comps`` (see the module docstring).

    g [m/s²], depth [m] (inf: deep water; the depth the waves use), stretching one of
    STRETCHING.  ``at(p, r, points, rho)`` → (P, 8) rows [u (3) m/s, a (3) m/s², p_d Pa, η m]
    for the points (P, 3) [m, global], phasors p (``Phasors.at(t)``) and ramp r.
    """

    def __init__(self, comps: Components, g: float = 9.81, depth: float = math.inf, stretching: str = "none"):
        if stretching not in STRETCHING:
            raise ValueError(f"stretching must be one of {', '.join(STRETCHING)}, found {stretching!r}")
        self.stretching = stretching
        self.omega = np.asarray(comps.omega, dtype=float)
        b = np.radians(np.asarray(comps.direction, dtype=float))
        self.k = wave_number(self.omega, g, depth)
        self.kx, self.ky = self.k * np.cos(b), self.k * np.sin(b)
        self.cos, self.sin = np.cos(b), np.sin(b)
        self.g, self.depth = float(g), float(depth)
        self.w2 = self.omega ** 2
        # every output as one product: [F_h·E, F_v·E, F_p·E, E] (E as interleaved (re, im) floats,
        # each factor repeated for re and im) times this (8N × 8) weight matrix
        n = self.omega.size
        w = np.zeros((8 * n, 8))
        re, im = np.arange(0, 2 * n, 2), np.arange(1, 2 * n, 2)
        w[re, 0], w[re, 1] = self.omega * self.cos, self.omega * self.sin          # u_h: ω F_h Re E
        w[im, 3], w[im, 4] = -self.w2 * self.cos, -self.w2 * self.sin              # a_h: −ω² F_h Im E
        w[2 * n + im, 2], w[2 * n + re, 5] = -self.omega, -self.w2                 # w, a_z: −F_v (w = ∂η/∂t at 0)
        w[4 * n + re, 6] = 1.0                                                    # p_d / ρg: F_p Re E
        w[6 * n + re, 7] = 1.0                                                    # η
        self.weights = w
        if math.isinf(depth):
            self.coth = self.tanh = np.ones_like(self.k)
        else:
            self.tanh = np.tanh(self.k * depth)
            self.coth = 1.0 / self.tanh
        self._where = None   # the last points and their factors (a fixed point computes them once)

    def factors(self, z) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(F_h, F_v, F_p), each (P, N), at evaluation heights z (P,) [m] (the formulas as they stand)."""
        k = self.k[None, :]
        z = np.asarray(z, dtype=float)[:, None]
        e = np.exp(k * z)
        if math.isinf(self.depth):
            return e, e, e
        far = np.exp(-k * (z + 2 * self.depth))
        d = np.exp(-2 * k * self.depth)
        return (e + far) / (1 - d), (e - far) / (1 - d), (e + far) / (1 + d)

    def _above(self, z):
        """(F_h, F_v, F_p) at 0 < z by the chosen stretching (not Wheeler's)."""
        if self.stretching == "vertical":
            return self.factors(np.zeros_like(z))
        if self.stretching == "extrapolation":
            kz = self.k[None, :] * np.asarray(z, dtype=float)[:, None]
            return self.coth + kz, 1 + kz * self.coth, 1 + kz * self.tanh
        return self.factors(z)   # none: the formulas as they stand

    def horizontal(self, points) -> np.ndarray:
        """e^{−ik·x} (P, N) at the points' horizontal positions."""
        pts = np.asarray(points, dtype=float)
        return np.exp(-1j * (pts[:, 0:1] * self.kx + pts[:, 1:2] * self.ky))

    def at(self, p: np.ndarray, r: float, points, rho: float = 1025.0) -> np.ndarray:
        """(P, 8) [u (3), a (3), p_d, η] at the points (P, 3) for phasors p and ramp r."""
        pts = np.atleast_2d(np.asarray(points, dtype=float))
        z = pts[:, 2]
        if self._where is not None and np.array_equal(self._where[0], pts):
            _, h, stacked = self._where
        else:
            h, stacked = self.horizontal(pts), None
        e = h * (r * p)                          # E_k, (P, N)
        eta = e.real.sum(axis=1)
        if self.stretching == "wheeler":         # the factors move with η
            zs = z - eta if math.isinf(self.depth) else self.depth * (z - eta) / (self.depth + eta)
            stacked = self._stack(*self.factors(np.minimum(zs, 0.0)))
        elif stacked is None:
            below = z <= 0
            fh, fv, fp = (np.empty((z.size, self.k.size)) for _ in range(3))
            if below.any():
                fh[below], fv[below], fp[below] = self.factors(z[below])
            if (~below).any():
                fh[~below], fv[~below], fp[~below] = self._above(z[~below])
            stacked = self._stack(fh, fv, fp)
        self._where = (pts.copy(), h, stacked if self.stretching != "wheeler" else None)
        ev = e.view(float)                       # (P, 2N) interleaved (re, im)
        out = (stacked * ev[:, None, :]).reshape(ev.shape[0], -1).dot(self.weights)
        out[:, 6] *= rho * self.g
        out[:, 7] = eta
        dry = (z > eta) | (z < -self.depth)
        out[dry, :7] = 0.0
        return out

    @staticmethod
    def _stack(fh, fv, fp):
        """[F_h, F_v, F_p, 1], each repeated for (re, im): (P, 4, 2N)."""
        return np.stack((np.repeat(fh, 2, axis=1), np.repeat(fv, 2, axis=1), np.repeat(fp, 2, axis=1),
                         np.ones((fh.shape[0], 2 * fh.shape[1]))), axis=1)


class Water:
    """The incident wave field the effects of one FMU see at its current step.

    ``kinematics`` (WaveKinematics) and ``phasors`` (waves.Phasors, advanced by the FMU to the
    step's time before its effects run), ρ [kg/m³].  ``at(x, y, z)`` → (8,) [u (3) m/s,
    a (3) m/s², p_d Pa, η m] at a global point; ``wet(row, z)``: the point is below the
    instantaneous surface (z ≤ η) and above the sea bed.
    """

    def __init__(self, kinematics: WaveKinematics, phasors, rho: float = 1025.0):
        self.kinematics, self.phasors, self.rho = kinematics, phasors, float(rho)

    def at(self, x: float, y: float, z: float) -> np.ndarray:
        ph = self.phasors
        return self.kinematics.at(ph.p, ph.ramp_factor, [(x, y, z)], self.rho)[0]

    def wet(self, row, z: float) -> bool:
        return -self.kinematics.depth <= z <= row[7]
