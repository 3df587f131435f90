"""hydrofmu: hydrodynamic loads on floating bodies as FMI 2.0 co-simulation FMUs.

Public API (imported on first use, so ``import hydrofmu`` stays cheap):

- ``load_scene(path) -> Scene``: read and validate a scene file;
- ``build(scene, out) -> Path``: build its FMUs into ``out/<scene name>/``;
- ``run(scene_or_folder, stop=..., step=...) -> Result``: build if needed and run;
  ``run_files(folder, engine)``: the files ``hydrofmu run`` writes beside a build;
- ``tune(scene, tolerance) -> Tuning``: the cheapest run settings within a tolerance;
- ``read_parquet(path)``: the Parquet file a streamed run wrote, columns read when asked;
- ``Result`` (``to_csv``, ``plot``, ``motion``, ``vector``) and ``read_csv``;
- ``run_batch(cases, out) -> DataFrame``: a matrix of load cases on Dask, one row per
  case, and ``read_series(out, case)`` (the ``batch`` extra);
- the physics: ``ViscousDrag`` (AQWA), ``CurrentPolar`` (DeepLines), ``LumpedBody``
  (RIFLEX BODY), ``BallJoint`` (RIFLEX CONB), ``Coupling`` (SIMO), ``Convolution`` and
  ``StateSpace`` (retardation memory), ``BodyLoads``, ``RigidBody``, ``CoupledBodies``,
  ``Motion``, ``Env``; ``InputError`` for bad input.

Layout: ``physics`` (pure numpy kernels), ``decks`` (vendor input readers), ``scene``
(scene files), ``fmi`` (FMU wrapping and building), ``cosim`` (masters).  The package uses
relative imports only, so a build can embed a renamed copy of it inside each FMU; this
file imports nothing at load time, so the copy's start-up inside an FMU pays nothing for it
(and names no module in an import statement: the names' types are in ``__init__.pyi``).
"""
from importlib import import_module

__version__ = "0.1.0"

# public name -> module (relative to the package) that defines it
_WHERE = {
    "load_scene": "api", "Scene": "scene", "InputError": "errors",
    "build": "api", "run": "api", "run_files": "api", "tune": "tuning", "Tuning": "tuning", "run_batch": "batch", "read_series": "batch",
    "Result": "cosim.result", "read_csv": "cosim.result", "read_parquet": "cosim.stream",
    "ViscousDrag": "physics.viscous_drag", "CurrentPolar": "physics.current_polar",
    "LumpedBody": "physics.lumped", "BallJoint": "physics.joint", "Coupling": "physics.coupling",
    "Convolution": "physics.memory", "StateSpace": "physics.memory", "BodyLoads": "physics.loads",
    "RigidBody": "physics.rigid_body", "CoupledBodies": "physics.rigid_body",
    "Motion": "physics.state", "Env": "physics.state",
}
__all__ = sorted(_WHERE) + ["__version__"]


def __getattr__(name):
    if name in _WHERE:
        value = getattr(import_module(f".{_WHERE[name]}", __name__), name)
        globals()[name] = value   # the next lookup is a plain attribute
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(_WHERE))

