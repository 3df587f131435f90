"""All the load kernels of one body, summed: the physics behind a body's FMU.

Kernels are built from plain data (the scene's effect tables, decks already read), so
the FMU only carries JSON.  Acceleration loads follow the two modes of the README
(Conventions: Acceleration loads):

- ``export``: the effect's acceleration loads are not applied; their 6×6 mass
  contribution (about the reference point, global axes, evaluated at the initial pose)
  is published for the dynamics side to add to its mass matrix.
- ``explicit``: applied as loads, −M·a, with the added-mass stability limit of staggered
  coupling (diverges when A/M ≳ 1).

The velocity-dependent part of a point mass's inertia load (centripetal, −M_p·ω×(ω×r),
``velocity_load`` where a kernel has one) is not an acceleration load: it is applied in
both modes, since an exported constant M cannot carry it.
"""
import numpy as np

from .current_polar import CurrentPolar
from .hydrostatics import Hydrostatics
from .lumped import LumpedBody
from .viscous_drag import ViscousDrag


def _viscous_drag(name, d):
    return ViscousDrag(name, np.asarray(d["matrix"], dtype=float), bool(d["relative"]), bool(d.get("waves", False)))


def _current_polar(name, d):
    return CurrentPolar(name, *(np.asarray(d[k], dtype=float) for k in ("angles", "cx", "cy", "cmz")),
                        *d["point"], d["surface"], bool(d.get("waves", False)))


def _lumped(name, d):
    return LumpedBody(name, d["offset"], d["am"], d["ae"], d["icoo"], d["cd"], d["added_mass"])


def _hydrostatics(name, d):
    return Hydrostatics(name, d["stiffness"], d["position0"], d["attitude0"])


KERNELS = {
    "riflex_body": _lumped,
    "bem_hydrostatics": _hydrostatics,
    "aqwa_viscous_drag": _viscous_drag,
    "deeplines_current_polar": _current_polar,
}


def make_effect(etype, name, data):
    """Kernel object for a scene effect (see scene.EFFECT_TYPES)."""
    return KERNELS[etype](name, data)


class BodyLoads:
    """Sum of a body's effects.  ``explicit``: apply acceleration loads as forces."""

    def __init__(self, effects, explicit=False):
        self.effects = list(effects)
        self.explicit = explicit
        self.uses_current = any(e.uses_current for e in self.effects)
        self.uses_acceleration = any(e.uses_acceleration for e in self.effects)

    def effect_loads(self, motion, env, out=None):
        """(n_effects, 6) loads on the body, global axes, about the reference point (into
        ``out`` if given)."""
        out = np.empty((len(self.effects), 6)) if out is None else out
        for i, eff in enumerate(self.effects):
            load = eff.load(motion, env)
            if eff.uses_acceleration:
                if self.explicit:
                    load = load - eff.mass_matrix(motion) @ motion.acceleration
                velocity_load = getattr(eff, "velocity_load", None)
                if velocity_load is not None:
                    load = load + velocity_load(motion)
            out[i] = load
        return out

    def mass_matrix(self, motion):
        """Exported 6×6 mass contribution [kg, kg·m, kg·m²] of all acceleration loads."""
        total = np.zeros((6, 6))
        for eff in self.effects:
            if eff.uses_acceleration:
                total += eff.mass_matrix(motion)
        return total
