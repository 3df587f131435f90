"""AQWA ``*Viscous Drag`` reader: a 6×6 quadratic drag matrix per floating body.

Layout, as the AQWA manual prints it (keywords case-insensitive, blanks around ``=``
allowed, numbers separated by commas and/or blanks)::

    *Viscous Drag
    FLOATING BODY=FPSO
    TYPE=MATRIX
    OPTION=RELATIVE
    V11, V12, V13, V14, V15, V16
    ...                              (six rows of six numbers)
    V61, V62, V63, V64, V65, V66
    FLOATING BODY=Buoy               (the body block repeats for further bodies)
    ...

``TYPE`` may only be ``MATRIX`` (the default when the line is left out); ``OPTION`` is
``ABSOLUTE`` (default when left out) or ``RELATIVE`` (body velocity relative to the current).
The settings follow the manual's order (TYPE, OPTION, then the rows or ``VISCOUS DRAG``), each
at most once: a setting after a later one is an error (it would belong to another body).

Named matrices (the manual's "Body - Viscous Drag Coefficients" table), hydrofmu's
plain-text layout: a matrix is defined once under a name in a ``*Viscous Drag
Coefficients`` section, and a body block refers to it with ``VISCOUS DRAG=name`` instead
of giving the six rows::

    *Viscous Drag Coefficients
    NAME=HullDrag
    (six rows of six numbers)
    NAME=...                         (further named matrices)

    *Viscous Drag
    FLOATING BODY=FPSO
    OPTION=RELATIVE
    VISCOUS DRAG=HullDrag

The sections may come in any order and repeat. A section runs until the next line
starting with ``*``. A whole AQWA input holds other ``*`` sections (geometry, mass,
environment, …): they are skipped, as are lines before the first section.  Keywords and
setting names are written in full, any case (decks/lines.py ``Grammar``, exact): a ``*``
keyword that resembles ours (``*Viscous Drg``, ``*Viscous``, a word after it) is an error,
not skipped; so is an unknown ``*`` section right after one of ours whose lines read as
more of it (a stray line inside our section).
Lines starting with ``#`` or ``!`` are comments. Names keep their spelling and inner
blanks; two bodies (or two matrices) whose names differ only by case are duplicates.

Units: V_ij is a drag coefficient times a projected area (times lever arms for the
rotational terms) such that F_i = −Σ_j V_ij·w_j·|w_j| with w in m/s and rad/s, F in N and
N·m; the matrix acts in body axes, moments about the body's reference point.
"""
import warnings
from dataclasses import dataclass

import numpy as np

from ..admissible import negative_diagonal
from ..errors import InputError, InputWarning
from .lines import Grammar, Reading, fields, interrupted, read_lines, with_reading

OPTIONS = ("ABSOLUTE", "RELATIVE")
DRAG, TABLE = "*Viscous Drag", "*Viscous Drag Coefficients"
GRAMMAR = Grammar([DRAG, TABLE], stems=["*Viscous"], exact=True)
_BODY, _TYPE, _OPTION, _REF, _NAME = (tuple(k.split()) for k in
                                      ("FLOATING BODY", "TYPE", "OPTION", "VISCOUS DRAG", "NAME"))
_ORDER = (_TYPE, _OPTION, _REF)      # the settings of a body block, in the manual's order


@dataclass
class ViscousDragData:
    """One body's viscous drag definition.

    ``matrix``: 6×6 V matrix [N/(m/s)², ...], body axes, about the reference point;
    ``option``: 'ABSOLUTE' or 'RELATIVE'; ``table``: name of the named matrix used, or None;
    ``path``/``line``: where the body block starts (its FLOATING BODY line).
    """
    name: str
    matrix: np.ndarray
    option: str
    table: str | None
    path: str
    line: int

    @property
    def relative(self):
        return self.option == "RELATIVE"


def read_viscous_drag(path):
    """Read ``*Viscous Drag`` body blocks (and named matrices) from ``path``.

    Returns body name → ViscousDragData, in file order. Raises InputError naming the
    file, the line and the field on the first problem.
    """
    lines = read_lines(path, comment=("#", "!"))
    reading = Reading(str(path), "AQWA")
    bodies, tables, refs = {}, {}, []  # refs: (body name, VISCOUS DRAG line)
    seen_drag = False
    pos, previous = 0, None           # previous: (our section's name, its first line) just read
    while pos < len(lines):
        line = lines[pos]
        key = GRAMMAR.find(line) if line.text.startswith("*") else None
        end = pos + 1
        while end < len(lines) and not lines[end].text.startswith("*"):
            end += 1
        block = lines[pos + 1:end]
        if key is None:
            # another section of the AQWA input (or lines before the first): skipped, unless
            # it reads as more of the section it follows
            if previous is not None and block:
                read = _read_bodies if previous[0] == DRAG else _read_tables
                interrupted(line, f"the {previous[0]} section at line {previous[1]}",
                            lambda: read(block, lines, end, {}, []) or True)
            reading.skip(line, count=end - pos)
            previous = None
            pos = end
            continue
        if key.spelling == DRAG:
            seen_drag = True
            if not block:
                raise line.error("FLOATING BODY", "*Viscous Drag has no FLOATING BODY block")
            before = len(bodies)
            _read_bodies(block, lines, end, bodies, refs)
            for b in list(bodies.values())[before:]:
                reading.use(f"{DRAG}: FLOATING BODY={b.name}", b.line)
        else:
            if not block:
                raise line.error("NAME", "*Viscous Drag Coefficients has no NAME block")
            before = len(tables)
            _read_tables(block, lines, end, tables)
            for name, _, number in list(tables.values())[before:]:
                reading.use(f"{TABLE}: NAME={name}", number)
        previous = (key.spelling, line.number)
        pos = end
    if not seen_drag:
        raise InputError(path, None, "*Viscous Drag", "no *Viscous Drag keyword in the file")
    for name, ref_line in refs:
        _, ref = _pair(ref_line)
        key = ref.upper()
        if key not in tables:
            known = ", ".join(t[0] for t in tables.values()) or "none"
            raise ref_line.error("VISCOUS DRAG", f"no matrix named {ref!r} under *Viscous Drag "
                                                 f"Coefficients (defined: {known})")
        bodies[name.upper()].matrix = tables[key][1].copy()
    return with_reading({d.name: d for d in bodies.values()}, reading)


def _pair(line):
    """(keyword key, value) of a ``KEY = value`` line, or (None, None) without '='."""
    if "=" not in line.text:
        return None, None
    key, value = line.text.split("=", 1)
    return tuple(key.upper().split()), value.strip()


def _read_bodies(block, lines, end, bodies, refs):
    i = 0
    prev_ref = False
    while i < len(block):
        head = block[i]
        key, name = _pair(head)
        if key != _BODY:
            hint = (" (rows are not allowed after VISCOUS DRAG=name)" if prev_ref and key is None else "")
            raise head.error("FLOATING BODY", f"expected FLOATING BODY=name, found {head.text!r}{hint}")
        if not name:
            raise head.error("FLOATING BODY", "empty body name")
        if name.upper() in bodies:
            first = bodies[name.upper()]
            raise head.error("FLOATING BODY", f"body {name!r} already defined at line {first.line}")
        i += 1
        settings = {}
        while i < len(block):
            key, value = _pair(block[i])
            if key is None or key == _BODY:
                break
            if key not in (_TYPE, _OPTION, _REF):
                raise block[i].error(block[i].text.split("=", 1)[0].strip().upper(),
                                     "unknown setting; expected TYPE, OPTION or VISCOUS DRAG")
            label = {_TYPE: "TYPE", _OPTION: "OPTION", _REF: "VISCOUS DRAG"}[key]
            if key in settings:
                raise block[i].error(label, f"given twice for body {name!r} "
                                            f"(first at line {settings[key][0].number})")
            later = [k for k in settings if _ORDER.index(k) > _ORDER.index(key)]
            if later:
                raise block[i].error(label, f"out of the manual's order for body {name!r}: FLOATING BODY, then "
                                            f"TYPE, OPTION, then the matrix or VISCOUS DRAG (found after "
                                            f"{' '.join(later[0])} at line {settings[later[0]][0].number})")
            settings[key] = (block[i], value)
            i += 1
        if _TYPE in settings:
            tline, value = settings[_TYPE]
            if value.upper() != "MATRIX":
                raise tline.error("TYPE", f"only TYPE=MATRIX is supported, found {value!r}")
        option = "ABSOLUTE"
        if _OPTION in settings:
            oline, value = settings[_OPTION]
            option = value.upper()
            if option not in OPTIONS:
                raise oline.error("OPTION", f"expected ABSOLUTE or RELATIVE, found {value!r}")
        data = ViscousDragData(name, None, option, None, head.path, head.number)
        if _REF in settings:
            rline, ref = settings[_REF]
            if not ref:
                raise rline.error("VISCOUS DRAG", "empty matrix name")
            data.table = ref
            refs.append((name, rline))
            prev_ref = True
        else:
            data.matrix, i = _read_matrix(block, i, lines, end, f"body {name!r}")
            prev_ref = False
        bodies[name.upper()] = data


def _read_tables(block, lines, end, tables):
    i = 0
    while i < len(block):
        head = block[i]
        key, name = _pair(head)
        if key != _NAME:
            raise head.error("NAME", f"expected NAME=name, found {head.text!r}")
        if not name:
            raise head.error("NAME", "empty matrix name")
        if name.upper() in tables:
            raise head.error("NAME", f"matrix {name!r} already defined at line {tables[name.upper()][2]}")
        matrix, i = _read_matrix(block, i + 1, lines, end, f"matrix {name!r}")
        tables[name.upper()] = (name, matrix, head.number)


def _read_matrix(block, i, lines, end, what):
    """Six rows V_r1..V_r6 from block[i:]; returns (6×6 array, next index)."""
    matrix = np.empty((6, 6))
    for r in range(6):
        names = [f"V{r + 1}{c + 1}" for c in range(6)]
        if i >= len(block) or "=" in block[i].text:
            # Name the line where the row was expected (next keyword line), else the last row.
            at = block[i] if i < len(block) else (lines[end] if end < len(lines) else block[i - 1])
            raise at.error(names[0], f"{what}: expected 6 rows of the viscous drag matrix, found {r}")
        values = fields(block[i], names)   # finite: checked by fields
        matrix[r] = [values[n] for n in names]
        i += 1
    for k, message in negative_diagonal(matrix):
        row = block[i - 6 + k]
        warnings.warn(InputWarning(row.path, row.number, f"V{k + 1}{k + 1}", f"{what}: {message}"))
    return matrix, i
