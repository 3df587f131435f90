"""Current profile: speed and direction at levels of height z, as SIMO, RIFLEX and DeepLines
give it, and how the FMU inputs ``current.speed`` and ``current.direction`` drive it.

Levels z_k [m] (global z up, 0 at the mean free surface, all z_k ≤ 0), speeds U_k ≥ 0 [m/s],
directions β_k [deg, "going to", counter-clockwise from global +x].  Between two levels the
speed and the direction are linear in z (the direction along the shorter arc: 350° and 10°
turn through 0°, not through 180°; exactly 180° apart turns clockwise); above the top level
and below the deepest the values of that level hold.

The profile is stored as a shape about its surface value (z = 0), U_s = U(0), β_s = β(0):

    ratio(z) = U(z) / U_s,   turn(z) = β(z) − β_s

and the current at a point of height z, with the FMU inputs speed U_in and direction β_in
(start values U_s and β_s, so a master that leaves them alone gets the profile as given), is

    u(z) = U_in·ratio(z)·(cos(β_in + turn(z)), sin(β_in + turn(z)), 0)

i.e. ``current.speed`` scales every level's speed by U_in/U_s and ``current.direction``
turns every level by β_in − β_s.  A profile of one level has ratio ≡ 1 and turn ≡ 0: it is
exactly the uniform current of speed U_in and direction β_in.  A profile that is zero at the
surface but not below cannot be scaled this way and is refused; one that is zero everywhere
has ratio ≡ 1 (the inputs then set a uniform current).
"""
from bisect import bisect_right
from dataclasses import dataclass

import numpy as np


def profile_problem(z, speed, direction):
    """The first problem of a profile's levels as (index, field, message), or None.
    ``field`` is 'z', 'speed' or 'direction'; levels may come from the top down or the
    bottom up but must be strictly ordered."""
    z, speed, direction = (np.asarray(a, float) for a in (z, speed, direction))
    if len(z) == 0:
        return 0, "z", "a profile needs at least one level"
    for k in range(len(z)):
        for name, a in (("z", z), ("speed", speed), ("direction", direction)):
            if not np.isfinite(a[k]):
                return k, name, f"expected a finite number, found {a[k]}"
        if z[k] > 0.0:
            return k, "z", f"level z = {z[k]:g} m is above the mean free surface (z = 0, z up)"
        if speed[k] < 0.0:
            return k, "speed", f"speed must not be negative, found {speed[k]:g} (give the direction instead)"
    step = np.diff(z)
    if len(step) and not (np.all(step < 0.0) or np.all(step > 0.0)):
        k = 1 + int(np.argmax(step * np.sign(step[0]) <= 0.0))
        return k, "z", (f"levels must be strictly ordered by depth (all from the top down or all from the "
                        f"bottom up): z = {z[k]:g} follows z = {z[k - 1]:g}")
    top = int(np.argmax(z))
    if speed[top] == 0.0 and np.any(speed != 0.0):
        return top, "speed", ("the speed at the top level is 0 but not below: the profile cannot be scaled by "
                              "the input current.speed (give the surface a small speed)")
    return None


@dataclass(frozen=True)
class CurrentProfile:
    """A validated profile (see the module docstring).  ``z`` increasing; ``ratio`` and
    ``turn`` [deg] per level; ``surface_speed`` U_s [m/s], ``surface_direction`` β_s [deg]."""
    z: tuple
    ratio: tuple
    turn: tuple
    surface_speed: float
    surface_direction: float

    @classmethod
    def from_levels(cls, z, speed, direction):
        """From levels in either order; raises ValueError with ``profile_problem``'s message."""
        problem = profile_problem(z, speed, direction)
        if problem is not None:
            raise ValueError(f"level {problem[0] + 1}, {problem[1]}: {problem[2]}")
        order = np.argsort(np.asarray(z, float))
        z = np.asarray(z, float)[order]
        speed = np.asarray(speed, float)[order]
        beta = np.asarray(direction, float)[order]
        beta = beta[0] + np.concatenate([[0.0], np.cumsum((np.diff(beta) + 180.0) % 360.0 - 180.0)])  # shorter arc
        u_s, b_s = _interp(0.0, z, speed), _interp(0.0, z, beta)
        ratio = speed / u_s if u_s > 0.0 else np.ones_like(speed)
        return cls(tuple(z.tolist()), tuple(ratio.tolist()), tuple((beta - b_s).tolist()),
                   float(u_s), float(b_s % 360.0))

    @classmethod
    def from_rows(cls, rows):
        """From [[z, speed, direction], ...] rows."""
        z, speed, direction = zip(*rows)
        return cls.from_levels(z, speed, direction)

    def shape(self, z):
        """(ratio, turn [deg]) at height ``z`` [m]: linear between levels, constant outside."""
        return _interp(z, self.z, self.ratio), _interp(z, self.z, self.turn)


def _interp(x, xs, ys):
    """Linear in x between the points (xs increasing), the end values outside."""
    k = bisect_right(xs, x)
    if k == 0:
        return float(ys[0])
    if k == len(xs):
        return float(ys[-1])
    t = (x - xs[k - 1]) / (xs[k] - xs[k - 1])
    return float(ys[k - 1] + t * (ys[k] - ys[k - 1]))
