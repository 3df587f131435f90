"""Open Simulation Platform files of a built scene: the OSP-IS model description of each FMU
(``<modelName>_OspModelDescription.xml``, OSP Interface Specification 1.0.1, beside the FMU
where libcosim looks for it) and ``OspSystemStructure.xml`` (libcosim's format 0.1).

A load FMU and its dynamics partner exchange mechanical power: the load FMU's force out and
the body's velocity in, the dynamics' load in and velocity out.  Each such body side is a
pair of ports in global axes, ``LinearMechanicalPort`` (force[1..3] N, velocity[1..3] m/s)
and ``AngularMechanicalPort`` (force[4..6] N·m about the reference point, velocity[4..6]
rad/s), the two sides of opposite causality.  ``bonds(system)`` lists them from the
assembly's routes, the same routes the build's connections come from; the ports' variables,
units and causalities are read from the slaves that write modelDescription.xml.

In OspSystemStructure.xml every bond is a ``VariableGroupConnection`` of two ports; every
other flow (position, attitude, acceleration, a coupled body's velocity) is a plain
``VariableConnection``: signals, not halves of a power bond.  libcosim expands a port
connection into the same scalar connections as before, so a fixed-step run is unchanged.
The port connections carry no ``powerBond`` attribute: the libcosim of libcosimpy 0.0.6
accepts it only on a pair of scalar ``VariableConnection`` elements and only one bond per
file (a second bond name fails the load), and on a ``VariableGroupConnection`` it fails
the load.  ECCO gets the bonds through libcosim's API instead: ``manifest.json``'s
``bonds`` lists each scalar bond (one per axis) as the two (instance, output, input) ends
``CosimAlgorithm.add_power_bond`` takes.
"""
from __future__ import annotations

from dataclasses import dataclass
from xml.dom import minidom
from xml.etree import ElementTree as ET

from .model_description import base_unit

NS = "https://open-simulation-platform.com/OspModelDescription/1.0.1"
VERSION = "1.0"   # the schema's fixed version attribute of OSP-IS 1.0.x
SYSTEM_NS = "http://opensimulationplatform.com/MSMI/OSPSystemStructure"
AXES = ("x", "y", "z")
# port tag, effort tag, flow tag, name suffixes, 1-based components of the 6-vectors
PORTS = (("LinearMechanicalPort", "Force", "LinearVelocity", "linear", ("force", "velocity"), (1, 2, 3)),
         ("AngularMechanicalPort", "Torque", "AngularVelocity", "angular", ("torque", "velocity"), (4, 5, 6)))
# plain (non-bond) vector groups: FMU variable group, components, OSP-IS tag, group name suffix
SIGNALS = (("position", (1, 2, 3), "LinearDisplacement", ""),
           ("attitude", (1, 2, 3), "AngularDisplacement", ""),
           ("velocity", (1, 2, 3), "LinearVelocity", ".linear"),
           ("velocity", (4, 5, 6), "AngularVelocity", ".angular"),
           ("acceleration", (1, 2, 3), "LinearAcceleration", ".linear"),
           ("acceleration", (4, 5, 6), "AngularAcceleration", ".angular"))
# OSP-IS 1.0.1's VariableGroups is an xs:sequence: the groups used here, in its order
ORDER = ("Force", "Torque", "LinearVelocity", "AngularVelocity", "LinearDisplacement", "AngularDisplacement",
         "LinearAcceleration", "AngularAcceleration", "LinearMechanicalPort", "AngularMechanicalPort")


@dataclass(frozen=True)
class Side:
    """One body side of an FMU instance: its load 6-vector ``force`` and the body's
    ``velocity`` 6-vector (FMU variable group names, global axes, loads about the body's
    reference point); ``force_out``: the load is an output (load or joint FMU) and the
    velocity an input, else the reverse (the dynamics partner)."""
    instance: str
    body: str
    force: str
    velocity: str
    force_out: bool

    def port(self, kind: str) -> str:
        """Name of the 'linear' or 'angular' port in the instance's OSP model description."""
        return f"{self.force}.{kind}"


@dataclass(frozen=True)
class Bond:
    """A power bond: the load side (force out) of a load or joint FMU and the side of the
    body's dynamics partner that takes that load (force in, velocity out)."""
    load: Side
    dynamics: Side

    @property
    def body(self) -> str:
        return self.load.body


def bonds(system) -> list[Bond]:
    """The power bonds of an ``assembly.System``, from each instance's force routes: the
    output group ``<p>force`` of an instance goes to the body that also feeds its motion
    prefix ``<p>``, whose velocity therefore closes the bond."""
    out = []
    for inst in system.instances:
        for group, body, inp in inst.forces:
            prefix = group[:-len("force")]
            if not group.endswith("force") or inst.motion.get(prefix) != body:
                raise ValueError(f"{inst.name}: load {group} on {body} has no velocity input of {body}")
            dyn, dp = system.dynamics[body]
            out.append(Bond(Side(inst.name, body, group, f"{prefix}velocity", True),
                            Side(dyn, body, f"{dp}{inp}", f"{dp}velocity", False)))
    return out


def scalar_bonds(bonds_: list[Bond]) -> list[dict]:
    """One bond per axis, as manifest.json holds them: ``load`` = [instance, force output,
    velocity input], ``dynamics`` = [instance, velocity output, force input]."""
    return [{"name": f"{b.load.instance}.{b.load.force}[{i}]", "body": b.body,
             "load": [b.load.instance, f"{b.load.force}[{i}]", f"{b.load.velocity}[{i}]"],
             "dynamics": [b.dynamics.instance, f"{b.dynamics.velocity}[{i}]", f"{b.dynamics.force}[{i}]"]}
            for b in bonds_ for i in range(1, 7)]


def bond_connections(bonds_: list[Bond]) -> set:
    """The scalar connections (source, output, target, input) the bonds stand for."""
    out = set()
    for b in scalar_bonds(bonds_):
        (li, force, vel), (di, dvel, dforce) = b["load"], b["dynamics"]
        out |= {(li, force, di, dforce), (di, dvel, li, vel)}
    return out


def _group(parent, tag, name, refs, slave):
    """A typed group of ``refs``, each with its unit (the slave's) and the global axis of
    its component (none for an attitude: roll, pitch, yaw are angles of a sequence)."""
    el = ET.SubElement(parent, tag, name=name)
    for axis, ref in zip(AXES, refs):
        attrs = {"ref": ref, "unit": slave.units[ref]}
        if tag != "AngularDisplacement":
            attrs["axis"] = axis
        ET.SubElement(el, "Variable", attrs)


def model_description(instance: str, slave, sides: list[Side], motion_prefixes) -> bytes:
    """``<modelName>_OspModelDescription.xml`` of one FMU instance: its ports (``sides``)
    and, as plain typed groups, every other motion vector it has under ``motion_prefixes``
    (position, attitude, velocity not in a port, acceleration)."""
    names = {v.name for v in slave.vars.values()}
    causality = {v.name: v.causality.name for v in slave.vars.values()}
    groups = []   # (tag, name, refs or [(tag, name, refs)] for a port)
    in_ports = set()
    for side in sides:
        want = ("output", "input") if side.force_out else ("input", "output")
        for tag, effort, flow, kind, (ename, fname), comps in PORTS:
            force = [f"{side.force}[{i}]" for i in comps]
            vel = [f"{side.velocity}[{i}]" for i in comps]
            got = ({causality[r] for r in force}, {causality[r] for r in vel})
            if got != ({want[0]}, {want[1]}):
                raise ValueError(f"{instance}: port {side.port(kind)} has causalities {got}, expected {want}")
            in_ports.update(vel)
            name = side.port(kind)
            groups.append((tag, name, [(effort, f"{name}.{ename}", force), (flow, f"{name}.{fname}", vel)]))
    for prefix in motion_prefixes:
        for var, comps, tag, suffix in SIGNALS:
            refs = [f"{prefix}{var}[{i}]" for i in comps]
            if all(r in names for r in refs) and not set(refs) & in_ports:
                groups.append((tag, f"{prefix}{var}{suffix}", refs))
    leaves = [leaf for g in groups for leaf in (g[2] if g[0].endswith("Port") else [g])]
    root = ET.Element("OspModelDescription", xmlns=NS, version=VERSION)
    defs = ET.SubElement(root, "UnitDefinitions")
    for unit in sorted({slave.units[r] for _, _, refs in leaves for r in refs}):
        ET.SubElement(ET.SubElement(defs, "Unit", name=unit), "BaseUnit", base_unit(unit))
    vg = ET.SubElement(root, "VariableGroups")
    for tag, name, children in sorted(groups, key=lambda g: ORDER.index(g[0])):   # stable within a tag
        if tag.endswith("Port"):
            port = ET.SubElement(vg, tag, name=name)
            for leaf in children:
                _group(port, *leaf, slave)
        else:
            _group(vg, tag, name, children, slave)
    return _pretty(root)


def model_descriptions(system, slaves, bonds_: list[Bond]) -> dict:
    """{model id: OSP model description bytes} for every instance of the system."""
    out = {}
    for inst in system.instances:
        sides = [s for b in bonds_ for s in (b.load, b.dynamics) if s.instance == inst.name]
        prefixes = list(inst.motion) + [dp for dyn, dp in system.dynamics.values() if dyn == inst.name]
        out[inst.model_id] = model_description(inst.name, slaves[inst.name], sides, dict.fromkeys(prefixes))
    return out


def system_structure(system, conns: list, bonds_: list[Bond], step: float, starts: dict | None = None) -> str:
    """OspSystemStructure.xml text: the simulators (each with ``starts[instance]``, {input:
    value}, as its InitialValues: the FMUs' own start values, fmi.starts), every bond as a
    connection of two ports (linear and angular) and every other connection of ``conns`` as
    a plain one.  A bond stands for scalar connections that must all be in ``conns``: the
    system is the same."""
    covered = bond_connections(bonds_)
    missing = covered - {tuple(c) for c in conns}
    if missing:
        raise ValueError(f"power bonds name connections the system does not have: {sorted(missing)[:3]}")
    root = ET.Element("OspSystemStructure", xmlns=SYSTEM_NS, version="0.1")
    ET.SubElement(root, "StartTime").text = "0.0"
    ET.SubElement(root, "BaseStepSize").text = repr(step)
    ET.SubElement(root, "Algorithm").text = "fixedStep"
    sims = ET.SubElement(root, "Simulators")
    for inst in system.instances:
        sim = ET.SubElement(sims, "Simulator", name=inst.name, source=f"{inst.model_id}.fmu")
        values = (starts or {}).get(inst.name)
        if values:
            initial = ET.SubElement(sim, "InitialValues")
            for var, value in values.items():
                ET.SubElement(ET.SubElement(initial, "InitialValue", variable=var), "Real", value=repr(float(value)))
    cons = ET.SubElement(root, "Connections")
    for src, svar, dst, dvar in conns:
        if (src, svar, dst, dvar) not in covered:
            vc = ET.SubElement(cons, "VariableConnection")
            ET.SubElement(vc, "Variable", simulator=src, name=svar)
            ET.SubElement(vc, "Variable", simulator=dst, name=dvar)
    for b in bonds_:
        for kind in ("linear", "angular"):
            gc = ET.SubElement(cons, "VariableGroupConnection")
            ET.SubElement(gc, "VariableGroup", simulator=b.load.instance, name=b.load.port(kind))
            ET.SubElement(gc, "VariableGroup", simulator=b.dynamics.instance, name=b.dynamics.port(kind))
    return _pretty(root).decode()


def _pretty(root) -> bytes:
    return minidom.parseString(ET.tostring(root, encoding="unicode")).toprettyxml(indent="  ", encoding="utf-8")
