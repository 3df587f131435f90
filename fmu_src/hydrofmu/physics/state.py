"""Inputs every load kernel sees: the body's motion and the environment.

Load kernels ("effects") follow one protocol so the FMU wrapper can hold any mix:

    name: str                 # effect name, used for the `<name>.force` output
    uses_current: bool        # needs the current (Env.current_at its point's height)
    uses_acceleration: bool   # has acceleration loads (mass, added mass)
    load(motion, env) -> (6,) # [force N; moment N·m about the reference point], global
                              # axes, WITHOUT the acceleration loads (an effect in waves reads
                              # env.water, the incident waves at this step)
    mass_matrix(motion) -> (6, 6)
                              # mass contribution M about the reference point, global
                              # axes; the acceleration load is −M·motion.acceleration
                              # (applied only in `explicit` mode, else exported)
"""
from dataclasses import dataclass, field
import numpy as np

from .kinematics import current_components, current_velocity, rotation_rows


class _once:
    """``functools.cached_property`` without its lock (before Python 3.12 every access takes
    one: ~0.7 µs, more than computing the rotation): the first access stores the value in the
    instance, which later accesses read directly."""

    def __init__(self, compute):
        self.compute, self.name, self.__doc__ = compute, compute.__name__, compute.__doc__

    def __get__(self, obj, cls=None):
        if obj is None:
            return self
        value = obj.__dict__[self.name] = self.compute(obj)
        return value


@dataclass
class Motion:
    """Motion of a body's reference point.

    position [m] global; attitude (φ, θ, ψ) [rad]; velocity [m/s, rad/s] and
    acceleration [m/s², rad/s²] as 6-vectors in global axes.
    """
    position: np.ndarray = field(default_factory=lambda: np.zeros(3))
    attitude: np.ndarray = field(default_factory=lambda: np.zeros(3))
    velocity: np.ndarray = field(default_factory=lambda: np.zeros(6))
    acceleration: np.ndarray = field(default_factory=lambda: np.zeros(6))

    @_once
    def rot_rows(self):
        """The rows of R as tuples of floats (computed once: a Motion is a snapshot, every
        effect of an evaluation reads it; kernels on plain floats take these)."""
        return rotation_rows(self.attitude)

    @_once
    def rot(self):
        """Body-to-global rotation matrix R = Rz(ψ)·Ry(θ)·Rx(φ)."""
        return np.array(self.rot_rows)


@dataclass
class Env:
    """Water density ρ [kg/m³], gravity g [m/s²], current: speed [m/s] and 'going to'
    direction [deg, counter-clockwise from global +x] at the surface, and ``profile`` (a
    physics.current.CurrentProfile, or None: uniform over depth) giving its shape with depth."""
    rho: float = 1025.0
    g: float = 9.81
    current_speed: float = 0.0
    current_direction: float = 0.0
    profile: object = None
    water: object = None   # physics.wave_kinematics.Water: the incident waves at this step (None: still water)

    @property
    def current(self):
        """Global current velocity vector [m/s] at the surface (everywhere if uniform)."""
        return current_velocity(self.current_speed, self.current_direction)

    def current_at(self, z):
        """Global current velocity [m/s] at height ``z`` [m] (global, z up, 0 at the mean free
        surface): U·ratio(z) going to β + turn(z) (physics/current.py)."""
        return np.array(self.current_xyz(z))

    def current_xyz(self, z):
        """``current_at(z)`` as a tuple of three floats (kernels on plain floats take this)."""
        if self.profile is None:
            return current_components(self.current_speed, self.current_direction)
        ratio, turn = self.profile.shape(z)
        return current_components(self.current_speed * ratio, self.current_direction + turn)
