"""The load hold against light damping: measured growth of free oscillations next to
``physics.hold`` (Δζ = −ω·h/4 constant hold, −(ω·h)³/6 linear hold), and whether the scenes
of models/ and the wave test scenes stay bounded with each hold and step.

1. Free pitch decay of the cylinder of tests/data/bem/wave_cylinder.nc (BEM hydrostatics as a
   load FMU, initial pitch rate 0.03 rad/s), with and without the radiation memory (its
   coupling): the growth rate σ of the peaks (log-linear fit) at each hold and step, as a
   damping ratio ζ = −σ/ω, against ζ_rad (the linear hold at 0.01 s with memory) + Δζ.
2. Every scene of models/ and the cylinder in a JONSWAP sea (Hs 2 m, Tp 9 s, 30°, no ramp)
   with each hold at its step and twice it: bounded (largest |attitude| under
   90°, finite) and the largest roll/pitch, over ``stop`` seconds.
"""
from __future__ import annotations

import math
import warnings
from pathlib import Path

import numpy as np

from ..physics.hold import damping_change

DATA = Path(__file__).resolve().parents[3] / "tests" / "data" / "bem"
MODELS = Path(__file__).resolve().parents[3] / "models"


def cylinder_scene(folder, hold, step, stop, memory=True, waves=None, velocity=0.03, name="hold_cylinder"):
    """A scene file of the wave_cylinder.nc cylinder (mass = displacement, centre of mass 3 m
    below the waterline, radii of gyration 2, 2, 1.5 m), BEM hydrostatics as its restoring,
    the radiation memory when ``memory``, ``waves`` a [waves] table text (else a free decay
    from a pitch rate ``velocity`` [rad/s]); returns its path."""
    import shutil
    import xarray as xr
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    bem = folder / "wave_cylinder.nc"
    if not bem.is_file():
        shutil.copy(DATA / "wave_cylinder.nc", bem)
    m = float(xr.load_dataset(bem)["inertia_matrix"].values[0, 0])
    text = (f'[scene]\nname = "{name}"\n[run]\nstep = {step!r}\nstop = {stop!r}\nsubstep = {min(step, 0.05)!r}\n'
            f'load_hold = "{hold}"\n' + (waves or "")
            + f"[bodies.cyl]\nposition = [0.0, 0.0, 0.0]\nmass = {m!r}\n"
              f"inertia = [{4 * m!r}, {4 * m!r}, {2.25 * m!r}]\ncog = [0.0, 0.0, -3.0]\n"
            + ("" if waves else f"velocity = [0.0, 0.0, 0.0, 0.0, {velocity!r}, 0.0]\n")
            + '[[bodies.cyl.effects]]\ntype = "bem_hydrostatics"\nbem = "wave_cylinder.nc"\nbody = "cyl"\n'
            + ('[[bodies.cyl.effects]]\ntype = "wave_excitation"\nbem = "wave_cylinder.nc"\nbody = "cyl"\n'
               if waves else "")
            + ('[[couplings]]\nbem = "wave_cylinder.nc"\nbodies = { cyl = "cyl" }\n' if memory else ""))
    path = folder / f"{name}.toml"
    path.write_text(text)
    return path


def growth(time_, x):
    """(σ [1/s], ω [rad/s]) of a free oscillation from its positive peaks (log-linear fit of
    their heights, mean spacing of them)."""
    k = np.flatnonzero((x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]) & (x[1:-1] > 0)) + 1
    if len(k) < 3:
        return math.nan, math.nan
    sigma = float(np.polyfit(time_[k], np.log(x[k]), 1)[0])
    return sigma, 2 * math.pi / float(np.mean(np.diff(time_[k])))


def _run(path, overrides=None, record=None):
    from ..cosim import inprocess
    from ..cosim.master import run
    from ..errors import InputWarning
    from ..scene import load_scene
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        scene = load_scene(path, overrides or {})
    return run(inprocess.system(scene), progress=False, record=record)


def decay(out, steps=(0.05, 0.1, 0.2), stop=30.0):
    """Rows {memory, hold, step, omega, zeta, zeta_rad, predicted, growth_per_s}."""
    rows = []
    for memory in (False, True):
        path = cylinder_scene(Path(out) / "hold", "linear", 0.01, stop, memory)
        name = "cyl_dynamics.attitude[2]"
        ref = _run(path, record=[name])
        s0, w0 = growth(ref.time, ref.values[:, 0])
        zeta_rad = -s0 / w0 - float(damping_change(w0, 0.01, "linear"))   # the reference's own hold removed
        for hold in ("constant", "linear"):
            for step in steps:
                try:
                    r = _run(path, {"run.load_hold": hold, "run.step": step, "run.substep": min(step, 0.05)},
                             [name])
                    sigma, w = growth(r.time, r.values[:, 0])
                except RuntimeError:
                    sigma, w = math.inf, w0
                rows.append({"memory": memory, "hold": hold, "step": step, "omega": w,
                             "zeta": -sigma / w, "zeta_rad": zeta_rad,
                             "predicted": zeta_rad + float(damping_change(w, step, hold)), "growth_per_s": sigma})
    return rows


SEA = '[waves]\nspectrum = "jonswap"\nhs = 2.0\ntp = 9.0\ndirection = 30.0\nramp = 0.0\n'   # no ramp: the hold alone


def scenes(out, stop=300.0, factors=(1, 2)):
    """Rows {scene, hold, step, bounded, max_angle_deg, error}: every scene of models/ and the
    cylinder in a JONSWAP sea, each hold at the scene's step × ``factors``."""
    from ..scene import load_scene
    paths = sorted(MODELS.glob("*.toml")) + [cylinder_scene(Path(out) / "hold", "linear", 0.1, stop,
                                                            waves=SEA, name="hold_sea")]
    rows = []
    for path in paths:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            base = load_scene(path).run["step"]
        for hold in ("constant", "linear"):
            for f in factors:
                step = base * f
                over = {"run.load_hold": hold, "run.step": step, "run.stop": stop}
                try:
                    r = _run(path, over)
                    att = [j for j, c in enumerate(r.columns) if ".attitude[1]" in c or ".attitude[2]" in c]
                    worst = float(np.degrees(np.abs(r.values[:, att]).max())) if att else 0.0
                    rows.append({"scene": path.stem, "hold": hold, "step": step, "bounded": worst < 90.0,
                                 "max_angle_deg": worst, "error": ""})
                except RuntimeError as exc:
                    rows.append({"scene": path.stem, "hold": hold, "step": step, "bounded": False,
                                 "max_angle_deg": math.nan, "error": str(exc)[:120]})
    return rows


def summary(decay_rows, scene_rows):
    lines = []
    for r in decay_rows:
        lines.append(f"cylinder pitch decay{' with memory' if r['memory'] else ', hydrostatics only'}, "
                     f"{r['hold']} hold, step {r['step']:g} s: ζ = {100 * r['zeta']:+.3f} % "
                     f"(predicted {100 * r['predicted']:+.3f} %: radiation {100 * r['zeta_rad']:.3f} % "
                     f"+ hold {100 * (r['predicted'] - r['zeta_rad']):+.3f} %), ω = {r['omega']:.3f} rad/s")
    for r in scene_rows:
        lines.append(f"{r['scene']}, {r['hold']} hold, step {r['step']:g} s: "
                     + (f"bounded, largest roll/pitch {r['max_angle_deg']:.2f}°" if r["bounded"]
                        else "NOT bounded " + (r["error"] or f"({r['max_angle_deg']:.0f}°)")))
    return lines
