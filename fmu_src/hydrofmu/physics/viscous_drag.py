"""AQWA-style viscous drag: a 6×6 quadratic damping matrix in body axes.

    w = [Rᵀ·v ; Rᵀ·ω]                    body velocity of the reference point [m/s, rad/s], body axes
    RELATIVE:  w[0:3] = Rᵀ·(v − u_c)     the current velocity u_c (global) at the reference point's
                                         height is subtracted (the matrix acts there)
    F_body = −V · (w ∘ |w|)              [N; N·m], body axes, moments about the reference point
    F = [R·F_body[0:3] ; R·F_body[3:6]]  global axes

Our extension (``waves = true``, with RELATIVE only; AQWA's hull drag sees the current alone):
u_c also holds the incident-wave particle velocity at the reference point's instantaneous
position (physics/wave_kinematics.py), none when that point is above the instantaneous surface.

V_ij [N·s²/m², ...] couples load i with velocity j (AQWA layout, V11 surge … V66 yaw).
The matrix is taken about the body's reference point: for AQWA data (given at the centre of
gravity) the scene's reference point should be that centre of gravity.
"""
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .kinematics import rotate, rotate_back


@dataclass
class ViscousDrag:
    """Viscous drag load kernel (effect protocol of physics.state).

    ``matrix``: 6×6 V matrix, body axes; ``relative``: True for AQWA OPTION=RELATIVE
    (velocity relative to the current), False for ABSOLUTE; ``waves``: the relative velocity
    also subtracts the incident waves' (``env.water``; our extension, RELATIVE only).
    """
    name: str
    matrix: np.ndarray
    relative: bool = False
    waves: bool = False
    uses_acceleration: ClassVar[bool] = False

    def __post_init__(self):
        self.matrix = np.array(self.matrix, dtype=float)
        if self.matrix.shape != (6, 6):
            raise ValueError(f"viscous drag matrix must be 6×6, got {self.matrix.shape}")
        if self.waves and not self.relative:
            raise ValueError("viscous drag: waves = true needs the RELATIVE option (the velocity relative to the water)")

    @property
    def uses_current(self):
        return self.relative

    def load(self, motion, env):
        """[force N; moment N·m about the reference point], global axes."""
        # plain floats for the rotations: numpy's per-call cost dominates on 3-vectors
        rows = motion.rot_rows
        vx, vy, vz, wx, wy, wz = motion.velocity.tolist()
        if self.relative:   # the current at the reference point
            x, y, z = motion.position.tolist()
            cx, cy, cz = env.current_xyz(z)
            if self.waves and env.water is not None:
                row = env.water.at(x, y, z)
                if env.water.wet(row, z):
                    cx, cy, cz = cx + row[0], cy + row[1], cz + row[2]
            vx, vy, vz = vx - cx, vy - cy, vz - cz
        w = rotate_back(rows, vx, vy, vz) + rotate_back(rows, wx, wy, wz)
        fx, fy, fz, mx, my, mz = self.matrix.dot([x * abs(x) for x in w]).tolist()   # −F_body
        return np.array(rotate(rows, -fx, -fy, -fz) + rotate(rows, -mx, -my, -mz))

    def mass_matrix(self, motion):
        return np.zeros((6, 6))

    C_TAG = "drag"   # its record in a compiled FMU (viscous_drag.c)

    def c_params(self):
        """viscous_drag.c's parameters: [relative (0, 1; 2: RELATIVE with waves), matrix (36, row-major)]."""
        return [float(self.relative) + float(self.waves)] + self.matrix.ravel().tolist()
