"""Our kinematics and slice loads against OpenFAST HydroDyn on the same cases
(tests/data/peers/hydrodyn/, README there), each settled against theory first: the Airy
field and the closed-form Morison integral over the column.

Cases: held vertical cylinder R 1 m, regular wave H 4 m, T 8 s along +x, depth 200 m,
η(0, 0, t) = 2·cos ωt.  Our scenes are the peer folder's: 40 RIFLEX BODY slices of 0.5 m
(AE = πR²·dz, AMX = AMY = ρ·Ca·πR²·dz, CDX = CDY = ½ρ·Cd·2R·dz) at the slices' mid-heights,
loads summed about the origin.  HydroDyn's member: strip theory on 0.5 m divisions, its
kinematics interpolated on a grid (about 1e-5 of the amplitude, the peer's README).

What the slices can and cannot match.  Horizontally they are the midpoint rule of the strip
integral: ∫f dz − dz·Σf(z_i) ≤ L·dz²/24·max|f''| (L the length), the bound these tests derive
from each integrand (f'' by differences on a fine grid).  A slice is a point: it is all wet or
all dry, so the surface-piercing cases compare only while every slice is wet (η ≥ −0.25 m);
HydroDyn there integrates to the still-water line whatever η (`WaveStMod 0`).  Vertically a
stack of slices feels ρ·πR²·∫a_z dz = πR²·(p_d(bottom) − p_d(top)): for the submerged column
(both end plates wet) that is the plates' Froude–Krylov exactly; for a surface-piercing one it
adds a lid at z = 0 that is not there, −πR²·p_d(0) = −ρg·η·πR² (3.5 times the bottom plate's
load at the crest), so the slices cannot match it: the member effect's wetted-length
integration and end plates are for that (issue 37, items 3–4).
"""
import gzip
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import quad

from airy import wave_number

PEER = Path(__file__).parent / "data" / "peers" / "hydrodyn"
RHO, G, DEPTH, A_WAVE, W = 1025.0, 9.81, 200.0, 2.0, 2 * math.pi / 8.0
R, AREA, DZ, CM, CD, U = 1.0, math.pi, 0.5, 2.0, 0.7, 0.5
DT, STEPS = 0.05, 200                 # the peer's step; 10 s: 1.25 periods
INTERPOLATION = 1e-5                  # the peer's kinematics interpolation, of each amplitude


def peer(case):
    """HydroDyn's output table {column: values} (6 header lines, names, units, rows)."""
    lines = gzip.open(PEER / f"{case}.out.gz", "rt").read().splitlines()
    names = [n.strip() for n in lines[6].split("\t")]
    rows = np.array([[float(x) for x in line.split()] for line in lines[8:] if line.strip()])
    return {n: rows[:, i] for i, n in enumerate(names)}


K = float(wave_number(W, DEPTH))


def airy(z, t):
    """(u, a_x, a_z, p_d) of the regular wave at (0, 0, z), textbook Airy: η = a·cos ωt."""
    fh = np.cosh(K * (z + DEPTH)) / np.sinh(K * DEPTH)
    fv = np.sinh(K * (z + DEPTH)) / np.sinh(K * DEPTH)
    fp = np.cosh(K * (z + DEPTH)) / np.cosh(K * DEPTH)
    c, s = np.cos(W * t), np.sin(W * t)
    return W * A_WAVE * fh * c, -W * W * A_WAVE * fh * s, -W * W * A_WAVE * fv * c, RHO * G * A_WAVE * fp * c


def ours(case, tmp, flavour, slices=True):
    """The pile's load FMU (test_wave_laws.Flavour) of the peer folder's scene ``case``
    (``slices`` False: without its effects, the named points alone)."""
    from test_wave_laws import Flavour
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    path = PEER / f"{case}.toml"
    if not slices:
        text = path.read_text()
        path = Path(tmp) / f"{case}.toml"
        path.write_text(text[:text.index("[[bodies.pile.effects]]")])
    folder = build_scene(load_scene(path), Path(tmp) / "fmus", log=lambda *_: None, runtime="c")
    fmu, unzipped = folder / f"{case}_pile.fmu", Path(tmp) / f"{case}_{flavour}"
    if not unzipped.exists():
        with zipfile.ZipFile(fmu) as z:
            z.extractall(unzipped)
    return Flavour(fmu, unzipped, flavour, flavour)


def midpoint_bound(f, lo, hi, times):
    """L·dz²/24·max|f''| over [lo, hi] and the times (the midpoint rule's error bound),
    f'' by second differences on a 1 mm grid."""
    z = np.linspace(lo, hi, int((hi - lo) / 1e-3) + 1)
    worst = 0.0
    for t in times:
        v = f(z, t)
        worst = max(worst, np.abs(np.diff(v, 2)).max() / 1e-6)
    return (hi - lo) * DZ ** 2 / 24 * worst


def strip(f, lo, hi, t):
    """∫ f(z, t) dz over [lo, hi] at the times t: Gauss–Legendre, 8 nodes on each of 200
    panels (the drag's |s|·s is C¹: a panel holding its kink errs by ~panel³·Δf'', 1e-7 of the
    load here; held against scipy's adaptive quadrature at one time)."""
    x, w = np.polynomial.legendre.leggauss(8)
    edges = np.linspace(lo, hi, 201)
    half = (edges[1] - edges[0]) / 2
    z = ((edges[:-1] + edges[1:]) / 2)[:, None] + half * x[None, :]
    out = np.array([np.sum(f(z, tt) * w) * half for tt in t])
    check = quad(lambda zz: float(f(np.array([zz]), t[3])[0]), lo, hi, epsabs=0, epsrel=1e-10, limit=400)[0]
    assert abs(out[3] - check) <= 1e-7 * np.abs(out).max()
    return out


@pytest.mark.parametrize("flavour", ["python", "c"])
def test_wheeler_point_kinematics_equal_hydrodyn(flavour, tmp_path):
    """k_wheeler: velocity, acceleration and dynamic pressure at (0,0,−5), (0,0,−15),
    (10,0,−2), (0,0,+1) under Wheeler stretching, and the elevation, within the peer's
    interpolation error (1e-5 of ω·a, ω²·a, ρ·g·a, a) while the point is wet; where ours is
    dry (the point at +1 m above the surface) HydroDyn gives 0 too."""
    fl = ours("k_wheeler", tmp_path, flavour, slices=False)
    got = fl.record(["p1", "p2", "p3", "p4"], STEPS, dt=DT)
    ref = peer("k_wheeler")
    scale = np.array([W * A_WAVE] * 3 + [W * W * A_WAVE] * 3 + [RHO * G * A_WAVE])
    for j, (name, z) in enumerate((("p1", -5.0), ("p2", -15.0), ("p3", -2.0), ("p4", 1.0)), 1):
        row = got[name][0]
        cols = [f"FVel{j}{a}i" for a in "xyz"] + [f"FAcc{j}{a}i" for a in "xyz"] + [f"FDynP{j}"]
        theirs = np.column_stack([ref[c][1:STEPS + 1] for c in cols])
        wet = row[:, 7] >= z
        assert wet.sum() > 50
        assert np.all(np.abs(row[wet, :7] - theirs[wet]) <= INTERPOLATION * scale), name
        assert np.all(theirs[~wet] == 0.0) and np.all(row[~wet, :7] == 0.0), name
        if name != "p3":   # Wave1Elev is at (0, 0)
            assert np.all(np.abs(row[:, 7] - ref["Wave1Elev"][1:STEPS + 1]) <= INTERPOLATION * A_WAVE)


def test_submerged_column_loads_equal_theory_and_hydrodyn(tmp_path):
    """m_submerged (z = −25 … −5 m, both end plates wet, Ca 1, Cd 0): ours (both flavours)
    and HydroDyn against the closed forms — horizontal ρ·C_M·πR²·∫a_x dz, its moment
    ∫z·dF about the origin, vertical ρg·V + πR²·(p_d(−25) − p_d(−5)) (the end plates' FK: a
    closed body, Gauss).  Ours within the midpoint rule's bound, HydroDyn within its
    trapezoid rule's (nodes at the division ends: twice the midpoint's, opposite sign) plus its
    interpolation, the two within the sum.  The vertical FK has the closed form's sign (before
    4c78ca3 it was its negative)."""
    lo, hi = -25.0, -5.0
    ref = peer("m_submerged")
    t = ref["Time"][1:STEPS + 1]
    fx = lambda z, tt: RHO * CM * AREA * airy(z, tt)[1]          # noqa: E731
    my = lambda z, tt: z * fx(z, tt)                              # noqa: E731
    fz = lambda z, tt: RHO * AREA * airy(z, tt)[2]                # noqa: E731
    closed = np.column_stack([strip(f, lo, hi, t) for f in (fx, my, fz)])
    plates = RHO * G * AREA * (hi - lo) + AREA * (airy(lo, t)[3] - airy(hi, t)[3])
    assert np.allclose(closed[:, 2] + RHO * G * AREA * (hi - lo), plates, rtol=1e-9)   # Gauss
    closed[:, 2] = plates
    peer_cols = np.column_stack([ref["HydroFxi"], ref["HydroMyi"], ref["HydroFzi"]])[1:STEPS + 1]
    runs = {}
    for flavour, n in (("c", STEPS), ("python", STEPS // 5)):   # (the Python flavour: 2 s, 40 slices cost)
        got = runs[flavour] = ours("m_submerged", tmp_path, flavour).outputs(["force[1]", "force[5]", "force[3]"], n,
                                                                              dt=DT)
        for i, f in enumerate((fx, my, fz)):
            mid = midpoint_bound(f, lo, hi, t[::10])
            interp = INTERPOLATION * np.abs(closed[:, i]).max()
            assert np.all(np.abs(got[:, i] - closed[:n, i]) <= mid), (flavour, i)
            assert np.all(np.abs(peer_cols[:, i] - closed[:, i]) <= 2 * mid + interp), i
            assert np.all(np.abs(got[:, i] - peer_cols[:n, i]) <= 3 * mid + interp), (flavour, i)
    # at the crest (t = 8 s) the top plate, under more water, pushes down: −33.0 kN of FK
    crest = int(np.argmin(np.abs(t - 8.0)))
    fk = runs["c"][crest, 2] - RHO * G * AREA * (hi - lo)
    assert -3.31e4 < fk < -3.29e4 and abs(peer_cols[crest, 2] - RHO * G * AREA * (hi - lo) - fk) < 10.0


@pytest.mark.parametrize("case", ["m_inertia", "m_drag_current"])
def test_surface_piercing_column_loads_against_theory_and_hydrodyn(case, tmp_path):
    """m_inertia (Ca 1, Cd 0) and m_drag_current (Cd 0.7, current 0.5 m/s along +x), z = −20 m
    to the still-water line: while every slice is wet (η ≥ −0.25 m), our horizontal force and
    moment (both flavours) equal the strip integral ∫[ρC_M·πR²·a_x + ½ρ·Cd·2R·(U + u)|U + u|]dz
    to its midpoint bound (the compiled flavour; the Python one is held equal to it by
    test_compiled and on the submerged column here).  HydroDyn's moment equals the integral to its own interpolation and
    integration error too, its force is 6.0e-4 of its peak below it in both cases (measured:
    −5.98e-4, −5.91e-4), a force with no lever arm, i.e. a load missing at the still-water line:
    the one disagreement that remains, on HydroDyn's side by theory.  Vertically the slices sum
    a lid at z = 0 (module docstring): ours is ρgV + πR²·(p_d(−20) − p_d(0)) and HydroDyn's the
    column's ρgV + πR²·p_d(−20) to 1e-5 of the bottom plate's load."""
    lo, hi = -20.0, 0.0
    ref = peer(case)
    t = ref["Time"][1:STEPS + 1]
    wet = A_WAVE * np.cos(W * t) >= -DZ / 2
    cd = CD if case == "m_drag_current" else 0.0
    uc = U if case == "m_drag_current" else 0.0

    def fx(z, tt):
        u, ax, _, _ = airy(z, tt)
        return RHO * CM * AREA * ax + 0.5 * RHO * cd * 2 * R * (uc + u) * np.abs(uc + u)
    my = lambda z, tt: z * fx(z, tt)   # noqa: E731
    closed = np.column_stack([strip(f, lo, hi, t) for f in (fx, my)])
    scale = np.abs(closed).max(axis=0)
    peer_cols = np.column_stack([ref["HydroFxi"], ref["HydroMyi"]])[1:STEPS + 1]
    off = np.abs(peer_cols - closed).max(axis=0) / scale
    assert 5e-4 < off[0] < 7e-4 and off[1] < 2e-5, off   # HydroDyn: force short at the surface, moment right
    buoyancy = RHO * G * AREA * (hi - lo)
    column = buoyancy + AREA * airy(lo, t)[3]
    assert np.all(np.abs(ref["HydroFzi"][1:STEPS + 1] - column) <= INTERPOLATION * RHO * G * A_WAVE * AREA)
    for flavour in ("c",):   # (the Python flavour: the submerged column's test, and test_compiled)
        got = ours(case, tmp_path, flavour).outputs(["force[1]", "force[5]", "force[3]"], STEPS, dt=DT)
        assert wet.sum() > 100
        for i, f in enumerate((fx, my)):
            mid = midpoint_bound(f, lo, hi, t[wet][::10])
            assert np.all(np.abs(got[wet, i] - closed[wet, i]) <= mid), (flavour, i)
        slices = buoyancy + AREA * (airy(lo, t)[3] - airy(hi, t)[3])
        mid_z = midpoint_bound(lambda z, tt: RHO * AREA * airy(z, tt)[2], lo, hi, t[::10])
        assert np.all(np.abs(got[wet, 2] - slices[wet]) <= mid_z), flavour
        # the lid: ours − HydroDyn's vertical = −ρg·η·πR² at the mean level
        lid = -RHO * G * A_WAVE * np.cos(W * t) * AREA
        assert np.all(np.abs(got[wet, 2] - ref["HydroFzi"][1:STEPS + 1][wet] - lid[wet])
                      <= mid_z + INTERPOLATION * RHO * G * A_WAVE * AREA)
