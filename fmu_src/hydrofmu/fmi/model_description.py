"""Complete pythonfmu 0.7's modelDescription.xml so that it validates: units declared in
UnitDefinitions and on every Real, and a ModelStructure with output dependencies and
InitialUnknowns (pythonfmu writes only a bare Outputs list)."""
import xml.etree.ElementTree as ET
from xml.dom import minidom

# unit -> (SI base-unit exponents, factor): FMI 2.0 BaseUnit attributes
UNITS = {
    "m": ({"m": 1}, 1.0),
    "rad": ({"rad": 1}, 1.0),
    "deg": ({"rad": 1}, 0.017453292519943295),
    "s": ({"s": 1}, 1.0),
    "m/s": ({"m": 1, "s": -1}, 1.0),
    "rad/s": ({"rad": 1, "s": -1}, 1.0),
    "m/s2": ({"m": 1, "s": -2}, 1.0),
    "rad/s2": ({"rad": 1, "s": -2}, 1.0),
    "N": ({"kg": 1, "m": 1, "s": -2}, 1.0),
    "Pa": ({"kg": 1, "m": -1, "s": -2}, 1.0),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, 1.0),
    "N/m": ({"kg": 1, "s": -2}, 1.0),
    "N.s/m": ({"kg": 1, "s": -1}, 1.0),
    "kg": ({"kg": 1}, 1.0),
    "kg.m": ({"kg": 1, "m": 1}, 1.0),
    "kg.m2": ({"kg": 1, "m": 2}, 1.0),
    "kg/m3": ({"kg": 1, "m": -3}, 1.0),
}

# FMI 2.0 order of the children of fmiModelDescription
ORDER = ["ModelExchange", "CoSimulation", "UnitDefinitions", "TypeDefinitions", "LogCategories",
         "DefaultExperiment", "VendorAnnotations", "ModelVariables", "ModelStructure"]


def base_unit(unit):
    """BaseUnit attributes of a unit of UNITS (SI exponents, factor when not 1)."""
    exps, factor = UNITS[unit]
    base = {k: str(v) for k, v in exps.items()}
    if factor != 1.0:
        base["factor"] = repr(factor)
    return base


def complete(xml_text, units, dependencies, starts=None, description=None):
    """Return modelDescription.xml text with units, exact start values and a full ModelStructure.

    ``units``: variable name -> unit (a key of UNITS).  ``dependencies``: output name ->
    names of the inputs it depends on directly (feedthrough); an output absent from it
    depends on no input (it is a state).  ``starts``: variable name -> start value, written
    in full (repr: the float itself, where pythonfmu writes 16 digits) wherever the
    variable has a start.
    """
    root = ET.fromstring(xml_text)
    if description:
        root.set("description", description)
    variables = root.find("ModelVariables").findall("ScalarVariable")
    index = {sv.get("name"): i + 1 for i, sv in enumerate(variables)}

    used = set()
    for sv in variables:
        unit = units.get(sv.get("name"))
        real = sv.find("Real")
        if real is not None and real.get("start") is not None and starts and sv.get("name") in starts:
            real.set("start", repr(float(starts[sv.get("name")])))
        if unit is None or real is None:
            continue
        if unit not in UNITS:
            raise ValueError(f"variable {sv.get('name')}: unit {unit!r} has no definition")
        real.set("unit", unit)
        used.add(unit)

    for old in root.findall("UnitDefinitions"):
        root.remove(old)
    if used:
        defs = ET.Element("UnitDefinitions")
        for unit in sorted(used):
            ET.SubElement(ET.SubElement(defs, "Unit", name=unit), "BaseUnit", base_unit(unit))
        root.append(defs)

    for old in root.findall("ModelStructure"):
        root.remove(old)
    structure = ET.SubElement(root, "ModelStructure")

    def unknown(parent, sv):
        deps = sorted(index[n] for n in dependencies.get(sv.get("name"), []))
        ET.SubElement(parent, "Unknown", index=str(index[sv.get("name")]),
                      dependencies=" ".join(map(str, deps)))

    outputs = [sv for sv in variables if sv.get("causality") == "output"]
    if outputs:
        node = ET.SubElement(structure, "Outputs")
        for sv in outputs:
            unknown(node, sv)
    # outputs (initial calculated by default) and calculated parameters are initial unknowns
    initial = [sv for sv in variables
               if (sv.get("causality") == "output" and sv.get("initial") in (None, "calculated", "approx"))
               or sv.get("causality") == "calculatedParameter"]
    if initial:
        node = ET.SubElement(structure, "InitialUnknowns")
        for sv in initial:
            unknown(node, sv)

    children = sorted(list(root), key=lambda el: ORDER.index(el.tag) if el.tag in ORDER else len(ORDER))
    for el in list(root):
        root.remove(el)
    root.extend(children)
    text = ET.tostring(root, encoding="unicode")
    return minidom.parseString(text).toprettyxml(indent="  ", encoding="UTF-8")
