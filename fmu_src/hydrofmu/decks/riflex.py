"""RIFLEX input: the BODY and CONB component data groups, and the current states of the
environments (``read_current_states``, layout at its definition below).

Layout, one data group per component (keywords by their capitals, any case, decks/lines.py;
lines starting with ' are comments; commas separate like blanks)::

    NEW COMPonent BODY              NEW COMPonent CONB
    CMPTYP-ID                       CMPTYP-ID
    AM AE                           AM AE
    ICOO CDX CDY CDZ AMX AMY AMZ    ICOO CDX CDY CDZ AMX AMY AMZ
                                    IRX IRY IRZ        (optional line, each defaults to 0)

Units: AM [kg], AE [m³], CD [N/(m/s)²], AMX.. [kg] after conversion from the file's
system (decks/units.py: the scene's ``units``, checked against the file's ``UNIT NAMe
SPECification`` line UT UL UM UF GRAV GCONS when it has one); ICOO GLOBAL or LOCAL; IRX..
1 fixed, 0 free.

FREAD rules (decks/lines.py): ``/`` gives IRX, IRY, IRZ their default 0, and AM, AE, CDX …
AMZ the value 0 (no default printed: the term is absent); ICOO and CMPTYP-ID have none.
``&`` continues a line, ``'`` starts a comment, ``END`` ends the input.

Whole INPMOD files: every other data group, and lines before the first group, are
skipped (strict inside our groups, lenient only between groups: decks/lines.py ``Grammar``).
A line starts a data group when it is a NEW line or all its words begin with a letter
(RIFLEX groups such as ``END`` or ``UNIT NAMES SPECIFICATION``): such a line ends the CONB
group without its IRX line; any other line left after one of our groups is an error (a
level beyond NCULEV, a fourth CONB line).  A line that resembles one of our keywords
(``UNIT NA SPEC``, ``NEW COMP BOD``, words after it) is an error, as is a second ``UNIT NAMe
SPECification`` and a group right after a CONB whose first line reads as the CONB's IRX IRY
IRZ line (a stray or misplaced line inside the CONB group).  The codes are numbers (the
manual's 0 and 1): a line of one to three freedom words after a CONB (``FIX FIX FREE``,
``fixed``; ``CODE_WORDS``) is the IRX IRY IRZ line written in words, an error at its line and
field, never a skipped group (it left the hinge a ball joint).
"""
from dataclasses import dataclass, replace

from ..errors import InputError
from ..physics.lumped import LumpedBody, coordinate_code
from . import units as unit_systems
from .lines import (Cursor, Grammar, Reading, after_group, check_profile, fields, fread_lines, interrupted, is_end,
                    with_reading)

HYDRO = ("ICOO", "CDX", "CDY", "CDZ", "AMX", "AMY", "AMZ")
FREEDOM = ("IRX", "IRY", "IRZ")
GROUPS = {"BODY": "NEW COMPonent BODY", "CONB": "NEW COMPonent CONB"}
UNITS = "UNIT NAMe SPECification"


@dataclass(frozen=True)
class _Lumped:
    name: str                 # CMPTYP-ID
    am: float                 # mass [kg]
    ae: float                 # displaced volume [m³]
    icoo: str                 # 'GLOBAL' or 'LOCAL'
    cd: tuple                 # (CDX, CDY, CDZ) [N/(m/s)²]
    added_mass: tuple         # (AMX, AMY, AMZ) [kg]
    path: str                 # deck file
    line: int                 # line of the data group identifier

    def lumped(self, offset, name=None):
        """The component as a LumpedBody at ``offset`` (body axes, m) of a body."""
        return LumpedBody(name or self.name, offset, self.am, self.ae, self.icoo, self.cd, self.added_mass)


@dataclass(frozen=True)
class BodyData(_Lumped):
    """NEW COMPonent BODY: lumped mass, volume, drag and added mass at a point."""


@dataclass(frozen=True)
class ConbData(_Lumped):
    """NEW COMPonent CONB: ball joint; ``codes`` = (IRX, IRY, IRZ), 1 fixed, 0 free."""
    codes: tuple = (0, 0, 0)

    @property
    def free(self):
        """(3,) bools, True where the rotation about that axis is free (code 0)."""
        return tuple(c == 0 for c in self.codes)


def starts_group(line):
    """True if ``line`` opens a data group: a NEW line or one of words that all begin with a letter."""
    words = line.words
    return words[0].upper() == "NEW" or all(w[0].isalpha() for w in words)


def _groups(path, reader, read):
    """The FREAD group loop shared by the component and current readers: every line between
    groups is looked up in GRAMMAR (a near miss is an error), our groups are handed to
    ``read(cur, line, key)``, the rest skipped; the unit declaration is read once."""
    cur = Cursor(fread_lines(path), path)
    reading = Reading(str(path), reader)
    system, first = None, None
    while not cur.done():
        pos = cur.pos
        line = cur.next("data group")
        if is_end(line):
            break
        key = GRAMMAR.find(line)
        if key is not None and key.spelling == UNITS:
            if first is not None:
                raise line.error(UNITS, f"{UNITS!r} given twice (first at line {first}): a file declares its "
                                        f"units once")
            system, first = _units(cur), line.number
            reading.use(UNITS, line)
        elif key is None or not read(cur, line, key.spelling, reading):
            reading.skip(line, pos)
    return system, reading


def read_components(path, units="SI"):
    """All BODY and CONB components of a RIFLEX file: dict CMPTYP-ID → BodyData | ConbData
    (with ``.reading``, decks/lines.py).
    ``units``: the file's unit system (decks/units.py); values come back in SI."""
    out = {}

    def read(cur, line, name, reading):
        kind = next((k for k, key in GROUPS.items() if key == name), None)
        if kind is None:
            return False
        comp = _read_group(cur, line, kind, out)
        out[comp.name] = comp
        reading.use(f"{GROUPS[kind]} {comp.name}", line)
        after_group(cur, starts_group, f"{kind} {comp.name!r}", "a new data group (NEW ...) or the end of the file")
        return True
    system, reading = _groups(path, "RIFLEX", read)
    unit_systems.check(system, units, path)
    mass, force = unit_systems.factors(units)
    return with_reading({k: replace(c, am=c.am * mass, cd=tuple(x * force for x in c.cd),
                                    added_mass=tuple(x * mass for x in c.added_mass)) for k, c in out.items()},
                        reading)


def _units(cur):
    """The declaration of the ``UNIT NAMe SPECification`` line that follows."""
    return unit_systems.riflex_units(_next_data(cur, ("UT", "UL", "UM", "UF", "GRAV", "GCONS"), UNITS))


def _next_data(cur, names, owner):
    """The next line, which must be the data line ``names`` of ``owner``."""
    if cur.done():
        last = cur.lines[-1].number if cur.lines else None
        raise InputError(cur.path, last, names[0], f"unexpected end of file: missing line '{' '.join(names)}' of {owner}")
    line = cur.next(names[0])
    if starts_group(line):
        raise line.error(names[0], f"expected the line '{' '.join(names)}' of {owner}, found {line.text!r}")
    return line


def _non_negative(line, values, names):
    for name in names:
        if values[name] < 0.0:
            raise line.error(name, f"must be >= 0, found {values[name]:g}")


def _read_group(cur, head, kind, seen):
    owner = f"{kind} at line {head.number}"
    if cur.done():
        raise InputError(cur.path, head.number, "CMPTYP-ID", f"unexpected end of file: missing CMPTYP-ID of {owner}")
    line = cur.next("CMPTYP-ID")
    if line.words[0].upper() == "NEW" or len(line.words) != 1:
        raise line.error("CMPTYP-ID", f"expected one component identifier, found {line.text!r}")
    name = line.words[0]
    if len(name) > 8:
        raise line.error("CMPTYP-ID", f"{name!r} is longer than 8 characters")
    if name in seen:
        raise line.error("CMPTYP-ID", f"duplicate component {name!r} (first at line {seen[name].line})")
    owner = f"{kind} {name!r}"

    line = _next_data(cur, ("AM", "AE"), owner)
    mass = fields(line, ["AM", "AE"], slash={"AM": 0.0, "AE": 0.0})
    _non_negative(line, mass, ["AM", "AE"])

    line = _next_data(cur, HYDRO, owner)
    hydro = fields(line, list(HYDRO), kind=[str] + [float] * 6, slash=dict.fromkeys(HYDRO[1:], 0.0))
    icoo = coordinate_code(hydro["ICOO"])
    if icoo is None:
        raise line.error("ICOO", f"expected GLOBAL or LOCAL, found {hydro['ICOO']!r}")
    _non_negative(line, hydro, HYDRO[1:])

    common = dict(name=name, am=mass["AM"], ae=mass["AE"], icoo=icoo,
                  cd=tuple(hydro[k] for k in HYDRO[1:4]), added_mass=tuple(hydro[k] for k in HYDRO[4:]),
                  path=str(cur.path), line=head.number)
    if kind == "BODY":
        return BodyData(**common)

    codes = (0, 0, 0)
    nxt = cur.peek()
    if nxt is not None and _codes_in_words(nxt):
        word = next(w for w in nxt.words if w.upper() in CODE_WORDS)
        field_ = FREEDOM[nxt.words.index(word)]
        raise nxt.at_word(nxt.words.index(word)).error(
            field_, f"freedom codes are numbers, 0 (free) or 1 (fixed), found {word!r} in {nxt.text!r}: write "
                    f"e.g. '1 1 0' (read as another data group, the line would leave the joint free)")
    if nxt is not None and not starts_group(nxt):
        codes = _codes(cur.next("IRX"))
    elif nxt is not None and not is_end(nxt) and cur.pos + 1 < len(cur.lines):
        after = cur.lines[cur.pos + 1]      # the group after the CONB: is its first line our IRX line?
        interrupted(nxt, f"CONB {name!r} (its IRX IRY IRZ line)", lambda: not starts_group(after) and _codes(after))
    return ConbData(**common, codes=codes)


# words a CONB's IRX IRY IRZ line written in words would hold: no RIFLEX data group is named so
CODE_WORDS = {"FIX", "FIXED", "FREE", "RIGID", "LOCK", "LOCKED", "PIN", "PINNED", "HINGE", "HINGED", "ON", "OFF",
              "YES", "NO", "TRUE", "FALSE", "T", "F", "Y", "N", "ZERO", "ONE"}


def _codes_in_words(line):
    """True for a line of one to three words, all freedom words (``FIX FIX FREE``): the CONB's
    IRX IRY IRZ line written in words, not a data group."""
    words = [w.upper() for w in line.words]
    return 1 <= len(words) <= 3 and all(w in CODE_WORDS for w in words)


def _codes(line):
    """CONB's ``IRX IRY IRZ`` line (each 0 free or 1 fixed, default 0)."""
    values = fields(line, list(FREEDOM), kind=int, defaults=dict.fromkeys(FREEDOM, 0))
    for key in FREEDOM:
        if values[key] not in (0, 1):
            raise line.error(key, f"expected 0 (free) or 1 (fixed), found {values[key]}")
    return tuple(values[k] for k in FREEDOM)


# --- current profiles: environment data (INPMOD data group D) ------------------------------
# Layout from the RIFLEX INPMOD input description, "Data Group D: Environmental Data"
# (SINTEF Ocean's RIFLEX user manual): an environment is
#   ENVIronment IDENtification / one text line (may be blank) / IDENV
#   WATErdepth AND WAVEtype / WDEPTH NOIRW NORW NCUSTA NWISTA
#   … waves, constants …
#   NEW CURRENT STATE / ICUSTA NCULEV L_EXT / NCULEV lines CURLEV CURDIR CURVEL
# (the last group repeated for each current state 1, 2, …, NCUSTA).  CURLEV: global z [L],
# 0 at the mean water level, negative below, levels given with decreasing z; CURDIR: the
# direction the current goes, degrees from global X counter-clockwise seen from above;
# CURVEL [L/T]; linear between levels, constant outside.  1 ≤ NCULEV ≤ 30; L_EXT (default
# 0) = 1 puts the levels in an external CURMOD file, which hydrofmu does not read.
ENVIRONMENT = "ENVIronment IDENtification"
WATER = "WATErdepth AND WAVEtype"
CURRENT_STATE = "NEW CURRENT STATE"
CURRENT_LINE = "NEW CURRENT LINE"
GRAMMAR = Grammar([UNITS, *GROUPS.values(), ENVIRONMENT, WATER, CURRENT_STATE, CURRENT_LINE], once=[UNITS])


@dataclass(frozen=True)
class CurrentState:
    """One ``NEW CURRENT STATE`` of an environment: profile ``rows`` [[z m, speed m/s,
    direction deg going to], ...] from the top down; ``line``: its ICUSTA line."""
    environment: str
    number: int
    rows: list
    path: str
    line: int


def read_current_states(path, units=None):
    """Every current state of a RIFLEX INPMOD file: {IDENV: {ICUSTA: CurrentState}}.

    Other data groups are skipped (FREAD rules, ``END`` ends the input).  ``units``: the
    scene's name for the file's unit system, checked against its ``UNIT NAMe
    SPECification`` when given; CURLEV [L] and CURVEL [L/T] are m and m/s in every system
    hydrofmu reads (decks/units.py checks UL = m and UT = s), so no value is scaled.
    Raises InputError naming file, line and field (a level above the surface, levels not in
    decreasing z, a missing value, a state out of order, …)."""
    out, env = {}, {}           # env: the environment being read: name, NCUSTA, WATER's line

    def read(cur, line, name, reading):
        if name == ENVIRONMENT:
            env.clear()
            env["name"] = _environment(cur, line, out)
            out[env["name"]] = {}
            reading.use(f"{ENVIRONMENT} {env['name']}", line)
        elif name == WATER:
            if not env:
                raise line.error(WATER, f"{WATER!r} before any {ENVIRONMENT!r}")
            if "water" in env:
                raise line.error(WATER, f"{WATER!r} given twice in environment {env['name']!r} (first at line "
                                        f"{env['water']})")
            names = ("WDEPTH", "NOIRW", "NORW", "NCUSTA", "NWISTA")
            values = fields(_next_data(cur, names, WATER), list(names), kind=[float, int, int, int, int],
                            defaults={"NWISTA": 0})
            env["ncusta"], env["water"] = values["NCUSTA"], line.number
            reading.use(f"{WATER} of {env['name']}", line)
        elif name == CURRENT_STATE:
            if not env:
                raise line.error("IDENV", f"{CURRENT_STATE!r} before any {ENVIRONMENT!r}: a current belongs "
                                          f"to an environment")
            if "water" not in env:
                raise line.error(CURRENT_STATE, f"{CURRENT_STATE!r} before {WATER!r} of environment "
                                                f"{env['name']!r}: the manual's order is WATErdepth first")
            state = _current_state(cur, env["name"], out[env["name"]], env["ncusta"], reading)
            out[env["name"]][state.number] = state
            reading.use(f"{CURRENT_STATE} {env['name']}/{state.number}", line)
            after_group(cur, starts_group, f"current state {state.number} of {env['name']!r} "
                                           f"(NCULEV = {len(state.rows)} levels)")
        else:
            return False
        return True
    system, reading = _groups(path, "RIFLEX current", read)
    if units is not None:
        unit_systems.check(system, units, path, key="current_units")
    return with_reading(out, reading)


def _environment(cur, head, seen):
    """IDENV of an ``ENVIronment IDENtification`` group: the text line (which may be blank,
    and FREAD drops blank lines) then IDENV; the manual puts ``WATErdepth AND WAVEtype``
    right after, which tells a blank text line from a given one."""
    ident = cur.next("IDENV")              # the text line, or IDENV when the text line was blank
    nxt = cur.peek()
    if nxt is not None and not is_end(nxt) and GRAMMAR.find(nxt) is not GRAMMAR.groups[4]:
        ident = cur.next("IDENV")
    if len(ident.words) != 1:
        raise ident.error("IDENV", f"expected one environment identifier after the text line of "
                                   f"{ENVIRONMENT!r} (line {head.number}), found {ident.text!r} (the manual puts "
                                   f"{WATER!r} right after IDENV)")
    name = ident.words[0]
    if name in seen:
        raise ident.error("IDENV", f"environment {name!r} given twice (each must have a unique identifier)")
    return name


def _current_state(cur, env, states, ncusta, reading=None):
    names = ("ICUSTA", "NCULEV", "L_EXT")
    dim = _next_data(cur, names, CURRENT_STATE)
    v = fields(dim, list(names), kind=int, defaults={"L_EXT": 0})
    number, n = v["ICUSTA"], v["NCULEV"]
    if number != len(states) + 1:
        raise dim.error("ICUSTA", f"current states of environment {env!r} must be given as 1, 2, ...: "
                                  f"expected {len(states) + 1}, found {number}")
    if ncusta is not None and number > ncusta:
        raise dim.error("ICUSTA", f"state {number} but NCUSTA = {ncusta} in {WATER!r} of environment {env!r}")
    if not 1 <= n <= 30:
        raise dim.error("NCULEV", f"number of current levels must be 1 ... 30, found {n}")
    if v["L_EXT"] not in (0, 1):
        raise dim.error("L_EXT", f"expected 0 (levels in this file) or 1 (external file), found {v['L_EXT']}")
    if v["L_EXT"] == 1:
        raise dim.error("L_EXT", "L_EXT = 1 puts the current levels in an external CURMOD file, which hydrofmu "
                                 "does not read: give the NCULEV lines 'CURLEV CURDIR CURVEL' here (L_EXT = 0)")
    rows, where = [], []
    for k in range(n):
        level = [f"CURLEV({k + 1})", f"CURDIR({k + 1})", f"CURVEL({k + 1})"]
        nxt = cur.peek()
        if nxt is None or starts_group(nxt):
            at = nxt or cur.lines[-1]
            raise at.error(level[0], f"NCULEV = {n} but {k} level line(s) 'CURLEV CURDIR CURVEL' given "
                                     f"(found {at.text if nxt else 'the end of the file'!r})")
        line = cur.next(level[0])
        f = fields(line, level)
        if k and f[level[0]] >= rows[-1][0]:
            raise line.error(level[0], f"levels must be given with decreasing z (the manual): z = "
                                       f"{f[level[0]]:g} follows z = {rows[-1][0]:g}")
        rows.append([f[level[0]], f[level[2]], f[level[1]]])
        where.append((line, dict(zip(("z", "direction", "speed"), level))))
    check_profile(rows, where, reading)
    return CurrentState(env, number, rows, str(cur.path), dim.number)
