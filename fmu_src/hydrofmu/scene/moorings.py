"""The ``[moorings.NAME]`` tables: mooring lines from a MoorDyn v2 input file, on the scene's
bodies, in the scene's sea (docs/moorings.md).

    [moorings.spread]
    moordyn = "decks/lines.dat"                 # the MoorDyn file, relative to the scene
    bodies = { Body1 = "cyl" }                  # the file's coupled objects -> scene bodies
    lengths = { 2 = 310.0 }                     # optional: UnstrLen of line 2 [m] (a batch knob)

``bodies`` names, for every object of the file that hydrofmu moves, the scene body it rides
on: ``Body<ID>`` a coupled body of BODIES (its ``Body<ID>`` points in the scene body's axes
from its reference point), ``Point<ID>`` a coupled point of POINTS (a fairlead given in
global coordinates at the scene's initial pose).  The checks, each one error naming the
file's line and the scene's key: MoorDyn's own reading (its message, the line mapped back to
the user's file); an object on no body, or a body the scene lacks; a second sea (MoorDyn's
WaveKin above 1, Currents, a SeafloorFile); water, gravity or depth not the scene's; a
coupled body with mass, volume, drag or added mass of its own (the scene body has them); a
line far shorter than the distance between its ends.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import keys
from ..errors import InputError, numbers
from .problems import deck_path, identifier

MOORING_KEYS = keys.names(keys.MOORING)
OBJECT = re.compile(r"(body|point)(\d+)", re.IGNORECASE)
TAUT_LIMIT = 0.10   # strain a line would need to span its ends: above it an error (a slip), below a warning
REL = 1e-6          # rho, g and depth agree within this relative difference


@dataclass
class MooringSpec:
    """One ``[moorings.NAME]``: the MoorDyn file ``path``, the copy hydrofmu runs (``text``,
    decks.moordyn.Runnable), ``couplings`` (physics.mooring.Coupling, one per coupled object),
    the lines' IDs and the water depth [m] the file's bed is at."""
    name: str
    path: Path
    runnable: object
    couplings: list
    lines: tuple
    depth: float
    lengths: dict = field(default_factory=dict)

    @property
    def text(self):
        return self.runnable.text


def read_moorings(problems, table, bodies, env, sea):
    """{name: MooringSpec} of ``[moorings]``; ``env``: {"rho", "g"} of the scene, ``sea``: its
    SeaState or None.  Problems are recorded, not raised."""
    if not isinstance(table, dict):
        problems.add("moorings", "expected tables [moorings.NAME]")
        return {}
    out = {}
    for name, entry in table.items():
        where = f"moorings.{name}"
        if not isinstance(entry, dict):
            problems.add(where, "expected a table")
            continue
        if not identifier(name) or name in bodies:
            problems.add(where, "mooring name must be an identifier that is not a body's name (it names an FMU)")
            continue
        spec = _read(problems, name, entry, where, bodies, env, sea)
        if spec is not None:
            out[name] = spec
    return out


def _read(problems, name, entry, where, bodies, env, sea):
    from ..decks.moordyn import read_moordyn
    problems.known_keys(entry, where, MOORING_KEYS)
    path = deck_path(problems, entry, where, "moordyn")
    mapping = _mapping(problems, entry, where, bodies)
    lengths = _lengths(problems, entry, where)
    if path is None or mapping is None or lengths is None:
        return None
    try:
        deck = read_moordyn(path)
    except InputError as exc:
        problems.add(f"{where}.moordyn", str(exc))
        return None
    n = len(problems.items)
    for ident in lengths:
        if ident not in deck.lines:
            problems.add(f"{where}.lengths.{ident}", f"{path.name} has no line {ident} "
                                                    f"(its lines: {', '.join(map(str, deck.lines)) or 'none'})")
    try:
        options, depth = _options(problems, deck, where, env, sea)
    except InputError as exc:
        problems.add(f"{where}.moordyn", str(exc))
        return None
    if len(problems.items) > n or options is None:
        return None
    return _coupled(problems, name, deck, where, mapping, lengths, options, depth, bodies)


def _mapping(problems, entry, where, bodies):
    raw = entry.get("bodies")
    if not isinstance(raw, dict) or not raw:
        problems.add(f"{where}.bodies", 'expected a table of the file\'s coupled objects and the scene bodies they '
                                        'ride on, e.g. bodies = { Body1 = "hull" } or { Point4 = "hull" }')
        return None
    out = {}
    for key, value in raw.items():
        found = OBJECT.fullmatch(key)
        if found is None:
            problems.add(f"{where}.bodies.{key}", "expected Body<ID> (a coupled body of the MoorDyn file) or "
                                                  f"Point<ID> (a coupled point), found {key!r}")
            continue
        if not isinstance(value, str) or value not in bodies:
            problems.add(f"{where}.bodies.{key}", f"{value!r} is not a body of this scene "
                                                  f"(bodies: {', '.join(bodies) or 'none'})")
            continue
        out[(found.group(1).lower(), int(found.group(2)))] = (key, value)
    return out if len(out) == len(raw) else None


def _lengths(problems, entry, where):
    raw = entry.get("lengths", {})
    if not isinstance(raw, dict):
        problems.add(f"{where}.lengths", "expected a table {line ID = unstretched length in m}")
        return None
    out = {}
    for key, value in raw.items():
        if not key.isdigit():
            problems.add(f"{where}.lengths.{key}", f"expected a line ID (a whole number), found {key!r}")
            continue
        metres = problems.number(raw, key, f"{where}.lengths.{key}", positive=True)
        if metres is not None:
            out[int(key)] = metres
    return out if len(out) == len(raw) else None


def _at(deck, name):
    """'lines.dat:12' of option ``name``, or the file alone."""
    return f"{deck.path.name}:{deck.options[name][1]}" if name in deck.options else deck.path.name


def _options(problems, deck, where, env, sea):
    """The OPTIONS hydrofmu sets ({name: value}) and the bed's depth; problems recorded."""
    from ..physics.mooring import RUN_OPTIONS
    key = f"{where}.moordyn"
    wavekin = deck.option("wavekin", 0.0)
    if wavekin not in (0.0, 1.0):
        problems.add(key, f"{_at(deck, 'wavekin')}: WaveKin {wavekin:g} makes MoorDyn draw its own waves, a second "
                          "sea: hydrofmu gives the lines the scene's waves and current (set WaveKin 0 or remove it)")
    if deck.option("currents", 0.0) != 0.0:
        problems.add(key, f"{_at(deck, 'currents')}: Currents {deck.option('currents'):g} is MoorDyn's own current, "
                          "a second one: the lines get the scene's [environment] current (remove the option)")
    if "seafloorfile" in deck.options:
        problems.add(key, f"{_at(deck, 'seafloorfile')}: a SeafloorFile bathymetry: the scene's sea has one depth "
                          "(remove it; give WtrDpth)")
    for opt, scene_key in (("rho", "rho"), ("g", "g")):
        value = deck.option(opt)
        if value is not None and abs(value - env[scene_key]) > REL * env[scene_key]:
            problems.add(key, f"{_at(deck, opt)}: {opt} {value:g} in the MoorDyn file but environment.{scene_key} = "
                              f"{env[scene_key]:g} in the scene: give one value")
    depth = _depth(problems, deck, key, sea)
    if depth is None:
        return None, None
    return {**RUN_OPTIONS, "rho": env["rho"], "g": env["g"], "wtrdpth": depth}, depth


def _depth(problems, deck, key, sea):
    """The bed's depth [m]: WtrDpth, else MoorDyn's default (its deepest fixed point), checked
    against [waves] depth (deep-water waves: every component must be deep at that depth)."""
    fixed = [-p.position[2] for p in deck.points.values() if p.attachment.upper() in ("FIXED", "FIX", "ANCHOR")]
    given = deck.option("wtrdpth")
    depth = given if given is not None else max([0.0] + fixed)
    said = f"{_at(deck, 'wtrdpth')}: WtrDpth {depth:g} m" if given is not None else \
        f"{deck.path.name} has no WtrDpth: MoorDyn puts the bed at its deepest anchor, {depth:g} m,"
    if depth <= 0:
        problems.add(key, f"{deck.path.name}: no water depth (WtrDpth, or an anchor below the surface)")
        return None
    deep = [p for p in deck.points.values() if p.attachment.upper() in ("FIXED", "FIX", "ANCHOR")
            and -p.position[2] > depth * (1 + REL)]
    for p in deep:
        problems.add(key, f"{deck.path.name}:{p.line}: an anchor at z = {p.position[2]:g} m is below the bed "
                          f"({said.split(': ', 1)[-1]})")
    if sea is None:
        return depth
    if math.isfinite(sea.depth):
        if abs(sea.depth - depth) > REL * sea.depth:
            problems.add(key, f"{said} but waves.depth = {sea.depth:g} m in the scene: the lines and the waves "
                              "need one sea bed")
        return depth
    from ..physics.waves import band, wave_number
    lo = 2 * math.pi / sea.period if sea.spectrum == "regular" else \
        band(sea.tp, 1.0 if sea.spectrum == "pierson_moskowitz" else sea.gamma)[0]
    if wave_number(lo) * depth < math.pi:
        problems.add(key, f"{said} but the scene's waves are deep-water (no waves.depth) and its longest, "
                          f"{2 * math.pi / wave_number(lo):.4g} m at {lo:.3g} rad/s, reach that bed (deep water needs "
                          f"a depth of at least half a wave length): give waves.depth = {depth:g}")
    return depth


def _coupled(problems, name, deck, where, mapping, lengths, options, depth, bodies):
    """MoorDyn's reading of the copy, the coupled objects against ``bodies``, the couplings."""
    from ..decks.moordyn import runnable
    from ..physics.mooring import Coupling, MooringError, inspect
    copy = runnable(deck, options, lengths)
    try:
        layout = inspect(copy.text, deck.path.name)
    except ImportError:
        problems.add(f"{where}.moordyn", "mooring lines need the moordyn package: pip install hydrofmu[mooring]")
        return None
    except MooringError as exc:
        problems.add(f"{where}.moordyn", _moordyn_message(str(exc), deck, copy))
        return None
    for message in layout.warnings:
        problems.warn(f"{where}.moordyn", f"MoorDyn: {_users(_strip(message), deck, copy)}")
    for kind, ident in layout.unsupported:
        line = deck.bodies[ident].line if kind == "body" else deck.rods.get(ident)
        problems.add(f"{where}.moordyn", f"{deck.path.name}:{line}: {kind.capitalize()}{ident} is "
                                         f"{'coupled pinned' if kind == 'body' else 'a coupled rod'}: hydrofmu's "
                                         "bodies move coupled bodies (6 dof) and coupled points")
    coupled = {("body", i): deck.bodies[i].line for i in layout.bodies}
    coupled.update({("point", i): deck.points[i].line for i in layout.points})
    names = ", ".join(f"{k.capitalize()}{i}" for k, i in coupled) or "none"
    for (kind, ident), (key, body) in mapping.items():
        if (kind, ident) in coupled:
            continue
        entry = (deck.bodies if kind == "body" else deck.points).get(ident)
        what = f"is {entry.attachment} ({deck.path.name}:{entry.line}): MoorDyn moves it itself" if entry else \
            f"is not in {deck.path.name}"
        problems.add(f"{where}.bodies.{key}", f"{key} {what}; only coupled objects ride on the scene's bodies "
                                              f"(the file's coupled objects: {names})")
    for (kind, ident), line in coupled.items():
        if (kind, ident) not in mapping:
            label = f"{kind.capitalize()}{ident}"
            problems.add(f"{where}.bodies", f"{label} ({deck.path.name}:{line}) is coupled (moved by hydrofmu) "
                                            f"but on no body: add {label} = \"<body>\" to {where}.bodies "
                                            f"(bodies: {', '.join(bodies)})")
    if layout.unsupported or any(k not in coupled for k in mapping) or any(k not in mapping for k in coupled):
        return None
    couplings = []
    for (kind, ident), (key, bname) in mapping.items():
        body = bodies[bname]
        if kind == "body":
            _own(problems, deck, where, key, ident, body)
            couplings.append(Coupling("body", ident, bname))
        else:
            rot = _rotation(body)
            offset = rot.T @ (np.array(deck.points[ident].position) - np.array(body.position))
            couplings.append(Coupling("point", ident, bname, tuple(float(v) for v in offset)))
    _taut(problems, deck, where, mapping, lengths, bodies)
    return MooringSpec(name, deck.path, copy, couplings, layout.lines, depth, dict(lengths))


def _rotation(body):
    from ..physics.kinematics import rotation
    return rotation(body.attitude)


def _own(problems, deck, where, key, ident, body):
    """A coupled body carries nothing of its own (the scene body has its mass, buoyancy,
    drag); its pose in the file, unused by MoorDyn, should be the scene body's."""
    entry = deck.bodies[ident]
    own = {k: v for k, v in entry.own.items() if any(x != 0.0 for x in v)}
    if own:
        said = ", ".join(f"{k} {'|'.join(f'{x:g}' for x in v)}" for k, v in own.items())
        problems.add(f"{where}.bodies.{key}", f"{deck.path.name}:{entry.line}: {key} is coupled to the scene body "
                                              f"{body.name!r} but has {said} of its own: the scene body carries the "
                                              f"hull's mass, buoyancy and drag (bodies.{body.name}), MoorDyn would add "
                                              "them to the mooring loads a second time; set Mass, Volume, CdA and "
                                              "Ca to 0")
    pose = np.array(list(body.position) + list(np.degrees(body.attitude)))
    if not np.allclose(entry.pose, pose, rtol=0.0, atol=1e-6):
        problems.warn(f"{where}.bodies.{key}", f"{deck.path.name}:{entry.line}: {key} at X0..y0 = "
                                               f"{numbers(entry.pose)} but bodies.{body.name} starts at "
                                               f"{numbers(pose)} (position m, attitude deg): MoorDyn places the "
                                               "coupled body at the scene body; its points are read in the body's "
                                               "axes from the reference point")


def _end(deck, word, mapping, bodies):
    """Where a line's end is at the scene's initial pose (global [m]), or None (a free point,
    a rod end, a body hydrofmu does not move)."""
    if not word.isdigit() or int(word) not in deck.points:
        return None
    p = deck.points[int(word)]
    kind = p.attachment.upper()
    if kind in ("FIXED", "FIX", "ANCHOR") or ("point", int(word)) in mapping:
        return np.array(p.position)
    if p.body is not None and ("body", p.body) in mapping:
        body = bodies[mapping[("body", p.body)][1]]
        return np.array(body.position) + _rotation(body) @ np.array(p.position)
    return None


def _taut(problems, deck, where, mapping, lengths, bodies):
    """A line shorter than the distance between its ends: it must stretch to span it.  Above
    TAUT_LIMIT of strain an error (no mooring material stretches that far in service: a slip
    in UnstrLen or a coordinate), below it a warning (a taut leg, pretensioned by EA·strain)."""
    for ident, line in deck.lines.items():
        ends = [_end(deck, w, mapping, bodies) for w in line.ends]
        if any(e is None for e in ends):
            continue
        span = float(np.linalg.norm(ends[1] - ends[0]))
        length = lengths.get(ident, line.length)
        strain = span / length - 1
        if strain <= 0:
            continue
        key = f"{where}.lengths.{ident}" if ident in lengths else f"{where}.moordyn"
        said = (f"{deck.path.name}:{line.line}: line {ident} is {length:g} m long (UnstrLen"
                f"{', ' + key if ident in lengths else ''}) but its ends are {span:.6g} m apart at the scene's "
                f"initial pose ({numbers(ends[0])} and {numbers(ends[1])})")
        if strain > TAUT_LIMIT:
            problems.add(key, f"{said}: it would stretch {100 * strain:.3g} %, beyond any mooring line (limit "
                              f"{100 * TAUT_LIMIT:g} %); check UnstrLen and the points")
        else:
            ea = deck.line_types[line.type].ea if line.type in deck.line_types else None
            tension = f", a tension of at least EA·strain = {ea * strain / 1e3:.4g} kN" if ea else ""
            problems.warn(key, f"{said}: taut, stretched {100 * strain:.3g} %{tension} (meant for a taut leg?)")


def _strip(message):
    """A MoorDyn message without its source location ('ERR /project/source/X.cpp:12 f(): ')."""
    return re.sub(r"^(ERR|WRN|MSG|DBG)\s+\S+:\d+\s+\S+\(\)\s*:\s*", "", message.strip())


def _users(said, deck, copy):
    """MoorDyn's text with the copy's 'name at line N' and 'name:N' as the user's file and line."""
    def user(found):
        line = copy.user_line(int(found.group(1)))
        return f"{deck.path}:{line}" if line else f"{deck.path} (an option hydrofmu set)"
    return re.sub(rf"{re.escape(deck.path.name)}(?: at line |:)(\d+)", user, said)


def _moordyn_message(text, deck, copy):
    """MoorDyn's refusal, its lines mapped back to the user's file."""
    said = " ".join(_strip(t) for t in text.splitlines() if t.strip())
    return f"MoorDyn refused the file: {_users(said, deck, copy)}"
