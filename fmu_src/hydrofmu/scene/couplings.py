"""The ``[[couplings]]`` tables: SIMO coupling decks and BEM results (self and cross
couplings of the mapped bodies), with their memory evaluator knobs."""
import numpy as np

from .. import keys
from ..admissible import depth_mismatch
from ..decks.bem import PERIOD_VARIABLES
from ..description import HydroCoupling, Kernel
from ..errors import InputError, numbers
from ..names import did_you_mean
from .problems import deck_path, deck_units, identifier
from .run import MEMORY_DEFAULTS


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


def read_couplings(problems, items, bodies, memory=MEMORY_DEFAULTS, env=None):
    from ..decks.simo import read_couplings as read_simo_couplings
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
        path = deck_path(problems, table, where)
        name = problems.string(table, "coupling", f"{where}.coupling")
        knobs = _memory_knobs(problems, table, where, memory)
        units = deck_units(problems, table, where)
        if path is None or name is None or knobs[0] is None or units is None:
            continue
        decks = problems.deck(path, f"{where}.deck", read_simo_couplings, frozenset(known), units)
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
    from .. import bem
    from ..decks.bem import read_bem
    from ..physics.radiation import SYMMETRY_TOL
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
    variable = (problems.choice(table, "period_variable", f"{where}.period_variable", tuple(PERIOD_VARIABLES))
                if "period_variable" in table else None)
    knobs = _memory_knobs(problems, table, where, memory)
    centres = problems.table(table, "rotation_centers", f"{where}.rotation_centers", required=False) or {}
    centres = {b: problems.vector(centres, b, f"{where}.rotation_centers.{b}", 3) for b in centres}
    if file is None or mapping is None or knobs[0] is None or prefix is None or not identifier(prefix) \
            or a_inf_from is None or None in centres.values() or ("period_variable" in table and variable is None):
        if prefix is not None and not identifier(prefix):
            problems.add(f"{where}.name", f"expected an identifier, found {prefix!r}")
        return []
    path = (problems.path.parent / file).resolve()
    if not path.is_file():
        problems.add(f"{where}.bem", f"BEM file not found: {path}")
        return []
    rho = env.get("rho") or 1025.0
    try:
        data = read_bem(path, ulen=opt["ulen"], rho=rho, g=env.get("g") or 9.81, period_variable=variable)
        mismatch = depth_mismatch(data.water_depth, env.get("depth"))
        if mismatch:
            raise InputError(path, None, "water_depth", f"{mismatch} (waves.depth): the radiation coefficients "
                                                        "depend on the depth; solve again at the scene's depth, or "
                                                        "set waves.depth to the result's")
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
                raise InputError(path, None, f"rotation_center[{b}]", f"{numbers(data.rotation_centers[b])} m in "
                                                                      f"the file but {numbers(xyz)} m declared in the scene")
            data.rotation_centers[b] = list(xyz)
        for b, message in _check_centres(data, mapping, bodies):
            problems.add_once(("rotation_center", str(path), b), f"{where}.bem",
                              f"{path}: rotation_center[{b}]: {message}")
        if any(("rotation_center", str(path), b) in problems.facts for b in data.bodies):
            return []
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
    (radiation coefficients do not change when the whole group moves horizontally): the
    [(BEM body, message)] of those that do not match."""
    known = [b for b in data.bodies if b in mapping and b in data.rotation_centers]
    if not known:
        return []
    ref = known[0]
    shift = np.array(bodies[mapping[ref]].position, float) - np.array(data.rotation_centers[ref], float)
    shift[2] = 0.0
    out = []
    for b in known:
        want = np.array(bodies[mapping[b]].position, float)
        got = np.array(data.rotation_centers[b], float) + shift
        if np.max(np.abs(got - want)) > CENTRE_TOL:
            moved = f" after the common shift {numbers(shift[:2])} m of x, y" if np.any(shift[:2]) else ""
            out.append((b, f"{numbers(data.rotation_centers[b])} m in the file but the reference point of scene body "
                           f"{mapping[b]!r} is at {numbers(want)} m (bodies.{mapping[b]}.position){moved}: the "
                           f"coefficients are about the rotation centre (move the body there, or solve again about "
                           f"its reference point)"))
    return out
