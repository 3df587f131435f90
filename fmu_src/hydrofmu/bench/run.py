"""``hydrofmu bench``: every benchmark in one run, CSV and PNG per part, a summary table.

Parts (each also callable alone, see ``PARTS``):

- overhead: load FMU through fmpy against its kernels in-process (``overhead``)
- memory: evaluator cost against force error at 2000 lags (``memory_cost.tradeoff``)
- sweep: communication step × algorithm × load hold on the two-body scene (``cosim_cost``)
- growth: cost against kernel length, number of coupled bodies, simulated time
- stability: added-mass stability map, explicit against export (``stability``)

``quick`` shrinks every part (for a smoke run); the figures in the README come from a full run.
"""
import csv
import time
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from . import cosim_cost, memory_cost, overhead, stability  # noqa: E402


def write_csv(path, rows):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        for r in rows:
            w.writerow({k: (repr(float(v)) if isinstance(v, float) else v) for k, v in r.items()})
    return path


def part_overhead(out, quick):
    rows = []
    for method in ("state_space", "convolution"):
        r = overhead.measure(out / f"overhead_{method}", method, steps=200 if quick else 1000,
                             rounds=3 if quick else 5)
        rows.append({"coupling_method": method, "fmu_us": 1e6 * r["fmu"], "in_process_us": 1e6 * r["in_process"],
                     "ratio": r["ratio"]})
    write_csv(out / "overhead.csv", rows)
    return [f"FMU overhead ({r['coupling_method']} memory): {r['ratio']:.2f}× "
            f"({r['fmu_us']:.0f} µs vs {r['in_process_us']:.0f} µs per step)" for r in rows]


def part_memory(out, quick):
    size = dict(lags=400 if quick else 2000, duration=60.0 if quick else 300.0,
                calls=100 if quick else 400, rounds=3 if quick else 5)
    rows = memory_cost.tradeoff(**size)
    # the same at half the kernel's sample spacing (co-simulation steps are often finer)
    half = memory_cost.tradeoff(**size, lengths=(), tolerances=(0.01,), orders=(), dt=0.025)
    write_csv(out / "memory_tradeoff.csv", rows + half)
    fig, ax = plt.subplots(figsize=(7, 5))
    for r in rows:
        marker = "s" if r["evaluator"].startswith("convolution") else "o"
        ax.loglog(r["cost_us"], max(r["error"], 1e-12), marker)
        ax.annotate(r["evaluator"], (r["cost_us"], max(r["error"], 1e-12)), fontsize=7)
    ax.set_xlabel("cost per step [µs]")
    ax.set_ylabel("force error (normalised RMS, worst component)")
    ax.set_title("Memory evaluators on a full 6×6 interaction kernel")
    ax.grid(True, which="both", alpha=0.3)
    fig.tight_layout()
    fig.savefig(out / "memory_tradeoff.png", dpi=120)
    plt.close(fig)
    good = [r for r in rows if r["evaluator"].startswith("state_space") and r["error"] <= 0.01]
    best = max(good, key=lambda r: r["cheaper"]) if good else None
    lines = [f"state-space vs full convolution at dt = TIMDEL: {best['cheaper']:.1f}× cheaper at "
             f"{100 * best['error']:.2f} % error ({best['knob']})" if best else "no state-space fit within 1 %"]
    return lines + [f"at dt = TIMDEL/2: {half[-1]['cheaper']:.1f}× cheaper at {100 * half[-1]['error']:.2f} % error"]


def part_sweep(out, quick):
    steps = (0.2, 0.1, 0.05) if quick else (0.2, 0.1, 0.05, 0.02, 0.01)
    rows = cosim_cost.step_sweep(out / "sweep", steps=steps, stop=20.0 if quick else 60.0)
    write_csv(out / "step_sweep.csv", rows)
    fig, ax = plt.subplots(figsize=(7, 5))
    for alg in ("jacobi", "gauss-seidel"):
        for hold in ("constant", "linear"):
            rs = [r for r in rows if r["algorithm"] == alg and r["load_hold"] == hold]
            ax.loglog([r["wall_s"] for r in rs], [r["error"] for r in rs], "o-" if alg != "jacobi" else "s--",
                      label=f"{alg}, {hold} hold")
            for r in rs:
                ax.annotate(f"{r['step']:g}", (r["wall_s"], r["error"]), fontsize=7)
    front = sorted((r for r in rows if r["pareto"]), key=lambda r: r["wall_s"])
    ax.loglog([r["wall_s"] for r in front], [r["error"] for r in front], "k:", lw=2, label="Pareto front")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("error vs monolithic (normalised RMS)")
    ax.set_title("Two bodies, SIMO interaction: communication step sweep (labels: step [s])")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out / "step_sweep.png", dpi=120)
    plt.close(fig)
    return [f"Pareto: {r['algorithm']}, {r['load_hold']} hold, step {r['step']:g} s: "
            f"{100 * r['error']:.3g} % in {r['wall_s']:.1f} s" for r in front]


def part_growth(out, quick):
    lags = memory_cost.growth((100, 1000) if quick else (100, 300, 1000, 3000, 10000),
                              calls=100 if quick else 300, rounds=3 if quick else 5)
    bodies = cosim_cost.body_growth(out / "bodies", (2, 4) if quick else (2, 4, 8), stop=5.0 if quick else 20.0)
    flat = cosim_cost.flatness(out / "flat", stop=100.0 if quick else 1000.0, chunks=5 if quick else 10)
    write_csv(out / "growth_lags.csv", lags)
    write_csv(out / "growth_bodies.csv", bodies)
    write_csv(out / "growth_time.csv", flat)
    fig, ax = plt.subplots(1, 3, figsize=(14, 4.5))
    ax[0].loglog([r["lags"] for r in lags], [r["convolution_us"] for r in lags], "s-", label="convolution")
    ax[0].loglog([r["lags"] for r in lags], [r["state_space_us"] for r in lags], "o-", label="state-space (1 %)")
    ax[0].set(xlabel="kernel length [lags]", ylabel="cost per step [µs]", title="6×6 memory")
    ax[1].plot([r["bodies"] for r in bodies], [r["ms_per_step"] for r in bodies], "o-")
    ax[1].set(xlabel="coupled bodies (all pairs)", ylabel="co-simulation cost per step [ms]",
              title="design preset, fmpy")
    ax[2].plot([0.5 * (r["t_start"] + r["t_end"]) for r in flat], [r["us_per_step"] for r in flat], "o-")
    ax[2].set(xlabel="simulated time [s]", ylabel="cost per step [µs]", title="two bodies, convolution",
              ylim=(0, 1.3 * max(r["us_per_step"] for r in flat)))
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend()
    fig.tight_layout()
    fig.savefig(out / "growth.png", dpi=120)
    plt.close(fig)
    late = [r["us_per_step"] for r in flat if r["t_start"] >= 60.0]
    return [f"kernel {lags[0]['lags']} → {lags[-1]['lags']} lags: convolution ×{lags[-1]['convolution_us'] / lags[0]['convolution_us']:.1f}, "
            f"state-space ×{lags[-1]['state_space_us'] / lags[0]['state_space_us']:.2f}",
            f"bodies {bodies[0]['bodies']} → {bodies[-1]['bodies']}: cost per step ×{bodies[-1]['ms_per_step'] / bodies[0]['ms_per_step']:.1f}",
            f"cost per step after the memory fills: last/first = {late[-1] / late[0]:.2f}" if len(late) > 1 else ""]


def part_stability(out, quick):
    csv_path, png = stability.run(out)
    return [f"added-mass map: {csv_path.name}, {png.name}"]


PARTS = {"overhead": part_overhead, "memory": part_memory, "sweep": part_sweep, "growth": part_growth,
         "stability": part_stability}


def main(out, parts=None, quick=False, log=print):
    """Run the benchmark ``parts`` (default all) into folder ``out``; returns summary lines."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lines = []
    for name in parts or PARTS:
        t0 = time.perf_counter()
        log(f"bench {name} …")
        got = [x for x in PARTS[name](out, quick) if x]
        for x in got:
            log(f"  {x}")
        lines += [f"{name}: {x}" for x in got]
        log(f"  ({time.perf_counter() - t0:.0f} s)")
    (out / "summary.txt").write_text("\n".join(lines) + "\n")
    return lines
