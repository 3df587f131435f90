"""Scene files: which bodies exist, their mass properties, and which effects each one has.

A scene is a TOML file (read with the standard library).  Validation collects every
problem, each named by the file and the key path (``bodies.barge.effects[1].deck``),
and raises one InputError listing them all before anything is built.  Effect data
comes inline or from a vendor deck (path relative to the scene file + the name of the
body/structure in the deck).  The format, key by key: docs/scenes.md.
"""
import math
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from . import admissible, keys
from .description import Effect, HydroCoupling, Kernel
from .errors import InputError, InputWarning
from .names import did_you_mean
from .textfile import read_toml

ACCEL_MODES = ("export", "explicit")


@dataclass
class Body:
    """A floating body.  ``position``/``attitude``: initial pose of the reference point
    (global, m / rad), which is also the equilibrium the stiffness acts about;
    ``velocity``: initial velocity (6, global, m/s and rad/s).  Mass properties are what the dynamics side needs: mass [kg],
    inertia [kg·m²] about the CoG in body axes, cog [m] in body axes from the reference
    point, stiffness K and linear damping D (6×6, about the reference point, global)."""
    name: str
    position: list
    attitude: list
    velocity: list
    mass: float
    inertia: list
    cog: list
    stiffness: list
    damping: list
    accel_mode: str = "export"
    effects: list = field(default_factory=list)


@dataclass
class Scene:
    name: str
    path: Path
    rho: float
    g: float
    current_speed: float
    current_direction: float
    bodies: dict
    run: dict
    joints: dict = field(default_factory=dict)
    couplings: list = field(default_factory=list)
    current_profile: list = None     # [[z m, speed m/s, direction deg], ...] or None (uniform)
    warnings: list = field(default_factory=list)   # suspicious but legal input, said at load (InputWarning)
    decks: list = field(default_factory=list)   # decks.lines.Reading of each deck read: used, skipped, warnings
    runtime: str = "python"          # [build] runtime: "python" (pythonfmu) or "c" (compiled)
    waves: object = None             # physics.waves.SeaState of [waves], or None (no waves)


class Problems:
    """Collects validation problems so that one error lists them all."""

    def __init__(self, path):
        self.path, self.items = Path(path), []
        self.unknown = {}  # key path of an unknown key -> the keys allowed there (batch knobs are checked by it)
        self.decks = {}   # (deck path, reader, args) -> entries or the InputError: each deck read once
        self.readings = []   # what each deck read gave: groups used and skipped, warnings (decks.lines.Reading)

    def read(self, found):
        """Keep the ``reading`` of a deck reader's result (once); returns the result."""
        reading = getattr(found, "reading", None)
        if reading is not None and all(r is not reading for r in self.readings):
            self.readings.append(reading)
        return found

    def add(self, key, message):
        self.items.append((key, message))

    def add_all(self, where, problems):
        """Record the (field, message) problems of an admissibility check as ``where.field``."""
        for name, message in problems:
            self.add(f"{where}.{name}", message)

    def warn(self, key, message):
        warnings.warn(InputWarning(self.path, None, key, message))

    def raise_if_any(self):
        if self.items:
            (first, message), rest = self.items[0], self.items[1:]
            exc = InputError(self.path, None, first, "; ".join([message] + [f"{k}: {m}" for k, m in rest]))
            exc.unknown = dict(self.unknown)   # for callers that check key paths (batch knobs)
            raise exc

    def deck(self, path, where, reader, *args):
        """``reader(path, *args)``, read once per scene; a deck error is recorded once
        (under the key path ``where`` of its first use) and None returned."""
        key = (str(path), reader, args)
        if key not in self.decks:
            try:
                self.decks[key] = self.read(reader(path, *args))
            except InputError as exc:
                self.decks[key] = exc
                if not any(isinstance(v, InputError) and str(v) == str(exc) for k, v in self.decks.items()
                           if k != key):
                    self.add(where, str(exc))
        found = self.decks[key]
        return None if isinstance(found, InputError) else found

    # typed getters: return a value or None after recording the problem
    def table(self, parent, key, where, required=True):
        value = parent.get(key)
        if value is None:
            if required:
                self.add(where, "missing table")
            return {} if not required else None
        if not isinstance(value, dict):
            self.add(where, "expected a table")
            return None
        return value

    def number(self, parent, key, where, default=None, positive=False, nonneg=False):
        value = parent.get(key, default)
        if value is None:
            self.add(where, "missing value")
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not _finite(value):
            self.add(where, f"expected a finite number, found {_short(value)}")
            return None
        if positive and value <= 0:
            self.add(where, f"must be positive, found {value}")
            return None
        if nonneg and value < 0:
            self.add(where, f"must not be negative, found {value}")
            return None
        return float(value)

    def vector(self, parent, key, where, n, default=None):
        value = parent.get(key, default)
        if value is None:
            self.add(where, f"missing {n}-vector")
            return None
        arr = self.array(value, where)
        if arr is None:
            return None
        if arr.shape != (n,):
            self.add(where, f"expected {n} numbers, found shape {list(arr.shape)}")
            return None
        return arr.tolist()

    def matrix(self, parent, key, where, n, default=None, diagonal_ok=True):
        """n×n matrix; a list of n numbers means a diagonal matrix."""
        value = parent.get(key, default)
        if value is None:
            self.add(where, f"missing {n}x{n} matrix")
            return None
        arr = self.array(value, where)
        if arr is None:
            return None
        if diagonal_ok and arr.shape == (n,):
            arr = np.diag(arr)
        if arr.shape != (n, n):
            self.add(where, f"expected a {n}x{n} matrix{' or ' + str(n) + ' diagonal values' if diagonal_ok else ''}, "
                            f"found shape {list(arr.shape)}")
            return None
        return arr.tolist()

    def choice(self, parent, key, where, options, default=None):
        value = parent.get(key, default)
        if value not in options:
            self.add(where, f"expected one of {', '.join(map(repr, options))}, found {value!r}")
            return None
        return value

    def string(self, parent, key, where, default=None):
        value = parent.get(key, default)
        if not isinstance(value, str) or not value:
            self.add(where, f"expected a non-empty string, found {value!r}")
            return None
        return value

    def known_keys(self, table, where, allowed):
        for key in table:
            if key not in allowed:
                path = f"{where}.{key}" if where else key
                self.unknown[path] = sorted(allowed)
                self.add(path, f"unknown key{did_you_mean(key, allowed)} (allowed: {', '.join(sorted(allowed))})")

    def array(self, value, where):
        try:
            arr = np.array(value, dtype=float)
        except OverflowError:
            self.add(where, "contains a number too large for a float")
            return None
        except (TypeError, ValueError):
            self.add(where, "expected numbers (ragged or non-numeric array)")
            return None
        if not np.all(np.isfinite(arr)):
            self.add(where, "contains a non-finite number")
            return None
        return arr


def _finite(value):
    try:
        return bool(np.isfinite(float(value)))
    except OverflowError:   # a TOML integer of 400 digits
        return False


def _short(value):
    text = repr(value)
    return text if len(text) <= 40 else text[:20] + "…" + text[-8:]


def identifier(name):
    """True for names usable in FMU variable names and model identifiers."""
    return bool(name) and name.replace("_", "a").isalnum() and name[0].isalpha() and name.isascii()


# --- effect types: each validator turns the scene table into kernel data ------------

def _deck_path(problems, table, where, key="deck"):
    deck = problems.string(table, key, f"{where}.{key}")
    if deck is None:
        return None
    path = (problems.path.parent / deck).resolve()
    if not path.is_file():
        problems.add(f"{where}.{key}", f"deck file not found: {path}")
        return None
    return path


def _units(problems, table, where):
    """The ``units`` of a SIMO/RIFLEX deck reference (decks/units.py), default SI."""
    from .decks.units import SYSTEMS
    return problems.choice(table, "units", f"{where}.units", tuple(SYSTEMS), "SI")


def _from_deck(problems, table, where, reader, name_key, units=False):
    """Read a deck and pick the named entry; deck errors are recorded, not raised.
    ``units``: the reader takes the file's unit system (scene key ``units``)."""
    path = _deck_path(problems, table, where)
    name = problems.string(table, name_key, f"{where}.{name_key}")
    system = _units(problems, table, where) if units else None
    if path is None or name is None or (units and system is None):
        return None, None
    entries = problems.deck(path, f"{where}.deck", reader, *((system,) if units else ()))
    if entries is None:
        return None, None
    if name not in entries:
        problems.add(f"{where}.{name_key}", f"{name!r} is not in {path.name} (it has: {', '.join(entries) or 'none'})")
        return None, None
    return entries[name], path


def _aqwa_viscous_drag(problems, table, where):
    from .decks.aqwa import read_viscous_drag
    if "deck" in table:
        problems.known_keys(table, where, keys.effect_keys("aqwa_viscous_drag", True))
        data, _ = _from_deck(problems, table, where, read_viscous_drag, "body")
        if data is None:
            return None
        return {"matrix": np.asarray(data.matrix).tolist(), "relative": data.option == "RELATIVE"}
    problems.known_keys(table, where, keys.effect_keys("aqwa_viscous_drag", False))
    matrix = problems.matrix(table, "matrix", f"{where}.matrix", 6)
    option = problems.choice(table, "option", f"{where}.option", ("ABSOLUTE", "RELATIVE"), "ABSOLUTE")
    if matrix is None or option is None:
        return None
    for k, message in admissible.negative_diagonal(matrix):
        problems.warn(f"{where}.matrix[{k + 1},{k + 1}]", message)
    return {"matrix": matrix, "relative": option == "RELATIVE"}


def _deeplines_current_polar(problems, table, where):
    from .decks.deeplines import CurrentPolarData, read_current_polars
    from .physics.current_polar import expand_polar
    symmetry = problems.choice(table, "symmetry", f"{where}.symmetry", ("none", "xz", "yz", "xz+yz"), "none")
    if "deck" in table:
        problems.known_keys(table, where, keys.effect_keys("deeplines_current_polar", True))
        data, _ = _from_deck(problems, table, where, read_current_polars, "structure")
    else:
        problems.known_keys(table, where, keys.effect_keys("deeplines_current_polar", False))
        point = problems.vector(table, "point", f"{where}.point", 3)
        surface = problems.number(table, "surface", f"{where}.surface", positive=True)
        raw = table.get("table")
        arr = problems.array(raw, f"{where}.table") if raw is not None else None
        if raw is None:
            problems.add(f"{where}.table", "missing table of [angle, CX, CY, CMZ] rows")
        elif arr is not None and (arr.ndim != 2 or arr.shape[1] != 4 or arr.shape[0] < 2):
            problems.add(f"{where}.table", f"expected rows of 4 numbers [angle, CX, CY, CMZ], found shape {list(arr.shape)}")
            arr = None
        if point is None or surface is None or arr is None:
            return None
        data = CurrentPolarData(name=table.get("name", "polar"), xc=point[0], yc=point[1], zc=point[2],
                                surfc=surface, angles=arr[:, 0], cx=arr[:, 1], cy=arr[:, 2], cmz=arr[:, 3],
                                path=str(problems.path), line=None)
    if data is None or symmetry is None:
        return None
    try:
        angles, cx, cy, cmz = expand_polar(data, symmetry)
    except InputError as exc:
        if "deck" in table:
            problems.add(f"{where}.symmetry", str(exc))   # names the deck's file and line
        else:   # an inline table: the key at fault, the column in the message
            key = "symmetry" if "symmetry" in exc.message else "table"
            problems.add(f"{where}.{key}", f"{exc.field}: {exc.message}")
        return None
    return {"angles": angles.tolist(), "cx": cx.tolist(), "cy": cy.tolist(), "cmz": cmz.tolist(),
            "point": [data.xc, data.yc, data.zc], "surface": data.surfc}


LUMPED_KEYS = keys.names(keys.LUMPED)


def _lumped_data(problems, table, where, kind):
    """RIFLEX lumped properties (AM, AE, ICOO, CD, added mass) from a deck component or
    inline; ``kind`` is 'BODY' or 'CONB'.  Returns (data dict, conb codes or None)."""
    from .decks.riflex import BodyData, ConbData, read_components
    if "deck" in table:
        comp, path = _from_deck(problems, table, where, read_components, "component", units=True)
        if comp is None:
            return None, None
        want = BodyData if kind == "BODY" else ConbData
        if not isinstance(comp, want):
            problems.add(f"{where}.component", f"{table['component']!r} in {path.name} is not a "
                                               f"NEW COMPonent {kind} data group")
            return None, None
        data = {"am": comp.am, "ae": comp.ae, "icoo": comp.icoo, "cd": list(comp.cd),
                "added_mass": list(comp.added_mass)}
        return data, (list(comp.codes) if kind == "CONB" else None)
    data = {
        "am": problems.number(table, "am", f"{where}.am", 0.0, nonneg=True),
        "ae": problems.number(table, "ae", f"{where}.ae", 0.0, nonneg=True),
        "icoo": problems.choice(table, "icoo", f"{where}.icoo", ("GLOBAL", "LOCAL"), "GLOBAL"),
        "cd": problems.vector(table, "cd", f"{where}.cd", 3, [0.0] * 3),
        "added_mass": problems.vector(table, "added_mass", f"{where}.added_mass", 3, [0.0] * 3),
    }
    codes = None
    if kind == "CONB":
        codes = problems.vector(table, "codes", f"{where}.codes", 3, [0, 0, 0])
        if codes is not None and any(c not in (0, 1) for c in codes):
            problems.add(f"{where}.codes", f"freedom codes IRX IRY IRZ must be 0 (free) or 1 (fixed), found {codes}")
            codes = None
    if any(v is None for v in data.values()) or (kind == "CONB" and codes is None):
        return None, None
    return data, ([int(c) for c in codes] if codes is not None else None)


def _riflex_body(problems, table, where):
    problems.known_keys(table, where, keys.effect_keys("riflex_body", "deck" in table))
    offset = problems.vector(table, "offset", f"{where}.offset", 3)
    data, _ = _lumped_data(problems, table, where, "BODY")
    if data is None or offset is None:
        return None
    return {**data, "offset": offset}


def _bem_entry(problems, table, where, reader):
    """(data read by ``reader``, file, BEM body name) of a BEM wave effect entry (keys bem,
    body, ulen), or (None, None, None) after recording the problem."""
    path = _deck_path(problems, table, where, "bem")
    ulen = problems.number(table, "ulen", f"{where}.ulen", positive=True) if "ulen" in table else None
    body = problems.string(table, "body", f"{where}.body") if "body" in table else None
    if path is None or ("ulen" in table and ulen is None) or ("body" in table and body is None):
        return None, None, None
    env = getattr(problems, "env", {})
    data = problems.deck(path, f"{where}.bem", reader, ulen, env.get("rho", 1025.0), env.get("g", 9.81))
    if data is None:
        return None, None, None
    if body is None:
        if len(data.bodies) != 1:
            problems.add(f"{where}.body", f"{path.name} holds {len(data.bodies)} bodies ({', '.join(data.bodies)}): "
                                          "name one")
            return None, None, None
        body = data.bodies[0]
    if body not in data.bodies:
        problems.add(f"{where}.body", f"{body!r} is not a body of {path.name} (it has: {', '.join(data.bodies)})")
        return None, None, None
    return data, path, body


def _wave_excitation(problems, table, where):
    """First-order wave excitation from a BEM result (Capytaine .nc, WAMIT .3 / .2): the
    transfer functions of one BEM body; the sea state is the scene's [waves]."""
    from .decks.bem_waves import read_excitation
    problems.known_keys(table, where, keys.effect_keys("wave_excitation", False))
    data, path, body = _bem_entry(problems, table, where, read_excitation)
    if data is None:
        return None
    x = data.body(body)
    return {"bem": str(path), "body": body, "kind": data.kind, "omega": data.omega.tolist(),
            "directions": data.directions.tolist(), "re": x.real.tolist(), "im": x.imag.tolist(),
            "rotation_center": data.rotation_centers.get(body), "rho": data.rho, "g": data.g,
            "water_depth": data.water_depth}


def _bem_hydrostatics(problems, table, where):
    """Hydrostatic restoring −C·(η − η0) from a BEM result (Capytaine .nc, WAMIT .hst)."""
    from .decks.bem_waves import read_hydrostatics
    problems.known_keys(table, where, keys.effect_keys("bem_hydrostatics", False))
    data, path, body = _bem_entry(problems, table, where, read_hydrostatics)
    if data is None:
        return None
    return {"bem": str(path), "body": body, "kind": data.kind, "stiffness": data.stiffness[body].tolist(),
            "weight": data.weight, "mass": data.mass.get(body), "center_of_mass": data.center_of_mass.get(body),
            "rotation_center": data.rotation_centers.get(body), "rho": data.rho, "g": data.g}


# type -> (validator, default effect name)
EFFECT_TYPES = {
    "wave_excitation": (_wave_excitation, "waves"),
    "bem_hydrostatics": (_bem_hydrostatics, "hydrostatics"),
    "aqwa_viscous_drag": (_aqwa_viscous_drag, "viscous_drag"),
    "deeplines_current_polar": (_deeplines_current_polar, "current_polar"),
    "riflex_body": (_riflex_body, "riflex_body"),
}

RUN_DEFAULTS = {"step": 0.1, "stop": 100.0, "algorithm": "gauss-seidel", "substep": 0.01, "load_hold": "constant"}
ALGORITHMS = ("jacobi", "gauss-seidel", "ecco")
# libcosim's ECCO (energy-conservation-based co-simulation, Sadjina & Pedersen 2020): the
# step adapts to the power-bond energy residual; `step` is its first step.  Names as in
# OspSystemStructure.xml's <EccoConfiguration>, snake case; tolerances on the residual
# energy per step: abs [J], rel (to the energy the bonds carry in that step).
ECCO_DEFAULTS = {"rel_tolerance": 1e-3, "abs_tolerance": 1.0, "min_step": 0.005, "max_step": 0.2,
                 "safety_factor": 0.8, "min_change_rate": 0.2, "max_change_rate": 1.5,
                 "p_gain": 0.2, "i_gain": 0.15}
MEMORY_DEFAULTS = {"method": "convolution", "tolerance": 0.002, "memory_length": None}   # tolerance: see docs/bem.md (coarse grids)

# Speed/accuracy presets a scene names with [run] preset = "…": each sets the run knobs
# and the default memory evaluator of every coupling; knobs the scene sets still win.
# The figures behind each choice are in the README (measured by `hydrofmu bench`).
PRESETS = {
    "screening": {"step": 0.2, "algorithm": "gauss-seidel", "substep": 0.05, "load_hold": "linear",
                  "memory": {"method": "state_space", "tolerance": 0.05, "memory_length": None}},
    "design": {"step": 0.05, "algorithm": "gauss-seidel", "substep": 0.05, "load_hold": "linear",
               "memory": {"method": "state_space", "tolerance": 0.01, "memory_length": None}},
    "reference": {"step": 0.01, "algorithm": "gauss-seidel", "substep": 0.005, "load_hold": "linear",
                  "memory": {"method": "convolution", "tolerance": 0.01, "memory_length": None}},
    "adaptive": {"step": 0.01, "algorithm": "ecco", "substep": 0.01, "load_hold": "linear",
                 "memory": {"method": "state_space", "tolerance": 0.01, "memory_length": None},
                 "ecco": dict(ECCO_DEFAULTS)},
}


# what a run writes (not run knobs: no preset sets them): `outputs`, names of what to record
# (body names, body.position …, instance.variable; default every output), `interval`, the
# output interval [s] (a whole number of steps; default every step)
OUTPUT_KEYS = ("outputs", "interval")


def _outputs(p, run):
    value = run.get("outputs")
    if value is not None and (not isinstance(value, list) or not value
                              or not all(isinstance(v, str) and v for v in value)):
        p.add("run.outputs", f"expected a non-empty array of output names (e.g. [\"barge\", \"barge.force[1]\"]), "
                             f"found {value!r}")
        return None
    return value


def _ecco(p, run, base, step):
    """The ECCO settings of ``[run.ecco]`` over the preset's (or the defaults), checked."""
    table = p.table(run, "ecco", "run.ecco", required=False) or {}
    p.known_keys(table, "run.ecco", keys.names(keys.ECCO))
    out = {k: p.number(table, k, f"run.ecco.{k}", v, positive=True)
           for k, v in base.get("ecco", ECCO_DEFAULTS).items()}
    if None in out.values():
        return out
    lo, hi = out["min_step"], out["max_step"]
    if lo > hi:
        p.add("run.ecco.min_step", f"must not exceed max_step ({hi:g} s), found {lo:g}")
    elif step is not None and not lo <= step <= hi:
        p.add("run.step", f"ECCO's first step must lie within [min_step, max_step] = [{lo:g}, {hi:g}] s, "
                          f"found {step:g}")
    if out["safety_factor"] > 1:
        p.add("run.ecco.safety_factor", f"must be in (0, 1], found {out['safety_factor']:g}")
    if out["min_change_rate"] > 1:
        p.add("run.ecco.min_change_rate", f"must be in (0, 1], found {out['min_change_rate']:g}")
    if out["max_change_rate"] < 1:
        p.add("run.ecco.max_change_rate", f"must be at least 1, found {out['max_change_rate']:g}")
    return out


COUPLING_KEYS = keys.names(keys.COUPLING)


def _memory_knobs(problems, table, where, memory):
    """(method, tolerance, order, memory_length, knobs the table sets) of a coupling entry."""
    method = problems.choice(table, "method", f"{where}.method", ("convolution", "state_space"), memory["method"])
    tol = problems.number(table, "tolerance", f"{where}.tolerance", memory["tolerance"], positive=True)
    order = table.get("order")
    if order is not None and (not isinstance(order, int) or isinstance(order, bool) or order < 1):
        problems.add(f"{where}.order", f"expected a positive integer, found {order!r}")
    length = (problems.number(table, "memory_length", f"{where}.memory_length", positive=True)
              if "memory_length" in table else memory["memory_length"])
    return method, tol, order, length, sorted(k for k in ("method", "tolerance", "order", "memory_length")
                                              if k in table)


def _couplings(problems, items, bodies, memory=MEMORY_DEFAULTS, env=None):
    from .decks.simo import read_couplings
    if not isinstance(items, list):
        problems.add("couplings", "expected an array of tables ([[couplings]])")
        return []
    out, names = [], set()
    for i, table in enumerate(items):
        where = f"couplings[{i}]"
        if not isinstance(table, dict):
            problems.add(where, "expected a table")
            continue
        if "bem" in table:
            for c in _bem_couplings(problems, table, where, bodies, memory, env or {}):
                if c.name in names:
                    problems.add(f"{where}.name", f"coupling names must be distinct, {c.name!r} is used twice")
                names.add(c.name)
                out.append(c)
            continue
        problems.known_keys(table, where, COUPLING_KEYS)
        mapping = table.get("bodies", {})
        if not isinstance(mapping, dict) or any(v not in bodies for v in mapping.values()):
            problems.add(f"{where}.bodies", "expected a table SIMO body name = scene body name, "
                                            f"scene bodies: {', '.join(bodies)}")
            continue
        twice = [v for v in set(mapping.values()) if list(mapping.values()).count(v) > 1]
        if twice:
            problems.add(f"{where}.bodies", f"SIMO bodies {', '.join(k for k, v in mapping.items() if v == twice[0])} "
                                            f"are all mapped to scene body {twice[0]!r}: one deck body per scene body")
            continue
        known = set(mapping) | set(bodies)
        path = _deck_path(problems, table, where)
        name = problems.string(table, "coupling", f"{where}.coupling")
        knobs = _memory_knobs(problems, table, where, memory)
        units = _units(problems, table, where)
        if path is None or name is None or knobs[0] is None or units is None:
            continue
        decks = problems.deck(path, f"{where}.deck", read_couplings, frozenset(known), units)
        if decks is None:
            continue
        if name not in decks:
            problems.add(f"{where}.coupling", f"{name!r} is not in {path.name} (it has: {', '.join(decks) or 'none'})")
            continue
        in_deck = {b for c in decks.values() for b in (c.body_a, c.body_b)}
        stray = [k for k in mapping if k not in in_deck]
        if stray:   # a misspelt key maps nothing: the body it meant keeps its deck name
            problems.add(f"{where}.bodies.{stray[0]}", f"no coupling of {path.name} names a body {stray[0]!r}"
                                                      f"{did_you_mean(stray[0], sorted(in_deck))} (its bodies: "
                                                      f"{', '.join(sorted(in_deck))})")
            continue
        d = decks[name]
        a, b = mapping.get(d.body_a, d.body_a), mapping.get(d.body_b, d.body_b)
        for side, body in (("A", a), ("B", b)):
            if body not in bodies:
                problems.add(f"{where}.bodies", f"CHBDY_{side} {body!r} of {name} is not a scene body: map it, "
                                                f"e.g. bodies = {{ {body} = \"{next(iter(bodies), 'name')}\" }}")
        if not identifier(name) or name in names:
            problems.add(f"{where}.coupling", f"coupling names must be distinct identifiers, found {name!r}")
        names.add(name)
        out.append(_coupling(name, a, b, d, knobs))
    return out


def _coupling(name, a, b, d, knobs, bem=None):
    """A scene coupling from the arrays of a ``decks.simo.CouplingData`` (or alike) and the
    memory knobs of its entry (``_memory_knobs``)."""
    method, tol, order, length, set_ = knobs
    return HydroCoupling(name, a, b, np.asarray(d.added_mass, float), d.timdel,
                         [Kernel(i, j, np.asarray(h, float)) for (i, j), h in d.kernels.items()],
                         method, tol, order, length, set_, bem=bem)


BEM_KEYS = keys.names(keys.BEM_COUPLING)
CENTRE_TOL = 0.01   # m: BEM rotation centres vs scene reference points


def _bem_couplings(problems, table, where, bodies, memory, env):
    """A `bem = "…"` entry: every self and cross coupling of the mapped BEM bodies."""
    from . import bem
    from .decks.bem import read_bem
    from .physics.radiation import SYMMETRY_TOL
    problems.known_keys(table, where, BEM_KEYS)
    file = problems.string(table, "bem", f"{where}.bem")
    mapping = problems.table(table, "bodies", f"{where}.bodies")
    if mapping is not None and (not mapping or any(v not in bodies for v in mapping.values())
                                or len(set(mapping.values())) != len(mapping)):
        problems.add(f"{where}.bodies", "expected a table BEM body = scene body (distinct), "
                                        f"scene bodies: {', '.join(bodies)}")
        mapping = None
    prefix = problems.string(table, "name", f"{where}.name", "bem")
    dofs = table.get("dofs")
    if dofs is not None and (not isinstance(dofs, list) or not dofs or not all(isinstance(d, str) for d in dofs)):
        problems.add(f"{where}.dofs", f"expected a list of dof names (\"Surge\", …, \"Yaw\"), found {dofs!r}")
        dofs = None
    opt = {k: problems.number(table, k, f"{where}.{k}", positive=True) if k in table else None
           for k in ("ulen", "timdel", "kernel_length", "symmetry_tolerance")}
    a_inf_from = problems.choice(table, "a_inf", f"{where}.a_inf", ("ogilvie", "file"), "ogilvie")
    knobs = _memory_knobs(problems, table, where, memory)
    centres = problems.table(table, "rotation_centers", f"{where}.rotation_centers", required=False) or {}
    centres = {b: problems.vector(centres, b, f"{where}.rotation_centers.{b}", 3) for b in centres}
    if file is None or mapping is None or knobs[0] is None or prefix is None or not identifier(prefix) \
            or a_inf_from is None or None in centres.values():
        if prefix is not None and not identifier(prefix):
            problems.add(f"{where}.name", f"expected an identifier, found {prefix!r}")
        return []
    path = (problems.path.parent / file).resolve()
    if not path.is_file():
        problems.add(f"{where}.bem", f"BEM file not found: {path}")
        return []
    rho = env.get("rho") or 1025.0
    try:
        data = read_bem(path, ulen=opt["ulen"], rho=rho)
        for name, scene_value in (("rho", rho), ("g", env.get("g") or 9.81)):
            value = getattr(data, name)
            if value is not None and abs(value - scene_value) > 1e-6 * scene_value:
                raise InputError(path, None, name, f"{name} = {value:g} in the BEM result but {scene_value:g} in the "
                                                   f"scene (environment.{name}): solve again with {name} = "
                                                   f"{scene_value:g}, or set environment.{name} = {value:g}")
        for b, xyz in centres.items():     # declared (WAMIT's XBODY); a file's own value must agree
            if b not in data.bodies:
                raise InputError(path, None, "rotation_centers", f"{b!r} is not a body of the result "
                                                                 f"(it has: {', '.join(data.bodies)})")
            if b in data.rotation_centers and np.max(np.abs(np.subtract(data.rotation_centers[b], xyz))) > CENTRE_TOL:
                raise InputError(path, None, f"rotation_center[{b}]", f"{data.rotation_centers[b]} m in the file "
                                                                      f"but {xyz} m declared in the scene")
            data.rotation_centers[b] = list(xyz)
        _check_centres(data, mapping, bodies)
        result = bem.couplings(data, mapping, dofs, opt["timdel"], opt["kernel_length"],
                               opt["symmetry_tolerance"] or SYMMETRY_TOL, prefix, a_inf_from)
    except InputError as exc:
        problems.add(f"{where}.bem", str(exc))
        return []
    left = [b for b in data.bodies if b not in mapping]
    if left:
        problems.warn(f"{where}.bodies", f"{path} has bodies {', '.join(left)} not mapped to scene bodies: their "
                                         "couplings with the mapped ones are left out")
    for text in result.warnings:
        problems.warn(f"{where}.bem", text)
    return [_coupling(c.name, c.body_a, c.body_b, c, knobs, bem=result) for c in result.couplings]


def _check_centres(data, mapping, bodies):
    """BEM rotation centres = the scene bodies' reference points, up to one horizontal shift
    (radiation coefficients do not change when the whole group moves horizontally)."""
    known = [b for b in data.bodies if b in mapping and b in data.rotation_centers]
    if not known:
        return
    ref = known[0]
    shift = np.array(bodies[mapping[ref]].position) - np.array(data.rotation_centers[ref])
    shift[2] = 0.0
    for b in known:
        want = np.array(bodies[mapping[b]].position)
        got = np.array(data.rotation_centers[b]) + shift
        if np.max(np.abs(got - want)) > CENTRE_TOL:
            raise InputError(data.path, None, f"rotation_center[{b}]",
                             f"{data.rotation_centers[b]} m does not match the reference point of scene body "
                             f"{mapping[b]!r} at {list(want)} m (z must agree, x and y up to one common shift "
                             f"{shift[:2].tolist()} m); the coefficients must be about the reference point")


JOINT_KEYS = keys.names(keys.JOINT)


@dataclass
class Joint:
    """A CONB ball joint between body ``a`` and body ``b`` (None: the earth).
    ``a_point``: joint point in A's body axes; ``b_point``: in B's body axes, or global
    for the earth (default: where A's point is at t = 0).  ``codes``: IRX IRY IRZ about
    A's axes (1 fixed, 0 free).  Spring/damper values None mean the build's defaults."""
    name: str
    a: str
    b: object
    a_point: list
    b_point: object
    codes: list
    node: dict
    stiffness: object = None
    damping: object = None
    rot_stiffness: object = None
    rot_damping: object = None
    accel_mode: str = "export"


def _joint(problems, name, table, where, bodies):
    problems.known_keys(table, where, keys.joint_keys("deck" in table))
    if not identifier(name) or name in bodies or name.endswith("_dynamics"):
        problems.add(where, "joint name must be an identifier that is not a body's name")
    problems.choice(table, "type", f"{where}.type", ("riflex_conb",), "riflex_conb")
    a = problems.string(table, "a", f"{where}.a")
    b = table.get("b", "earth")
    for side, value in (("a", a), ("b", b)):
        if value is not None and value != "earth" and value not in bodies:
            problems.add(f"{where}.{side}", f"{value!r} is not a body of this scene"
                                            + (" (side a cannot be the earth)" if value == "earth" else ""))
    if a == "earth":
        problems.add(f"{where}.a", "side a must be a body (name the earth as side b)")
    if a is not None and a == b:
        problems.add(f"{where}.b", "a joint needs two different sides")
    a_point = problems.vector(table, "a_point", f"{where}.a_point", 3)
    b_point = problems.vector(table, "b_point", f"{where}.b_point", 3) if "b_point" in table else None
    node, codes = _lumped_data(problems, table, where, "CONB")
    optional = {k: (problems.number(table, k, f"{where}.{k}", positive=True) if k in table else None)
                for k in ("stiffness", "damping", "rot_stiffness", "rot_damping")}
    mode = problems.choice(table, "acceleration_loads", f"{where}.acceleration_loads", ACCEL_MODES, "export")
    if node is None or a_point is None:
        return None
    return Joint(name, a, None if b == "earth" else b, a_point, b_point, codes, node, accel_mode=mode, **optional)

BODY_KEYS = keys.names(keys.BODY)
def _body(problems, name, table, where):
    problems.known_keys(table, where, BODY_KEYS)
    if not identifier(name):
        problems.add(where, "body name must start with a letter and hold only letters, digits and '_'")
    elif name.endswith("_dynamics"):
        problems.add(where, "body names ending in '_dynamics' are reserved for the dynamics FMUs")
    body = Body(
        name=name,
        position=problems.vector(table, "position", f"{where}.position", 3, [0.0, 0.0, 0.0]),
        attitude=problems.vector(table, "attitude", f"{where}.attitude", 3, [0.0, 0.0, 0.0]),
        velocity=problems.vector(table, "velocity", f"{where}.velocity", 6, [0.0] * 6),
        mass=problems.number(table, "mass", f"{where}.mass", positive=True),
        inertia=problems.matrix(table, "inertia", f"{where}.inertia", 3),
        cog=problems.vector(table, "cog", f"{where}.cog", 3, [0.0, 0.0, 0.0]),
        stiffness=problems.matrix(table, "stiffness", f"{where}.stiffness", 6, [0.0] * 6),
        damping=problems.matrix(table, "damping", f"{where}.damping", 6, [0.0] * 6),
        accel_mode=problems.choice(table, "acceleration_loads", f"{where}.acceleration_loads",
                                   ACCEL_MODES, "export"),
    )
    if body.inertia is not None:
        problems.add_all(where, admissible.inertia(body.inertia))
    if body.attitude is not None:
        problems.add_all(where, admissible.attitude(body.attitude))
        if admissible.odd_attitude(body.attitude):
            problems.warn(f"{where}.attitude", admissible.odd_attitude(body.attitude))
    effects = table.get("effects", [])
    if not isinstance(effects, list):
        problems.add(f"{where}.effects", "expected an array of tables ([[bodies.NAME.effects]])")
        effects = []
    names = set()
    for i, eff in enumerate(effects):
        ew = f"{where}.effects[{i}]"
        if not isinstance(eff, dict):
            problems.add(ew, "expected a table")
            continue
        etype = eff.get("type")
        if etype not in EFFECT_TYPES:
            problems.add(f"{ew}.type", f"unknown effect type {etype!r} (known: {', '.join(EFFECT_TYPES)})")
            continue
        validate, default_name = EFFECT_TYPES[etype]
        ename = eff.get("name", default_name)
        if not isinstance(ename, str) or not identifier(ename):
            problems.add(f"{ew}.name", f"effect name must be an identifier, found {ename!r}")
            continue
        if ename in names:
            problems.add(f"{ew}.name", f"duplicate effect name {ename!r} on body {name!r}")
            continue
        names.add(ename)
        data = validate(problems, eff, ew)
        if data is not None:
            body.effects.append(Effect(etype, ename, data))
    return body


def load_scene(path, overrides=None):
    """Read and validate a scene file.  Raises one InputError naming the file and the
    key path of every problem; returns a Scene whose effect data is ready for kernels.
    ``overrides``: {key path: value} replacing values of the file (``override``).
    Suspicious but legal input is an InputWarning (issued again here, for the caller's
    handlers) and kept in ``Scene.warnings`` (the build writes them into the manifest)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", InputWarning)
        try:
            scene = _load_scene(path, overrides)
        finally:
            said = list(caught)
    for w in said:
        warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    scene.warnings = list(dict.fromkeys(str(w.message) for w in said if issubclass(w.category, InputWarning)))
    return scene


def _load_scene(path, overrides=None):
    path = Path(path)
    doc = read_toml(path, "scene")
    for key, value in (overrides or {}).items():
        override(doc, key, value, path)
    p = Problems(path)
    p.known_keys(doc, "", keys.names(keys.SCENE))
    meta = p.table(doc, "scene", "scene", required=False) or {}
    p.known_keys(meta, "scene", keys.names(keys.SCENE_META))
    name = meta.get("name", path.stem)
    if not isinstance(name, str) or not identifier(name):
        p.add("scene.name", f"scene name must be an identifier, found {name!r}")
    env = p.table(doc, "environment", "environment", required=False) or {}
    p.known_keys(env, "environment", keys.names(keys.ENVIRONMENT))
    run = p.table(doc, "run", "run", required=False) or {}
    p.known_keys(run, "run", keys.names(keys.RUN))
    build_t = p.table(doc, "build", "build", required=False) or {}
    p.known_keys(build_t, "build", keys.names(keys.BUILD))
    runtime = p.choice(build_t, "runtime", "build.runtime", RUNTIMES, "python")
    preset = run.get("preset")
    if preset is not None and preset not in PRESETS:
        p.add("run.preset", f"expected one of {', '.join(map(repr, PRESETS))}, found {preset!r}")
        preset = None
    base = {**RUN_DEFAULTS, **PRESETS.get(preset, {})}
    run_cfg = {
        "preset": preset,
        "step": p.number(run, "step", "run.step", base["step"], positive=True),
        "stop": p.number(run, "stop", "run.stop", base["stop"], positive=True),
        "algorithm": p.choice(run, "algorithm", "run.algorithm", ALGORITHMS, base["algorithm"]),
        "substep": p.number(run, "substep", "run.substep", base["substep"], positive=True),
        "load_hold": p.choice(run, "load_hold", "run.load_hold", ("constant", "linear"), base["load_hold"]),
        "memory": dict(base.get("memory", MEMORY_DEFAULTS)),
        "set": sorted(k for k in run if k != "preset" and k not in OUTPUT_KEYS),   # knobs the scene sets itself
        "outputs": _outputs(p, run),
        "interval": p.number(run, "interval", "run.interval", positive=True) if "interval" in run else None,
    }
    run_cfg["ecco"] = _ecco(p, run, base, run_cfg["step"] if run_cfg["algorithm"] == "ecco" else None)
    if run_cfg["algorithm"] not in (None, "ecco") and None not in (run_cfg["step"], run_cfg["stop"]):
        for field_, message in admissible.whole_steps(run_cfg["stop"], run_cfg["step"])[1]:
            p.add(f"run.{field_}", message)
    if run_cfg["interval"] is not None and run_cfg["step"] and run_cfg["algorithm"] != "ecco":
        for field_, message in admissible.whole_interval(run_cfg["interval"], run_cfg["step"])[1]:
            p.add(f"run.{field_}", message)
    if "ecco" in run and run_cfg["algorithm"] not in (None, "ecco"):
        p.add("run.ecco", f"ECCO settings need algorithm = \"ecco\" (the run's algorithm is {run_cfg['algorithm']!r})")
    # rho and g first: the BEM wave effects of the bodies make WAMIT files dimensional with them
    rho = p.number(env, "rho", "environment.rho", 1025.0, positive=True)
    g = p.number(env, "g", "environment.g", 9.81, positive=True)
    p.env = {"rho": rho or 1025.0, "g": g or 9.81}
    bodies_t = p.table(doc, "bodies", "bodies") or {}
    bodies = {}
    for bname, btable in bodies_t.items():
        if not isinstance(btable, dict):
            p.add(f"bodies.{bname}", "expected a table")
            continue
        bodies[bname] = _body(p, bname, btable, f"bodies.{bname}")
    if not bodies and "bodies" in doc:
        p.add("bodies", "a scene needs at least one body")
    joints = {}
    joints_t = p.table(doc, "joints", "joints", required=False) or {}
    for jname, jtable in joints_t.items():
        if not isinstance(jtable, dict):
            p.add(f"joints.{jname}", "expected a table")
            continue
        joint = _joint(p, jname, jtable, f"joints.{jname}", bodies)
        if joint is not None:
            joints[jname] = joint
    couplings = (_couplings(p, doc["couplings"], bodies, run_cfg["memory"], {"rho": rho, "g": g})
                 if "couplings" in doc else [])
    speed, direction, profile = _current(p, env)
    sea = _waves(p, doc["waves"]) if "waves" in doc else None
    _wave_effects(p, bodies, sea, rho, g)
    _check_names(p, bodies, joints, couplings)
    scene = Scene(
        name=name, path=path, joints=joints, couplings=couplings, rho=rho, g=g,
        current_speed=speed, current_direction=direction, current_profile=profile,
        bodies=bodies, run=run_cfg, decks=p.readings, runtime=runtime or "python", waves=sea,
    )
    p.raise_if_any()
    return scene


def _check_names(problems, bodies, joints, couplings):
    """Names that become FMU files, instances and variables must never meet: bodies and
    joints name FMU files (``<scene>_<name>.fmu``), compared ignoring case (a Windows or macOS
    folder holds one of ``Barge.fmu`` and ``barge.fmu``); ``earth`` is a joint's side B, not
    a body; on one body, an effect's loads ``<name>.force`` must not meet a coupling's or a
    joint's of the same name (the load FMU and the results would hold two ``X.force``), nor
    ``total`` (the results' sum of every load)."""
    seen = {}
    for key, name in [(f"bodies.{b}", b) for b in bodies] + [(f"joints.{j}", j) for j in joints]:
        if name == "earth":
            problems.add(key, "'earth' is a joint's fixed side (b = \"earth\"), not a body name: rename the body")
        other = seen.setdefault(name.lower(), key)
        if other != key and other.split(".", 1)[1] != name:
            problems.add(key, f"{name!r} differs from {other} only in case: FMU files are named by it, and a "
                              "Windows or macOS folder keeps one of the two")
    for bname, body in bodies.items():
        taken = {c.name: f"coupling {c.name}" for c in couplings if bname in (c.a, c.b)}
        taken.update({j.name: f"joint {j.name}" for j in joints.values() if bname in (j.a, j.b)})
        taken["total"] = "the sum of the body's loads in the results"
        for i, effect in enumerate(body.effects):
            if effect.name in taken:
                problems.add(f"bodies.{bname}.effects[{i}].name",
                             f"effect name {effect.name!r} is also {taken[effect.name]} on body {bname!r}: "
                             f"two loads {effect.name}.force; rename the effect")


SECTIONS = ("scene", "environment", "run", "bodies", "joints", "couplings", "build", "waves")
RUNTIMES = tuple(keys.BUILD["runtime"][0]["enum"])   # [build] runtime: fmi/build.py, fmi/cbuild.py
WAVE_KEYS = keys.names(keys.WAVES)


def _waves(problems, table):
    """The sea state of ``[waves]`` (physics.waves.SeaState), checked; None after recording
    the problems."""
    from .physics.waves import SPECTRA, SeaState, WaveError
    if not isinstance(table, dict):
        problems.add("waves", "expected a table [waves]")
        return None
    problems.known_keys(table, "waves", WAVE_KEYS)
    spectrum = problems.choice(table, "spectrum", "waves.spectrum", SPECTRA, "jonswap")
    if spectrum is None:
        return None
    need = ("height", "period") if spectrum == "regular" else ("hs", "tp")
    defaults = SeaState()
    values = {}
    for key in WAVE_KEYS - {"spectrum", "depth"}:
        if key in table or key not in need:
            values[key] = problems.number(table, key, f"waves.{key}", getattr(defaults, key))
        else:
            problems.add(f"waves.{key}", f"missing value ({spectrum} waves need {' and '.join(need)})")
            values[key] = None
    depth = table.get("depth", math.inf)
    if isinstance(depth, float) and depth == math.inf:      # TOML's inf: deep water (the default)
        values["depth"] = math.inf
    else:
        values["depth"] = problems.number(table, "depth", "waves.depth", positive=True)
    if None in values.values():
        return None
    for key in ("components", "seed"):
        values[key] = int(values[key]) if values[key] == int(values[key]) else values[key]
    sea = SeaState(spectrum, **values)
    try:
        sea.check()
    except WaveError as exc:
        problems.add(f"waves.{exc.field}", str(exc))
        return None
    return sea


def _wave_effects(problems, bodies, sea, rho, g):
    """Checks of the BEM wave effects against the scene: rho, g, depth, rotation centres at the
    reference points (positions matter to the excitation's phase: no shift allowed), the sea
    state within every transfer function (frequencies, directions), the hydrostatics' mass,
    centre of mass and weight terms against the body's, and no restoring counted twice.
    Fills each hydrostatics effect's equilibrium pose."""
    from .physics.kinematics import rotation
    from .physics.waves import TransferFunction, WaveError, components
    tfs = []
    for body in bodies.values():
        for i, eff in enumerate(body.effects):
            if eff.type not in ("wave_excitation", "bem_hydrostatics") or body.position is None:
                continue
            where, d = f"bodies.{body.name}.effects[{i}]", eff.data
            name = Path(d["bem"]).name
            bad = [f"{k} = {d[k]:g} in {name} but {v:g} in the scene (environment.{k})"
                   for k, v in (("rho", rho), ("g", g)) if d.get(k) is not None and v is not None
                   and abs(d[k] - v) > 1e-6 * v]
            centre = d.get("rotation_center")
            if centre is not None and np.max(np.abs(np.subtract(centre, body.position))) > CENTRE_TOL:
                bad.append(f"rotation_center of {d['body']!r} in {name} is {centre} m but the reference point of body "
                           f"{body.name!r} is at {body.position} m: the transfer functions are about the rotation centre "
                           f"and their phases refer to the body's place (move the body or solve again)")
            if eff.type == "wave_excitation":
                depth = d.get("water_depth")
                if sea is not None and depth is not None and not (depth == sea.depth or
                                                                  abs(depth - sea.depth) <= 1e-6 * sea.depth):
                    bad.append(f"water_depth = {depth:g} m in {name} but waves.depth = {sea.depth:g} m")
                elif not bad:
                    values = np.asarray(d["re"]) + 1j * np.asarray(d["im"])
                    try:
                        tfs.append((where, name, TransferFunction(d["omega"], d["directions"], values,
                                                                  body.position[:2], g or 9.81,
                                                                  sea.depth if sea else math.inf)))
                    except WaveError as exc:
                        bad.append(f"{name}: {exc}")
            else:
                bad += _hydrostatic_problems(d, body, name, rotation)
                d["position0"], d["attitude0"] = list(body.position or [0.0] * 3), list(body.attitude or [0.0] * 3)
            for message in bad:
                problems.add(f"{where}.bem", message)
    if sea is None:
        for where, _, _ in tfs:
            problems.warn(where, "no [waves] in the scene: this body's wave excitation is left out of its FMU")
        return
    if not tfs:
        if not problems.items:
            problems.warn("waves", "no body has a wave_excitation effect: the sea state acts on nothing")
        return
    lo = max(tf.window[0] for _, _, tf in tfs)
    hi = min(tf.window[1] for _, _, tf in tfs)
    try:
        comps = components(sea, (lo, hi))
    except WaveError as exc:
        problems.add(f"waves.{exc.field}", f"{exc} (from {', '.join(sorted({n for _, n, _ in tfs}))})")
        return
    for where, name, tf in tfs:
        try:
            tf.at(comps.omega, comps.direction)
        except WaveError as exc:
            problems.add(f"waves.{exc.field}", f"{name} ({where}): {exc}")
            return


MASS_TOL = 0.01   # relative: the BEM result's mass against the scene's


def _hydrostatic_problems(d, body, name, rotation):
    """What makes a BEM hydrostatic matrix wrong for this scene body (messages)."""
    bad = []
    if not d["weight"]:
        bad.append(f"{name} gives no centre of mass: cannot tell whether its hydrostatic_stiffness holds the "
                   "weight's moment (solve with center_of_mass set)")
    if d.get("mass") is not None and body.mass is not None and abs(d["mass"] - body.mass) > MASS_TOL * body.mass:
        bad.append(f"mass = {d['mass']:.6g} kg in {name} (its restoring's weight terms) but {body.mass:.6g} kg in the "
                   f"scene (bodies.{body.name}.mass)")
    com = d.get("center_of_mass")
    if com is not None and None not in (body.position, body.attitude, body.cog):
        scene_com = np.add(body.position, rotation(body.attitude) @ np.asarray(body.cog, float))
        if np.max(np.abs(scene_com - com)) > CENTRE_TOL:
            bad.append(f"center_of_mass = {com} m in {name} but {scene_com.round(6).tolist()} m in the scene "
                       f"(bodies.{body.name}.position + cog)")
    k = np.asarray(body.stiffness if body.stiffness is not None else np.zeros((6, 6)))
    vertical = [2, 3, 4]
    if np.any(k[vertical, :] != 0) or np.any(k[:, vertical] != 0):
        bad.append(f"bodies.{body.name}.stiffness has heave, roll or pitch terms and {name}'s hydrostatics would count "
                   "the restoring twice: leave only mooring terms (surge, sway, yaw) in the body's stiffness")
    return bad
CURRENT_FORMATS = ("deeplines", "sima", "riflex")
# keys that go with current_deck; the last three only with current_format = "riflex"
CURRENT_DECK_KEYS = tuple(keys.CURRENT_DECK)


def _current(problems, env):
    """(surface speed, surface direction, profile rows or None) of ``[environment]``: a uniform
    current (current_speed, current_direction), an inline ``current_profile`` of
    [z, speed, direction] rows, or a ``current_deck`` read by its ``current_format``."""
    from .physics.current import CurrentProfile, profile_problem
    given = [k for k in ("current_profile", "current_deck") if k in env]
    loose = [k for k in CURRENT_DECK_KEYS if k in env]
    if loose and "current_deck" not in env:
        problems.add(f"environment.{loose[0]}", "goes with current_deck (the file the current is read from)")
        return None, None, None
    uniform = [k for k in ("current_speed", "current_direction") if k in env]
    if len(given) > 1 or (given and uniform):
        problems.add(f"environment.{(given + uniform)[1]}", "give the current once: current_speed/current_direction "
                                                            "(uniform), current_profile or current_deck")
        return None, None, None
    if not given:
        speed = problems.number(env, "current_speed", "environment.current_speed", 0.0, nonneg=True)
        direction = problems.number(env, "current_direction", "environment.current_direction", 0.0)
        if direction is not None and admissible.odd_direction(direction):
            problems.warn("environment.current_direction", admissible.odd_direction(direction))
        return speed, direction, None
    if "current_deck" in env:
        rows = _current_deck(problems, env)
    else:
        rows = _profile_rows(problems, env["current_profile"], "environment.current_profile")
        if rows is not None:
            problem = profile_problem(*zip(*rows))
            if problem is not None:
                k, name, message = problem
                problems.add(f"environment.current_profile[{k}]", f"{name}: {message}")
                rows = None
    if rows is None:
        return None, None, None
    for k, row in enumerate(rows if "current_profile" in env else ()):
        if admissible.odd_direction(row[2]):
            problems.warn(f"environment.current_profile[{k}]", admissible.odd_direction(row[2]))
    profile = CurrentProfile.from_rows(rows)
    return profile.surface_speed, profile.surface_direction, [list(r) for r in rows]


def _profile_rows(problems, raw, where):
    """[[z, speed, direction], ...] from the scene, or None after recording one problem."""
    if not isinstance(raw, list) or not raw:
        problems.add(where, "expected rows [z, speed, direction] (z m up from the mean free surface, "
                            "speed m/s, direction deg going to)")
        return None
    for k, row in enumerate(raw):
        if not isinstance(row, list) or len(row) != 3:
            n = len(row) if isinstance(row, list) else 1
            problems.add(f"{where}[{k}]", f"{'missing value' if n < 3 else 'too many values'}: expected "
                                          f"[z, speed, direction], found {row!r}")
            return None
        for name, v in zip(("z", "speed", "direction"), row):
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                problems.add(f"{where}[{k}]", f"{name}: expected a number, found {v!r}")
                return None
    return [[float(v) for v in row] for row in raw]


def _current_deck(problems, env):
    """Profile rows from a vendor file: DeepLines *CURRENT/*CURPROF, a SIMA (SIMO/RIFLEX)
    current profile file, or a current state of a RIFLEX INPMOD file's environment; deck
    errors are recorded with their file, line and field."""
    from .decks.deeplines import read_current_profile
    from .decks.simo import read_current_profile as read_sima
    fmt = problems.choice(env, "current_format", "environment.current_format", CURRENT_FORMATS)
    path = _deck_path(problems, env, "environment", "current_deck")
    riflex_only = [k for k in CURRENT_DECK_KEYS[1:] if k in env]
    if fmt is not None and fmt != "riflex" and riflex_only:
        problems.add(f"environment.{riflex_only[0]}", 'only for current_format = "riflex" (an INPMOD file '
                                                     'holds several environments and current states)')
        return None
    if fmt is None or path is None:
        return None
    if fmt == "riflex":
        return _riflex_current(problems, env, path)
    try:
        return problems.read((read_current_profile if fmt == "deeplines" else read_sima)(path))
    except InputError as exc:
        problems.add("environment.current_deck", str(exc))
        return None


def _riflex_current(problems, env, path):
    """The profile of one ``NEW CURRENT STATE`` of a RIFLEX INPMOD file: the environment
    ``current_environment`` (IDENV) and state ``current_state`` (ICUSTA), each optional
    when the file has only one; ``current_units`` checked against the file's units line."""
    from .decks.riflex import read_current_states
    from .decks.units import SYSTEMS
    units = None
    if "current_units" in env:
        units = problems.choice(env, "current_units", "environment.current_units", tuple(SYSTEMS))
        if units is None:
            return None
    found = problems.deck(path, "environment.current_deck", read_current_states, units)
    if found is None:
        return None
    envs = {k: v for k, v in found.items() if v}
    name = env.get("current_environment")
    if name is None:
        if len(envs) != 1:
            problems.add("environment.current_environment",
                         f"{path.name} has {len(envs)} environments with a NEW CURRENT STATE"
                         f"{' (' + ', '.join(envs) + '): name one' if envs else ''}")
            return None
        name = next(iter(envs))
    elif not isinstance(name, str) or name not in envs:
        problems.add("environment.current_environment",
                     f"{name!r} is not an environment with a NEW CURRENT STATE in {path.name} "
                     f"(it has: {', '.join(envs) or 'none'})")
        return None
    states = envs[name]
    number = env.get("current_state")
    if number is None:
        if len(states) != 1:
            problems.add("environment.current_state", f"environment {name!r} of {path.name} has {len(states)} "
                                                      f"current states ({', '.join(map(str, states))}): name one")
            return None
        number = next(iter(states))
    elif not isinstance(number, int) or isinstance(number, bool) or number not in states:
        problems.add("environment.current_state", f"{number!r} is not a current state of environment {name!r} "
                                                  f"in {path.name} (it has: {', '.join(map(str, states))})")
        return None
    return [list(r) for r in states[number].rows]


def override(doc, key, value, path="scene"):
    """Set the value at a scene key path (``run.preset``, ``bodies.barge.velocity``,
    ``couplings[0].method``) in a parsed scene ``doc``, as if the file held it.  A missing
    top-level table is created; every other table or array on the way must exist."""
    import re
    parts = [(m.group(1), m.group(2)) for m in re.finditer(r"([^.\[\]]+)((?:\[\d+\])*)", key)]
    if not parts or ".".join(n + i for n, i in parts) != key or parts[0][0] not in SECTIONS:
        raise InputError(path, None, key, f"not a scene key path (it starts with one of {', '.join(SECTIONS)})")
    node, where = doc, ""
    steps = [s for name, idx in parts for s in [name] + [int(i) for i in re.findall(r"\d+", idx)]]
    for i, step in enumerate(steps):
        last = i == len(steps) - 1
        if isinstance(step, int):
            if not isinstance(node, list) or step >= len(node):
                raise InputError(path, None, key, f"{where} has no element [{step}]")
        elif not isinstance(node, dict) or (not last and step not in node and i > 0):
            raise InputError(path, None, key, f"{where or 'the scene'} has no table {step!r}")
        if last:
            node[step] = value
        else:
            if i == 0 and step not in node:
                node[step] = {}
            node = node[step]
        where = f"{where}[{step}]" if isinstance(step, int) else f"{where}.{step}" if where else step
