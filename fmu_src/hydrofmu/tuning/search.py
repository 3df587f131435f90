"""``hydrofmu tune``, step 1 and 2: the scene's converged reference, and the search for the
cheapest settings that meet the tolerance over the window (steps with a stability margin,
substeps, memory evaluators, per-coupling orders, ECCO), with the presets and the scene's own
settings run the same way."""
from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from ..admissible import whole_steps
from ..errors import InputError
from .runner import _error, _Runner
from .settings import (ALGORITHMS, ECCO_MIN, ECCO_TOLERANCES, HOLDS, MEMORY, ORDERS, STEPS, SUBSTEPS, Point,
                       Setting)

# A step is offered only this factor below the smallest step of the same algorithm and hold
# that diverged over the window (its run failed, or its error reached DIVERGED): the constant
# hold's damping change grows as the step (ω·h/4), the linear hold's as its cube (docs/tuning.md)
MARGIN = 3.0
DIVERGED = 1.0   # an error of the whole range of the reference: the run left it


class Search:
    """One tune's runs over the window: the reference (``reference()``), every point run
    (``points``: Setting -> Point, with its error against the reference) and the tolerance test
    (``feasible``: error + the reference's uncertainty u within the tolerance)."""

    def __init__(self, path, own, tolerance, outputs, window, log, cache):
        self.path, self.own, self.tolerance, self.window, self.log = path, own, tolerance, window, log
        key = (str(path), window, tuple(outputs or ()))
        self.runner = cache.setdefault(("runner",) + key, _Runner(path, window, outputs, log))
        self.runner.joints = bool(own.joints)
        self.runs = cache.setdefault(("runs",) + key, {})
        self.stop = own.run["stop"]
        self.has_memory = bool(own.couplings)
        self.points = {}
        self.searched, self.pruned, self.margins = [], [], []

    def fits(self, step):
        """A step that divides the window and the scene's stop, at most half the window."""
        return (not whole_steps(self.window, step)[1] and not whole_steps(self.stop, step)[1]
                and step <= self.window / 2)

    def get(self, setting):
        if setting not in self.runs:
            self.runs[setting] = self.runner.run(setting)
        return self.runs[setting]

    def reference(self):
        """The ``reference`` preset, halved (step and substep) until a halving changes it by at
        most tolerance / 4 (twice at most): ``ref_setting`` (the halved one), ``u``, the moving
        outputs and their scale."""
        path, tolerance, runner = self.path, self.tolerance, self.runner
        ref = Setting(0.01, "gauss-seidel", "linear", 0.005, "reference" if self.has_memory else None)
        t0, y0, _ = self.get(ref)
        scale_all = np.ptp(y0, axis=0)
        kind = [("attitude" in c) for c in runner.columns]
        top = {k: max([s for s, kk in zip(scale_all, kind) if kk == k] or [0]) for k in (True, False)}
        moving = np.array([s > 1e-9 * top[k] and s > 0 for s, k in zip(scale_all, kind)])
        if not moving.any():
            raise InputError(path, None, "outputs", "none of the outputs moves over the window: nothing to tune against")
        self.still = [c for c, m in zip(runner.columns, moving) if not m]
        halvings = 0
        while True:
            half = replace(ref, step=ref.step / 2, substep=ref.substep / 2)
            t1, y1, _ = self.get(half)
            scale = np.ptp(y1[:, moving], axis=0)
            u = _error(t0, y0[:, moving], t1, y1[:, moving], scale)
            if u <= tolerance / 4 or halvings == 2:
                break
            ref, t0, y0, halvings = half, t1, y1, halvings + 1
        if u > tolerance / 2:
            raise InputError(path, None, "tolerance", f"{100 * tolerance:g} % is below what the reference resolves "
                                                      f"(its halving changes it by {100 * u:.2g} %): loosen it")
        self.ref_setting, self.u, self.moving, self.scale = half, u, moving, scale
        self.ref_time, self.ref_values = t1, y1[:, moving]
        self.log(f"tune {self.own.name}: reference {half.label()}, uncertainty {100 * u:.2g} %")

    def point(self, setting, source="search"):
        points = self.points
        if setting not in points:
            t, y, sec = self.get(setting)
            err = math.inf if t is None else _error(t, y[:, self.moving], self.ref_time, self.ref_values, self.scale)
            if not math.isfinite(err):
                err = math.inf
            points[setting] = Point(setting, err, sec / self.window,
                                    setting.proxy(self.window, self.runner.instances,
                                                  t if setting.algorithm == "ecco" else None),
                                    source=source)
        elif source != "search":
            old = points[setting].source
            points[setting].source = source if old == "search" else f"{old} = {source}"
        return points[setting]

    def feasible(self, p):
        return p.error + self.u <= self.tolerance

    def search(self):
        """The best point over the window (None when nothing met the tolerance)."""
        has_memory, feasible, point = self.has_memory, self.feasible, self.point
        memories = list(MEMORY) if has_memory else [None]
        exact = "reference" if has_memory else None
        steps = [s for s in STEPS if self.fits(s)]
        self.steps = steps
        sub = lambda s: max([x for x in SUBSTEPS if x <= min(s, 0.01) and _divides(x, s)] or [s])
        best = None
        for algorithm in ALGORITHMS:
            for hold in HOLDS:
                found = self._largest_step(steps, algorithm, hold, sub, exact)
                if found is None:
                    continue
                step = steps[found]
                floor = Setting(step, algorithm, hold, step, None).proxy(self.window, self.runner.instances)
                if best is not None and floor >= best.proxy:
                    self.pruned.append(f"{algorithm}/{hold} (best step {step:g} s cannot beat {best.setting.label()})")
                    continue
                chosen = point(Setting(step, algorithm, hold, sub(step), exact))
                # the largest substep
                for s in sorted((x for x in SUBSTEPS if x <= step and _divides(x, step)
                                 and x > chosen.setting.substep), reverse=True):
                    p = point(replace(chosen.setting, substep=s))
                    if feasible(p):
                        chosen = p
                        break
                # the cheapest memory evaluator
                for m in memories[:-1]:
                    p = point(replace(chosen.setting, memory=m))
                    if feasible(p):
                        chosen = p
                        break
                if best is None or chosen.proxy < best.proxy or (chosen.proxy == best.proxy
                                                                 and chosen.cost < best.cost):
                    best = chosen
        if best is not None and has_memory:
            best = _search_orders(self.own, self.path, self.window, best, point, feasible, self.searched)
        self.ecco_pruned = None
        if best is not None:
            self.ecco_pruned = _search_ecco(self.runner, self.window, best, point, feasible, self.searched)
        return best

    def _largest_step(self, steps, algorithm, hold, sub, exact):
        """Index of the largest step meeting the tolerance (from the design step 0.05 s: doubling
        while it holds, halving while it does not), MARGIN below the smallest larger step that
        diverged (run here up to MARGIN times the step found); None when none meets it."""
        feasible = self.feasible
        at = lambda k: self.point(Setting(steps[k], algorithm, hold, sub(steps[k]), exact))
        i = min(range(len(steps)), key=lambda k: abs(steps[k] - 0.05)) if steps else None
        found = None
        if i is not None and feasible(at(i)):   # double while the tolerance holds
            found = i
            while found + 1 < len(steps) and feasible(at(found + 1)):
                found += 1
        elif i is not None:                     # halve until it holds
            found = next((k for k in range(i - 1, -1, -1) if feasible(at(k))), None)
        if found is None:
            return None
        # the stability margin: the steps up to MARGIN x the one found must not diverge
        limit = next((steps[k] for k in range(found + 1, len(steps))
                      if steps[k] <= MARGIN * steps[found] + 1e-12 and at(k).error >= DIVERGED), None)
        if limit is None:
            return found
        keep = next((k for k in range(found, -1, -1) if steps[k] <= limit / MARGIN + 1e-12 and feasible(at(k))), None)
        self.margins.append(f"{algorithm}/{hold}: step {limit:g} s diverged over the window, so "
                            + (f"{steps[found]:g} s (meets the tolerance) gave way to {steps[keep]:g} s"
                               if keep is not None else f"no step within 1/{MARGIN:g} of it meets the tolerance")
                            + f" (stability margin {MARGIN:g}x)")
        return keep

    def presets(self):
        """The presets and the scene's own settings, as points of their own."""
        from ..scene import PRESETS
        for name in ("screening", "design", "reference"):
            pr = PRESETS[name]
            if self.fits(pr["step"]) and pr["step"] > 0:
                self.point(Setting(pr["step"], pr["algorithm"], pr["load_hold"], pr["substep"],
                                   name if self.has_memory else None), name)
        mine = self.own.run
        if mine["algorithm"] != "ecco" and self.fits(mine["step"]):
            memory = _memory_preset(self.own) if self.has_memory else None
            if memory is not None or not self.has_memory:
                self.point(Setting(mine["step"], mine["algorithm"], mine["load_hold"], mine["substep"], memory),
                           "scene")


def _search_orders(scene, path, window, best, point, feasible, searched):
    """Per coupling that does not set its own method, on the best point: a state-space order of
    ``ORDERS``, lowest first, with fewer states than the coupling's evaluator there (its
    tolerance fit's largest element order; any order in place of the full convolution); the
    first that meets the tolerance is kept.  Returns the best point, with the orders kept."""
    from ..scene import load_scene
    tuned = [i for i, c in enumerate(scene.couplings) if not c.set and c.kernels]
    fitted = load_scene(path, {"run.preset": best.setting.memory, "run.stop": window}) if tuned else None
    for i in tuned:
        c = fitted.couplings[i]
        if c.method == "state_space":
            largest = max(f.order for f in c.model().fits.values())
            ladder = [n for n in ORDERS if n < largest]
            why = f"tol {c.tolerance:g} fit, largest element order {largest}"
        else:
            ladder, why = list(ORDERS), "full convolution"
        tried = []
        for n in ladder:
            p = point(replace(best.setting, orders=best.setting.orders + ((i, n),)))
            tried.append(f"{n}: {100 * p.error:.3g} %" + ("" if feasible(p) else " (fails)"))
            if feasible(p):
                best = p
                break
        searched.append(f"order of couplings[{i}] ({c.name}; {why}): "
                        + ("; ".join(tried) if tried else "no smaller order to try"))
    return best


def _search_ecco(runner, window, best, point, feasible, searched):
    """ECCO on the best point's hold, substep and memory, where it can pay: abs_tolerance of
    ``ECCO_TOLERANCES``, loosest first, until one meets the tolerance or takes more steps
    than the best point.  Returns why it was not tried, or None."""
    from ..cosim.bonds import power_bonds
    if not power_bonds(runner.manifest):
        return "ECCO: not applicable (no power bonds: a load FMU's force to a dynamics FMU and its velocity back)"
    # ECCO's largest step: the largest searched one up to 4x the best point's (a joint's default
    # spring follows the largest step: one for 1 s steps is another joint than the reference's)
    top = max([s for s in STEPS if s <= min(window / 2, 4 * best.setting.step)] or [best.setting.step])
    floor = Setting(top, "jacobi", best.setting.load_hold, top, None).proxy(window, runner.instances)
    if floor >= best.proxy:
        return (f"ECCO: pruned, it cannot pay (its fewest steps, all {top:g} s with one Runge–Kutta step each, "
                f"cost {floor:.0f} step units, the best point {best.proxy:.0f}: {best.setting.label()})")
    try:
        import libcosimpy  # noqa: F401  (the test extra)
    except ImportError:
        return "ECCO: needs libcosimpy (pip install libcosimpy), not installed"
    base = replace(best.setting, step=top, algorithm="ecco", ecco=ECCO_TOLERANCES[0])
    runner.calibration = replace(best.setting, algorithm="jacobi")
    try:
        runner.calibrate(base, runner.calibration)
    except RuntimeError as exc:   # libcosim could not run the FMUs built for it
        return f"ECCO: not run, libcosim failed on the FMUs built for it ({exc})"
    tried = []
    for tol in ECCO_TOLERANCES:
        p = point(replace(base, ecco=tol))
        tried.append(f"abs_tolerance {tol:g} J: {100 * p.error:.3g} %{'' if feasible(p) else ' (fails)'}, "
                     f"{p.proxy:.0f} step units")
        if feasible(p):
            break
        if p.proxy >= best.proxy and tol != ECCO_TOLERANCES[-1]:
            tried.append("tighter tolerances take more steps than the best point: stopped")
            break
    searched.append(f"ECCO (libcosim, steps {ECCO_MIN:g}–{top:g} s; best fixed point {best.proxy:.0f} step units; "
                    f"its cost × {runner.ratios[-1]:.2g}, this process's over libcosim's seconds for "
                    f"{runner.calibration.label()}): " + "; ".join(tried))
    return None


def _divides(small, big):
    return abs(big / small - round(big / small)) < 1e-9


def _memory_preset(scene):
    """The preset whose memory evaluator the scene's couplings use, or None."""
    from ..scene import MEMORY_DEFAULTS, PRESETS
    used = {(c.method, c.tolerance if c.method == "state_space" else None, c.order, c.memory_length)
            for c in scene.couplings}
    for name in MEMORY:
        m = PRESETS[name]["memory"]
        if used == {(m["method"], m["tolerance"] if m["method"] == "state_space" else None, None, m["memory_length"])}:
            return name
    return None


