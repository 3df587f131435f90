"""Line-level tools shared by the deck readers: numbered lines, keyword matching,
typed fields with errors that name the file, the line and the field.

FREAD, the free-format reader of SIMO and RIFLEX input (``fread_lines``, ``fields``,
``is_keyword``), as the readers apply it:

- a data group starts with an identifier of up to three words; only the first four letters
  of each word count, case does not (``HYDRodynamic COUPling DATA`` = ``hydr coup data``);
- values are separated by blanks (tabs) and/or commas; a number may carry a Fortran ``D``
  exponent (``2.5D+03``);
- ``/`` in place of a value gives that field its default (``fields(..., defaults=)``);
- ``&`` at the end of a line continues it on the next line;
- ``'`` starts a comment: a line whose first non-blank character is ``'`` is skipped, and
  text after a ``'`` on a data line is ignored;
- ``END`` ends the input: whatever follows it is not read.
"""
import math
from dataclasses import dataclass
from pathlib import Path

from ..admissible import finite_problem
from ..errors import InputError
from ..textfile import read_text


@dataclass(frozen=True)
class Line:
    path: str
    number: int  # 1-based line number in the file (first line of a continued line)
    text: str
    pieces: tuple = ()   # continued line: (physical line number, start in text) of each piece

    @property
    def words(self):
        return self.text.replace(",", " ").split()

    def error(self, field, message):
        return InputError(self.path, self.number, field, message)

    def at_word(self, index):
        """This line numbered as the physical line that holds word ``index`` (0-based) of
        a continued line; one pass over the words before it (only on the error path)."""
        count = 0
        for k, (number, start) in enumerate(self.pieces):
            end = self.pieces[k + 1][1] if k + 1 < len(self.pieces) else len(self.text)
            count += len(self.text[start:end].replace(",", " ").split())
            if count > index:
                return Line(self.path, number, self.text)
        return self


DEFAULT = "/"      # FREAD: a value left to its default
COMMENT = "'"      # FREAD: comment mark
END = "END"        # FREAD: end of input


def read_lines(path, comment="'", continuation=None, inline=False):
    """Non-blank, non-comment lines of a text file as ``Line`` objects.

    ``comment``: prefix (after leading blanks) of comment lines, or a tuple of them.
    ``continuation``: a trailing mark (e.g. ``&``) that joins a line with the next one.
    ``inline``: a comment mark after data also ends the line's data.
    """
    path = Path(path)
    raw = read_text(path, "deck").splitlines()
    comments = (comment,) if isinstance(comment, str) else tuple(comment or ())
    out, pending = [], []   # pending: (number, text) pieces of a continued line, joined once: linear
    for number, text in enumerate(raw, start=1):
        stripped = data_part(text, comments) if inline else text.strip()
        if not stripped or (comments and stripped.startswith(comments)):
            continue
        if continuation and stripped.endswith(continuation):
            pending.append((number, stripped[: -len(continuation)].rstrip()))
            continue
        pending.append((number, stripped))
        out.append(_joined(str(path), pending))
        pending = []
    if pending:
        out.append(_joined(str(path), pending))
    return out


def _joined(path, pieces):
    if len(pieces) == 1:
        return Line(path, *pieces[0])
    starts, at = [], 0
    for number, text in pieces:
        starts.append((number, at))
        at += len(text) + 1
    return Line(path, pieces[0][0], " ".join(text for _, text in pieces), tuple(starts))


def data_part(text, comments=(COMMENT,)):
    """``text`` without a trailing comment (from the first comment mark on), stripped;
    a comment line keeps its mark so that it is still seen as one."""
    stripped = text.strip()
    if stripped.startswith(comments):
        return stripped
    cut = min((i for i in (stripped.find(c) for c in comments) if i >= 0), default=-1)
    return stripped if cut < 0 else stripped[:cut].rstrip()


def fread_lines(path):
    """The data lines of a SIMO/RIFLEX input file by the FREAD rules (module docstring)."""
    return read_lines(path, comment=COMMENT, continuation="&", inline=True)


def is_end(line):
    """True for the FREAD ``END`` line that ends the input."""
    return keyword_key(line.text) == (END,)


def keyword_key(text):
    """Normalised keyword: the first four letters of each word, upper case.
    'NEW COMPonent BODY' and 'new comp body' both give ('NEW', 'COMP', 'BODY')."""
    return tuple(word[:4].upper() for word in text.split())


def is_keyword(line, keyword):
    """True if ``line`` is the keyword line ``keyword`` (first four letters of each word
    count, case does not; extra words on the line are not allowed)."""
    return keyword_key(line.text) == keyword_key(keyword)


def fields(line, names, kind=float, defaults=None, slash=None):
    """Parse the words of ``line`` as the named fields.

    ``kind``: a type for all fields or a list of types, one per name.
    ``defaults``: values for fields that may be left out at the end of the line or given
    as ``/`` (FREAD's default); ``slash``: values only ``/`` may give (a field the manual
    prints no default for, left out on purpose); ``/`` for any other field is an error.
    Returns a dict name → value; one InputError names the first bad or missing field.
    """
    kinds = kind if isinstance(kind, (list, tuple)) else [kind] * len(names)
    defaults = defaults or {}
    slash = {**defaults, **(slash or {})}
    words = line.words
    empty = _empty_field(line.text)
    if empty is not None and empty < len(names):
        raise line.error(names[empty], f"empty field between commas; expected {' '.join(names)}")
    if len(words) > len(names):
        raise line.error(names[-1], f"expected {len(names)} values ({' '.join(names)}), found {len(words)}")
    values = {}
    for i, (name, typ) in enumerate(zip(names, kinds)):
        if i >= len(words):
            if name in defaults:
                values[name] = defaults[name]
                continue
            raise line.error(name, f"missing value; expected {' '.join(names)}")
        if words[i] == DEFAULT:
            if name not in slash:
                raise line.error(name, f"'{DEFAULT}' asks for the default value, but {name} has none: give a value")
            values[name] = slash[name]
            continue
        values[name] = convert(line, name, words[i], typ)
    return values


def _empty_field(text):
    """Index of the first empty comma-separated field ('1, ,2' or ',1'), or None."""
    if "," not in text:
        return None
    parts = text.split(",")
    for k, part in enumerate(parts[:-1]):   # a trailing comma ends the list, it is no field
        if not part.strip():
            return sum(len(p.split()) for p in parts[:k])
    return None


def convert(line, name, word, typ):
    """One word as ``typ`` (float, int or str), or an error naming the field.  Numbers
    must be finite: NaN, inf and overflowing values (1e400) are errors here, for every deck."""
    if typ is str:
        return word
    try:
        value = float(word.replace("D", "E").replace("d", "e"))
        if typ is int and math.isfinite(value):
            if value != int(value):
                raise ValueError
            return int(value)
    except ValueError:
        raise line.error(name, f"expected {'an integer' if typ is int else 'a number'}, found {word!r}") from None
    problem = finite_problem(value)
    if problem:
        raise line.error(name, f"{problem} ({word!r})")
    return value


class Cursor:
    """Walks through a list of lines; ``next(field)`` names what was expected when the
    deck ends too early."""

    def __init__(self, lines, path):
        self.lines, self.path, self.pos = lines, str(path), 0

    def done(self):
        return self.pos >= len(self.lines)

    def peek(self):
        return None if self.done() else self.lines[self.pos]

    def next(self, field):
        if self.done():
            last = self.lines[-1].number if self.lines else None
            raise InputError(self.path, last, field, "unexpected end of file")
        line = self.lines[self.pos]
        self.pos += 1
        return line


def check_profile(rows, where):
    """Check current profile rows [[z, speed, direction], ...] read from a file
    (physics.current.profile_problem); ``where[k]`` = (line, {"z": field, "speed": field,
    "direction": field}) names the first problem's line and field; ``line`` may be a dict
    of lines by the same keys when a level's values sit on different lines."""
    from ..physics.current import profile_problem
    problem = profile_problem(*zip(*rows))
    if problem is not None:
        k, name, message = problem
        line, names = where[k]
        raise (line[name] if isinstance(line, dict) else line).error(names[name], message)
    return rows
