"""The ``[joints.NAME]`` tables: RIFLEX CONB ball joints between two bodies or to the earth."""
from dataclasses import dataclass

from .. import keys
from .bodies import ACCEL_MODES
from .effects import lumped_data
from .problems import identifier


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


def read_joint(problems, name, table, where, bodies):
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
    node, codes = lumped_data(problems, table, where, "CONB")
    optional = {k: (problems.number(table, k, f"{where}.{k}", positive=True) if k in table else None)
                for k in ("stiffness", "damping", "rot_stiffness", "rot_damping")}
    mode = problems.choice(table, "acceleration_loads", f"{where}.acceleration_loads", ACCEL_MODES, "export")
    if node is None or a_point is None:
        return None
    return Joint(name, a, None if b == "earth" else b, a_point, b_point, codes, node, accel_mode=mode, **optional)
