"""Loads that feel the incident waves (physics/lumped.py, viscous_drag.py, current_polar.py,
joint.py through its node) against formulas written here: Morison drag and inertia on a held
lumped body (harmonics of |u|u, mean drag under current), a slender vertical cylinder of 40
lumped bodies against the closed-form integral, a neutrally buoyant body following the
particle orbit."""
import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from airy import Airy
from hydrofmu.physics import waves
from hydrofmu.physics.current_polar import CurrentPolar
from hydrofmu.physics.joint import BallJoint
from hydrofmu.physics.lumped import LumpedBody
from hydrofmu.physics.state import Env, Motion
from hydrofmu.physics.viscous_drag import ViscousDrag
from hydrofmu.physics.wave_kinematics import Water, WaveKinematics
from hydrofmu.physics.waves import Components, Phasors

RHO, G = 1025.0, 9.81


def regular(a=1.5, period=8.0, beta=0.0, depth=math.inf, ramp=0.0):
    comps = Components(np.array([2 * math.pi / period]), np.array([a]), np.array([beta]), np.array([0.0]))
    ph = Phasors(comps, ramp)
    return comps, ph, Env(RHO, G, water=Water(WaveKinematics(comps, G, depth), ph, RHO))


def held(x=0.0, y=0.0, z=0.0):
    return Motion(np.array([x, y, z]), np.zeros(3), np.zeros(6), np.zeros(6))


def test_held_lumped_body_morison_drag_and_inertia():
    """A body 8 m down on a held barge, regular deep-water wave a = 1.5 m, T = 8 s going to +x,
    plus a current: F_x = CD·(U_c + u)|U_c + u| + (ρ·AE + AMX)·∂u/∂t, u = ωa e^{kz} cos ωt."""
    a, period, z = 1.5, 8.0, -8.0
    w = 2 * math.pi / period
    k = w * w / G
    cd, ae, amx = 3.0e3, 2.0, 1.5e3
    for uc in (0.0, 1.0):
        comps, ph, env = regular(a, period)
        env.current_speed = uc
        body = LumpedBody("clump", np.array([0.0, 0.0, z]), am=1000.0, ae=ae, cd=np.array([cd, cd, cd]),
                          added_mass=np.array([amx, amx, amx]))
        t = np.linspace(0.0, period, 256, endpoint=False)
        f = []
        for x in t:
            ph.at(x)
            f.append(body.load(held(), env))
        f = np.array(f)
        # the water's motion at the body from the wave's potential (tests/airy.py)
        water = np.array([Airy(a, w, 0.0, 0.0).at(0.0, 0.0, z, x) for x in t])
        u, wz, dudt, dwdt = water[:, 0], water[:, 2], water[:, 3], water[:, 5]
        want_x = cd * (uc + u) * np.abs(uc + u) + (RHO * ae + amx) * dudt
        want_z = cd * wz * np.abs(wz) + (RHO * ae + amx) * dwdt + RHO * G * ae - 1000.0 * G
        np.testing.assert_allclose(f[:, 0], want_x, rtol=0, atol=1e-9 * np.abs(want_x).max())
        np.testing.assert_allclose(f[:, 2], want_z, rtol=0, atol=1e-9 * np.abs(want_z).max())
        np.testing.assert_allclose(f[:, 4], z * f[:, 0], rtol=0, atol=1e-9 * np.abs(z * f[:, 0]).max())  # M_y = z F_x
        # the drag alone: the Fourier series of |u|u (no current: 8/(3π), 0, 8/(15π) of CD·U0²),
        # the mean under a current stronger than the orbit: CD·(U_c² + U0²/2)
        drag = f[:, 0] - (RHO * ae + amx) * dudt
        c = np.fft.rfft(drag) / t.size * 2
        u0 = u[0]   # (t = 0: under the crest)
        if uc == 0.0:
            # (256 samples: the harmonics above 128, ~n⁻³, alias in at 1e-8)
            assert abs(c[1]) == pytest.approx(cd * u0 ** 2 * 8 / (3 * math.pi), rel=1e-7)
            assert abs(c[3]) == pytest.approx(cd * u0 ** 2 * 8 / (15 * math.pi), rel=1e-7)
            assert abs(c[0]) < 1e-9 * cd * u0 ** 2 and abs(c[2]) < 1e-9 * cd * u0 ** 2
        else:
            assert uc > u0
            assert c[0].real / 2 == pytest.approx(cd * (uc ** 2 + u0 ** 2 / 2), rel=1e-9)


def test_held_body_above_the_surface_is_dry():
    """A point above the instantaneous surface feels no drag and no water acceleration (its
    weight and buoyancy stay): at the crest of a = 1.5 m a point at z = 1 m is wet, in the
    trough it is dry."""
    comps, ph, env = regular(1.5, 8.0)
    env.current_speed = 1.0
    body = LumpedBody("b", np.array([0.0, 0.0, 1.0]), am=100.0, ae=0.5, cd=np.array([1e3, 1e3, 1e3]),
                      added_mass=np.array([50.0, 50.0, 50.0]))
    ph.at(0.0)   # crest
    wet = body.load(held(), env)
    ph.at(4.0)   # trough
    dry = body.load(held(), env)
    np.testing.assert_allclose(dry, [0, 0, RHO * G * 0.5 - 100.0 * G, 0, 0, 0], atol=1e-9)
    assert wet[0] > 1e3   # current + crest velocity: drag and buoyancy


@pytest.mark.parametrize("depth", [math.inf, 30.0])
def test_slender_cylinder_of_lumped_bodies_against_the_integral(depth):
    """A fixed vertical cylinder r = 1 m, draught 20 m, made of 40 lumped bodies (slices at
    mid-heights, AE = πr²dz, AMX = AMY = C_a·ρπr²dz, no drag): the horizontal force and the
    moment about the reference point at the mean surface against ∫ ρ C_M π r² ∂u/∂t dz over the
    draught in closed form (deep: (1 − e^{−kT})/k; finite: (sinh kh − sinh k(h − T))/(k sinh kh)),
    to the midpoint rule's (k dz)²/24."""
    # (a = 0.2 m: the top slice, 0.25 m down, stays wet in the troughs; the integral is linear)
    r, draught, n, ca, a, period = 1.0, 20.0, 40, 1.0, 0.2, 9.0
    comps, ph, env = regular(a, period, depth=depth)
    w = comps.omega[0]
    k = float(waves.wave_number(w, G, depth))
    dz = draught / n
    bodies = [LumpedBody(f"s{i}", np.array([0.0, 0.0, -dz * (i + 0.5)]), am=0.0, ae=math.pi * r * r * dz,
                         added_mass=np.array([ca * RHO * math.pi * r * r * dz] * 2 + [0.0])) for i in range(n)]
    if math.isinf(depth):
        force_int = (1 - math.exp(-k * draught)) / k
        moment_int = (-1 + math.exp(-k * draught) * (1 + k * draught)) / k ** 2
    else:
        h = depth
        sk = math.sinh(k * h)
        force_int = (sk - math.sinh(k * (h - draught))) / (k * sk)
        prim = lambda z: z * math.sinh(k * (z + h)) / k - math.cosh(k * (z + h)) / k ** 2   # noqa: E731
        moment_int = (prim(0.0) - prim(-draught)) / sk
    cm = 1 + ca
    for t in np.linspace(0, period, 17):
        ph.at(t)
        total = sum(b.load(held(), env) for b in bodies)
        dudt = -w * w * a * math.sin(w * t)   # ∂u/∂t / F_h(z) at x = 0
        fx = RHO * cm * math.pi * r * r * dudt * force_int
        my = RHO * cm * math.pi * r * r * dudt * moment_int
        scale = RHO * cm * math.pi * r * r * w * w * a * force_int
        tol = 2 * (k * dz) ** 2 / 24 * scale
        assert abs(total[0] - fx) <= tol, (t, total[0], fx)
        assert abs(total[4] - my) <= tol * draught, (t, total[4], my)
        assert abs(total[1]) < 1e-9 * scale


def test_neutrally_buoyant_body_follows_the_particle_orbit():
    """A small body with m = ρ·AE, no drag, C_a = 0, free in a regular deep-water wave
    (a = 1 cm: second-order drift negligible) started with the water's velocity: its path is the
    particle's circle of radius a·e^{kz} about its start (to 1 % of the radius); a body twice as
    heavy does not follow (it moves half as much)."""
    a, period, z0 = 0.01, 6.0, -3.0
    comps, ph, env = regular(a, period)
    w = comps.omega[0]
    k = w * w / G
    radius = a * math.exp(k * z0)
    vol = 0.1

    def path(mass):
        body = LumpedBody("p", np.zeros(3), am=mass, ae=vol)

        def rhs(t, y):
            ph.at(t)
            f = body.load(Motion(y[:3], np.zeros(3), np.r_[y[3:], 0, 0, 0], np.zeros(6)), env)
            f[2] += mass * G - RHO * G * vol   # weight and buoyancy out (balanced or not, the orbit's test)
            return np.r_[y[3:], f[:3] / mass]
        u0 = [w * radius, 0.0, 0.0]   # at t = 0, x = 0: u = ωa e^{kz}, w = 0
        t = np.linspace(0, 3 * period, 301)
        sol = solve_ivp(rhs, (0, t[-1]), np.r_[0.0, 0.0, z0, u0], t_eval=t, rtol=1e-10, atol=1e-12)
        return t, sol.y
    t, y = path(RHO * vol)
    # linear particle orbit: started under the crest (x = 0, t = 0), the particle is at the top of
    # its circle moving forward; ξ = ∫u dt = r sin ωt, ζ = ∫w dt = −r(1 − cos ωt) (it sinks after
    # the crest has passed, rises again before the next)
    # Second order, both known in closed form: horizontally Stokes's drift ω·k·r² (the field is
    # felt where the body is, as by a fluid particle); vertically the body feels the local
    # acceleration ∂u/∂t only, without the particle's convective (u·∇)u = ∇(|u|²/2) = k·ω²·r²·e_z
    # (|u| = ωr e^{kz} all along the orbit), so it sinks by ½·k·ω²·r²·t² from the particle's path
    np.testing.assert_allclose(y[0], radius * np.sin(w * t) + w * k * radius ** 2 * t, rtol=0, atol=0.01 * radius)
    np.testing.assert_allclose(y[2] - z0, -radius * (1 - np.cos(w * t)) - 0.5 * k * (w * radius * t) ** 2,
                               rtol=0, atol=0.01 * radius)
    quarter = np.argmin(np.abs(t - period / 4))
    assert y[2][quarter] < z0 - 0.9 * radius   # a quarter period after the crest: going down (η falling)
    t, heavy = path(2 * RHO * vol)
    assert np.abs(heavy[0] - radius * np.sin(w * t)).max() > 0.3 * radius


def test_aqwa_drag_and_polar_with_waves_opt_in():
    """AQWA drag (RELATIVE) and the DeepLines polar see current − structure velocity as their
    manuals define; ``waves = true`` (our extension) adds the incident velocity at the
    reference point / at P."""
    a, period = 1.0, 8.0
    comps, ph, env = regular(a, period)
    env.current_speed = 0.5
    w = comps.omega[0]
    k = w * w / G
    z = -4.0
    m = Motion(np.array([0.0, 0.0, z]), np.zeros(3), np.zeros(6), np.zeros(6))
    v = np.diag([1e4, 2e4, 3e4, 0, 0, 0])
    for t in (0.0, 1.0, 2.5):
        ph.at(t)
        u, _, uz = Airy(a, w, 0.0, 0.0).at(0.0, 0.0, z, t)[:3]   # from the potential (tests/airy.py)
        plain = ViscousDrag("d", v, relative=True).load(m, env)
        assert plain[0] == pytest.approx(1e4 * 0.5 * 0.5)
        wet = ViscousDrag("d", v, relative=True, waves=True).load(m, env)
        assert wet[0] == pytest.approx(1e4 * (0.5 + u) * abs(0.5 + u), rel=1e-12)
        assert wet[2] == pytest.approx(3e4 * uz * abs(uz), rel=1e-12)
        polar = CurrentPolar("p", np.array([0.0, 90.0, 180.0, 270.0]), np.array([1.0, 0.0, -1.0, 0.0]),
                             np.zeros(4), np.zeros(4), 0.0, 0.0, 0.0, 10.0)
        assert polar.load(held(z=z), env)[0] == pytest.approx(0.5 * RHO * 10.0 * 0.25)
        polar.waves = True
        assert polar.load(held(z=z), env)[0] == pytest.approx(0.5 * RHO * 10.0 * (0.5 + u) ** 2, rel=1e-12)
    with pytest.raises(ValueError, match="RELATIVE"):
        ViscousDrag("d", v, relative=False, waves=True)


def test_conb_node_feels_the_waves():
    """A CONB node (a LumpedBody carried by side A at the joint point) gets the same wave drag
    and inertia as a BODY at that point."""
    comps, ph, env = regular(1.0, 7.0)
    node = LumpedBody("n", np.zeros(3), am=10.0, ae=0.2, cd=np.array([500.0, 500.0, 500.0]),
                      added_mass=np.array([80.0, 80.0, 80.0]))
    joint = BallJoint("j", np.array([2.0, 0.0, -5.0]), np.array([2.0, 0.0, -5.0]), 0.0, 0.0, node=node)
    body = LumpedBody("b", np.array([2.0, 0.0, -5.0]), am=10.0, ae=0.2, cd=np.array([500.0, 500.0, 500.0]),
                      added_mass=np.array([80.0, 80.0, 80.0]))
    for t in (0.3, 2.0, 5.1):
        ph.at(t)
        load_a, _ = joint.loads(held(), None, env)
        np.testing.assert_allclose(load_a, body.load(held(), env), rtol=1e-14, atol=1e-9)
        assert abs(load_a[0]) > 1.0


def test_joined_barges_clump_with_and_without_waves(tmp_path):
    """models/joined_barges.toml in a JONSWAP sea (bench.kinematics_cost.joined_barges_clump):
    the clump's load in the run against the Morison formula written here from the run's own
    motion of barge A (Airy from its potential, tests/airy.py, Wheeler-stretched, at the clump's
    instantaneous position; current 1 m/s at 10°; centripetal part), to 1e-11 of its range; without waves its surge load is the
    steady current drag; the plot is written."""
    from hydrofmu.bench import kinematics_cost
    from hydrofmu.physics.kinematics import rotation
    from hydrofmu.scene import load_scene
    res = kinematics_cost.joined_barges_clump(tmp_path, stop=30.0)
    scene = load_scene(tmp_path / "joined_barges_waves.toml")
    clump = next(e for e in scene.bodies["barge_a"].effects if e.name == "clump").data
    comps = waves.components(scene.waves)
    r = res["current and waves"]
    airy = Airy.of(comps)
    uc = np.array([math.cos(math.radians(10.0)), math.sin(math.radians(10.0)), 0.0])
    cd, am, ae, added = np.array(clump["cd"]), clump["am"], clump["ae"], np.array(clump["added_mass"])
    got, want = [], []
    for i, t in list(enumerate(r.time))[::3]:   # (every third sample: the reference costs 1 ms)
        x, att, v = (np.array([r[f"barge_a_dynamics.{q}[{j}]"][i] for j in range(1, n + 1)])
                     for q, n in (("position", 3), ("attitude", 3), ("velocity", 6)))
        off = rotation(att) @ np.array(clump["offset"])
        p = x + off
        rr = waves.ramp(t, scene.waves.ramp)
        # Airy from its potential (tests/airy.py), Wheeler-stretched (deep: z' = z − η)
        eta = airy.at(p[0], p[1], 0.0, t, rr)[7]
        u, a = np.split(airy.at(p[0], p[1], p[2] - eta, t, rr)[:6], 2)
        omega = v[3:]
        rel = uc + u - (v[:3] + np.cross(omega, off))
        f = cd * rel * np.abs(rel) + RHO * ae * a + added * a - (am + added) * np.cross(omega, np.cross(omega, off))
        f[2] += RHO * G * ae - am * G
        want.append(f)
        got.append([r[f"barge_a.clump.force[{j}]"][i] for j in (1, 2, 3)])
    got, want = np.array(got), np.array(want)
    assert np.all(np.abs(got - want) <= 1e-11 * np.ptp(want, axis=0).max())
    calm = np.asarray(res["current only"]["barge_a.clump.force[1]"])
    surge = got[:, 0]
    assert np.ptp(calm[50:]) < 0.05 * np.ptp(surge[50:])   # the calm load barely moves; the waves' does
    png = kinematics_cost.plot_clump(res, tmp_path / "clump.png")
    assert png.read_bytes()[:4] == b"\x89PNG"


def box_surface(centre, half, n=8):
    """Gauss–Legendre nodes (P, 3), outward normals (P, 3) and weights (P,) [m²] on the six
    faces of a box of half-sides ``half`` about ``centre``."""
    x, w = np.polynomial.legendre.leggauss(n)
    pts, normals, weights = [], [], []
    for axis in range(3):
        a, b = [i for i in range(3) if i != axis]
        u, v = np.meshgrid(x, x, indexing="ij")
        ww = np.outer(w, w).ravel() * half[a] * half[b]
        for side in (-1.0, 1.0):
            p = np.zeros((u.size, 3))
            p[:, axis] = side * half[axis]
            p[:, a], p[:, b] = u.ravel() * half[a], v.ravel() * half[b]
            nrm = np.zeros_like(p)
            nrm[:, axis] = side
            pts.append(p + centre), normals.append(nrm), weights.append(ww)
    return np.vstack(pts), np.vstack(normals), np.concatenate(weights)


@pytest.mark.parametrize("spectrum, depth", [("regular", math.inf), ("spread", 30.0), ("jonswap", 8.0)])
def test_froude_krylov_on_a_small_body_is_rho_v_a(spectrum, depth, tmp_path):
    """Gauss: the incident pressure on a small submerged body, −∮p·n dS with the total
    pressure p = p_d − ρg·z of the kinematics integrated here over a box (half-sides 0.5, 0.3,
    0.4 m, 8×8 Gauss points a face), equals ρ·V·(a + g·e_z) in every direction: the RIFLEX
    BODY's ρ·AE·a_w + ρ·g·AE (AE = V), kernel and load FMU (both flavours), and ρ·V times a
    named point's acceleration.  The box's mean acceleration differs from the centre's by
    Σ r_i²/6·∂²a/∂x_i² (harmonic a: zero for a cube) and higher orders: for each component at
    most (k·r_max)²/6·(1 + (k·r_max)²) of its acceleration amplitude ω²·a·F_h, the tolerance.
    (Stretching none: the body stays below the troughs, Airy as it stands.)"""
    from test_wave_laws import SEAS, Flavour, Sea, built, scene_text, sea_state
    centre, half = np.array([4.0, -3.0, -5.0 if depth > 10 else -4.5]), np.array([0.5, 0.3, 0.4])
    where = tuple(float(c) for c in centre)
    vol = float(8 * half.prod())
    comps = waves.components(sea_state(spectrum, depth, "none"))
    kin, ph = WaveKinematics(comps, G, depth), Phasors(comps)
    pts, normals, weights = box_surface(centre, half)
    sea = Sea(comps, depth)
    kr = sea.k * half.max()
    tol = np.sum(sea.w ** 2 * sea.a * sea.factor(centre[2] + half[2]) * kr ** 2 / 6 * (1 + kr ** 2)) * RHO * vol
    effect = ('[[bodies.b.effects]]\ntype = "riflex_body"\nname = "box"\n'
              f'offset = [{centre[0]}, {centre[1]}, {centre[2]}]\nam = 0.0\nae = {vol!r}\n')
    fmu, unzipped = built(tmp_path, scene_text(spectrum, depth, "none", {"c": where}, effects=effect))
    steps = 100
    names = [f"box.force[{i}]" for i in (1, 2, 3)] + [f"waves.c.acceleration[{i}]" for i in (1, 2, 3)]
    fmu_rows = {f: Flavour(fmu, unzipped, f).outputs(names, steps) for f in ("python", "c")}
    body = LumpedBody("box", centre, am=0.0, ae=vol)
    env = Env(RHO, G, water=Water(WaveKinematics(comps, G, depth), ph, RHO))
    buoyancy = RHO * G * vol * np.array([0.0, 0.0, 1.0])
    for i in range(0, steps, 10):
        t = (i + 1) * 0.01
        rows = kin.at(ph.at(t), 1.0, pts, RHO)
        assert np.all(rows[:, 7] > pts[:, 2])   # all wet
        p = rows[:, 6] - RHO * G * pts[:, 2]
        gauss = -(p * weights) @ normals
        kernel = body.load(held(), env)[:3]
        for got in [kernel] + [r[i, :3] for r in fmu_rows.values()] + \
                [RHO * vol * r[i, 3:] + buoyancy for r in fmu_rows.values()]:
            assert np.all(np.abs(got - gauss) <= tol), (t, got - gauss, tol)
    assert tol < 0.01 * RHO * vol * sea.scale(0, 2, centre[2])   # a small body: kr ≲ 0.2
    # the difference is the box's shape, of order (kr)²: a cube of the same volume feels ρ·V·a to (kr)⁴
    cube = np.full(3, vol ** (1 / 3) / 2)
    pts, normals, weights = box_surface(centre, cube)
    rows = kin.at(ph.at(1.0), 1.0, pts, RHO)
    gauss = -((rows[:, 6] - RHO * G * pts[:, 2]) * weights) @ normals
    kc = sea.k * cube[0]
    tol4 = np.sum(sea.w ** 2 * sea.a * sea.factor(centre[2] + cube[2]) * kc ** 4 / 10) * RHO * vol
    ph.at(1.0)
    assert np.all(np.abs(body.load(held(), env)[:3] - gauss) <= tol4) and tol4 < 0.05 * tol
