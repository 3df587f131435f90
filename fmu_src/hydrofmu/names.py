"""Closest valid names for a name that is not one: one rule for every "unknown name" message
(scene keys, batch knobs and outputs, run records, result columns).

``closest`` ranks by difflib's similarity ratio (case-insensitive, so ``Barge.Force`` finds
``barge.force``); ``unknown`` is the message text that goes after the field of an error.
"""
from __future__ import annotations

import difflib
from typing import Iterable

CUTOFF = 0.6   # difflib's default: below it two names share too little to suggest one for the other


def closest(name: str, valid: Iterable[str], n: int = 3) -> list[str]:
    """Up to ``n`` names of ``valid`` most like ``name``, best first (none when nothing is close)."""
    valid = list(dict.fromkeys(str(v) for v in valid))
    lower = {}
    for v in valid:
        lower.setdefault(v.lower(), v)
    found = difflib.get_close_matches(str(name).lower(), list(lower), n=n, cutoff=CUTOFF)
    return [lower[f] for f in found]


def did_you_mean(name: str, valid: Iterable[str], n: int = 3) -> str:
    """``" (did you mean 'a' or 'b'?)"`` for the closest names, or ``""``."""
    found = closest(name, valid, n)
    if not found:
        return ""
    quoted = [repr(f) for f in found]
    return f" (did you mean {' or '.join(quoted) if len(quoted) < 3 else ', '.join(quoted[:-1]) + ' or ' + quoted[-1]}?)"


def unknown(what: str, name: str, valid: Iterable[str], show: int = 12) -> str:
    """``"unknown {what} 'x' (did you mean …?); valid: a, b, …"``: the closest names, then
    the valid ones (at most ``show`` of them, with how many more)."""
    valid = list(dict.fromkeys(str(v) for v in valid))
    listed = ", ".join(valid[:show]) + (f", … ({len(valid) - show} more)" if len(valid) > show else "")
    return f"unknown {what} {name!r}{did_you_mean(name, valid)}; valid: {listed or 'none'}"


class UnknownName(KeyError, ValueError):
    """A name that is not there (a result's column, instance, variable or body): ``kind``,
    the ``name`` asked for, and `unknown`'s message (the closest names, then the valid
    ones).  A KeyError (a failed lookup) and a ValueError (what ``list.index`` raised
    before), printed as plain text."""

    def __init__(self, kind: str, name: str, valid: Iterable[str], where: str = ""):
        self.kind, self.name = kind, name
        self.message = unknown(kind, name, valid).replace(f"{name!r}", f"{name!r}{where}", 1)
        super().__init__(self.message)

    def __str__(self):
        return self.message
