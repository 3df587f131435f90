"""Line-level tools shared by the deck readers: numbered lines, keyword matching,
typed fields with errors that name the file, the line and the field.

FREAD, the free-format reader of SIMO and RIFLEX input (``fread_lines``, ``fields``,
``Keyword``), as the readers apply it:

- a data group starts with an identifier of up to three words, printed in the manuals with
  capitals and lower-case letters: the capitals of each word must be written, the lower-case
  letters may be (``UNIT NAMe SPECification`` = ``UNIT NAM SPEC`` = ``unit names
  specification``; ``UNIT NA SPEC`` is an error), case does not count; letters written beyond
  the capitals must spell the word (a longer word, such as a plural, may follow it in full);
  no extra words;
- values are separated by blanks (tabs) and/or commas; a number is written as Fortran reads
  it (``12``, ``-1.5``, ``.5``, ``2.``, ``1.5E3``, with a ``D`` exponent ``2.5D+03``):
  ``1_000``, ``0x10`` or ``1,5`` are errors, not numbers Python would make of them;
- ``/`` in place of a value gives that field its default (``fields(..., defaults=)``);
- ``&`` at the end of a line continues it on the next line;
- ``'`` starts a comment: a line whose first non-blank character is ``'`` is skipped, and
  text after a ``'`` on a data line is ignored;
- ``END`` ends the input: whatever follows it is not read.

Strict inside a group, lenient only between groups (``Grammar``): a line that resembles a
keyword a reader knows (too short, misspelt, extra words, a known stem) is an error naming
the keyword, never a skipped group; a sub-group outside its group, or a group that may be
given once given twice, is an error; the line after a group must start a new one.  What a
reader used and skipped, and its warnings, is kept in a ``Reading``.
"""
import math
import re
import warnings
from dataclasses import dataclass, field
from pathlib import Path

from ..admissible import finite_problem, odd_direction
from ..errors import InputError, InputWarning
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
    return END_KEY.matches(line.words)


class Keyword:
    """A keyword as a manual prints it, and the rule that matches it.

    FREAD (``exact=False``): each word's leading capitals must be written, its lower-case
    letters may be, letters written beyond the capitals must spell the word (a longer word,
    e.g. a plural, may follow the whole word), case does not count, the word count must be
    the keyword's.  ``exact=True`` (DeepLines, AQWA): every word in full, any case.
    """

    def __init__(self, spelling, exact=False):
        self.spelling, self.exact = spelling, exact
        self.words = tuple((w.upper() if exact else w[:_caps(w)].upper(), w.upper()) for w in spelling.split())

    def __repr__(self):
        return self.spelling

    def _word(self, k, word):
        """'match', 'near' (too short, misspelt, letters beyond an exact word) or None."""
        caps, full = self.words[k]
        w = word.upper()
        if self.exact:
            if w == full:
                return "match"
            return "near" if w.startswith(full) or full.startswith(w) or _osa(w, full) <= 1 else None
        rest, more = w[len(caps):], full[len(caps):]
        if w.startswith(caps) and (not rest or rest.isalpha()) and (rest.startswith(more) or more.startswith(rest)):
            return "match"
        if caps.startswith(w) or (w[:1] == full[:1] and len(w) >= 3 and min(
                (_osa(w, full[:n]) for n in range(max(len(caps), len(w) - 1), min(len(full), len(w) + 1) + 1)),
                default=2) <= 1):
            return "near"
        return None

    def matches(self, words):
        return len(words) == len(self.words) and all(self._word(k, w) == "match" for k, w in enumerate(words))

    def resembles(self, words):
        """Why ``words`` look like this keyword without matching it, or None."""
        n = len(self.words)
        kinds = [self._word(k, w) for k, w in enumerate(words[:n])]
        if len(words) == n and None not in kinds and "near" in kinds and (n == 1 or "match" in kinds):
            return "abbreviated below its capitals or misspelt" if not self.exact else "misspelt"
        if len(words) > n and all(k == "match" for k in kinds):
            return f"extra words after the keyword ({' '.join(words[n:])!r})"
        if 2 <= len(words) < n and all(k == "match" for k in kinds):
            return "incomplete"
        return None


def _caps(word):
    """Length of a keyword word's leading capitals (all of it when it has no lower case)."""
    return next((i for i, c in enumerate(word) if c.islower()), len(word))


def _osa(a, b):
    """Edit distance with adjacent transpositions (optimal string alignment)."""
    d = [[i + j if i * j == 0 else 0 for j in range(len(b) + 1)] for i in range(len(a) + 1)]
    for i in range(1, len(a) + 1):
        for j in range(1, len(b) + 1):
            d[i][j] = min(d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + (a[i - 1] != b[j - 1]))
            if i > 1 and j > 1 and a[i - 1] == b[j - 2] and a[i - 2] == b[j - 1]:
                d[i][j] = min(d[i][j], d[i - 2][j - 2] + 1)
    return d[-1][-1]


END_KEY = Keyword(END)


class Grammar:
    """The keywords a reader knows: ``groups`` (top-level data groups), ``inner`` (sub-groups,
    legal only inside their group), ``once`` (groups a file may hold once) and ``stems``
    (starts that only our groups have: a line starting so is ours or an error).

    ``find(line)`` gives the keyword a line is, None for a line that starts like no keyword
    we read, and raises InputError (file, line, the keyword it resembles) otherwise."""

    def __init__(self, groups, inner=(), once=(), stems=(), exact=False, words=None):
        self.exact = exact
        self.groups = [Keyword(k, exact) for k in groups]
        self.inner = [Keyword(k, exact) for k in inner]
        self.once = {k.spelling for k in self.groups if k.spelling in once}
        self.stems = [Keyword(k, exact) for k in stems]
        self.words = words or (lambda line: line.words)

    def find(self, line, field_=None):
        """``field_``: the field an error names (default: "data group" for FREAD, the
        keyword itself for exact keywords)."""
        words = self.words(line)
        if not words:
            return None
        for key in self.groups + self.inner:
            if key.matches(words):
                return key
        for key in self.groups + self.inner:
            why = key.resembles(words)
            if why:
                hint = "" if self.exact else "; write it as the manual prints it (capitals required)"
                raise line.error(field_ or ("data group" if not self.exact else key.spelling),
                                 f"{line.text!r} looks like the keyword {key.spelling!r} but is not it ({why}){hint}")
        for stem in self.stems:
            n = len(stem.words)
            if len(words) >= n and all(stem._word(k, w) == "match" for k, w in enumerate(words[:n])):
                known = " or ".join(repr(k.spelling) for k in self.groups + self.inner
                                    if k.words[:n] == stem.words)
                raise line.error(field_ or ("data group" if not self.exact else self.groups[0].spelling),
                                 f"expected {known}, found {line.text!r}")
        return None

    def expect(self, line, *keys):
        """``line`` must be one of ``keys``: the Keyword it is, or an error naming them."""
        found = self.find(line, keys[0])
        if found is None or found.spelling not in keys:
            raise line.error(keys[0], f"expected {' or '.join(map(repr, keys))}, found {line.text!r}")
        return found


@dataclass
class Reading:
    """What a reader did with a file: the groups it ``used`` and the ones it ``skipped``
    (each (name, line)), and the ``warnings`` it gave (suspicious but legal data)."""
    path: str
    reader: str
    used: list = field(default_factory=list)
    skipped: list = field(default_factory=list)
    warnings: list = field(default_factory=list)
    _next: int = None

    def use(self, name, line):
        self.used.append((str(name), line.number if isinstance(line, Line) else line))

    def skip(self, line, pos=None, count=1):
        """``count`` lines skipped from ``line`` on; ``pos``: the index of a single line among
        the data lines, to make consecutive skipped lines one span named by its first line."""
        if pos is not None and self.skipped and self._next == pos:
            name, number, n = self.skipped[-1]
            self.skipped[-1] = (name, number, n + count)
        else:
            self.skipped.append((line.text, line.number, count))
        self._next = None if pos is None else pos + count

    def warn(self, line, field_, message):
        """A warning for suspicious but legal data (printed by the CLI, kept for the manifest)."""
        w = InputWarning(self.path, line.number if line is not None else None, field_, message)
        self.warnings.append(str(w))
        warnings.warn(w)

    def as_dict(self):
        return {"path": self.path, "reader": self.reader,
                "used": [{"group": n, "line": k} for n, k in self.used],
                "skipped": [{"group": n, "line": k, "lines": c} for n, k, c in self.skipped],
                "warnings": list(self.warnings)}

    def summary(self):
        """Lines for the build output: what was used and skipped, by name and line."""
        used = ", ".join(f"{n} (line {k})" for n, k in self.used) or "nothing"
        skipped = ", ".join(f"{n!r} (line {k}{f', {c} lines' if c > 1 else ''})"
                            for n, k, c in self.skipped) or "nothing"
        return [f"deck {self.path} ({self.reader}): used {used}", f"  skipped {skipped}"]


class Entries(dict):
    """A reader's result (name → data) with its ``reading``."""
    reading = None


class Rows(list):
    """A reader's profile rows with its ``reading``."""
    reading = None


def with_reading(result, reading):
    out = (Entries if isinstance(result, dict) else Rows)(result)
    out.reading = reading
    return out


def after_group(cur, starts_group, owner, expected="a new data group"):
    """The line after a group's last line must end the input or start a new group: a data
    line there (a count exceeded, a row too many) is an error, never skipped."""
    nxt = cur.peek()
    if nxt is not None and not is_end(nxt) and not starts_group(nxt):
        raise nxt.error("data group identifier", f"unexpected line {nxt.text!r} after {owner}: the layout has no "
                                                 f"further line here (a count exceeded or a row too many?); "
                                                 f"expected {expected}")


def interrupted(unknown, owner, rest):
    """A group (one we skip) that ends one of ours where its layout allows, but whose lines
    read as more of ours (``rest()`` parses them without error), is a stray line inside our
    group: an error, not a skipped group."""
    try:
        ok = rest()
    except InputError:
        return
    if ok:
        raise unknown.error("data group", f"{unknown.text!r} ends {owner} where its layout allows, but the lines "
                                          f"after it read as more of that group: a stray or misplaced line inside "
                                          f"it? (remove it, or move the group it starts)")


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
    if len(words) > len(names):   # named at the physical line of the first value too many
        raise line.at_word(len(names)).error(names[-1], f"expected {len(names)} values ({' '.join(names)}), "
                                                        f"found {len(words)}")
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


_NUMBER = re.compile(r"[+-]?(\d+\.?\d*|\.\d+)([EeDd][+-]?\d+)?\Z", re.ASCII)


def fortran_float(word):
    """A number as Fortran reads it (``D`` exponents too), or ValueError: Python's float()
    also takes ``1_000`` and digits no deck writes.  NaN and inf pass (callers say why
    they are refused)."""
    if not _NUMBER.match(word) and word.lstrip("+-").lower() not in ("nan", "inf", "infinity"):
        raise ValueError(f"not a number: {word!r}")
    return float(word.replace("D", "E").replace("d", "e"))


def convert(line, name, word, typ):
    """One word as ``typ`` (float, int or str), or an error naming the field.  Numbers
    must be finite: NaN, inf and overflowing values (1e400) are errors here, for every deck."""
    if typ is str:
        return word
    try:
        value = fortran_float(word)
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


def check_profile(rows, where, reading=None):
    """Check current profile rows [[z, speed, direction], ...] read from a file
    (physics.current.profile_problem); ``where[k]`` = (line, {"z": field, "speed": field,
    "direction": field}) names the first problem's line and field; ``line`` may be a dict
    of lines by the same keys when a level's values sit on different lines.  A direction
    outside [0°, 360°] (370° for 10°?) is legal but said: a warning in ``reading``."""
    from ..physics.current import profile_problem
    problem = profile_problem(*zip(*rows))
    at = (lambda k, name: (where[k][0][name] if isinstance(where[k][0], dict) else where[k][0]))
    if problem is not None:
        k, name, message = problem
        raise at(k, name).error(where[k][1][name], message)
    for k, row in enumerate(rows):
        odd = odd_direction(row[2])
        if reading is not None and odd:
            reading.warn(at(k, "direction"), where[k][1]["direction"], odd)
    return rows


# --- numeric output files (WAMIT .1 .2 .3 .hst …) ------------------------------------------
_STARTS_NUMBER = re.compile(r"[+-]?(\d|\.\d)")


def _is_fortran_number(word):
    try:
        fortran_float(word)
        return True
    except ValueError:
        return False


def numeric_rows(path, names, counts=None):
    """The rows of a file of numbers in columns (WAMIT's numeric outputs): ``(rows, header)``,
    rows = [(line number, [floats])], header = [(line number, text)].

    ``names``: the fields of a full row; ``counts``: the numbers of fields a row may have
    (default: exactly ``len(names)``).  Lines before the first row whose first word does not
    start like a number (and that are not all numbers: ``nan 1 1 …`` is a row) are header lines (WAMIT's ``NUMHDR=1`` line ``WAMIT Numeric Output --
    Filename …``); after the first row every line must be a row.  A row with more fields than
    its format, fewer, a word that is not a Fortran number or a non-finite value is one
    InputError naming the file, the line and the field."""
    counts = tuple(counts or (len(names),))
    rows, header = [], []
    for number, text in enumerate(read_text(path, "file").splitlines(), 1):
        words = text.replace(",", " ").split()
        if not words:
            continue
        if not rows and not _STARTS_NUMBER.match(words[0]) and not all(map(_is_fortran_number, words)):
            header.append((number, text.strip()))
            continue
        values = []
        for name, word in zip(names, words):
            try:
                value = fortran_float(word)
            except ValueError:
                where = "" if rows else " (a header line must not start like a number)"
                raise InputError(path, number, name, f"not a number: {word!r}{where}") from None
            if not math.isfinite(value):
                raise InputError(path, number, name, f"non-finite value {word!r}")
            values.append(value)
        if len(words) not in counts:
            many = len(words) > max(counts)
            want = " or ".join(map(str, counts))
            raise InputError(path, number, " ".join(names) if many else names[len(words)],
                             f"expected {want} numbers ({' '.join(names)}), found {len(words)}: {text.strip()!r}"
                             + (": more fields than the format (a merged or shifted line?)" if many else ""))
        rows.append((number, values))
    return rows, header
