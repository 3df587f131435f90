"""physics/mooring.py: MoorDyn's lines on our bodies, held against answers found apart from
MoorDyn: the elastic catenary with seabed contact (tests/moordyn_files.py, solved with scipy),
the spread's offset-force curve from it, the surge period from its linearised stiffness, the
rotation convention of DESIGN.md, one description of the mooring against another, and the
water the nodes feel against our own kinematics."""
import math

import numpy as np
import pytest

from moordyn_files import catenary, moordyn_file, wet_weight

moordyn = pytest.importorskip("moordyn", reason="needs the moordyn package (pip install hydrofmu[mooring])")

from hydrofmu.decks.moordyn import read_moordyn, runnable  # noqa: E402
from hydrofmu.physics.kinematics import rotation  # noqa: E402
from hydrofmu.physics.mooring import RUN_OPTIONS, Coupling, Mooring, moordyn_angles  # noqa: E402
from hydrofmu.physics.state import Env, Motion  # noqa: E402

DEPTH = 50.0
OPTIONS = [(0.005, "dtM"), (DEPTH, "WtrDpth"), (1e-5, "threshIC")]
FAIR_Z, SPAN, LENGTH, RADIUS = -5.0, 100.0, 120.0, 2.0


def running(tmp_path, text, couplings, options=None, **kw):
    """A Mooring of a MoorDyn file as a user writes it (read, made runnable as the scene does)."""
    path = tmp_path / "lines.dat"
    path.write_text(text)
    deck = read_moordyn(path)
    run = runnable(deck, {**RUN_OPTIONS, "rho": 1025.0, "g": 9.81, "wtrdpth": DEPTH} if options is None else options)
    return Mooring(run.text, couplings, **kw)


def at(position=(0.0, 0.0, 0.0), attitude=(0.0, 0.0, 0.0), velocity=(0.0,) * 6):
    return Motion(np.array(position, float), np.array(attitude, float), np.array(velocity, float))


def one_line(segments):
    return moordyn_file([("Fixed", SPAN, 0, -DEPTH), ("Coupled", 0, 0, FAIR_Z)],
                        [(1, 2, LENGTH, segments, "-")], OPTIONS)


def test_one_line_against_the_elastic_catenary(tmp_path):
    """One chain from an anchor on the bed to a fairlead 100 m away and 45 m up, MoorDyn's
    initial equilibrium against the elastic catenary (tests/moordyn_files.py): the fairlead's
    force (H, V), the nodes on the curve, the tensions at both ends.  The lumped-mass line
    converges to it at second order in its segment length: halving the segments divides the
    error by about four (not merely shrinks it), and at 20 segments H is within 0.5 %."""
    h_, v, shape = catenary(SPAN, DEPTH + FAIR_Z, LENGTH)
    errors = {}
    for n in (10, 20):
        with running(tmp_path, one_line(n), [Coupling("point", 2, "ship")]) as m:
            load = m.start(0.0, {"ship": at((0.0, 0.0, FAIR_Z))})["ship"]
            fair, anchor = m.tensions()
            nodes = m.nodes()[0]
        errors[n] = abs(load[0] / h_ - 1), abs(-load[2] / v - 1)
        assert np.allclose(load[[1, 3, 4, 5]], 0.0, atol=1e-6)   # in the x-z plane, at the point
    assert errors[10][0] / errors[20][0] > 3.5 and errors[10][1] / errors[20][1] > 3.5, errors
    assert errors[20][0] < 5e-3 and errors[20][1] < 2.5e-3, errors
    # the nodes on the curve (x from the anchor), their unstretched arc lengths i·L/n
    x, z = shape(np.arange(21) * LENGTH / 20)
    assert np.allclose(SPAN - nodes[:, 0], x, atol=0.05) and np.allclose(nodes[:, 2] + DEPTH, z, atol=0.1)
    assert np.abs(nodes[:, 1]).max() < 1e-9
    # FairTen is the top segment's tension: the curve's at its midpoint s = L − ΔL/2, between the
    # nodes; AnchTen on a frictionless bed is H
    w = wet_weight()
    s_mid = v / w - LENGTH / 40
    assert fair[0] == pytest.approx(math.hypot(h_, w * s_mid), rel=4e-3)
    assert anchor[0] == pytest.approx(h_, rel=5e-3)


def spread(segments=20, kind="point", outputs="-"):
    """Three lines at 120° from fairleads at radius 2 m, 5 m below the reference point of a
    body at the origin; as coupled points (global coordinates) or BodyN points of a coupled body."""
    points, lines = [], []
    for k in range(3):
        c, s = math.cos(2 * math.pi * k / 3), math.sin(2 * math.pi * k / 3)
        r = RADIUS + SPAN
        points.append(("Fixed", r * c, r * s, -DEPTH))
        points.append(("Coupled" if kind == "point" else "Body1", RADIUS * c, RADIUS * s, FAIR_Z))
        lines.append((2 * k + 1, 2 * k + 2, LENGTH, segments, outputs))
    bodies = [("Coupled", 0, 0, 0, 0, 0, 0, 0, 0)] if kind == "body" else ()
    couplings = ([Coupling("point", 2 * k + 2, "ship", (RADIUS * math.cos(2 * math.pi * k / 3),
                                                        RADIUS * math.sin(2 * math.pi * k / 3), FAIR_Z))
                  for k in range(3)] if kind == "point" else [Coupling("body", 1, "ship")])
    return moordyn_file(points, lines, OPTIONS, bodies=bodies), couplings


def catenary_force(surge):
    """The spread's horizontal force on the body offset by ``surge`` [m], from the catenary."""
    total = np.zeros(2)
    for k in range(3):
        u = np.array([math.cos(2 * math.pi * k / 3), math.sin(2 * math.pi * k / 3)])
        to_anchor = (RADIUS + SPAN) * u - (RADIUS * u + [surge, 0.0])
        h_, _, _ = catenary(np.linalg.norm(to_anchor), DEPTH + FAIR_Z, LENGTH)
        total += h_ * to_anchor / np.linalg.norm(to_anchor)
    return total


def test_offset_force_curve_of_a_spread_against_the_catenary(tmp_path):
    """The spread's static surge force at offsets of −8…+8 m, each MoorDyn's equilibrium with the
    body held there, against the catenaries of the three lines at their new spans: within 1 %
    of the curve's range (the lines' own error, −0.4 % of H each at 20 segments, cancels in
    part between the lines); the curve stiffens with the offset (softening the other way)."""
    text, couplings = spread()
    ours, theirs = [], []
    with running(tmp_path, text, couplings) as m:
        for surge in (-8.0, 0.0, 4.0, 8.0):
            ours.append(m.start(0.0, {"ship": at((surge, 0.0, 0.0))})["ship"][:2])
            theirs.append(catenary_force(surge))
    ours, theirs = np.array(ours), np.array(theirs)
    scale = np.ptp(theirs[:, 0])
    assert np.abs(ours - theirs).max() < 0.01 * scale, (ours, theirs)
    assert abs(ours[1, 0]) < 1e-3 * scale   # symmetric at rest
    assert ours[3, 0] - ours[2, 0] < ours[2, 0] - ours[1, 0] < 0   # restoring, stiffer with the offset


def test_surge_period_against_the_linearised_stiffness(tmp_path):
    """A 1500 t body on the spread, free in surge only (M·ẍ = F_x of the Mooring, semi-implicit
    Euler at 0.1 s), released 1 m off: its period against 2π·√(M/k), k = −dF_x/dx of the
    catenary at rest.  The lines' own mass (3 × 12 t, some of it moving with the body) and
    drag lengthen it slightly: within 3 %."""
    mass = 1.5e6
    d = 0.5
    k = -(catenary_force(d)[0] - catenary_force(-d)[0]) / (2 * d)
    expected = 2 * math.pi * math.sqrt(mass / k)
    text, couplings = spread(segments=10)
    x, v, dt = 1.0, 0.0, 0.1
    crossings, t = [], 0.0
    with running(tmp_path, text, couplings) as m:
        fx = m.start(0.0, {"ship": at((x, 0, 0))})["ship"][0]
        while len(crossings) < 2 and t < 2 * expected:
            v += dt * fx / mass
            x_new = x + dt * v
            fx = m.step(t, dt, {"ship": at((x, 0, 0), velocity=(v, 0, 0, 0, 0, 0))})["ship"][0]
            if x > 0 >= x_new or x < 0 <= x_new:
                crossings.append(t + dt * x / (x - x_new))
            x, t = x_new, t + dt
    assert len(crossings) == 2
    period = 2 * (crossings[1] - crossings[0])   # released at the crest: crossings at T/4 and 3T/4
    assert period == pytest.approx(expected, rel=0.03), (period, expected, k)


@pytest.mark.parametrize("pose", [
    at((1.0, -0.5, 0.2), (0.05, -0.08, 0.6), (0.1, -0.05, 0.02, 0.0, 0.0, 0.0)),   # tilted, moving
    at((0.5, 0.3, 0.0), (0.0, 0.0, 2.5), (0.05, 0.0, 0.0, 0.0, 0.0, 0.03))],        # yawed, turning
    ids=["tilted", "turning"])
def test_a_coupled_body_and_coupled_points_are_one_mooring(tmp_path, pose):
    """The same three lines written as BodyN points of a coupled body and as coupled points:
    with the body rolled, pitched and yawed (our R = Rz·Ry·Rx), MoorDyn puts the body's points
    at p + R·r (its own angles, R = Rx·Ry·Rz, made from ours), and the two files give one load
    about our reference point, at rest and stepping at a steady velocity (to 1e-4 of it: a
    turning point goes along the chord, MoorDyn's body point along the arc, and MoorDyn adds
    the centripetal terms of a turning body).
    A change of velocity between two steps differs by the inertia of what the coupled body
    carries, −M_k·Δv_k/dt at each of its lines' end nodes k (M_k: MoorDyn's mass matrix of the
    node, with its added mass): MoorDyn adds it to a coupled body's load, not to a point's.  A tilted body that also turns is
    left out: MoorDyn takes its angle rates for the angular velocity (module docstring)."""
    loads, inertia = {}, np.zeros(6)
    dt = 0.1
    for kind in ("body", "point"):
        text, couplings = spread(kind=kind)
        with running(tmp_path, text, couplings) as m:
            got = [m.start(0.0, {"ship": pose})["ship"]]
            if kind == "body":
                r = rotation(pose.attitude)
                for k in range(3):
                    arm = r @ [RADIUS * math.cos(2 * math.pi * k / 3), RADIUS * math.sin(2 * math.pi * k / 3), FAIR_Z]
                    assert np.allclose(moordyn.GetPointPos(moordyn.GetPoint(m.md, 2 * k + 2)),
                                       pose.position + arm, atol=1e-9)
                    line = moordyn.GetLine(m.md, k + 1)
                    node = np.array(moordyn.GetLineNodeM(line, moordyn.GetLineN(line))).reshape(3, 3)
                    # the node's velocity from rest to v + ω × R·r in the first step
                    force = -node @ (pose.velocity[:3] + np.cross(pose.velocity[3:], arm)) / dt
                    inertia += np.concatenate([force, np.cross(arm, force)])
            for k in range(3):   # the body moves on at its velocity (from rest at the start)
                moved = at(pose.position + k * dt * pose.velocity[:3], pose.attitude, pose.velocity)
                got.append(m.step(k * dt, dt, {"ship": moved})["ship"])
            loads[kind] = np.array(got)
    body, point = loads["body"], loads["point"]
    body[1] -= inertia
    for a, b in zip(body, point):
        assert np.allclose(a[:3], b[:3], rtol=0, atol=1e-4 * np.abs(a[:3]).max()), (a, b)
        assert np.allclose(a[3:], b[3:], rtol=0, atol=1e-4 * np.abs(a[3:]).max()), (a, b)


def test_moordyn_angles_make_our_rotation():
    """Rx(a)·Ry(b)·Rz(c) of moordyn_angles equals Rz(ψ)·Ry(θ)·Rx(φ) (DESIGN.md), each built here."""
    def rx(a):
        return np.array([[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]])

    def ry(a):
        return np.array([[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]])

    def rz(a):
        return np.array([[math.cos(a), -math.sin(a), 0], [math.sin(a), math.cos(a), 0], [0, 0, 1]])
    for phi, theta, psi in [(0.1, -0.2, 0.3), (-0.4, 0.3, 2.9), (0.0, 0.0, -3.1), (0.2, 1.2, -1.0)]:
        a, b, c = moordyn_angles([phi, theta, psi])
        assert np.allclose(rx(a) @ ry(b) @ rz(c), rz(psi) @ ry(theta) @ rx(phi), atol=1e-12)


def test_the_nodes_feel_our_current_and_our_waves(tmp_path):
    """One sea: the water velocity MoorDyn used at every node (its own line output 'U', read back
    from its output file) is our current profile plus our waves (WaveKinematics of the same
    components) at the node's position and the step's midpoint; a node on the bed feels the
    water just above it."""
    from hydrofmu.physics.current import CurrentProfile
    from hydrofmu.physics.wave_kinematics import WaveKinematics
    from hydrofmu.physics.waves import Components, Phasors
    comps = Components(np.array([0.6, 0.9]), np.array([1.0, 0.4]), np.array([20.0, -30.0]), np.array([0.3, 2.0]))
    kin = WaveKinematics(comps, 9.81, DEPTH, "wheeler")
    env = Env(current_speed=0.6, current_direction=45.0,
              profile=CurrentProfile.from_rows([[0.0, 0.6, 45.0], [-30.0, 0.3, 60.0], [-50.0, 0.1, 90.0]]))
    text = one_line(10).replace("10       -", "10       pU")
    options = {"wavekin": 1, "rho": 1025.0, "g": 9.81, "wtrdpth": DEPTH}   # output files kept
    dt, steps = 0.2, 5
    with running(tmp_path, text, [Coupling("point", 2, "ship")], options, kinematics=kin,
                 phasors=Phasors(comps, ramp_length=0.0)) as m:
        m.start(0.0, {"ship": at((0.0, 0.0, FAIR_Z))}, env)
        for k in range(steps):
            m.step(k * dt, dt, {"ship": at((0.3 * math.sin(k), 0.0, FAIR_Z))}, env)
        moordyn.Close(m.md)   # MoorDyn writes its output files out when closed
        m.md = None
        out = next(m.workdir.glob("*_Line1.out"))
        names = out.read_text().split("\n", 1)[0].split()
        rows = np.loadtxt(out, skiprows=2)
    assert len(rows) == steps + 1
    pos = rows[:, [names.index(f"Node{i}p{c}") for i in range(11) for c in "xyz"]].reshape(-1, 11, 3)
    used = rows[:, [names.index(f"Node{i}U{c}") for i in range(11) for c in "xyz"]].reshape(-1, 11, 3)
    ph = Phasors(comps, ramp_length=0.0)
    for k in range(steps):   # row k + 1: after step k, whose water was set at the nodes of row k
        pts = pos[k].copy()
        pts[:, 2] = np.maximum(pts[:, 2], -DEPTH)
        rows_k = kin.at(ph.at(k * dt + dt / 2), 1.0, pts)
        expect = rows_k[:, :3] + np.array([env.current_at(z) for z in pts[:, 2]])
        assert np.allclose(used[k + 1], expect, rtol=1e-6, atol=1e-7), k
    assert np.abs(used[1:]).max() > 0.1   # it is not still water


def test_state_restores_the_run_bit_for_bit(tmp_path):
    """state() then set_state(): the steps after it again give the same loads exactly."""
    text, couplings = spread(segments=6)
    with running(tmp_path, text, couplings) as m:
        m.start(0.0, {"ship": at()})

        def run(k0):
            return [m.step(0.1 * k, 0.1, {"ship": at((0.5 * math.sin(0.3 * k), 0, 0), (0, 0, 0.01 * k),
                                                     (0.15 * math.cos(0.3 * k), 0, 0, 0, 0, 0.1))})["ship"]
                    for k in range(k0, k0 + 5)]
        run(0)
        saved = m.state()
        first = run(5)
        m.set_state(saved)
        again = run(5)
    assert np.array_equal(np.array(first), np.array(again))


def test_a_c_program_on_moordyns_library_gives_the_same_loads(tmp_path):
    """The compiled flavour's way in (docs/moorings.md): tests/native/moordyn_host.c, built by
    the system C compiler against the library the moordyn wheel ships (its C API), run on the
    copy hydrofmu runs with a prescribed surge, prints the loads and tensions our Mooring gives
    for the same motion: the same numbers (one library, to the last bit)."""
    import subprocess
    from pathlib import Path
    from conftest import ROOT, tools
    from hydrofmu import cc
    libs = sorted((Path(moordyn.__file__).resolve().parents[1] / "moordyn.libs").glob("libmoordyn*.so*"))
    if not libs:
        pytest.skip("no libmoordyn in the moordyn wheel (not a Linux wheel)")
    tools(cc.compiler()[0], why="compiles the C program")
    program = tmp_path / "moordyn_host"
    subprocess.run(cc.compiler() + ["-std=c99", "-O2", str(ROOT / "tests" / "native" / "moordyn_host.c"), "-o",
                                    str(program), str(libs[0]), f"-Wl,-rpath,{libs[0].parent}", "-lm"], check=True)
    text, _ = spread(kind="body", segments=8)
    path = tmp_path / "lines.dat"
    path.write_text(text)
    copy = runnable(read_moordyn(path), {**RUN_OPTIONS, "rho": 1025.0, "g": 9.81, "wtrdpth": DEPTH})
    (tmp_path / "copy.dat").write_text(copy.text)
    steps, dt, amp, w = 20, 0.1, 0.5, 0.6
    done = subprocess.run([str(program), str(tmp_path / "copy.dat"), str(steps), str(dt), str(amp), str(w)],
                          capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr[-2000:]
    theirs = np.array([[float(v) for v in line.split()] for line in done.stdout.splitlines()
                       if line and line[0] in "-0123456789"])
    ours = []
    with Mooring(copy.text, [Coupling("body", 1, "ship")]) as m:
        m.start(0.0, {"ship": at()})
        for k in range(steps):
            t = k * dt
            load = m.step(t, dt, {"ship": at((amp * math.sin(w * t), 0, 0),
                                            velocity=(amp * w * math.cos(w * t), 0, 0, 0, 0, 0))})["ship"]
            ours.append(np.concatenate([load, m.tensions()[0]]))
    assert theirs.shape == (steps, 9)
    assert np.array_equal(theirs, np.array(ours))
