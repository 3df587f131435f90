"""BEM results checked by laws their excitation and radiation obey together (decks/bem_laws.py),
as checks of each reader's conventions (decks/bem.py, decks/bem_waves.py: Capytaine datasets,
WAMIT .1/.3 as WAMIT writes them), and the build warning for a user's dataset that breaks them.

- Haskind: B_ij = k/(8πρg·c_g)·Re∫X_i·X̄_j dβ, c_g the group velocity at the depth, on the
  test datasets (tests/data/bem/: make_waves_data.py, make_barge_data.py; wamit_sphere/ from a
  WAMIT run): a pair of cylinders over the whole circle (deep), one cylinder on 0…90°, on the
  0/45/90° grid and on one heading (axisymmetric: the headings completed by the symmetry its
  radiation coefficients show), a box barge in 12 m of water on the whole circle and on
  0/45/90° (two symmetry planes), the WAMIT hemisphere in 50 m on one heading.  Measured worst
  misfits, of √(peak B_ii·peak B_jj): 2.5 % (pair), 4.5 % (cylinder: surge at 4 rad/s, the
  coarse mesh), 3.0 % (barge), 0.02 % (WAMIT): the warning's tolerance is 10 %.
- reciprocity A_ij = A_ji, B_ij = B_ji of every reader (cross-body terms included).
- the warning: silent on clean data; a conjugated copy, a sign-flipped copy (the long-wave
  phase), one dof's sign flipped, a wrong ULEN (Haskind) each said once naming the file; one
  heading of a two-body result: said once that the check is left out.
"""
import math
import re
import warnings
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks import bem_laws
from hydrofmu.decks.bem import read_bem
from hydrofmu.decks.bem_waves import read_excitation

DATA = Path(__file__).parent / "data" / "bem"
SPHERE = DATA / "wamit_sphere"
RHO, G = 1025.0, 9.81


def reading(name):
    """(radiation, excitation) of a test dataset (the WAMIT pair: ULEN 1 m, ρ, g)."""
    if name == "sphere":
        return (read_bem(SPHERE / "sphere.1", 1.0, RHO, G), read_excitation(SPHERE / "sphere.3", 1.0, RHO, G))
    return read_bem(DATA / f"{name}.nc"), read_excitation(DATA / f"{name}.nc")


@pytest.mark.parametrize("name, body, headings, depth, sym", [
    ("wave_pair", "cyl1", None, math.inf, ()),
    ("wave_pair", "cyl2", None, math.inf, ()),
    ("wave_cylinder", "cyl", None, math.inf, ("xz", "yz", "axi")),
    ("wave_cylinder", "cyl", (0, 45, 90), math.inf, ("xz", "yz", "axi")),
    ("wave_cylinder", "cyl", (0,), math.inf, ("xz", "yz", "axi")),
    ("barge_finite", "barge", None, 12.0, ("xz", "yz")),
    ("barge_finite", "barge", (0, 45, 90), 12.0, ("xz", "yz")),
    ("sphere", "body1", None, 50.0, ("xz", "yz", "axi")),
])
def test_haskind_relation_holds_on_clean_data(name, body, headings, depth, sym):
    """Each reader's X and B obey Haskind within the tolerance (the measured worst in the
    module docstring), the symmetry read from the coefficients is the body's, the long-wave
    phase holds; in finite depth the deep-water group velocity breaks the relation (the law
    sees c_g: 20–65 % off on the WAMIT hemisphere)."""
    rad, exc = reading(name)
    damping, added = bem_laws.body_block(rad, body)
    assert (bem_laws.symmetry(damping, added) if len(rad.bodies) == 1 else ()) == sym
    x, beta = exc.body(body), exc.directions
    if headings is not None:
        keep = np.isin(np.round(beta), headings)
        x, beta = x[:, keep], beta[keep]
    position = (exc.rotation_centers.get(body) or [0.0, 0.0])[:2]
    w, from_x, file_b = bem_laws.haskind(exc.omega, beta, x, position, rad.omega, damping, depth, RHO, G, sym)
    assert w.size >= 4
    m = bem_laws.misfit(from_x, file_b)
    assert np.nanmax(m) <= bem_laws.TOLERANCE, np.round(m, 3)
    assert np.nanmax(np.abs(np.diagonal(m))) < 0.05
    assert bem_laws.long_wave_phase(exc.omega, beta, x, position, G, depth) == []
    if not math.isinf(depth):
        deep = bem_laws.haskind(exc.omega, beta, x, position, rad.omega, damping, math.inf, RHO, G, sym)
        assert np.nanmax(bem_laws.misfit(deep[1], deep[2])) > 2 * bem_laws.TOLERANCE


@pytest.mark.parametrize("name, tol", [("wave_pair", 0.15), ("twobody", 0.15), ("barge_finite", 0.15),
                                       ("cylinders", 0.15), ("sphere", 1e-4)])
def test_radiation_coefficients_are_reciprocal(name, tol):
    """A_ij = A_ji and B_ij = B_ji (Green's reciprocity) as read, every pair of live dofs
    (a round body's yaw is the panels' noise), cross-body terms included, of √(peak m_ii·peak
    m_jj): a reader that mixes up a body's dofs or a rotation's sign breaks the strong couplings
    (surge–pitch, sway–roll: ~1 of that scale) by O(1).  Measured: Capytaine's coarse panels
    0.2–8.3 % (the cross-body sway–heave damping of cylinders.nc; twobody.nc's float–spar
    surge added mass 7.0 %): 15 %; WAMIT to its printed digits (< 1e-5)."""
    rad = read_bem(SPHERE / "sphere.1", 1.0, RHO, G) if name == "sphere" else read_bem(DATA / f"{name}.nc")
    rotation = np.array([k > 3 for _, k in rad.dofs])
    for m in (rad.added_mass, rad.damping):
        diag = np.abs(np.einsum("nii->ni", m)).max(axis=0)
        kind = np.where(rotation, diag[rotation].max(), diag[~rotation].max())
        live = np.outer(diag > 1e-6 * kind, diag > 1e-6 * kind)
        asym = np.abs(m - np.swapaxes(m, 1, 2)).max(axis=0) / np.sqrt(np.outer(diag, diag) + 1e-300)
        assert asym[live].max() <= tol, (name, asym[live].max())
        strong = np.abs(m).max(axis=0) >= 0.5 * np.sqrt(np.outer(diag, diag))
        np.fill_diagonal(strong, False)
        assert (strong & live).any()   # couplings that a convention error would break
    if len(rad.bodies) > 1:   # cross-body couplings among them
        a, b = rad.index(rad.bodies[0], 1), rad.index(rad.bodies[1], 1)
        assert abs(rad.added_mass[:, a, b]).max() > 0.05 * abs(rad.added_mass[:, a, a]).max()


SCENE = """
[bodies.b]
position = [0.0, 0.0, 0.0]
mass = 5.0e4
inertia = [1e6, 1e6, 1e6]
stiffness = [1e4, 1e4, 1e5, 1e7, 1e7, 1e6]

[[bodies.b.effects]]
type = "wave_excitation"
bem = "{bem}"
{extra}
[waves]
spectrum = "regular"
height = 1.0
period = {period}
direction = 0.0
{depth}
"""


def copy(tmp, name, change):
    """A copy of tests/data/bem/NAME.nc with its excitation (and its diffraction and
    Froude–Krylov parts) changed by ``change``(complex values, dof names)."""
    import xarray as xr
    ds = xr.load_dataset(DATA / f"{name}.nc")
    dofs = [str(d) for d in ds["influenced_dof"].values]
    for var in ("excitation_force", "diffraction_force", "Froude_Krylov_force"):
        v = ds[var]
        z = change(v.sel(complex="re").values + 1j * v.sel(complex="im").values,
                   dofs, list(v.sel(complex="re").dims).index("influenced_dof"))
        ds[var].loc[{"complex": "re"}] = z.real
        ds[var].loc[{"complex": "im"}] = z.imag
    path = Path(tmp) / f"{name}_changed.nc"
    ds.to_netcdf(path)
    return path


def flip(dof):
    def change(z, dofs, axis):
        sign = np.ones(len(dofs))
        sign[dofs.index(dof)] = -1.0
        shape = [1] * z.ndim
        shape[axis] = -1
        return z * sign.reshape(shape)
    return change


def said(tmp, bem, extra="", period=6.0, depth=""):
    """The warnings of loading a scene with a wave_excitation from ``bem`` that mention it."""
    from hydrofmu.scene import load_scene
    path = Path(tmp) / "s.toml"
    path.write_text(SCENE.format(bem=Path(bem).as_posix(), extra=extra, period=period, depth=depth))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        scene = load_scene(path)
    return [w for w in scene.warnings if Path(bem).name in w and "effects[0].bem" in w]


@pytest.mark.parametrize("case, pattern", [
    ("clean", None),
    ("conjugated", r"lags the elevation at the body by 90° instead of leading it"),
    ("sign-flipped", r"lags the elevation at the body by 90° instead of leading it"),
    ("pitch flipped", r"break the Haskind relation .* in (surge–pitch|roll–sway)"),
])
def test_capytaine_excitation_that_breaks_the_laws_is_a_warning(case, pattern, tmp_path):
    """wave_cylinder.nc as a user's scene: silent as it is; its excitation conjugated (the
    e^{−iωt} convention read as ours), every sign flipped, or the pitch dof's alone flipped:
    one warning naming the file and the effect's key.  (|X|² cannot see the first two: the
    long-wave phase does; a single dof's sign flips the Haskind coupling B_15.)"""
    bem = {"clean": DATA / "wave_cylinder.nc",
           "conjugated": lambda: copy(tmp_path, "wave_cylinder", lambda z, d, a: np.conj(z)),
           "sign-flipped": lambda: copy(tmp_path, "wave_cylinder", lambda z, d, a: -z),
           "pitch flipped": lambda: copy(tmp_path, "wave_cylinder", flip("Pitch"))}[case]
    bem = bem if isinstance(bem, Path) else bem()
    found = said(tmp_path, bem)
    if pattern is None:
        assert found == []
    else:
        assert len(found) == 1 and re.search(pattern, found[0]), found


def test_wamit_excitation_checked_against_its_one_file(tmp_path):
    """The WAMIT hemisphere (.3 read with the .1 beside it, ULEN 1 m, 50 m of water): silent;
    read with ULEN 2 m (the X and B scale by L² and L³·ω: Haskind sees L) it is said once."""
    extra = "ulen = {}\n"
    assert said(tmp_path, SPHERE / "sphere.3", extra.format(1.0), period=25.0, depth="depth = 50.0") == []
    found = said(tmp_path, SPHERE / "sphere.3", extra.format(2.0), period=25.0, depth="depth = 50.0")
    assert len(found) == 1 and "break the Haskind relation" in found[0], found


def test_headings_that_do_not_go_round_are_said_once(tmp_path):
    """twobody.nc: two bodies, one heading: no symmetry is taken for a group of bodies, the
    Haskind check is left out and said once (not guessed)."""
    found = said(tmp_path, DATA / "twobody.nc", 'body = "float"\n', period=8.0)
    assert len(found) == 1 and "left out" in found[0] and "several bodies" in found[0], found


def test_long_wave_phase_sees_what_the_squares_cannot():
    """The lowest frequency's surge and sway lead the elevation at the body by 90° in every
    clean dataset (the body moves with a long wave's water); a conjugated or sign-flipped X,
    headings measured coming-from (β + 180°) or clockwise (−β) lag it — while the Haskind
    integral of |X|² over the circle is the same for all four."""
    for name, depth in (("wave_pair", math.inf), ("barge_finite", 12.0), ("sphere", 50.0)):
        rad, exc = reading(name)
        body = exc.bodies[0]
        x, beta = exc.body(body), exc.directions
        position = (exc.rotation_centers.get(body) or [0.0, 0.0])[:2]
        lw = lambda xx, bb: bem_laws.long_wave_phase(exc.omega, bb, xx, position, G, depth)   # noqa: E731
        assert lw(x, beta) == []
        for wrong, b in ((np.conj(x), beta), (-x, beta), (x, beta + 180.0), (x, -beta)):
            if wrong is x and np.array_equal(np.mod(b, 360.0), np.mod(beta, 360.0)):
                continue   # (the sphere's one heading 0°: clockwise, it is the same)
            assert lw(wrong, b), (name, b)
