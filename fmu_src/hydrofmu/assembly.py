"""Scene → system: the one place that turns a validated scene into physics and FMU instances.

``assemble(scene)`` resolves everything the FMUs need from the physics, once:

- the mass each body's load FMU, self-couplings and joint nodes export (export mode);
- the dynamics groups: bodies coupled by cross added mass in export mode share one FMU;
- the joints' spring–dampers where the scene leaves them out (for the scene's step);
- the staggered-coupling stability indicator of every cross coupling;

and returns a ``System``: the FMU instances in Gauss–Seidel order, each with its typed
description (``hydrofmu.description``) and its routes (which body's motion feeds which
input prefix, which load output goes to which body's dynamics).  ``fmi.build`` packages
the instances and writes the system files; it asks the physics nothing itself.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from . import description as d
from .errors import InputError
from .physics import joint as conb
from .physics.kinematics import rotation
from .physics.loads import BodyLoads, make_effect
from .physics.lumped import LumpedBody
from .physics.rigid_body import RigidBody
from .physics.state import Motion


@dataclass
class Instance:
    """One FMU instance: ``name``, ``model_id``, ``kind`` ('load' | 'joint' | 'dynamics'),
    ``body`` it belongs to, its typed description ``fmu``, and its routes: ``motion`` maps
    an input prefix to the body whose dynamics outputs feed it; ``forces`` lists (output
    group, body, input group) routes to that body's dynamics."""
    name: str
    model_id: str
    kind: str
    body: str
    fmu: d.Description
    motion: dict[str, str]
    forces: list[tuple[str, str, str]]


@dataclass
class System:
    """A scene's FMU instances (Gauss–Seidel order: load and joint FMUs first, so that every
    FMU steps from t_k with inputs that are values at t_k), ``dynamics``: body → (dynamics
    instance, variable prefix), ``indicators``: coupling name → ρ (``stability_indicators``)."""
    instances: list[Instance]
    dynamics: dict[str, tuple[str, str]]
    indicators: dict[str, float]


TIMED = ("wave_excitation", "wave_drift")   # effects of time, not motion: the load FMU drives them itself


def body_loads(body):
    """physics.loads.BodyLoads of a scene body (its motion-dependent effects)."""
    return BodyLoads([make_effect(e.type, e.name, e.data) for e in body.effects if e.type not in TIMED],
                     body.accel_mode == "explicit")


def wave_window(scene):
    """The frequency window [rad/s] every body's excitation and drift data cover: one set of
    components for the whole scene (one wave field)."""
    omegas = [e.data["omega"] for b in scene.bodies.values() for e in b.effects if e.type in TIMED]
    return [max(w[0] for w in omegas), min(w[-1] for w in omegas)] if omegas else None


def body_waves(scene, body):
    """description.Waves of a body, or None (no [waves] in the scene, or nothing on this body
    feels them: no excitation, no effect that feels the kinematics, no named point).  Global
    named points go to the first body's load FMU."""
    from .scene.waves import feels_waves
    if scene.waves is None:
        return None
    eff = next((e for e in body.effects if e.type == "wave_excitation"), None)
    kinematics = any(feels_waves(e) for e in body.effects if e.type not in TIMED)
    first = next(iter(scene.bodies)) == body.name
    points = {n: ({"offset": list(p["offset"])} if "body" in p else {"position": list(p["position"])})
              for n, p in scene.wave_points.items() if p.get("body") == body.name or ("position" in p and first)}
    if eff is None and not kinematics and not points:
        return None
    sea = {k: v for k, v in vars(scene.waves).items() if k != "spectrum"}
    if eff is None:
        return d.Waves(None, scene.waves.spectrum, sea, wave_window(scene), kinematics=kinematics, points=points)
    dat = eff.data
    return d.Waves(eff.name, scene.waves.spectrum, sea, wave_window(scene), np.array(dat["omega"]),
                   np.array(dat["directions"]), np.array(dat["re"]), np.array(dat["im"]),
                   np.array(body.position[:2], float), kinematics, points)


def joint_waves(scene):
    """description.Waves of a CONB joint's connector FMU (its node feels the kinematics), or None."""
    if scene.waves is None:
        return None
    sea = {k: v for k, v in vars(scene.waves).items() if k != "spectrum"}
    return d.Waves(None, scene.waves.spectrum, sea, wave_window(scene), kinematics=True)


def body_drift(scene, body):
    """description.Drift of a body, or None (no [waves] in the scene, or no drift effect)."""
    eff = next((e for e in body.effects if e.type == "wave_drift"), None)
    return None if scene.waves is None or eff is None else d.Drift.of(eff, body.position)


def initial_motion(body):
    return Motion(np.array(body.position, float), np.array(body.attitude, float))


def joint_node(joint):
    return LumpedBody("node", joint.a_point, **joint.node)


def rigid_mass(body, added):
    """6×6 rigid-body mass matrix of a scene body with ``added`` mass, about its reference point."""
    return RigidBody(body.mass, body.inertia, body.cog, added_mass=added, attitude0=body.attitude).mass_matrix()


def coupling_sides(couplings):
    """d.CouplingSide of every coupling: side A (load on a from b's motion, A∞) and, across
    bodies, side B (load on b from a's motion, A∞ᵀ)."""
    return [d.CouplingSide(c, side) for c in couplings for side in (("A",) if c.a == c.b else ("A", "B"))]


def target(side):
    """The body a coupling side's load acts on."""
    return side.coupling.a if side.side == "A" else side.coupling.b


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
    for s in coupling_sides(scene.couplings):
        if s.own and export(scene.bodies[s.source].accel_mode):
            out[s.source] = out[s.source] + s.mass
    return out


def check_total_mass(scene, added):
    """Each body's mass plus the added mass on it (``added``: `exported_mass` in every mode)
    must be positive definite, or no integrator can move it (e.g. a negative A∞ diagonal
    larger than the mass): one InputError naming the body."""
    for name, body in scene.bodies.items():
        m = rigid_mass(body, added[name])
        low = np.linalg.eigvalsh(0.5 * (m + m.T)).min()
        if not low > 0:
            raise InputError(scene.path, None, f"bodies.{name}",
                             f"mass + added mass is not positive definite (smallest eigenvalue {low:.4g}): a "
                             "negative added mass from a coupling deck, effect or joint outweighs the body's "
                             "own; check the signs and units of the added mass")


def dynamics_groups(scene):
    """Bodies coupled by cross-body added mass in export mode share one dynamics FMU.
    Returns {body: (instance, variable prefix)} and [(instance, [bodies])]."""
    parent = {b: b for b in scene.bodies}

    def root(b):
        while parent[b] != b:
            b = parent[b]
        return b
    for s in coupling_sides(scene.couplings):
        if not s.own and scene.bodies[target(s)].accel_mode == "export" and np.any(s.mass):
            parent[root(target(s))] = root(s.source)
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


def stability_indicators(scene, exported):
    """Spectral radius ρ[(M_A+A_AA)⁻¹·A_AB·(M_B+A_BB)⁻¹·A_BA] of every cross coupling:
    explicit (staggered) coupling of the cross added mass diverges when ρ ≥ 1."""
    from .physics.coupling import stability_indicator
    out = {}
    for c in scene.couplings:
        if c.a == c.b:
            continue
        a, b = scene.bodies[c.a], scene.bodies[c.b]
        out[c.name] = float(stability_indicator(rigid_mass(a, np.zeros((6, 6))), exported[c.a], c.added_mass,
                                                rigid_mass(b, np.zeros((6, 6))), exported[c.b], c.added_mass.T))
    return out


def joint_spring(scene, joint, exported):
    """BallJoint parameters: points, initial relative rotation and, where the scene leaves
    them out, the default spring–damper for the scene's communication step."""
    a, b = scene.bodies[joint.a], scene.bodies.get(joint.b)
    point_a_world = np.array(a.position) + rotation(a.attitude) @ np.array(joint.a_point)
    if joint.b_point is not None:
        point_b = np.array(joint.b_point, float)
    elif b is None:
        point_b = point_a_world
    else:
        point_b = rotation(b.attitude).T @ (point_a_world - np.array(b.position))

    def effective(body, point):
        return conb.effective_mass(rigid_mass(body, exported[body.name]), rotation(body.attitude) @ point)

    m_a, i_a = effective(a, np.array(joint.a_point))
    m_b, i_b = effective(b, point_b) if b is not None else (None, None)
    # the largest step the run takes: ECCO may grow its step up to max_step
    dt = scene.run["ecco"]["max_step"] if scene.run.get("algorithm") == "ecco" else scene.run["step"]
    pick = lambda given, default: float(given) if given is not None else float(default)
    return d.JointSpring(
        point_a=np.array(joint.a_point, float), point_b=point_b,
        k_lin=pick(joint.stiffness, conb.default_stiffness(m_a, m_b, dt)),
        c_lin=pick(joint.damping, conb.default_damping(m_a, m_b, dt)),
        k_rot=pick(joint.rot_stiffness, conb.default_stiffness(i_a, i_b, dt)),
        c_rot=pick(joint.rot_damping, conb.default_damping(i_a, i_b, dt)),
        free=[c == 0 for c in joint.codes],
        r_rel0=conb.initial_relative_rotation(a.attitude, b.attitude if b is not None else None))


def _pose(body):
    """The body's state at t = 0, what its dynamics partner outputs then."""
    return d.Pose(np.array(body.position, float), np.array(body.attitude, float), np.array(body.velocity, float))


def _dynamics(scene, instance, members, exported, sides):
    bodies = [d.DynamicsBody(
        name=name, mass=body.mass, inertia=np.array(body.inertia, float), cog=np.array(body.cog, float),
        stiffness=np.array(body.stiffness, float), damping=np.array(body.damping, float),
        position=np.array(body.position, float), attitude=np.array(body.attitude, float),
        velocity=np.array(body.velocity, float),
        load_sources=[""] + [j.name for j in scene.joints.values() if name in (j.a, j.b)],
        added_mass=exported[name]) for name, body in ((n, scene.bodies[n]) for n in members)]
    cross = [d.CrossMass(target(s), s.source, s.mass) for s in sides
             if not s.own and target(s) in members and s.source in members
             and scene.bodies[target(s)].accel_mode == "export"]
    fmu = d.DynamicsFMU(f"6-DOF rigid-body dynamics of {', '.join(members)} (scene {scene.name})",
                        bodies, cross, scene.run["substep"], scene.run["load_hold"])
    return Instance(instance, f"{scene.name}_{instance}", "dynamics", members[0], fmu, {}, [])


def _loads(scene, body, sides, env):
    mine = [s if s.own else replace(s, velocity=np.array(scene.bodies[s.source].velocity, float))
            for s in sides if target(s) == body.name]
    motion = {"": body.name}
    motion.update({f"{s.source}.": s.source for s in mine if not s.own})
    waves = body_waves(scene, body)
    names = [f"{e.name} ({e.type})" for e in body.effects if e.type not in TIMED or waves is not None]
    names += [f"{s.name} (simo_coupling)" for s in mine]
    fmu = d.LoadFMU(
        description=f"hydrodynamic loads on '{body.name}' (scene {scene.name}): "
                    + (", ".join(names) or "no effects"),
        body=body.name, position=np.array(body.position, float), attitude=np.array(body.attitude, float),
        accel_mode=body.accel_mode, effects=[e for e in body.effects if e.type not in TIMED], couplings=mine,
        environment=env, velocity=np.array(body.velocity, float), waves=waves,
        drift=body_drift(scene, body) if waves is not None else None)
    return Instance(body.name, f"{scene.name}_{body.name}", "load", body.name, fmu, motion,
                    [("force", body.name, d.DynamicsBody.load_input(""))])


def _connector(scene, joint, exported, env):
    a, b = scene.bodies[joint.a], scene.bodies.get(joint.b)
    motion = {"A.": a.name}
    forces = [("A.force", a.name, d.DynamicsBody.load_input(joint.name))]
    if b is not None:
        motion["B."] = b.name
        forces.append(("B.force", b.name, d.DynamicsBody.load_input(joint.name)))
    fmu = d.ConnectorFMU(
        description=f"RIFLEX CONB ball joint '{joint.name}' between '{a.name}' and "
                    f"'{b.name if b is not None else 'earth'}' (codes IRX IRY IRZ = "
                    f"{' '.join(map(str, joint.codes))}, scene {scene.name})",
        name=joint.name, accel_mode=joint.accel_mode, node=dict(joint.node),
        joint=joint_spring(scene, joint, exported), a=_pose(a), b=_pose(b) if b is not None else None,
        environment=env, waves=joint_waves(scene))
    return Instance(joint.name, f"{scene.name}_{joint.name}", "joint", a.name, fmu, motion, forces)


def assemble(scene) -> System:
    """The FMU instances of a validated scene, their typed descriptions and routes."""
    env = d.Environment(scene.rho, scene.g, scene.current_speed, scene.current_direction, scene.current_profile)
    exported = exported_mass(scene)
    dyn_of, groups = dynamics_groups(scene)
    sides = coupling_sides(scene.couplings)
    loads = [_loads(scene, body, sides, env) for body in scene.bodies.values()]
    joints = [_connector(scene, joint, exported, env) for joint in scene.joints.values()]
    dynamics = [_dynamics(scene, instance, members, exported, sides) for instance, members in groups]
    every = exported_mass(scene, every_mode=True)
    check_total_mass(scene, every)
    indicators = stability_indicators(scene, every)
    return System(loads + joints + dynamics, dyn_of, indicators)


def fit_memories(couplings):
    """Realise every state-space coupling's kernels once and store the fits in the coupling
    (``HydroCoupling.fits``, carried by the FMU descriptions that hold it): instantiation
    then only loads them.  The build calls this, not ``assemble``: a batch assembles every
    case to tell its variants apart and must not pay the fits for it.  A coupling whose
    realisation misses its tolerance (``physics.coupling.Coupling.fallback``, warned once
    there) is stored as a convolution: the FMUs step what the build reported."""
    for c in couplings:
        if c.method == "state_space" and c.kernels and not c.fits:
            model = c.model()
            if model.method == "convolution":
                c.method = "convolution"
                continue
            c.fits = [d.Fit(i, j, f.A, f.B, f.C, f.error) for (i, j), f in sorted(model.fits.items())]


def notes(scene, system):
    """Build-time lines for the user: what was read from each deck (the groups used and
    skipped, by name and line: decks.lines.Reading), every cross coupling's stability
    indicator (with a warning where explicit coupling diverges), every state-space fit's
    order and error, and each wave drift's report (scene.effects.drift_on_sea)."""
    out = [line for reading in scene.decks for line in reading.summary()]
    out += [line for b in scene.bodies.values() for e in b.effects for line in e.data.get("report", ())]
    for name, rho in system.indicators.items():
        c = next(c for c in scene.couplings if c.name == name)
        explicit = "explicit" in (scene.bodies[c.a].accel_mode, scene.bodies[c.b].accel_mode)
        out.append(f"coupling {name}: staggered-coupling indicator ρ = {rho:.3g}"
                   + (" — WARNING: explicit coupling of the cross added mass will diverge (ρ ≥ 1); use export mode"
                      if explicit and rho >= 1 else ""))
    for c in scene.couplings:
        if c.method != "state_space" or not c.kernels:
            continue
        model = c.model()
        worst = max(f.error for f in model.fits.values())
        out.append(f"coupling {c.name}: state-space orders "
                   + ", ".join(f"{i}{j}:{f.order}" for (i, j), f in sorted(model.fits.items()))
                   + f"; worst fit error {100 * worst:.2f} % (normalised RMS)")
    return out
