"""The ``[waves]`` table (the scene's one sea state) and the checks of the BEM wave effects
(excitation, hydrostatics) against the scene."""
import math
from pathlib import Path

import numpy as np

from .. import keys
from .couplings import CENTRE_TOL

WAVE_KEYS = keys.names(keys.WAVES)


def read_waves(problems, table):
    """The sea state of ``[waves]`` (physics.waves.SeaState), checked; None after recording
    the problems."""
    from ..physics.waves import SPECTRA, SeaState, WaveError
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


def check_wave_effects(problems, bodies, sea, rho, g):
    """Checks of the BEM wave effects against the scene: rho, g, depth, rotation centres at the
    reference points (positions matter to the excitation's phase: no shift allowed), the sea
    state within every transfer function (frequencies, directions), the hydrostatics' mass,
    centre of mass and weight terms against the body's, and no restoring counted twice.
    Fills each hydrostatics effect's equilibrium pose."""
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
            if centre is not None and np.max(np.abs(np.subtract(centre, body.position))) > CENTRE_TOL:
                bad.append(f"rotation_center of {d['body']!r} in {name} is {centre} m but the reference point of body "
                           f"{body.name!r} is at {body.position} m: the transfer functions are about the rotation centre "
                           f"and their phases refer to the body's place (move the body or solve again)")
            if eff.type in ("wave_excitation", "wave_drift"):
                depth = d.get("water_depth")
                if sea is not None and depth is not None and not (depth == sea.depth or
                                                                  abs(depth - sea.depth) <= 1e-6 * sea.depth):
                    bad.append(f"water_depth = {depth:g} m in {name} but waves.depth = {sea.depth:g} m")
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
                bad += _hydrostatic_problems(d, body, name, rotation)
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
        if not problems.items:
            problems.warn("waves", "no body has a wave_excitation effect: the sea state acts on nothing")
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
    from ..assembly import body_drift
    for where, name, body, eff in drifts:
        try:   # the drift of these components: data within the window, QTF headings for the sea
            body_drift(_SeaOnly(sea), body).kernel(comps, g or 9.81, sea.depth)
        except WaveError as exc:
            key = "waves.spreading" if exc.field == "spreading" else f"{where}.bem"
            problems.add(key, f"{name} ({where}): {exc}")


class _SeaOnly:
    """What body_drift reads of a scene: its waves."""

    def __init__(self, waves):
        self.waves = waves


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
