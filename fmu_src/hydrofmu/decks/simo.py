"""SIMO hydrodynamic coupling between bodies: reader for the `HYDRodynamic COUPling DATA` group.

Deck layout (FREAD rules, see decks/lines.py: keywords by their capitals, `/` for
a default, `&` continues a line, `'` starts a comment, blanks or commas, D exponents)::

    BODY DATA                        ' minimal body declaration (optional, see below)
    CHBDY                            ' body identifier
    HYDRodynamic COUPling DATA
    CHCPL                            ' coupling identifier, unique in the file
    TEXT                             ' two free text lines (not blank, not starting with ')
    TEXT
    CHBDY_A                          ' body A
    CHBDY_B                          ' body B (may equal A: the body's own radiation memory)
    COUPled ADDEd MASS               ' optional sub-group
    AM11 AM12 … AM16                 ' six rows [kg, kg·m, kg·m²]
    …
    COUPled RETArdation FUNCtion     ' optional sub-group (at least one of the two is given)
    TIMDEL                           ' sample spacing of the kernels [s], > 0
    RETArdation ELEment DATA         ' once for all blocks, or again before each block
    NRETij IDOF_A IDOF_B             ' one block per element, repeated until the next group
    RETij(1) … RETij(NRETij)         ' one line, continued with & [N·s/m, N·s, N·m·s]

`/` for AMij or RETij(k) gives 0 (the manual prints no default: the term is absent);
identifiers, TIMDEL, NRETij and the dofs have no default.

Whole files: a SIMO system description file holds many other data groups (``SYSTem
DESCription SIMO``, body data, environment, …).  The reader picks out the groups above and
skips every other line (strict inside our groups, lenient only between groups: decks/lines.py
``Grammar``); ``END`` ends the file.  A line that resembles one of our keywords (too short,
misspelt, values or words after it) is an error, as is a sub-group outside its coupling group
or out of the manual's order (``COUPled ADDEd MASS`` after the retardation function), a second
``SYSTem DESCription SIMO``, a data line after a finished group (a seventh added-mass row),
and an unknown group whose lines read as more retardation blocks of the coupling it ended.  The environment (``ENVIronment DATA
SPECification`` and its wave, wind and current groups) is skipped: the layout of its current
group is not in any public material we found, so a SIMO current comes from SIMA's current
file (``read_current_profile`` below) or the scene.  A line that starts like the coupling group
(``HYDRodynamic COUPling …``) but is not it is an error, not skipped.  ``BODY DATA
SPECification`` followed by the body identifier also declares a body.  The units line of
``SYSTem DESCription SIMO`` (LENUNI TIMUNI MASUNI GRAV RHOW …) is checked against the
scene's ``units`` (decks/units.py); values are converted to SI.

Meaning (manual): an acceleration of A in dof i times AM_ij is a force on B in dof j, and an
acceleration of B in dof j times AM_ij a force on A in dof i; the kernel of block
(IDOF_A = i, IDOF_B = j) convolves A's velocity in i into B's dof j, and B's velocity in j
into A's dof i (see physics/coupling.py for the signs).  Units: SI after conversion.

Bodies: the manual requires the body data of CHBDY_A and CHBDY_B to precede the coupling.
A body counts as defined when it is in ``bodies`` (the bodies the scene defines) or when a
`BODY DATA` group earlier in the same file declares it: the group line followed by one line
holding the body identifier CHBDY (SIMO's body data group; here only the identifier is read).
A pair of bodies is coupled at most once.
"""
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..admissible import symmetric
from ..errors import InputError
from . import units as unit_systems
from .lines import (DEFAULT, Cursor, Grammar, Reading, after_group, check_profile, convert, fields, fread_lines,
                    interrupted, is_end, with_reading)

GROUP = "HYDRodynamic COUPling DATA"
BODY = "BODY DATA"
BODY_SPEC = "BODY DATA SPECification"
SYSTEM = "SYSTem DESCription SIMO"
ADDED_MASS = "COUPled ADDEd MASS"
RETARDATION = "COUPled RETArdation FUNCtion"
ELEMENTS = "RETArdation ELEment DATA"
GRAMMAR = Grammar([SYSTEM, BODY_SPEC, BODY, GROUP], inner=[ADDED_MASS, RETARDATION, ELEMENTS], once=[SYSTEM],
                  stems=["HYDRodynamic COUPling"])
_NUMBER = re.compile(r"^[+-]?(\d+\.?\d*|\.\d+)([EeDd][+-]?\d+)?$")


@dataclass
class CouplingData:
    """One hydrodynamic coupling between bodies A and B (SI units).

    added_mass[i−1, j−1] = AM_ij: couples dof i of A with dof j of B [kg, kg·m, kg·m²].
    kernels[(i, j)] (1-based IDOF_A, IDOF_B): retardation samples at s = 0, TIMDEL, …
    timdel [s]: None when the deck gives no retardation function.
    path, line: where the group starts (for later messages).
    """
    name: str
    text: tuple
    body_a: str
    body_b: str
    added_mass: np.ndarray = field(default_factory=lambda: np.zeros((6, 6)))
    timdel: float = None
    kernels: dict = field(default_factory=dict)
    path: str = ""
    line: int = None


def read_couplings(path, bodies=None, units="SI"):
    """Read every `HYDRodynamic COUPling DATA` group of a deck: {CHCPL: CouplingData}
    (with ``.reading``: the groups used and skipped, decks/lines.py ``Reading``).

    ``bodies``: identifiers of the bodies defined before this file (e.g. by the scene).
    ``units``: the file's unit system (decks/units.py); values come back in SI.
    Raises InputError (file, line, field) on bad input.
    """
    cur = Cursor(fread_lines(path), path)
    reading = Reading(str(path), "SIMO")
    declared = {}                                   # body → line of its BODY DATA group
    known = set(bodies or ())
    out, pairs, system, once = {}, {}, None, {}
    while not cur.done():
        pos = cur.pos
        line = cur.next("data group")
        if is_end(line):
            break
        key = GRAMMAR.find(line)
        if key is None:                             # another data group of the file, or its data
            reading.skip(line, pos)
            continue
        name = key.spelling
        if key in GRAMMAR.inner:
            raise line.error(name, f"{name!r} outside a {GROUP!r} group or out of the manual's order "
                                   f"(CHBDY_B, then {ADDED_MASS!r}, then {RETARDATION!r})")
        if name in GRAMMAR.once:
            if name in once:
                raise line.error(name, f"{name!r} given twice (first at line {once[name]}): a file has one")
            once[name] = line.number
        if name == SYSTEM:
            system = _system(cur, line)
            reading.use(f"{SYSTEM} (units line {system.line.number})", line)
        elif name in (BODY, BODY_SPEC):
            body_line = cur.next("CHBDY")
            body = fields(body_line, ["CHBDY"], str)["CHBDY"] if name == BODY else body_line.words[0]
            if body in declared:
                raise body_line.error("CHBDY", f"body {body!r} declared twice (first at line {declared[body]})")
            declared[body] = body_line.number
            known.add(body)
            reading.use(f"{name} {body}", line)
        else:
            data = _coupling(cur, line, known, out, pairs)
            out[data.name] = data
            reading.use(f"{GROUP} {data.name}", line)
    unit_systems.check(system, units, path)
    mass, force = unit_systems.factors(units)
    for data in out.values():
        data.added_mass *= mass
        for ij in data.kernels:
            data.kernels[ij] *= force
    return with_reading(out, reading)


def _starts_group(line):
    """Between groups a FREAD line whose first word starts with a letter starts a group."""
    return line.words[0][:1].isalpha()


def _system(cur, head):
    """The units line of `SYSTem DESCription SIMO`: the first of the next four lines that
    reads as LENUNI TIMUNI MASUNI GRAV RHOW … (the three TXSYS lines come before it; a
    blank one is not a line here)."""
    for _ in range(4):
        if cur.peek() is None:
            break
        line = cur.next("LENUNI")
        words = line.words
        if len(words) <= 8 and all(w == DEFAULT or w.upper() in unit_systems.UNIT_NAMES for w in words[:3]) \
                and all(w == DEFAULT or _NUMBER.match(w) for w in words[3:]):
            return unit_systems.simo_units(line)
    where = cur.peek() or head
    raise where.error("LENUNI", f"expected the units line 'LENUNI TIMUNI MASUNI GRAV RHOW ...' within four "
                                f"lines after {SYSTEM!r} (line {head.number})")


def _coupling(cur, start, known, out, pairs):
    cl = cur.next("CHCPL")
    name = _one_word(cl, "CHCPL")
    if name in out:
        raise cl.error("CHCPL", f"duplicate coupling identifier {name!r} "
                                f"(first in the group at line {out[name].line})")
    text = (cur.next("TEXT").text, cur.next("TEXT").text)
    body = {}
    for key in ("CHBDY_A", "CHBDY_B"):
        bl = cur.next(key)
        body[key] = _one_word(bl, key, hint=" (two TEXT lines follow CHCPL)")
        if body[key] not in known:
            raise bl.error(key, f"body {body[key]!r} is not defined before the coupling "
                                f"(define it in the scene or in a {BODY!r} group earlier in the file)")
    pair = frozenset(body.values())
    if pair in pairs:
        raise bl.error("CHBDY_B", f"bodies {body['CHBDY_A']!r} and {body['CHBDY_B']!r} are already "
                                  f"coupled by {pairs[pair]!r}; give each pair once")
    pairs[pair] = name
    data = CouplingData(name, text, body["CHBDY_A"], body["CHBDY_B"], path=str(start.path), line=start.number)

    first = cur.peek()
    if first is None:
        raise cur.lines[-1].error(ADDED_MASS, f"expected {ADDED_MASS!r} and/or {RETARDATION!r} after CHBDY_B, "
                                              f"found the end of file")
    key = GRAMMAR.expect(first, ADDED_MASS, RETARDATION)
    if key.spelling == ADDED_MASS:
        head = cur.next(ADDED_MASS)
        for i in range(6):
            names = [f"AM{i + 1}{j + 1}" for j in range(6)]
            row = fields(cur.next(names[0]), names, slash=dict.fromkeys(names, 0.0))
            data.added_mass[i] = [row[n] for n in names]
        if data.body_a == data.body_b:
            _check_symmetric(head, data.added_mass)
        nxt = cur.peek()
        key = GRAMMAR.find(nxt) if nxt is not None and not is_end(nxt) else None
    if key is not None and key.spelling == RETARDATION:
        cur.next(RETARDATION)
        tl = cur.next("TIMDEL")
        data.timdel = fields(tl, ["TIMDEL"])["TIMDEL"]
        if not data.timdel > 0:
            raise tl.error("TIMDEL", f"must be > 0, found {data.timdel:g}")
        el = cur.next(ELEMENTS)
        GRAMMAR.expect(el, ELEMENTS)
        _blocks(cur, data, el)
        _stray(cur, data)
    after_group(cur, _starts_group, f"the coupling {name!r} (line {start.number})")
    return data


def _stray(cur, data):
    """An unknown group right after the retardation blocks whose lines read as further
    blocks: a stray line inside the coupling (decks/lines.py ``interrupted``)."""
    unknown = cur.peek()
    if unknown is None or is_end(unknown) or GRAMMAR.find(unknown) is not None:
        return
    probe = Cursor(cur.lines[cur.pos + 1:], cur.path)

    def rest():
        _blocks(probe, CouplingData("", (), "", ""), unknown, report=False)
        return True
    interrupted(unknown, f"the retardation blocks of coupling {data.name!r}", rest)


def _blocks(cur, data, head, report=True):
    """`NRETij IDOF_A IDOF_B` + values blocks, until a line that does not start with a number."""
    first = {}
    while True:
        nxt = cur.peek()
        if nxt is None or is_end(nxt):
            break
        if not _NUMBER.match(nxt.words[0]):
            if report and GRAMMAR.find(nxt) is GRAMMAR.inner[2]:   # the identifier again before a block
                cur.next(ELEMENTS)
                continue
            break
        hl = cur.next("NRETij")
        f = fields(hl, ["NRETij", "IDOF_A", "IDOF_B"], int)
        n = f["NRETij"]
        if n < 1:
            raise hl.error("NRETij", f"must be ≥ 1, found {n}")
        for key in ("IDOF_A", "IDOF_B"):
            if not 1 <= f[key] <= 6:
                raise hl.error(key, f"degree of freedom must be 1…6, found {f[key]}")
        dofs = (f["IDOF_A"], f["IDOF_B"])
        if dofs in first:
            raise hl.error("IDOF_A IDOF_B", f"duplicate block for (IDOF_A, IDOF_B) = {dofs} "
                                            f"(first at line {first[dofs]})")
        first[dofs] = hl.number
        vl = cur.next("RETij(1)")
        words = vl.words
        if len(words) < n:
            raise vl.at_word(len(words) - 1).error(
                f"RETij({len(words) + 1})", f"NRETij = {n} but {len(words)} values given "
                                             f"(continue a long line with '&')")
        if len(words) > n:
            raise vl.at_word(n).error(f"RETij({n + 1})", f"NRETij = {n} but {len(words)} values given")
        data.kernels[dofs] = _numbers(vl, ["0" if w == DEFAULT else w for w in words])   # '/': no term
    if not first:
        where = cur.peek() or head
        raise where.error("NRETij", f"expected at least one 'NRETij IDOF_A IDOF_B' block after {ELEMENTS!r}")


def _numbers(line, words, chunk=4096):
    """The words of a kernel line as floats, in chunks: on a bad word only its chunk is
    looked at again, so the error path costs what the good one does (linear)."""
    out = []
    for k0 in range(0, len(words), chunk):
        part = words[k0:k0 + chunk]
        try:
            values = np.array([float(w.replace("D", "E").replace("d", "e")) for w in part])
            if np.all(np.isfinite(values)):
                out.append(values)
                continue
        except ValueError:
            pass
        for k, w in enumerate(part, start=k0):
            try:
                convert(line, f"RETij({k + 1})", w, float)
            except InputError:   # the bad word: again, naming its physical line
                convert(line.at_word(k), f"RETij({k + 1})", w, float)
    return np.concatenate(out) if out else np.zeros(0)


def _one_word(line, name, hint=""):
    words = line.words
    if len(words) != 1:
        raise line.error(name, f"expected one identifier, found {line.text!r}{hint}")
    return words[0]


def _check_symmetric(head, am):
    """A body's own added mass must be symmetric (the coupling applies it once, as given)."""
    for name, message in symmetric(am, lambda i, j: f"AM{i + 1}{j + 1}"):
        raise head.error(name, f"self-coupling added mass {message}")


def format_coupling(name, body_a, body_b, added_mass=None, kernels=None, timdel=None,
                    text=("written by hydrofmu", "SI units")):
    """Lines of one `HYDRodynamic COUPling DATA` group (the layout ``read_couplings`` reads).

    added_mass: 6×6 [kg, kg·m, kg·m²] or None; kernels: {(IDOF_A, IDOF_B): samples at
    s = 0, TIMDEL, …} (1-based) with ``timdel`` [s]; at least one of the two is given.
    """
    lines = [GROUP, name, *text, body_a, body_b]
    if added_mass is not None:
        lines.append(ADDED_MASS)
        lines += ["  " + "  ".join(f"{x:.9e}" for x in row) for row in np.asarray(added_mass, float).reshape(6, 6)]
    if kernels:
        lines += [RETARDATION, repr(float(timdel)), ELEMENTS]
        for (i, j), h in kernels.items():
            h = np.asarray(h, float).ravel()
            lines.append(f"{h.size} {i} {j}")
            rows = [" ".join(f"{x:.9e}" for x in h[k:k + 6]) for k in range(0, h.size, 6)]
            lines += [r + " &" for r in rows[:-1]] + rows[-1:]
    return lines


def write_couplings(path, groups, header="SIMO hydrodynamic coupling data (SI units)"):
    """Write groups of ``format_coupling`` lines to a deck file; returns its path."""
    text = [f"' {header}"]
    for g in groups:
        text += ["'"] + list(g)
    Path(path).write_text("\n".join(text) + "\n")
    return Path(path)


def read_current_profile(path):
    """A SIMA current profile file (SIMO's and RIFLEX's "regular current from file", as SIMA's
    SIMO pages document it) as profile rows [[z, speed, direction], ...].  Layout (FREAD
    rules)::

        NCUR                        number of levels
        CURLEV CURDIR CURVEL        NCUR lines: global z [m] (z up, 0 at the mean free surface),
                                    direction [deg, going to, CCW from +x], speed [m/s]

    Raises InputError naming file, line and field (a missing or extra level, a missing value,
    a level above the surface, levels not ordered)."""
    cur = Cursor(fread_lines(path), path)
    head = cur.next("NCUR")
    n = fields(head, ["NCUR"], int)["NCUR"]
    if n < 1:
        raise head.error("NCUR", f"must be ≥ 1, found {n}")
    rows, where = [], []
    for k in range(n):
        names = [f"CURLEV({k + 1})", f"CURDIR({k + 1})", f"CURVEL({k + 1})"]
        line = cur.next(names[0])
        if is_end(line):
            raise line.error(names[0], f"NCUR = {n} but only {k} levels given")
        v = fields(line, names)
        rows.append([v[names[0]], v[names[2]], v[names[1]]])
        where.append((line, dict(zip(("z", "direction", "speed"), names))))
    extra = cur.peek()
    if extra is not None and not is_end(extra):
        raise extra.error(f"CURLEV({n + 1})", f"NCUR = {n} but more levels follow")
    reading = Reading(str(path), "SIMA current")
    reading.use(f"NCUR = {n} levels", head)
    return with_reading(check_profile(rows, where, reading), reading)
