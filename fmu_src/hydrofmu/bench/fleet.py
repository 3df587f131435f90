"""A row of identical floating bodies coupled by SIMO hydrodynamic interaction: the scene
and deck for the FMU path, and the monolithic Cummins solution (scipy) it is measured
against.

Body k (1-based, name ``b<k>``) sits at y = (k − 1)·spacing.  Each has its own infinite-
frequency added mass and radiation memory (self-coupling), and every pair (i < j) is coupled
with the cross terms scaled by 1/(j − i) (interaction fades with distance).  Kernels are
h(t) = c·e^(−a·t)·cos(ω·t), sampled at TIMDEL for the deck; the monolithic solution carries
them exactly as complex first-order states, so its only error is scipy's tolerance:

    (M + A∞)·ẍ + Σ ∫ h(t − τ)·ẋ(τ) dτ + K·x = 0,   x(0) = 0,  ẋ(0) = V0 (body 1 only)

with the element rule of physics/coupling.py: block (i, j) of a cross coupling loads dof i
of the first body from dof j of the second, and its transpose the other way.
"""
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.integrate import solve_ivp

from ..decks.simo import format_coupling, write_couplings

M, INERTIA = 1.0e6, [1.0e8, 2.0e8, 2.0e8]
# 1000 t body, 20 m × 20 m waterplane: heave K = ρ·g·A_wp ≈ 4e6 N/m (heave period ≈ 4 s)
K = np.array([1.0e5, 1.2e5, 4.0e6, 1.0e9, 1.0e9, 1.0e9])
SELF_AM = np.diag([1.0e5, 5.0e5, 8.0e5, 0, 0, 0])
CROSS_AM = np.zeros((6, 6))
CROSS_AM[1, 1], CROSS_AM[2, 2], CROSS_AM[1, 2] = 2.0e5, 1.0e5, 5.0e4
# {(IDOF_A, IDOF_B): (c [N·s/m], a [1/s], ω [rad/s])}
SELF_K = {(1, 1): (1.0e5, 0.6, 1.0), (2, 2): (3.0e5, 0.5, 1.2), (3, 3): (6.0e5, 0.8, 1.5)}
CROSS_K = {(2, 2): (1.0e5, 0.5, 0.8), (3, 3): (1.5e5, 0.7, 1.1), (2, 3): (4.0e4, 0.6, 0.9)}
V0 = [0.1, 0.5, 0.2, 0.0, 0.0, 0.0]   # body 1 released with surge, sway and heave velocity
TIMDEL, LENGTH = 0.1, 40.0


def sampled(c, a, w, timdel=TIMDEL, length=LENGTH):
    """c·e^(−a·t)·cos(ω·t) at t = 0, TIMDEL, …, length."""
    t = np.arange(int(round(length / timdel)) + 1) * timdel
    return c * np.exp(-a * t) * np.cos(w * t)


@dataclass
class Fleet:
    """``n`` bodies ``spacing`` [m] apart (see the module docstring)."""
    n: int = 2
    spacing: float = 40.0

    @property
    def names(self):
        return [f"b{k + 1}" for k in range(self.n)]

    def pairs(self):
        """(coupling name, i, j, scale) for every self (i = j) and cross (i < j) coupling."""
        out = [(f"S{i + 1}", i, i, 1.0) for i in range(self.n)]
        out += [(f"C{i + 1}_{j + 1}", i, j, 1.0 / (j - i)) for i in range(self.n) for j in range(i + 1, self.n)]
        return out

    def write_deck(self, path):
        groups = []
        for name, i, j, scale in self.pairs():
            am, terms = (SELF_AM, SELF_K) if i == j else (scale * CROSS_AM, CROSS_K)
            kernels = {ij: sampled(scale * c if i != j else c, a, w) for ij, (c, a, w) in terms.items()}
            groups.append(format_coupling(name, f"B{i + 1}", f"B{j + 1}", am, kernels, TIMDEL,
                                          ("hydrofmu benchmark fleet", "h(t) = c exp(-a t) cos(w t)")))
        return write_couplings(path, groups)

    def scene(self, folder, run="", coupling="", mode="export", name="fleet"):
        """Write the deck and the scene into ``folder``; returns the scene path.
        ``run``: lines of the [run] table; ``coupling``: extra lines of every coupling."""
        folder = Path(folder)
        folder.mkdir(parents=True, exist_ok=True)
        deck = self.write_deck(folder / f"{name}.sim")
        mapping = ", ".join(f'B{k + 1} = "{b}"' for k, b in enumerate(self.names))
        text = [f'[scene]\nname = "{name}"\n', f"[run]\n{run}\n"]
        for k, b in enumerate(self.names):
            text.append(f"[bodies.{b}]\nposition = [0.0, {k * self.spacing}, 0.0]\n"
                        + (f"velocity = {V0}\n" if k == 0 else "")
                        + f"mass = {M}\ninertia = {INERTIA}\nstiffness = {K.tolist()}\n"
                        + f'acceleration_loads = "{mode}"\n')
        for cname, _, _, _ in self.pairs():
            text.append(f'[[couplings]]\ndeck = "{deck.name}"\ncoupling = "{cname}"\n'
                        f"bodies = {{ {mapping} }}\n{coupling}\n")
        path = folder / f"{name}.toml"
        path.write_text("\n".join(text))
        return path

    def monolithic(self, t_eval):
        """Displacements (n_times, 6n) of the Cummins equations above (scipy DOP853,
        rtol 1e-10): dofs of body 1, then body 2, …"""
        n = 6 * self.n
        mass = np.diag(np.tile([M] * 3 + INERTIA, self.n))
        stiff = np.diag(np.tile(K, self.n))
        terms = []                         # (loaded dof, driving dof, c, a, ω)
        for _, i, j, scale in self.pairs():
            if i == j:
                mass[6 * i:6 * i + 6, 6 * i:6 * i + 6] += SELF_AM
                terms += [(6 * i + p - 1, 6 * i + q - 1, c, a, w) for (p, q), (c, a, w) in SELF_K.items()]
            else:
                mass[6 * i:6 * i + 6, 6 * j:6 * j + 6] += scale * CROSS_AM     # load on i from j's acceleration
                mass[6 * j:6 * j + 6, 6 * i:6 * i + 6] += scale * CROSS_AM.T
                for (p, q), (c, a, w) in CROSS_K.items():
                    terms += [(6 * i + p - 1, 6 * j + q - 1, scale * c, a, w),
                              (6 * j + q - 1, 6 * i + p - 1, scale * c, a, w)]
        inv = np.linalg.inv(mass)
        row, col = (np.array([t[k] for t in terms], int) for k in (0, 1))
        c, a, w = (np.array([t[k] for t in terms]) for k in (2, 3, 4))
        pole = -a + 1j * w

        def rhs(_, y):
            x, v, z = y[:n], y[n:2 * n], y[2 * n:].view(complex)
            force = -stiff @ x - np.bincount(row, weights=c * z.real, minlength=n)  # Re(c·z)
            dz = pole * z + v[col]                                                  # z' = (−a + iω)·z + v
            return np.concatenate([v, inv @ force, dz.view(float)])

        y0 = np.concatenate([np.zeros(n), V0, np.zeros(n - 6), np.zeros(2 * len(terms))])
        sol = solve_ivp(rhs, (0, t_eval[-1]), y0, t_eval=t_eval, rtol=1e-10, atol=1e-12, method="DOP853")
        return sol.y[:n].T

    def displacements(self, result):
        """(n_times, 6n) pose change of every body from a co-simulation Result, same
        layout as ``monolithic`` (position then attitude per body)."""
        out = np.hstack([np.hstack([result.motion(b, "position", 3), result.motion(b, "attitude", 3)])
                         for b in self.names])
        return out - out[0]


def nrms(got, ref):
    """Normalised RMS error per column: √mean((got − ref)²) / (max ref − min ref)."""
    return np.sqrt(np.mean((got - ref) ** 2, axis=0)) / np.ptp(ref, axis=0)
