"""Runs of one scene's settings in this process (ECCO: in libcosim), and their error."""
from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from .settings import ECCO_MIN, STEPS, Setting


class _Runner:
    """Runs settings of one scene in this process over the window (ECCO: in libcosim, on FMUs
    built for it once)."""

    def __init__(self, path, window, outputs, log):
        self.path, self.window, self.log = Path(path), window, log
        self.outputs, self.manifest, self.instances = outputs, None, 0
        self.builds, self.ratios, self._tmp, self.joints = {}, [], None, True

    def run(self, setting: Setting):
        """(times, values of the columns, seconds of stepping)."""
        if setting.algorithm == "ecco":
            return self.run_ecco(setting)
        from ..cosim import inprocess
        from ..cosim.master import run
        from ..scene import load_scene
        scene = load_scene(self.path, setting.overrides(self.window))
        system = inprocess.system(scene)
        if self.manifest is None:
            from ..cosim.stream import select
            self.manifest, self.instances = system.manifest, len(system.instances)
            valid = [f"{n}.{v}" for n, inst in system.instances.items() for v in inst.outputs()]
            self.columns = select(system.manifest, self.outputs or list(system.manifest["dynamics"]), valid,
                                  self.path, "outputs")
        marks = {}
        n = int(round(self.window / setting.step))

        def mark(k):
            if k in (1, n):
                marks[k] = time.perf_counter()
        try:
            # every communication point compared, whatever the scene's [run] interval
            result = run(system, stop=self.window, step=setting.step, algorithm=setting.algorithm,
                         record=self.columns, progress=False, on_step=mark, interval=setting.step)
        except RuntimeError as exc:   # the run failed (diverged): a point that meets nothing
            return None, str(exc), float("nan")
        finally:
            system.free()
        seconds = marks[n] - marks[1] if n > 1 else float("nan")
        return result.time, result.values, seconds * n / max(n - 1, 1)

    def built(self, setting: Setting):
        """The FMUs of an ECCO setting: one build per setting but its abs_tolerance (a run knob)
        and, in a scene without joints, its largest step (a run knob too; a joint's default
        spring follows it)."""
        import tempfile
        from ..fmi.build import build_scene
        from ..scene import load_scene
        key = replace(setting, ecco=1.0, step=setting.step if self.joints else STEPS[-1])
        if key not in self.builds:
            if self._tmp is None:
                self._tmp = tempfile.TemporaryDirectory(prefix="hydrofmu-tune-")
            scene = load_scene(self.path, key.overrides(self.window))
            scene.run["interval"] = None   # every point ECCO takes is compared
            self.builds[key] = build_scene(scene, Path(self._tmp.name) / str(len(self.builds)), log=lambda *_: None)
        return self.builds[key]

    def run_ecco(self, setting: Setting):
        """An ECCO run in libcosim: (its time points up to the window, values, seconds of
        stepping converted to this process's by the latest Jacobi calibration ``ratios``)."""
        from ..cosim import libcosim
        clock = {}
        try:
            r = libcosim.run(self.built(setting), stop=self.window, step=setting.first_step(), algorithm="ecco",
                             record=self.columns, timing=clock,
                             ecco={"abs_tolerance": setting.ecco, "min_step": ECCO_MIN, "max_step": setting.step})
        except RuntimeError as exc:
            return None, str(exc), float("nan")
        keep = r.time <= self.window + 1e-9
        return r.time[keep], r.values[keep, :len(self.columns)], clock["stepping"] * self.ratios[-1]

    def calibrate(self, ecco: Setting, jacobi: Setting):
        """A fixed-step Jacobi run of ``jacobi`` (ECCO's hold, substep and memory) in libcosim on
        the build of ``ecco`` and in this process, timed back to back: appends the ratio of
        their seconds of stepping (this process / libcosim)."""
        from ..cosim import libcosim
        clock = {}
        libcosim.run(self.built(ecco), stop=self.window, step=jacobi.step, algorithm="jacobi", record=self.columns,
                     timing=clock)
        self.ratios.append(self.run(jacobi)[2] / clock["stepping"])


def _error(time_, values, ref_time, ref_values, scale):
    """Largest normalised RMS difference at ``time_`` (the reference linear between its points:
    exact at a fixed-step run's points, which lie on its grid)."""
    ref = np.column_stack([np.interp(time_, ref_time, col) for col in ref_values.T])
    return float(np.max(np.sqrt(np.mean((values - ref) ** 2, axis=0)) / scale))
