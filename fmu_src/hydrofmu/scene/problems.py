"""Problem collection for scene files: every problem named by the file and its key path,
raised together as one InputError; typed getters for the scene's tables; and the helpers
that read a vendor deck named in a table."""
import warnings
from pathlib import Path

import numpy as np

from ..errors import InputError, InputWarning
from ..names import did_you_mean


class Problems:
    """Collects validation problems so that one error lists them all."""

    def __init__(self, path):
        self.path, self.items = Path(path), []
        self.unknown = {}  # key path of an unknown key -> the keys allowed there (batch knobs are checked by it)
        self.decks = {}   # (deck path, reader, args) -> entries or the InputError: each deck read once
        self.readings = []   # what each deck read gave: groups used and skipped, warnings (decks.lines.Reading)
        self.facts = set()   # mismatches already stated (add_once): one statement per mismatch

    def read(self, found):
        """Keep the ``reading`` of a deck reader's result (once); returns the result."""
        reading = getattr(found, "reading", None)
        if reading is not None and all(r is not reading for r in self.readings):
            self.readings.append(reading)
        return found

    def add(self, key, message):
        self.items.append((key, message))

    def add_once(self, fact, key, message):
        """``add`` unless the same ``fact`` (a hashable naming the mismatch: e.g. the BEM file,
        its body and what disagrees) was stated already, under this key or another (a BEM file
        read by a coupling and two effects states its rotation centre's mismatch once)."""
        if fact not in self.facts:
            self.facts.add(fact)
            self.add(key, message)

    def add_all(self, where, problems):
        """Record the (field, message) problems of an admissibility check as ``where.field``."""
        for name, message in problems:
            self.add(f"{where}.{name}", message)

    def warn(self, key, message):
        warnings.warn(InputWarning(self.path, None, key, message))

    def raise_if_any(self):
        if self.items:
            (first, message), rest = self.items[0], self.items[1:]
            exc = InputError(self.path, None, first, "; ".join([message] + [f"{k}: {m}" for k, m in rest]))
            exc.unknown = dict(self.unknown)   # for callers that check key paths (batch knobs)
            raise exc

    def deck(self, path, where, reader, *args):
        """``reader(path, *args)``, read once per scene; a deck error is recorded once
        (under the key path ``where`` of its first use) and None returned."""
        key = (str(path), reader, args)
        if key not in self.decks:
            try:
                self.decks[key] = self.read(reader(path, *args))
            except InputError as exc:
                self.decks[key] = exc
                if not any(isinstance(v, InputError) and str(v) == str(exc) for k, v in self.decks.items()
                           if k != key):
                    self.add(where, str(exc))
        found = self.decks[key]
        return None if isinstance(found, InputError) else found

    # typed getters: return a value or None after recording the problem
    def table(self, parent, key, where, required=True):
        value = parent.get(key)
        if value is None:
            if required:
                self.add(where, "missing table")
            return {} if not required else None
        if not isinstance(value, dict):
            self.add(where, "expected a table")
            return None
        return value

    def number(self, parent, key, where, default=None, positive=False, nonneg=False):
        value = parent.get(key, default)
        if value is None:
            self.add(where, "missing value")
            return None
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not _finite(value):
            self.add(where, f"expected a finite number, found {_short(value)}")
            return None
        if positive and value <= 0:
            self.add(where, f"must be positive, found {value}")
            return None
        if nonneg and value < 0:
            self.add(where, f"must not be negative, found {value}")
            return None
        return float(value)

    def vector(self, parent, key, where, n, default=None):
        value = parent.get(key, default)
        if value is None:
            self.add(where, f"missing {n}-vector")
            return None
        arr = self.array(value, where)
        if arr is None:
            return None
        if arr.shape != (n,):
            self.add(where, f"expected {n} numbers, found shape {list(arr.shape)}")
            return None
        return arr.tolist()

    def matrix(self, parent, key, where, n, default=None, diagonal_ok=True):
        """n×n matrix; a list of n numbers means a diagonal matrix."""
        value = parent.get(key, default)
        if value is None:
            self.add(where, f"missing {n}x{n} matrix")
            return None
        arr = self.array(value, where)
        if arr is None:
            return None
        if diagonal_ok and arr.shape == (n,):
            arr = np.diag(arr)
        if arr.shape != (n, n):
            self.add(where, f"expected a {n}x{n} matrix{' or ' + str(n) + ' diagonal values' if diagonal_ok else ''}, "
                            f"found shape {list(arr.shape)}")
            return None
        return arr.tolist()

    def choice(self, parent, key, where, options, default=None):
        value = parent.get(key, default)
        if value not in options:
            self.add(where, f"expected one of {', '.join(map(repr, options))}, found {value!r}")
            return None
        return value

    def string(self, parent, key, where, default=None):
        value = parent.get(key, default)
        if not isinstance(value, str) or not value:
            self.add(where, f"expected a non-empty string, found {value!r}")
            return None
        return value

    def known_keys(self, table, where, allowed):
        for key in table:
            if key not in allowed:
                path = f"{where}.{key}" if where else key
                self.unknown[path] = sorted(allowed)
                self.add(path, f"unknown key{did_you_mean(key, allowed)} (allowed: {', '.join(sorted(allowed))})")

    def array(self, value, where):
        try:
            arr = np.array(value, dtype=float)
        except OverflowError:
            self.add(where, "contains a number too large for a float")
            return None
        except (TypeError, ValueError):
            self.add(where, "expected numbers (ragged or non-numeric array)")
            return None
        if not np.all(np.isfinite(arr)):
            self.add(where, "contains a non-finite number")
            return None
        return arr


def _finite(value):
    try:
        return bool(np.isfinite(float(value)))
    except OverflowError:   # a TOML integer of 400 digits
        return False


def _short(value):
    text = repr(value)
    return text if len(text) <= 40 else text[:20] + "…" + text[-8:]


def identifier(name):
    """True for names usable in FMU variable names and model identifiers."""
    return bool(name) and name.replace("_", "a").isalnum() and name[0].isalpha() and name.isascii()



def deck_path(problems, table, where, key="deck"):
    deck = problems.string(table, key, f"{where}.{key}")
    if deck is None:
        return None
    path = (problems.path.parent / deck).resolve()
    if not path.is_file():
        problems.add(f"{where}.{key}", f"deck file not found: {path}")
        return None
    return path


def deck_units(problems, table, where):
    """The ``units`` of a SIMO/RIFLEX deck reference (decks/units.py), default SI."""
    from ..decks.units import SYSTEMS
    return problems.choice(table, "units", f"{where}.units", tuple(SYSTEMS), "SI")


def from_deck(problems, table, where, reader, name_key, units=False):
    """Read a deck and pick the named entry; deck errors are recorded, not raised.
    ``units``: the reader takes the file's unit system (scene key ``units``)."""
    path = deck_path(problems, table, where)
    name = problems.string(table, name_key, f"{where}.{name_key}")
    system = deck_units(problems, table, where) if units else None
    if path is None or name is None or (units and system is None):
        return None, None
    entries = problems.deck(path, f"{where}.deck", reader, *((system,) if units else ()))
    if entries is None:
        return None, None
    if name not in entries:
        problems.add(f"{where}.{name_key}", f"{name!r} is not in {path.name} (it has: {', '.join(entries) or 'none'})")
        return None, None
    return entries[name], path

