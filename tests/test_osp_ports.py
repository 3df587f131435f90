"""OSP-IS port descriptions and the power-bonded OspSystemStructure.xml of every scene.

The names and rules checked below are those of the OSP Interface Specification 1.0.1 XML
schema (``OspModelDescription-1.0.1.xsd`` of the Open Simulation Platform, as published
with its osp-validator; fmi2Unit's BaseUnit plus OSP's ``percent``), written out here as
the subset this project uses; libcosim's behaviour is checked by running it (libcosimpy
in a subprocess, whose console log is read, and the native C host of test_native).
"""
import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from conftest import build
from test_native import SCENES, clean_env, hosts, scenes  # noqa: F401 (fixtures)

pytest.importorskip("libcosimpy")

# beside models/: a buoy with explicit acceleration loads held to the earth by a joint
# (a connector with side A only) and tied to a ship by a second joint (soft springs given:
# the default ones, sized for Gauss–Seidel, let this light buoy's pitch diverge under Jacobi)
EXTRA = """
    [scene]
    name = "earth_explicit"
    [run]
    step = 0.1
    substep = 0.05
    [bodies.buoy]
    mass = 2.0e5
    inertia = [1e7, 1e7, 2e7]
    acceleration_loads = "explicit"
    stiffness = [0.0, 0.0, 3.0e5, 1e8, 1e8, 0.0]
    damping = [1e4, 1e4, 1e4, 1e6, 1e6, 1e6]
    [[bodies.buoy.effects]]
    type = "riflex_body"
    name = "sphere"
    offset = [0.0, 0.0, -2.0]
    am = 2.0e3
    ae = 10.0
    icoo = "GLOBAL"
    cd = [1e3, 1e3, 2e3]
    [bodies.ship]
    position = [30.0, 0.0, 0.0]
    mass = 1.0e6
    inertia = [1e8, 2e8, 3e8]
    stiffness = [1e5, 1e5, 1e7, 1e9, 1e9, 1e8]
    [[bodies.ship.effects]]
    type = "riflex_body"
    name = "weight"
    offset = [0.0, 0.0, 0.0]
    am = 1.0e3
    ae = 0.0
    icoo = "GLOBAL"
    cd = [0.0, 0.0, 0.0]
    [joints.anchor]
    type = "riflex_conb"
    a = "buoy"
    a_point = [0.0, 0.0, -5.0]
    b = "earth"
    codes = [1, 1, 1]
    stiffness = 1.0e4
    damping = 1.0e4
    rot_stiffness = 1.0e5
    rot_damping = 1.0e5
    acceleration_loads = "explicit"
    am = 1.0e3
    ae = 0.5
    icoo = "GLOBAL"
    cd = [10.0, 10.0, 10.0]
    [joints.hawser]
    type = "riflex_conb"
    a = "ship"
    a_point = [-10.0, 0.0, 0.0]
    b = "buoy"
    codes = [0, 0, 0]
    stiffness = 1.0e4
    damping = 1.0e4
    """
ALL = SCENES + ["earth_explicit"]
# counted by hand from the scene files: bonds (load or joint side, dynamics side) per scene
BONDS = {"moored_barge": 1, "side_by_side": 2, "joined_barges": 4, "earth_explicit": 5, "buoy_in_waves": 1,
         "moored_cylinder": 1}


@pytest.fixture(scope="module")
def built(scenes, tmp_path_factory):  # noqa: F811
    """Every scene of models/ and EXTRA, built: {name: folder}."""
    return {**scenes, "earth_explicit": build(tmp_path_factory.mktemp("extra"), EXTRA)}

# -- OSP-IS 1.0.1, the schema's names -----------------------------------------------------
NS = "https://open-simulation-platform.com/OspModelDescription/1.0.1"
VERSION = "1.0"                                       # OspModelDescriptionType/@version, fixed
ROOT_CHILDREN = ["UnitDefinitions", "VariableGroups"]  # xs:sequence, both optional
# VariableGroupsType is an xs:sequence: group elements must appear in this order (its first 19)
GROUP_SEQUENCE = ["Generic", "Force", "Torque", "Voltage", "Pressure", "LinearVelocity", "AngularVelocity",
                  "Current", "VolumeFlowRate", "LinearDisplacement", "AngularDisplacement", "Charge", "Volume",
                  "LinearAcceleration", "AngularAcceleration", "LinearMechanicalPort", "AngularMechanicalPort",
                  "ElectromagneticPort", "HydraulicPort"]
LEAF_TYPES = set(GROUP_SEQUENCE[1:15])                # 1 to 3 Variable elements each
PORTS = {"LinearMechanicalPort": ["Force", "LinearVelocity"], "AngularMechanicalPort": ["Torque", "AngularVelocity"]}
VARIABLE_ATTRS = {"ref", "unit", "axis"}              # ref required; axis one of x, y, z
BASE_UNIT_ATTRS = {"kg", "m", "s", "A", "K", "mol", "cd", "rad", "percent", "factor", "offset"}
# what the ports carry in this project: global-axes components with SI units
PORT_UNITS = {"Force": "N", "Torque": "N.m", "LinearVelocity": "m/s", "AngularVelocity": "rad/s"}


def q(tag):
    return f"{{{NS}}}{tag}"


def fmu_variables(fmu):
    """{name: (causality, unit)} of an FMU's modelDescription.xml, its modelName and units."""
    from fmpy import read_model_description
    md = read_model_description(str(fmu))
    units = {u.name: {k: getattr(u.baseUnit, k) for k in ("kg", "m", "s", "rad", "factor")} for u in md.unitDefinitions}
    return md.modelName, {v.name: (v.causality, v.unit) for v in md.modelVariables}, units


def check_osp_is(path, variables, fmu_units):
    """Check one OSP model description against the OSP-IS 1.0.1 names and rules; returns
    {port name: (tag, [(child tag, causality, [refs])])} and {group name: tag} of leaves."""
    root = ET.parse(path).getroot()
    assert root.tag == q("OspModelDescription") and root.attrib == {"version": VERSION}, path
    tags = [c.tag for c in root]
    assert tags == [q(t) for t in ROOT_CHILDREN if q(t) in tags], tags
    units = {}
    for unit in root.find(q("UnitDefinitions")):
        assert unit.tag == q("Unit") and set(unit.attrib) == {"name"}
        (base,) = list(unit)
        assert base.tag == q("BaseUnit") and set(base.attrib) <= BASE_UNIT_ATTRS
        units[unit.get("name")] = base.attrib
    names, ports, leaves = [], {}, {}

    def leaf(el):
        vs = list(el)
        assert 1 <= len(vs) <= 3 and all(v.tag == q("Variable") for v in vs), el.get("name")
        out = []
        for v in vs:
            assert set(v.attrib) <= VARIABLE_ATTRS and "ref" in v.attrib and v.get("axis", "x") in "xyz"
            ref, unit = v.get("ref"), v.get("unit")
            assert ref in variables, f"{path.name}: {ref} is not a variable of the FMU"
            assert unit == variables[ref][1], (ref, unit, variables[ref][1])   # the FMU's unit
            # defined here with the SI exponents the FMU gives it
            assert {k: int(x) for k, x in units[unit].items() if k != "factor"} == {
                k: x for k, x in fmu_units[unit].items() if k != "factor" and x}
            out.append(ref)
        causes = {variables[r][0] for r in out}
        assert len(causes) == 1, (el.get("name"), causes)   # one causality per group
        names.append(el.get("name"))
        return causes.pop(), out

    order = [c.tag for c in root.find(q("VariableGroups"))]
    positions = [GROUP_SEQUENCE.index(t.split("}")[1]) for t in order]
    assert positions == sorted(positions), f"{path.name}: groups out of the schema's sequence"
    for el in root.find(q("VariableGroups")):
        tag = el.tag.split("}")[1]
        assert set(el.attrib) == {"name"}
        if tag in PORTS:
            kids = list(el)
            assert [k.tag for k in kids] == [q(t) for t in PORTS[tag]], el.get("name")
            names.append(el.get("name"))
            ports[el.get("name")] = (tag, [(t, *leaf(k)) for t, k in zip(PORTS[tag], kids)])
        else:
            assert tag in LEAF_TYPES, tag
            leaves[el.get("name")] = tag
            leaf(el)
    assert len(names) == len(set(names)), f"{path.name}: group names are not unique"
    return ports, leaves


def test_every_fmu_has_an_osp_is_model_description(built):
    """Beside each FMU, ``<modelName>_OspModelDescription.xml`` (where libcosim looks): it
    parses as OSP-IS 1.0.1; every port pairs a Force with a LinearVelocity (Torque with
    AngularVelocity) of opposite causality, the three global components of each with units
    N, m/s (N·m, rad/s); every load and joint FMU has one port pair per body side, force out."""
    seen = 0
    for name, folder in built.items():
        manifest = json.loads((folder / "manifest.json").read_text())
        assert sorted(p.name for p in folder.glob("*_OspModelDescription.xml")) == sorted(
            f"{fmu_variables(folder / i['fmu'])[0]}_OspModelDescription.xml" for i in manifest["instances"].values())
        for inst, info in manifest["instances"].items():
            model, variables, units = fmu_variables(folder / info["fmu"])
            ports, leaves = check_osp_is(folder / f"{model}_OspModelDescription.xml", variables, units)
            for pname, (tag, ((effort, ecause, erefs), (flow, fcause, frefs))) in ports.items():
                assert {ecause, fcause} == {"input", "output"}, pname   # opposite causality
                assert [variables[r][1] for r in erefs] == [PORT_UNITS[effort]] * 3
                assert [variables[r][1] for r in frefs] == [PORT_UNITS[flow]] * 3
                # the components of one 6-vector each: force[1..3] with velocity[1..3] …
                first = 1 if tag == "LinearMechanicalPort" else 4
                assert [r.rsplit("[", 1)[1] for r in erefs + frefs] == [f"{i}]" for i in range(first, first + 3)] * 2
                assert ecause == ("input" if info["kind"] == "dynamics" else "output")
                seen += 1
            # every load 6-vector the FMU sends to a dynamics FMU is in a port pair
            fed = {c[1].rsplit("[", 1)[0] for c in manifest["connections"]
                   if c[0] == inst and manifest["instances"][c[2]]["kind"] == "dynamics"}
            assert {p.rsplit(".", 1)[0] for p in ports} >= fed and (fed or info["kind"] == "dynamics")
            # and every body side's position is a plain displacement group
            sides = ([f"{dp}" for dyn, dp in manifest["dynamics"].values() if dyn == inst] if info["kind"] == "dynamics"
                     else {"load": [""], "joint": ["A."]}[info["kind"]])
            assert all(leaves[f"{p}position"] == "LinearDisplacement" for p in sides)
    assert seen == 4 * sum(BONDS.values())   # two ports on each end of each bond


def parse_structure(path):
    ns = {"o": "http://opensimulationplatform.com/MSMI/OSPSystemStructure"}
    root = ET.parse(path).getroot()
    plain = [tuple(x for v in c.findall("o:Variable", ns) for x in (v.get("simulator"), v.get("name")))
             for c in root.iter(f"{{{ns['o']}}}VariableConnection")]
    groups = [tuple(x for v in c.findall("o:VariableGroup", ns) for x in (v.get("simulator"), v.get("name")))
              for c in root.iter(f"{{{ns['o']}}}VariableGroupConnection")]
    return root, plain, groups


def port_variables(folder, manifest, instance):
    model = Path(manifest["instances"][instance]["fmu"]).stem
    root = ET.parse(folder / f"{model}_OspModelDescription.xml").getroot()
    return {p.get("name"): (p.tag.split("}")[1], [[v.get("ref") for v in k] for k in p])
            for p in root.find(q("VariableGroups")) if p.tag.split("}")[1] in PORTS}


def test_bonds_link_an_out_force_port_to_an_in_force_port_of_the_same_body(built):
    """Every VariableGroupConnection of OspSystemStructure.xml is a power bond: two ports of
    one type, force out (a load or joint FMU) and force in (a dynamics FMU), on one body (the
    dynamics body whose position feeds the load side's motion prefix); the plain and the
    expanded port connections are exactly the build's connections, each once."""
    from fmpy import read_model_description
    for name, folder in built.items():
        manifest = json.loads((folder / "manifest.json").read_text())
        _, plain, groups = parse_structure(folder / "OspSystemStructure.xml")
        assert len(groups) == 2 * BONDS[name], name
        expanded = []
        causal = {i: {v.name: v.causality for v in read_model_description(str(folder / x["fmu"])).modelVariables}
                  for i, x in manifest["instances"].items()}
        feeds = {(d, dv): (s, sv) for s, sv, d, dv in manifest["connections"]}
        for a_inst, a_port, b_inst, b_port in groups:
            ta, (fa, va) = port_variables(folder, manifest, a_inst)[a_port]
            tb, (fb, vb) = port_variables(folder, manifest, b_inst)[b_port]
            assert ta == tb
            assert {causal[a_inst][fa[0]], causal[b_inst][fb[0]]} == {"output", "input"}
            (li, lf, lv), (di, df, dv) = sorted([(a_inst, fa, va), (b_inst, fb, vb)],
                                                key=lambda s: causal[s[0]][s[1][0]] != "output")
            assert manifest["instances"][li]["kind"] in ("load", "joint")
            assert manifest["instances"][di]["kind"] == "dynamics"
            # the body: whose dynamics output feeds the load side's position input of the same prefix
            prefix = lv[0][:-len("velocity[1]")]
            src, svar = feeds[li, f"{prefix}position[1]"]
            body = next(b for b, (dyn, dp) in manifest["dynamics"].items() if dyn == src and svar == f"{dp}position[1]")
            dyn, dp = manifest["dynamics"][body]
            assert di == dyn and all(v.startswith(f"{dp}velocity[") for v in dv), (name, a_port, b_port)
            expanded += [[li, f, di, g] for f, g in zip(lf, df)] + [[di, g, li, f] for f, g in zip(lv, dv)]
        together = [list(c) for c in plain] + expanded
        assert sorted(together) == sorted(manifest["connections"]) and len(together) == len(set(map(tuple, together)))
        # the manifest's scalar bonds are these connections, one per axis
        bonds = {(b["load"][0], b["load"][1], b["dynamics"][0], b["dynamics"][2]) for b in manifest["bonds"]}
        assert bonds == {tuple(c) for c in expanded if causal[c[0]][c[1]] == "output" and "force" in c[1]
                         and manifest["instances"][c[0]]["kind"] != "dynamics"}
        assert len(manifest["bonds"]) == 3 * len(groups)


def old_structure(folder, manifest, path):
    """The same system as plain VariableConnections only (the file before ports)."""
    root, _, _ = parse_structure(folder / "OspSystemStructure.xml")
    ns = root.tag.split("}")[0][1:]
    cons = root.find(f"{{{ns}}}Connections")
    for c in list(cons):
        cons.remove(c)
    for s, sv, d, dv in manifest["connections"]:
        vc = ET.SubElement(cons, f"{{{ns}}}VariableConnection")
        ET.SubElement(vc, f"{{{ns}}}Variable", simulator=s, name=sv)
        ET.SubElement(vc, f"{{{ns}}}Variable", simulator=d, name=dv)
    ET.register_namespace("", ns)
    path.write_bytes(ET.tostring(root, xml_declaration=True, encoding="utf-8"))
    return path


LIBCOSIMPY_RUN = textwrap.dedent("""
    import json, sys
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    log_output_level(CosimLogLevel.INFO)
    out = {}
    for path in sys.argv[2:]:
        ex = CosimExecution.from_osp_config_file(path)
        obs = CosimObserver.create_last_value()
        ex.add_observer(obs)
        assert ex.simulate_until(target_time=int(sys.argv[1]))
        out[path] = {}
        for info in ex.slave_infos():
            i = ex.slave_index_from_instance_name(info.name.decode())
            vs = ex.slave_variables(i)
            out[path][info.name.decode()] = dict(zip([v.name.decode() for v in vs],
                                                     obs.last_real_values(i, [v.reference for v in vs])))
    print("RESULT " + json.dumps(out))
""")


def test_libcosimpy_builds_the_bonded_system_without_warning_and_runs_as_before(built):
    """libcosimpy loads every scene's OspSystemStructure.xml (ports and plain connections)
    with its log at INFO: the log reaches us (libcosim's 'Configuring algorithm' line) and
    holds no warning or error; 20 steps of it equal, to the bit, the same system written as
    plain scalar connections (the file before ports)."""
    paths = []
    for folder in built.values():
        manifest = json.loads((folder / "manifest.json").read_text())
        paths += [str(folder / "OspSystemStructure.xml"), str(old_structure(folder, manifest, folder / "plain.xml"))]
    step = 0.05   # every scene's step divides it: 20 of the smallest
    run = subprocess.run([sys.executable, "-c", LIBCOSIMPY_RUN, str(int(20 * step * 1e9))] + paths,
                         capture_output=True, text=True, timeout=300)
    log = run.stdout + run.stderr
    assert run.returncode == 0, log
    assert log.count("Configuring algorithm: fixedStep") == len(paths)
    assert not [line for line in log.splitlines() if "[warning]" in line or "[error]" in line], log
    result = json.loads(next(line for line in run.stdout.splitlines() if line.startswith("RESULT "))[7:])
    for new, old in zip(paths[::2], paths[1::2]):
        assert result[new] == result[old] and len(result[new]) >= 2
        moving = [v for inst in result[new].values() for k, v in inst.items() if "position[" in k and v]
        assert moving, new   # the bodies have moved away from 0 somewhere


def test_libcosim_needs_the_port_descriptions(scenes, tmp_path):
    """The ports are really read: without one FMU's OSP model description libcosim cannot
    resolve the port connections and refuses the file."""
    folder = tmp_path / "moored_barge"
    shutil.copytree(scenes["moored_barge"], folder)
    next(folder.glob("*_dynamics_OspModelDescription.xml")).unlink()
    script = ("import sys\nfrom libcosimpy.CosimExecution import CosimExecution\n"
              "try:\n    CosimExecution.from_osp_config_file(sys.argv[1])\nexcept Exception as e:\n"
              "    print('REFUSED', e)\n")
    run = subprocess.run([sys.executable, "-c", script, str(folder / "OspSystemStructure.xml")],
                         capture_output=True, text=True, timeout=120)
    assert "REFUSED" in run.stdout and "extended model description" in run.stdout, run.stdout + run.stderr


def host_tables(hosts, config, stop, out, level):  # noqa: F811
    run = subprocess.run([str(hosts["cosim"]), str(config), repr(stop), "0", str(out)],
                         env=clean_env(COSIM_LOG_LEVEL=str(level)), capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stdout + run.stderr
    tables = {}
    for csv in out.glob("*.csv"):
        instance = csv.name.rsplit("_", 3)[0]
        tables[instance] = np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2)
    return run.stdout + run.stderr, tables


@pytest.mark.parametrize("name", ALL)
def test_native_libcosim_host_builds_the_bonded_system_without_warning(name, built, hosts, tmp_path):  # noqa: F811
    """The C host (libcosimc.so, no Python of its own) on the bonded OspSystemStructure.xml,
    log at INFO: no warning or error; its file observer's tables equal those of the same
    system as plain connections."""
    folder = built[name]
    manifest = json.loads((folder / "manifest.json").read_text())
    stop = 20 * manifest["run"]["step"]
    log, new = host_tables(hosts, folder / "OspSystemStructure.xml", stop, tmp_path / "new", 2)
    assert "Configuring algorithm: fixedStep" in log
    assert not [line for line in log.splitlines() if "[warning" in line or "[error" in line], log
    _, old = host_tables(hosts, old_structure(folder, manifest, folder / "plain.xml"), stop, tmp_path / "old", 3)
    assert sorted(new) == sorted(manifest["instances"]) == sorted(old)
    for inst in new:
        np.testing.assert_array_equal(new[inst], old[inst])


ECCO_BUILD = textwrap.dedent("""
    import json, sys
    from pathlib import Path
    from libcosimpy.CosimAlgorithm import CosimAlgorithm, EccoParams
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave
    log_output_level(CosimLogLevel.INFO)
    for folder in map(Path, sys.argv[1:]):
        m = json.loads((folder / "manifest.json").read_text())
        h = m["run"]["step"]
        ecco = CosimAlgorithm.create_ecco_algorithm(EccoParams(step_size=h, min_step_size=h / 4, max_step_size=4 * h))
        ex = CosimExecution.from_algorithm(ecco)
        index, refs = {}, {}
        for name in m["order"]:
            fmu = str((folder / m["instances"][name]["fmu"]).resolve())
            index[name] = ex.add_local_slave(CosimLocalSlave(fmu_path=fmu, instance_name=name))
            refs[name] = {v.name.decode(): v.reference for v in ex.slave_variables(index[name])}
        for (li, lo, lin), (di, do, din) in ((b["load"], b["dynamics"]) for b in m["bonds"]):
            assert ecco.add_power_bond(index[li], refs[li][lo], refs[li][lin], index[di], refs[di][do], refs[di][din]) == 0
        for s, sv, d, dv in m["connections"]:
            assert ex.connect_real_variables(index[s], refs[s][sv], index[d], refs[d][dv]) is not False
        # ECCO reads the bonds' inputs too: only an observer exposes them for reading
        # (without one the first step fails: "Variables must be exposed before calling get()")
        ex.add_observer(CosimObserver.create_last_value())
        assert ex.simulate_until(target_time=int(5 * h * 1e9))
        print("BONDS", folder.name, len(m["bonds"]))
""")


def test_libcosim_ecco_takes_every_bond_of_the_manifest(built):
    """The manifest's scalar bonds are what libcosim's ECCO algorithm takes (through its API:
    see fmi.osp for why not through the file): every one is accepted by ``add_power_bond``
    (the same velocity output may close several bonds), and the execution builds and steps
    with no warning or error in libcosim's log."""
    run = subprocess.run([sys.executable, "-c", ECCO_BUILD] + [str(f) for f in built.values()],
                         capture_output=True, text=True, timeout=300)
    log = run.stdout + run.stderr
    assert run.returncode == 0, log
    assert sorted(line.split()[1:] for line in log.splitlines() if line.startswith("BONDS")) == sorted(
        [n, str(6 * k)] for n, k in BONDS.items())
    assert not [line for line in log.splitlines() if "[warning]" in line or "[error]" in line], log
