"""``hydrofmu tune``, step 3: the choice confirmed over the run it is tuned for.

The search's window may be short; a setting that meets the tolerance there may still drift
or diverge later (the constant hold's half-step lag drives lightly damped modes: physics.hold).
So the candidates, cheapest first, are run again over the confirmation length (the scene's
``stop``, or the ``confirm`` seconds asked), next to the converged reference over the same
length, and the first that meets the tolerance there is the choice.  Its error is measured
as in the search (RMS difference over the reference's range) over the whole length and over
each quarter of it (same range); when the length is shorter than the scene's stop (the drift
check) the last quarter's error must meet the tolerance too: an error that grows toward the
end shows there.  A candidate that fails is reported ("diverges later") and not offered."""
from __future__ import annotations

import math

import numpy as np

from .runner import _error, _Runner

QUARTERS = 4


def confirm(search, candidates, length, outputs, cache):
    """The first of ``candidates`` (Points, in the order to try) that meets the tolerance over
    ``length`` seconds (and the drift check when that is shorter than the stop); sets each tried point's
    ``confirmed`` and ``drift``.  Returns (that point or None, report lines)."""
    key = ("confirm", str(search.path), length, tuple(outputs or ()))
    runner = cache.setdefault(key + ("runner",), _Runner(search.path, length, outputs, search.log))
    runner.joints = search.runner.joints
    runs = cache.setdefault(key + ("runs",), {})

    def get(setting):
        if setting not in runs:
            runs[setting] = runner.run(setting)
        return runs[setting]

    t_ref, y_ref, _ = get(search.ref_setting)
    if t_ref is None:
        return None, [f"confirmation over {length:g} s: the reference itself failed ({y_ref})"]
    y_ref = y_ref[:, search.moving]
    scale = np.ptp(y_ref, axis=0)
    stop, u, tol = search.stop, search.u, search.tolerance
    lines = []
    for p in candidates:
        t, y, _ = get(p.setting)
        if t is None:
            p.confirmed = p.drift = math.inf
            lines.append(f"  {p.setting.label()}: diverges later (the run over {length:g} s failed: {y})")
            continue
        y = y[:, search.moving]
        p.confirmed = _error(t, y, t_ref, y_ref, scale)
        # each quarter's error over the whole length's range: an error that grows toward the end
        # of the confirmation shows in the last quarter
        edges = np.linspace(0.0, t[-1], QUARTERS + 1)
        errs = []
        for a, b in zip(edges[:-1], edges[1:]):
            sel = (t >= a - 1e-9) & (t <= b + 1e-9)
            errs.append(_error(t[sel], y[sel], t_ref, y_ref, scale))
        short = length < stop - 1e-9
        p.drift = errs[-1] if short else p.confirmed
        ok = max(p.confirmed, p.drift) + u <= tol
        lines.append(f"  {p.setting.label()}: {100 * p.confirmed:.3g} % over {length:g} s (per quarter "
                     + ", ".join(f"{100 * e:.2g}" for e in errs) + " %"
                     + (")" if ok else f"): diverges later, not offered (window error {100 * p.error:.3g} %)"))
        if ok:
            return p, lines
    return None, lines
