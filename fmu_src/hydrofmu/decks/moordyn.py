"""MoorDyn v2 input files (MoorDyn-C 2.7): what hydrofmu reads of them, and the copy it runs.

The file, as MoorDyn-C reads it: free text until the first section; a section starts at a
header line holding ``---`` and one of its key phrases (any case: ``LINE TYPES`` or ``LINE
DICTIONARY``, ``BODIES``, ``POINTS`` (or ``POINT LIST``, ``CONNECTION PROPERTIES``, ``NODE
PROPERTIES``), ``RODS``, ``LINES`` (or ``LINE LIST``, ``LINE PROPERTIES``), ``OPTIONS``,
``OUTPUTS``) and runs to the next line holding ``---``.  A table section has two lines of
column names and units after its header; OPTIONS lines are ``value name [comment]``.  ``!``,
``#`` and ``%`` start a comment.  Values are separated by blanks; ``a|b|c`` packs several.

Columns read here (MoorDyn's v2 names):

- LINE TYPES: ``TypeName Diam Mass/m EA BA/-zeta EI Cd Ca CdAx CaAx`` (Diam the
  volume-equivalent diameter [m], Mass/m in air [kg/m], EA [N]);
- BODIES: ``ID Attachment X0 Y0 Z0 r0 p0 y0 Mass CG I Volume CdA Ca`` (angles in degrees);
- POINTS: ``ID Attachment X Y Z Mass Volume [FX FY FZ] CdA Ca`` (a ``BodyN`` point in body
  N's axes, the others global);
- LINES: ``ID LineType AttachA AttachB UnstrLen NumSegs LineOutputs`` (ends: point IDs,
  or ``R<n>A``/``R<n>B`` rod ends).

MoorDyn itself reads the whole file (its own messages name the line); this reader keeps
the numbers hydrofmu checks against the scene, each with its line, and writes the copy
hydrofmu runs (``runnable``): the same lines, some OPTIONS set by hydrofmu (external wave
kinematics, the scene's water and gravity, no output files), the ``UnstrLen`` of lines the
scene changes.  ``Runnable.origin`` maps each line of the copy to the user's line.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import InputError
from ..textfile import read_text

SECTIONS = {   # our name -> MoorDyn's key phrases, in the order MoorDyn looks for them
    "line_types": ("LINE DICTIONARY", "LINE TYPES"),
    "rod_types": ("ROD DICTIONARY", "ROD TYPES"),
    "bodies": ("BODIES", "BODY LIST", "BODY PROPERTIES"),
    "points": ("POINTS", "POINT LIST", "POINT PROPERTIES", "CONNECTION PROPERTIES", "NODE PROPERTIES"),
    "rods": ("RODS", "ROD LIST", "ROD PROPERTIES"),
    "lines": ("LINES", "LINE LIST", "LINE PROPERTIES"),
    "options": ("OPTIONS",),
    "outputs": ("OUTPUT",),
}
COMMENTS = re.compile(r"[!#%]")
# options that name the same setting (MoorDyn compares option names in lower case)
ALIASES = {"rhow": "rho", "gravity": "g"}


@dataclass(frozen=True)
class LineType:
    diameter: float      # volume-equivalent [m]
    mass: float          # in air [kg/m]
    ea: float | None     # axial stiffness [N] (None: a nonlinear curve)
    line: int

    def weight(self, rho: float, g: float) -> float:
        """Submerged weight per unit length [N/m]: (m − ρ·π·d²/4)·g."""
        return (self.mass - rho * math.pi * self.diameter ** 2 / 4) * g


@dataclass(frozen=True)
class Body:
    attachment: str      # the file's word (Coupled, Free, Fixed, …)
    pose: tuple          # X0 Y0 Z0 [m], r0 p0 y0 [deg]
    own: dict            # Mass, Volume, CdA, Ca: the body's own properties (each a tuple of numbers)
    line: int


@dataclass(frozen=True)
class Point:
    attachment: str      # Fixed, Coupled, Free, BodyN, …
    position: tuple      # [m]: global, or in body N's axes for BodyN
    body: int | None     # N of a BodyN point
    line: int


@dataclass(frozen=True)
class MDLine:
    type: str
    ends: tuple          # (AttachA, AttachB) as written
    length: float        # UnstrLen [m]
    segments: int
    line: int


@dataclass
class Deck:
    """What a MoorDyn file holds that hydrofmu checks (module docstring); every entry keeps
    its 1-based line.  ``options``: lower-case name (aliases folded) -> (value text, line)."""
    path: Path
    lines_text: list
    line_types: dict = field(default_factory=dict)
    bodies: dict = field(default_factory=dict)
    points: dict = field(default_factory=dict)
    rods: dict = field(default_factory=dict)      # ID -> line
    lines: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    options_at: tuple | None = None               # (header index, end index) of OPTIONS, 0-based
    sections: dict = field(default_factory=dict)  # our name -> header line (1-based)

    def option(self, name, default=None):
        """The number of option ``name`` (lower case), or ``default``; an option that is not a
        number is an InputError naming its line."""
        if name not in self.options:
            return default
        text, line = self.options[name]
        return number(self.path, line, name, text)

    def error(self, line, name, message):
        return InputError(self.path, line, name, message)


def _header(text):
    """Our section name of a header line, or None."""
    if "---" not in text:
        return None
    upper = text.upper()
    for name, phrases in SECTIONS.items():
        if any(p in upper for p in phrases):
            return name
    return None


def number(path, line, name, text):
    """``text`` as a float, or an InputError naming the file, line and column ``name``
    (MoorDyn reads a malformed number as 0 without a word)."""
    try:
        value = float(text)
    except ValueError:
        raise InputError(path, line, name, f"expected a number, found {text!r}") from None
    if not math.isfinite(value):
        raise InputError(path, line, name, f"expected a finite number, found {text!r}")
    return value


def numbers(path, line, name, text):
    """``a|b|c`` as a tuple of floats."""
    return tuple(number(path, line, name, t) for t in text.split("|"))


def read_moordyn(path) -> Deck:
    """The MoorDyn v2 file at ``path`` (module docstring).  A table row too short for the
    columns read, or a malformed number among them, is an InputError naming the file, the
    line and the column."""
    path = Path(path)
    text = read_text(path, "MoorDyn file").splitlines()
    deck = Deck(path, text)
    i = 0
    while i < len(text):
        name = _header(text[i])
        if name is None or name in deck.sections:   # MoorDyn reads the first section of a name
            i += 1
            continue
        deck.sections[name] = i + 1
        start = i + 1 if name in ("options", "outputs") else i + 3
        end = start
        while end < len(text) and "---" not in text[end]:
            end += 1
        rows = [(k + 1, COMMENTS.split(text[k], 1)[0].split()) for k in range(start, min(end, len(text)))]
        rows = [(k, w) for k, w in rows if w]
        if name == "options":
            deck.options_at = (i, end)
            for k, words in rows:
                if len(words) >= 2:
                    key = words[1].lower()
                    deck.options[ALIASES.get(key, key)] = (words[0], k)
        else:
            reader = _ROWS.get(name)
            for k, words in rows:
                if reader is not None:
                    reader(deck, k, words)
        i = end
    return deck


def _need(deck, k, words, columns):
    if len(words) < len(columns):
        raise deck.error(k, columns[len(words)], f"missing value: the row has {len(words)} values, "
                                                 f"{len(columns)} needed ({' '.join(columns)})")


def _line_type(deck, k, words):
    cols = ("TypeName", "Diam", "Mass/m", "EA")
    _need(deck, k, words, cols)
    ea = words[3].split("|")[0]
    try:
        ea_value = float(ea)
    except ValueError:   # a nonlinear stiffness curve (a file name)
        ea_value = None
    deck.line_types[words[0]] = LineType(number(deck.path, k, "Diam", words[1]),
                                         number(deck.path, k, "Mass/m", words[2]), ea_value, k)


def _id(deck, k, words):
    value = number(deck.path, k, "ID", words[0])
    if value != int(value):
        raise deck.error(k, "ID", f"expected a whole number, found {words[0]!r}")
    return int(value)


def _body(deck, k, words):
    cols = ("ID", "Attachment", "X0", "Y0", "Z0", "r0", "p0", "y0", "Mass", "CG", "I", "Volume", "CdA", "Ca")
    _need(deck, k, words, cols)
    pose = tuple(number(deck.path, k, c, w) for c, w in zip(cols[2:8], words[2:8]))
    own = {c: numbers(deck.path, k, c, words[cols.index(c)]) for c in ("Mass", "Volume", "CdA", "Ca")}
    deck.bodies[_id(deck, k, words)] = Body(words[1], pose, own, k)


def _point(deck, k, words):
    cols = ("ID", "Attachment", "X", "Y", "Z", "Mass", "Volume", "CdA", "Ca")
    _need(deck, k, words, cols)
    xyz = tuple(number(deck.path, k, c, w) for c, w in zip("XYZ", words[2:5]))
    found = re.fullmatch(r"body(\d+)", words[1], re.IGNORECASE)
    deck.points[_id(deck, k, words)] = Point(words[1], xyz, int(found.group(1)) if found else None, k)


def _rod(deck, k, words):
    deck.rods[_id(deck, k, words)] = k


def _line(deck, k, words):
    cols = ("ID", "LineType", "AttachA", "AttachB", "UnstrLen", "NumSegs", "LineOutputs")
    _need(deck, k, words, cols)
    length = number(deck.path, k, "UnstrLen", words[4])
    segments = number(deck.path, k, "NumSegs", words[5])
    deck.lines[_id(deck, k, words)] = MDLine(words[1], (words[2], words[3]), length, int(segments), k)


_ROWS = {"line_types": _line_type, "bodies": _body, "points": _point, "rods": _rod, "lines": _line}


@dataclass(frozen=True)
class Runnable:
    """The copy hydrofmu runs: ``text`` (its lines) and ``origin``: for each of its lines
    (index = line number − 1) the user's line number, or None for a line hydrofmu wrote."""
    text: str
    origin: tuple

    def user_line(self, number: int) -> int | None:
        return self.origin[number - 1] if 1 <= number <= len(self.origin) else None


def runnable(deck: Deck, options: dict, lengths: dict | None = None) -> Runnable:
    """The copy of ``deck`` with ``options`` ({lower-case name: value}) set, each where the
    file gives it or added at the end of its OPTIONS section (one is made before OUTPUTS, or
    at the end, when the file has none), and the UnstrLen of the lines of ``lengths``
    ({line ID: metres}) replaced."""
    text = list(deck.lines_text)
    origin = list(range(1, len(text) + 1))
    for ident, metres in (lengths or {}).items():
        entry = deck.lines[ident]
        words = text[entry.line - 1].split()
        words[4] = repr(float(metres))
        text[entry.line - 1] = "  ".join(words)
    added = []
    for name, value in options.items():
        if name in deck.options:
            k = deck.options[name][1]
            text[k - 1] = f"{value}  {name}  ! set by hydrofmu"
        else:
            added.append(f"{value}  {name}  ! set by hydrofmu")
    if deck.options_at is not None:
        at = deck.options_at[1]
    else:
        at = deck.sections["outputs"] - 1 if "outputs" in deck.sections else len(text)
        added.insert(0, "---------------------- OPTIONS (added by hydrofmu) ----------------------")
        if "outputs" not in deck.sections:
            added.append("------------------------------------------------------------------------")
    text[at:at] = added
    origin[at:at] = [None] * len(added)
    return Runnable("\n".join(text) + "\n", tuple(origin))
