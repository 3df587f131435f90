"""The ``[bodies.NAME]`` tables: mass properties, initial pose, stiffness and damping, effects."""
from dataclasses import dataclass, field

from .. import admissible, keys
from ..description import Effect
from .effects import EFFECT_TYPES
from .problems import identifier

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



BODY_KEYS = keys.names(keys.BODY)
def read_body(problems, name, table, where):
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
