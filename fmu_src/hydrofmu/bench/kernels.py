"""Realistic retardation kernels and body motions for the memory benchmarks.

Kernels come from radiation damping curves by the cosine transform that links them
(Ogilvie): h(t) = (2/π)·∫₀^∞ B(ω)·cos(ωt) dω  [N·s/m per unit velocity, t ≥ 0].

- Own damping: B(ω) = b·(ω/ωp)²·exp(1 − (ω/ωp)²), a smooth hump peaking at ωp with
  B ∝ ω² at low frequency (no memory of a steady velocity: ∫h = B(0) = 0 — what panel
  codes give for most dofs).
- Interaction between two bodies a distance d apart: the same hump times cos(k·d) with the
  deep-water wave number k = ω²/g, so the damping changes sign with frequency and the
  kernel carries a dispersive echo arriving after the group travel time 2ωd/g — the
  feature that makes interaction kernels long and hard to fit with few poles.
"""
import numpy as np

G = 9.81


def damping_kernel(t, b, omega_p, distance=0.0, g=G):
    """h(t) of the damping curve above (module docstring) at times t [s].

    b [N·s/m]: peak damping; omega_p [rad/s]: peak frequency; distance [m]: 0 for a body's
    own damping, else the separation of two interacting bodies.
    """
    t = np.asarray(t, float)
    w_max = 6.0 * omega_p                                   # B < 1e-14·b beyond
    dw = min(omega_p / 200.0, np.pi / (4.0 * max(t.max(initial=0.0), 1.0)))   # no alias in t
    w = np.arange(0.0, w_max + dw, dw)
    curve = b * (w / omega_p) ** 2 * np.exp(1.0 - (w / omega_p) ** 2) * np.cos(w ** 2 * distance / g)
    weight = np.full(w.size, dw)
    weight[[0, -1]] *= 0.5                                   # trapezoid rule
    out = np.empty(t.size)
    for k in range(0, t.size, 500):                          # 500 rows at a time: bounded memory
        out[k:k + 500] = np.cos(np.outer(t[k:k + 500], w)) @ (curve * weight)
    return 2.0 / np.pi * out


def coupling_kernels(timdel, lags, distance=35.0, seed=1, stretch=1.0):
    """A full 6×6 interaction kernel matrix {(i, j): samples} (0-based), ``lags`` samples at
    ``timdel`` [s]: every element a damping_kernel with its own peak and scale (dofs of a
    barge pair: translations ~1e5 N·s/m, rotations ~1e9 N·m·s).  ``stretch`` scales time
    (h(t/stretch)): the same family decaying over a longer or shorter window."""
    rng = np.random.default_rng(seed)
    t = timdel * np.arange(lags) / stretch
    scale = np.array([1e5, 1e5, 3e5, 3e7, 3e8, 3e8])
    out = {}
    for i in range(6):
        for j in range(6):
            b = np.sqrt(scale[i] * scale[j]) * rng.uniform(0.3, 1.0) * (1.0 if i == j else 0.4)
            out[(i, j)] = damping_kernel(t, b, rng.uniform(0.5, 1.2), distance)
    return out


def irregular_velocity(t, seed=2, hs=3.0, tp=10.0, n=60):
    """(len(t), 6) velocities [m/s, rad/s] of a body in an irregular sea: sums of n random-
    phase harmonics over 0.3…2 rad/s with a JONSWAP-like spectrum (significant height hs
    [m], peak period tp [s]), rotations scaled by 0.02 rad/m."""
    rng = np.random.default_rng(seed)
    w = np.linspace(0.3, 2.0, n)
    wp = 2 * np.pi / tp
    spec = w ** -5 * np.exp(-1.25 * (wp / w) ** 4) * 3.3 ** np.exp(-(w - wp) ** 2 / (2 * 0.08 ** 2 * wp ** 2))
    amp = np.sqrt(2 * spec * (w[1] - w[0]))
    amp *= hs / (4 * np.sqrt(np.sum(amp ** 2) / 2))           # Hs = 4·√m0
    out = np.empty((np.size(t), 6))
    for d in range(6):
        phase = rng.uniform(0, 2 * np.pi, n)
        out[:, d] = (np.sin(np.outer(t, w) + phase) * (w * amp)).sum(axis=1) * (1.0 if d < 3 else 0.02)
    return out
