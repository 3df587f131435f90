"""Reading an input file as text, the same way for every deck reader and the scene loader.

UTF-8 only (ASCII included), with or without a byte-order mark; line ends LF, CRLF or CR.
Anything else (a Latin-1 accent, a binary file) is one InputError naming the file, the
line and the column of the first bad byte: nothing is guessed or silently replaced.
"""
from pathlib import Path

from .errors import InputError

BOM = "\ufeff"


def read_text(path, what="file"):
    """The text of ``path`` (BOM removed, line ends as read; use ``str.splitlines``).
    ``what`` names the file's role in the message of an unreadable file ('deck', 'scene')."""
    path = Path(path)
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise InputError(path, None, "file", f"cannot read {what} ({exc.strerror or exc})") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as exc:
        head = data[:exc.start]
        line = head.count(b"\n") + 1
        column = exc.start - (head.rfind(b"\n") + 1) + 1
        kind = "a binary file, not text" if b"\0" in data[:4096] else "not UTF-8 text"
        raise InputError(path, line, "encoding", f"{what} is {kind} (byte 0x{data[exc.start]:02x} at "
                                                 f"column {column}); save it as UTF-8") from None
    if "\0" in text:
        line = text.count("\n", 0, text.index("\0")) + 1
        raise InputError(path, line, "encoding", f"{what} is a binary file, not text (NUL byte)")
    return text[1:] if text.startswith(BOM) else text


def read_toml(path, what="file"):
    """The parsed TOML of ``path`` (read as ``read_text``); a syntax error is one InputError
    naming the file and its line (older tomllib versions say the line only in the text)."""
    import re
    import tomllib
    try:
        return tomllib.loads(read_text(path, what))
    except tomllib.TOMLDecodeError as exc:
        line = getattr(exc, "lineno", None)
        if line is None:
            found = re.search(r"\(at line (\d+), column \d+\)", str(exc))
            line = int(found.group(1)) if found else None
        raise InputError(path, line, "toml", str(exc)) from None
