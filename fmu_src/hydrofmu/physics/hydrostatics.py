"""Linear hydrostatic restoring from a BEM result's stiffness matrix (an effect).

F = −C·δ, C (6×6) [N/m, N, N·m/rad] the BEM matrix about the reference point (= the BEM
rotation centre), δ the pose deviation from the scene's initial pose (the equilibrium,
where weight and buoyancy balance): δ = [x − x0, y − y0, z − z0, t_x, t_y, ψ − ψ0] with
the tilt (t_x, t_y) = (−n_y, n_x), n = R·R0ᵀ·e_z the body's vertical axis in global axes
(R the attitude's rotation).  For small rotations the tilt is the roll and pitch
deviation; unlike Euler-angle differences it does not depend on the yaw (Euler's roll and
pitch are taken in yawed axes: a body that turned freely would feel its restoring moment
about the wrong axis).  Global axes, the load on the body.

C is the complete restoring: buoyancy and the weight's moment (Capytaine with a centre of
mass, WAMIT's .hst).  The dynamics partner applies no gravity (it integrates about η0), so
the weight is counted once, here; the body's own ``stiffness`` then holds mooring terms only.
Linear: exact for small motions about η0 (no large-angle or wetted-surface change).
"""
import numpy as np

from .kinematics import rotation


class Hydrostatics:
    """Effect protocol (physics.state): ``load(motion, env)`` = −C·δ (module docstring)."""

    uses_current = False
    uses_acceleration = False

    def __init__(self, name, stiffness, position0, attitude0):
        self.name = name
        self.stiffness = np.asarray(stiffness, dtype=float).reshape(6, 6)
        self.position0 = np.asarray(position0, dtype=float)
        self.yaw0 = float(attitude0[2])
        self.vertical0 = rotation(attitude0)[2]        # R0ᵀ·e_z: the body's vertical in body axes
        self._delta = np.empty(6)

    def deviation(self, motion):
        """δ (6,) [m, rad] of the module docstring."""
        d = self._delta
        d[:3] = motion.position
        d[:3] -= self.position0
        n = motion.rot.dot(self.vertical0)
        d[3], d[4] = -n[1], n[0]
        d[5] = motion.attitude[2] - self.yaw0
        return d

    def load(self, motion, env):
        return -self.stiffness.dot(self.deviation(motion))

    C_TAG = "hydrostatics"   # its record in a compiled FMU (hydrostatics.c)

    def c_params(self):
        """hydrostatics.c's parameters: [C (36, row-major), position0 (3), yaw0, vertical0 (3)]."""
        return self.stiffness.ravel().tolist() + self.position0.tolist() + [self.yaw0] + self.vertical0.tolist()
