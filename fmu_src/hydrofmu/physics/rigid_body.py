"""6-DOF rigid body: the dynamics partner that stands in for a vessel simulator in
co-simulation tests.  Pure numpy; the FMU wrapper feeds it the summed loads of the load
FMUs and publishes its motion.

Conventions (README, Conventions: Frames and motion, Signs)
-----------------------------------------------------------
- Global frame earth-fixed, right-handed, z up.  SI units.
- Pose η = [x, y, z, φ, θ, ψ]: position of the reference point O [m], global axes, and
  attitude (roll, pitch, yaw) [rad]; body-to-global rotation R = Rz(ψ)·Ry(θ)·Rx(φ).
- Velocity ν = [v; ω]: linear velocity of O [m/s] and angular velocity [rad/s], both in
  global axes.  Acceleration [a; α] likewise [m/s², rad/s²].
- Loads [F; M] [N, N·m]: global axes, moment about O, the load ON the body.
- Angles are integrated as they are, never wrapped (a spinning body's ψ keeps growing),
  so the restoring load below stays continuous.

Equations of motion
-------------------
With m the mass, c the CoG offset from O in body axes, I_g the 3×3 inertia about the CoG
in body axes:

    r    = R·c                                       CoG offset, global axes
    I_O  = R·(I_g + m(|c|²·1 − c·cᵀ))·Rᵀ             inertia about O, global axes
    M_rb = [[m·1, −m[r]×], [m[r]×, I_O]]              ([r]×·a = r × a)
    b    = [m·ω×(ω×r); ω×(I_O·ω)]                    centripetal / gyroscopic terms
    (M_rb + A)·[a; α] = F_ext − K·(η − η0) − D·ν − b

which is Newton  m(a + α×r + ω×(ω×r)) = F  and Euler about O
I_O·α + ω×(I_O·ω) + m·r×a = M,  with the added-mass load −A·[a; α] moved to the left.

- η0 is the initial pose: the equilibrium, where weight and buoyancy balance, so no
  gravity term appears; K (6×6) is the mooring + hydrostatic stiffness acting on the
  pose deviation, attitude part in Euler angles.  D (6×6) is linear damping.
- A (6×6) is the added mass about O in global axes (what load FMUs export in `export`
  mode).  It is held constant over a step (the wrapper may replace it between steps via
  the ``added_mass`` attribute); no added-mass Coriolis/Munk terms are included.
- F_ext is held constant over a communication step (zero-order hold).

Kinematics
----------
    ẋ = v,   ω = T·[φ̇, θ̇, ψ̇],   T = [Rz·Ry·e_x | Rz·e_y | e_z]
      = [[cψ·cθ, −sψ, 0], [sψ·cθ, cψ, 0], [−sθ, 0, 1]],   det T = cos θ
    φ̇ = (cψ·ωx + sψ·ωy)/cθ,   θ̇ = −sψ·ωx + cψ·ωy,   ψ̇ = ωz + sθ·φ̇

singular at θ = ±90° (gimbal lock): ``GimbalLockError`` is raised when |cos θ| falls
below ``GIMBAL_TOL`` or cos θ changes sign within a step (a substep jumped across).

Integrator
----------
Butcher's 7-stage Runge–Kutta method of order 6 in equal internal steps of each
communication step, n = ceil(dt / (5·max_substep)), on the 12 states [η; ν] of every body
of a group at once; when the communication step is no longer than max_substep, one
classic RK4 step instead (4 stages: cheaper, and its error per period, ≈ 82/N⁴ with
N = T/dt ≥ T/max_substep, is within the RK4-in-substeps bound below).  RK6 replaced
classic RK4 in steps of max_substep (20 derivative evaluations per 5·max_substep, 7 now).
Measured on an undamped oscillator of period T, per period: RK4 ≈ 80/N⁴
(N = T/max_substep), RK6 ≈ 250/M⁶ with M = N/5 internal steps, i.e. 8e-7 against 4e-6 at
N = 100, 1e-8 against 5e-9 at N = 300, 8e-11 against 4e-12 at N = 1000: smaller than
RK4's from N ≈ 220, a few times larger at N = 100.
Each evaluation works on plain floats for the kinematics and the rotating parts of the
mass matrix, adds them to the constant part (every added-mass block, m·1) and solves once
for the whole group.  The acceleration is affine in the load, a = (M_rb + A)⁻¹·(rhs + F):
the matrix and rhs at the end of a step give the published acceleration and, under the
next step's load, that step's first stage (one evaluation per step saved).  scipy's
solve_ivp was measured slower at co-simulation steps (its per-call start-up dominates).
Where it compiles, the C kernel rigid.c (physics.rigid_kernel) takes every step with these
same formulas (~6× faster on two coupled bodies); this module is its reference and its
fallback (a step the kernel cannot finish is redone here and raises the error).
Fixed internal steps make the result independent of how the master splits time (1 step of
1 s = 10 steps of 0.1 s to round-off when 5·max_substep divides both).  Accuracy:
max_substep ≤ T_min/100 (T_min the shortest natural period or decay time) keeps the phase
error below ~4e-6 per period.  Explicit methods are only stable for ω·h below ~3: very
stiff springs or heavy damping need max_substep below ~T_min/10 (RK6) or steps below
~0.45·T_min (one RK4 step).
"""
import math

import numpy as np

from ..admissible import inertia as inertia_problems
from ..errors import InputError
from . import quiet, rigid_kernel
from .state import Motion

try:   # the gufunc behind np.linalg.solve, without their ~3 µs of wrapping per call
    from numpy.linalg._umath_linalg import solve1 as _solve
except ImportError:  # pragma: no cover - other numpy layouts
    def _solve(a, b, out=None):
        x = np.linalg.solve(a, b)
        if out is None:
            return x
        out[...] = x
        return out


def _finite(x):
    """True if every entry of the small array x is finite (barring an overflow of their sum,
    which callers then look at closer); a sum of floats is ~5× cheaper than a numpy reduction."""
    return math.isfinite(sum(x.tolist()))

GIMBAL_TOL = 1e-6  # |cos θ| below which the Euler-angle rates are declared singular
# The range the load models assume (linear hydrostatics, first-order wave loads at the mean
# position): the dynamics partner warns once when |roll| or |pitch| passes LINEAR_RANGE and
# fails the step as capsized past CAPSIZE (or at the Euler angles' singularity) [rad].
LINEAR_RANGE = math.radians(15.0)
CAPSIZE = math.radians(90.0)

# Butcher's 7-stage Runge–Kutta method of order 6: nodes c, weights b, coefficients a.
RK_C = np.array([0.0, 1 / 3, 2 / 3, 1 / 3, 1 / 2, 1 / 2, 1.0])
RK_B = np.array([11 / 120, 0.0, 27 / 40, 27 / 40, -4 / 15, -4 / 15, 11 / 120])
RK_A = np.zeros((7, 7))
for _i, _row in enumerate([[], [1 / 3], [0, 2 / 3], [1 / 12, 1 / 3, -1 / 12], [-1 / 16, 9 / 8, -3 / 16, -3 / 8],
                           [0, 9 / 8, -3 / 8, -3 / 4, 1 / 2], [9 / 44, -9 / 11, 63 / 44, 18 / 11, 0, -16 / 11]]):
    RK_A[_i, :_i] = _row
STEP_RATIO = 5  # internal steps up to STEP_RATIO·max_substep (module docstring)
# classic RK4: one step when the communication step is no longer than max_substep
RK4 = (np.array([[0.0, 0.0, 0.0, 0.0], [0.5, 0.0, 0.0, 0.0], [0.0, 0.5, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]]),
       np.array([1 / 6, 1 / 3, 1 / 3, 1 / 6]), np.array([0.0, 0.5, 0.5, 1.0]))
RK6 = (RK_A, RK_B, RK_C)


class GimbalLockError(ArithmeticError):
    """The pitch angle reached ±90°, where ZYX Euler-angle rates are undefined."""


def _gimbal_message(attitude):
    phi, theta, psi = np.degrees(attitude)
    return (f"pitch θ = {theta:.4f}° reached ±90° (roll {phi:.4f}°, yaw {psi:.4f}°): the "
            "ZYX Euler-angle rates are singular there; the rigid body cannot go on")


NO_START = ()   # the start of a state the C kernel stepped to: not computed, empty (false)


class _Equations:
    """Equations of motion of n rigid bodies whose accelerations are coupled by a constant
    added mass: the one kernel behind RigidBody (n = 1) and CoupledBodies.

    State y (12n,) = [η_1; ν_1; η_2; ν_2; …], loads (6n,) = [F_1; M_1; …] (module
    docstring).  Inside ``integrate`` the state is reordered as [η_1; …; η_n; ν_1; …; ν_n],
    so a derivative is [kinematic rates; accelerations] in two slices.  The mass matrix is a
    constant part (every added-mass block, m·1 of each body) plus the rotating parts of
    each M_rb, computed on plain floats."""

    def __init__(self, bodies, cross=None):
        n = self.n = len(bodies)
        self.const = np.zeros((6 * n, 6 * n))
        kd = np.zeros((6 * n, 12 * n))     # [K | D] per body: K·η + D·ν = kd·y
        self.k_eta0 = np.zeros(6 * n)
        self.props, block_idx = [], []
        for i, b in enumerate(bodies):
            s = slice(6 * i, 6 * i + 6)
            self.const[s, s] = b.added_mass
            self.const[s, s][:3, :3] += b.mass * np.eye(3)
            kd[s, 12 * i:12 * i + 6], kd[s, 12 * i + 6:12 * i + 12] = b.stiffness, b.damping
            self.k_eta0[s] = b.stiffness @ b.eta0
            cog = tuple(b.cog.tolist()) if np.any(b.cog) else None
            io = b.inertia + b.mass * (b.cog @ b.cog * np.eye(3) - np.outer(b.cog, b.cog))
            self.props.append((b.mass, cog, tuple(io[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]].tolist())))
            # flat indices of the rotating blocks: I_O, then m·[r]× (lower) and −m·[r]× (upper)
            rot, lin = np.arange(6 * i + 3, 6 * i + 6), np.arange(6 * i, 6 * i + 3)
            for rows, cols in [(rot, rot)] + ([(rot, lin), (lin, rot)] if cog else []):
                block_idx.append((rows[:, None] * 6 * n + cols[None, :]).ravel())
        for (i, j), m in (cross or {}).items():
            self.const[6 * i:6 * i + 6, 6 * j:6 * j + 6] += m
        self.block_idx = np.concatenate(block_idx)
        # the constant part under each body's rotating blocks (I_O's 9, then m·[r]×'s 18),
        # added to them on floats
        under = self.const.reshape(-1)[self.block_idx].tolist()
        at = 0
        for i, (m, cog, io_b) in enumerate(self.props):
            k = 9 + (18 if cog else 0)
            self.props[i] = (m, cog, io_b, io_b[1] == io_b[2] == io_b[4] == 0.0, tuple(under[at:at + 9]),
                             under[at + 9:at + k])
            at += k
        idx = np.arange(12 * n).reshape(n, 2, 6)
        self.order = np.concatenate([idx[:, 0].ravel(), idx[:, 1].ravel()])   # y[order]: [η…; ν…]
        self.back = np.argsort(self.order)
        self.kd = kd[:, self.order]
        self.first = bodies[0]   # names the body in a singular-matrix error
        self._tables = {}
        self._big = self.const.copy()   # the stages' mass matrix (rotating entries put anew in each)
        lib = rigid_kernel.library()
        self.kernel = None if lib is None else rigid_kernel.Kernel(
            lib, GIMBAL_TOL, [[m, 1.0 if cog else 0.0, *(cog or (0.0, 0.0, 0.0)), *io_b] for m, cog, io_b, *_ in self.props],
            self.const, kd, self.k_eta0)

    def parts(self, yl, signs=None):
        """Rotating mass-matrix entries (constant part included, at ``block_idx``), bias
        b and kinematic rates [ẋ; φ̇, θ̇, ψ̇] of every body, as floats, at the reordered state
        ``yl`` (a list), and ``signs``: the sign of cos θ of each body at the start of the
        step (default: now); a cos θ below GIMBAL_TOL on that side raises GimbalLockError."""
        n6 = 6 * self.n
        kin, bias, blocks = [], [], []
        now = signs is None
        if now:
            signs = []
        cos, sin = math.cos, math.sin
        for i, (m, cog, io_b, principal, c_io, c_r) in enumerate(self.props):
            j = 6 * i
            phi, theta, psi = yl[j + 3:j + 6]
            vx, vy, vz, wx, wy, wz = yl[n6 + j:n6 + j + 6]
            cf, sf, ct, st, cp, sp = cos(phi), sin(phi), cos(theta), sin(theta), cos(psi), sin(psi)
            if now:
                signs.append(1.0 if ct > 0.0 else -1.0)
            if ct * signs[i] < GIMBAL_TOL:
                raise GimbalLockError(_gimbal_message(np.array([phi, theta, psi])))
            # R = Rz(ψ)·Ry(θ)·Rx(φ); Euler rates solving ω = T·[φ̇, θ̇, ψ̇]
            stsf, stcf = st * sf, st * cf
            r00, r01, r02 = cp * ct, cp * stsf - sp * cf, cp * stcf + sp * sf
            r10, r11, r12 = sp * ct, sp * stsf + cp * cf, sp * stcf - cp * sf
            r20, r21, r22 = -st, ct * sf, ct * cf
            phi_dot = (cp * wx + sp * wy) / ct
            kin += (vx, vy, vz, phi_dot, cp * wy - sp * wx, wz + st * phi_dot)
            # inertia about O in global axes, R·I_O·Rᵀ (symmetric), and ω × (I_O·ω)
            a00, a01, a02, a11, a12, a22 = io_b
            if principal:   # principal axes (most bodies): R·I_O on the diagonal only
                p00, p01, p02 = r00 * a00, r01 * a11, r02 * a22
                p10, p11, p12 = r10 * a00, r11 * a11, r12 * a22
                i22 = r20 * r20 * a00 + r21 * r21 * a11 + r22 * r22 * a22
            else:
                p00, p01, p02 = (r00 * a00 + r01 * a01 + r02 * a02, r00 * a01 + r01 * a11 + r02 * a12,
                                 r00 * a02 + r01 * a12 + r02 * a22)
                p10, p11, p12 = (r10 * a00 + r11 * a01 + r12 * a02, r10 * a01 + r11 * a11 + r12 * a12,
                                 r10 * a02 + r11 * a12 + r12 * a22)
                i22 = ((r20 * a00 + r21 * a01 + r22 * a02) * r20 + (r20 * a01 + r21 * a11 + r22 * a12) * r21
                       + (r20 * a02 + r21 * a12 + r22 * a22) * r22)
            i00, i01, i02 = p00 * r00 + p01 * r01 + p02 * r02, p00 * r10 + p01 * r11 + p02 * r12, p00 * r20 + p01 * r21 + p02 * r22
            i11, i12 = p10 * r10 + p11 * r11 + p12 * r12, p10 * r20 + p11 * r21 + p12 * r22
            c0, c1, c2, c3, c4, c5, c6, c7, c8 = c_io
            blocks += (c0 + i00, c1 + i01, c2 + i02, c3 + i01, c4 + i11, c5 + i12, c6 + i02, c7 + i12, c8 + i22)
            hx, hy, hz = i00 * wx + i01 * wy + i02 * wz, i01 * wx + i11 * wy + i12 * wz, i02 * wx + i12 * wy + i22 * wz
            gx, gy, gz = wy * hz - wz * hy, wz * hx - wx * hz, wx * hy - wy * hx   # ω × (I_O·ω)
            if cog is None:
                bias += (0.0, 0.0, 0.0, gx, gy, gz)
                continue
            cx, cy, cz = cog
            rx, ry, rz = (r00 * cx + r01 * cy + r02 * cz, r10 * cx + r11 * cy + r12 * cz,
                          r20 * cx + r21 * cy + r22 * cz)
            mx, my, mz = m * rx, m * ry, m * rz
            # m·[r]× below, −m·[r]× above
            blocks += [k + v for k, v in zip(c_r, (0.0, -mz, my, mz, 0.0, -mx, -my, mx, 0.0,
                                                  0.0, mz, -my, -mz, 0.0, mx, my, -mx, 0.0))]
            ux, uy, uz = wy * rz - wz * ry, wz * rx - wx * rz, wx * ry - wy * rx          # ω × r
            bias += (m * (wy * uz - wz * uy), m * (wz * ux - wx * uz), m * (wx * uy - wy * ux), gx, gy, gz)
        return blocks, bias, kin, signs

    def matrix(self, blocks):
        big = self.const.copy()
        big.put(self.block_idx, blocks)
        return big

    def check(self, big):
        """Raise the InputError of a singular (finite) mass matrix M_rb + A."""
        if np.isfinite(big).all():
            try:
                np.linalg.inv(big)
            except np.linalg.LinAlgError:
                raise self.first._error("added_mass", "mass matrix M_rb + A is singular") from None

    def start(self, yp, signs=None):
        """What a step needs at the reordered state yp, whatever the load: (kinematic
        rates, M_rb + A, right-hand side without the load, signs of cos θ, yp).  The
        acceleration under a load L is then (M_rb + A)⁻¹·(rhs + L): the published
        acceleration of one step and the first stage of the next one share it."""
        blocks, bias, kin, signs = self.parts(yp.tolist(), signs)
        rhs = self.k_eta0 - self.kd.dot(yp)   # .dot: a third of @'s cost on small arrays
        rhs -= bias
        return kin, self.matrix(blocks), rhs, signs, yp

    def accelerations(self, y, load, start=None):
        """[a; α] of every body (6n,) at state y under ``load`` (``start``: ``self.start``
        of y, if known)."""
        big, rhs = (start or self.start(y[self.order]))[1:3]
        token = quiet.off()
        try:
            acc = _solve(big, rhs + load)
        finally:
            quiet.restore(token)
        if not _finite(acc):
            self.check(big)
        return acc

    def table(self, h, method):
        """RK coefficients of ``method`` (RK4 or RK6) for an internal step h: rows
        [1, h·a_s] per stage, [1, h·b], and the stages' times h·c as a column."""
        t = self._tables.get((h, method is RK4))
        if t is None:
            ra, rb, rc = method
            a = np.zeros((len(rb), len(rb) + 1))
            a[:, 0], a[:, 1:] = 1.0, h * ra
            b = np.concatenate([[1.0], h * rb])
            t = self._tables[(h, method is RK4)] = (a, b, (h * rc)[:, None])
            if len(self._tables) > 8:
                self._tables.pop(next(iter(self._tables)))
        return t

    def integrate(self, y, load, rate, dt, max_substep, start=None, checked=False):
        """(state after dt [s] > 0 from y under load + rate·t (rate None: held load),
        ``start`` of that state (NO_START from the C kernel), the load at the end of the
        step and the accelerations there under it).  ``start``: ``self.start`` of y, if
        known.  The C kernel (physics.rigid_kernel) takes the step when there is one; a step it
        cannot finish, and a result that is not finite, is computed again here,
        ``checked``: a gimbal lock raises GimbalLockError, a singular matrix InputError."""
        if dt <= max_substep * (1.0 + 1e-12):   # 1e-12: round-off
            method, n = RK4, 1
        else:
            method, n = RK6, max(1, math.ceil(dt / (STEP_RATIO * max_substep) * (1.0 - 1e-12)))
        if self.kernel is not None and not checked:
            got = self.kernel.steps(y, load, rate, dt / n, n, method)
            if type(got) is tuple:
                return got[0], NO_START, (load if rate is None else load + dt * rate), got[1]
        if not start:   # (one body: the order is [η; ν] already)
            start = self.start(y[self.order] if self.n > 1 else y)
        yp = start[4]
        token = quiet.off()   # a non-finite result is checked below
        try:
            yp = self._steps(yp, load, rate, dt / n, n, start, method, checked)
            end = self.start(yp)   # (checks |cos θ| at the end of the step)
            load_end = load if rate is None else load + dt * rate
            acc = _solve(end[1], end[2] + load_end)
        finally:
            quiet.restore(token)
        if not math.isfinite(sum(yp.tolist()) + sum(acc.tolist())):   # a singular matrix, or non-finite loads
            if not checked:
                return self.integrate(y, load, rate, dt, max_substep, start, checked=True)
            return yp[self.back], None, load_end, acc
        return (yp[self.back] if self.n > 1 else yp), end, load_end, acc

    def _steps(self, yp, load, rate, h, n, start, method, checked):
        """n internal steps h of ``method`` from the reordered state yp, whose ``start``
        is given (integrate)."""
        n6 = 6 * self.n
        a, b, hc = self.table(h, method)
        ns = len(a)
        kd, parts, idx, big = self.kd, self.parts, self.block_idx, self._big
        signs = start[3]
        stages = np.zeros((ns + 1, 2 * n6))    # [y; k_1 … k_s]; rows past a stage meet zeros of a
        base = load + self.k_eta0
        for m in range(n):
            if rate is None:
                l0, forcing = load, [base] * ns
            else:   # the load at the step's start and at each stage's time
                l0 = load + (m * h) * rate if m else load
                forcing = (base + (m * h) * rate if m else base) + hc * rate
            kin, big0, rhs = (start or self.start(yp, signs))[:3]
            stages[0], stages[1, :n6] = yp, kin
            _solve(big0, rhs + l0, out=stages[1, n6:])
            if checked and not _finite(stages[1]):
                self.check(big0)
            for s in range(1, ns):
                ys = a[s].dot(stages)
                blocks, bias, kin, _ = parts(ys.tolist(), signs)
                rhs = forcing[s] - kd.dot(ys)
                rhs -= bias
                big.put(idx, blocks)
                acc = _solve(big, rhs, out=stages[s + 1, n6:])
                stages[s + 1, :n6] = kin
                if checked and not _finite(acc):
                    self.check(big)
            yp = b.dot(stages)
            start = None
        return yp


class RigidBody:
    """6-DOF rigid body integrated in fixed internal steps under a zero-order-hold load.

    mass [kg]; inertia (3×3) [kg·m²] about the CoG, body axes; cog (3,) [m] CoG offset
    from the reference point O, body axes; stiffness K (6×6) [N/m, N·m/rad, mixed];
    damping D (6×6) [N·s/m, ...]; added_mass A (6×6) [kg, kg·m, kg·m²] about O, global
    axes; position0 (3,) [m], attitude0 (3,) [rad] of O: the initial pose, also the
    equilibrium η0 of K; velocity0 (6,) [m/s, rad/s] global; max_substep [s]: the
    accuracy knob (internal steps are up to 5·max_substep long, module docstring).  Mass, inertia, cog, K and D are fixed
    after construction.  ``source`` names the body in error messages (e.g. the scene file
    and body name, used as the InputError path).
    """

    def __init__(self, mass, inertia, cog=None, stiffness=None, damping=None, added_mass=None,
                 position0=None, attitude0=None, velocity0=None, max_substep=0.01, source="rigid body"):
        self.source = str(source)
        self.mass = self._scalar(mass, "mass")
        inertia = self._array(inertia, (3, 3), "inertia")
        for field, message in inertia_problems(inertia):
            raise self._error(field, message)
        self.inertia = inertia
        self.cog = self._array(cog, (3,), "cog")
        self.stiffness = self._array(stiffness, (6, 6), "stiffness")
        self.damping = self._array(damping, (6, 6), "damping")
        self.max_substep = self._scalar(max_substep, "max_substep")
        pose = np.concatenate([self._array(position0, (3,), "position0"),
                               self._array(attitude0, (3,), "attitude0")])
        if abs(math.cos(pose[4])) < GIMBAL_TOL:
            raise self._error("attitude0", "pitch θ = ±90° is singular for ZYX Euler angles")
        self.eta0 = pose
        self.added_mass = added_mass
        self._y = np.concatenate([pose, self._array(velocity0, (6,), "velocity0")])
        self._load = np.zeros(6)

    def mass_matrix(self):
        """Total 6×6 mass matrix M_rb + A about the reference point, global axes, at the
        current attitude [kg, kg·m, kg·m²]."""
        eq = self._eq
        return eq.matrix(eq.parts(self._y[eq.order].tolist())[0])

    @property
    def added_mass(self):
        """Added mass A (6×6) about O, global axes.  The wrapper may assign a new matrix
        between steps (e.g. an attitude-dependent export); it is held over each step."""
        return self._added_mass

    @added_mass.setter
    def added_mass(self, value):
        self._added_mass = self._array(value, (6, 6), "added_mass")
        self._eq = _Equations([self])
        self._end = None   # (state, _Equations.start of it) after a step

    # -- input checks -------------------------------------------------------------------
    def _error(self, field, message):
        return InputError(self.source, None, field, message)

    def _scalar(self, value, field):
        try:
            value = float(value)
        except (TypeError, ValueError):
            raise self._error(field, f"expected a number, found {value!r}") from None
        if not (math.isfinite(value) and value > 0.0):
            raise self._error(field, f"must be positive and finite, found {value}")
        return value

    def _array(self, value, shape, field):
        if value is None:
            return np.zeros(shape)
        try:
            arr = np.array(value, dtype=float)
        except (TypeError, ValueError):
            raise self._error(field, f"expected numbers of shape {shape}") from None
        if arr.shape != shape:
            raise self._error(field, f"expected shape {shape}, found {arr.shape}")
        if not np.all(np.isfinite(arr)):
            raise self._error(field, "must be finite")
        return arr

    # -- dynamics -----------------------------------------------------------------------
    def step(self, dt, external_load, load_rate=None):
        """Advance the state by dt [s] (≥ 0) with the external load [F; M about O], in [N, N·m],
        global axes, held constant, or varying linearly at ``load_rate`` [N/s, N·m/s] from
        its value at the start of the step.  dt = 0 only replaces the held load.  Returns the
        acceleration after the step (``acceleration``)."""
        dt = float(dt)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise self._error("dt", f"communication step must be finite and ≥ 0, found {dt}")
        load = self._array(external_load, (6,), "external_load")
        y = self._y
        if dt > 0.0:
            rate = None if load_rate is None else np.asarray(load_rate, dtype=float)
            y, end, load, acc = self._eq.integrate(y, load, rate, dt, self.max_substep, self._start())
            self._end = (y, end)
            if end is not None:
                self._y, self._load = y, load
                return acc
        self._y, self._load = y, load
        return self._eq.accelerations(y, load, self._start())

    def _start(self):
        """_Equations.start of the current state if the last step left it, else None."""
        end = self._end
        return end[1] if end is not None and end[0] is self._y else None

    # -- outputs ------------------------------------------------------------------------
    @property
    def position(self):
        """Position of the reference point [m], global axes."""
        return self._y[0:3].copy()

    @property
    def attitude(self):
        """Attitude (φ, θ, ψ) [rad], R = Rz(ψ)·Ry(θ)·Rx(φ)."""
        return self._y[3:6].copy()

    @property
    def velocity(self):
        """[v; ω], in [m/s, rad/s]: reference-point velocity and angular velocity, global axes."""
        return self._y[6:12].copy()

    @property
    def acceleration(self):
        """[a; α], in [m/s², rad/s²], global axes, from the current state and the load of the
        last step (zero before the first step)."""
        return self._eq.accelerations(self._y, self._load, self._start())

    def motion(self):
        """The current motion as a state.Motion (what load kernels take as input)."""
        return Motion(self.position, self.attitude, self.velocity, self.acceleration)

    def state(self):
        """Copy of the full state (18,): [position, attitude, velocity (6), held load (6)]."""
        return np.concatenate([self._y, self._load])

    def set_state(self, state):
        """Restore a state returned by ``state()``."""
        s = self._array(state, (18,), "state")
        if abs(math.cos(s[4])) < GIMBAL_TOL:
            raise GimbalLockError(_gimbal_message(s[3:6]))
        self._y, self._load = s[:12].copy(), s[12:].copy()


class CoupledBodies:
    """Rigid bodies whose accelerations are coupled by cross-body added mass (SIMO coupled
    A∞ in ``export`` mode: the dynamics side holds it in its mass matrix).

    ``bodies``: RigidBody objects (their own added mass on the diagonal, as they are at
    construction); ``cross``: {(i, j): 6×6} global, the load on body i is −cross[i, j]·a_j.
    Equations: [[M_1+A_11, A_12, …], [A_21, M_2+A_22, …], …]·[a_1; a_2; …] = [rhs_1; rhs_2; …],
    integrated as one system (module docstring; the smallest max_substep of the bodies).
    """

    def __init__(self, bodies, cross):
        self.bodies = list(bodies)
        self.cross = {k: np.asarray(v, dtype=float) for k, v in cross.items()}
        self.max_substep = min(b.max_substep for b in self.bodies)
        self._eq = _Equations(self.bodies, self.cross)
        self._end = None   # (the bodies' states, _Equations.start of them) after a step
        self.y = None      # the state after the last step

    def step(self, dt, loads, rates=None):
        """Advance all bodies by dt [s] with their external loads (list of (6,)) held, or
        varying linearly at ``rates`` from their values at the start of the step.  Returns
        the (n, 6) accelerations after the step (``accelerations``)."""
        loads = np.array(loads, dtype=float).ravel()
        last = self._last()
        y, end = (last[0], last[2]) if last else (np.concatenate([b._y for b in self.bodies]), None)
        acc = None
        if dt > 0.0:
            if rates is not None and not (type(rates) is np.ndarray and rates.ndim == 1):
                rates = np.asarray(rates, dtype=float).reshape(-1)
            y, end, loads, acc = self._eq.integrate(y, loads, rates, dt, self.max_substep, end)
        self.y = y   # every body's [η; ν], one after the other (the bodies hold views of it)
        held = []
        for i, b in enumerate(self.bodies):
            b._y, b._load = y[12 * i:12 * i + 12], loads[6 * i:6 * i + 6]
            held += (b._y, b._load)
        self._end = (held, y, loads, end)
        if acc is None or end is None:
            acc = self._eq.accelerations(y, loads, end)
        return acc.reshape(-1, 6)

    def _last(self):
        """(state, loads, _Equations.start of the state or None) of all bodies as the last
        step left them, while the bodies still hold them; else None."""
        end = self._end
        if end is None:
            return None
        held = end[0]
        for i, b in enumerate(self.bodies):
            if b._y is not held[2 * i] or b._load is not held[2 * i + 1]:
                return None
        return end[1:]

    def accelerations(self):
        """(n, 6) accelerations from the current states and the last held loads."""
        last = self._last()
        if last:
            return self._eq.accelerations(last[0], last[1], last[2]).reshape(-1, 6)
        y = np.concatenate([b._y for b in self.bodies])
        return self._eq.accelerations(y, np.concatenate([b._load for b in self.bodies])).reshape(-1, 6)
