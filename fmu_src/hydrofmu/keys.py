"""The keys of scene files and case files: every table, its keys, each key's type and meaning.

This is the one place that defines them.  the scene package and ``batch.py`` accept exactly these
keys (an unknown one is an error naming the closest, `scene.Problems.known_keys`), and
``schema.py`` turns them into the JSON Schema shipped with the package
(``hydrofmu/schema/scene.schema.json``, ``cases.schema.json``), which TOML editors (taplo,
Even Better TOML) use to complete keys and flag mistakes while a file is typed.  A new key
goes here first; the validator then still checks its value.

Each key maps to ``(schema, description)``: ``schema`` a JSON Schema fragment for its value
(the shape a TOML editor can check; the validator's checks go further: finite numbers,
positive definite inertia, decks that exist…), ``description`` one line with its unit.
"""
NUMBER = {"type": "number"}
POSITIVE = {"type": "number", "exclusiveMinimum": 0}
NONNEG = {"type": "number", "minimum": 0}
STRING = {"type": "string", "minLength": 1}
NAME = {"type": "string", "pattern": "^[A-Za-z][A-Za-z0-9_]*$"}


def vector(n):
    return {"type": "array", "items": NUMBER, "minItems": n, "maxItems": n}


def matrix(n):
    """n values (the diagonal) or n×n."""
    return {"oneOf": [vector(n), {"type": "array", "items": vector(n), "minItems": n, "maxItems": n}]}


def enum(*values):
    return {"enum": list(values)}


ROWS = {"type": "array", "items": {"type": "array", "items": NUMBER}}
NAMES = {"type": "array", "items": STRING}
BODY_MAP = {"type": "object", "additionalProperties": STRING}
UNITS = ("units", enum("SI", "Mg-kN", "kg-kN"), "unit system of a SIMO/RIFLEX file (checked against its declaration)")

SCENE_META = {
    "name": (NAME, "identifier; FMU model identifiers are <scene>_<body> (default: the file name)"),
    "description": ({"type": "string"}, "free text"),
}

CURRENT_DECK = {
    "current_format": (enum("deeplines", "sima", "riflex"), "format of current_deck"),
    "current_environment": (STRING, "RIFLEX only: IDENV of the environment in the INPMOD file"),
    "current_state": ({"type": "integer", "minimum": 1}, "RIFLEX only: ICUSTA of the current state"),
    "current_units": (UNITS[1], "RIFLEX only: the file's unit system"),
}

ENVIRONMENT = {
    "rho": (POSITIVE, "water density [kg/m3] (default 1025)"),
    "g": (POSITIVE, "gravity [m/s2] (default 9.81)"),
    "current_speed": (NONNEG, "current speed [m/s], start value of the FMU input current.speed"),
    "current_direction": (NUMBER, "current direction [deg], going to, counter-clockwise from +x"),
    "current_profile": (ROWS, "[[z m, speed m/s, direction deg], …], z ≤ 0, strictly ordered"),
    "current_deck": (STRING, "current profile file, relative to the scene (with current_format)"),
    **CURRENT_DECK,
}

ECCO = {
    "rel_tolerance": (POSITIVE, "residual energy per step relative to the energy the bonds carry"),
    "abs_tolerance": (POSITIVE, "residual energy per step [J]"),
    "min_step": (POSITIVE, "smallest step [s]"),
    "max_step": (POSITIVE, "largest step [s]"),
    "safety_factor": (POSITIVE, "PI controller's safety factor, in (0, 1]"),
    "min_change_rate": (POSITIVE, "smallest step ratio, in (0, 1]"),
    "max_change_rate": (POSITIVE, "largest step ratio, ≥ 1"),
    "p_gain": (POSITIVE, "PI controller's proportional gain"),
    "i_gain": (POSITIVE, "PI controller's integral gain"),
}

RUN = {
    "preset": (enum("screening", "design", "reference", "adaptive"), "speed/accuracy preset: sets the knobs below"),
    "step": (POSITIVE, "communication step [s] (ECCO: the first step)"),
    "stop": (POSITIVE, "end time [s], a whole number of steps"),
    "algorithm": (enum("jacobi", "gauss-seidel", "ecco"), "master algorithm"),
    "substep": (POSITIVE, "accuracy of the dynamics partner [s]: internal steps ≤ 5·substep"),
    "load_hold": (enum("constant", "linear"), "how the dynamics hold a load input over a step"),
    "ecco": ({"table": ECCO}, "libcosim's ECCO settings (algorithm = \"ecco\")"),
    "outputs": ({**NAMES, "minItems": 1}, "what hydrofmu run records: body names, body.position (attitude, velocity, "
                                          "acceleration), instance.variable (default: every output)"),
    "interval": (POSITIVE, "output interval [s], a whole number of steps (default: every step)"),
    "split": (POSITIVE, "period [s] splitting the statistics' low- and wave-frequency parts (default: 2·Tp of the sea)"),
}

LUMPED = {
    "am": (NONNEG, "mass [kg]"),
    "ae": (NONNEG, "volume [m3] (buoyancy ρ·g·AE)"),
    "icoo": (enum("GLOBAL", "LOCAL"), "axes of the drag and added-mass coefficients"),
    "cd": (vector(3), "quadratic drag [N/(m/s)2] per axis"),
    "added_mass": (vector(3), "added mass [kg] per axis"),
}
COMPONENT = {
    "deck": (STRING, "RIFLEX input file, relative to the scene"),
    "component": (STRING, "CMPTYP-ID of the component"),
    UNITS[0]: UNITS[1:],
}
EFFECT_COMMON = {
    "type": (STRING, "effect type"),
    "name": (NAME, "effect name: its loads are <name>.force[1..6] (default per type)"),
}

# effect type -> {"deck": keys when the data come from a deck, "inline": keys otherwise}
EFFECTS = {
    "aqwa_viscous_drag": {
        "deck": {"deck": (STRING, "AQWA input file, relative to the scene"),
                 "body": (STRING, "FLOATING BODY name in the deck"),
                 "waves": ({"type": "boolean"}, "our extension: the relative velocity also subtracts the incident waves' velocity")},
        "inline": {"matrix": (matrix(6), "6×6 drag matrix V (or 6 diagonal values), body axes"),
                   "option": (enum("ABSOLUTE", "RELATIVE"), "RELATIVE: velocity relative to the current"),
                   "waves": ({"type": "boolean"}, "our extension: the relative velocity also subtracts the incident waves' velocity")},
    },
    "deeplines_current_polar": {
        "deck": {"deck": (STRING, "DeepLines data file, relative to the scene"),
                 "structure": (STRING, "*CURRENTPOL,NAME= of the structure"),
                 "symmetry": (enum("none", "xz", "yz", "xz+yz"), "symmetry completing the table"),
                 "waves": ({"type": "boolean"}, "our extension: the current also subtracts the incident waves' velocity")},
        "inline": {"point": (vector(3), "current centre (XC, YC, ZC) [m], body axes"),
                   "surface": (POSITIVE, "reference surface SURFC [m2]"),
                   "table": (ROWS, "[[angle deg, CX, CY, CMZ m], …]"),
                   "symmetry": (enum("none", "xz", "yz", "xz+yz"), "symmetry completing the table"),
                   "waves": ({"type": "boolean"}, "our extension: the current also subtracts the incident waves' velocity")},
    },
    "riflex_body": {
        "deck": {"offset": (vector(3), "attachment point [m], body axes from the reference point"), **COMPONENT},
        "inline": {"offset": (vector(3), "attachment point [m], body axes from the reference point"), **LUMPED},
    },
}

PERIOD_VARIABLE = (enum("period", "omega", "wavenumber", "hz"),
                   "WAMIT: the first column of the file, as the run's IPEROUT wrote it: period [s] (default), "
                   "omega [rad/s], wavenumber (KL = ω²L/g), hz [Hz]")
BEM_EFFECT = {
    "bem": (STRING, "Capytaine dataset (.nc), or WAMIT file, relative to the scene"),
    "body": (STRING, "BEM body (optional for a one-body file; WAMIT: body1, body2, …)"),
    "ulen": (POSITIVE, "WAMIT: the length ULEN [m]"),
}
# effects whose data always come from a BEM result: no deck variant (an empty one never matches)
EFFECTS["wave_excitation"] = {"deck": {}, "inline": {**BEM_EFFECT, "bem": (STRING, "excitation: Capytaine dataset "
                                                                                  "(.nc) or WAMIT .3 / .2"),
                                                     "period_variable": PERIOD_VARIABLE}}
EFFECTS["bem_hydrostatics"] = {"deck": {}, "inline": {**BEM_EFFECT, "bem": (STRING, "hydrostatics: Capytaine dataset "
                                                                                   "(.nc) or WAMIT .hst")}}

EFFECTS["wave_drift"] = {"deck": {}, "inline": {
    **BEM_EFFECT,
    "bem": (STRING, "drift: WAMIT .7/.8/.9 (mean), .10d/.11d/.12d (QTF) or a Capytaine dataset with the "
                    "far-field drift (hydrofmu meandrift)"),
    "method": (enum("mean", "newman", "qtf"), "mean drift, Newman's approximation or the full difference-frequency "
                                              "QTF; default qtf for a QTF file (WAMIT .10d/.11d/.12d; newman when "
                                              "it is unidirectional and the sea spread), newman for mean drift "
                                              "files"),
    "cutoff": (POSITIVE, "qtf: the largest |ω_i − ω_j| kept [rad/s] (default: every pair)"),
    "period_variable": PERIOD_VARIABLE,
}}

WAVES = {
    "spectrum": (enum("regular", "jonswap", "pierson_moskowitz"), "sea state type (default jonswap)"),
    "hs": (NONNEG, "significant wave height Hs = 4·sqrt(m0) [m] (spectra)"),
    "tp": (POSITIVE, "spectral peak period [s] (spectra)"),
    "gamma": ({"type": "number", "minimum": 1}, "JONSWAP peak enhancement (default 3.3)"),
    "height": (NONNEG, "regular wave height H [m]"),
    "period": (POSITIVE, "regular wave period [s]"),
    "phase": (NUMBER, "regular wave phase at the origin, t = 0 [deg]"),
    "direction": (NUMBER, "wave direction [deg], going to, counter-clockwise from +x"),
    "spreading": (NONNEG, "cos-2s spreading exponent s (0: long-crested)"),
    "components": ({"type": "integer", "minimum": 1}, "number of wave components (default 200)"),
    "seed": ({"type": "integer", "minimum": 0}, "random seed of frequencies, phases, directions"),
    "ramp": (NONNEG, "length of the smooth start ramp [s] (default: 3 peak periods; 0: none)"),
    "depth": (POSITIVE, "water depth [m] (default: deep water)"),
    "stretching": (enum("none", "vertical", "wheeler", "extrapolation"),
                   "wave kinematics above the mean water level (default wheeler)"),
}
WAVE_POINT = {
    "position": (vector(3), "a fixed point [m], global (outputs on the first body's load FMU)"),
    "body": (STRING, "the body carrying the point (outputs on its load FMU)"),
    "offset": (vector(3), "the point on the body [m], body axes from its reference point"),
}
WAVES["points"] = ({"type": "object", "additionalProperties": {
    "type": "object", "additionalProperties": False,
    "properties": {k: dict(v[0], description=v[1]) for k, v in WAVE_POINT.items()}}},
    "named points whose wave kinematics are FMU outputs waves.<point>.*: [waves.points.NAME]")

BODY = {
    "position": (vector(3), "initial (equilibrium) position of the reference point [m], global"),
    "attitude": (vector(3), "initial roll, pitch, yaw [rad]"),
    "velocity": (vector(6), "initial velocity [m/s, rad/s], global axes"),
    "mass": (POSITIVE, "mass [kg]"),
    "inertia": (matrix(3), "inertia about the CoG [kg m2], body axes (3 values = diagonal, or 3×3)"),
    "cog": (vector(3), "centre of gravity [m], body axes from the reference point"),
    "stiffness": (matrix(6), "6×6 stiffness (or 6 diagonal values) [N/m, N m/rad]"),
    "damping": (matrix(6), "6×6 linear damping (or 6 diagonal values) [N s/m, N m s/rad]"),
    "acceleration_loads": (enum("export", "explicit"), "acceleration loads exported as added mass, or applied"),
    "effects": ({"effects": EFFECTS}, "the body's load effects ([[bodies.NAME.effects]])"),
}

JOINT = {
    "type": (enum("riflex_conb"), "joint type"),
    "a": (STRING, "side A: a body"),
    "a_point": (vector(3), "joint point [m] in A's body axes"),
    "b": (STRING, "side B: a body or \"earth\""),
    "b_point": (vector(3), "joint point [m] in B's body axes (global for the earth)"),
    "stiffness": (POSITIVE, "translational spring [N/m] (default from the step)"),
    "damping": (NONNEG, "translational damper [N s/m] (default from the step)"),
    "rot_stiffness": (POSITIVE, "rotational spring [N m/rad] (default from the step)"),
    "rot_damping": (NONNEG, "rotational damper [N m s/rad] (default from the step)"),
    "acceleration_loads": (enum("export", "explicit"), "of the joint node's mass (goes to side A)"),
}
JOINT_DECK = dict(COMPONENT)
JOINT_INLINE = {**LUMPED, "codes": (vector(3), "freedom codes IRX IRY IRZ: 0 free, 1 fixed")}

MEMORY = {
    "method": (enum("convolution", "state_space"), "memory evaluator"),
    "tolerance": (POSITIVE, "state space: fit tolerance (normalised RMS)"),
    "order": ({"type": "integer", "minimum": 1}, "state space: order per kernel instead of a tolerance"),
    "memory_length": (POSITIVE, "truncate the kernels [s]"),
}
COUPLING = {
    "deck": (STRING, "SIMO system file, relative to the scene"),
    "coupling": (STRING, "CHCPL of the HYDRodynamic COUPling DATA group"),
    "bodies": (BODY_MAP, "SIMO body -> scene body (default: same name)"),
    UNITS[0]: UNITS[1:],
    **MEMORY,
}
BEM_COUPLING = {
    "bem": (STRING, "Capytaine dataset (.nc) or WAMIT .1 file, relative to the scene"),
    "bodies": (BODY_MAP, "BEM body -> scene body (WAMIT: body1, body2, …)"),
    "name": (NAME, "prefix of the couplings' names (default \"bem\")"),
    "dofs": (NAMES, "dofs to keep, e.g. [\"Surge\", \"Heave\", \"Pitch\"] (default: all)"),
    "ulen": (POSITIVE, "WAMIT: the length ULEN [m]"),
    "period_variable": PERIOD_VARIABLE,
    "timdel": (POSITIVE, "kernel spacing [s] (default from the grid)"),
    "kernel_length": (POSITIVE, "kernel length [s] (default from the grid)"),
    "symmetry_tolerance": (POSITIVE, "A∞ asymmetry allowed, relative to √(A_ii·A_jj)"),
    "a_inf": (enum("ogilvie", "file"), "A∞ consistent with the kernels (Ogilvie), or the file's ω = ∞ row"),
    "rotation_centers": ({"type": "object", "additionalProperties": vector(3)},
                         "declared rotation centre per BEM body [m] (WAMIT's XBODY)"),
    **MEMORY,
}

MOORING = {
    "moordyn": (STRING, "MoorDyn v2 input file, relative to the scene (line types, points, lines, options)"),
    "bodies": ({"type": "object", "propertyNames": {"pattern": "^([Bb][Oo][Dd][Yy]|[Pp][Oo][Ii][Nn][Tt])[0-9]+$"},
                "additionalProperties": STRING},
               "the file's coupled objects -> scene bodies: Body<ID> (a coupled body) or Point<ID> (a coupled "
               "point) = \"body\""),
    "lengths": ({"type": "object", "propertyNames": {"pattern": "^[0-9]+$"}, "additionalProperties": POSITIVE},
                "line ID -> unstretched length [m], replacing the file's UnstrLen (a batch knob)"),
}

BUILD = {
    "runtime": (enum("python", "c"), "the FMUs' flavour: pythonfmu (the reference) or compiled C (no Python at run time)"),
}

SCENE = {
    "scene": ({"table": SCENE_META}, "name and description"),
    "environment": ({"table": ENVIRONMENT}, "water, gravity and current"),
    "run": ({"table": RUN}, "run settings (hydrofmu run, demo)"),
    "bodies": ({"map": BODY}, "one table per floating body: [bodies.NAME]"),
    "joints": ({"map": JOINT, "variants": {"deck": JOINT_DECK, "inline": JOINT_INLINE}},
               "RIFLEX CONB joints: [joints.NAME]"),
    "couplings": ({"couplings": (COUPLING, BEM_COUPLING)},
                  "SIMO hydrodynamic couplings ([[couplings]]: deck + coupling, or bem)"),
    "build": ({"table": BUILD}, "build settings (hydrofmu build)"),
    "waves": ({"table": WAVES}, "one wave field for the scene: the sea state ([waves])"),
    "moorings": ({"map": MOORING}, "mooring lines from a MoorDyn file on the scene's bodies: [moorings.NAME]"),
}

CASES = {
    "scene": (STRING, "the scene file, or a built scene folder, relative to this file"),
    "outputs": (NAMES, "'instance.variable' outputs whose statistics the table holds"),
    "stop": (POSITIVE, "end time of every case [s]"),
    "step": (POSITIVE, "communication step of every case [s]"),
    "algorithm": (enum("jacobi", "gauss-seidel", "ecco"), "master algorithm of every case"),
    "transient": (NONNEG, "statistics leave out t < transient [s]"),
    "split": (POSITIVE, "period [s] splitting the low- and wave-frequency parts (default: 2·Tp of each case's sea)"),
    "series": ({"type": "boolean"}, "write each case's time series"),
    "set": ({"type": "object"}, "knobs of every case: {\"key.path\" = value}"),
    "matrix": ({"type": "object", "additionalProperties": {"type": "array", "minItems": 1}},
               "the cases are the cross product: {\"key.path\" = [values]}"),
    "cases": ({"type": "array", "items": {"type": "object"}}, "single cases after the matrix ones"),
}


def names(table):
    """The set of keys of a table above (``ENVIRONMENT``, ``RUN``, …)."""
    return set(table)


def effect_keys(kind, from_deck):
    """The keys an effect of type ``kind`` takes, with its data from a deck or inline."""
    return set(EFFECT_COMMON) | set(EFFECTS[kind]["deck" if from_deck else "inline"])


def joint_keys(from_deck):
    return set(JOINT) | set(JOINT_DECK if from_deck else JOINT_INLINE)


def unit(path: str) -> str | None:
    """The unit a scene key's description states (``'m/s'`` for ``environment.current_speed``,
    ``'kg'`` for ``bodies.barge.mass``), for labels; None when it states one of none or several."""
    import re
    parts = re.sub(r"\[\d+\]", "", path).split(".")
    kind = SCENE.get(parts[0], ({},))[0]
    table = kind.get("table") or kind.get("map")
    rest = parts[1:] if "table" in kind else parts[2:]
    if not table or len(rest) != 1 or rest[0] not in table:
        return None
    found = re.findall(r"\[([^\]]+)\]", table[rest[0]][-1])
    return found[0] if len(found) == 1 else None
