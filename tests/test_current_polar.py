"""*CURRENTPOL symmetry expansion, circle coverage and the CurrentPolar kernel."""
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from hydrofmu.decks.deeplines import CurrentPolarData, read_current_polars
from hydrofmu.errors import InputError
from hydrofmu.physics.current_polar import CurrentPolar, expand_polar
from hydrofmu.physics.state import Env, Motion

DATA = Path(__file__).parent / "data" / "deeplines"


def manual():
    return read_current_polars(DATA / "currentpol_manual.dat")["FPSO"]


def polar(rows, xc=0.0, yc=0.0, zc=0.0, surfc=100.0, name="T"):
    """CurrentPolarData from rows (angle, cx, cy, cmz); row i on line 3 + i like a deck."""
    t = np.array(rows, float)
    return CurrentPolarData(name, xc, yc, zc, surfc, t[:, 0], t[:, 1], t[:, 2], t[:, 3],
                            "tab.dat", 1, [3 + i for i in range(len(t))])


def raises(data, symmetry, line, field):
    with pytest.raises(InputError) as exc:
        expand_polar(data, symmetry)
    err = exc.value
    assert (err.line, err.field) == (line, field), str(err)
    assert f"{Path(data.path).name}:{line}: {field}:" in str(err)
    return str(err)


# ---- symmetry expansion and coverage -------------------------------------------------

def test_manual_example_needs_both_mirrors():
    angles, cx, cy, cmz = expand_polar(manual(), "xz+yz")
    # Given rows (1, 0, 0, 0), (45, 1.14, 1.14, 0.2), (90, 0, -1, 0), mirrored by hand:
    # xz (360−α, CX, −CY, −CMZ), yz (180−α, −CX, CY, −CMZ), both (180+α, −CX, −CY, CMZ).
    table = {
        1: (0, 0, 0), 45: (1.14, 1.14, 0.2), 90: (0, -1, 0),
        359: (0, 0, 0), 315: (1.14, -1.14, -0.2), 270: (0, 1, 0),
        179: (0, 0, 0), 135: (-1.14, 1.14, -0.2),
        181: (0, 0, 0), 225: (-1.14, -1.14, 0.2),
    }
    keys = sorted(table)
    np.testing.assert_array_equal(angles, keys)
    np.testing.assert_allclose(np.column_stack([cx, cy, cmz]), [table[k] for k in keys])


@pytest.mark.parametrize("symmetry", ["none", "xz", "yz"])
def test_manual_example_rejected_without_both(symmetry):
    msg = raises(manual(), symmetry, 1, "symmetry")
    assert "currentpol_manual.dat" in msg and "NAME=FPSO" in msg and "'xz+yz' would complete it" in msg


def test_half_table_with_port_starboard_symmetry():
    rows = [(0, 1.0, 0, 0), (60, 0.5, 0.8, 2.0), (120, -0.4, 0.9, -1.0), (180, -0.9, 0, 0)]
    angles, cx, cy, cmz = expand_polar(polar(rows), "xz")
    np.testing.assert_array_equal(angles, [0, 60, 120, 180, 240, 300])
    np.testing.assert_allclose(cx, [1.0, 0.5, -0.4, -0.9, -0.4, 0.5])
    np.testing.assert_allclose(cy, [0, 0.8, 0.9, 0, -0.9, -0.8])
    np.testing.assert_allclose(cmz, [0, 2.0, -1.0, 0, 1.0, -2.0])
    assert "'xz' would complete it" in raises(polar(rows), "none", 1, "symmetry")


def test_full_table_passes_none_and_consistent_symmetry():
    barge = read_current_polars(DATA / "currentpol_multi.dat")["BARGE"]
    for sym in ("none", "xz"):
        angles, cx, cy, cmz = expand_polar(barge, sym)
        np.testing.assert_array_equal(angles, barge.angles)
        np.testing.assert_array_equal(cy, barge.cy)
    # Fore/aft mirror of 0° is 180°: CX would be −0.80, the table says −0.85; the first
    # contradiction by angle is reported at the given row 0° (line 7).
    msg = raises(barge, "yz", 7, "CXC")
    assert "currentpol_multi.dat" in msg


def test_row_at_360_merges_with_0():
    spar = read_current_polars(DATA / "currentpol_multi.dat")["SPAR"]
    angles, cx, _, _ = expand_polar(spar, "none")
    np.testing.assert_array_equal(angles, [0, 90, 180, 270])
    np.testing.assert_array_equal(cx, [0.9, 0, -0.9, 0])
    rows = [(0, 1, 0, 0), (90, 0, 1, 0), (180, -1, 0, 0), (270, 0, -1, 0), (360, 0.8, 0, 0)]
    raises(polar(rows), "none", 7, "CXC")


@pytest.mark.parametrize("sym, rows, line, field", [
    # xz maps 0° and 180° onto themselves: CY and CMZ must vanish there.
    ("xz", [(0, 1, 0.1, 0), (90, 0, 1, 0), (180, -1, 0, 0)], 3, "CYC"),
    ("xz", [(0, 1, 0, 0), (90, 0, 1, 0), (180, -1, 0, 0.5)], 5, "CMZC"),
    # yz maps 90° onto itself: CX and CMZ must vanish there (and 270°).
    ("yz", [(90, 0.2, 1, 0), (180, -1, 0, 0), (270, 0, -1, 0)], 3, "CXC"),
    ("xz+yz", [(0, 1, 0, 0), (45, 0.7, 0.7, 0), (90, 0, 1, 0.3)], 5, "CMZC"),
])
def test_symmetry_contradicting_data(sym, rows, line, field):
    assert f"symmetry {sym!r} contradicts" in raises(polar(rows), sym, line, field)


def test_load_point_off_mirror_plane():
    rows = [(0, 1, 0, 0), (90, 0, 1, 0), (180, -1, 0, 0)]
    raises(polar(rows, yc=2.0), "xz", 1, "YC")
    raises(polar([(0, 1, 0, 0), (90, 0, 1, 0)], xc=-5.0), "xz+yz", 1, "XC")


def test_coverage_rule():
    # 0..170 by 10 with xz leaves 170°→190° (20° > 10°); xz+yz fills it.
    rows = [(a, np.cos(np.radians(a)), 0.0, 0.0) for a in range(0, 180, 10)]
    assert "'xz+yz' would complete it" in raises(polar(rows), "xz", 1, "symmetry")
    assert len(expand_polar(polar(rows), "xz+yz")[0]) == 36
    # A 120° step fails with "none"; CY ≠ 0 at 0° rules out xz, CX ≠ 0 at 90° rules out yz.
    coarse = [(0, 1, 0.2, 0), (90, 0.3, 1, 0), (180, -1, 0, 0), (300, 0.5, -0.8, 0)]
    assert "no symmetry completes it" in raises(polar(coarse), "none", 1, "symmetry")
    # Steps of 120° consistent with fore/aft symmetry: yz fills in 60°, 180°, 300°.
    tri = [(0, 1, 0, 0), (120, -0.5, 0.8, 0), (240, -0.5, -0.8, 0)]
    assert "'yz' or 'xz+yz' would complete it" in raises(polar(tri), "none", 1, "symmetry")
    np.testing.assert_array_equal(expand_polar(polar(tri), "yz")[0], [0, 60, 120, 180, 240, 300])
    raises(polar(rows), "diagonal", 1, "symmetry")
    raises(polar([(0, 1, 0, 0), (200, 0, 1, 0), (100, -1, 0, 0)]), "none", 1, "ANGC")


# ---- kernel ---------------------------------------------------------------------------

def rot(att):
    """Body-to-global R = Rz(ψ)·Ry(θ)·Rx(φ): intrinsic z-y'-x'' Euler angles (scipy)."""
    return Rotation.from_euler("ZYX", att[::-1]).as_matrix()


def expected(k, att, vel, u, rho):
    """The README's formula (DeepLines `*CURRENTPOL`) written out with np.interp(period=360)."""
    r = rot(att)
    p = r @ np.array([k.xc, k.yc, k.zc])
    vb = r.T @ (u - (vel[:3] + np.cross(vel[3:], p)))
    v2 = vb[0] ** 2 + vb[1] ** 2
    a = np.degrees(np.arctan2(vb[1], vb[0])) % 360
    c = [np.interp(a, k.angles, t, period=360) for t in (k.cx, k.cy, k.cmz)]
    q = 0.5 * rho * k.surfc * v2
    f = r @ np.array([q * c[0], q * c[1], 0.0])
    return np.concatenate([f, np.cross(p, f) + r @ np.array([0, 0, q * c[2]])])


def test_manual_fpso_hand_load_with_moment_transfer():
    # Body yawed 90° at rest; current 2 m/s going to 135° → body incidence 45°.
    # q·V² = ½·1025·1000·4 = 2.05e6; F_body = 2.05e6·(1.14, 1.14), Mz = 2.05e6·0.2 = 4.1e5.
    # R maps body (x, y) to global (−y, x): F = (−2.337e6, 2.337e6, 0).
    # P = (0, 0, 10): r × F = (−10·Fy, 10·Fx, 0) = (−2.337e7, −2.337e7, 0).
    k = CurrentPolar.from_deck(manual(), "xz+yz")
    motion = Motion(attitude=np.array([0.0, 0.0, np.pi / 2]))
    got = k.load(motion, Env(rho=1025.0, current_speed=2.0, current_direction=135.0))
    np.testing.assert_allclose(got, [-2.337e6, 2.337e6, 0, -2.337e7, -2.337e7, 4.1e5], rtol=1e-12, atol=1e-6)
    assert k.name == "FPSO" and k.uses_current and not k.uses_acceleration


def test_interpolation_across_wrap():
    # Table steps 350° → 10° across 0°; incidences 355° and 5° sit a quarter and three
    # quarters of the way.
    angles = [10.0, 100.0, 190.0, 280.0, 350.0]
    cx, cy, cmz = [1.0, 0.0, -1.0, 0.0, 0.6], [0.2, 1.0, 0.0, -1.0, -0.2], [3.0, 0, 0, 0, -1.0]
    k = CurrentPolar("w", angles, cx, cy, cmz, 0.0, 0.0, 0.0, 10.0)
    for alpha, t in ((355.0, 0.25), (5.0, 0.75)):
        want = [0.6 + t * 0.4, -0.2 + t * 0.4, -1.0 + t * 4.0]
        np.testing.assert_allclose(k.coefficients(alpha), want, rtol=1e-12)
        # Same incidence from a yawed body at rest: body yaw 20°, current going to 20° + α.
        psi = np.radians(20.0)
        got = k.load(Motion(attitude=np.array([0, 0, psi])),
                     Env(rho=1000.0, current_speed=3.0, current_direction=20.0 + alpha))
        q = 0.5 * 1000.0 * 10.0 * 9.0
        fb = q * np.array(want[:2])
        f = [np.cos(psi) * fb[0] - np.sin(psi) * fb[1], np.sin(psi) * fb[0] + np.cos(psi) * fb[1], 0]
        np.testing.assert_allclose(got, [*f, 0, 0, q * want[2]], rtol=1e-12, atol=1e-9)
    grid = np.linspace(0, 359.999, 721)
    np.testing.assert_allclose([k.coefficients(a)[0] for a in grid], np.interp(grid, angles, cx, period=360))


@pytest.mark.parametrize("att", [(0.0, 0.0, 0.0), (0.15, -0.1, 2.5), (-0.3, 0.25, -1.2)])
def test_general_motion_roll_pitch_yaw(att):
    data = polar([(a, np.cos(np.radians(a)) + 0.1, 0.8 * np.sin(np.radians(a)), 5 * np.sin(np.radians(2 * a)))
                  for a in range(0, 360, 15)], xc=12.0, yc=-3.0, zc=-8.0, surfc=800.0)
    k = CurrentPolar.from_deck(data, "none")
    att = np.array(att)
    vel = np.array([0.4, -0.3, 0.1, 0.02, -0.03, 0.05])
    env = Env(rho=1025.0, current_speed=1.1, current_direction=250.0)
    np.testing.assert_allclose(k.load(Motion(attitude=att, velocity=vel), env),
                               expected(k, att, vel, env.current, 1025.0), rtol=1e-10, atol=1e-8)


def test_zero_relative_velocity_gives_zero_load():
    k = CurrentPolar.from_deck(manual(), "xz+yz")
    env = Env(current_speed=0.7, current_direction=33.0)
    for motion, e in ((Motion(), Env()),
                      (Motion(attitude=np.array([0.1, 0.2, 0.3]),
                              velocity=np.concatenate([env.current, np.zeros(3)])), env)):
        got = k.load(motion, e)
        assert np.all(np.isfinite(got))
        np.testing.assert_allclose(got, 0.0, atol=1e-9)
    np.testing.assert_array_equal(k.mass_matrix(Motion()), np.zeros((6, 6)))


def test_kernel_rejects_unsorted_angles():
    with pytest.raises(ValueError):
        CurrentPolar("x", [0, 200, 100], [0, 0, 0], [0, 0, 0], [0, 0, 0], 0, 0, 0, 1)
    with pytest.raises(ValueError):
        CurrentPolar("x", [0, 360], [0, 0], [0, 0], [0, 0], 0, 0, 0, 1)
