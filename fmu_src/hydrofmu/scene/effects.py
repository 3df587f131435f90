"""The effect tables of a body (``[[bodies.NAME.effects]]``): each validator turns its table
into kernel data, from inline values or a vendor deck (RIFLEX BODY/CONB lumped data too)."""
import math
from pathlib import Path

import numpy as np

from .. import admissible, keys
from ..errors import InputError
from .problems import deck_path, from_deck


def _aqwa_viscous_drag(problems, table, where):
    from ..decks.aqwa import read_viscous_drag
    if "deck" in table:
        problems.known_keys(table, where, keys.effect_keys("aqwa_viscous_drag", True))
        data, _ = from_deck(problems, table, where, read_viscous_drag, "body")
        if data is None:
            return None
        return _drag_waves(problems, table, where, {"matrix": np.asarray(data.matrix).tolist(),
                                                     "relative": data.option == "RELATIVE"})
    problems.known_keys(table, where, keys.effect_keys("aqwa_viscous_drag", False))
    matrix = problems.matrix(table, "matrix", f"{where}.matrix", 6)
    option = problems.choice(table, "option", f"{where}.option", ("ABSOLUTE", "RELATIVE"), "ABSOLUTE")
    if matrix is None or option is None:
        return None
    for k, message in admissible.negative_diagonal(matrix):
        problems.warn(f"{where}.matrix[{k + 1},{k + 1}]", message)
    return _drag_waves(problems, table, where, {"matrix": matrix, "relative": option == "RELATIVE"})


def _flag(problems, table, key, where):
    """A boolean key (default false), or None after recording the problem."""
    value = table.get(key, False)
    if not isinstance(value, bool):
        problems.add(where, f"expected true or false, found {value!r}")
        return None
    return value


def _drag_waves(problems, table, where, data):
    """The drag's opt-in ``waves`` (our extension; RELATIVE only)."""
    waves = _flag(problems, table, "waves", f"{where}.waves")
    if waves is None:
        return None
    if waves and not data["relative"]:
        problems.add(f"{where}.waves", "waves = true needs the RELATIVE option (the drag on the velocity relative "
                                       "to the water); this drag is ABSOLUTE")
        return None
    return {**data, "waves": waves}


def _deeplines_current_polar(problems, table, where):
    from ..decks.deeplines import CurrentPolarData, read_current_polars
    from ..physics.current_polar import expand_polar
    symmetry = problems.choice(table, "symmetry", f"{where}.symmetry", ("none", "xz", "yz", "xz+yz"), "none")
    if "deck" in table:
        problems.known_keys(table, where, keys.effect_keys("deeplines_current_polar", True))
        data, _ = from_deck(problems, table, where, read_current_polars, "structure")
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
    waves = _flag(problems, table, "waves", f"{where}.waves")
    if waves is None:
        return None
    return {"angles": angles.tolist(), "cx": cx.tolist(), "cy": cy.tolist(), "cmz": cmz.tolist(),
            "point": [data.xc, data.yc, data.zc], "surface": data.surfc, "waves": waves}


LUMPED_KEYS = keys.names(keys.LUMPED)


def lumped_data(problems, table, where, kind):
    """RIFLEX lumped properties (AM, AE, ICOO, CD, added mass) from a deck component or
    inline; ``kind`` is 'BODY' or 'CONB'.  Returns (data dict, conb codes or None)."""
    from ..decks.riflex import BodyData, ConbData, read_components
    if "deck" in table:
        comp, path = from_deck(problems, table, where, read_components, "component", units=True)
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
    data, _ = lumped_data(problems, table, where, "BODY")
    if data is None or offset is None:
        return None
    return {**data, "offset": offset}


def _bem_entry(problems, table, where, reader):
    """(data read by ``reader``, file, BEM body name) of a BEM wave effect entry (keys bem,
    body, ulen, and period_variable when the effect takes it), or (None, None, None) after
    recording the problem."""
    from ..decks.bem import PERIOD_VARIABLES
    path = deck_path(problems, table, where, "bem")
    ulen = problems.number(table, "ulen", f"{where}.ulen", positive=True) if "ulen" in table else None
    body = problems.string(table, "body", f"{where}.body") if "body" in table else None
    variable = (problems.choice(table, "period_variable", f"{where}.period_variable", tuple(PERIOD_VARIABLES))
                if "period_variable" in table else None)
    if path is None or ("ulen" in table and ulen is None) or ("body" in table and body is None) \
            or ("period_variable" in table and variable is None):
        return None, None, None
    env = getattr(problems, "env", {})
    extra = (variable,) if "period_variable" in table else ()
    data = problems.deck(path, f"{where}.bem", reader, ulen, env.get("rho", 1025.0), env.get("g", 9.81), *extra)
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
    from ..decks.bem_waves import read_excitation
    problems.known_keys(table, where, keys.effect_keys("wave_excitation", False))
    data, path, body = _bem_entry(problems, table, where, read_excitation)
    if data is None:
        return None
    x = data.body(body)
    return {"bem": str(path), "body": body, "kind": data.kind, "omega": data.omega.tolist(),
            "directions": data.directions.tolist(), "re": x.real.tolist(), "im": x.imag.tolist(),
            "rotation_center": data.rotation_centers.get(body), "rho": data.rho, "g": data.g,
            "water_depth": data.water_depth, "ulen": table.get("ulen"), "period_variable": table.get("period_variable")}


def _bem_hydrostatics(problems, table, where):
    """Hydrostatic restoring −C·(η − η0) from a BEM result (Capytaine .nc, WAMIT .hst)."""
    from ..decks.bem_waves import read_hydrostatics
    problems.known_keys(table, where, keys.effect_keys("bem_hydrostatics", False))
    data, path, body = _bem_entry(problems, table, where, read_hydrostatics)
    if data is None:
        return None
    return {"bem": str(path), "body": body, "kind": data.kind, "stiffness": data.stiffness[body].tolist(),
            "weight": data.weight, "mass": data.mass.get(body), "center_of_mass": data.center_of_mass.get(body),
            "rotation_center": data.rotation_centers.get(body), "rho": data.rho, "g": data.g}


def _wave_drift(problems, table, where):
    """Second-order wave drift from a BEM result (WAMIT .7/.8/.9/.10d/.11d/.12d, Capytaine
    dataset with the far-field drift): mean drift or the difference-frequency QTF of one BEM
    body, ``method`` mean | newman | qtf (default qtf for a QTF file, newman for a mean drift
    file); the sea state is the scene's [waves].  A QTF file read for mean or newman keeps the
    full QTF under ``full_qtf`` for the build's report (``drift_on_sea``), the kernel reading
    its diagonal."""
    from ..decks.drift import QTF_SUFFIXES, read_mean_drift, read_qtf
    problems.known_keys(table, where, keys.effect_keys("wave_drift", False))
    is_qtf = str(table.get("bem", "")).endswith(QTF_SUFFIXES)
    method = problems.choice(table, "method", f"{where}.method", ("mean", "newman", "qtf"),
                             "qtf" if is_qtf else "newman")
    cutoff = problems.number(table, "cutoff", f"{where}.cutoff", positive=True) if "cutoff" in table else math.inf
    if method is None or cutoff is None:
        return None
    if "cutoff" in table and method != "qtf":
        problems.add(f"{where}.cutoff", f"applies to method = \"qtf\" only (this effect's method is {method!r})")
        return None
    if method == "qtf" and not is_qtf:
        problems.add(f"{where}.bem", "method = \"qtf\" needs a difference-frequency QTF: a WAMIT .10d, .11d or .12d "
                                     "file (mean drift files hold the diagonal only: use method = \"newman\")")
        return None
    data, path, body = _bem_entry(problems, table, where, read_qtf if is_qtf else read_mean_drift)
    if data is None:
        return None
    for message in data.warnings:
        problems.warn(f"{where}.bem", message)
    out = {"bem": str(path), "body": body, "kind": data.kind, "method": method, "cutoff": cutoff,
           "method_default": "method" not in table, "omega": data.omega.tolist(),
           "rotation_center": data.rotation_centers.get(body), "rho": data.rho, "g": data.g,
           "water_depth": data.water_depth}
    if is_qtf:
        q = data.body(body)
        full = {"pairs": [list(p) for p in data.pairs], "re": q.real.tolist(), "im": q.imag.tolist()}
        if method == "qtf":
            return {**out, **full}
        try:
            mean = data.mean()
        except InputError as exc:     # no unidirectional pair: no mean drift in the file
            problems.add(f"{where}.bem", str(exc))
            return None
        return {**out, "directions": mean.directions.tolist(), "values": mean.body(body).tolist(), "full_qtf": full}
    return {**out, "directions": data.directions.tolist(), "values": data.body(body).tolist()}


DOF = ("surge", "sway", "heave", "roll", "pitch", "yaw")
NEWMAN_TOL = 0.10     # Newman's slow-drift std against the full QTF's: said beyond it
HEADING_TOL = 0.02    # the heading interpolation's error estimate: said beyond it


def drift_on_sea(problems, where, eff, body, comps, sea, g):
    """A ``wave_drift`` effect on the sea's components (scene.waves.check_wave_effects): the
    default method of a unidirectional QTF in a spread sea becomes newman (said); the kernel is
    built (a physics.waves.WaveError when the data do not hold the sea); the report lines in
    ``eff.data["report"]`` (printed by the build): Newman's slow-drift std against the full
    QTF's per dof where the file is a QTF (a warning beyond NEWMAN_TOL when the run uses
    Newman) and the heading interpolation's error estimate (a warning beyond HEADING_TOL)."""
    from ..description import Drift
    from ..physics.drift import QTF, heading_error, slow_drift_std
    d = eff.data
    full = d.get("full_qtf") or ({k: d[k] for k in ("pairs", "re", "im")} if "pairs" in d else None)
    qtf = None if full is None else QTF(d["omega"], [tuple(p) for p in full["pairs"]],
                                        np.array(full["re"]) + 1j * np.array(full["im"]))
    spread = sea.spreading > 0
    if d["method"] == "qtf" and d.get("method_default") and spread and not qtf.bidirectional:
        mean = qtf.diagonal()
        d.update(method="newman", directions=mean.directions.tolist(), values=mean.values.tolist(), full_qtf=full)
        for k in ("pairs", "re", "im"):
            d.pop(k)
        problems.warn(f"{where}.method", f"{Path(d['bem']).name} holds unidirectional heading pairs only and the sea "
                                         f"is spread (waves.spreading): Newman's approximation is used (set method "
                                         f"= \"newman\" to say so, or give bidirectional pairs for the full QTF)")
    drift = Drift.of(eff, body.position)
    data = drift.data(g, sea.depth)
    drift.kernel(comps, g, sea.depth)
    name, report = Path(d["bem"]).name, []
    if qtf is not None and (qtf.bidirectional or not spread):
        sq, sn = slow_drift_std(comps, qtf, drift.cutoff)
        kind_max = [max(sq[:3].max(), sn[:3].max()), max(sq[3:].max(), sn[3:].max())]
        shown = [k for k in range(6) if max(sq[k], sn[k]) > 1e-3 * kind_max[k // 3]]
        ratio = {k: sn[k] / sq[k] if sq[k] > 0 else math.inf for k in shown}
        band = f", |ω_i − ω_j| ≤ {drift.cutoff:g} rad/s" if math.isfinite(drift.cutoff) else ""
        report.append(f"drift of {body.name} ({name}, method {d['method']}): slow-drift std for this sea "
                      f"({comps.omega.size} components{band}), Newman / full QTF: "
                      + ", ".join(f"{DOF[k]} {ratio[k]:.3f} ({sn[k]:.4g} / {sq[k]:.4g} {'N' if k < 3 else 'N·m'})"
                                  for k in shown))
        off = [k for k in shown if abs(ratio[k] - 1) > NEWMAN_TOL]
        if off and d["method"] == "newman":
            problems.warn(f"{where}.method", f"Newman's slow-drift std departs from the full QTF's by more than "
                                             f"{100 * NEWMAN_TOL:g} % for this sea: "
                                             + ", ".join(f"{DOF[k]} {ratio[k]:.2f}×" for k in off)
                                             + f" ({name} is a full QTF: method = \"qtf\", its default, uses it)")
    mean = data.diagonal() if isinstance(data, QTF) else data
    est = heading_error(mean, comps)
    if est is not None:
        err, n = est
        heads = ", ".join(f"{h:g}°" for h in mean.table.directions)
        if err is None:
            problems.warn(f"{where}.bem", f"{n} of the sea's {comps.omega.size} components lie between the only two "
                                          f"headings of {name} ({heads}): the heading interpolation's error cannot be "
                                          f"estimated (it is exact for a body the same from every heading); add "
                                          f"headings around the sea's direction (waves.direction = "
                                          f"{sea.direction:g}°) to the BEM run")
        else:
            report.append(f"drift of {body.name} ({name}): heading interpolation at {n} of {comps.omega.size} "
                          f"components between headings {heads}, linear against cubic on the mean drift: "
                          + ", ".join(f"{DOF[k]} {100 * err[k]:.2g} %" for k in range(6) if err[k] > 0))
            bad = [k for k in range(6) if err[k] > HEADING_TOL]
            if bad:
                problems.warn(f"{where}.bem", f"the heading interpolation of {name}'s drift may be off by "
                                              + ", ".join(f"{100 * err[k]:.2g} % in {DOF[k]}" for k in bad)
                                              + f" for this sea (linear against cubic between its headings "
                                              f"{heads}): add headings around the sea's direction (waves.direction "
                                              f"= {sea.direction:g}°) to the BEM run, or turn the sea onto a "
                                              f"computed heading")
    d["report"] = report


# type -> (validator, default effect name)
EFFECT_TYPES = {
    "wave_excitation": (_wave_excitation, "waves"),
    "wave_drift": (_wave_drift, "drift"),
    "bem_hydrostatics": (_bem_hydrostatics, "hydrostatics"),
    "aqwa_viscous_drag": (_aqwa_viscous_drag, "viscous_drag"),
    "deeplines_current_polar": (_deeplines_current_polar, "current_polar"),
    "riflex_body": (_riflex_body, "riflex_body"),
}
