"""ECCO (libcosim's adaptive step) beside fixed-step Jacobi and Gauss–Seidel: error, number
of steps, wall time and the power-bond energy residual (``cosim.bonds``), on the two-body
SIMO fleet (error against its monolithic Cummins solution) and on every scene of models/
(error against Gauss–Seidel at a fine step on the same FMUs).

Every run of one case uses the same FMUs, built with the scene asking for ECCO (so a joint's
default spring is the one for ECCO's largest step) and the scene's load hold.  Fixed steps
run in our fmpy master (Jacobi, Gauss–Seidel) and in libcosim's fixed-step master (Jacobi:
the same numbers as ours, its own cost per step, so ECCO's cost compares engine for
engine).  The error is the worst normalised RMS (``fleet.nrms``) over the translations and
rotations that move, a run interpolated linearly to the reference's time points.
"""
import time
from pathlib import Path

import numpy as np

from ..cosim import bonds, libcosim, master
from ..fmi.build import build_scene
from ..scene import load_scene
from .fleet import Fleet, nrms

QUIET = {"log": lambda *_: None}
ENGINES = {"jacobi": "fmpy", "gauss-seidel": "fmpy", "jacobi (libcosim)": "libcosim", "ecco": "libcosim"}


def motion(result, bodies):
    """(n_times, 6·bodies) position and attitude change of each body since t = 0 (the
    layout of ``Fleet.monolithic``)."""
    out = np.hstack([np.hstack([result.motion(b, "position", 3), result.motion(b, "attitude", 3)])
                     for b in bodies])
    return out - out[0]


def motion_error(result, ref_time, ref, bodies):
    """Worst normalised RMS over the columns of ``ref`` (``motion`` layout, at ``ref_time``)
    that move, of ``result`` interpolated linearly to ``ref_time``."""
    got = np.column_stack([np.interp(ref_time, result.time, x) for x in motion(result, bodies).T])
    moving = np.ptp(ref, axis=0) > 1e-9 * max(1.0, np.abs(ref).max())
    return float(nrms(got[:, moving], ref[:, moving]).max())


def cases(folder, stop, fine, scenes=None):
    """(label, built folder, bodies, reference) per case; ``reference(result)`` gives the
    reference's (time, motion).  ``scenes``: the file names (stems) of models/ to take
    (default: all)."""
    folder = Path(folder)
    fleet = Fleet(2)
    built = build_scene(load_scene(fleet.scene(folder / "two_body", run=f'preset = "adaptive"\nstop = {stop}')),
                        folder / "two_body" / "fmus", **QUIET)
    yield "two_body", built, fleet.names, lambda r: (r.time, fleet.monolithic(r.time))
    for path in sorted(Path("models").glob("*.toml")):
        if scenes is not None and path.stem not in scenes:
            continue
        scene = load_scene(path, {"run.algorithm": "ecco", "run.stop": stop})
        built = build_scene(scene, folder / "scenes", **QUIET)
        ref = master.run(built, algorithm="gauss-seidel", step=fine, progress=False)
        bodies = list(ref.dynamics)
        yield scene.name, built, bodies, lambda r, ref=ref, bodies=bodies: (ref.time, motion(ref, bodies))


def measure(folder, stop=60.0, steps=(0.1, 0.05, 0.02), tolerances=(10.0, 1.0, 0.1), fine=0.005, scenes=None):
    """Rows {case, algorithm, engine, knob, error, steps, min_step, max_step, wall_s,
    residual_J, residual_rel, net_J} and {case: the ECCO Result at the middle tolerance}.
    ``tolerances``: ECCO's abs_tolerance [J] (the knob that moves its steps on our scenes;
    rel_tolerance from 1e-4 to 1e-2 changed no run's step count by more than 0.5 %)."""
    rows, traces = [], {}
    for label, built, bodies, reference in cases(folder, stop, fine, scenes):
        runs = [(alg, f"step {h:g} s", {"algorithm": alg.split()[0], "step": h})
                for alg in ("jacobi", "gauss-seidel", "jacobi (libcosim)") for h in steps]
        runs += [("ecco", f"abs_tolerance {tol:g} J", {"algorithm": "ecco", "ecco": {"abs_tolerance": tol}})
                 for tol in tolerances]
        for alg, knob, kw in runs:
            t0 = time.perf_counter()
            result = (libcosim.run(built, **kw) if ENGINES[alg] == "libcosim"
                      else master.run(built, progress=False, **kw))
            wall = time.perf_counter() - t0
            t_ref, ref = reference(result)
            res, h = bonds.residual(result), np.diff(result.time)
            rows.append({"case": label, "algorithm": alg, "engine": ENGINES[alg], "knob": knob,
                         "error": motion_error(result, t_ref, ref, bodies), "steps": len(h),
                         "min_step": float(h.min()), "max_step": float(h.max()), "wall_s": wall,
                         "residual_J": res.total, "residual_rel": res.relative, "net_J": res.net})
            if alg == "ecco" and kw["ecco"]["abs_tolerance"] == tolerances[len(tolerances) // 2]:
                traces[label] = result
    return rows, traces


def sweep_rows(folder, stop, tolerances, method="convolution"):
    """ECCO points for the step sweep (``cosim_cost.step_sweep``): its two-body scene (same
    stop, substep and memory) asking for ECCO with linear hold and a first step of 0.01 s
    (ECCO never repeats a step: a large first one over the release costs accuracy for the
    whole run), one libcosim run per
    abs_tolerance [J], rows in the sweep's layout (``step``: ECCO's mean step) plus ``tolerance``."""
    from .cosim_cost import MOVING
    fleet, folder = Fleet(2), Path(folder) / "ecco"
    scene = fleet.scene(folder, run=f'stop = {stop}\nsubstep = 0.01\nalgorithm = "ecco"\nload_hold = "linear"\n'
                                    'step = 0.01', coupling=f'method = "{method}"')   # a small first step
    built = build_scene(load_scene(scene), folder / "fmus", **QUIET)
    rows = []
    for tol in tolerances:
        t0 = time.perf_counter()
        result = libcosim.run(built, ecco={"abs_tolerance": tol})
        wall = time.perf_counter() - t0
        err = nrms(fleet.displacements(result)[:, MOVING], fleet.monolithic(result.time)[:, MOVING]).max()
        rows.append({"algorithm": "ecco", "load_hold": "linear", "step": float(np.mean(np.diff(result.time))),
                     "error": float(err), "wall_s": wall, "tolerance": tol})
    return rows
