"""Is a number physically admissible?  One set of checks for every deck reader, the scene
loader and the physics: each returns a list of (field, message) problems, empty when the
values are fine, and the caller names the file and line (deck) or key path (scene).

Conventions: inertia [kg·m²] about the CoG in body axes; added mass 6×6 [kg, kg·m,
kg·m²]; attitude (roll, pitch, yaw) [rad], ZYX Euler angles.
"""
import math

import numpy as np

SYMMETRY_TOL = 1e-3      # |A_ij − A_ji| ≤ SYMMETRY_TOL·√(A_ii·A_jj): relative, unit-consistent
TRIANGLE_TOL = 1e-9      # principal inertias: I_a ≤ (I_b + I_c)·(1 + TRIANGLE_TOL)
POSE_COS_MIN = 1e-3      # |cos θ| of the initial pitch: ≥ this (|θ| ≤ 89.94°), away from gimbal lock


def finite_problem(value):
    """A message when ``value`` is not a finite number, else None."""
    return None if math.isfinite(value) else f"expected a finite number, found {value}"


def symmetric(a, label, tol=SYMMETRY_TOL):
    """Symmetry of a square matrix by |a_ij − a_ji| ≤ tol·√(a_ii·a_jj) (each entry compared
    with the diagonal entries of its own row and column, so mixed units never meet).
    ``label(i, j)`` names entry (i, j) (0-based), e.g. ``lambda i, j: f'AM{i+1}{j+1}'``."""
    a = np.asarray(a, dtype=float)
    d = np.sqrt(np.abs(np.diag(a)))
    excess = np.abs(a - a.T) - tol * np.outer(d, d)
    if not np.any(excess > 0.0):
        return []
    i, j = np.unravel_index(np.argmax(excess), a.shape)
    i, j = (i, j) if i < j else (j, i)
    return [(label(i, j), f"must be symmetric: {label(i, j)} = {a[i, j]:g} but {label(j, i)} = "
                          f"{a[j, i]:g} (allowed difference {tol:g}·√({label(i, i)}·{label(j, j)}) "
                          f"= {tol * d[i] * d[j]:g})")]


def inertia(matrix, field="inertia"):
    """Inertia tensor about the CoG: symmetric, positive definite, principal values
    within the triangle inequality (I_a ≤ I_b + I_c, equality for a flat plate)."""
    i = np.asarray(matrix, dtype=float)
    label = lambda r, c: f"{field}[{r + 1},{c + 1}]"
    problems = symmetric(i, label)
    if problems:
        return problems
    p = np.linalg.eigvalsh(0.5 * (i + i.T))
    if p.min() <= 0.0:
        return [(field, f"must be positive definite: principal inertias {_list(p)}")]
    if p[2] > (p[0] + p[1]) * (1.0 + TRIANGLE_TOL):
        return [(field, f"principal inertias {_list(p)} violate the triangle inequality "
                        f"(largest {p[2]:g} > sum of the others {p[0] + p[1]:g}): no rigid body has them")]
    return []


def attitude(angles, field="attitude"):
    """A pose away from the ZYX Euler-angle singularity (pitch ±90°)."""
    theta = float(angles[1])
    if abs(math.cos(theta)) < POSE_COS_MIN:
        return [(field, f"pitch {math.degrees(theta):.4f}° is at the ZYX Euler-angle singularity "
                        f"(±90°, gimbal lock): keep |cos(pitch)| ≥ {POSE_COS_MIN:g}")]
    return []


def negative_diagonal(matrix):
    """Suspicious, not wrong: a negative diagonal drag coefficient feeds energy in.
    Returns warnings [(index k of the diagonal entry, message)]."""
    d = np.diag(np.asarray(matrix, dtype=float))
    return [(k, f"negative diagonal drag coefficient {d[k]:g} puts energy into the body "
                "(a drag diagonal is normally ≥ 0)") for k in np.flatnonzero(d < 0.0)]


def odd_direction(degrees):
    """Suspicious, not wrong: a direction outside 0…360° (370° is 10°: a typing slip?).
    Returns the message, or None."""
    if 0.0 <= degrees <= 360.0:
        return None
    return f"direction {degrees:g}° is outside 0…360° (read as {degrees % 360.0:g}°): a typing slip?"


def odd_attitude(angles):
    """Suspicious, not wrong: an attitude angle beyond ±2π rad (degrees written where
    radians go: 90 for a quarter turn is 90 rad).  Returns the message, or None."""
    big = [a for a in angles if abs(a) > 2.0 * math.pi]
    if not big:
        return None
    return (f"{big[0]:g} rad is beyond ±2π (read as {math.degrees(big[0]) % 360.0:.4g}°): attitude is in "
            f"radians; degrees written? ({big[0]:g}° = {math.radians(big[0]):.6g} rad)")


def _list(values):
    return "[" + ", ".join(f"{v:.6g}" for v in values) + "]"


MAX_STEPS = 10 ** 8   # a run's results are kept in memory: 1e8 rows of a few dozen columns is tens of GB
STEPS_TOL = 1e-9   # relative: stop/step within this of a whole number counts as whole (0.3/0.1 = 2.9999999999999996)


def whole_steps(stop, step):
    """(number of communication steps, problems) of a fixed-step run from 0 to ``stop`` [s] in
    steps of ``step`` [s]: ``stop`` must be a whole number n ≥ 1 of steps (no silently shorter
    or longer run); problems name the field ``stop``."""
    if not (math.isfinite(stop) and math.isfinite(step) and stop > 0 and step > 0):
        return 0, [("stop" if not (math.isfinite(stop) and stop > 0) else "step",
                    f"must be a positive finite number, found {stop if not (math.isfinite(stop) and stop > 0) else step:g}")]
    ratio = stop / step
    n = round(ratio)
    if ratio < 1 - STEPS_TOL:
        return 0, [("stop", f"stop {stop:g} s is shorter than one step ({step:g} s): nothing would run; "
                            f"use stop ≥ {step:g} s or a smaller step")]
    if n > MAX_STEPS:
        return 0, [("step", f"{n:.3g} steps of {step:g} s to {stop:g} s: more than {MAX_STEPS:.0e} "
                            "(the recorded results alone would not fit in memory); use a larger step")]
    if abs(ratio - n) > STEPS_TOL * max(1.0, ratio):
        lo, hi = math.floor(ratio), math.ceil(ratio)
        return 0, [("stop", f"stop {stop:g} s is not a whole number of steps of {step:g} s ({ratio:.6g} steps): "
                            f"use stop {lo * step:.10g} or {hi * step:.10g} s, or a step that divides {stop:g} s")]
    return n, []


def whole_interval(interval, step):
    """(communication points per output row, problems) of an output ``interval`` [s]: a whole
    number ≥ 1 of steps ``step`` [s]; problems name the field ``interval``."""
    ratio = interval / step
    every = round(ratio)
    if every < 1 or abs(ratio - every) > STEPS_TOL * max(1.0, ratio):
        return 1, [("interval", f"the output interval must be a whole number of steps ({step:g} s), "
                                f"found {interval:g} s")]
    return int(every), []


def _depth(value):
    return "deep water (inf)" if math.isinf(value) else f"{value:g} m"


def depth_mismatch(file_depth, scene_depth, rel=1e-6):
    """A message when a BEM result's water depth is not the scene's (both [m], inf: deep
    water), else None.  Infinite and finite never match: |50 − ∞| ≤ 1e-6·∞ is no test."""
    if file_depth is None or scene_depth is None:
        return None
    if math.isinf(file_depth) or math.isinf(scene_depth):
        same = math.isinf(file_depth) and math.isinf(scene_depth)
    else:
        same = abs(file_depth - scene_depth) <= rel * scene_depth
    return None if same else f"water depth {_depth(file_depth)} in the BEM result but {_depth(scene_depth)} in the scene"


# What a sea can be (issue 31): beyond these a value is a slip (millimetres for metres, a
# frequency for a period), said naming the key.  Errors: no sea state on record has Hs near
# 30 m (the largest measured are about 20 m) and no wave is 60 m high; warnings: periods
# outside 1…40 s are legal (model-basin scale, long swell) but rarely meant, and a wave steeper
# than the breaking limit H/L = 1/7 (L of its period and depth) is beyond linear theory.
HS_MAX = 30.0            # m: significant wave height, error above
HEIGHT_MAX = 60.0        # m: regular wave height, error above
PERIOD_RANGE = (1.0, 40.0)   # s: Tp and the regular period, warning outside
BREAKING = 1 / 7         # H/L: regular waves (Hs/Lp for spectra), warning above

# the keys each spectrum reads ([waves]); the others are ignored by it (a warning names them)
WAVE_KEYS_USED = {
    "regular": {"height", "period", "phase", "direction", "ramp", "depth"},
    "jonswap": {"hs", "tp", "gamma", "direction", "spreading", "components", "seed", "ramp", "depth"},
    "pierson_moskowitz": {"hs", "tp", "direction", "spreading", "components", "seed", "ramp", "depth"},
}
for _used in WAVE_KEYS_USED.values():   # the kinematics' keys: every spectrum reads them
    _used |= {"stretching", "points"}


def sea_problems(spectrum, values, g=9.81):
    """(errors, warnings) of a sea state's values (``values``: key → number, the [waves]
    knobs): each a list of (key, message); see HS_MAX … BREAKING."""
    from .physics.waves import wave_number
    errors, warns = [], []
    regular = spectrum == "regular"
    h_key, t_key = ("height", "period") if regular else ("hs", "tp")
    h, t = values.get(h_key), values.get(t_key)
    limit = HEIGHT_MAX if regular else HS_MAX
    if h is not None and h > limit:
        errors.append((h_key, f"{h:g} m is beyond any sea ({'a regular wave' if regular else 'Hs'} above {limit:g} m): "
                              "millimetres or centimetres written for metres?"))
    if t is not None and t > 0 and not PERIOD_RANGE[0] <= t <= PERIOD_RANGE[1]:
        warns.append((t_key, f"{t:g} s is outside {PERIOD_RANGE[0]:g}…{PERIOD_RANGE[1]:g} s, the periods of sea waves "
                             "at full scale: a frequency written for a period, or a model-scale sea?"))
    if h is not None and t is not None and h > 0 and t > 0 and not errors:
        depth = values.get("depth", math.inf)
        length = 2 * math.pi / float(wave_number(2 * math.pi / t, g, depth))
        if h / length > BREAKING:
            warns.append((h_key, f"{h:g} m in a wave {length:.3g} m long ({t_key} = {t:g} s): steeper than the breaking "
                                 f"limit H/L = 1/7 (H/L = {h / length:.2f}); linear waves do not hold there"))
    return errors, warns


def ignored_wave_keys(spectrum, given):
    """The keys of ``given`` (a [waves] table's keys) the spectrum does not read."""
    used = WAVE_KEYS_USED.get(spectrum, set()) | {"spectrum"}
    return sorted(k for k in given if k not in used)


def memory_bytes():
    """The machine's physical memory [bytes] (None when the system does not say)."""
    import os
    try:
        return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")
    except (ValueError, OSError, AttributeError):
        return None


def size_problem(count, bytes_each, what):
    """A message when ``count`` items of ``bytes_each`` bytes (an allocation a size key asks
    for) cannot fit in the machine's memory, else None: said before anything is allocated,
    instead of a MemoryError."""
    total = float(count) * float(bytes_each)
    limit = memory_bytes() or 2.0 ** 40
    if not math.isfinite(total) or total > limit:
        return (f"{count:.4g} {what} would need {total / 2 ** 30:.3g} GiB, more than this machine's "
                f"{limit / 2 ** 30:.3g} GiB of memory")
    return None
