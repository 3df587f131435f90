"""6-DOF rigid body: the dynamics partner that stands in for a vessel simulator in
co-simulation tests.  Pure numpy; the FMU wrapper feeds it the summed loads of the load
FMUs and publishes its motion.

Conventions (DESIGN.md)
-----------------------
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
Classic fixed-step RK4 over n = ceil(dt / max_substep) equal substeps of each
communication step, on the 12 states [η; ν].  Chosen over scipy's solve_ivp after
measuring a coupled 6-DOF case (periods ~3 s, 10 s simulated, max_substep 0.01 s):
RK4 0.09 s whatever the communication step; solve_ivp (DOP853, rtol 1e-9) 0.36 s at
dt = 0.01 s (its per-call start-up dominates), 0.06 s at dt = 0.1 s, 0.03 s at dt = 1 s,
but 0.28–0.36 s at any dt once held to steps ≤ max_substep.  Co-simulation steps are
short, and fixed substeps make the result independent of how the master splits time
(1 step of 1 s = 10 steps of 0.1 s to round-off when max_substep divides both).
Accuracy: RK4's phase error is about 80/N⁴ per period with N substeps per period, so
max_substep ≤ T_min/100 (T_min the shortest natural period or decay time) gives ~1e-6
per period.  Very stiff springs or heavy damping need max_substep below ~T_min/3 for
stability.
"""
import math

import numpy as np

from ..errors import InputError
from .kinematics import point_mass_matrix, rotation, skew
from .state import Motion

GIMBAL_TOL = 1e-6  # |cos θ| below which the Euler-angle rates are declared singular


class GimbalLockError(ArithmeticError):
    """The pitch angle reached ±90°, where ZYX Euler-angle rates are undefined."""


def _euler_rates(theta, psi, ct, omega):
    """[φ̇, θ̇, ψ̇] solving ω = T·[φ̇, θ̇, ψ̇] (module docstring); ct = cos θ, checked by the caller."""
    cp, sp = math.cos(psi), math.sin(psi)
    wx, wy, wz = omega
    phi_dot = (cp * wx + sp * wy) / ct
    return np.array([phi_dot, -sp * wx + cp * wy, wz + math.sin(theta) * phi_dot])


def _gimbal_message(attitude):
    phi, theta, psi = np.degrees(attitude)
    return (f"pitch θ = {theta:.4f}° reached ±90° (roll {phi:.4f}°, yaw {psi:.4f}°): the "
            "ZYX Euler-angle rates are singular there; the rigid body cannot go on")


class RigidBody:
    """6-DOF rigid body integrated with RK4 substeps under a zero-order-hold load.

    mass [kg]; inertia (3×3) [kg·m²] about the CoG, body axes; cog (3,) [m] CoG offset
    from the reference point O, body axes; stiffness K (6×6) [N/m, N·m/rad, mixed];
    damping D (6×6) [N·s/m, ...]; added_mass A (6×6) [kg, kg·m, kg·m²] about O, global
    axes; position0 (3,) [m], attitude0 (3,) [rad] of O: the initial pose, also the
    equilibrium η0 of K; velocity0 (6,) [m/s, rad/s] global; max_substep [s] the largest
    internal RK4 step.  Mass, inertia and cog are fixed after construction.  ``source`` names the body in error messages (e.g. the scene file
    and body name, used as the InputError path).
    """

    def __init__(self, mass, inertia, cog=None, stiffness=None, damping=None, added_mass=None,
                 position0=None, attitude0=None, velocity0=None, max_substep=0.01, source="rigid body"):
        self.source = str(source)
        self.mass = self._scalar(mass, "mass")
        inertia = self._array(inertia, (3, 3), "inertia")
        if not np.allclose(inertia, inertia.T, rtol=1e-12, atol=1e-12 * np.abs(inertia).max()):
            raise self._error("inertia", "must be symmetric")
        if np.linalg.eigvalsh(inertia).min() <= 0.0:
            raise self._error("inertia", "must be positive definite")
        self.inertia = inertia
        self.cog = self._array(cog, (3,), "cog")
        self.stiffness = self._array(stiffness, (6, 6), "stiffness")
        self.damping = self._array(damping, (6, 6), "damping")
        self.added_mass = added_mass
        self.max_substep = self._scalar(max_substep, "max_substep")
        pose = np.concatenate([self._array(position0, (3,), "position0"),
                               self._array(attitude0, (3,), "attitude0")])
        if abs(math.cos(pose[4])) < GIMBAL_TOL:
            raise self._error("attitude0", "pitch θ = ±90° is singular for ZYX Euler angles")
        self.eta0 = pose
        # M_rb in body axes is constant; in global axes it is Q·M_b·Qᵀ with Q = diag(R, R).
        self._mrb_body = point_mass_matrix(self.mass * np.eye(3), self.cog)
        self._mrb_body[3:, 3:] += inertia
        self._y = np.concatenate([pose, self._array(velocity0, (6,), "velocity0")])
        self._load = np.zeros(6)

    def mass_matrix(self):
        """Total 6×6 mass matrix M_rb + A about the reference point, global axes, at the
        current attitude [kg, kg·m, kg·m²]."""
        return self._mass_and_bias(self._y[3:6], np.zeros(3))[0]

    @property
    def added_mass(self):
        """Added mass A (6×6) about O, global axes.  The wrapper may assign a new matrix
        between steps (e.g. an attitude-dependent export); it is held over each step."""
        return self._added_mass

    @added_mass.setter
    def added_mass(self, value):
        self._added_mass = self._array(value, (6, 6), "added_mass")

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
    def _mass_and_bias(self, attitude, omega):
        """Total mass matrix M_rb + A and the centripetal/gyroscopic vector b (global)."""
        rot = rotation(attitude)
        q = np.zeros((6, 6))
        q[:3, :3] = q[3:, 3:] = rot
        mrb = q @ self._mrb_body @ q.T
        w = skew(omega)  # skew products: np.cross costs ~10 µs a call, this is the hot loop
        bias = np.concatenate([self.mass * (w @ (w @ (rot @ self.cog))), w @ (mrb[3:, 3:] @ omega)])
        return mrb + self._added_mass, bias

    def _system(self, y, load):
        """(M_rb + A, right-hand side) of the equations of motion at state y."""
        eta, nu = y[:6], y[6:]
        mtot, bias = self._mass_and_bias(eta[3:], nu[3:])
        return mtot, load - self.stiffness @ (eta - self.eta0) - self.damping @ nu - bias

    def _accel(self, y, load):
        try:
            return np.linalg.solve(*self._system(y, load))
        except np.linalg.LinAlgError:
            raise self._error("added_mass", "mass matrix M_rb + A is singular") from None

    def _deriv(self, y, load, cos_sign):
        theta, psi = y[4], y[5]
        ct = math.cos(theta)
        if ct * cos_sign < GIMBAL_TOL:  # also catches a substep that jumped across ±90°
            raise GimbalLockError(_gimbal_message(y[3:6]))
        return np.concatenate([y[6:9], _euler_rates(theta, psi, ct, y[9:]), self._accel(y, load)])

    def step(self, dt, external_load, load_rate=None):
        """Advance the state by dt [s] (≥ 0) with the external load [F; M about O] [N, N·m],
        global axes, held constant, or varying linearly at ``load_rate`` [N/s, N·m/s] from
        its value at the start of the step.  dt = 0 only replaces the held load."""
        dt = float(dt)
        if not (math.isfinite(dt) and dt >= 0.0):
            raise self._error("dt", f"communication step must be finite and ≥ 0, found {dt}")
        load = self._array(external_load, (6,), "external_load")
        y = self._y
        if dt > 0.0:
            # The 1e-12 guard keeps 0.1/0.01 at 10 substeps despite round-off.
            n = max(1, math.ceil(dt / self.max_substep * (1.0 - 1e-12)))
            h = dt / n
            sign = 1.0 if math.cos(y[4]) > 0.0 else -1.0
            f = self._deriv
            rate = np.zeros(6) if load_rate is None else np.asarray(load_rate, dtype=float)
            for m in range(n):
                l0 = load + rate * (m * h)
                lh, l1 = l0 + rate * (0.5 * h), l0 + rate * h
                k1 = f(y, l0, sign)
                k2 = f(y + 0.5 * h * k1, lh, sign)
                k3 = f(y + 0.5 * h * k2, lh, sign)
                k4 = f(y + h * k3, l1, sign)
                y = y + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            load = load + rate * dt
            if abs(math.cos(y[4])) < GIMBAL_TOL:
                raise GimbalLockError(_gimbal_message(y[3:6]))
        self._y, self._load = y, load

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
        """[v; ω] [m/s, rad/s]: reference-point velocity and angular velocity, global axes."""
        return self._y[6:12].copy()

    @property
    def acceleration(self):
        """[a; α] [m/s², rad/s²], global axes, from the current state and the load of the
        last step (zero before the first step)."""
        return self._accel(self._y, self._load)

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

    ``bodies``: RigidBody objects (their own added mass on the diagonal); ``cross``:
    {(i, j): 6×6} global, the load on body i is −cross[i, j]·a_j.  Equations:
    [[M_1+A_11, A_12, …], [A_21, M_2+A_22, …], …]·[a_1; a_2; …] = [rhs_1; rhs_2; …],
    integrated with RK4 in equal substeps (the smallest max_substep of the bodies).
    """

    def __init__(self, bodies, cross):
        self.bodies = list(bodies)
        self.cross = {k: np.asarray(v, dtype=float) for k, v in cross.items()}
        self.max_substep = min(b.max_substep for b in self.bodies)

    def _solve(self, ys, loads):
        n = len(self.bodies)
        big, rhs = np.zeros((6 * n, 6 * n)), np.zeros(6 * n)
        for i, (b, y, load) in enumerate(zip(self.bodies, ys, loads)):
            big[6 * i:6 * i + 6, 6 * i:6 * i + 6], rhs[6 * i:6 * i + 6] = b._system(y, load)
        for (i, j), m in self.cross.items():
            big[6 * i:6 * i + 6, 6 * j:6 * j + 6] += m
        return np.linalg.solve(big, rhs).reshape(n, 6)

    def _deriv(self, ys, loads):
        acc = self._solve(ys, loads)
        out = []
        for y, a in zip(ys, acc):
            ct = math.cos(y[4])
            if abs(ct) < GIMBAL_TOL:
                raise GimbalLockError(_gimbal_message(y[3:6]))
            out.append(np.concatenate([y[6:9], _euler_rates(y[4], y[5], ct, y[9:]), a]))
        return np.array(out)

    def step(self, dt, loads, rates=None):
        """Advance all bodies by dt [s] with their external loads (list of (6,)) held, or
        varying linearly at ``rates`` from their values at the start of the step."""
        loads = np.array(loads, dtype=float)
        rates = np.zeros_like(loads) if rates is None else np.array(rates, dtype=float)
        ys = np.array([b._y for b in self.bodies])
        if dt > 0.0:
            n = max(1, math.ceil(dt / self.max_substep * (1.0 - 1e-12)))
            h = dt / n
            for m in range(n):
                l0 = loads + rates * (m * h)
                lh, l1 = l0 + rates * (0.5 * h), l0 + rates * h
                k1 = self._deriv(ys, l0)
                k2 = self._deriv(ys + 0.5 * h * k1, lh)
                k3 = self._deriv(ys + 0.5 * h * k2, lh)
                k4 = self._deriv(ys + h * k3, l1)
                ys = ys + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
            loads = loads + rates * dt
        for b, y, load in zip(self.bodies, ys, loads):
            b._y, b._load = y, load

    def accelerations(self):
        """(n, 6) accelerations from the current states and the last held loads."""
        return self._solve([b._y for b in self.bodies], [b._load for b in self.bodies])
