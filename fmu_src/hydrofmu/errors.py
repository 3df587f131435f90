"""One error type for every bad input: it names the file, the line and the field."""


class InputError(ValueError):
    """Bad user input.

    ``path`` is the file, ``line`` the 1-based line number (``None`` when the problem is
    not tied to one line, e.g. a missing file), ``field`` the name of what was expected
    (a deck field such as ``CDX`` or a scene key path such as ``bodies.barge.effects``).
    """

    def __init__(self, path, line, field, message):
        self.path, self.line, self.field, self.message = str(path), line, field, message
        where = self.path if line is None else f"{self.path}:{line}"
        super().__init__(f"{where}: {field}: {message}")


class InputWarning(UserWarning):
    """Legal but suspicious input (e.g. a negative drag coefficient): same naming as
    InputError; the build goes on, the CLI prints one ``warning:`` line."""

    def __init__(self, path, line, field, message):
        self.path, self.line, self.field, self.message = str(path), line, field, message
        where = self.path if line is None else f"{self.path}:{line}"
        super().__init__(f"{where}: {field}: {message}")


def numbers(values, digits: int = 6) -> str:
    """``[0, 0, -1]``: a vector as an error message prints it (plain numbers, ``digits`` significant
    digits, no numpy reprs such as ``np.float64(-1.0)``)."""
    return "[" + ", ".join(f"{float(v):.{digits}g}" for v in values) + "]"
