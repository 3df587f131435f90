"""Sweep the communication step (and the master algorithm) and plot accuracy against cost.

    python examples/step_sweep.py [SCENE] [--steps 0.4 0.2 0.1 0.05] [--stop T] [--out DIR]

Every run is compared with a reference run at a quarter of the smallest step (Gauss–
Seidel): error = RMS of the bodies' position difference at the coarsest step's times,
divided by the RMS of the reference's motion from its initial pose.  Cost = wall time.
Writes step_sweep.csv and step_sweep.png into DIR.  Wall times include loading the FMUs
(about a second) and are noisy on a busy machine.  (A scene with joints uses springs
sized for its own step at build time: sweeping the step of such a scene needs a build
per step.)
"""
import argparse
import csv
import time
from pathlib import Path

import numpy as np

import hydrofmu

MODELS = Path(__file__).resolve().parents[1] / "models"


def positions(result, bodies, every):
    """(n, 3·bodies) positions at every ``every``-th communication point."""
    return np.hstack([result.motion(b, "position", 3)[::every] for b in bodies])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", default=MODELS / "moored_barge.toml", type=Path)
    parser.add_argument("--steps", type=float, nargs="+", default=[0.4, 0.2, 0.1, 0.05], help="steps [s]")
    parser.add_argument("--stop", type=float, default=120.0, help="end time [s]")
    parser.add_argument("--out", type=Path, default=Path("build") / "examples", help="output folder")
    args = parser.parse_args(argv)

    scene = hydrofmu.load_scene(args.scene)
    folder = hydrofmu.build(scene, args.out, log=lambda line: None)
    bodies = sorted(scene.bodies)
    coarse = max(args.steps)
    ref_step = min(args.steps) / 4
    reference = hydrofmu.run(folder, stop=args.stop, step=ref_step, algorithm="gauss-seidel")
    ref = positions(reference, bodies, round(coarse / ref_step))
    scale = np.sqrt(np.mean((ref - ref[0]) ** 2))

    rows = []
    for algorithm in ("jacobi", "gauss-seidel"):
        for step in sorted(args.steps, reverse=True):
            t0 = time.perf_counter()
            result = hydrofmu.run(folder, stop=args.stop, step=step, algorithm=algorithm)
            wall = time.perf_counter() - t0
            got = positions(result, bodies, round(coarse / step))
            error = np.sqrt(np.mean((got - ref) ** 2)) / scale
            rows.append({"algorithm": algorithm, "step_s": step, "wall_s": wall, "error": error})
            print(f"{algorithm:12s} step {step:g} s: error {100 * error:.3g} %, {wall:.2f} s wall")

    args.out.mkdir(parents=True, exist_ok=True)
    with open(args.out / "step_sweep.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from hydrofmu.cosim.report import plain_log_ticks
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for algorithm, marker in (("jacobi", "s"), ("gauss-seidel", "o")):
        mine = [r for r in rows if r["algorithm"] == algorithm]
        ax.loglog([r["wall_s"] for r in mine], [100 * r["error"] for r in mine], marker=marker, label=algorithm)
        for r in mine:   # labels beside the points, offset in screen units so they do not overlap them
            ax.annotate(f"{r['step_s']:g} s", (r["wall_s"], 100 * r["error"]), textcoords="offset points",
                        xytext=(6, -3 if algorithm == "jacobi" else 5), fontsize=8)
    ax.set(xlabel="wall time [s]", ylabel="position error vs reference [%]",
           title=f"{scene.name}: communication step (labels) against cost, {args.stop:g} s simulated")
    plain_log_ticks(ax)   # 0.2, 0.5, 1 rather than 2×10⁻¹
    ax.margins(x=0.15, y=0.1)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(args.out / "step_sweep.png", dpi=110)
    plt.close(fig)
    print(f"wrote {args.out / 'step_sweep.csv'} and {args.out / 'step_sweep.png'}")
    return rows


if __name__ == "__main__":
    main()
