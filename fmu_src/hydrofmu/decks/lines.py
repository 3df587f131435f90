"""Line-level tools shared by the deck readers: numbered lines, keyword matching,
typed fields with errors that name the file, the line and the field."""
from dataclasses import dataclass
from pathlib import Path

from ..errors import InputError


@dataclass(frozen=True)
class Line:
    path: str
    number: int  # 1-based line number in the file (first line of a continued line)
    text: str

    @property
    def words(self):
        return self.text.replace(",", " ").split()

    def error(self, field, message):
        return InputError(self.path, self.number, field, message)


def read_lines(path, comment="'", continuation=None):
    """Non-blank, non-comment lines of a text file as ``Line`` objects.

    ``comment``: prefix (after leading blanks) of comment lines, or a tuple of them.
    ``continuation``: a trailing mark (e.g. ``&``) that joins a line with the next one.
    """
    path = Path(path)
    try:
        raw = path.read_text(encoding="utf-8", errors="replace").splitlines()
    except OSError as exc:
        raise InputError(path, None, "file", f"cannot read deck ({exc.strerror})") from None
    comments = (comment,) if isinstance(comment, str) else tuple(comment or ())
    out, pending = [], None
    for number, text in enumerate(raw, start=1):
        stripped = text.strip()
        if not stripped or (comments and stripped.startswith(comments)):
            continue
        if pending is not None:
            stripped = pending.text + " " + stripped
            number = pending.number
            pending = None
        if continuation and stripped.endswith(continuation):
            pending = Line(str(path), number, stripped[: -len(continuation)].rstrip())
            continue
        out.append(Line(str(path), number, stripped))
    if pending is not None:
        out.append(pending)
    return out


def keyword_key(text):
    """Normalised keyword: the first four letters of each word, upper case.
    'NEW COMPonent BODY' and 'new comp body' both give ('NEW', 'COMP', 'BODY')."""
    return tuple(word[:4].upper() for word in text.split())


def is_keyword(line, keyword):
    """True if ``line`` is the keyword line ``keyword`` (first four letters of each word
    count, case does not; extra words on the line are not allowed)."""
    return keyword_key(line.text) == keyword_key(keyword)


def fields(line, names, kind=float, defaults=None):
    """Parse the words of ``line`` as the named fields.

    ``kind``: a type for all fields or a list of types, one per name.
    ``defaults``: values for trailing fields that may be left out.
    Returns a dict name → value; one InputError names the first bad or missing field.
    """
    kinds = kind if isinstance(kind, (list, tuple)) else [kind] * len(names)
    defaults = defaults or {}
    words = line.words
    if len(words) > len(names):
        raise line.error(names[-1], f"expected {len(names)} values ({' '.join(names)}), found {len(words)}")
    values = {}
    for i, (name, typ) in enumerate(zip(names, kinds)):
        if i >= len(words):
            if name in defaults:
                values[name] = defaults[name]
                continue
            raise line.error(name, f"missing value; expected {' '.join(names)}")
        values[name] = convert(line, name, words[i], typ)
    return values


def convert(line, name, word, typ):
    """One word as ``typ`` (float, int or str), or an error naming the field."""
    if typ is str:
        return word
    try:
        if typ is int:
            value = float(word)
            if value != int(value):
                raise ValueError
            return int(value)
        return float(word.replace("D", "E").replace("d", "e"))
    except ValueError:
        raise line.error(name, f"expected {'an integer' if typ is int else 'a number'}, found {word!r}") from None


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
