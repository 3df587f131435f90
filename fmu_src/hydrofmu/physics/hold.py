"""How the dynamics partner's load hold damps (or drives) a mode whose restoring is a load input.

A load FMU's restoring load (BEM hydrostatics, a mooring effect) reaches the dynamics as an
input sampled at the communication points t_k = k·h and held over [t_k, t_k+1] (Gauss–Seidel:
F_k = F(x_k)).  For a mode x = e^{iωt} of natural frequency ω the held signal's component
at ω, averaged over a step (u = s/h ∈ [0, 1], a = ω·h), is F·g(a) with

- constant hold: g = mean(e^{−iau}) ≈ 1 − i·a/2: the load lags by h/2;
- linear hold (the slope over the last step, F_k + (F_k − F_k−1)·s/h):
  g = mean(e^{−iau}·(1 + (1 − e^{−ia})·u)) ≈ 1 + 5a²/12 − i·a³/3.

A restoring −C·x lagging by τ acts as a damping −C·τ·ẋ of the wrong sign: the mode's damping
ratio changes by Δζ = −ω·τ/2 (C = m·ω²), so

    constant hold:  Δζ = −ω·h/4            linear hold:  Δζ = −(ω·h)³/6

per mode, whatever the mass.  A body whose only damping is radiation (1–2 % of critical in
roll and pitch for a spar or a cylinder) goes unstable with the constant hold once ω·h/4
exceeds it (ω = 0.5 rad/s, h = 0.1 s: −1.25 %).  tests/test_hold.py measures the growth
rate of a free pitch oscillation with BEM hydrostatics and no other damping against ω²·h/4 and
ω·(ω·h)³/6; ``hydrofmu bench --part hold`` sweeps steps and scenes.  Frequencies in rad/s,
steps in s.
"""
from __future__ import annotations

import numpy as np

HOLDS = ("constant", "linear")
# the hold's damping change is kept below this share of critical by the default step: a tenth
# of the lightest radiation damping of roll/pitch we measured (1 %, docs/tuning.md)
ZETA_BUDGET = 1e-3
# the steps a default is chosen from [s], largest first (the preset-free default is the first)
DEFAULT_STEPS = (0.1, 0.05, 0.02, 0.01)


def damping_change(omega, step, hold):
    """Δζ (negative: the hold drives the mode) of a mode of natural frequency ``omega``
    [rad/s] whose restoring is held over steps ``step`` [s] (Gauss–Seidel exchange)."""
    a = np.asarray(omega, dtype=float) * step
    if hold == "constant":
        return -a / 4
    if hold == "linear":
        return -a ** 3 / 6
    raise ValueError(f"hold must be one of {HOLDS}, found {hold!r}")


def held_gain(a, hold, n=2001):
    """The held signal's complex gain g(a) at ω (a = ω·h), averaged over a step numerically
    (the exact form of the series in the module docstring)."""
    u = np.linspace(0.0, 1.0, n)
    f = np.exp(-1j * a * u) * (1.0 if hold == "constant" else 1.0 + (1.0 - np.exp(-1j * a)) * u)
    return np.trapezoid(f, u) if hasattr(np, "trapezoid") else np.trapz(f, u)


def natural_frequencies(mass, stiffness):
    """Undamped natural frequencies [rad/s] (ascending) of M·ẍ + C·x = 0 over the modes with
    positive stiffness; ``mass`` (6, 6) [kg, kg·m, kg·m²] (without added mass: the
    frequencies are then upper bounds), ``stiffness`` (6, 6)."""
    m = np.asarray(mass, dtype=float)
    c = np.asarray(stiffness, dtype=float)
    w2 = np.linalg.eigvals(np.linalg.solve(m, c)).real
    return np.sqrt(np.sort(w2[w2 > 1e-9 * max(1.0, np.abs(w2).max())]))


def stable_step(omega_max, stop, steps=DEFAULT_STEPS, hold="linear", budget=ZETA_BUDGET):
    """The largest of ``steps`` that divides ``stop`` and keeps |Δζ| of the fastest lagged mode
    (``omega_max`` [rad/s]) within ``budget``; the smallest of them when none does."""
    fits = [h for h in steps if stop >= h and abs(stop / h - round(stop / h)) < 1e-9 * max(1.0, stop / h)]
    fits = fits or [min(steps)]
    for h in sorted(fits, reverse=True):
        if abs(damping_change(omega_max, h, hold)) <= budget:
            return h
    return min(fits)
