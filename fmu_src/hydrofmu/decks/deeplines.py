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
case-insensitive and may have blanks around ``=`` and ``,``.  Keywords are written in full
(decks/lines.py ``Grammar``, exact): a ``*`` keyword that resembles ours (``*CURRENTPL``,
``*CURRENTPOLE``, ``*CURRENTS``) is an error, not skipped; so is an unknown keyword right after
a ``*CURRENTPOL`` block whose lines read as more of its rows (4 numbers, the angles going on).
The table has no count: every row up to the next keyword is read.

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
from .lines import Grammar, Line, Reading, check_profile, convert, fields, interrupted, read_lines, with_reading

KEYWORD = "*CURRENTPOL"
ROW = ("ANGC", "CXC", "CYC", "CMZC")
CURRENT, CURPROF = "*CURRENT", "*CURPROF"


def _keyword(line):
    """The keyword of a ``*`` line, blanks and what follows a comma or a blank left out."""
    text = line.text.split(",")[0].strip()
    return [text.split()[0]] if text.startswith("*") and text.split() else []


GRAMMAR = Grammar([KEYWORD, CURRENT, CURPROF], exact=True, words=_keyword)


def _blocks(lines, reading):
    """(keyword line, its Keyword or None, its data lines) of each ``*`` block; the unknown
    ones (and lines before the first keyword) recorded as skipped."""
    out, pos = [], 0
    while pos < len(lines):
        end = pos + 1
        while end < len(lines) and not lines[end].text.startswith("*"):
            end += 1
        key = GRAMMAR.find(lines[pos])
        out.append((lines[pos], key, lines[pos + 1:end]))
        pos = end
    return out


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
    reading = Reading(str(path), "DeepLines")
    out, previous = {}, None
    for line, key, block in _blocks(lines, reading):
        if key is not None and key.spelling == KEYWORD:
            _is_currentpol(line)
            data = _read_block(line, block)
            k = data.name.upper()
            if k in out:
                raise line.error("NAME", f"structure {data.name!r} already has a *CURRENTPOL "
                                         f"at line {out[k].line}")
            out[k] = previous = data
            reading.use(f"{KEYWORD},NAME={data.name}", line)
            continue
        if key is None and previous is not None and block:
            interrupted(line, f"*CURRENTPOL,NAME={previous.name} (line {previous.line})",
                        lambda: _more_rows(previous, block))
        reading.skip(line, count=len(block) + 1)
        previous = None
    if not out:
        raise InputError(path, None, KEYWORD, "no *CURRENTPOL keyword in the file")
    return with_reading({d.name: d for d in out.values()}, reading)


def _more_rows(data, block):
    """True when every line of ``block`` is a row ANGC CXC CYC CMZC going on from the table."""
    last = data.angles[-1]
    for row in block:
        angle = fields(row, list(ROW))["ANGC"]
        if not last < angle <= 360.0:
            return False
        last = angle
    return True


def _is_currentpol(line):
    text = line.text.replace(" ", "").upper()
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


def read_current_profile(path):
    """The current of a DeepLines data file as profile rows [[z, speed, direction], ...].

    ``*CURRENT`` as the DeepLines keyword list prints it (principia-support.com, List of
    keywords, *CURRENT): one line per time, continued with ``&``,
    ``TCUR TETC(1) VCUR(1) … TETC(NZCUR) VCUR(NZCUR)``: time [s], then per level the
    heading [deg from +x, anticlockwise, the way the current goes: 180 = towards −x] and
    the speed [m/s]; NZCUR = 1 (uniform) unless a ``*CURPROF`` precedes it.  One time line
    is a steady current (its TCUR is not used; the manual's own example gives 1.); several
    (a current changing in time) are refused: the master drives ``current.speed`` and
    ``current.direction`` in time instead.

    ``*CURPROF`` gives the levels ZCUR(1) … ZCUR(NZCUR).  Its data layout is not in the
    public keyword list (only its name and NZCUR are, through *CURRENT): hydrofmu reads the
    block as that list of level heights z [m] (global z up, 0 at the mean free surface, so
    ≤ 0), on one or more lines.  Data may start on the keyword line.  A file written
    otherwise (positive depths, a leading count) fails the checks below with an error, it
    is never read silently wrong.  Other keywords are skipped.

    Raises InputError naming file, line and field (a level above the surface, levels not
    ordered, a missing or extra value, *CURPROF after *CURRENT, several times)."""
    lines = read_lines(path, comment=("!", "#"), continuation="&")
    reading = Reading(str(path), "DeepLines current")
    blocks = {}
    for line, found, block in _blocks(lines, reading):
        key = found.spelling if found is not None else None
        if key not in (CURRENT, CURPROF):
            reading.skip(line, count=len(block) + 1)
            continue
        if key in blocks:
            raise line.error(key, f"{key} given twice (first at line {blocks[key][0].number})")
        blocks[key] = (line, _data(line, block))
        reading.use(key, line)
    if CURRENT not in blocks:
        raise InputError(path, None, CURRENT, "no *CURRENT keyword in the file")
    head, rows = blocks[CURRENT]
    if CURPROF in blocks:
        prof_head, prof_rows = blocks[CURPROF]
        if prof_head.number > head.number:
            raise prof_head.error(CURPROF, f"*CURPROF must precede *CURRENT (line {head.number}): the manual "
                                           f"reads *CURRENT with NZCUR = 1 otherwise")
        levels = [(row.at_word(k), w) for row in prof_rows for k, w in enumerate(row.words)]
        if not levels:
            raise prof_head.error("ZCUR(1)", "*CURPROF has no level ZCUR(1) ... ZCUR(NZCUR)")
        z = [(at, convert(at, f"ZCUR({j + 1})", w, float)) for j, (at, w) in enumerate(levels)]
    else:
        z = [(head, 0.0)]
    if not rows:
        raise head.error("TCUR(1)", "*CURRENT has no line 'TCUR TETC(1) VCUR(1) ...'")
    if len(rows) > 1:
        raise rows[1].error("TCUR(2)", f"*CURRENT gives {len(rows)} times: a current changing in time is not "
                                       f"read (give one line and drive current.speed and current.direction "
                                       f"from the master instead)")
    row, n = rows[0], len(z)
    names = ["TCUR(1)"] + [f"{f}(1,{j + 1})" for j in range(n) for f in ("TETC", "VCUR")]
    words = row.words
    if len(words) != len(names):
        short = len(words) < len(names)
        field_ = names[len(words)] if short else f"TETC(1,{n + 1})"
        at = row.at_word(len(words) - 1 if short else len(names))
        raise at.error(field_, f"{'missing value' if short else 'too many values'}: NZCUR = {n} level(s) "
                               f"({'from *CURPROF' if CURPROF in blocks else 'no *CURPROF'}) takes 1 + 2·NZCUR = "
                               f"{len(names)} values 'TCUR TETC VCUR ...', found {len(words)}")
    values = [convert(row.at_word(k), name, w, float) for k, (name, w) in enumerate(zip(names, words))]
    out, where = [], []
    for j, (at_z, zj) in enumerate(z):
        out.append([zj, values[2 + 2 * j], values[1 + 2 * j]])
        where.append(({"z": at_z, "speed": row.at_word(2 + 2 * j), "direction": row.at_word(1 + 2 * j)},
                      {"z": f"ZCUR({j + 1})" if CURPROF in blocks else "TCUR(1)",
                       "speed": names[2 + 2 * j], "direction": names[1 + 2 * j]}))
    return with_reading(check_profile(out, where, reading), reading)


def _data(head, body):
    """Data lines of a keyword block; words after the keyword on its own line count as a
    first data line (one line, as it was continued)."""
    rest = head.text.split(None, 1)[1] if len(head.text.split(None, 1)) > 1 else ""
    if not rest:
        return list(body)
    first = Line(head.path, head.number, rest, tuple((n, max(0, s - (len(head.text) - len(rest))))
                                                     for n, s in head.pieces))
    return [first] + list(body)
