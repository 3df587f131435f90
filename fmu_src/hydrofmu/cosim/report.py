"""Plots of a run: motions of every body and the loads of every load FMU."""
from pathlib import Path


def plot(result, manifest, path):
    """Write a PNG: one row per body (motions: surge/sway/heave and roll/pitch/yaw; loads:
    each effect's force and yaw moment)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    bodies = sorted(manifest["dynamics"])
    fig, axes = plt.subplots(len(bodies), 3, figsize=(15, 3.6 * len(bodies)), squeeze=False)
    t = result.time
    for row, body in zip(axes, bodies):
        load = body
        pos = result.motion(body, "position", 3)
        att = np.degrees(result.motion(body, "attitude", 3))
        for i, label in enumerate(("x", "y", "z")):
            row[0].plot(t, pos[:, i], label=label)
        row[0].set(title=f"{body}: position [m]", xlabel="time [s]")
        for i, label in enumerate(("roll", "pitch", "yaw")):
            row[1].plot(t, att[:, i], label=label)
        row[1].set(title=f"{body}: attitude [deg]", xlabel="time [s]")
        groups = sorted({c.split(".")[1] for c in result.columns
                         if c.startswith(f"{load}.") and c.endswith("force[1]") and c.count(".") == 2})
        for g in ["force"] + groups:
            prefix = "force" if g == "force" else f"{g}.force"
            try:
                f = result.vector(load, prefix, 6)
            except ValueError:
                continue
            lw = 2.0 if g == "force" else 1.0
            row[2].plot(t, f[:, 0] / 1e3, lw=lw, label=f"{g} Fx")
            row[2].plot(t, f[:, 1] / 1e3, lw=lw, ls="--", label=f"{g} Fy")
        row[2].set(title=f"{body}: loads [kN] (global axes)", xlabel="time [s]")
        for ax in row:
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
    fig.suptitle(f"{manifest['scene']} ({result.algorithm}, step {result.step:g} s)")
    fig.tight_layout()
    fig.savefig(Path(path), dpi=110)
    plt.close(fig)
