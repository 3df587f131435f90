"""DeepLines ``*CURRENTPOL`` reader: current load coefficients per floating structure.

Layout, as the DeepLines manual prints it::

    *CURRENTPOL,NAME=FPSO
      XC    YC    ZC    SURFC          (load point, body axes [m]; reference surface [m²])
      ANGC  CXC   CYC   CMZC           (one row per incidence, as many rows as needed)
      ...

Numbers are separated by blanks (commas are tolerated). The rows run until the next line
starting with ``*`` or the end of the file; other ``*`` keywords (the rest of a DeepLines
model) are skipped. Several ``*CURRENTPOL`` blocks may follow each other, one per
structure. Lines starting with ``!`` or ``#`` are comments. The keyword and ``NAME`` are
case-insensitive and may have blanks around ``=`` and ``,``.

Checks: NAME given, at most 8 characters, no blanks, not repeated (case-insensitive);
first line exactly 4 numbers with SURFC > 0; each row exactly 4 numbers; at least 2 rows;
ANGC [deg] in [0, 360] and strictly increasing. Whether the table spans the circle is
checked when the scene's symmetry is known (physics.current_polar.expand_polar).

Units: ANGC in degrees, counter-clockwise from body +x, the direction the relative current
goes to; CXC, CYC dimensionless (Fx = ½ρ·SURFC·CXC·V²), CMZC in m (Mz = ½ρ·SURFC·CMZC·V²,
the reference length is folded into the coefficient).
"""
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError
from .lines import check_profile, fields, read_lines

KEYWORD = "*CURRENTPOL"
ROW = ("ANGC", "CXC", "CYC", "CMZC")


@dataclass
class CurrentPolarData:
    """One ``*CURRENTPOL`` block as given in the deck.

    ``xc, yc, zc`` [m]: load point in body axes; ``surfc`` [m²]; ``angles`` [deg], ``cx``,
    ``cy`` [-], ``cmz`` [m]: one entry per row. ``path``/``line``: the keyword line;
    ``rows``: the line number of each row (for error messages).
    """
    name: str
    xc: float
    yc: float
    zc: float
    surfc: float
    angles: np.ndarray
    cx: np.ndarray
    cy: np.ndarray
    cmz: np.ndarray
    path: str = ""
    line: int = 0
    rows: list = field(default_factory=list)


def read_current_polars(path):
    """Read every ``*CURRENTPOL`` block of ``path``: structure name → CurrentPolarData.

    Raises InputError naming the file, the line and the field on the first problem.
    """
    lines = read_lines(path, comment=("!", "#"))
    out = {}
    pos = 0
    while pos < len(lines):
        line = lines[pos]
        end = pos + 1
        while end < len(lines) and not lines[end].text.startswith("*"):
            end += 1
        if _is_currentpol(line):
            data = _read_block(line, lines[pos + 1:end])
            key = data.name.upper()
            if key in out:
                raise line.error("NAME", f"structure {data.name!r} already has a *CURRENTPOL "
                                         f"at line {out[key].line}")
            out[key] = data
        pos = end
    if not out:
        raise InputError(path, None, KEYWORD, "no *CURRENTPOL keyword in the file")
    return {d.name: d for d in out.values()}


def _is_currentpol(line):
    text = line.text.replace(" ", "").upper()
    if not text.startswith(KEYWORD):
        return False
    if text != KEYWORD and not text.startswith(KEYWORD + ","):  # e.g. '*CURRENTPOL NAME=X'
        raise line.error("NAME", f"expected *CURRENTPOL,NAME=structure, found {line.text!r}")
    return True


def _read_block(head, block):
    name = _name(head)
    if not block:
        raise head.error("XC", "missing first line XC YC ZC SURFC")
    first = block[0]
    if len(first.words) != 4:
        raise first.error("XC", f"first line must hold the 4 values XC YC ZC SURFC, found "
                                f"{len(first.words)}; the ANGC CXC CYC CMZC rows start on the next line")
    p = fields(first, ["XC", "YC", "ZC", "SURFC"])   # finite: checked by fields
    if p["SURFC"] <= 0:
        raise first.error("SURFC", f"reference surface must be > 0, found {p['SURFC']}")
    rows = block[1:]
    if len(rows) < 2:
        at = rows[-1] if rows else first
        raise at.error("ANGC", f"*CURRENTPOL,NAME={name}: at least 2 rows ANGC CXC CYC CMZC "
                               f"are needed, found {len(rows)}")
    table = np.empty((len(rows), 4))
    for i, row in enumerate(rows):
        names = [f"{n}({i + 1})" for n in ROW]
        if len(row.words) != 4:
            field_ = names[min(len(row.words), 3)]
            raise row.error(field_, f"row {i + 1} must hold the 4 values ANGC CXC CYC CMZC, "
                                    f"found {len(row.words)}")
        v = fields(row, names)
        table[i] = [v[n] for n in names]
        angle = table[i, 0]
        if not 0.0 <= angle <= 360.0:
            raise row.error(names[0], f"incidence must be in [0, 360] degrees, found {angle:g}")
        if i and angle <= table[i - 1, 0]:
            raise row.error(names[0], f"incidences must increase strictly: {angle:g} follows "
                                      f"{table[i - 1, 0]:g} (line {rows[i - 1].number})")
    return CurrentPolarData(name, p["XC"], p["YC"], p["ZC"], p["SURFC"],
                            table[:, 0].copy(), table[:, 1].copy(), table[:, 2].copy(), table[:, 3].copy(),
                            head.path, head.number, [r.number for r in rows])


def _name(head):
    """NAME of a ``*CURRENTPOL,NAME=...`` line (≤ 8 characters, no blanks)."""
    params = head.text.split(",")[1:]
    name = None
    for p in params:
        key, _, value = p.partition("=")
        if key.strip().upper() != "NAME" or not _:
            raise head.error("NAME", f"expected NAME=structure, found {p.strip()!r}")
        if name is not None:
            raise head.error("NAME", "NAME given twice")
        name = value.strip()
    if name is None:
        raise head.error("NAME", "missing NAME=structure after *CURRENTPOL")
    if not name or any(c.isspace() for c in name):
        raise head.error("NAME", f"structure name must be non-empty without blanks, found {name!r}")
    if len(name) > 8:
        raise head.error("NAME", f"structure name must have at most 8 characters, found {name!r} ({len(name)})")
    return name


# --- current profile: *CURRENT and *CURPROF ---------------------------------------------
CURRENT, CURPROF = "*CURRENT", "*CURPROF"


def read_current_profile(path):
    """The current of a DeepLines data file as profile rows [[z, speed, direction], ...].

    hydrofmu's reading of the two keywords (the manual excerpt names them, not their data)::

        *CURRENT
          VC  DIRC               surface speed [m/s], direction [deg, going to, CCW from +x]
        *CURPROF                 (optional: without it the current is uniform)
          Z  RATIO  [DIR]        one row per level: z ≤ 0 [m] (z up, 0 at the mean free surface),
                                 speed RATIO·VC, direction DIR (default DIRC)

    Other keywords are skipped.  Raises InputError naming file, line and field.
    """
    lines = read_lines(path, comment=("!", "#"))
    blocks = {}
    pos = 0
    while pos < len(lines):
        end = pos + 1
        while end < len(lines) and not lines[end].text.startswith("*"):
            end += 1
        key = lines[pos].text.replace(" ", "").upper().split(",")[0]
        if key in (CURRENT, CURPROF):
            if key in blocks:
                raise lines[pos].error(key, f"{key} given twice (first at line {blocks[key][0].number})")
            blocks[key] = (lines[pos], lines[pos + 1:end])
        pos = end
    if CURRENT not in blocks:
        raise InputError(path, None, CURRENT, "no *CURRENT keyword in the file")
    head, body = blocks[CURRENT]
    if len(body) != 1:
        at = body[1] if len(body) > 1 else head
        raise at.error("VC", f"*CURRENT takes one line 'VC DIRC', found {len(body)}")
    c = fields(body[0], ["VC", "DIRC"])
    if CURPROF not in blocks:
        rows, where = [[0.0, c["VC"], c["DIRC"]]], [(body[0], {"z": "VC", "speed": "VC", "direction": "DIRC"})]
    else:
        head, body = blocks[CURPROF]
        if not body:
            raise head.error("Z", "*CURPROF has no 'Z RATIO [DIR]' row")
        rows, where = [], []
        for k, line in enumerate(body):
            names = [f"Z({k + 1})", f"RATIO({k + 1})", f"DIR({k + 1})"]
            v = fields(line, names, defaults={names[2]: c["DIRC"]})
            rows.append([v[names[0]], v[names[1]] * c["VC"], v[names[2]]])
            where.append((line, dict(zip(("z", "speed", "direction"), names))))
    return check_profile(rows, where)
