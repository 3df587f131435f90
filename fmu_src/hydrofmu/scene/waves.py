"""The ``[waves]`` table (the scene's one sea state) and the checks of the BEM wave effects
(excitation, hydrostatics) against the scene."""
import math
from pathlib import Path

import numpy as np

from .. import keys
from ..admissible import WAVE_KEYS_USED, depth_mismatch, ignored_wave_keys, sea_problems, size_problem
from ..errors import numbers
from .couplings import CENTRE_TOL
from .effects import drift_on_sea

WAVE_KEYS = keys.names(keys.WAVES)
# the ramp a sea state gets unless [waves] sets one: this many peak periods (a start without
# a ramp kicks a body that has no surge stiffness into a drift of hundreds of metres, docs/tuning.md)
RAMP_PERIODS = 3.0


def read_waves(problems, table):
    """The sea state of ``[waves]`` (physics.waves.SeaState), checked; None after recording
    the problems."""
    from ..physics.waves import SPECTRA, STRETCHING, SeaState, WaveError
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
    stretching = problems.choice(table, "stretching", "waves.stretching", STRETCHING, "wheeler")
    for key in WAVE_KEYS - {"spectrum", "depth", "stretching", "points"}:
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
    if None in values.values() or stretching is None:
        return None
    values["stretching"] = stretching
    for key in ("components", "seed"):
        values[key] = int(values[key]) if values[key] == int(values[key]) else values[key]
    if "ramp" not in table:
        values["ramp"] = RAMP_PERIODS * (values["period"] if spectrum == "regular" else values["tp"])
    sea = SeaState(spectrum, **values)
    try:
        sea.check()
    except WaveError as exc:
        problems.add(f"waves.{exc.field}", str(exc))
        return None
    return sea if _plausible(problems, table, spectrum, values) else None


# bytes a wave component holds in a load FMU: ω, a, β, φ and k, and the transfer function's
# six complex values per body at it (a generous bound for a few bodies)
COMPONENT_BYTES = 8 * 5 + 16 * 6 * 4
MAX_COMPONENTS = 10 ** 7   # physics/waves.c refuses more at initialization: said here, for both flavours


def _plausible(problems, table, spectrum, values):
    """What a sea can be (admissible.sea_problems: errors and warnings naming the key), the
    keys this spectrum ignores (a warning naming them) and a component count that fits in
    memory (an error before anything is allocated).  False after recording an error."""
    errors, warns = sea_problems(spectrum, values, getattr(problems, "env", {}).get("g", 9.81))
    too_big = size_problem(values["components"], COMPONENT_BYTES, "wave components")
    if values["components"] > MAX_COMPONENTS and not too_big:
        too_big = (f"{values['components']:.4g} wave components: more than {MAX_COMPONENTS:.0e}, the compiled "
                   "FMUs' limit (each step sums them all)")
    if too_big and spectrum != "regular":
        errors.append(("components", too_big))
    for key, message in errors:
        problems.add(f"waves.{key}", message)
    for key, message in warns:
        problems.warn(f"waves.{key}", message)
    ignored = ignored_wave_keys(spectrum, table)
    if ignored:
        problems.warn(f"waves.{ignored[0]}", f"{', '.join(ignored)} {'is' if len(ignored) == 1 else 'are'} not read "
                                             f"by spectrum = {spectrum!r} (it reads "
                                             f"{', '.join(sorted(WAVE_KEYS_USED[spectrum]))}): left out")
    return not errors


POINT_KEYS = keys.names(keys.WAVE_POINT)


def feels_waves(effect):
    """True for an effect that feels the incident-wave kinematics (a RIFLEX body always, an
    AQWA drag or a DeepLines polar with ``waves = true``)."""
    return effect.data is not None and (effect.type == "riflex_body" or bool(effect.data.get("waves")))


def read_wave_points(problems, table, bodies, sea=None):
    """``[waves.points.NAME]``: {name: {"position": global (3)} or {"body": name, "offset": (3)}},
    in the file's order; each name an identifier (it prefixes FMU variables).  With the sea
    state ``sea``, a point never in the water is a warning (``_dry_point``)."""
    from .problems import identifier
    raw = table.get("points", {}) if isinstance(table, dict) else {}
    if not isinstance(raw, dict):
        problems.add("waves.points", "expected a table of named points [waves.points.NAME]")
        return {}
    points = {}
    for name, entry in raw.items():
        where = f"waves.points.{name}"
        if not identifier(name):
            problems.add(where, f"a point's name must be an identifier (it names FMU variables), found {name!r}")
            continue
        if not isinstance(entry, dict):
            problems.add(where, "expected a table with position, or body and offset")
            continue
        problems.known_keys(entry, where, POINT_KEYS)
        if ("position" in entry) == ("body" in entry):
            problems.add(where, "give either position (a fixed global point) or body (and offset: a point on it)")
            continue
        if "position" in entry:
            if "offset" in entry:
                problems.add(f"{where}.offset", "offset is a point on a body: give body too, or only position")
                continue
            pos = problems.vector(entry, "position", f"{where}.position", 3)
            if pos is not None:
                points[name] = {"position": pos}
            continue
        body = problems.string(entry, "body", f"{where}.body")
        offset = problems.vector(entry, "offset", f"{where}.offset", 3, [0.0, 0.0, 0.0])
        if body is not None and body not in bodies:
            problems.add(f"{where}.body", f"no body {body!r} in the scene (bodies: {', '.join(bodies) or 'none'})")
            continue
        if body is not None and offset is not None:
            points[name] = {"body": body, "offset": offset}
    if sea is not None:
        for name, point in points.items():
            _dry_point(problems, f"waves.points.{name}", point, bodies, sea)
    return points


# a spectrum's crests exceed this many Hs with probability exp(−8·3²) = e^{−72} per wave
# (linear crests are Rayleigh distributed, P(η_c > x) = exp(−8x²/Hs²))
CREST_HS = 3.0


def _dry_point(problems, where, point, bodies, sea):
    """A warning for a named point that is never in the water (its outputs always 0): below
    the bed, or above the highest crest the scene's sea reaches — Σ a_k, what the linear sea
    can sum to at most (a regular wave's H/2), and for a spectrum 3·Hs, which a crest passes
    with probability e^{−72}.  A point on a body is judged at the body's initial pose."""
    from ..physics.kinematics import rotation
    from ..physics.waves import WaveError, components
    if "position" in point:
        z, key, at = point["position"][2], f"{where}.position", ""
    else:
        body = bodies[point["body"]]
        if body.position is None or body.attitude is None:
            return
        z = float(body.position[2] + (rotation(body.attitude) @ np.asarray(point["offset"], float))[2])
        key, at = f"{where}.offset", f" at the initial pose of body {point['body']!r}"
    if z < -sea.depth:
        problems.warn(key, f"z = {z:g} m{at} is below the sea bed (waves.depth = {sea.depth:g} m): the point is never "
                           "in the water, its outputs stay 0")
        return
    try:
        crest = float(np.sum(components(sea).amplitude))
    except WaveError:
        return   # said by the effects' checks
    why = "the sum of the components' amplitudes, which the linear sea never exceeds"
    if sea.spectrum != "regular" and CREST_HS * sea.hs < crest:
        crest, why = CREST_HS * sea.hs, (f"{CREST_HS:g}·Hs: a crest passes it with probability e^{{−72}} per wave "
                                         "(Rayleigh crests)")
    if z > crest:
        problems.warn(key, f"z = {z:g} m{at} is above the highest crest of the scene's sea ({crest:.3g} m: {why}): "
                           "the point is never in the water, its outputs stay 0")


def check_wave_effects(problems, bodies, sea, rho, g, feels=False):
    """Checks of the BEM wave effects against the scene: rho, g, depth, rotation centres at the
    reference points (positions matter to the excitation's phase: no shift allowed), the sea
    state within every transfer function (frequencies, directions), the hydrostatics' mass,
    centre of mass and weight terms against the body's, and no restoring counted twice.
    Fills each hydrostatics effect's equilibrium pose.  ``feels``: something other than an
    excitation feels the waves (kinematics: RIFLEX bodies, CONB nodes, drags with waves, points)."""
    from ..physics.kinematics import rotation
    from ..physics.waves import TransferFunction, WaveError, components
    tfs, drifts = [], []
    for body in bodies.values():
        _drift_problems(problems, body)
        for i, eff in enumerate(body.effects):
            if eff.type not in ("wave_excitation", "bem_hydrostatics", "wave_drift") or body.position is None:
                continue
            where, d = f"bodies.{body.name}.effects[{i}]", eff.data
            name = Path(d["bem"]).name
            bad = [f"{k} = {d[k]:g} in {name} but {v:g} in the scene (environment.{k})"
                   for k, v in (("rho", rho), ("g", g)) if d.get(k) is not None and v is not None
                   and abs(d[k] - v) > 1e-6 * v]
            centre = d.get("rotation_center")
            fact = ("rotation_center", str(Path(d["bem"]).resolve()), d["body"])
            if centre is not None and np.max(np.abs(np.subtract(centre, body.position))) > CENTRE_TOL:
                # one statement per mismatch: the coupling or the other effect of this file may have made it
                problems.add_once(fact, f"{where}.bem",
                                  f"{Path(d['bem']).resolve()}: rotation_center[{d['body']}]: {numbers(centre)} m in the "
                                  f"file but the reference point of scene body {body.name!r} is at "
                                  f"{numbers(body.position)} m (bodies.{body.name}.position): the coefficients are about "
                                  f"the rotation centre and the wave phases refer to the body's place (move the body "
                                  f"there, or solve again about its reference point)")
            if eff.type in ("wave_excitation", "wave_drift"):
                mismatch = depth_mismatch(d.get("water_depth"), sea.depth if sea is not None else None)
                if mismatch:
                    bad.append(f"{mismatch} (waves.depth; {name}'s water_depth): solve again at the scene's depth, "
                               "or set waves.depth to the result's")
                elif not bad and eff.type == "wave_drift":
                    drifts.append((where, name, body, eff))
                elif not bad:
                    values = np.asarray(d["re"]) + 1j * np.asarray(d["im"])
                    try:
                        tfs.append((where, name, TransferFunction(d["omega"], d["directions"], values,
                                                                  body.position[:2], g or 9.81,
                                                                  sea.depth if sea else math.inf)))
                    except WaveError as exc:
                        bad.append(f"{name}: {exc}")
                    else:
                        for message in _bem_laws(d, values, body, sea, rho, g):
                            problems.warn(f"{where}.bem", message)
            else:
                # a body away from the rotation centre has its centre of mass away too: said once, above
                bad += _hydrostatic_problems(d, body, name, rotation, centre_said=fact in problems.facts)
                d["position0"], d["attitude0"] = list(body.position or [0.0] * 3), list(body.attitude or [0.0] * 3)
            for message in bad:
                problems.add(f"{where}.bem", message)
    if sea is None:
        for where, _, _ in tfs:
            problems.warn(where, "no [waves] in the scene: this body's wave excitation is left out of its FMU")
        for where, _, _, _ in drifts:
            problems.warn(where, "no [waves] in the scene: this body's wave drift is left out of its FMU")
        return
    if not tfs:
        if not problems.items and not feels:
            problems.warn("waves", "no body has a wave_excitation effect, a RIFLEX body, a drag with waves = true or "
                                   "named points: the sea state acts on nothing")
        return
    lo = max([tf.window[0] for _, _, tf in tfs] + [e.data["omega"][0] for _, _, _, e in drifts])
    hi = min([tf.window[1] for _, _, tf in tfs] + [e.data["omega"][-1] for _, _, _, e in drifts])
    try:
        comps = components(sea, (lo, hi))
    except WaveError as exc:
        files = {n for _, n, _ in tfs} | {n for _, n, _, _ in drifts}
        problems.add(f"waves.{exc.field}", f"{exc} (from {', '.join(sorted(files))})")
        return
    for where, name, tf in tfs:
        try:
            tf.at(comps.omega, comps.direction)
        except WaveError as exc:
            problems.add(f"waves.{exc.field}", f"{name} ({where}): {exc}")
            return
    for where, name, body, eff in drifts:
        try:   # the drift of these components: data within the window, QTF headings for the sea; its report
            drift_on_sea(problems, where, eff, body, comps, sea, g or 9.81)
        except WaveError as exc:
            key = "waves.spreading" if exc.field == "spreading" else f"{where}.bem"
            problems.add(key, f"{name} ({where}): {exc}")


def _bem_laws(d, values, body, sea, rho, g):
    """The warnings of decks/bem_laws.py for a wave_excitation effect's data ``d`` (its
    transfer functions ``values``) against the radiation result of the same file (a WAMIT
    .3 / .2: the .1 beside it): the Haskind relation and the long-wave phase."""
    from ..decks import bem_laws
    if sea is None:
        return []
    rho, g = rho or 1025.0, g or 9.81
    radiation = bem_laws.radiation_of(d["bem"], d.get("ulen"), rho, g, d.get("period_variable"))
    return bem_laws.excitation_problems(Path(d["bem"]).name, d["body"], np.asarray(d["omega"]), d["directions"],
                                        values, body.position[:2], radiation, sea.depth, rho, g)


def _drift_problems(problems, body):
    """A wave_drift needs the body's wave_excitation (the sea state's parameters and the
    window live with it) and is one per body."""
    kinds = [e.type for e in body.effects]
    drift = [i for i, t in enumerate(kinds) if t == "wave_drift"]
    for i in drift[1:]:
        problems.add(f"bodies.{body.name}.effects[{i}].type", "one wave_drift per body (a second one would count "
                                                              "the drift twice)")
    if drift and "wave_excitation" not in kinds:
        problems.add(f"bodies.{body.name}.effects[{drift[0]}].type", "a wave_drift needs the body's wave_excitation "
                                                                      "effect (the first-order loads of the same sea)")


MASS_TOL = 0.01   # relative: the BEM result's mass against the scene's


def _hydrostatic_problems(d, body, name, rotation, centre_said=False):
    """What makes a BEM hydrostatic matrix wrong for this scene body (messages)."""
    bad = []
    if not d["weight"]:
        bad.append(f"{name} gives no centre of mass: cannot tell whether its hydrostatic_stiffness holds the "
                   "weight's moment (solve with center_of_mass set)")
    if d.get("mass") is not None and body.mass is not None and abs(d["mass"] - body.mass) > MASS_TOL * body.mass:
        bad.append(f"mass = {d['mass']:.6g} kg in {name} (its restoring's weight terms) but {body.mass:.6g} kg in the "
                   f"scene (bodies.{body.name}.mass)")
    com = d.get("center_of_mass")
    if com is not None and None not in (body.position, body.attitude, body.cog) and not centre_said:
        scene_com = np.add(body.position, rotation(body.attitude) @ np.asarray(body.cog, float))
        if np.max(np.abs(scene_com - com)) > CENTRE_TOL:
            bad.append(f"center_of_mass = {numbers(com)} m in {name} but {numbers(scene_com)} m in the scene "
                       f"(bodies.{body.name}.position + cog)")
    k = np.asarray(body.stiffness if body.stiffness is not None else np.zeros((6, 6)))
    vertical = [2, 3, 4]
    if np.any(k[vertical, :] != 0) or np.any(k[:, vertical] != 0):
        bad.append(f"bodies.{body.name}.stiffness has heave, roll or pitch terms and {name}'s hydrostatics would count "
                   "the restoring twice: leave only mooring terms (surge, sway, yaw) in the body's stiffness")
    return bad
