"""Power bonds of a built scene and the energy residual of a run across them.

A load or connector FMU sends a force component to a dynamics FMU and gets the matching
velocity component back: one scalar power bond per component (6 per body side: forces with
linear velocities, moments with angular velocities, global axes, so F·v is a power in W),
as the build lists them in manifest.json's ``bonds`` (``fmi.osp.scalar_bonds``).

Energy residual (Sadjina & Pedersen 2020, the quantity libcosim's ECCO controls): over the
step [t_k, t_k+1] of length h_k, each side holds its input at the value of t_k, so the load
side's power is F(t_k+1)·v(t_k) and the dynamics side's v(t_k+1)·F(t_k); the coupling
creates or destroys

    δE_k = h_k · Σ_bonds [F(t_k+1)·v(t_k) − F(t_k)·v(t_k+1)]   [J]

where F is the force the load side sends and v the velocity the dynamics side sends, both as
recorded at the communication points.
"""
from dataclasses import dataclass

import numpy as np

from ..errors import InputError


@dataclass(frozen=True)
class Bond:
    """One scalar power bond: ``load.force`` → ``dynamics.dyn_force`` and
    ``dynamics.dyn_velocity`` → ``load.velocity``."""
    load: str
    force: str
    velocity: str
    dynamics: str
    dyn_velocity: str
    dyn_force: str


def power_bonds(manifest) -> list:
    """The scalar power bonds of a built scene (its manifest's ``bonds``)."""
    if "bonds" not in manifest:
        raise InputError(manifest.get("source", "manifest.json"), None, "bonds",
                         "this folder was built before hydrofmu listed power bonds: rebuild the scene")
    return [Bond(*b["load"], *b["dynamics"]) for b in manifest["bonds"]]


def columns(bonds) -> list:
    """The recorded columns the residual needs: each bond's force and velocity."""
    out = []
    for b in bonds:
        for col in (f"{b.load}.{b.force}", f"{b.dynamics}.{b.dyn_velocity}"):
            if col not in out:
                out.append(col)
    return out


@dataclass
class Residual:
    """Energy bookkeeping of a run across its power bonds (arrays per step k, [t_k, t_k+1]).

    ``step``: h_k [s]; ``power``: Σ_bonds F·v at t_k+1 [W]; ``residual``: δE_k [J];
    ``exchanged``: h_k·Σ_bonds |F·v| at t_k+1 [J], the energy the bonds carry.
    """
    step: np.ndarray
    power: np.ndarray
    residual: np.ndarray
    exchanged: np.ndarray

    @property
    def total(self) -> float:
        """Σ|δE_k| [J]: the energy the coupling got wrong over the run."""
        return float(np.sum(np.abs(self.residual)))

    @property
    def net(self) -> float:
        """Σ δE_k [J]: the energy the coupling created (> 0) or destroyed (< 0)."""
        return float(np.sum(self.residual))

    @property
    def relative(self) -> float:
        """Σ|δE_k| / Σ exchanged: the residual as a share of the energy the bonds carried."""
        carried = float(np.sum(self.exchanged))
        return self.total / carried if carried > 0 else 0.0


def residual(result, bonds=None) -> Residual:
    """The energy residual of a ``Result`` across ``bonds`` (default: the manifest's)."""
    bonds = power_bonds(result.manifest) if bonds is None else bonds
    f = np.column_stack([result[f"{b.load}.{b.force}"] for b in bonds])
    v = np.column_stack([result[f"{b.dynamics}.{b.dyn_velocity}"] for b in bonds])
    h = np.diff(result.time)
    dp = np.sum(f[1:] * v[:-1] - f[:-1] * v[1:], axis=1)
    fv = f[1:] * v[1:]
    return Residual(h, fv.sum(axis=1), h * dp, h * np.abs(fv).sum(axis=1))
