"""Scene files: which bodies exist, their mass properties, and which effects each one has.

A scene is a TOML file (read with the standard library).  Validation collects every
problem, each named by the file and the key path (``bodies.barge.effects[1].deck``),
and raises one InputError listing them all before anything is built.  Effect data
comes inline or from a vendor deck (path relative to the scene file + the name of the
body/structure in the deck).  The format, key by key: docs/scenes.md.

One module per table family: ``run`` ([run], presets), ``bodies``, ``effects`` (the effect
tables of a body), ``joints``, ``couplings``, ``waves`` ([waves] and the BEM wave effects'
checks), ``current`` (the current of [environment]); ``problems`` collects what is wrong;
``load`` reads a whole file.
"""
from .bodies import ACCEL_MODES, Body
from .effects import EFFECT_TYPES
from .joints import Joint
from .load import RUNTIMES, SECTIONS, Scene, load_scene, override
from .problems import Problems, identifier
from .run import ALGORITHMS, ECCO_DEFAULTS, MEMORY_DEFAULTS, PRESETS, RUN_DEFAULTS

__all__ = ["ACCEL_MODES", "ALGORITHMS", "Body", "ECCO_DEFAULTS", "EFFECT_TYPES", "Joint", "MEMORY_DEFAULTS",
           "PRESETS", "Problems", "RUNTIMES", "RUN_DEFAULTS", "SECTIONS", "Scene", "identifier", "load_scene",
           "override"]
