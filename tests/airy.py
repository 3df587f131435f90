"""Airy waves for the tests' references, derived from the velocity potential instead of typed
again output by output (the suite once pinned a sign error that way, issue 37).

One component, θ = ω·t − k·(x cos β + y sin β) + φ0, depth h (deep water: the limits):

    φ = −(g·a/ω) · cosh k(z + h)/cosh kh · sin θ

the potential of the wave η = a·cos θ: Laplace's equation (k² − k² = 0), no flow through the
bed (∂φ/∂z = 0 at z = −h: sinh 0), the linear dynamic surface condition η = −(1/g)·∂φ/∂t at
z = 0 and, with ω² = g·k·tanh kh (solved here by Newton's method), the kinematic one
∂η/∂t = ∂φ/∂z at z = 0.  ``check_potential`` holds those four by differences.  Everything else
follows from it by differentiation, not by formulas: u = ∇φ and p_d = −ρ·∂φ/∂t by complex-step
derivatives (f' = Im f(x + iε)/ε: exact to rounding), the local acceleration a = ∂u/∂t by an
8th-order central difference in time (error (ωh)⁸/630 ≈ 1e-15 and round-off ~1e-14 of ω·|u| at
h = 0.02 s), η = −(1/g)·∂φ/∂t at z = 0.
"""
import math

import numpy as np

G, RHO = 9.81, 1025.0
STEP = 1e-30                                   # the complex step
DT = 0.02                                      # s: the time difference's step
WEIGHTS = np.array([1 / 280, -4 / 105, 1 / 5, -4 / 5, 0.0, 4 / 5, -1 / 5, 4 / 105, -1 / 280])


def wave_number(omega, depth, g=G):
    """k of ω² = g·k·tanh(k·h) (Newton's method; deep water ω²/g)."""
    omega = np.asarray(omega, dtype=float)
    k = omega ** 2 / g
    if math.isinf(depth):
        return k
    k = k / np.sqrt(np.tanh(k * depth))
    for _ in range(60):
        k = k - (g * k * np.tanh(k * depth) - omega ** 2) / (g * np.tanh(k * depth) + g * k * depth / np.cosh(k * depth) ** 2)
    return k


class Airy:
    """The potential of components (a, ω, β [deg], φ0 [rad]) at depth h, ramp ``r``."""

    def __init__(self, amplitude, omega, direction, phase, depth=math.inf, g=G, rho=RHO):
        self.a, self.w = np.atleast_1d(amplitude).astype(float), np.atleast_1d(omega).astype(float)
        b = np.radians(np.atleast_1d(direction).astype(float))
        self.cb, self.sb, self.phase = np.cos(b), np.sin(b), np.atleast_1d(phase).astype(float)
        self.depth, self.g, self.rho = float(depth), g, rho
        self.k = wave_number(self.w, depth, g)

    @classmethod
    def of(cls, comps, depth=math.inf):
        """From a physics.waves.Components."""
        return cls(comps.amplitude, comps.omega, comps.direction, comps.phase, depth)

    def phi(self, x, y, z, t):
        """φ at arrays of x, y, z, t (broadcast; complex allowed: the complex step)."""
        x, y, z, t = (np.asarray(v)[..., None] for v in (x, y, z, t))
        theta = self.w * t - self.k * (x * self.cb + y * self.sb) + self.phase
        if math.isinf(self.depth):
            decay = np.exp(self.k * z)
        else:
            decay = np.cosh(self.k * (z + self.depth)) / np.cosh(self.k * self.depth)
        return np.sum(-self.g * self.a / self.w * decay * np.sin(theta), axis=-1)

    def d(self, axis, x, y, z, t):
        """∂φ/∂(x, y, z, t)[axis] by the complex step (t may be an array)."""
        args = [np.asarray(v, dtype=complex) for v in (x, y, z, t)]
        args[axis] = args[axis] + 1j * STEP
        return self.phi(*args).imag / STEP

    def velocity(self, x, y, z, t):
        """u = ∇φ, (…, 3) for the times t (…)."""
        return np.stack([self.d(i, x, y, z, t) for i in range(3)], axis=-1)

    def at(self, x, y, z, t, r=1.0):
        """[u (3), a (3), p_d, η] at a point (as WaveKinematics.at's row), ramp ``r``."""
        u = self.velocity(x, y, z, t + (np.arange(9) - 4) * DT)
        acc = WEIGHTS @ u / DT
        pressure = -self.rho * self.d(3, x, y, z, t)
        eta = -self.d(3, x, y, 0.0, t) / self.g
        return r * np.r_[u[4], acc, pressure, eta]


def check_potential(airy, points, times, tol=1e-6):
    """Laplace's equation, the bed and the two linear surface conditions of ``airy``'s φ, by
    central differences (step 1e-3) at the points and times, to ``tol`` of each term's scale."""
    h = 1e-3
    scale = float(np.sum(airy.g * airy.a / airy.w * airy.k ** 2))
    for t in times:
        for x, y, z in points:
            lap = sum((airy.d(i, *(np.add((x, y, z), np.eye(3)[i] * h)), t)
                       - airy.d(i, *(np.subtract((x, y, z), np.eye(3)[i] * h)), t)) / (2 * h) for i in range(3))
            assert abs(lap) <= tol * scale, ("Laplace", lap)
        w0 = airy.d(2, 0.3, -0.2, 0.0, t)
        detadt = -(airy.d(3, 0.3, -0.2, 0.0, t + h) - airy.d(3, 0.3, -0.2, 0.0, t - h)) / (2 * h) / airy.g
        assert abs(w0 - detadt) <= tol * scale / airy.k.min(), ("kinematic surface condition", w0, detadt)
        if not math.isinf(airy.depth):
            assert abs(airy.d(2, 0.3, -0.2, -airy.depth, t)) <= 1e-12 * scale / airy.k.min(), "bed"
