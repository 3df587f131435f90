"""Readers for BEM radiation results: Capytaine datasets (NetCDF) and WAMIT `.1` files.

Both give a ``BemData``: added mass A(ω) and radiation damping B(ω) in SI units on a grid of
finite frequencies, the infinite-frequency added mass when the file has it, and the dofs as
(body, k) with k = 1…6 (surge, sway, heave, roll, pitch, yaw) in the matrices' order.
Element [i, j]: load in dof i per motion of dof j (Capytaine: influenced_dof i,
radiating_dof j; WAMIT: I, J).

Capytaine (needs the `bem` extra: xarray and netCDF4): the dataset as ``cpt.export_dataset``
writes it: ``added_mass`` and ``radiation_damping`` over (omega, influenced_dof,
radiating_dof) (or another frequency dimension with an ``omega`` coordinate), scalar
``rho``, ``g``, ``water_depth`` (inf: deep water), ``forward_speed`` = 0, and
``rotation_center`` per body.  Dof names: "Surge" … "Yaw" for one body, "<body>__Surge" …
for several (Capytaine's joined bodies).  ω = ∞ is the infinite-frequency added mass, ω = 0
the zero-frequency one (not used).

WAMIT (manual, chapter 4): lines ``PER I J Ā [B̄]``, PER the period [s] (the default output,
IPEROUT = 1), PER = −1 the infinite period (ω = 0, kept as ``a_zero``) and PER = 0 the zero
period (ω = ∞, ``a_inf``), both with Ā only.  The rows are read as WAMIT writes them:
header lines first (``NUMHDR = 1``: ``WAMIT Numeric Output -- Filename …``; text that is not
a row of numbers, before the first row), periods in any order (WAMIT writes them as the run's
PER array, usually decreasing).  The first column may be another variable (WAMIT's IPEROUT),
declared, never guessed (``PERIOD_VARIABLES``): ``omega`` [rad/s], ``wavenumber`` (KL =
ω²L/g, needs g), ``hz``; the limit codes −1 and 0 are the period's, so with another
variable a first column ≤ 0 is refused.  Nondimensional with the length ULEN and the density ρ:
A = Ā·ρ·L^k, B = B̄·ρ·L^k·ω, k = 3 for I, J ≤ 3 (of each body), 5 for both rotations, 4 mixed.
Several bodies: I = 6·(body − 1) + k, bodies named "body1", "body2", …  A pair (I, J) missing
at every period is zero (WAMIT leaves out what it does not compute) and said in ``warnings``;
a pair present at some periods and missing at others (a truncated or spliced file) is an
error, and so is a pair of the finite periods missing from the PER = 0 (ω = ∞) rows.  A row
with more or fewer numbers than ``PER I J A [B]`` is an error at its line (decks/lines.py
``numeric_rows``).

Refused (InputError naming the file and the field): ``rho`` or ``g`` not a positive finite
number, a ``water_depth`` not positive (inf is deep water), a negative or repeated frequency, two
ω = ∞ rows, a non-numeric value, a ``rotation_center`` whose bodies are not the dofs'
bodies.  Said in ``BemData.warnings`` (legal, but a reviewer would ask): no ρ or g in a
Capytaine dataset.
"""
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from .lines import numeric_rows

DOF_NAMES = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")


@dataclass
class BemData:
    """A BEM radiation result in SI units (see the module docstring).

    omega (N,) [rad/s] finite, > 0, increasing; added_mass, damping (N, n, n); a_inf (n, n) or
    None; a_zero (n, n): the zero-frequency added mass when the file has it (kept, not used); dofs [(body, k)] (k 1…6); bodies [names] in file order; rotation_centers
    {body: [x, y, z]} [m] when the file gives them; rho [kg/m³], g [m/s²], water_depth [m]
    (inf: deep) or None when the file does not say; path: the file.
    """
    path: str
    omega: np.ndarray
    added_mass: np.ndarray
    damping: np.ndarray
    dofs: list
    bodies: list
    a_inf: np.ndarray = None
    a_zero: np.ndarray = None
    rotation_centers: dict = field(default_factory=dict)
    rho: float = None
    g: float = None
    water_depth: float = None
    kind: str = ""
    warnings: list = field(default_factory=list)

    def index(self, body, k):
        """Row/column of (body, dof k) or None."""
        try:
            return self.dofs.index((body, k))
        except ValueError:
            return None


def body_dofs(values, dofs, name):
    """``values[..., c]`` of the columns c whose (body, k) is body ``name``, spread over its
    6 dofs (k = 1…6); zero for the dofs the file leaves out."""
    out = np.zeros(values.shape[:-1] + (6,), values.dtype)
    for c, (b, k) in enumerate(dofs):
        if b == name:
            out[..., k - 1] = values[..., c]
    return out


def read_bem(path, ulen=None, rho=None, g=None, period_variable=None):
    """Read a Capytaine dataset (.nc) or a WAMIT .1 file (by its extension); ``ulen``,
    ``rho``, ``g`` and ``period_variable`` (what the first column is) apply to WAMIT."""
    path = Path(path)
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        for name, value, why in (("ulen", ulen, "a Capytaine dataset is in SI units already"),
                                 ("period_variable", period_variable, "a Capytaine dataset's omega is in rad/s")):
            if value is not None:   # an option that would change nothing is not taken silently
                raise InputError(path, None, name, f"applies to a nondimensional WAMIT .1 file only: {why}")
        data = read_capytaine(path)
        if len(data.omega) < 3:   # the transform needs a grid (WAMIT: the same rule on its periods)
            raise InputError(path, None, "omega", f"{len(data.omega)} finite frequencies: at least 3 needed "
                                                  "(the ω = 0 and ω = ∞ rows do not count)")
        return data
    if path.suffix == ".1":
        return read_wamit(path, ulen, rho, g, period_variable)
    raise InputError(path, None, "bem", "expected a Capytaine NetCDF dataset (.nc) or a WAMIT .1 file")


def check_scalar(path, name, value):
    """A dataset's ``rho``, ``g`` (positive, finite), ``water_depth`` (positive, inf: deep
    water) or ``forward_speed`` (finite): else one InputError.  A NaN or a zero here would
    pass every later comparison with the scene's values."""
    if name in ("rho", "g") and not (np.isfinite(value) and value > 0):
        raise InputError(path, None, name, f"must be a positive finite number, found {value:g}")
    if name == "water_depth" and not value > 0:
        raise InputError(path, None, name, f"must be positive (inf: deep water), found {value:g}")
    if name == "forward_speed" and not np.isfinite(value):
        raise InputError(path, None, name, f"must be a finite speed, found {value:g}")
    return value


def _check_finite(path, name, values, coords):
    """Error naming the variable and the coordinates of the first non-finite value."""
    bad = ~np.isfinite(values)
    if bad.any():
        where = np.argwhere(bad)[0]
        at = ", ".join(f"{k}={v[i]}" for (k, v), i in zip(coords, where))
        raise InputError(path, None, name, f"{bad.sum()} non-finite value(s), first at {at} ({values[tuple(where)]})")


def read_capytaine(path):
    """Read a Capytaine NetCDF dataset: a BemData."""
    path = Path(path)
    try:
        import xarray as xr
    except ImportError:
        raise InputError(path, None, "bem", "reading Capytaine datasets needs xarray and netCDF4: "
                                             "pip install -e \".[bem]\"") from None
    try:
        ds = xr.load_dataset(path)
    except (OSError, ValueError) as exc:
        raise InputError(path, None, "bem", f"cannot read as a NetCDF dataset ({exc})") from None
    for var in ("added_mass", "radiation_damping"):
        if var not in ds:
            raise InputError(path, None, var, f"missing (variables: {', '.join(ds.data_vars) or 'none'}); "
                                              "solve the radiation problems and export with cpt.export_dataset")
    if "complex" in ds.dims:
        ds = ds.sel(complex="re", drop=True) if "complex" in ds["added_mass"].dims else ds
    scalars = {}
    for name in ("rho", "g", "water_depth", "forward_speed"):
        if name in ds.coords or name in ds:
            v = _floats(path, name, np.atleast_1d(ds[name].values))
            if v.size != 1:
                raise InputError(path, None, name, f"{v.size} values {v.tolist()}: select one "
                                                   f"(ds.sel({name}=…)) before exporting")
            scalars[name] = float(v[0])
            if name in ds.dims:
                ds = ds.squeeze(name, drop=True)
    for name, value in scalars.items():
        check_scalar(path, name, value)
    if scalars.get("forward_speed", 0.0) != 0.0:
        raise InputError(path, None, "forward_speed", f"{scalars['forward_speed']:g} m/s: only zero speed results "
                                                      "give Cummins' kernels")
    am = ds["added_mass"]
    extra = [d for d in am.dims if d not in ("influenced_dof", "radiating_dof")]
    dims_ok = "influenced_dof" in am.dims and "radiating_dof" in am.dims and len(extra) == 1
    if not dims_ok:
        raise InputError(path, None, "added_mass", f"expected dimensions (frequency, influenced_dof, radiating_dof), "
                                                   f"found {am.dims}")
    freq = extra[0]
    if freq == "omega" or ("omega" in ds.coords and ds["omega"].dims == (freq,)):
        omega = _floats(path, "omega", ds["omega"].values)
    else:
        raise InputError(path, None, "omega", f"no angular frequency coordinate along {freq!r}")
    rows = [str(x) for x in ds["influenced_dof"].values]
    cols = [str(x) for x in ds["radiating_dof"].values]
    if set(rows) != set(cols):
        miss = sorted(set(rows) ^ set(cols))
        raise InputError(path, None, "radiating_dof", f"missing dof(s) {', '.join(miss)}: radiating and influenced "
                                                      f"dofs must be the same set")
    order = [cols.index(r) for r in rows]
    a = _floats(path, "added_mass", am.transpose(freq, "influenced_dof", "radiating_dof").values)[:, :, order]
    b = _floats(path, "radiation_damping",
                ds["radiation_damping"].transpose(freq, "influenced_dof", "radiating_dof").values)[:, :, order]
    dofs, bodies = [], []
    for name in rows:
        body, _, dof = name.rpartition("__")
        if not body:
            body = _single_name(ds)
        if dof not in DOF_NAMES:
            raise InputError(path, None, "radiating_dof", f"{name!r} is not a rigid-body dof "
                                                          f"({', '.join(DOF_NAMES)}, or <body>__<dof>)")
        if (body, DOF_NAMES.index(dof) + 1) in dofs:
            raise InputError(path, None, "radiating_dof", f"dof {name!r} appears twice")
        dofs.append((body, DOF_NAMES.index(dof) + 1))
        if body not in bodies:
            bodies.append(body)
    coords = [(freq, omega), ("influenced_dof", rows), ("radiating_dof", rows)]
    inf = np.isinf(omega)
    fin = np.isfinite(omega) & (omega > 0)
    if np.isnan(omega).any():
        raise InputError(path, None, "omega", "NaN frequency")
    if np.any(omega < 0):
        raise InputError(path, None, "omega", f"negative frequency {omega[omega < 0][0]:g} rad/s: ω must be ≥ 0 "
                                              "(0: the zero-frequency limit, inf: the infinite-frequency one)")
    if np.sum(omega == np.inf) > 1:
        raise InputError(path, None, "omega", f"{int(np.sum(omega == np.inf))} rows at ω = inf: one "
                                              "infinite-frequency added mass expected")
    for name, v in (("added_mass", a), ("radiation_damping", b)):
        sel = fin | inf if name == "added_mass" else fin
        _check_finite(path, name, v[sel], [(freq, omega[sel])] + coords[1:])
    k = np.argsort(omega[fin])
    w = omega[fin][k]
    if np.any(np.diff(w) <= 0):
        raise InputError(path, None, "omega", "repeated frequency")
    centres = {}
    if "rotation_center" in ds.coords or "rotation_center" in ds:
        rc = ds["rotation_center"]
        if "body" in rc.dims:
            centres = {str(n): _floats(path, f"rotation_center[{n}]", rc.sel(body=n).values).tolist()
                       for n in rc["body"].values}
            if set(centres) != set(bodies):
                raise InputError(path, None, "rotation_center", f"given for bodies {', '.join(centres)} but the "
                                 f"dofs name bodies {', '.join(bodies)}: the centres would go unchecked")
        elif len(bodies) == 1:
            centres = {bodies[0]: _floats(path, "rotation_center", rc.values).tolist()}
        else:
            raise InputError(path, None, "rotation_center", f"one centre for {len(bodies)} bodies "
                                                            f"({', '.join(bodies)}): give one per body")
    missing = [name for name in ("rho", "g") if name not in scalars]
    warnings = ([f"{path}: {', '.join(missing)} not in the dataset: the coefficients are taken as solved "
                 f"with the scene's (environment.rho, environment.g); check they match the BEM run"]
                if missing else [])
    return BemData(str(path), w, a[fin][k], b[fin][k], dofs, bodies,
                   a_inf=a[inf][0] if inf.any() else None, a_zero=a[omega == 0][0] if (omega == 0).any() else None,
                   rotation_centers=centres,
                   rho=scalars.get("rho"), g=scalars.get("g"), water_depth=scalars.get("water_depth"),
                   kind="Capytaine", warnings=warnings)


def _floats(path, name, values):
    """``values`` as a float array, or an InputError naming the variable and the first value
    that is not a number."""
    try:
        return np.asarray(values).astype(float)
    except (TypeError, ValueError):
        flat = np.asarray(values, dtype=object).ravel()
        bad = next((v for v in flat if not _is_number(v)), flat[0] if flat.size else None)
        raise InputError(path, None, name, f"not a number: {bad!r}") from None


def _is_number(value):
    try:
        float(value)
        return True
    except (TypeError, ValueError):
        return False


def _single_name(ds):
    """Name of the body of a one-body dataset (dofs without a '<body>__' prefix)."""
    if "body" in ds.coords and ds["body"].size == 1:
        return str(np.atleast_1d(ds["body"].values)[0])
    return "body"


def _wamit_k(i, j):
    """The length exponent of Ā_ij (WAMIT): 3 translation–translation, 4 mixed, 5 rotations."""
    return 3 + ((i - 1) % 6 >= 3) + ((j - 1) % 6 >= 3)


# The first column of WAMIT's numeric outputs (the manual's IPEROUT, config file): what a
# scene's ``period_variable`` (the CLI's --period-variable) declares it to be.
PERIOD_VARIABLES = {
    "period": "the wave period [s] (WAMIT's default, IPEROUT = 1)",
    "omega": "the radian frequency ω [rad/s] (IPEROUT = 2)",
    "wavenumber": "the nondimensional infinite-depth wavenumber KL = ω²·L/g (IPEROUT = 3)",
    "hz": "the frequency f = ω/2π [Hz] (a converted file: not a WAMIT option)",
}


def period_variable(path, value):
    """``value`` (None: the default "period") if it is one of PERIOD_VARIABLES, else an error."""
    if value is None:
        return "period"
    if value not in PERIOD_VARIABLES:
        raise InputError(path, None, "period_variable", f"expected one of {', '.join(map(repr, PERIOD_VARIABLES))}, "
                                                        f"found {value!r} (WAMIT's IPEROUT = 4, the finite-depth "
                                                        "wavenumber, is not read: write periods, IPEROUT = 1)")
    return value


def wamit_omega(path, number, value, variable, ulen=None, g=None):
    """ω [rad/s] of a WAMIT row's first column ``value`` read as ``variable``; 0.0 and inf for
    WAMIT's limit rows, PER = −1 (infinite period, ω = 0) and PER = 0 (zero period, ω = ∞).
    Those codes are the period's: in another variable a value ≤ 0 is refused (a 0 there
    could mean either limit; never guessed)."""
    if variable == "period":
        if value == -1.0:
            return 0.0
        if value == 0.0:
            return np.inf
        if value < 0:
            raise InputError(path, number, "PER", f"period must be > 0, −1 (infinite) or 0 (zero), found {value:g}")
        return 2 * np.pi / value
    if value <= 0:
        raise InputError(path, number, "PER", f"{value:g} where the first column is declared "
                                              f"{PERIOD_VARIABLES[variable]} (period_variable = {variable!r}): "
                                              "WAMIT marks the ω = 0 and ω = ∞ rows with the period codes −1 and 0, "
                                              "which this variable cannot tell apart; write the file with periods "
                                              "(IPEROUT = 1), or leave those rows out")
    if variable == "omega":
        return value
    if variable == "hz":
        return 2 * np.pi * value
    return float(np.sqrt(value * g / ulen))     # wavenumber: KL = ω²L/g


def read_wamit(path, ulen, rho, g=None, variable=None):
    """Read a WAMIT .1 file; ``ulen`` [m] and ``rho`` [kg/m³] make it dimensional;
    ``variable``: what its first column is (PERIOD_VARIABLES, default "period"); ``g``
    [m/s²] converts a wavenumber."""
    path = Path(path)
    if ulen is None or not ulen > 0:
        raise InputError(path, None, "ulen", "a WAMIT .1 file is nondimensional: declare ULEN (ulen = … m), "
                                             "the length of the run's .gdf")
    if rho is None or not rho > 0:
        raise InputError(path, None, "rho", "declare the density that makes the WAMIT file dimensional")
    variable = period_variable(path, variable)
    if variable == "wavenumber" and (g is None or not g > 0):
        raise InputError(path, None, "g", "a wavenumber column needs g (> 0) to give ω")
    table, header = numeric_rows(path, ["PER", "I", "J", "A", "B"], (4, 5))
    rows = {}   # ω (0: A(0), inf: A∞) → {(I, J): (A, B)}
    first, written = {}, {}   # written: ω → the first column as the file writes it (for messages)
    for number, vals in table:
        w = wamit_omega(path, number, vals[0], variable, ulen, g)
        i, j = (_dof_index(path, number, v, name) for v, name in ((vals[1], "I"), (vals[2], "J")))
        if np.isfinite(w) and w > 0 and len(vals) != 5:
            raise InputError(path, number, "B", f"missing the damping at {_as_written(vals[0], variable)}")
        if not (np.isfinite(w) and w > 0) and len(vals) == 5 and vals[4] != 0:
            raise InputError(path, number, "B", f"a damping {vals[4]:g} at PER = {vals[0]:g}: WAMIT writes Ā alone "
                                                "at the limits (B = 0 there); a fifth number is a shifted row?")
        key = (w, i, j)
        if key in first:
            raise InputError(path, number, "I J", f"duplicate ({_as_written(vals[0], variable)}, I = {i}, J = {j}) "
                                                  f"(first at line {first[key]})")
        first[key] = number
        written.setdefault(w, _as_written(vals[0], variable))
        rows.setdefault(w, {})[(i, j)] = (vals[3], vals[4] if len(vals) == 5 else 0.0)
    omegas = sorted(w for w in rows if np.isfinite(w) and w > 0)        # increasing ω
    if len(omegas) < 3:
        raise InputError(path, None, "PER", f"{len(omegas)} finite frequencies: at least 3 needed"
                                            + ("" if table or not header else
                                               f" (the file has {len(header)} text line(s) and no numeric row)"))
    warnings = _wamit_pairs(path, rows, omegas, first, written)
    index = sorted({i for r in rows.values() for ij in r for i in ij})
    n = len(index)
    pos = {d: k for k, d in enumerate(index)}
    scale = np.array([[rho * ulen ** _wamit_k(i, j) for j in index] for i in index])

    def matrices(r, col):
        m = np.zeros((n, n))
        for (i, j), v in r.items():
            m[pos[i], pos[j]] = v[col]
        return m * scale
    omega = np.array(omegas)
    a = np.array([matrices(rows[w], 0) for w in omegas])
    b = np.array([matrices(rows[w], 1) for w in omegas]) * omega[:, None, None]
    nb = (max(index) - 1) // 6 + 1
    bodies = [f"body{k + 1}" for k in range(nb)]
    dofs = [(f"body{(d - 1) // 6 + 1}", (d - 1) % 6 + 1) for d in index]
    bodies = [x for x in bodies if any(d[0] == x for d in dofs)]
    return BemData(str(path), omega, a, b, dofs, bodies,
                   a_inf=matrices(rows[np.inf], 0) if np.inf in rows else None,
                   a_zero=matrices(rows[0.0], 0) if 0.0 in rows else None,
                   rho=None, g=None, water_depth=None, kind="WAMIT", warnings=warnings)


def _as_written(value, variable):
    return {"period": f"period {value:g} s", "omega": f"ω = {value:g} rad/s", "hz": f"f = {value:g} Hz",
            "wavenumber": f"KL = {value:g}"}[variable]


def _dof_index(path, number, value, name):
    if value != int(value) or value < 1:
        raise InputError(path, number, name, f"dof index must be a positive integer, found {value:g}")
    return int(value)


def _wamit_pairs(path, rows, omegas, first, written):
    """A pair (I, J) given at some finite frequencies (or at them but not at PER = 0) and missing
    at others is an error (a truncated or spliced file, read as zeros otherwise); pairs of
    given dofs missing at every frequency are zeros by WAMIT's rule, said as a warning."""
    given = {ij for w in omegas for ij in rows[w]}
    for w in omegas + ([np.inf] if np.inf in rows else []):
        gap = sorted(given - set(rows[w]))
        if gap:
            i, j = gap[0]
            last = max(first[(w, *ij)] for ij in rows[w])
            what = "the infinite-frequency rows (PER = 0)" if np.isinf(w) else written[w]
            raise InputError(path, last, "I J", f"{len(gap)} pair(s) given at other periods are missing at {what}, "
                             f"first ({i}, {j}) (its rows end at line {last}): a truncated file? every period "
                             "must list the same pairs")
    dofs = sorted({i for ij in given for i in ij})
    absent = [(i, j) for i in dofs for j in dofs if (i, j) not in given]
    if not absent:
        return []
    shown = ", ".join(f"({i}, {j})" for i, j in absent[:6]) + (", …" if len(absent) > 6 else "")
    return [f"{path}: {len(absent)} pair(s) of its dofs missing at every period, read as zeros: {shown}"]
