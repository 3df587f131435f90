"""Hydrodynamic coupling between two bodies A and B (SIMO `HYDRodynamic COUPling DATA`).

Loads (README, Conventions: SIMO hydrodynamic coupling), 6-vectors [force N; moment N·m] on each body, in the same axes and about the
same reference point as the 6-vector velocities v [m/s, rad/s] and accelerations a [m/s², rad/s²]:

    F_B = −A∞ᵀ·a_A − ∫ hᵀ(t − τ)·v_A(τ) dτ
    F_A = −A∞·a_B  − ∫ h(t − τ)·v_B(τ) dτ

Element form (manual): A∞[i−1, j−1] = AM_ij couples dof i of A with dof j of B, so an
acceleration of A in dof i gives −AM_ij·a_A,i on B in dof j and an acceleration of B in dof j
gives −AM_ij·a_B,j on A in dof i; the kernel of block (IDOF_A = i, IDOF_B = j) does the same
with velocities.  Side 'A' is the load on A (driven by B's motion), side 'B' the load on B
(driven by A's motion).

Self-coupling (body A = body B): the body's own infinite-frequency added mass and radiation
memory, applied once: F = −A∞·a − ∫ h(t − τ)·v(τ) dτ (A∞ symmetric; only side 'A').

Acceleration loads follow the hydrofmu modes: ``mass(side)`` is the 6×6 block the dynamics
puts in its mass matrix (rows: the loaded body, columns: the driving body) in `export` mode;
``acceleration_load`` applies it as a force in `explicit` mode, where ``stability_indicator``
tells whether the staggered exchange can converge.
"""
import warnings

import numpy as np

from .memory import Convolution, MemoryFitWarning, StateSpace


class Coupling:
    """Loads of one hydrodynamic coupling between bodies A and B, from plain arrays.

    added_mass: A∞ (6×6, ``added_mass[i−1, j−1]`` couples dof i of A with dof j of B)
    [kg, kg·m, kg·m²]; timdel [s]: kernel sample spacing (None without kernels); kernels:
    {(IDOF_A, IDOF_B): samples at s = 0, TIMDEL, …} (1-based).  ``own``: self-coupling
    (A is B: only side 'A').  method: 'convolution' (exact for piecewise-linear velocity,
    ``memory_length`` [s] may truncate the kernels) or 'state_space' (kernels realised to
    normalised RMS error ≤ tol, or at ``order``; see ``memory.realise``; ``fits``: stored
    {(IDOF_A, IDOF_B): Realisation} to use instead).  v0_a, v0_b: velocities at the start.
    A state-space realisation that misses ``tol`` (or none usable, ``memory.realise``) is not
    used: the coupling then steps the exact convolution (``method`` says which; ``fallback``
    why, "" when none) and says so once in a ``MemoryFitWarning``.
    ``name``, ``bodies``: labels (the names ``target``/``source`` return).

    ``memory[side]``: the retardation evaluator of that side: ``advance(dt, v_source)`` moves
    it by dt [s] to the source body's new velocity and returns the memory load −∫ h·v at the
    new time [N, N·m] (the one stepping signature, see ``memory``).  ``fits``: for 'state_space', {(IDOF_A, IDOF_B): Realisation} (order, error)
    shared by both sides.
    """

    def __init__(self, added_mass, timdel=None, kernels=None, method="convolution", tol=0.002, order=None,
                 memory_length=None, v0_a=None, v0_b=None, *, own=False, name="", bodies=("A", "B"), fits=None):
        self.name, (self.body_a, self.body_b) = name, bodies
        self.self_coupling = own
        self.sides = ("A",) if own else ("A", "B")
        am = np.array(added_mass, float).reshape(6, 6)
        self._mass = {"A": am, "B": am.T.copy()}
        k_a = {(i - 1, j - 1): np.asarray(h, float) for (i, j), h in (kernels or {}).items()}
        kernels = {"A": k_a, "B": {(j, i): h for (i, j), h in k_a.items()}}   # hᵀ for side B
        v0 = {"A": v0_a if own else v0_b, "B": v0_a}
        self.fits = {}
        self.memory = {}
        self.fallback = ""
        if method == "state_space":
            stored = {(i - 1, j - 1): f for (i, j), f in (fits or {}).items()} or None
            a = StateSpace(k_a, timdel, shape=(6, 6), v0=v0["A"], tol=tol, order=order,
                           memory_length=memory_length, fits=stored)
            if a.missed:   # a realisation that misses what was asked: the exact convolution instead
                self.fallback = "; ".join(f"kernel ({i + 1}, {j + 1}): {why}" for (i, j), why in sorted(a.missed.items()))
                warnings.warn(MemoryFitWarning(f"coupling {name or bodies}: state-space memory not used, "
                                               f"convolution instead: {self.fallback}"), stacklevel=2)
                method = "convolution"
            else:
                self.memory["A"] = a
                self.fits = {(i + 1, j + 1): f for (i, j), f in a.fits.items()}
                if "B" in self.sides:                  # the same realisations, transposed
                    self.memory["B"] = StateSpace(kernels["B"], timdel, shape=(6, 6), v0=v0["B"],
                                                  fits={(j, i): f for (i, j), f in a.fits.items()})
        if method == "convolution":
            for s in self.sides:
                self.memory[s] = Convolution(kernels[s], timdel, shape=(6, 6), v0=v0[s],
                                             memory_length=memory_length)
        elif method != "state_space":
            raise ValueError(f"method must be 'convolution' or 'state_space', not {method!r}")
        self.method = method

    @classmethod
    def from_deck(cls, data, *args, **kwargs):
        """The coupling of a deck record (``decks.simo.CouplingData``); further arguments as
        for the constructor."""
        return cls(data.added_mass, data.timdel, data.kernels, *args, own=data.body_a == data.body_b,
                   name=data.name, bodies=(data.body_a, data.body_b), **kwargs)

    def _side(self, side):
        if side not in self.sides:
            raise ValueError(f"side must be one of {self.sides}, not {side!r}")
        return side

    def target(self, side):
        """The body that side's load acts on."""
        return self.body_a if self._side(side) == "A" else self.body_b

    def source(self, side):
        """The body whose velocity and acceleration drive that side's load."""
        return self.body_b if self._side(side) == "A" else self.body_a

    def mass(self, side):
        """6×6 added-mass block of that side: load = −mass(side)·a_source.
        'A': A∞ (rows dof of A, columns dof of B); 'B': A∞ᵀ."""
        return self._mass[self._side(side)].copy()

    def acceleration_load(self, side, a_source):
        """−mass(side)·a_source [N, N·m] (explicit mode)."""
        return -self._mass[self._side(side)] @ np.asarray(a_source, float)

    def state(self):
        """Everything needed to continue exactly (plain lists per side)."""
        return {s: self.memory[s].state() for s in self.sides}

    def set_state(self, state):
        for s in self.sides:
            self.memory[s].set_state(state[s])


def stability_indicator(m_a, a_aa, a_ab, m_b, a_bb, a_ba):
    """Spectral radius of G = (M_A + A_AA)⁻¹·A_AB·(M_B + A_BB)⁻¹·A_BA.

    m_a, m_b: rigid-body mass matrices; a_aa, a_bb: each body's own added mass (in its mass
    matrix); a_ab = A∞ (load on A per acceleration of B), a_ba = A∞ᵀ.  With the cross terms
    applied explicitly one step late, a_A ← −(M_A + A_AA)⁻¹·A_AB·a_B and vice versa, so the
    accelerations follow a_A(n) = G·a_A(n − 2): ρ(G) > 1 means the staggered coupling
    diverges whatever the step.
    """
    lhs_a = np.atleast_2d(m_a) + np.atleast_2d(a_aa)
    lhs_b = np.atleast_2d(m_b) + np.atleast_2d(a_bb)
    g = np.linalg.solve(lhs_a, np.atleast_2d(a_ab) @ np.linalg.solve(lhs_b, np.atleast_2d(a_ba)))
    return float(np.max(np.abs(np.linalg.eigvals(g))))
