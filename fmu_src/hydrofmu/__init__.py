"""hydrofmu: hydrodynamic loads on floating bodies as FMI 2.0 co-simulation FMUs.

Layout: ``physics`` (pure numpy kernels), ``decks`` (vendor input readers),
``scene`` (scene files), ``fmi`` (FMU wrapping and building), ``cosim`` (masters).
The package uses relative imports only, so a build can embed a renamed copy of it
inside each FMU.
"""
__version__ = "0.1.0"
