"""DeepLines-style current loads from a polar table of coefficients.

Load (all in body axes unless said otherwise):

    P = (XC, YC, ZC)                        load point [m], body axes; r = R·P (global offset)
    v_rel = u_c − (v + ω × r)               relative water velocity at P [m/s], global; u_c is
                                            the current at P's height (physics/current.py)
    (vx, vy, ·) = Rᵀ·v_rel                  body axes; the body-z component is ignored
    V = √(vx² + vy²),  α = atan2(vy, vx)    α in degrees in [0, 360), counter-clockwise from
                                            body +x: the direction the water goes to (α = 0 if V = 0)
    q = ½·ρ·SURFC·V²
    F_body = q·(CXC(α), CYC(α), 0),  M_body = (0, 0, q·CMZC(α))     at P
    load = [R·F_body ; r × R·F_body + R·M_body]   global, about the reference point

Our extension (``waves = true``; DeepLines' polar sees the current alone): u_c also holds the
incident-wave particle velocity at P's instantaneous position (physics/wave_kinematics.py),
none when P is above the instantaneous surface.

CXC, CYC are dimensionless, CMZC has the unit m (the formula has no reference length).
Coefficients interpolate linearly in α with wrap-around (359° → 0°).

Symmetry (declared in the scene, not in the deck) completes a table that covers part of the
circle.  Each mirror maps a row (α, CX, CY, CMZ) to a new row:

    "xz"  port/starboard (mirror y → −y):   (360 − α,  CX, −CY, −CMZ)
    "yz"  fore/aft       (mirror x → −x):   (180 − α, −CX,  CY, −CMZ)
    "xz+yz"  both, plus their product:       (180 + α, −CX, −CY,  CMZ)

A mirror that maps a row onto an angle already present must give the same coefficients
(e.g. with "xz", CY = CMZ = 0 at 0° and 180°), else the declaration contradicts the data.
The mirror plane must contain the load point (YC = 0 for "xz", XC = 0 for "yz"): the
moment is about P, and the mirror of P must be P.

Coverage rule ("the table spans the circle"): after expansion, the widest gap between
consecutive angles, wrap-around included, is no wider than the widest step between the
rows the user gave, and no wider than 90°.
"""
import bisect
import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import InputError

SYMMETRIES = ("none", "xz", "yz", "xz+yz")
MAX_GAP = 90.0  # [deg] widest gap allowed between table angles after expansion
_ANGLE_TOL = 1e-9  # [deg] angles closer than this are the same angle
_VALUE_TOL = 1e-6  # relative tolerance for mirrored coefficients to agree
# Mirror maps (a0, a, sx, sy, sm): α → a0 + a·α, CX → sx·CX, CY → sy·CY, CMZ → sm·CMZ.
_XZ = (360.0, -1.0, 1.0, -1.0, -1.0)
_YZ = (180.0, -1.0, -1.0, 1.0, -1.0)
_BOTH = (180.0, 1.0, -1.0, -1.0, 1.0)
_MAPS = {"none": (), "xz": (_XZ,), "yz": (_YZ,), "xz+yz": (_XZ, _YZ, _BOTH)}
_FIELDS = ("CXC", "CYC", "CMZC")


def normalize_symmetry(symmetry):
    """'none' | 'xz' | 'yz' | 'xz+yz' from a user spelling (case, blanks, 'yz+xz'); None if unknown."""
    s = "none" if symmetry is None else str(symmetry).replace(" ", "").lower()
    if s == "yz+xz":
        s = "xz+yz"
    return s if s in SYMMETRIES else None


def expand_polar(data, symmetry):
    """Complete a ``*CURRENTPOL`` table with its declared symmetry.

    ``data``: a decks.deeplines.CurrentPolarData; ``symmetry``: one of SYMMETRIES.
    Returns (angles [deg] sorted in [0, 360), cx, cy, cmz). Raises InputError (file, line
    of the *CURRENTPOL keyword or of the contradicted row, field ``symmetry`` or the
    coefficient) if the symmetry contradicts the data or the result does not span the circle.
    """
    sym = normalize_symmetry(symmetry)
    if sym is None:
        raise InputError(data.path, data.line, "symmetry",
                         f"unknown symmetry {symmetry!r}; expected one of {', '.join(SYMMETRIES)}")
    a = np.asarray(data.angles, dtype=float)
    if len(a) < 2 or a[0] < 0.0 or a[-1] > 360.0 or np.any(np.diff(a) <= 0.0):
        raise InputError(data.path, data.line, "ANGC", "need at least 2 incidences, strictly increasing "
                                                       "within [0, 360] degrees")
    table, problem = _expand(data, sym)
    if problem is not None:
        raise problem
    gap = _coverage_gap(data, table[:, 0])
    if gap is not None:
        width, lo, limit = gap
        fixes = [s for s in SYMMETRIES[1:] if s != sym and _complete(data, s)]
        hint = (f"symmetry {' or '.join(repr(s) for s in fixes)} would complete it" if fixes else
                "no symmetry completes it consistently with the data: add rows")
        raise InputError(data.path, data.line, "symmetry",
                         f"*CURRENTPOL,NAME={data.name} with symmetry {sym!r} does not span the circle: "
                         f"gap of {width:g}° from {lo:g}° to {(lo + width) % 360:g}° is wider than "
                         f"{limit:g}° (the table's widest step, capped at {MAX_GAP:g}°); {hint}")
    return table[:, 0].copy(), table[:, 1].copy(), table[:, 2].copy(), table[:, 3].copy()


def _expand(data, sym):
    """(n×4 table sorted by angle, None) or (None, InputError) if a mirror contradicts the data."""
    if sym in ("xz", "xz+yz") and data.yc != 0.0:
        return None, InputError(data.path, data.line, "YC",
                                f"symmetry {sym!r} mirrors about the body x-z plane, which must hold the "
                                f"load point, but YC = {data.yc:g}")
    if sym in ("yz", "xz+yz") and data.xc != 0.0:
        return None, InputError(data.path, data.line, "XC",
                                f"symmetry {sym!r} mirrors about the body y-z plane, which must hold the "
                                f"load point, but XC = {data.xc:g}")
    base = np.column_stack([data.angles, data.cx, data.cy, data.cmz]).astype(float)
    n = len(base)
    lines = list(data.rows) or [data.line] * n
    rows = [base] + [np.column_stack([a0 + a * base[:, 0], sx * base[:, 1], sy * base[:, 2], sm * base[:, 3]])
                     for a0, a, sx, sy, sm in _MAPS[sym]]
    rows = np.concatenate(rows)
    rows[:, 0] = np.mod(rows[:, 0], 360.0)
    rows[rows[:, 0] > 360.0 - _ANGLE_TOL, 0] = 0.0
    # Row k of `rows` comes from given row k % n; it is an image (mirrored) when k >= n.
    scale = np.maximum(np.abs(base[:, 1:]).max(axis=0), 1e-300)
    out, keep = [], None  # keep: index of the row that stands for the current angle
    for k in np.argsort(rows[:, 0], kind="stable"):
        if keep is None or rows[k, 0] - rows[keep, 0] > _ANGLE_TOL:
            keep = k
            out.append(rows[k])
            continue
        bad = np.abs(rows[k, 1:] - rows[keep, 1:]) > _VALUE_TOL * scale
        if bad.any():
            j = int(np.argmax(bad))
            at = lines[k % n] if k < n else lines[keep % n]  # prefer the line of a given row

            def who(i):
                kind = "given row" if i < n else "mirror of the row"
                where = "" if lines[i % n] is None else f" (line {lines[i % n]})"
                return f"{kind} at {base[i % n, 0]:g}°{where}"
            return None, InputError(
                data.path, at, _FIELDS[j],
                f"symmetry {sym!r} contradicts the table at {rows[keep, 0]:g}°: the {who(keep)} gives "
                f"{_FIELDS[j]} = {rows[keep, 1 + j]:g}, the {who(k)} gives {rows[k, 1 + j]:g}")
    return np.array(out) + 0.0, None  # + 0.0 turns mirrored -0.0 into 0.0


def _coverage_gap(data, angles):
    """None if ``angles`` (sorted, in [0, 360)) span the circle, else (gap, start, limit) [deg]."""
    limit = min(float(np.max(np.diff(data.angles))), MAX_GAP)
    gaps = np.diff(np.append(angles, angles[0] + 360.0))
    i = int(np.argmax(gaps))
    return None if gaps[i] <= limit + _ANGLE_TOL else (float(gaps[i]), float(angles[i]), limit)


def _complete(data, sym):
    table, problem = _expand(data, sym)
    return problem is None and _coverage_gap(data, table[:, 0]) is None


@dataclass
class CurrentPolar:
    """Current load kernel (effect protocol of physics.state) from an expanded table.

    ``angles`` [deg], strictly increasing in [0, 360), spanning the circle (expand_polar);
    ``cx``, ``cy`` [-], ``cmz`` [m] per angle; ``xc, yc, zc`` [m] load point in body axes;
    ``surfc`` [m²] reference surface.
    """
    name: str
    angles: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    cmz: np.ndarray
    xc: float
    yc: float
    zc: float
    surfc: float
    waves: bool = False   # our extension: u_c also holds the incident waves' velocity at P (env.water)
    uses_current: ClassVar[bool] = True
    uses_acceleration: ClassVar[bool] = False

    def __post_init__(self):
        a = np.asarray(self.angles, dtype=float)
        c = np.column_stack([self.cx, self.cy, self.cmz]).astype(float)
        if a.ndim != 1 or len(a) < 1 or c.shape[0] != len(a):
            raise ValueError("angles, cx, cy, cmz must be 1-D arrays of the same length")
        if a[0] < 0.0 or a[-1] >= 360.0 or np.any(np.diff(a) <= 0.0):
            raise ValueError("angles must increase strictly within [0, 360)")
        # Table closed over one period, so a plain search replaces np.interp(period=360).
        self._a = np.concatenate([[a[-1] - 360.0], a, [a[0] + 360.0]])
        self._c = np.vstack([c[-1], c, c[0]])
        self._slope = np.diff(self._c, axis=0) / np.diff(self._a)[:, None]
        self._p = np.array([self.xc, self.yc, self.zc], dtype=float)
        # the same table as plain lists: the per-step load works on floats
        self._rows = (self._a.tolist(), self._c.tolist(), self._slope.tolist())

    @classmethod
    def from_deck(cls, data, symmetry, name=None):
        """Kernel from a decks.deeplines.CurrentPolarData and the scene's symmetry."""
        angles, cx, cy, cmz = expand_polar(data, symmetry)
        return cls(name or data.name, angles, cx, cy, cmz, data.xc, data.yc, data.zc, data.surfc)

    def coefficients(self, alpha):
        """(CXC, CYC, CMZC) (floats) at incidence ``alpha`` [deg] in [0, 360), linear with
        wrap-around."""
        angles, coef, slope = self._rows
        i = bisect.bisect_right(angles, alpha) - 1
        d = alpha - angles[i]
        (c0, c1, c2), (s0, s1, s2) = coef[i], slope[i]
        return c0 + d * s0, c1 + d * s1, c2 + d * s2

    def load(self, motion, env):
        """[force N; moment N·m about the reference point], global axes."""
        # plain floats throughout: numpy's per-call cost dominates on 3-vectors
        (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = motion.rot_rows
        px, py, pz = self.xc, self.yc, self.zc
        rx, ry, rz = r00 * px + r01 * py + r02 * pz, r10 * px + r11 * py + r12 * pz, r20 * px + r21 * py + r22 * pz
        vx, vy, vz, wx, wy, wz = motion.velocity.tolist()
        ox, oy, oz = motion.position.tolist()
        cx, cy, cz = env.current_xyz(oz + rz)   # current at P
        if self.waves and env.water is not None:   # our extension: the waves' velocity at P too
            row = env.water.at(ox + rx, oy + ry, oz + rz)
            if env.water.wet(row, oz + rz):
                cx, cy, cz = cx + row[0], cy + row[1], cz + row[2]
        ux, uy, uz = cx - (vx + wy * rz - wz * ry), cy - (vy + wz * rx - wx * rz), cz - (vz + wx * ry - wy * rx)
        bx, by = r00 * ux + r10 * uy + r20 * uz, r01 * ux + r11 * uy + r21 * uz   # body axes
        v2 = bx * bx + by * by
        alpha = math.degrees(math.atan2(by, bx)) % 360.0 if v2 > 0.0 else 0.0
        if alpha >= 360.0:  # -tiny % 360 rounds to 360
            alpha = 0.0
        q = 0.5 * env.rho * self.surfc * v2
        c0, c1, c2 = self.coefficients(alpha)
        c0, c1, c2 = q * c0, q * c1, q * c2
        fx, fy, fz = r00 * c0 + r01 * c1, r10 * c0 + r11 * c1, r20 * c0 + r21 * c1
        return np.array((fx, fy, fz, ry * fz - rz * fy + r02 * c2, rz * fx - rx * fz + r12 * c2,
                         rx * fy - ry * fx + r22 * c2))

    def mass_matrix(self, motion):
        return np.zeros((6, 6))

    C_TAG = "polar"   # its record in a compiled FMU (current_polar.c)

    def c_params(self):
        """current_polar.c's parameters: [n, xc, yc, zc, surfc, the closed table's angles
        (n + 2), coefficients ((n + 2)·3), slopes ((n + 1)·3), waves (0/1)]."""
        return ([float(len(self.angles)), self.xc, self.yc, self.zc, self.surfc]
                + self._a.tolist() + self._c.ravel().tolist() + self._slope.ravel().tolist() + [float(self.waves)])
