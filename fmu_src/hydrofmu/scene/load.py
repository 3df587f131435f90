"""A scene file read whole: the ``Scene`` its tables make, the cross-table checks
(names that become FMU files and variables), and key-path overrides (batch knobs)."""
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from .. import keys
from ..errors import InputError, InputWarning
from ..textfile import read_toml
from .bodies import read_body
from .couplings import read_couplings
from .current import read_current
from .joints import read_joint
from .moorings import read_moorings
from .problems import Problems, identifier
from .run import read_run, stable_defaults
from .waves import check_wave_effects, feels_waves, read_wave_points, read_waves

SECTIONS = ("scene", "environment", "run", "bodies", "joints", "couplings", "build", "waves", "moorings")
RUNTIMES = tuple(keys.BUILD["runtime"][0]["enum"])   # [build] runtime: fmi/build.py, fmi/cbuild.py


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
    wave_points: dict = field(default_factory=dict)   # [waves.points]: name -> {position} or {body, offset}
    moorings: dict = field(default_factory=dict)   # [moorings.NAME]: name -> scene.moorings.MooringSpec


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
    run_cfg = read_run(p, run)
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
        bodies[bname] = read_body(p, bname, btable, f"bodies.{bname}")
    if not bodies and "bodies" in doc:
        p.add("bodies", "a scene needs at least one body")
    joints = {}
    joints_t = p.table(doc, "joints", "joints", required=False) or {}
    for jname, jtable in joints_t.items():
        if not isinstance(jtable, dict):
            p.add(f"joints.{jname}", "expected a table")
            continue
        joint = read_joint(p, jname, jtable, f"joints.{jname}", bodies)
        if joint is not None:
            joints[jname] = joint
    sea = read_waves(p, doc["waves"]) if "waves" in doc else None   # before the couplings: its depth
    couplings = (read_couplings(p, doc["couplings"], bodies, run_cfg["memory"],
                                {"rho": rho, "g": g, "depth": sea.depth if sea is not None else None})
                 if "couplings" in doc else [])
    speed, direction, profile = read_current(p, env)
    points = read_wave_points(p, doc["waves"], bodies, sea) if "waves" in doc else {}
    feels = bool(points) or bool(joints) or any(feels_waves(e) for b in bodies.values() for e in b.effects)
    check_wave_effects(p, bodies, sea, rho, g, feels)
    moorings = read_moorings(p, doc["moorings"], bodies, p.env, sea) if "moorings" in doc else {}
    if moorings:
        p.warn("moorings", "read and checked, not yet built: the FMUs of this version carry no mooring lines "
                           "(the bodies keep only their own stiffness)")
    _check_names(p, bodies, joints, couplings, moorings)
    if not p.items:   # defaults for what a valid scene holds (a scene with problems is refused below)
        stable_defaults(run_cfg, bodies, couplings, sea,
                        isinstance(doc.get("waves"), dict) and "ramp" not in doc["waves"], joints)
    scene = Scene(
        name=name, path=path, joints=joints, couplings=couplings, rho=rho, g=g,
        current_speed=speed, current_direction=direction, current_profile=profile,
        bodies=bodies, run=run_cfg, decks=p.readings, runtime=runtime or "python", waves=sea,
        wave_points=points if sea is not None else {}, moorings=moorings,
    )
    p.raise_if_any()
    return scene


def _check_names(problems, bodies, joints, couplings, moorings=()):
    """Names that become FMU files, instances and variables must never meet: bodies, joints
    and moorings name FMU files (``<scene>_<name>.fmu``), compared ignoring case (a Windows or macOS
    folder holds one of ``Barge.fmu`` and ``barge.fmu``); ``earth`` is a joint's side B, not
    a body; on one body, an effect's loads ``<name>.force`` must not meet a coupling's or a
    joint's of the same name (the load FMU and the results would hold two ``X.force``), nor
    ``total`` (the results' sum of every load)."""
    seen = {}
    for key, name in ([(f"bodies.{b}", b) for b in bodies] + [(f"joints.{j}", j) for j in joints]
                      + [(f"moorings.{m}", m) for m in moorings]):
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
