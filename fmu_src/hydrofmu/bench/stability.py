"""Stability at the extremes: explicit added mass, explicit cross-body added mass and
quadratic drag at very large steps, each as a linear (or exact nonlinear) theory next to
in-process co-simulations that use the real kernels.

The runs are scenes built in code, run in-process by the master itself
(``cosim.inprocess``: the scene's load and dynamics slaves, stepped by ``cosim.master.run``;
communication step h, t_k = k·h, loads held constant over a step, RK4 substeps in the
dynamics):

- ``gauss-seidel``: F_k = F(motion at t_k) acts over [t_k, t_k+1];
- ``jacobi``: F(motion at t_k−1) acts over [t_k, t_k+1]; the first two steps both use
  F(motion at t_0) (the master's initialisation resolves the feedthrough at t = 0).

The motion handed to load kernels carries the dynamics' acceleration output, which is
computed from the state and the load held over the previous step (``RigidBody.acceleration``).
Growth factors are computed from the run's samples: the state at t_k+1 next to the load
held over [t_k, t_k+1] (the load FMU's output sampled at t_k), normalised per study.

1. Explicit added mass (a RIFLEX BODY-like point with added mass A on a body of mass M)
---------------------------------------------------------------------------------------
1-DOF oscillator M·ẍ + C·ẋ + K·x = F, K = M·(2π/T)², C = 2ζ·√(K·M) (T and ζ are the
period and damping ratio of the dry body M, K).  Over a step h with F held, exactly

    [x; v]_k+1 = Φ·[x; v]_k + Γ·F_k,    [[Φ, Γ], [0, 1]] = expm([[0, 1, 0], [−K/M, −C/M, 1/M], [0, 0, 0]]·h)

``explicit``: F_k+1 = −A·a_k+1 with a_k+1 = (F_k − K·x_k+1 − C·v_k+1)/M, so on the state
(x, v, F_held) the step is the 3×3 map

    S = [[Φ, Γ], [(A/M)·(K·Φ_1 + C·Φ_2), (A/M)·(K·Γ_1 + C·Γ_2 − 1)]]     (Φ_i, Γ_i: rows i of Φ, Γ)

and ρ(S) is its spectral radius.  For h ≪ T, Φ → 1 and Γ → 0, so F_k+1 ≈ −(A/M)·F_k:
ρ → A/M when A/M > 1 (an alternating mode that grows by A/M per step whatever the step),
and ρ ≈ 1 (slightly below: the one-step-late inertia load damps a little) when A/M < 1.
``export``: A sits in the dynamics' mass matrix, no acceleration load; S = Φ of the
oscillator with mass M + A, ρ = exp(−ζ'·ω'·h) ≤ 1 (= 1 undamped) at any step.

Measured on the map (T = 20 s, ζ = 0): ρ = 1.1000 (A/M = 1.1, h = 1e-4 s), 1.0986
(1.1, 1 s), 1.9782 (2, 1 s), 95.25 (100, 1 s); ρ ≤ 1 for A/M ≤ 0.9 (0.99938 at 0.9,
1 s).  The statement "diverges above A/M = 1 whatever the step" needs h small against T:
with ζ = 2 % and T = 20 s, A/M = 1.01 is still unstable at h = 1 s (ρ = 1.0035) but
stable at h = 3 s (ρ = 0.9916), A/M = 1.05 stable at h = 5 s (ρ = 0.9975).  Hence T =
20 s here, so that the map's steps (≤ 1 s = T/20) stay in the h ≪ T regime.

Growth of a run (``added_mass_run``): the body starts at x = 0 with v0 = 1 m/s (heave);
X = v0·√((M + A)/K) is the free amplitude of the body with its added mass, and the
growth is max over the last quarter of the run of max(|x|/X, |v|/v0, |F_held|/(K·X)),
inf when it leaves 1e30 or turns non-finite.  The force is in the norm because the
alternating mode lives in F: x sees it only through F·h²/M, which at h = 1e-4 s hides a
1e16 growth of F in 400 steps.

2. Explicit cross-body added mass (SIMO coupled A∞ between bodies A and B)
-------------------------------------------------------------------------
Each body keeps its own added mass A_AA, A_BB in its mass matrix (export); the cross
blocks are loads F_A = −A_AB·a_B, F_B = −A_BA·a_A (A_BA = A_ABᵀ) from the neighbour's
acceleration output.  For h → 0, a_A,k+1 ≈ −(M_A + A_AA)⁻¹·A_AB·a_B,k and
a_B,k ≈ −(M_B + A_BB)⁻¹·A_BA·a_A,k−1, so a_A,k+1 = G·a_A,k−1 with

    G = (M_A + A_AA)⁻¹·A_AB·(M_B + A_BB)⁻¹·A_BA      (physics.coupling.stability_indicator)

an alternating mode growing by ρ(G) every two steps (√ρ(G) per step): ρ(G) > 1
diverges whatever the step.

ρ(G) < 1 is necessary, not sufficient.  The exact map (``cross_body_theory``: as in
section 1, on (x_A, v_A, x_B, v_B, F_A, F_B), translations) shows a second, slow
instability: the cross inertia load arrives about one step late, F_A(t) ≈ −c·a_B(t − τ),
τ ≈ h, and −c·a_B(t − τ) ≈ −c·a_B(t) + c·τ·ȧ_B(t).  On the anti-phase mode of two equal
bodies (x_B = −x_A, mass M − c, ω_a² = K/(M − c), c = A_AB) ȧ_B = +ω_a²·ẋ_A, a damping
of −c·τ·ω_a²: negative.  (On the in-phase mode, and on a body's own explicit added mass
of section 1, the sign is positive: that is why section 1 is stable below A/M = 1.)
Undamped, the per-step growth is then

    ln ρ_step ≈ c·ω_a²·τ·h / (2·(M − c)) = √ρ·ω0²·h² / (2·(1 − √ρ)²)    (equal bodies, ρ = ρ(G))

(exact map, ρ(G) = 0.8, T = 20 s: ρ_step − 1 = 3.75e-6 at h = 1e-3 s, i.e. τ = 0.95·h;
0.0199 at h = 0.1 s, where the rate saturates).  So without damping the explicit cross
coupling is unstable at every step, with a growth rate ∝ h; physical damping ζ (of each
dry body, on the anti-phase mode ζ/√(1 − √ρ)) stabilises it below

    h_max ≈ ζ·(1 − √ρ)·T / (π·√ρ)              (equal bodies, τ = h)

which the exact map puts 1.01–1.45 times higher (ρ(G) = 0.95 … 0.2, ζ = 1–5 %), e.g.
h_max = 0.016 s at ρ(G) = 0.8, 0.062 s at 0.5 (ζ = 2 %, T = 20 s): the explicit cross
coupling needs steps far below the periods as ρ(G) approaches 1.

3. Quadratic drag at large steps and speeds
-------------------------------------------
F = −c·w·|w| on the mass m that carries it (m = M + A when the added mass is exported to
the dynamics), w = v − u_c the velocity relative to the current (u_c = 0: absolute).
No other load: with F held, the step is exact, w' = w − k·h·w_F·|w_F|, k = c/m, where
w_F is the relative velocity the load was evaluated with.

Gauss–Seidel (w_F = w): with s = k·h·|w|, w' = (1 − s)·w, |w'| = |1 − s|·|w|.  If
s0 < 2, |w| falls, so s falls and the decay goes on (monotone for s0 ≤ 1, alternating
for 1 < s0 < 2).  If s0 > 2, |w'| = (s0 − 1)·|w| > |w| and s1 = s0·(s0 − 1) > s0: the
speed grows faster than exponentially.  s0 = 2 is a period-2 cycle (w → −w).  So

    h_max = 2·m / (c·|u_c − v|max)            (|u_c − v|max = |u_c − v0|: it only falls)

Jacobi (w_F = w one step earlier): w_n+1 = w_n − k·h·w_n−1·|w_n−1|.  Since w·|w| = |w|·w,
freezing |w| at the amplitude W (exact at constant amplitude, the secant gain) gives the
linear recurrence w_n+1 = w_n − s·w_n−1, s = k·h·W, with λ² − λ + s = 0: real roots in
(0, 1) for s ≤ 1/4, else |λ|² = s.  Stable iff s < 1:

    h_max,Jacobi = m / (c·|u_c − v|max)       (half the Gauss–Seidel limit)

Checked on the nonlinear recurrence from the master's start (w_−1 = w_0, u = k·h·w):
u0 < 1 decays, u0 > 1 diverges, and u0 = 1 is the period-6 cycle 1, 0, −1, −1, 0, 1 —
the λ = e^(±iπ/3) of the linear recurrence at s = 1 (|u| = 1 makes u·|u| = u).  (The
tangent linearisation, gain 2·k·|W|, would halve both limits: it describes small
perturbations of a decaying solution, not whether the amplitude grows.)
"""
import math
from pathlib import Path

import numpy as np
from scipy.linalg import expm

from ..cosim import inprocess, master
from ..description import Effect, HydroCoupling
from ..scene import Body, Scene

RATIOS = (0.01, 0.1, 0.5, 0.9, 1.1, 2.0, 10.0, 100.0)   # A/M of the map
STEPS = (1e-4, 1e-3, 1e-2, 0.1, 1.0)                    # communication steps [s]
MASS = 1.0e6            # [kg] body mass of the studies (results are scale-free)
BLOWUP = 1e30           # normalised state beyond which a run is declared diverged
ALGORITHMS = ("gauss-seidel", "jacobi")


# -- runs through the master -----------------------------------------------------------
def _body(name, mass, stiffness=0.0, damping=0.0, velocity=None, mode="export", effects=()):
    """Scene body of ``mass`` [kg] at the origin with gyration radius 10 m, translational
    stiffness [N/m] and damping [N·s/m], rotational ones 100× (the same natural period)."""
    per_dof = lambda x: [x] * 3 + [100.0 * x] * 3
    return Body(name, [0.0] * 3, [0.0] * 3, list(velocity if velocity is not None else [0.0] * 6), mass,
                np.diag([100.0 * mass] * 3).tolist(), [0.0] * 3, np.diag(per_dof(stiffness)).tolist(),
                np.diag(per_dof(damping)).tolist(), mode, list(effects))


def _scene(bodies, dt, substep, couplings=(), current=0.0):
    """A scene of ``bodies``, run settings for step ``dt`` [s], current [m/s] along ±x."""
    run_cfg = {"preset": None, "step": dt, "stop": dt, "algorithm": "gauss-seidel", "substep": substep,
               "load_hold": "constant", "memory": {}, "set": []}
    return Scene("stability", Path("bench/stability"), 1025.0, 9.81, abs(current), 0.0 if current >= 0 else 180.0,
                 {b.name: b for b in bodies}, run_cfg, couplings=list(couplings))


def _growth(scene, n_steps, algorithm, norm, parameters=None):
    """Growth factor of a scene's run through the master: ``norm(state, held)`` of the
    samples, max over the last quarter; inf when it leaves BLOWUP or a slave reports a
    non-finite value.  ``state(instance, name, n)``: outputs at t_1 … t_n;
    ``held(instance, name, n)``: outputs at t_0 … t_n−1, which for a load FMU is the load
    held over the step that follows (Gauss–Seidel: F(x_k) sampled after the exchange at t_k;
    Jacobi: F(x_k−1) sampled before it)."""
    if algorithm not in ALGORITHMS:
        raise ValueError(f"algorithm must be one of {ALGORITHMS}, not {algorithm!r}")
    try:
        with np.errstate(over="ignore", invalid="ignore"):
            result = master.run(inprocess.system(scene, parameters), stop=n_steps * scene.run["step"],
                                step=scene.run["step"], algorithm=algorithm, progress=False)
    except master.RunError:
        return math.inf
    values = norm(lambda i, name, n: result.vector(i, name, n)[1:],
                  lambda i, name, n: result.vector(i, name, n)[:-1])
    if not np.all(values < BLOWUP):
        return math.inf
    return float(values[n_steps - max(1, n_steps // 4):].max())


# -- 1. explicit added mass -------------------------------------------------------------
def _spring(period, zeta, mass=1.0):
    k = mass * (2.0 * math.pi / period) ** 2
    return k, 2.0 * zeta * math.sqrt(k * mass)


def added_mass_theory(ratio, dt, period=20.0, zeta=0.0, mode="explicit"):
    """Spectral radius per step of the exact linear co-simulation map (module docstring,
    section 1) of a body of mass M on a spring (natural period ``period`` [s] of M alone,
    damping ratio ``zeta``) with added mass A = ``ratio``·M, step ``dt`` [s], Gauss–Seidel.
    ``mode``: 'explicit' (−A·a applied one step late) or 'export' (A in the mass matrix).
    Valid as "unstable iff A/M > 1" for dt ≪ period (here dt ≤ period/20); see the module
    docstring for damped long steps where A/M slightly above 1 is stable."""
    if mode not in ("explicit", "export"):
        raise ValueError(f"mode must be 'explicit' or 'export', not {mode!r}")
    k, c = _spring(period, zeta)
    m = 1.0 + ratio if mode == "export" else 1.0
    e = expm(np.array([[0.0, 1.0, 0.0], [-k / m, -c / m, 1.0 / m], [0.0, 0.0, 0.0]]) * dt)
    if mode == "export":
        return float(np.max(np.abs(np.linalg.eigvals(e[:2, :2]))))
    s = e.copy()
    s[2] = ratio * (k * e[0] + c * e[1] - np.array([0.0, 0.0, 1.0]))   # F' = −A·(F − K·x' − C·v')/M
    return float(np.max(np.abs(np.linalg.eigvals(s))))


def added_mass_run(ratio, dt, mode, n_steps=400, period=20.0, zeta=0.0, mass=MASS, v0=1.0):
    """Growth factor (module docstring, section 1) of a Gauss–Seidel co-simulation through
    the master: a body of mass M = ``mass`` [kg] on a heave spring of natural period
    ``period`` [s] for M alone, damping ratio ``zeta``, carrying a RIFLEX BODY at the
    reference point with AMX = AMY = AMZ = ``ratio``·M (no drag, AM = AE = 0), started with
    heave velocity ``v0`` [m/s].  ``mode``: the body's acceleration loads, 'explicit' (the
    load FMU applies −A·a) or 'export' (A in the dynamics' mass matrix).  RK4 substeps
    ≤ min(dt, period/50)."""
    if mode not in ("explicit", "export"):
        raise ValueError(f"mode must be 'explicit' or 'export', not {mode!r}")
    a = ratio * mass
    point = Effect("riflex_body", "point", {"offset": [0.0] * 3, "am": 0.0, "ae": 0.0, "icoo": "GLOBAL",
                                            "cd": [0.0] * 3, "added_mass": [a, a, a]})
    k, c = _spring(period, zeta, mass)
    body = _body("hull", mass, k, c, [0.0, 0.0, v0, 0.0, 0.0, 0.0], mode, [point])
    x_scale = v0 * math.sqrt((mass + a) / k)

    def norm(state, held):
        return np.maximum.reduce([np.abs(state("hull_dynamics", "position", 3)[:, 2]) / x_scale,
                                  np.abs(state("hull_dynamics", "velocity", 6)[:, 2]) / v0,
                                  np.abs(held("hull", "force", 6)[:, 2]) / (k * x_scale)])
    return _growth(_scene([body], dt, min(dt, period / 50.0)), n_steps, "gauss-seidel", norm)


def added_mass_map(ratios=RATIOS, steps=STEPS, n_steps=400, period=20.0, zeta=0.0):
    """Theory and simulation over the grid.  Returns a dict of arrays: 'ratios' (A/M),
    'steps' [s], and for mode in ('explicit', 'export') 'rho_<mode>' (spectral radius per
    step) and 'growth_<mode>' (``added_mass_run``), both shaped (len(ratios), len(steps))."""
    out = {"ratios": np.asarray(ratios, float), "steps": np.asarray(steps, float),
           "n_steps": n_steps, "period": period, "zeta": zeta}
    for mode in ("explicit", "export"):
        out[f"rho_{mode}"] = np.array([[added_mass_theory(r, h, period, zeta, mode) for h in steps]
                                       for r in ratios])
        out[f"growth_{mode}"] = np.array([[added_mass_run(r, h, mode, n_steps, period, zeta) for h in steps]
                                          for r in ratios])
    return out


def diverged(growth):
    """Divergence criterion of the runs: growth > 1e3 or non-finite."""
    g = np.asarray(growth, float)
    return ~np.isfinite(g) | (g > 1e3)


def plot_added_mass_map(result, path):
    """PNG of ``added_mass_map``'s result: one panel per mode, log-log axes (step, A/M),
    stable (o) / diverged (x) runs, theory contour ρ = 1 on a dense grid."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ratios, steps = result["ratios"], result["steps"]
    dense_r = np.union1d(np.geomspace(ratios.min() / 2, ratios.max() * 2, 32), [1.0])  # the kink
    dense_h = np.geomspace(steps.min() / 2, steps.max() * 2, 20)
    fig, axes = plt.subplots(1, 2, figsize=(10, 4.2), sharey=True)
    for ax, mode in zip(axes, ("explicit", "export")):
        rho = np.array([[added_mass_theory(r, h, result["period"], result["zeta"], mode) for h in dense_h]
                        for r in dense_r])
        rho = np.where(rho > 1.0 + 1e-9, rho, np.minimum(rho, 1.0 - 1e-9))  # round-off ones: stable
        if rho.min() < 1.0 < rho.max():
            ax.contour(dense_h, dense_r, rho, levels=[1.0], colors="k", linestyles="--")
            ax.plot([], [], "k--", label="theory ρ = 1")
        hh, rr = np.meshgrid(steps, ratios)
        bad = diverged(result[f"growth_{mode}"])
        ax.plot(hh[~bad], rr[~bad], "o", color="tab:green", label="simulated: bounded")
        ax.plot(hh[bad], rr[bad], "x", color="tab:red", ms=9, mew=2, label="simulated: diverged")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("communication step [s]")
        ax.set_title(f"{mode} added mass (T = {result['period']:g} s, ζ = {result['zeta']:g})")
        ax.grid(True, which="major", alpha=0.3)
        ax.set_ylim(ratios.min() / 3, ratios.max() * 40)
        ax.legend(loc="upper center", ncol=3, fontsize=7, handletextpad=0.3, columnspacing=0.8)
    axes[0].set_ylabel("A / M")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


# -- 2. explicit cross-body added mass ------------------------------------------------
def _translational(matrix, field):
    m = np.zeros((6, 6)) if matrix is None else np.asarray(matrix, float)
    if np.any(m[3:]) or np.any(m[:, 3:]):
        raise ValueError(f"{field}: only translational blocks are supported (rotational rows/columns must be 0)")
    return m[:3, :3]


def cross_body_theory(cross, mass_a=MASS, mass_b=MASS, self_a=None, self_b=None, dt=0.1, period=20.0,
                      zeta=0.0):
    """Spectral radius per step of the exact linear co-simulation map of ``cross_body_run``
    (Gauss–Seidel, translations; module docstring, section 2).  Body X: mass matrix
    m·1 + A_XX (3×3), springs K = m·(2π/period)², dampers 2·zeta·m·(2π/period), both per
    translation; loads F_A = −A_AB·a_B, F_B = −A_ABᵀ·a_A with a from the state and the
    load held over the previous step.  ``cross``, ``self_a``, ``self_b``: 6×6 whose rotational
    rows and columns are zero."""
    c = _translational(cross, "cross")
    omega = 2.0 * math.pi / period
    blocks = []
    for m, own in ((mass_a, self_a), (mass_b, self_b)):
        mm = m * np.eye(3) + _translational(own, "self added mass")
        k, d = m * omega ** 2 * np.eye(3), 2.0 * zeta * m * omega * np.eye(3)
        inv = np.linalg.inv(mm)
        gen = np.zeros((9, 9))
        gen[:3, 3:6] = np.eye(3)
        gen[3:6] = np.hstack([-inv @ k, -inv @ d, inv])
        blocks.append((expm(gen * dt)[:6], inv, k, d))
    # state z = [x_A, v_A, x_B, v_B, F_A, F_B] (3 each)
    s = np.zeros((18, 18))
    for i, (e, _, _, _) in enumerate(blocks):
        rows = slice(6 * i, 6 * i + 6)
        s[rows, 6 * i:6 * i + 6], s[rows, 12 + 3 * i:15 + 3 * i] = e[:, :6], e[:, 6:]
    acc = []
    for i, (_, inv, k, d) in enumerate(blocks):   # a' = M⁻¹·(F − K·x' − D·v')
        f_held = np.zeros((3, 18))
        f_held[:, 12 + 3 * i:15 + 3 * i] = np.eye(3)
        acc.append(inv @ (f_held - k @ s[6 * i:6 * i + 3] - d @ s[6 * i + 3:6 * i + 6]))
    s[12:15], s[15:18] = -c @ acc[1], -c.T @ acc[0]
    return float(np.max(np.abs(np.linalg.eigvals(s))))


def cross_body_run(cross, mass_a=MASS, mass_b=MASS, self_a=None, self_b=None, dt=0.1, n_steps=400,
                   period=20.0, zeta=0.0, v0=1.0, algorithm="gauss-seidel"):
    """Growth factor of two bodies coupled by the cross added mass ``cross`` = A_AB
    (6×6, load on A per acceleration of B; B gets A_ABᵀ), a SIMO coupling without kernels
    applied explicitly by the load FMUs from the neighbour's acceleration output, run
    through the master.  Each body: mass ``mass_a``/``mass_b`` [kg] (gyration radius
    10 m), its own added mass ``self_a``/``self_b`` (6×6) in its dynamics' mass matrix (the
    ``added_mass`` parameters), springs of natural period ``period`` [s] and damping ratio
    ``zeta`` for the dry body.  A starts with velocity ``v0`` [m/s] in surge, sway and
    heave, B at rest.  Growth: max over the last quarter of max(|x|/X, |v|/v0, |F|/(K·X)),
    X = v0·T/(2π), over both bodies and all translations; inf if it diverged."""
    omega = 2.0 * math.pi / period
    bodies = [_body(n, m, m * omega ** 2, 2.0 * zeta * m * omega, v, "explicit")
              for n, m, v in (("a", mass_a, [v0] * 3 + [0.0] * 3), ("b", mass_b, None))]
    coupling = HydroCoupling("AB", "a", "b", np.asarray(cross, float), None, [])
    parameters = {f"{n}_dynamics.added_mass[{i + 1},{j + 1}]": own[i, j]
                  for n, own in (("a", self_a), ("b", self_b)) if own is not None
                  for i in range(6) for j in range(6)}
    x_scale = v0 / omega

    def norm(state, held):
        return np.maximum.reduce([np.maximum.reduce([
            np.abs(state(f"{b.name}_dynamics", "position", 3)).max(axis=1) / x_scale,
            np.abs(state(f"{b.name}_dynamics", "velocity", 6)[:, :3]).max(axis=1) / v0,
            np.abs(held(b.name, "force", 6)[:, :3]).max(axis=1) / (b.mass * omega ** 2 * x_scale)])
            for b in bodies])
    scene = _scene(bodies, dt, min(dt, period / 50.0), [coupling])
    return _growth(scene, n_steps, algorithm, norm, parameters)


# -- 3. quadratic drag -----------------------------------------------------------------
def drag_step_limit(mass, c, speed, algorithm="gauss-seidel"):
    """Largest stable communication step [s] for quadratic drag F = −c·w·|w| [N] on
    ``mass`` [kg] (M + A when the added mass is exported), |w|max = ``speed`` [m/s]
    (|u_current − v0|): 2·m/(c·speed) for Gauss–Seidel, m/(c·speed) for Jacobi."""
    if algorithm not in ALGORITHMS:
        raise ValueError(f"algorithm must be one of {ALGORITHMS}, not {algorithm!r}")
    return (2.0 if algorithm == "gauss-seidel" else 1.0) * mass / (c * abs(speed))


def drag_run(speed, dt, algorithm="gauss-seidel", mass=MASS, c=1.0e4, current=0.0, added=0.0,
             kernel="aqwa", n_steps=60):
    """Growth factor max|u_c − v|/speed over the last quarter (inf if diverged) of a free
    body (no spring) in surge under quadratic drag, run through the master.
    ``kernel``: 'aqwa' (AQWA viscous drag, V11 = c, RELATIVE when current ≠ 0) or 'riflex'
    (RIFLEX BODY CDX = c, AMX = ``added`` [kg] exported into the dynamics' mass matrix).
    The current [m/s] flows along +x (negative: along −x); the body starts with
    v0 = current − speed, so the relative velocity starts at +speed [m/s]."""
    if kernel == "aqwa":
        if added:
            raise ValueError("added mass needs kernel='riflex'")
        effect = Effect("aqwa_viscous_drag", "drag", {"matrix": np.diag([c, 0, 0, 0, 0, 0]).tolist(),
                                                      "relative": current != 0.0})
    elif kernel == "riflex":
        effect = Effect("riflex_body", "drag", {"offset": [0.0] * 3, "am": 0.0, "ae": 0.0, "icoo": "GLOBAL",
                                                "cd": [c, 0.0, 0.0], "added_mass": [added, 0.0, 0.0]})
    else:
        raise ValueError(f"kernel must be 'aqwa' or 'riflex', not {kernel!r}")
    body = _body("hull", mass, velocity=[current - speed, 0, 0, 0, 0, 0], effects=[effect])   # export mode

    def norm(state, held):
        return np.abs(current - state("hull_dynamics", "velocity", 6)[:, 0]) / speed
    return _growth(_scene([body], dt, dt, current=current), n_steps, algorithm, norm)


# -- everything, for `hydrofmu bench` -------------------------------------------------
def run(folder, n_steps=400):
    """Write added_mass_map.csv and added_mass_map.png into ``folder`` (``n_steps`` per
    simulated point); returns their paths."""
    from pathlib import Path
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    result = added_mass_map(n_steps=n_steps)
    rows = ["ratio,step,rho_explicit,growth_explicit,rho_export,growth_export"]
    for i, r in enumerate(result["ratios"]):
        for j, h in enumerate(result["steps"]):
            rows.append(",".join(repr(float(x)) for x in (
                r, h, result["rho_explicit"][i, j], result["growth_explicit"][i, j],
                result["rho_export"][i, j], result["growth_export"][i, j])))
    csv = folder / "added_mass_map.csv"
    csv.write_text("\n".join(rows) + "\n")
    return csv, plot_added_mass_map(result, folder / "added_mass_map.png")
