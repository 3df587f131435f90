"""RIFLEX BODY: a lumped mass, volume, drag and added mass at one point of a floating body.

The point sits at offset r (body axes, m) from the body's reference point; its global
offset is R·r with R the body-to-global rotation.  All loads are the load ON the body,
global axes, [force N; moment N·m about the reference point].

Static and drag loads (``LumpedBody.load``)::

    weight      F = −AM·g·e_z                       (AM [kg])
    buoyancy    F = +ρ·g·AE·e_z                     (AE [m³]; applied whatever the depth)
    drag        F_i = CD_i·vrel_i·|vrel_i|          (CD [N/(m/s)²], per axis)
                vrel = u_current − (v + ω × R·r)    (water past the point, global; the current
                                                     at the point's height, physics/current.py)

ICOO=GLOBAL: the drag axes i are the global axes.  ICOO=LOCAL: they are the body's axes
(vrel is rotated into body axes, the force computed there and rotated back).  In the
manual LOCAL means the axes of the neighbour line element; on a floating body the
neighbour is the body itself.  Moments follow from the force acting at the point.

Acceleration loads: the point's translational mass (no rotary inertia of its own)::

    M_p = AM·I + Q·diag(AMX, AMY, AMZ)·Qᵀ        Q = I (GLOBAL) or R (LOCAL)
    inertia load at the point  F = −M_p·a_p,     a_p = a + α × R·r + ω × (ω × R·r)

transferred to the reference point this splits into

    −M6·[a; α]      M6 = ``mass_matrix``  (kinematics.point_mass_matrix(M_p, R·r))
    ``velocity_load`` = transfer(−M_p·(ω × (ω × R·r)), R·r)   (centripetal, velocity only)

so the exact total acceleration load is −M6·acceleration + velocity_load.  The added
mass uses the Morison form −A·a_p.

In waves (``env.water``, the scene's incident wave field, physics/wave_kinematics.py) the point
feels the water's motion at its instantaneous position P, the Morison form for a small body
(the relative-velocity / relative-acceleration form of RIFLEX and OrcaFlex)::

    vrel = u_current(z_P) + u_wave(P, t) − v_P                       drag as above
    F_water = ρ·AE·a_wave(P, t) + Q·diag(AMX, AMY, AMZ)·Qᵀ·a_wave(P, t)  Froude–Krylov + added mass

(with −A·a_p above, the added mass acts on the relative acceleration a_wave − a_p).  A point above
the instantaneous surface (z_P > η(P, t)) is dry: no drag (current or waves) and no water
acceleration load; a body crossing the surface switches at its point (a lumped body has no
size: all or nothing, as its point is wet or dry).  Weight, buoyancy ρ·g·AE and the added
mass in the mass matrix stay as the deck defines them (constant), wet or dry.
"""
from dataclasses import dataclass, field

import numpy as np

from .kinematics import cross_floats, point_mass_matrix, rotate, rotate_back



def _vec3(x):
    return np.asarray(x, dtype=float).reshape(3)


def coordinate_code(icoo):
    """'GLOBAL' or 'LOCAL' for an ICOO code (first four letters count, any case), else None."""
    return {"GLOB": "GLOBAL", "LOCA": "LOCAL"}.get(str(icoo)[:4].upper())


@dataclass
class LumpedBody:
    """RIFLEX BODY attached at ``offset`` (body axes, m) of a floating body.

    am [kg] mass, ae [m³] displaced volume, icoo 'GLOBAL' or 'LOCAL' (axes of cd and
    added_mass), cd (3,) [N/(m/s)²] quadratic drag per axis, added_mass (3,) [kg]
    (AMX, AMY, AMZ); waves: feels ``env.water`` when the scene has waves.  Follows the effect
    protocol of physics/state.py, plus ``velocity_load`` (see the module docstring for the
    split of the inertia load).
    """
    name: str
    offset: np.ndarray
    am: float = 0.0
    ae: float = 0.0
    icoo: str = "GLOBAL"
    cd: np.ndarray = field(default_factory=lambda: np.zeros(3))
    added_mass: np.ndarray = field(default_factory=lambda: np.zeros(3))
    waves: bool = True

    def __post_init__(self):
        self.offset, self.cd, self.added_mass = _vec3(self.offset), _vec3(self.cd), _vec3(self.added_mass)
        self.am, self.ae = float(self.am), float(self.ae)
        code = coordinate_code(self.icoo)
        if code is None:
            raise ValueError(f"{self.name}: ICOO must be GLOBAL or LOCAL, got {self.icoo!r}")
        self.icoo = code

    @property
    def uses_current(self):
        return bool(np.any(self.cd != 0.0))

    @property
    def uses_acceleration(self):
        return bool(self.am != 0.0 or np.any(self.added_mass != 0.0))

    def _axes(self, rot):
        """Rotation from the coefficient axes to global axes."""
        return rot if self.icoo == "LOCAL" else np.eye(3)

    # load and velocity_load work on plain floats: numpy's per-call cost dominates on 3-vectors

    def _per_axis(self, motion, coef, power, x, y, z):
        """Q·(c_i·u_i·|u_i| if power else c_i·u_i) with u = Qᵀ·(x, y, z), global, for the coefficient axes Q
        (R if LOCAL, else I) and coefficients c = ``coef``: three floats."""
        local = self.icoo == "LOCAL"
        if local:
            x, y, z = rotate_back(motion.rot_rows, x, y, z)
        # c·(u·|u|), as numpy did: an overflowed u·|u| stays non-finite even where c = 0, so a
        # diverging run still ends in fmi2Error
        x, y, z = (c * (u * abs(u)) if power else c * u for c, u in zip(coef, (x, y, z)))
        return rotate(motion.rot_rows, x, y, z) if local else (x, y, z)

    def load(self, motion, env):
        """Weight, buoyancy and drag on the body [N, N·m], global, about the reference point."""
        rx, ry, rz = rotate(motion.rot_rows, *self.offset.tolist())
        vx, vy, vz, wx, wy, wz = motion.velocity.tolist()
        px, py, pz = cross_floats(wx, wy, wz, rx, ry, rz)
        ox, oy, oz = motion.position.tolist()
        cx, cy, cz = env.current_xyz(oz + rz)   # the current at the point
        water = env.water if self.waves else None
        gx = gy = gz = 0.0   # the water's acceleration load
        if water is not None:
            row = water.at(ox + rx, oy + ry, oz + rz)
            if water.wet(row, oz + rz):
                cx, cy, cz = cx + row[0], cy + row[1], cz + row[2]
                ax, ay, az = row[3:6].tolist()
                mx, my, mz = self._per_axis(motion, self.added_mass.tolist(), 0, ax, ay, az)
                fk = env.rho * self.ae
                gx, gy, gz = fk * ax + mx, fk * ay + my, fk * az + mz
            else:   # dry: no drag
                cx, cy, cz = vx + px, vy + py, vz + pz
        ux, uy, uz = cx - (vx + px), cy - (vy + py), cz - (vz + pz)    # water past the point
        fx, fy, fz = self._per_axis(motion, self.cd.tolist(), 1, ux, uy, uz)
        fx, fy, fz = fx + gx, fy + gy, fz + gz
        fz += env.rho * env.g * self.ae - self.am * env.g
        return np.array((fx, fy, fz) + cross_floats(rx, ry, rz, fx, fy, fz))

    def point_mass(self, motion):
        """3×3 translational mass M_p of the point [kg], global axes."""
        q = self._axes(motion.rot)
        return self.am * np.eye(3) + q @ np.diag(self.added_mass) @ q.T

    def mass_matrix(self, motion):
        """6×6 mass M6 about the reference point, global axes; acceleration load −M6·[a; α]."""
        return point_mass_matrix(self.point_mass(motion), motion.rot @ self.offset)

    C_TAG = "lumped"   # its record in a compiled FMU (lumped.c)

    def c_params(self):
        """lumped.c's parameters: [offset (3), am, ae, local (0/1), cd (3), added_mass (3)]."""
        return (self.offset.tolist() + [self.am, self.ae, float(self.icoo == "LOCAL")] + self.cd.tolist()
                + self.added_mass.tolist())

    def velocity_load(self, motion):
        """Centripetal part of the inertia load [N, N·m]: transfer(−M_p·ω×(ω×R r), R r), with
        M_p·c = AM·c + Q·diag(AMX, AMY, AMZ)·Qᵀ·c."""
        rx, ry, rz = rotate(motion.rot_rows, *self.offset.tolist())
        wx, wy, wz = motion.velocity[3:].tolist()
        cx, cy, cz = cross_floats(wx, wy, wz, *cross_floats(wx, wy, wz, rx, ry, rz))
        ax, ay, az = self._per_axis(motion, self.added_mass.tolist(), 0, cx, cy, cz)
        am = self.am
        fx, fy, fz = -(am * cx + ax), -(am * cy + ay), -(am * cz + az)
        return np.array((fx, fy, fz) + cross_floats(rx, ry, rz, fx, fy, fz))
