"""Readers for the wave data of BEM results: excitation transfer functions and hydrostatics.

Both return SI values in hydrofmu's convention (README / user guide, Waves): excitation per
unit wave amplitude X(ω, β) with F(t) = Re{X·e^{+iωt}} for the elevation η = cos(ωt) at the
global origin, direction β [deg] where the waves go to, counter-clockwise from +x.

Capytaine (NetCDF, ``cpt.export_dataset``; needs the `bem` extra): ``excitation_force`` or
``diffraction_force`` + ``Froude_Krylov_force`` over (omega, wave_direction [rad],
influenced_dof), complex values split along a ``complex`` dimension (re, im).  Capytaine's
time factor is e^{−iωt} with the incident elevation Re{e^{ik(x cos β + y sin β)}·e^{−iωt}}
= cos(ωt − k·x) (the same wave as ours), so a force Re{F·e^{−iωt}} = Re{F̄·e^{+iωt}}:
X = conj(F).  ω = ∞ and ω = 0 rows (no diffraction there) are dropped.  Hydrostatics:
``hydrostatic_stiffness`` (influenced_dof, radiating_dof), about each body's
``rotation_center``; Capytaine computes its rigid-body terms with the body's mass and
``center_of_mass`` (the weight's moment −m·g·z_G in roll and pitch is in the matrix), and
``inertia_matrix`` holds the mass used.

WAMIT (manual, chapter 4): ``.3`` (diffraction) and ``.2`` (Haskind) lines
``PER BETA I |X̄| phase(X̄)° Re(X̄) Im(X̄)``; PER [s] the period, BETA [deg] the heading
(propagation direction, counter-clockwise from +x), I = 6·(body − 1) + k.  Time factor
e^{+iωt}, phase relative to the incident elevation at the global origin: X = X̄·ρ·g·L^m
(m = 2 for forces, 3 for moments), no conjugation.  ``.hst`` lines ``I J C̄``:
C = C̄·ρ·g·L^k, k = 2 + [I is a rotation] + [J is a rotation]; WAMIT's C(4,4), C(5,5),
C(4,6), C(5,6) hold the weight terms (−m·g·z_G, m·g·x_G, …) of the run's mass
properties (the .hst has no mass of its own to check against the scene).

Read as WAMIT writes them (decks/lines.py ``numeric_rows``, decks/bem.py ``wamit_omega``):
header lines first (``NUMHDR = 1``), then rows of exactly the layout's count of numbers (a row
with more or fewer is an error at its line); the first column as declared (period by
default; ``omega``, ``wavenumber``, ``hz``); the PER = −1 / 0 rows (no incident wave) are
not excitation and are passed over.  Every period must list the same headings and every
(period, heading) the same dofs (a gap is an error at its line: it would read as zeros);
dofs of a body with no row at all (WAMIT leaves out modes it did not compute) read as zero
and are said once (a warning naming them, kept in ``reading``).  A ``.hst`` pair given twice
is an error; pairs of a body without a row read as zero and are said (WAMIT writes all 36).
"""
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from .bem import DOF_NAMES, _single_name, body_dofs, check_scalar, period_variable, wamit_omega
from .lines import Reading, numeric_rows


@dataclass
class ExcitationData:
    """Excitation transfer functions of a BEM result (module docstring's convention).

    omega (nω,) [rad/s] increasing; directions (nβ,) [deg]; values (nω, nβ, n) complex
    [N/m, N·m/m]; dofs [(body, k)]; bodies [names]; rotation_centers {body: [x, y, z]} when
    the file has them; rho, g, water_depth (None when the file does not say)."""
    path: str
    kind: str
    omega: np.ndarray
    directions: np.ndarray
    values: np.ndarray
    dofs: list
    bodies: list
    rotation_centers: dict = field(default_factory=dict)
    rho: float = None
    g: float = None
    water_depth: float = None
    reading: object = None    # decks.lines.Reading: the warnings of a WAMIT file

    def body(self, name):
        """(nω, nβ, 6) complex of one body, zero for dofs the file leaves out."""
        return body_dofs(self.values, self.dofs, name)


@dataclass
class HydrostaticsData:
    """Hydrostatic restoring of a BEM result: ``stiffness`` {body: 6×6} [N/m, N, N·m/rad]
    about each body's rotation centre; ``mass`` {body: kg} and ``center_of_mass``
    {body: [x, y, z]} the file used (when it says); ``weight``: True when the matrix holds
    the weight's moment terms."""
    path: str
    kind: str
    stiffness: dict
    bodies: list
    weight: bool
    mass: dict = field(default_factory=dict)
    center_of_mass: dict = field(default_factory=dict)
    rotation_centers: dict = field(default_factory=dict)
    rho: float = None
    g: float = None
    reading: object = None    # decks.lines.Reading: the warnings of a WAMIT file


def _open(path):
    """A Capytaine dataset as xarray, or one InputError."""
    try:
        import xarray as xr
    except ImportError:
        raise InputError(path, None, "bem", "reading Capytaine datasets needs xarray and netCDF4: "
                                             "pip install -e \".[bem]\"") from None
    try:
        return xr.load_dataset(path)
    except (OSError, ValueError) as exc:
        raise InputError(path, None, "bem", f"cannot read as a NetCDF dataset ({exc})") from None


def _scalar(ds, name, path=None):
    if name not in ds.coords and name not in ds:
        return None
    v = np.atleast_1d(ds[name].values).astype(float)
    return check_scalar(path, name, float(v[0])) if v.size == 1 else None


def _dof(path, name, ds, where):
    body, _, dof = str(name).rpartition("__")
    if dof not in DOF_NAMES:
        raise InputError(path, None, where, f"{name!r} is not a rigid-body dof ({', '.join(DOF_NAMES)}, "
                                            f"or <body>__<dof>)")
    return body or _single_name(ds), DOF_NAMES.index(dof) + 1


def _complex(var, path=None):
    """Complex values split along ``complex`` (re, im, by label) or stored complex; real
    values alone (a phase lost on export) are an error."""
    if "complex" in var.dims:
        return var.sel(complex="re").values + 1j * var.sel(complex="im").values
    if not np.iscomplexobj(var.values):
        raise InputError(path, None, var.name, "real values without a 'complex' (re, im) dimension: the phase "
                                               "is missing (export with cpt.export_dataset)")
    return np.asarray(var.values)


def _centres(ds, bodies):
    if "rotation_center" not in ds.coords and "rotation_center" not in ds:
        return {}
    rc = ds["rotation_center"]
    if "body" in rc.dims:
        return {str(n): rc.sel(body=n).values.astype(float).tolist() for n in rc["body"].values}
    return {bodies[0]: rc.values.astype(float).tolist()}


def read_excitation(path, ulen=None, rho=None, g=None, period_variable=None) -> ExcitationData:
    """Excitation of a Capytaine dataset (.nc) or a WAMIT .3 / .2 file (``ulen`` [m], ``rho``,
    ``g`` make WAMIT's values dimensional; ``period_variable``: what its first column is,
    decks/bem.py PERIOD_VARIABLES)."""
    path = Path(path)
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        _not_capytaine(path, period_variable)
        return _capytaine_excitation(path)
    if path.suffix in (".2", ".3"):
        return _wamit_excitation(path, ulen, rho, g, period_variable)
    raise InputError(path, None, "bem", "expected a Capytaine dataset (.nc) or a WAMIT .3 (diffraction) / "
                                        ".2 (Haskind) file for the wave excitation")


def _capytaine_excitation(path):
    ds = _open(path)
    if "excitation_force" in ds:
        name, x = "excitation_force", _complex(ds["excitation_force"], path)
        var = ds["excitation_force"]
    elif "diffraction_force" in ds and "Froude_Krylov_force" in ds:
        name, var = "diffraction_force", ds["diffraction_force"]
        x = _complex(var, path) + _complex(ds["Froude_Krylov_force"].transpose(*var.dims), path)
    else:
        raise InputError(path, None, "excitation_force", "missing: the dataset has no excitation_force nor "
                                                         "diffraction_force + Froude_Krylov_force (solve the "
                                                         "diffraction problems: a wave_direction coordinate)")
    dims = [d for d in var.dims if d != "complex"]
    want = ("omega", "wave_direction", "influenced_dof")
    if sorted(dims) != sorted(want):
        raise InputError(path, None, name, f"expected dimensions {want}, found {tuple(dims)} (select one "
                                           f"value of every other dimension before exporting)")
    x = np.moveaxis(x, [dims.index(d) for d in want], [0, 1, 2])
    omega = ds["omega"].values.astype(float)
    keep = np.isfinite(omega) & (omega > 0)
    omega, x = omega[keep], x[keep]
    order = np.argsort(omega)
    omega, x = omega[order], x[order]
    if omega.size < 2 or np.any(np.diff(omega) <= 0):
        raise InputError(path, None, "omega", "at least two distinct finite frequencies needed for the excitation")
    rad = np.atleast_1d(ds["wave_direction"].values.astype(float))
    if np.any(np.abs(rad) > 2 * np.pi + 1e-9):   # Capytaine's directions are radians
        raise InputError(path, None, "wave_direction", f"{rad[np.argmax(np.abs(rad))]:g} is beyond ±2π: Capytaine "
                                                       "gives directions in radians (degrees written here?)")
    if len(set(np.round(np.mod(rad, 2 * np.pi), 9))) < rad.size:
        raise InputError(path, None, "wave_direction", "a direction given twice (two columns for one heading)")
    beta = np.degrees(rad)
    names = [str(n) for n in np.atleast_1d(ds["influenced_dof"].values)]
    dofs = [_dof(path, n, ds, "influenced_dof") for n in names]
    bad = ~np.isfinite(x)
    if bad.any():
        i, j, k = np.argwhere(bad)[0]
        raise InputError(path, None, name, f"{bad.sum()} non-finite value(s) in the transfer function, first at "
                                           f"omega={omega[i]:g} rad/s, wave_direction={beta[j]:g}°, "
                                           f"influenced_dof={names[k]}")
    bodies = list(dict.fromkeys(b for b, _ in dofs))
    return ExcitationData(str(path), "Capytaine", omega, beta, np.conj(x), dofs, bodies, _centres(ds, bodies),
                          _scalar(ds, "rho", path), _scalar(ds, "g", path), _scalar(ds, "water_depth", path))


def _wamit_scale(path, ulen, rho, g):
    for name, v in (("ulen", ulen), ("rho", rho), ("g", g)):
        if v is None or not v > 0:
            raise InputError(path, None, name, f"a WAMIT file is nondimensional: declare {name} (> 0)")


def _index(path, number, value, name="I"):
    if value != int(value) or value < 1:
        raise InputError(path, number, name, f"dof index must be a positive integer, found {value:g}")
    return int(value)


def _wamit_excitation(path, ulen, rho, g, variable=None):
    _wamit_scale(path, ulen, rho, g)
    variable = period_variable(path, variable)
    rows, _ = numeric_rows(path, ["PER", "BETA", "I", "MOD", "PHA", "RE", "IM"])
    table, first = {}, {}
    for number, (per, beta, i, _, _, re, im) in rows:
        w = wamit_omega(path, number, per, variable, ulen, g)
        if not (np.isfinite(w) and w > 0):
            continue                      # the zero / infinite period limits: no excitation wave
        i = _index(path, number, i)
        key = (w, beta, i)
        if key in first:
            raise InputError(path, number, "PER BETA I", f"duplicate ({per:g}, {beta:g}, {i}) (first at line "
                                                         f"{first[key]})")
        first[key] = number
        table[key] = complex(re, im) * rho * g * ulen ** (2 if (i - 1) % 6 < 3 else 3)
    omegas = sorted({k[0] for k in table})
    betas = sorted({k[1] for k in table})
    index = sorted({k[2] for k in table})
    if len(omegas) < 2:
        raise InputError(path, None, "PER", f"{len(omegas)} finite periods: at least 2 needed")
    _excitation_gaps(path, table, first, omegas, betas, index)
    x = np.zeros((len(omegas), len(betas), len(index)), complex)
    for (w, beta, i), v in table.items():
        x[omegas.index(w), betas.index(beta), index.index(i)] = v
    dofs = [(f"body{(d - 1) // 6 + 1}", (d - 1) % 6 + 1) for d in index]
    bodies = list(dict.fromkeys(b for b, _ in dofs))
    reading = Reading(str(path), "WAMIT " + path.suffix)
    missing = {b: [k for k in range(1, 7) if (b, k) not in dofs] for b in bodies}
    for b, ks in missing.items():
        if ks:
            reading.warn(None, "I", f"no rows for {', '.join(DOF_NAMES[k - 1] for k in ks)} of {b} (I = "
                                    f"{', '.join(str(6 * (int(b[4:]) - 1) + k) for k in ks)}) at any period or "
                                    "heading: read as zero excitation (WAMIT leaves out modes it did not compute; "
                                    "a cut file drops them too)")
    return ExcitationData(str(path), "WAMIT", np.array(omegas), np.array(betas, float), x, dofs, bodies,
                          reading=reading)


def _excitation_gaps(path, table, first, omegas, betas, index):
    """Every (period, heading) must list the dofs of the file and every period the headings:
    a gap (a truncated or spliced file) would read as zeros.  One error at the line where the
    incomplete block ends."""
    seen = {}
    for (w, beta, i), number in first.items():
        seen.setdefault((w, beta), {})[i] = number
    for w in omegas:
        for beta in betas:
            block = seen.get((w, beta))
            if block is None:
                near = max(n for (ww, _), b in seen.items() if ww == w for n in b.values())
                raise InputError(path, near, "BETA", f"heading {beta:g}° missing at ω = {w:.6g} rad/s (given at "
                                                     "other periods): a truncated file? every period must list "
                                                     "the same headings")
            gap = [i for i in index if i not in block]
            if gap:
                raise InputError(path, max(block.values()), "I", f"dof(s) I = {', '.join(map(str, gap))} missing at "
                                 f"ω = {w:.6g} rad/s, heading {beta:g}° (given at others): a truncated file? "
                                 "every period and heading must list the same dofs")


def _not_capytaine(path, variable):
    if variable is not None:   # an option that would change nothing is not taken silently
        raise InputError(path, None, "period_variable", "applies to a WAMIT file only: a Capytaine dataset's "
                                                        "omega is in rad/s")


def read_hydrostatics(path, ulen=None, rho=None, g=None) -> HydrostaticsData:
    """Hydrostatic restoring of a Capytaine dataset (.nc) or a WAMIT .hst file."""
    path = Path(path)
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        return _capytaine_hydrostatics(path)
    if path.suffix == ".hst":
        return _wamit_hydrostatics(path, ulen, rho, g)
    raise InputError(path, None, "bem", "expected a Capytaine dataset (.nc) or a WAMIT .hst file for the "
                                        "hydrostatic restoring")


def _capytaine_hydrostatics(path):
    ds = _open(path)
    if "hydrostatic_stiffness" not in ds:
        raise InputError(path, None, "hydrostatic_stiffness", "missing: export the dataset with hydrostatics "
                                                              "(fill_dataset(..., hydrostatics=True))")
    var = ds["hydrostatic_stiffness"]
    extra = [d for d in var.dims if d not in ("influenced_dof", "radiating_dof")]
    if extra:
        var = var.squeeze(extra, drop=True) if all(ds.sizes[d] == 1 for d in extra) else None
    if var is None:
        raise InputError(path, None, "hydrostatic_stiffness", "several values of rho or g: select one")
    rows = [_dof(path, n, ds, "influenced_dof") for n in var["influenced_dof"].values]
    cols = [_dof(path, n, ds, "radiating_dof") for n in var["radiating_dof"].values]
    c = var.values.astype(float)
    if not np.all(np.isfinite(c)):
        raise InputError(path, None, "hydrostatic_stiffness", "non-finite value(s)")
    bodies = list(dict.fromkeys(b for b, _ in rows))
    stiffness = {}
    for b in bodies:
        m = np.zeros((6, 6))
        for r, (br, i) in enumerate(rows):
            for q, (bc, j) in enumerate(cols):
                if br == b and bc == b:
                    m[i - 1, j - 1] = c[r, q]
        stiffness[b] = m
    mass = {}
    if "inertia_matrix" in ds:
        im = ds["inertia_matrix"]
        im = im.squeeze([d for d in im.dims if d not in ("influenced_dof", "radiating_dof")], drop=True)
        names = [str(n) for n in im["influenced_dof"].values]
        for b in bodies:
            surge = next((names.index(n) for n in names if _dof(path, n, ds, "influenced_dof") == (b, 1)), None)
            if surge is not None:
                mass[b] = float(im.values[surge, surge])
    com = {}
    if "center_of_mass" in ds.coords or "center_of_mass" in ds:
        v = ds["center_of_mass"]
        com = ({str(n): v.sel(body=n).values.astype(float).tolist() for n in v["body"].values}
               if "body" in v.dims else {bodies[0]: v.values.astype(float).tolist()})
    return HydrostaticsData(str(path), "Capytaine", stiffness, bodies, weight=bool(com), mass=mass,
                            center_of_mass=com, rotation_centers=_centres(ds, bodies),
                            rho=_scalar(ds, "rho", path), g=_scalar(ds, "g", path))


def _wamit_hydrostatics(path, ulen, rho, g):
    _wamit_scale(path, ulen, rho, g)
    rows, _ = numeric_rows(path, ["I", "J", "C"])
    stiffness, first = {}, {}
    for number, (i, j, c) in rows:
        i, j = _index(path, number, i), _index(path, number, j, "J")
        if (i, j) in first:
            raise InputError(path, number, "I J", f"duplicate ({i}, {j}) (first at line {first[(i, j)]})")
        first[(i, j)] = number
        bi, bj = (i - 1) // 6 + 1, (j - 1) // 6 + 1
        if bi != bj:
            if c != 0:
                raise InputError(path, number, "C", f"hydrostatic coupling between bodies {bi} and {bj}: not supported")
            continue
        ki, kj = (i - 1) % 6, (j - 1) % 6
        m = stiffness.setdefault(f"body{bi}", np.zeros((6, 6)))
        m[ki, kj] = c * rho * g * ulen ** (2 + (ki >= 3) + (kj >= 3))
    if not stiffness:
        raise InputError(path, None, "I J C", "no hydrostatic coefficients in the file")
    reading = Reading(str(path), "WAMIT .hst")
    for b in sorted(stiffness):
        base = 6 * (int(b[4:]) - 1)
        absent = [(base + i, base + j) for i in range(1, 7) for j in range(1, 7) if (base + i, base + j) not in first]
        if absent:
            shown = ", ".join(f"({i}, {j})" for i, j in absent[:6]) + (", …" if len(absent) > 6 else "")
            reading.warn(None, "I J", f"{len(absent)} of the 36 pairs of {b} have no row, read as zero: {shown} "
                                      "(WAMIT writes every pair of a body; a cut file drops some)")
    return HydrostaticsData(str(path), "WAMIT", stiffness, sorted(stiffness), weight=True, reading=reading)
