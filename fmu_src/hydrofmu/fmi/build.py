"""Build the FMUs of a scene: one load FMU per floating body, holding only the effects the
scene gives it, plus one dynamics-partner FMU per body; a manifest (instances,
connections, run settings) for our masters, an OspSystemStructure.xml for libcosim and an
SSP file (``<scene>.ssp``, fmi/ssp.py) for any SSP importer.

Each FMU is self-contained: its resources carry a copy of the hydrofmu runtime under a
content-hashed name (two FMUs of different builds in one process never share code by
accident), the pythonfmu runtime and its JSON configuration; the host needs only numpy.
Everything is built in a temporary folder and moved into place at the end, so a failed
build leaves nothing half-written.
"""
import hashlib
import importlib
import json
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET
from xml.dom import minidom

import numpy as np

from . import model_description
from .ssp import write_ssp
from .slave import CONFIG
from ..physics import joint as conb
from ..physics.kinematics import rotation
from ..physics.loads import BodyLoads, make_effect
from ..physics.lumped import LumpedBody
from ..physics.rigid_body import RigidBody
from ..physics.state import Motion

PACKAGE = Path(__file__).resolve().parents[1]


def runtime_name():
    """'hydrofmu_rt_<hash>': the package copy's name, from the hash of its sources."""
    h = hashlib.sha256()
    for f in sorted(PACKAGE.rglob("*.py")):
        h.update(f.relative_to(PACKAGE).as_posix().encode())
        h.update(f.read_bytes())
    return f"hydrofmu_rt_{h.hexdigest()[:10]}"


SCRIPT = '''"""hydrofmu FMU {model_id}: {description}"""
import ctypes

from {runtime}.fmi.slave import {slave}


class {model_id}({slave}):
    def __init__(self, **kwargs):
        # pythonfmu 0.7's loader drops one reference to this module's globals at every
        # instantiation (PythonFMU issue #228): give it back, or a second instance fails.
        ctypes.pythonapi.Py_IncRef(ctypes.py_object(globals()))
        super().__init__(**kwargs)
'''


def body_loads(body):
    explicit = body.accel_mode == "explicit"
    return BodyLoads([make_effect(e.type, e.name, e.data) for e in body.effects], explicit)


def initial_motion(body):
    return Motion(np.array(body.position, float), np.array(body.attitude, float))


def exported_mass(scene, every_mode=False):
    """Per body: the 6×6 mass its load FMU, its self-couplings and the joints' nodes on it
    export (export mode); ``every_mode``: the body's own added mass whatever the mode."""
    export = lambda mode: every_mode or mode == "export"
    out = {}
    for body in scene.bodies.values():
        m = np.zeros((6, 6))
        if export(body.accel_mode):
            m += body_loads(body).mass_matrix(initial_motion(body))
        out[body.name] = m
    for joint in scene.joints.values():
        node = joint_node(joint)
        if export(joint.accel_mode) and node.uses_acceleration:
            out[joint.a] = out[joint.a] + node.mass_matrix(initial_motion(scene.bodies[joint.a]))
    for target, source, mass, _ in coupling_sides(scene.couplings):
        if target == source and export(scene.bodies[target].accel_mode):
            out[target] = out[target] + mass
    return out


def coupling_sides(couplings):
    """(target body, source body, 6×6 mass block, side) of every coupling side: side A is
    the load on a from b's motion (A∞), side B the load on b from a's motion (A∞ᵀ)."""
    out = []
    for c in couplings:
        am = np.array(c.data["added_mass"], dtype=float)
        out.append((c.a, c.b, am, "A"))
        if c.a != c.b:
            out.append((c.b, c.a, am.T, "B"))
    return out


def dynamics_groups(scene):
    """Bodies coupled by cross-body added mass in export mode share one dynamics FMU.
    Returns {body: (instance, variable prefix)} and [(instance, [bodies])]."""
    parent = {b: b for b in scene.bodies}

    def root(b):
        while parent[b] != b:
            b = parent[b]
        return b
    for target, source, mass, _ in coupling_sides(scene.couplings):
        if target != source and scene.bodies[target].accel_mode == "export" and np.any(mass):
            parent[root(target)] = root(source)
    groups = {}
    for b in scene.bodies:
        groups.setdefault(root(b), []).append(b)
    dyn_of, out = {}, []
    for members in groups.values():
        instance = f"{'_'.join(members)}_dynamics"
        out.append((instance, members))
        for b in members:
            dyn_of[b] = (instance, f"{b}." if len(members) > 1 else "")
    return dyn_of, out


def rigid_mass(body, added):
    return RigidBody(body.mass, body.inertia, body.cog, added_mass=added, attitude0=body.attitude).mass_matrix()


def stability_indicators(scene, exported):
    """Spectral radius ρ[(M_A+A_AA)⁻¹·A_AB·(M_B+A_BB)⁻¹·A_BA] of every cross coupling:
    explicit (staggered) coupling of the cross added mass diverges when ρ ≥ 1."""
    from ..physics.coupling import stability_indicator
    out = {}
    for c in scene.couplings:
        if c.a == c.b:
            continue
        a, b = scene.bodies[c.a], scene.bodies[c.b]
        am = np.array(c.data["added_mass"], dtype=float)
        out[c.name] = float(stability_indicator(rigid_mass(a, np.zeros((6, 6))), exported[c.a], am,
                                                rigid_mass(b, np.zeros((6, 6))), exported[c.b], am.T))
    return out


def joint_node(joint):
    return LumpedBody("node", joint.a_point, **joint.node)


def joint_config(scene, joint, exported):
    """BallJoint parameters: points, initial relative rotation and, where the scene leaves
    them out, the default spring–damper for the scene's communication step."""
    a, b = scene.bodies[joint.a], scene.bodies.get(joint.b)
    point_a_world = np.array(a.position) + rotation(a.attitude) @ np.array(joint.a_point)
    if joint.b_point is not None:
        point_b = np.array(joint.b_point)
    elif b is None:
        point_b = point_a_world
    else:
        point_b = rotation(b.attitude).T @ (point_a_world - np.array(b.position))

    def effective(body, point):
        return conb.effective_mass(rigid_mass(body, exported[body.name]), rotation(body.attitude) @ point)

    m_a, i_a = effective(a, np.array(joint.a_point))
    m_b, i_b = effective(b, point_b) if b is not None else (None, None)
    dt = scene.run["step"]
    pick = lambda given, default: float(given) if given is not None else float(default)
    return {
        "point_a": list(joint.a_point), "point_b": point_b.tolist(),
        "k_lin": pick(joint.stiffness, conb.default_stiffness(m_a, m_b, dt)),
        "c_lin": pick(joint.damping, conb.default_damping(m_a, m_b, dt)),
        "k_rot": pick(joint.rot_stiffness, conb.default_stiffness(i_a, i_b, dt)),
        "c_rot": pick(joint.rot_damping, conb.default_damping(i_a, i_b, dt)),
        "free": [c == 0 for c in joint.codes],
        "r_rel0": conb.initial_relative_rotation(a.attitude, b.attitude if b is not None else None).tolist(),
    }


def fmu_specs(scene):
    """What to build: one dict per FMU instance, in Gauss–Seidel order (load and joint
    FMUs first, so that every FMU steps from t_k with inputs that are values at t_k).
    ``motion``: input prefix -> body whose dynamics outputs feed it; ``forces``: (output
    group, body, input group) routes to that body's dynamics."""
    env = {"rho": scene.rho, "g": scene.g, "current_speed": scene.current_speed,
           "current_direction": scene.current_direction}
    exported = exported_mass(scene)
    dyn_of, groups = dynamics_groups(scene)
    sides = coupling_sides(scene.couplings)
    loads_specs, joint_specs, dyn_specs = [], [], []
    for instance, members in groups:
        bodies = []
        for name in members:
            body = scene.bodies[name]
            bodies.append({
                "name": name, "mass": body.mass, "inertia": body.inertia, "cog": body.cog,
                "stiffness": body.stiffness, "damping": body.damping,
                "position": body.position, "attitude": body.attitude, "velocity": body.velocity,
                "load_sources": [""] + [j.name for j in scene.joints.values() if name in (j.a, j.b)],
                "added_mass": exported[name].tolist(),
            })
        cross = [[t, src, m.tolist()] for t, src, m, _ in sides
                 if t != src and t in members and src in members and scene.bodies[t].accel_mode == "export"]
        dyn_specs.append({
            "instance": instance, "model_id": f"{scene.name}_{instance}",
            "slave": "DynamicsSlave", "kind": "dynamics", "body": members[0], "motion": {}, "forces": [],
            "config": {
                "description": f"6-DOF rigid-body dynamics of {', '.join(members)} (scene {scene.name})",
                "bodies": bodies, "cross": cross, "substep": scene.run["substep"],
                "load_hold": scene.run["load_hold"],
            },
        })
    for body in scene.bodies.values():
        couplings, motion = [], {"": body.name}
        for c in scene.couplings:
            for target, source, mass, side in coupling_sides([c]):
                if target != body.name:
                    continue
                couplings.append({"name": c.name, "side": side, "source": source, "self": source == target,
                                  "mass": mass.tolist(), "data": c.data, "method": c.method,
                                  "tolerance": c.tolerance, "order": c.order, "memory_length": c.memory_length})
                if source != target:
                    motion[f"{source}."] = source
        loads_specs.append({
            "instance": body.name, "model_id": f"{scene.name}_{body.name}",
            "slave": "LoadSlave", "kind": "load", "body": body.name,
            "motion": motion, "forces": [("force", body.name, "force")],
            "config": {
                "description": f"hydrodynamic loads on '{body.name}' (scene {scene.name}): "
                               + (", ".join([f"{e.name} ({e.type})" for e in body.effects]
                                            + [f"{c['name']} (simo_coupling)" for c in couplings]) or "no effects"),
                "body": body.name, "position": body.position, "attitude": body.attitude,
                "accel_mode": body.accel_mode,
                "effects": [{"type": e.type, "name": e.name, "data": e.data} for e in body.effects],
                "couplings": couplings,
                **env,
            },
        })
    for joint in scene.joints.values():
        a, b = scene.bodies[joint.a], scene.bodies.get(joint.b)
        motion = {"A.": a.name}
        forces = [("A.force", a.name, f"{joint.name}.force")]
        if b is not None:
            motion["B."] = b.name
            forces.append(("B.force", b.name, f"{joint.name}.force"))
        joint_specs.append({
            "instance": joint.name, "model_id": f"{scene.name}_{joint.name}",
            "slave": "ConnectorSlave", "kind": "joint", "body": a.name, "motion": motion, "forces": forces,
            "config": {
                "description": f"RIFLEX CONB ball joint '{joint.name}' between '{a.name}' and "
                               f"'{b.name if b is not None else 'earth'}' (codes IRX IRY IRZ = "
                               f"{' '.join(map(str, joint.codes))}, scene {scene.name})",
                "name": joint.name, "accel_mode": joint.accel_mode, "node": joint.node,
                "joint": joint_config(scene, joint, exported),
                "a": {"position": a.position, "attitude": a.attitude},
                "b": {"position": b.position, "attitude": b.attitude} if b is not None else None,
                **env,
            },
        })
    return loads_specs + joint_specs + dyn_specs, dyn_of


def build_fmu(spec, workdir, runtime, shim=True):
    """Build one FMU from a spec into ``workdir``; returns (fmu path, slave introspection)."""
    from pythonfmu.builder import FmuBuilder

    model_id = spec["model_id"]
    stage = workdir / "stage" / model_id
    stage.mkdir(parents=True)
    rt = stage / runtime
    shutil.copytree(PACKAGE, rt, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.c", "*.so"))
    (stage / CONFIG).write_text(json.dumps(spec["config"]))
    script = stage / f"{model_id}.py"
    script.write_text(SCRIPT.format(model_id=model_id, runtime=runtime, slave=spec["slave"],
                                    description=spec["config"]["description"]))
    saved_path = list(sys.path)
    try:
        fmu = FmuBuilder.build_FMU(script, dest=workdir / "fmus", project_files=[rt, stage / CONFIG],
                                   canGetAndSetFMUstate=True)
        slave = getattr(importlib.import_module(model_id), model_id)(
            instance_name="introspect", resources=str(stage))
    finally:
        sys.path[:] = saved_path
        sys.modules.pop(model_id, None)  # a later load of the FMU must import its own copy
    rewrite_model_description(fmu, slave)
    if shim:
        from .shim import install_shim
        install_shim(fmu)
    return Path(fmu), slave


def rewrite_model_description(fmu, slave):
    """Replace modelDescription.xml in the FMU zip (via a temporary copy)."""
    tmp = Path(str(fmu) + ".tmp")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = model_description.complete(data, slave.units, slave.dependencies)
            dst.writestr(item, data)
    tmp.replace(fmu)


def connections(specs, slaves, dyn_of):
    """Motion outputs of the dynamics FMUs → the motion inputs that exist (by name), and
    load outputs → the dynamics' load inputs, as each spec's routes say."""
    names = {s["instance"]: {v.name for v in slaves[s["instance"]].vars.values()} for s in specs}
    conns = []
    for s in specs:
        for prefix, body in s["motion"].items():
            dyn, dp = dyn_of[body]
            for group, n in (("position", 3), ("attitude", 3), ("velocity", 6), ("acceleration", 6)):
                for i in range(1, n + 1):
                    if f"{prefix}{group}[{i}]" in names[s["instance"]]:
                        conns.append([dyn, f"{dp}{group}[{i}]", s["instance"], f"{prefix}{group}[{i}]"])
        for out, body, inp in s["forces"]:
            dyn, dp = dyn_of[body]
            conns += [[s["instance"], f"{out}[{i}]", dyn, f"{dp}{inp}[{i}]"] for i in range(1, 7)]
    return conns


def osp_system_structure(scene, specs, conns):
    """OspSystemStructure.xml text: libcosim's description of the same system."""
    ns = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
    root = ET.Element("OspSystemStructure", xmlns=ns, version="0.1")
    ET.SubElement(root, "StartTime").text = "0.0"
    ET.SubElement(root, "BaseStepSize").text = repr(scene.run["step"])
    ET.SubElement(root, "Algorithm").text = "fixedStep"
    sims = ET.SubElement(root, "Simulators")
    for s in specs:
        ET.SubElement(sims, "Simulator", name=s["instance"], source=f"{s['model_id']}.fmu")
    cons = ET.SubElement(root, "Connections")
    for src, svar, dst, dvar in conns:
        vc = ET.SubElement(cons, "VariableConnection")
        ET.SubElement(vc, "Variable", simulator=src, name=svar)
        ET.SubElement(vc, "Variable", simulator=dst, name=dvar)
    return minidom.parseString(ET.tostring(root, encoding="unicode")).toprettyxml(indent="  ")


def report_fits(scene, log):
    """State-space couplings: fitted order and error of every kernel, at build time."""
    for c in scene.couplings:
        if c.method != "state_space" or not c.data["kernels"]:
            continue
        model = c.model()
        worst = max(f.error for f in model.fits.values())
        log(f"coupling {c.name}: state-space orders "
            + ", ".join(f"{i}{j}:{f.order}" for (i, j), f in sorted(model.fits.items()))
            + f"; worst fit error {100 * worst:.2f} % (normalised RMS)")


def bem_results(scene):
    """The BEM results behind the scene's couplings (each once)."""
    return list({id(c.bem): c.bem for c in scene.couplings if c.bem is not None}.values())


def report_bem(scene, log, folder):
    """BEM couplings: the transform's choices, time and quality, and a PNG of the rebuilt
    A(ω), B(ω) per result (``<folder>/<file stem>_quality.png``)."""
    from ..bem import plot_quality
    for result in bem_results(scene):
        for line in result.report():
            log(line)
        png = plot_quality(result, Path(folder) / f"{Path(result.data.path).stem}_quality.png")
        log(f"  wrote {png.name}")


def build_scene(scene, outdir, shim=True, log=print):
    """Build all FMUs of ``scene`` into ``outdir/<scene name>/``; returns that folder.
    The folder is replaced only when the whole build succeeded."""
    outdir = Path(outdir)
    target = outdir / scene.name
    specs, dyn_of = fmu_specs(scene)
    runtime = runtime_name()
    indicators = stability_indicators(scene, exported_mass(scene, every_mode=True))
    for name, rho in indicators.items():
        c = next(c for c in scene.couplings if c.name == name)
        explicit = "explicit" in (scene.bodies[c.a].accel_mode, scene.bodies[c.b].accel_mode)
        log(f"coupling {name}: staggered-coupling indicator ρ = {rho:.3g}"
            + (" — WARNING: explicit coupling of the cross added mass will diverge (ρ ≥ 1); use export mode"
               if explicit and rho >= 1 else ""))
    report_fits(scene, log)
    outdir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix=f".{scene.name}-", dir=outdir) as tmp:
        work = Path(tmp)
        slaves = {}
        for spec in specs:
            fmu, slaves[spec["instance"]] = build_fmu(spec, work, runtime, shim)
            log(f"built {fmu.name}")
        conns = connections(specs, slaves, dyn_of)
        result = work / "fmus"
        report_bem(scene, log, result)
        manifest = {
            "scene": scene.name, "source": str(scene.path), "run": scene.run,
            "instances": {s["instance"]: {"fmu": f"{s['model_id']}.fmu", "kind": s["kind"], "body": s["body"]}
                          for s in specs},
            "dynamics": {body: list(v) for body, v in dyn_of.items()},
            "stability_indicators": indicators,
            "couplings": {c.name: {"method": c.method, "tolerance": c.tolerance, "order": c.order,
                                   "memory_length": c.memory_length, "set": c.set} for c in scene.couplings},
            "order": [s["instance"] for s in specs],
            "connections": conns,
        }
        (result / "manifest.json").write_text(json.dumps(manifest, indent=2))
        (result / "OspSystemStructure.xml").write_text(osp_system_structure(scene, specs, conns))
        write_ssp(result / f"{scene.name}.ssp", scene.name,
                  {s["instance"]: result / f"{s['model_id']}.fmu" for s in specs}, conns,
                  scene.run["stop"], scene.run["step"])
        old = outdir / f".{scene.name}.old"
        if target.exists():
            shutil.rmtree(old, ignore_errors=True)
            target.rename(old)
        result.rename(target)
        shutil.rmtree(old, ignore_errors=True)
    return target
