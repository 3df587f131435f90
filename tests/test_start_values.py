"""Input start values are the scene's state at t = 0 (fmi.starts): a master that steps first
from the declared starts runs the same system as ours, which exchanges before the first step;
the build refuses a start that is not its source's value at t = 0."""
import json
import zipfile
from xml.etree import ElementTree as ET

import numpy as np
import pytest

from hydrofmu import assembly
from hydrofmu.cosim.master import run
from hydrofmu.fmi.starts import StartValueError

from conftest import build, coupled_pair_scene, open_fmus
from simo_decks import pair_deck

M = 1.0e6
STEPS = 40


def scene_text(deck, mode):
    """Bodies a (acceleration loads in ``mode``), b and c (export), each released with a
    velocity from a tilted pose; a in a current with drag and a massive ball joint to the
    earth (``mode`` too), b and c joined by a ball joint; SIMO self and cross couplings
    with memory (convolution and state space) between a and b."""
    return coupled_pair_scene(deck, [
        ("a", 0.0, mode, [0.3, -0.2, 0.1, 0.01, -0.02, 0.03], [0.05, -0.03, 0.2], -1.0),
        ("b", 40.0, "export", [0.1, 0.5, 0.2, 0.0, 0.01, -0.02], [-0.04, 0.02, -0.1], -1.0),
        ("c", 80.0, "export", [-0.2, 0.1, 0.0, 0.02, 0.0, 0.01], [0.0, 0.03, 0.05], -1.0)], mode, stop=2.0, extra="""
[joints.link]
a = "b"
a_point = [20.0, 0.0, 0.0]
b = "c"
b_point = [-20.0, 0.0, 0.0]
stiffness = 1.0e6
damping = 1.0e5
""")


@pytest.fixture(scope="module", params=["export", "explicit"])
def built(request, tmp_path_factory):
    folder = tmp_path_factory.mktemp(f"starts_{request.param}")
    return request.param, build(folder, scene_text(pair_deck(folder / "pair.sim", M).name, request.param))


def step_first(folder, manifest, columns, steps, step):
    """A Jacobi loop with no initial exchange, written here on fmpy's FMU2Slave: every
    connector starts at its input's start value in modelDescription.xml; at each step every
    FMU gets its connectors, steps, then every connected output is read (and the recorded
    columns sampled) and copied to its connectors.  Row 0: the outputs after initialization."""
    fmus, vrs, starts = open_fmus(folder, manifest)
    conns = manifest["connections"]
    value = {(d, dv): starts[d][dv] for _, _, d, dv in conns}
    by_instance = {}
    for col in columns:
        name, var = col.split(".", 1)
        by_instance.setdefault(name, []).append((columns.index(col), vrs[name][var]))
    out = np.empty((steps + 1, len(columns)))

    def sample(row):
        for name, cols in by_instance.items():
            got = fmus[name].getReal([vr for _, vr in cols])
            out[row, [j for j, _ in cols]] = got

    sample(0)
    for k in range(steps):
        for name, s in fmus.items():
            ins = [(vrs[name][dv], value[d, dv]) for _, _, d, dv in conns if d == name]
            s.setReal([vr for vr, _ in ins], [x for _, x in ins])
            s.doStep(k * step, step)
        got = {(src, sv): fmus[src].getReal([vrs[src][sv]])[0] for src, sv, _, _ in conns}
        sample(k + 1)
        for src, sv, d, dv in conns:
            value[d, dv] = got[src, sv]
    for s in fmus.values():
        s.terminate()
        s.freeInstance()
    return out


def worst(ours, theirs):
    """Largest difference of any column over that column's range in ``ours``."""
    span = ours.max(axis=0) - ours.min(axis=0)
    return float(np.max(np.abs(theirs - ours) / np.where(span > 0, span, 1.0)))


def test_step_first_masters_equal_ours(built):
    """Our Jacobi master (two exchanges in initialization mode), a loop that steps first
    from the declared start values, and libcosim's fixed-step master: every output of every
    FMU (loads, joints, coupled dynamics) equal to 1e-9 of its range over 40 steps, in a
    scene whose bodies start tilted and moving, with joints and memory.  With explicit
    acceleration loads the loop still equals ours (both give the load FMUs zero acceleration
    over the first step, the acceleration inputs' start); libcosim exchanges once more after
    initialization, when the dynamics have their acceleration, so its first step differs
    (the one input the build cannot know, fmi.starts)."""
    mode, built = built
    manifest = json.loads((built / "manifest.json").read_text())
    step = manifest["run"]["step"]
    ours = run(built, stop=STEPS * step, algorithm="jacobi", progress=False)
    # the scene moves: the columns compared are not constants
    moving = [c for c in ours.columns if np.ptp(ours.values[:, ours.columns.index(c)]) > 0]
    assert {"a.force[1]", "b.SB.force[3]", "link.B.force[2]", "a_b_dynamics.b.velocity[2]",
            "c_dynamics.attitude[3]"} <= set(moving)
    loop = step_first(built, manifest, ours.columns, STEPS, step)
    print(f"step-first loop: {worst(ours.values, loop):.2e} of the range")
    assert worst(ours.values, loop) < 1e-9, worst(ours.values, loop)
    if mode == "explicit":
        return
    pytest.importorskip("libcosimpy")
    from hydrofmu.cosim import libcosim
    theirs = libcosim.run(built, stop=STEPS * step, record=ours.columns, algorithm="jacobi")
    print(f"libcosim: {worst(ours.values, theirs.values):.2e} of the range")
    assert worst(ours.values, theirs.values) < 1e-9, worst(ours.values, theirs.values)


def test_starts_are_the_state_at_t0(built):
    """What the system files declare: every connected input's start in modelDescription.xml,
    OspSystemStructure.xml and the .ssp is the same number; the velocity inputs carry the
    scene's velocities, the dynamics' load inputs the load FMUs' loads at t = 0 (nonzero
    here: drag in a current, a stretched joint), the acceleration inputs 0."""
    mode, built = built
    manifest = json.loads((built / "manifest.json").read_text())
    from fmpy import read_model_description
    declared = {name: {v.name: float(v.start) for v in read_model_description(str(built / inst["fmu"])).modelVariables
                       if v.start is not None} for name, inst in manifest["instances"].items()}
    assert declared["a"]["velocity[2]"] == -0.2 and declared["a"]["b.velocity[2]"] == 0.5
    assert declared["link"]["B.velocity[1]"] == -0.2 and declared["link"]["A.attitude[3]"] == -0.1
    if mode == "explicit":
        assert declared["a"]["acceleration[1]"] == declared["a"]["b.acceleration[2]"] == 0.0
    assert abs(declared["a_b_dynamics"]["a.force[1]"]) > 1e3
    osp = ET.parse(built / "OspSystemStructure.xml").getroot()
    ns = {"o": "http://opensimulationplatform.com/MSMI/OSPSystemStructure"}
    in_osp = {(sim.get("name"), iv.get("variable")): float(iv.find("o:Real", ns).get("value"))
              for sim in osp.iterfind(".//o:Simulator", ns) for iv in sim.iterfind(".//o:InitialValue", ns)}
    from hydrofmu.fmi.ssp import SSD, SSV
    with zipfile.ZipFile(built / f"{manifest['scene']}.ssp") as z:
        ssd = ET.fromstring(z.read("SystemStructure.ssd"))
    in_ssp = {(comp.get("name"), p.get("name")): float(p.find(f"{{{SSV}}}Real").get("value"))
              for comp in ssd.iter(f"{{{SSD}}}Component") for p in comp.iter(f"{{{SSV}}}Parameter")}
    for _, _, dst, inp in manifest["connections"]:
        assert in_osp[dst, inp] == in_ssp[dst, inp] == declared[dst][inp], (dst, inp)


SMALL = """
    [environment]
    current_speed = 1.0
    current_direction = 20.0
    [run]
    step = 0.1
    stop = 1.0
    [bodies.a]
    position = [0.0, 0.0, 0.0]
    velocity = [0.2, 0.0, 0.0, 0.0, 0.0, 0.0]
    mass = 1e6
    inertia = [1e8, 1e8, 1e8]
    stiffness = [1e5, 1e5, 1e6, 1e8, 1e8, 1e8]
    [[bodies.a.effects]]
    type = "aqwa_viscous_drag"
    matrix = [2e4, 3e4, 1e4, 0.0, 0.0, 1e6]
    option = "RELATIVE"
    """


def test_the_build_refuses_a_wrong_start(tmp_path, monkeypatch):
    """The build's check fires, naming the input, its start and its source's value, when a
    start is not the value at t = 0: a load FMU whose velocity inputs start at rest (what
    every FMU declared before), and a dynamics partner whose load inputs start at zero."""
    from hydrofmu.fmi import starts

    real = assembly._loads
    monkeypatch.setattr(assembly, "_loads", lambda *a: _at_rest(real(*a)))
    with pytest.raises(StartValueError, match=r"a\.velocity\[1\] starts at 0\.0, its source a_dynamics\.velocity"
                                              r"\[1\] is 0\.2"):
        build(tmp_path / "rest", SMALL)
    assert not (tmp_path / "rest" / "fmus" / "scene").exists()   # nothing half-written
    monkeypatch.undo()
    monkeypatch.setattr(starts, "fill_loads", lambda system, t0: None)
    with pytest.raises(StartValueError, match=r"a_dynamics\.force\[1\] starts at 0\.0, its source a\.force\[1\]"):
        build(tmp_path / "zero", SMALL)


def _at_rest(instance):
    instance.fmu.velocity = np.zeros(6)
    return instance
