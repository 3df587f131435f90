"""Linear hydrostatic restoring from a BEM result's stiffness matrix (an effect).

F = −C·(η − η0), η = [x, y, z, φ, θ, ψ] the pose of the reference point (global position,
Euler angles as the dynamics partner integrates them), η0 the scene's initial pose (the
equilibrium, where weight and buoyancy balance), C (6×6) [N/m, N, N·m/rad] about the
reference point (= the BEM rotation centre).  Global axes, the load on the body.

C is the complete restoring: buoyancy and the weight's moment (Capytaine with a centre of
mass, WAMIT's .hst).  The dynamics partner applies no gravity (it integrates about η0), so
the weight is counted once, here; the body's own ``stiffness`` then holds mooring terms only.
Linear: exact for small motions about η0 (no large-angle or wetted-surface change).
"""
import numpy as np


class Hydrostatics:
    """Effect protocol (physics.state): ``load(motion, env)`` = −C·(η − η0)."""

    uses_current = False
    uses_acceleration = False

    def __init__(self, name, stiffness, position0, attitude0):
        self.name = name
        self.stiffness = np.asarray(stiffness, dtype=float).reshape(6, 6)
        self.pose0 = np.concatenate((np.asarray(position0, float), np.asarray(attitude0, float)))
        self._pose = np.empty(6)

    def load(self, motion, env):
        p = self._pose
        p[:3] = motion.position
        p[3:] = motion.attitude
        p -= self.pose0
        return -self.stiffness.dot(p)
