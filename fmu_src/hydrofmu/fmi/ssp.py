"""SSP 1.0 export of a built scene: ``<scene>.ssp``, a zip of ``SystemStructure.ssd`` and the
scene's FMUs under ``resources/``.

The SSD holds one component per FMU instance with the connectors the connections use
(inputs and outputs, with their units) and every parameter; each parameter and input is
bound to its start value (the value the build gave it; an input's is its source's value at
t = 0, fmi.starts); the connections; the units (as SI base-unit exponents); and the default
experiment (start 0, the scene's stop time) with the communication step in libcosim's
annotation (``osp:FixedStepAlgorithm``), since SSP 1.0 has no field for it.
"""
from __future__ import annotations

import math
import re
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from fmpy import read_model_description

SSD = "http://ssp-standard.org/SSP1/SystemStructureDescription"
SSC = "http://ssp-standard.org/SSP1/SystemStructureCommon"
SSV = "http://ssp-standard.org/SSP1/SystemStructureParameterValues"
OSP = "http://opensimulationplatform.com/SSP/OSPAnnotations"
for _prefix, _uri in (("ssd", SSD), ("ssc", SSC), ("ssv", SSV), ("osp", OSP)):
    ET.register_namespace(_prefix, _uri)

# unit symbol -> (factor to SI, {SI base unit: exponent}); products with '.', one '/', powers as digits
BASE = {"kg": (1.0, {"kg": 1}), "m": (1.0, {"m": 1}), "s": (1.0, {"s": 1}), "rad": (1.0, {"rad": 1}),
        "N": (1.0, {"kg": 1, "m": 1, "s": -2}), "deg": (math.pi / 180, {"rad": 1})}


def base_unit(unit: str) -> dict:
    """SSP BaseUnit attributes of a unit such as 'N.m', 'kg.m2', 'm/s2' or 'deg'."""
    factor, exps = 1.0, {}
    num, _, den = unit.partition("/")
    for part, sign in ((num, 1), (den, -1)):
        for token in filter(None, part.split(".")):
            m = re.fullmatch(r"([A-Za-z]+)(\d*)", token)
            if not m or m.group(1) not in BASE:
                raise ValueError(f"unit {unit!r}: no SI definition for {token!r}")
            f, e = BASE[m.group(1)]
            power = sign * int(m.group(2) or 1)
            factor *= f ** power
            for k, v in e.items():
                exps[k] = exps.get(k, 0) + v * power
    attrs = {k: str(v) for k, v in exps.items() if v}
    if factor != 1.0:
        attrs["factor"] = repr(factor)
    return attrs


def q(ns, tag):
    return f"{{{ns}}}{tag}"


def system_structure(name: str, instances: dict, connections: list, stop: float, step: float) -> bytes:
    """SystemStructure.ssd text.  ``instances``: {instance: FMU path}; ``connections``:
    [source instance, output, target instance, input]."""
    root = ET.Element(q(SSD, "SystemStructureDescription"), {"version": "1.0", "name": name})
    system = ET.SubElement(root, q(SSD, "System"), {"name": name})
    elements = ET.SubElement(system, q(SSD, "Elements"))
    used = {(i, v) for src, sv, dst, dv in connections for i, v in ((src, sv), (dst, dv))}
    units = set()
    for instance, fmu in instances.items():
        md = read_model_description(str(fmu), validate=False)
        comp = ET.SubElement(elements, q(SSD, "Component"), {
            "name": instance, "type": "application/x-fmu-sharedlibrary", "source": f"resources/{Path(fmu).name}"})
        connectors = ET.SubElement(comp, q(SSD, "Connectors"))
        params = []
        for v in md.modelVariables:
            if (instance, v.name) not in used and v.causality != "parameter":
                continue
            c = ET.SubElement(connectors, q(SSD, "Connector"), {"name": v.name, "kind": v.causality})
            ET.SubElement(c, q(SSC, "Real"), {"unit": v.unit} if v.unit else {})
            units.add(v.unit)
            if v.causality in ("parameter", "input") and v.start is not None:
                params.append(v)
        if params:
            values = ET.SubElement(ET.SubElement(ET.SubElement(comp, q(SSD, "ParameterBindings")),
                                                 q(SSD, "ParameterBinding")), q(SSD, "ParameterValues"))
            pset = ET.SubElement(values, q(SSV, "ParameterSet"), {"version": "1.0", "name": instance})
            plist = ET.SubElement(pset, q(SSV, "Parameters"))
            for v in params:
                p = ET.SubElement(plist, q(SSV, "Parameter"), {"name": v.name})
                ET.SubElement(p, q(SSV, "Real"), {"value": repr(float(v.start))})
    conns = ET.SubElement(system, q(SSD, "Connections"))
    for src, svar, dst, dvar in connections:
        ET.SubElement(conns, q(SSD, "Connection"), {"startElement": src, "startConnector": svar,
                                                      "endElement": dst, "endConnector": dvar})
    defs = ET.SubElement(root, q(SSD, "Units"))
    for unit in sorted(u for u in units if u):
        ET.SubElement(ET.SubElement(defs, q(SSC, "Unit"), {"name": unit}), q(SSC, "BaseUnit"), base_unit(unit))
    experiment = ET.SubElement(root, q(SSD, "DefaultExperiment"), {"startTime": "0.0", "stopTime": repr(float(stop))})
    note = ET.SubElement(ET.SubElement(experiment, q(SSD, "Annotations")), q(SSC, "Annotation"),
                         {"type": "com.opensimulationplatform"})
    ET.SubElement(ET.SubElement(note, q(OSP, "Algorithm")), q(OSP, "FixedStepAlgorithm"),
                  {"baseStepSize": repr(float(step))})
    ET.indent(root)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def write_ssp(path, name: str, instances: dict, connections: list, stop: float, step: float) -> Path:
    """Write ``path`` (.ssp): SystemStructure.ssd plus every FMU of ``instances`` under resources/."""
    path = Path(path)
    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
        z.writestr("SystemStructure.ssd", system_structure(name, instances, connections, stop, step))
        for fmu in dict.fromkeys(Path(f) for f in instances.values()):
            z.write(fmu, f"resources/{fmu.name}", compress_type=zipfile.ZIP_STORED)
    return path
