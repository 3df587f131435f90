"""RIFLEX CONB: ball joint, hinge or universal joint of zero length between two bodies.

Side A and side B are floating bodies (or B is the earth).  The joint point is
``point_a`` in A's body axes and ``point_b`` in B's body axes (a global point when B is
the earth).  The rigid connection is replaced by a stiff spring–damper (penalty) so each
side can run in its own FMU; all loads are ON the side, global axes, [force N; moment
N·m about that side's reference point] (about the joint point itself for the earth).

Translation (all three directions are always held)::

    d = p_B − p_A                      gap between the world positions of the two points
    f = k_lin·d + c_lin·(v_pB − v_pA)  force on A at p_A;  −f on B at p_B

Rotation, about side A's axes::

    R_def = (R_Aᵀ·R_B)·R_rel0ᵀ         relative rotation since the initial one (R_rel0)
    θ     = log(R_def)                 rotation vector [rad], A's axes
    ω_rel = R_Aᵀ·(ω_B − ω_A)           [rad/s], A's axes
    m_i   = k_rot·θ_i + c_rot·ω_rel,i  for a fixed axis i (code 1), 0 for a free one (code 0)
    moment on A = R_A·m,  on B = −R_A·m

The codes (IRX, IRY, IRZ) make the joint type: 0 0 0 ball joint (no moment), 1 1 0 hinge
about A's z axis (free about z only), 1 0 0 universal joint that passes torque about A's
x axis (the shaft) and bends freely about y and z, 1 1 1 rigid.  The split of θ into
axes is exact while the fixed components are small; for a large rotation about a free
axis (a hinge swung by γ) a small bend ε about a fixed axis gives a moment of size
≈ ε·(γ/2)/sin(γ/2) turned by γ/2 about the free axis (rotation-vector coupling).

The joint node's own mass, volume, drag and added mass (``node``, a LumpedBody) act at
the joint point and are carried entirely by side A: one call of the lumped kernel with
A's motion, offset = point_a.  Name the side that should carry them A (with the earth
as B, the node loads the moving body).
"""
import math
from dataclasses import dataclass, field, replace

import numpy as np

from .kinematics import cross_floats, rotate, rotate_back, rotation, skew
from .lumped import LumpedBody


def log_rotation(rot):
    """Rotation vector θ [rad] (axis·angle, |θ| ≤ π) of a rotation matrix: exp([θ]×) = rot.

    atan2 gives the angle without the arccos loss near 0 and π; near 0 a series avoids
    0/0; beyond π/2 the axis comes from the symmetric part (1 − cos)·n·nᵀ, which stays
    well conditioned up to π, with its sign taken from the skew part.
    """
    return np.array(_log_rotation(np.asarray(rot, dtype=float).tolist()))


def _log_rotation(rows):
    """``log_rotation`` of a rotation given by its rows of floats: three floats (the joint
    evaluates it every step; numpy's per-call cost dominates on 3×3)."""
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = rows
    wx, wy, wz = 0.5 * (r21 - r12), 0.5 * (r02 - r20), 0.5 * (r10 - r01)   # sin·n
    s, c = math.sqrt(wx * wx + wy * wy + wz * wz), 0.5 * (r00 + r11 + r22 - 1.0)
    angle = math.atan2(s, c)
    if angle < 1e-4:
        k = 1.0 + angle * angle / 6.0   # angle/sin(angle)
    elif c >= 0.0:
        k = angle / s
    else:   # (1 − c)·n·nᵀ = sym(rot) − c·1: its largest diagonal entry's column is ∥ n
        cols = ((r00 - c, 0.5 * (r10 + r01), 0.5 * (r20 + r02)),
                (0.5 * (r01 + r10), r11 - c, 0.5 * (r21 + r12)),
                (0.5 * (r02 + r20), 0.5 * (r12 + r21), r22 - c))
        nx, ny, nz = cols[max(range(3), key=lambda i: cols[i][i])]
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
        k = angle / norm if nx * wx + ny * wy + nz * wz >= 0.0 else -angle / norm
        return nx * k, ny * k, nz * k
    return wx * k, wy * k, wz * k


def initial_relative_rotation(attitude_a, attitude_b=None):
    """R_rel0 = R_Aᵀ·R_B at the start (R_B = I for the earth), attitudes (φ, θ, ψ) [rad]."""
    rot_b = np.eye(3) if attitude_b is None else rotation(attitude_b)
    return rotation(attitude_a).T @ rot_b


@dataclass
class BallJoint:
    """CONB joint between side A and side B (``motion_b`` None: B is the earth).

    point_a (3,) [m] A's body axes; point_b (3,) [m] B's body axes or global for the earth;
    k_lin [N/m], c_lin [N·s/m], k_rot [N·m/rad], c_rot [N·m·s/rad];
    free (3,) bool, True = free axis (IRX/IRY/IRZ = 0), about A's x, y, z;
    node: LumpedBody or None, the joint's own mass etc., carried by A at point_a (its
    offset is replaced by point_a); r_rel0: initial relative rotation R_Aᵀ·R_B.
    """
    name: str
    point_a: np.ndarray
    point_b: np.ndarray
    k_lin: float
    c_lin: float
    k_rot: float = 0.0
    c_rot: float = 0.0
    free: np.ndarray = field(default_factory=lambda: np.ones(3, dtype=bool))
    node: LumpedBody | None = None
    r_rel0: np.ndarray = field(default_factory=lambda: np.eye(3))

    def __post_init__(self):
        self.point_a = np.asarray(self.point_a, dtype=float).reshape(3)
        self.point_b = np.asarray(self.point_b, dtype=float).reshape(3)
        self.free = np.asarray(self.free, dtype=bool).reshape(3)
        self.r_rel0 = np.asarray(self.r_rel0, dtype=float).reshape(3, 3)
        if self.node is not None:
            self.node = replace(self.node, offset=self.point_a)

    @property
    def uses_current(self):
        return self.node is not None and self.node.uses_current

    @property
    def uses_acceleration(self):
        return self.node is not None and self.node.uses_acceleration

    def deformation(self, motion_a, motion_b):
        """Gap d = p_B − p_A [m] (global) and rotation vector θ [rad] (A's axes)."""
        return self.loads_and_deformation(motion_a, motion_b, None)[2:]

    def loads(self, motion_a, motion_b, env):
        """(load on A, load on B), each (6,) global about that side's reference point
        (the earth's about the joint point).  The node's static and drag loads are in A's;
        its acceleration loads are in ``mass_matrix``/``velocity_load`` (side A)."""
        return self.loads_and_deformation(motion_a, motion_b, env)[:2]

    def loads_and_deformation(self, motion_a, motion_b, env):
        """(load on A, load on B, gap d, rotation vector θ) in one pass; env None: no node
        loads.  On plain floats: every product here is 3×3 or smaller."""
        ra_rows = motion_a.rot_rows
        ax, ay, az = motion_a.position.tolist()
        vax, vay, vaz, wax, way, waz = motion_a.velocity.tolist()
        rax, ray, raz = rotate(ra_rows, *self.point_a.tolist())
        if motion_b is None:   # the earth: the point is global and still
            rb_rows, (rbx, rby, rbz) = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0)), (0.0, 0.0, 0.0)
            pbx, pby, pbz = self.point_b.tolist()
            vbx = vby = vbz = wbx = wby = wbz = 0.0
        else:
            rb_rows = motion_b.rot_rows
            rbx, rby, rbz = rotate(rb_rows, *self.point_b.tolist())
            bx, by, bz = motion_b.position.tolist()
            pbx, pby, pbz = bx + rbx, by + rby, bz + rbz
            vbx, vby, vbz, wbx, wby, wbz = motion_b.velocity.tolist()
            cx, cy, cz = cross_floats(wbx, wby, wbz, rbx, rby, rbz)
            vbx, vby, vbz = vbx + cx, vby + cy, vbz + cz
        dx, dy, dz = pbx - ax - rax, pby - ay - ray, pbz - az - raz
        cx, cy, cz = cross_floats(wax, way, waz, rax, ray, raz)   # A's point moves at v_A + ω_A × r_A
        k, c = self.k_lin, self.c_lin
        fx, fy, fz = (k * dx + c * (vbx - vax - cx), k * dy + c * (vby - vay - cy),
                      k * dz + c * (vbz - vaz - cz))
        # R_def = R_Aᵀ·R_B·R_rel0ᵀ, row by row
        ra_cols = tuple(zip(*ra_rows))
        ab = [rotate_back(rb_rows, *col) for col in ra_cols]  # row i of R_Aᵀ·R_B: R_Bᵀ·(column i of R_A)
        r0 = self.r_rel0.tolist()
        rdef = [rotate(r0, *row) for row in ab]               # (R_rel0·rowᵀ)ᵀ = row·R_rel0ᵀ
        theta = _log_rotation(rdef)
        w_rel = rotate_back(ra_rows, wbx - wax, wby - way, wbz - waz)
        kr, cr = self.k_rot, self.c_rot
        mb = [0.0 if free else kr * t + cr * w for free, t, w in zip(self.free.tolist(), theta, w_rel)]
        mx, my, mz = rotate(ra_rows, *mb)
        ux, uy, uz = cross_floats(rax, ray, raz, fx, fy, fz)
        tx, ty, tz = cross_floats(rbx, rby, rbz, fx, fy, fz)
        load_a = np.array((fx, fy, fz, ux + mx, uy + my, uz + mz))
        if self.node is not None and env is not None:
            load_a += self.node.load(motion_a, env)
        return (load_a, np.array((-fx, -fy, -fz, -tx - mx, -ty - my, -tz - mz)), np.array((dx, dy, dz)),
                np.array(theta))

    def c_params(self):
        """joint.c's parameters: [point_a (3), point_b (3), k_lin, c_lin, k_rot, c_rot,
        free (3, 0/1), r_rel0 (9, row-major)] (the node: its own ``c_params``)."""
        return (self.point_a.tolist() + self.point_b.tolist() + [self.k_lin, self.c_lin, self.k_rot, self.c_rot]
                + [float(f) for f in self.free.tolist()] + self.r_rel0.ravel().tolist())

    def mass_matrix(self, motion_a):
        """6×6 mass of the node about A's reference point (zeros without a node)."""
        return np.zeros((6, 6)) if self.node is None else self.node.mass_matrix(motion_a)

    def velocity_load(self, motion_a):
        """Centripetal inertia load of the node on A (zeros without a node)."""
        return np.zeros(6) if self.node is None else self.node.velocity_load(motion_a)


def _reduced(m_a, m_b):
    return float(m_a) if m_b is None else m_a * m_b / (m_a + m_b)


def default_stiffness(m_a, m_b, dt, n_steps=12):
    """Penalty stiffness k = μ·ω_n² [N/m, or N·m/rad with inertias] for a joint that a
    fixed-step explicit (Jacobi) co-simulation with step dt [s] keeps stable.

    μ = m_a·m_b/(m_a + m_b) is the reduced mass (μ = m_a when B is None, the earth) and
    ω_n = 2π/(n_steps·dt): the joint's natural period spans n_steps communication steps.
    Pass inertias [kg·m²] instead of masses for k_rot.  The masses are the effective
    ones at the joint point, added mass and the node included (see ``effective_mass``:
    a point far from the centre of gravity moves far more easily than the whole body).

    Stability analysis.  Side A feels +f, side B −f, f = k·d + c·ḋ, d = x_B − x_A.  In a
    Jacobi co-simulation f is computed from both sides' states at t_n and held over the
    step while each side integrates its own motion, so over the step d̈ = −f_n/μ.  With
    h = dt, Ω = ω_n·h (ω_n² = k/μ) and ζ = c/(2·μ·ω_n), one step maps (d, h·ḋ) by

        d'   = (1 − Ω²/2)·d + (1 − ζΩ)·hḋ
        hḋ'  = −Ω²·d        + (1 − 2ζΩ)·hḋ

    with characteristic polynomial z² − T·z + D, T = 2 − 2ζΩ − Ω²/2, D = 1 − 2ζΩ + Ω²/2.
    Both roots lie in the unit circle (Jury: |D| < 1, |T| < 1 + D) iff, for 0 < ζ ≤ 1,

        Ω < 4ζ   and   Ω < 1/ζ.

    Without damping D = 1 + Ω²/2 > 1: the held force pumps energy in at any step, so
    the damper is required.  Defaults n_steps = 12, ζ = 0.7 give Ω = 0.524 against a
    limit of 1.43: stable as long as the true reduced mass is above 0.13 of the one
    passed (the effective mass passed is already the smallest over all directions), and
    the gap decays by √D ≈ 0.68 per step.  12 rather than 20 steps per period makes the
    joint 2.8× stiffer: two 100 m barges in 1 m/s current keep their gap below 1 mm at
    dt = 0.05 s.  The static gap under a load F
    is F/k, so fewer steps per period (stiffer) shrink the gap and the margin together.
    The same holds for the rotation with inertias (small angles: θ̈ = −m/I_red).
    """
    w = 2.0 * np.pi / (n_steps * dt)
    return _reduced(m_a, m_b) * w * w


def default_damping(m_a, m_b, dt, n_steps=12, zeta=0.7):
    """Penalty damping c = 2ζ·μ·ω_n [N·s/m, or N·m·s/rad with inertias] matching
    ``default_stiffness`` (same μ and ω_n; analysis there)."""
    return 2.0 * zeta * _reduced(m_a, m_b) * 2.0 * np.pi / (n_steps * dt)


def effective_mass(mass6, r_global):
    """Smallest effective translational mass [kg] at a point and smallest effective
    inertia [kg·m²] of a body with 6×6 mass matrix ``mass6`` (about its reference point,
    global axes, added mass included), the point at global offset r from that point.

    The point's velocity is J·[v; ω] with J = [I, −[r]×]; a force F at the point gives
    the point acceleration J·M⁻¹·Jᵀ·F, so the least mass is 1/λ_max(J·M⁻¹·Jᵀ); likewise
    1/λ_max of the rotational block of M⁻¹ for a pure moment.
    """
    inv = np.linalg.inv(np.asarray(mass6, dtype=float))
    r = np.asarray(r_global, dtype=float).reshape(3)
    jac = np.hstack([np.eye(3), -skew(r)])
    lin = np.linalg.eigvalsh(jac @ inv @ jac.T)[-1]
    rot = np.linalg.eigvalsh(inv[3:, 3:])[-1]
    return 1.0 / lin, 1.0 / rot
