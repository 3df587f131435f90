"""Readers for second-order wave drift: mean drift (WAMIT ``.7/.8/.9``, Capytaine far-field
drift) and difference-frequency QTFs (WAMIT ``.10d/.11d/.12d``).

Every source is brought to hydrofmu's convention (DESIGN.md, Waves (second order)):

    F(t) = Σ_i Σ_j a_i·a_j·Re{Q⁻(ω_i, ω_j; β_i, β_j)·e^{i((ω_i − ω_j)t + φ_i − φ_j)}}

for the elevation η = Σ a_k·cos(ω_k·t + φ_k) at the global origin, β [deg] where the waves
go to, counter-clockwise from +x; Q⁻(ω_j, ω_i; β_j, β_i) = conj(Q⁻(ω_i, ω_j; β_i, β_j)), so
the mean drift of a regular wave of amplitude a is a²·Q⁻(ω, ω; β, β) (real).  Q in SI per
unit amplitude squared: N/m² (forces), N·m/m² (moments), global axes, moments about the
body's reference point (the BEM rotation centre / WAMIT's body origin).

WAMIT (manual, chapter 4 and the second-order chapter; time factor e^{+iωt}, phases relative
to the incident elevation at the origin, A the complex amplitude a·e^{iφ}):

- ``.7`` (control surface), ``.8`` (momentum conservation), ``.9`` (pressure integration):
  lines ``PER BETA1 BETA2 I Mod Pha Re Im``, F̄ = F/(ρ·g·A²·L^k), k = 1 forces, 2 moments
  (L = ``ulen``).  ``.8`` has I = 1, 2, 6 only (heave, roll, pitch read as zero by its
  definition; a ``.8`` row with I = 3, 4, 5 or a second body is refused).  Rows with
  BETA1 = BETA2 are the mean drift of a unidirectional wave, real: an imaginary part above
  REAL_RTOL of the file's largest |F̄| is refused at its line (WAMIT leaves round-off there,
  ~1e-7 of the largest value, on dofs that are zero by symmetry: the entry's own size is no
  scale for it), the real part kept.  Rows with BETA1 ≠ BETA2 (bidirectional, WAMIT's
  Re{A₁A₂*·F̄}) are kept in ``cross``, not used by the mean drift of a sea (the cross terms
  of two random-phase components average to zero) and said in ``warnings``.
- ``.10d`` / ``.11d`` / ``.12d``: lines ``PER1 PER2 BETA1 BETA2 I Mod Pha Re Im``, the same
  non-dimensionalisation, WAMIT's own difference-frequency form
  F = Re Σ_i Σ_j A_i·A_j*·F̄⁻_ij·e^{i(ω_i − ω_j)t} = ours, no conversion.  One triangle is
  enough (the other is its complex conjugate with the headings swapped); an entry written in
  both triangles must agree with its mirror's conjugate to MIRROR_RTOL of the file's largest
  |F̄| (the two are then averaged), an error naming both lines otherwise; a pair of the
  frequency grid written in neither is an error.  The diagonal (PER1 = PER2, BETA1 = BETA2)
  is its own mirror, the mean drift: real to REAL_RTOL of the file's largest |F̄| (as for
  ``.7/.8/.9``), the real part kept.

Both (``lines.numeric_rows``, the first-order readers' rules): lines before the first row that
do not start like a number are header lines (WAMIT's NUMHDR = 1: "WAMIT Numeric Output --
Filename …"), after it every line must be a row; a row with fewer or more fields than the
layout, a word that is not a number, a non-finite value are errors at the line; PER = 0 and −1
(the zero and infinite periods) are skipped (no drift there); a repeated key is an error
naming both lines; a dof given at some (periods, headings) and missing at others is an
error (a truncated file); a dof missing at every one is zero (WAMIT leaves out what it does
not compute), said in ``warnings``.

Capytaine (needs the `bem` extra): a dataset as ``cpt.export_dataset`` writes it holding
``cpt.post_pro.far_field_mean_drift_force``'s result as it returns it (``hydrofmu meandrift``
adds it to a user's dataset): ``drift_force_surge``, ``drift_force_sway``, ``drift_force_yaw``
over (omega, wave_direction_k, wave_direction_l) [rad], complex, per unit wave amplitude
squared (N/m², N·m/m²: the function leaves the amplitude out).  Its diagonal
(wave_direction_k = wave_direction_l) is the mean drift of a unidirectional wave, real (a
mean of products of first-order quantities: the same in Capytaine's e^{−iωt} and our
e^{+iωt}, no conjugation), read as Q(ω, ω; β, β) for dofs 1, 2, 6; the bidirectional
entries are not read (said in ``warnings``); ω = 0 and ∞ rows are dropped.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from .bem import body_dofs, period_variable as _variable, wamit_omega
from .lines import numeric_rows

MEAN_SUFFIXES = (".7", ".8", ".9")
QTF_SUFFIXES = (".10d", ".11d", ".12d")
# the checks are scaled by the file's largest |value| (non-dimensional for WAMIT), never by the
# entry's own: a dof zero by symmetry holds round-off as large as its own value
REAL_RTOL = 1e-4      # a mean drift's (diagonal's) imaginary part (WAMIT's round-off: ~1e-7)
MIRROR_RTOL = 1e-3    # an entry written in both triangles against its mirror's conjugate
HEADING_TOL = 1e-6    # deg


@dataclass
class MeanDriftData:
    """Mean drift of a BEM result in SI units (module docstring's convention).

    omega (nω,) [rad/s] increasing; directions (nβ,) [deg]; values (nω, nβ, n) real
    [N/m², N·m/m²] = Q(ω, ω; β, β); dofs [(body, k)]; bodies [names]; cross
    {(β1, β2): (nω, n) complex} the bidirectional entries (WAMIT BETA1 ≠ BETA2), not used for
    the mean drift of a sea; warnings: legal but said."""
    path: str
    kind: str
    omega: np.ndarray
    directions: np.ndarray
    values: np.ndarray
    dofs: list
    bodies: list
    cross: dict = field(default_factory=dict)
    rotation_centers: dict = field(default_factory=dict)
    rho: float = None
    g: float = None
    water_depth: float = None
    warnings: list = field(default_factory=list)

    def body(self, name):
        """(nω, nβ, 6) real of one body, zero for dofs the file leaves out."""
        return body_dofs(self.values, self.dofs, name)


@dataclass
class QTFData:
    """Difference-frequency QTF of a BEM result in SI units (module docstring's convention).

    omega (nω,) [rad/s] increasing; pairs [(β1, β2)] [deg] the heading pairs the file holds;
    values (nω, nω, nP, n) complex [N/m², N·m/m²], Q⁻(ω_i, ω_j; β1, β2) with both triangles
    filled (Q(ω_j, ω_i; β2, β1) = conj Q(ω_i, ω_j; β1, β2)); dofs [(body, k)]; bodies."""
    path: str
    kind: str
    omega: np.ndarray
    pairs: list
    values: np.ndarray
    dofs: list
    bodies: list
    rotation_centers: dict = field(default_factory=dict)
    rho: float = None
    g: float = None
    water_depth: float = None
    warnings: list = field(default_factory=list)

    def body(self, name):
        """(nω, nω, nP, 6) complex of one body, zero for dofs the file leaves out."""
        return body_dofs(self.values, self.dofs, name)

    def mean(self) -> MeanDriftData:
        """The diagonal (ω_i = ω_j, β1 = β2): the mean drift, real by the conjugate symmetry."""
        uni = [p for p, (b1, b2) in enumerate(self.pairs) if abs(b1 - b2) <= HEADING_TOL]
        if not uni:
            raise InputError(self.path, None, "BETA1 BETA2", "no unidirectional heading pair (BETA1 = BETA2): "
                                                             "no mean drift in the file")
        idx = np.arange(self.omega.size)
        diag = self.values[idx, idx][:, uni, :]
        return MeanDriftData(self.path, self.kind, self.omega, np.array([self.pairs[p][0] for p in uni]),
                             diag.real.copy(), self.dofs, self.bodies, rotation_centers=self.rotation_centers,
                             rho=self.rho, g=self.g, water_depth=self.water_depth, warnings=list(self.warnings))


def read_mean_drift(path, ulen=None, rho=None, g=None, period_variable=None) -> MeanDriftData:
    """Mean drift of a WAMIT .7/.8/.9 file (``ulen`` [m], ``rho``, ``g`` make it dimensional;
    ``period_variable``: what its first column is, as the run's IPEROUT wrote it, default period),
    a WAMIT .10d/.11d/.12d (its diagonal) or a Capytaine dataset (.nc) holding
    ``drift_force_surge``, ``drift_force_sway``, ``drift_force_yaw`` (``hydrofmu meandrift``)."""
    path = Path(path)
    if path.suffix.lower() in (".nc", ".nc4", ".netcdf"):
        return _capytaine_mean(path)
    if path.suffix in MEAN_SUFFIXES:
        return _wamit_mean(path, ulen, rho, g, _variable(path, period_variable))
    if path.suffix in QTF_SUFFIXES:
        return read_qtf(path, ulen, rho, g, period_variable).mean()
    raise InputError(path, None, "bem", "expected a WAMIT mean drift file (.7 control surface, .8 momentum, "
                                        ".9 pressure), a WAMIT QTF (.10d/.11d/.12d) or a Capytaine dataset (.nc) "
                                        "with drift_force_surge/sway/yaw (hydrofmu meandrift)")


def read_qtf(path, ulen=None, rho=None, g=None, period_variable=None) -> QTFData:
    """Difference-frequency QTF of a WAMIT .10d/.11d/.12d file (its two first columns as the
    run's IPEROUT wrote them: ``period_variable``, default period)."""
    path = Path(path)
    if path.suffix not in QTF_SUFFIXES:
        raise InputError(path, None, "bem", "expected a WAMIT difference-frequency QTF file (.10d, .11d or .12d)")
    return _wamit_qtf(path, ulen, rho, g, _variable(path, period_variable))


# ---------------------------------------------------------------------------- WAMIT

def _scale_checked(path, ulen, rho, g):
    for name, v in (("ulen", ulen), ("rho", rho), ("g", g)):
        if v is None or not v > 0:
            raise InputError(path, None, name, f"a WAMIT file is nondimensional: declare {name} (> 0)")


def _rows(path, names):
    """[(line number, [floats])] of a WAMIT numeric file with exactly len(names) fields per row
    (lines.numeric_rows: WAMIT's header lines first, then only rows)."""
    rows, _ = numeric_rows(path, names)
    if not rows:
        raise InputError(path, None, " ".join(names), "no data rows")
    return rows


def _dof_index(path, number, value):
    if value != int(value) or value < 1:
        raise InputError(path, number, "I", f"dof index must be a positive integer, found {value:g}")
    return int(value)


def _period(path, number, per, omega_of, variable, ulen, g):
    """The first column's value of a row (None for WAMIT's ω = 0 and ∞ limit rows: no drift
    there), its ω [rad/s] kept in ``omega_of`` (bem.wamit_omega: period, omega, Hz or KL)."""
    w = wamit_omega(path, number, per, variable, ulen, g)
    if w == 0.0 or not np.isfinite(w):
        return None
    omega_of[per] = w
    return per


def _heading(b):
    """Headings are compared on a 1e-6° grid (WAMIT writes them with a few decimals)."""
    return round(float(b), 6)


def _dim(value, i, rho, g, ulen):
    """WAMIT F̄ → SI per unit amplitude squared: ρ·g·L^k, k = 1 forces, 2 moments."""
    return value * rho * g * ulen ** (1 if (i - 1) % 6 < 3 else 2)


def _missing_dofs(path, table, keys, first):
    """Dofs given at some keys and missing at others: an error at the last line of the first
    incomplete key; returns the given dofs (sorted)."""
    given = sorted({i for k in keys for i in table[k]})
    for k in keys:
        gap = [i for i in given if i not in table[k]]
        if gap:
            last = max(first[k + (i,)] for i in table[k])
            raise InputError(path, last, "I", f"dof(s) {gap} given elsewhere are missing at {_key_text(k)} "
                                              f"(its rows end at line {last}): a truncated file?")
    return given


def _key_text(k):
    if len(k) == 3:
        return f"PER = {k[0]:g}, BETA1 = {k[1]:g}°, BETA2 = {k[2]:g}°"
    return f"PER1 = {k[0]:g}, PER2 = {k[1]:g}, BETA1 = {k[2]:g}°, BETA2 = {k[3]:g}°"


def _dof_warning(path, given, kind):
    want = [1, 2, 6] if kind == ".8" else list(range(1, 7))
    absent = [i for i in want if i not in given and ((i - 1) // 6) == 0]
    if not absent or max(given) > 6:
        return []
    return [f"{path}: dof(s) {absent} not in the file: read as zero (WAMIT leaves out what it does not compute)"]


def _largest(table):
    """The file's largest |Re + i·Im| (non-dimensional, finite periods): its checks' scale."""
    big = max((abs(v) for vals in table.values() for v in vals.values()), default=0.0)
    return big if big > 0 else 1.0


def _not_real(path, number, key, i, value, scale):
    """An error when a mean drift (a diagonal entry) is not real to REAL_RTOL of ``scale``."""
    if abs(value.imag) > REAL_RTOL * scale:
        raise InputError(path, number, "IM", f"{_key_text(key)}, I = {i}: the mean drift (a diagonal entry is its "
                                             f"own mirror) is real, found Im = {value.imag:g} against Re = "
                                             f"{value.real:g}, above {REAL_RTOL:g} of the file's largest |value| "
                                             f"{scale:g} (WAMIT's round-off stays near 1e-7 of it)")


def _wamit_mean(path, ulen, rho, g, variable="period"):
    _scale_checked(path, ulen, rho, g)
    rows = _rows(path, ["PER", "BETA1", "BETA2", "I", "MOD", "PHA", "RE", "IM"])
    table, first, omega_of = {}, {}, {}
    for number, (per, b1, b2, i, _, _, re, im) in rows:
        per = _period(path, number, per, omega_of, variable, ulen, g)
        if per is None:
            continue
        i = _dof_index(path, number, i)
        if path.suffix == ".8" and i not in (1, 2, 6):
            raise InputError(path, number, "I", f"a .8 (momentum conservation) holds I = 1, 2, 6 of one body only, "
                                                f"found I = {i} (a .9 or .7 renamed?)")
        b1, b2 = _heading(b1), _heading(b2)
        key = (per, b1, b2, i)
        if key in first:
            raise InputError(path, number, "PER BETA1 BETA2 I", f"duplicate ({per:g}, {b1:g}, {b2:g}, {i}) (first at "
                                                                f"line {first[key]})")
        first[key] = number
        table.setdefault((per, b1, b2), {})[i] = complex(re, im)
    scale = _largest(table)
    for key, vals in table.items():
        for i, v in vals.items():
            if key[1] == key[2]:
                _not_real(path, first[key + (i,)], key, i, v, scale)
    keys = sorted(table)
    given = _missing_dofs(path, table, keys, first)
    periods = sorted({k[0] for k in keys}, key=omega_of.get)      # increasing ω
    uni = sorted({k[1] for k in keys if k[1] == k[2]})
    if len(periods) < 2:
        raise InputError(path, None, "PER", f"{len(periods)} finite periods: at least 2 needed")
    if not uni:
        raise InputError(path, None, "BETA1 BETA2", "no unidirectional rows (BETA1 = BETA2): no mean drift")
    for per in periods:
        for b in uni:
            if (per, b, b) not in table:
                near = max((first[k + (i,)] for k in keys if k[0] == per for i in table[k]), default=None)
                raise InputError(path, near, "PER BETA1 BETA2", f"no rows for PER = {per:g} at BETA1 = BETA2 = "
                                                                f"{b:g}° (given at other periods): every period must "
                                                                f"list the same headings")
    values = np.array([[[_dim(table[(p, b, b)][i].real, i, rho, g, ulen) for i in given] for b in uni]
                       for p in periods])
    cross = {}
    for (p, b1, b2) in keys:
        if b1 != b2:
            cross.setdefault((b1, b2), np.full((len(periods), len(given)), np.nan, complex))
            cross[(b1, b2)][periods.index(p)] = [_dim(table[(p, b1, b2)][i], i, rho, g, ulen) for i in given]
    for (b1, b2), v in cross.items():
        if np.isnan(v.real).any():
            p = periods[int(np.argwhere(np.isnan(v.real).any(axis=1))[0][0])]
            raise InputError(path, None, "PER BETA1 BETA2", f"bidirectional pair ({b1:g}°, {b2:g}°) missing at "
                                                            f"PER = {p:g} (given at other periods)")
    dofs = [(f"body{(d - 1) // 6 + 1}", (d - 1) % 6 + 1) for d in given]
    bodies = list(dict.fromkeys(b for b, _ in dofs))
    warnings = _dof_warning(path, given, path.suffix)
    if cross:
        lines = sorted(first[k] for k in first if k[1] != k[2])
        warnings.append(f"{path}: {len(lines)} bidirectional rows (BETA1 ≠ BETA2, heading pairs "
                        f"{', '.join(f'({a:g}°, {b:g}°)' for a, b in sorted(cross))}; lines {lines[0]}…{lines[-1]}) "
                        f"are not read: the mean drift of a sea uses the unidirectional rows (BETA1 = BETA2)")
    return MeanDriftData(str(path), f"WAMIT {path.suffix}", np.array([omega_of[p] for p in periods]),
                         np.array(uni, float),
                         values, dofs, bodies, cross=cross, warnings=warnings)


def _wamit_qtf(path, ulen, rho, g, variable="period"):
    _scale_checked(path, ulen, rho, g)
    rows = _rows(path, ["PER1", "PER2", "BETA1", "BETA2", "I", "MOD", "PHA", "RE", "IM"])
    table, first, omega_of = {}, {}, {}
    for number, (p1, p2, b1, b2, i, _, _, re, im) in rows:
        p1 = _period(path, number, p1, omega_of, variable, ulen, g)
        p2 = _period(path, number, p2, omega_of, variable, ulen, g)
        if p1 is None or p2 is None:
            continue
        i = _dof_index(path, number, i)
        b1, b2 = _heading(b1), _heading(b2)
        key = (p1, p2, b1, b2, i)
        if key in first:
            raise InputError(path, number, "PER1 PER2 BETA1 BETA2 I", f"duplicate ({p1:g}, {p2:g}, {b1:g}, {b2:g}, "
                                                                      f"{i}) (first at line {first[key]})")
        first[key] = number
        table.setdefault((p1, p2, b1, b2), {})[i] = complex(re, im)     # non-dimensional until checked
    keys, scale = sorted(table), _largest(table)
    given = _missing_dofs(path, table, keys, first)
    periods = sorted({k[0] for k in keys} | {k[1] for k in keys}, key=omega_of.get)    # increasing ω
    if len(periods) < 2:
        raise InputError(path, None, "PER1 PER2", f"{len(periods)} finite periods: at least 2 needed")
    pairs = sorted({(k[2], k[3]) for k in keys} | {(k[3], k[2]) for k in keys})
    n, npair, nd = len(periods), len(pairs), len(given)
    pos = {p: k for k, p in enumerate(periods)}
    ppos = {p: k for k, p in enumerate(pairs)}
    q = np.full((n, n, npair, nd), np.nan, complex)
    line = np.zeros((n, n, npair, nd), int)       # the row each entry came from (0: none yet)
    for key, vals in table.items():
        p1, p2, b1, b2 = key
        i, j, h, hc = pos[p1], pos[p2], ppos[(b1, b2)], ppos[(b2, b1)]
        for c, d in sorted(enumerate(given), key=lambda cd: first[key + (cd[1],)]):   # in the file's order
            v, number = vals[d], first[key + (d,)]
            if (i, h) == (j, hc):          # the diagonal: its own mirror, the mean drift
                _not_real(path, number, key, d, v, scale)
                q[i, i, h, c], line[i, i, h, c] = v.real, number
                continue
            for (a, b, e, val) in ((i, j, h, v), (j, i, hc, np.conj(v))):
                if line[a, b, e, c]:       # written in the other triangle too
                    old = q[a, b, e, c]
                    if abs(old - val) > MIRROR_RTOL * scale:
                        m = old if (a, b, e) == (i, j, h) else np.conj(old)    # the mirror's conjugate
                        raise InputError(path, number, "RE IM",
                                         f"{_key_text(key)}, I = {d}: written in both triangles, but not the complex "
                                         f"conjugate of its mirror (line {line[a, b, e, c]}): {v.real:g}{v.imag:+g}i "
                                         f"against the mirror's conjugate {m.real:g}{m.imag:+g}i, apart by "
                                         f"{abs(old - val):.3g}, above {MIRROR_RTOL:g} of the file's largest |value| "
                                         f"{scale:g}")
                    val = 0.5 * (old + val)
                q[a, b, e, c], line[a, b, e, c] = val, number
    holes = np.argwhere(line[..., 0] == 0)
    if holes.size:
        a, b, c = holes[0]
        raise InputError(path, None, "PER1 PER2 BETA1 BETA2",
                         f"{len(holes)} (PER1, PER2, headings) combination(s) written in neither triangle, first "
                         f"PER1 = {periods[a]:g}, PER2 = {periods[b]:g}, headings {pairs[c]} (the file's periods "
                         f"make a {n} × {n} grid; every pair must be in one triangle)")
    q *= np.array([_dim(1.0, d, rho, g, ulen) for d in given])
    dofs = [(f"body{(d - 1) // 6 + 1}", (d - 1) % 6 + 1) for d in given]
    bodies = list(dict.fromkeys(b for b, _ in dofs))
    return QTFData(str(path), f"WAMIT {path.suffix}", np.array([omega_of[p] for p in periods]), pairs, q, dofs, bodies,
                   warnings=_dof_warning(path, given, path.suffix))


# ---------------------------------------------------------------------------- Capytaine

CAPYTAINE_DRIFT = {"drift_force_surge": 1, "drift_force_sway": 2, "drift_force_yaw": 6}


def _capytaine_mean(path):
    from .bem_waves import _centres, _complex, _open, _scalar
    ds = _open(path)
    names = [n for n in CAPYTAINE_DRIFT if n in ds]
    if not names:
        raise InputError(path, None, "drift_force_surge", "missing: add the far-field mean drift to the dataset with "
                                                          "`hydrofmu meandrift` (Capytaine's "
                                                          "post_pro.far_field_mean_drift_force)")
    want = ("omega", "wave_direction_k", "wave_direction_l")
    omega = ds["omega"].values.astype(float)
    keep = np.isfinite(omega) & (omega > 0)
    order = np.argsort(omega[keep])
    rad = np.atleast_1d(ds["wave_direction_k"].values.astype(float))
    if rad.tolist() != np.atleast_1d(ds["wave_direction_l"].values.astype(float)).tolist():
        raise InputError(path, None, "wave_direction_l", "expected the same headings as wave_direction_k")
    if np.any(np.abs(rad) > 2 * np.pi + 1e-9):
        raise InputError(path, None, "wave_direction_k", f"{rad[np.argmax(np.abs(rad))]:g} is beyond ±2π: Capytaine "
                                                         "gives directions in radians")
    idx = np.arange(rad.size)
    values, warnings = [], []
    # frequencies where the drift was not computed (hydrofmu meandrift --omega/--every): NaN rows
    solved = np.ones(int(keep.sum()), bool)
    for name in names:
        var = ds[name]
        dims = [d for d in var.dims if d != "complex"]
        if sorted(dims) == sorted(want):
            q = np.moveaxis(_complex(var, path), [dims.index(d) for d in want], [0, 1, 2])[keep][order]
            solved &= ~np.all(np.isnan(q.real), axis=(1, 2))
    if not solved.all():
        warnings.append(f"{path}: the drift is not computed at {int((~solved).sum())} of the dataset's "
                        f"{solved.size} frequencies (NaN rows): read at the {int(solved.sum())} others")
    for name in names:
        var = ds[name]
        dims = [d for d in var.dims if d != "complex"]
        if sorted(dims) != sorted(want):
            raise InputError(path, None, name, f"expected dimensions {want}, found {tuple(dims)}")
        q = np.moveaxis(_complex(var, path), [dims.index(d) for d in want], [0, 1, 2])[keep][order][solved]
        diag = q[:, idx, idx]
        bad = ~np.isfinite(diag)
        if bad.any():
            i, j = np.argwhere(bad)[0]
            raise InputError(path, None, name, f"{bad.sum()} non-finite value(s) on the diagonal, first at omega="
                                               f"{omega[keep][order][solved][i]:g} rad/s, wave_direction="
                                               f"{np.degrees(rad[j]):g}°")
        values.append(diag)
        if rad.size > 1 and not any("bidirectional" in w for w in warnings):
            warnings.append(f"{path}: {name}: the bidirectional entries (wave_direction_k ≠ wave_direction_l) are not "
                            f"read (the mean drift of a sea uses the diagonal)")
    scale = max(float(np.abs(np.stack(values)).max()), 1e-300)     # the dataset's largest |value|
    for name, diag in zip(names, values):
        if np.any(np.abs(diag.imag) > REAL_RTOL * scale):
            raise InputError(path, None, name, f"the diagonal (wave_direction_k = wave_direction_l) is the mean drift, "
                                               f"real; found Im up to {np.abs(diag.imag).max():g}, above {REAL_RTOL:g} "
                                               f"of the dataset's largest |value| {scale:g}")
    values = [diag.real for diag in values]
    omega = omega[keep][order][solved]
    if omega.size < 1:
        raise InputError(path, None, "omega", "no finite frequency: no mean drift")
    dofs = [("body" if "body" not in ds.coords else str(np.atleast_1d(ds["body"].values)[0]), CAPYTAINE_DRIFT[n])
            for n in names]
    bodies = list(dict.fromkeys(b for b, _ in dofs))
    return MeanDriftData(str(path), "Capytaine", omega, np.degrees(rad), np.stack(values, axis=-1), dofs, bodies,
                         rotation_centers=_centres(ds, bodies), rho=_scalar(ds, "rho", path),
                         g=_scalar(ds, "g", path), water_depth=_scalar(ds, "water_depth", path),
                         warnings=warnings)
