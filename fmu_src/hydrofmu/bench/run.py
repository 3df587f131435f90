"""``hydrofmu bench``: every benchmark in one run, CSV and PNG per part, a summary table.

Parts (each also callable alone, see ``PARTS``):

- overhead: load FMU through fmpy against its kernels in-process (``overhead``)
- memory: evaluator cost against force error at 2000 lags (``memory_cost.tradeoff``)
- sweep: communication step × algorithm × load hold on the two-body scene (``cosim_cost``)
- growth: cost against kernel length and simulated time
- floor: startup and cost per step of every scene of models/ and of 2, 4, 8 coupled bodies,
  as multiples of the pythonfmu floor (``floor``), with the targets and a noise verdict
- native: FMUs stepped alone in a native C host against the same FMUs under fmpy, and the
  design scene in libcosim against our fmpy master: cost per step and startup, side by side
  (``native``)
- startup: load, instantiate and initialise (and free) every scene of models/ again in a
  running process, against the pythonfmu floor (``startup``)
- stability: added-mass stability map, explicit against export (``stability``)
- hold: the load hold against light damping: free decays against Δζ of ``physics.hold``,
  every scene of models/ and the cylinder in a sea with each hold and step (``hold``)
- bem: the BEM transform (A(ω), B(ω) → A∞, K(t)) against dofs and frequencies (``radiation_cost``)
- robust: time to report one bad number near the end of a 50 MB deck against reading it
  good; memory over fmi2Instantiate/fmi2FreeInstance cycles with and without the shim's
  instance pool (``robust``)
- batch: load-case batches on Dask, speed-up from 1 to 2 local workers and the dispatch
  overhead per case (``batch_cost``)
- drift: the full QTF at the peer's case (the semisubmersible, Chebyshev blocks against the
  direct sum, both flavours); the wave drift's cost per step per method (mean, newman, qtf
  with and without a cut-off) against the first-order kernel at 50, 200, 1000 components,
  and Newman's error against the full QTF (``drift_cost``)
- waves: the `waves` effect's cost per step against the pythonfmu floor for 50, 200 and
  1000 components, and per 100 components (``waves_cost``); the floating cylinder's and the
  pair's motions in regular waves next to their lightly damped resonances, long runs at
  several steps, against the frequency domain (``waves_motions``)
- kinematics: the shared wave phasors (the `waves` kernel per component per step, against cos/sin
  every step) and the incident-wave kinematics per point per step against the `waves` kernel, at
  50, 200, 1000 components, Python and compiled flavours (``kinematics_cost``)
- ecco: libcosim's adaptive ECCO beside fixed-step Jacobi and Gauss–Seidel on the two-body
  case and every scene of models/: error, steps, wall time, energy residual; the step ECCO
  took against the bonds' power (``ecco_cost``)
- longrun: peak memory and wall time of a 3-hour side_by_side run (216 000 steps), streamed to
  Parquet + CSV against held in memory, each in a fresh process (``longrun``)

``quick`` shrinks every part (for a smoke run); the figures in the README come from a full run.
"""
import csv
import time
from pathlib import Path

import matplotlib
import numpy as np

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.ticker import FuncFormatter  # noqa: E402

from . import compiled, cosim_cost, floor, memory_cost, native, overhead, radiation_cost, robust  # noqa: E402
from . import hold, stability, startup  # noqa: E402
from . import waves_cost  # noqa: E402
from .timing import over  # noqa: E402


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
        r = overhead.measure(out / f"overhead_{method}", method, lags=100 if quick else 400,
                             steps=100 if quick else 1000, rounds=3 if quick else 5)
        rows.append({"coupling_method": method, "fmu_us": 1e6 * r["fmu"], "in_process_us": 1e6 * r["in_process"],
                     "ratio": r["ratio"], "floor_us": 1e6 * r["floor"],
                     "ratio_above_floor": (r["fmu"] - r["floor"]) / r["in_process"],
                     "spread": r["spread"], "noisy": r["noisy"]})
    write_csv(out / "overhead.csv", rows)
    return [overhead_line(r) for r in rows]


def overhead_line(r):
    """One line per overhead row: the figure, or why there is none.  The FMU runs the same
    kernels plus the FMI calls, so it cannot be faster than them: a ratio below 1 (or below
    the floor) is noise, said as such."""
    head = f"FMU overhead ({r['coupling_method']} memory): "
    times = f"{r['fmu_us']:.0f} µs vs {r['in_process_us']:.0f} µs per step in-process"
    if r["noisy"]:
        return head + f"too noisy ({over(r['spread'], floor.NOISY)} between rounds), no figure ({times})"
    if r["ratio"] < 1.0:
        return head + f"below the noise: the FMU measured no slower than its kernels ({times}), no figure"
    above = (f"the FMU above it {r['ratio_above_floor']:.2f}× the kernels" if r["ratio_above_floor"] > 0 else
             "the FMU above it within the noise")
    return head + f"{r['ratio']:.2f}× ({times}; the pythonfmu floor under the same calls {r['floor_us']:.0f} µs, {above})"


def part_memory(out, quick):
    # quick: a 20 s kernel (400 lags; a shorter one is not the same problem: its fits miss 1 %)
    size = dict(lags=400 if quick else 2000, duration=20.0 if quick else 300.0,
                calls=50 if quick else 400, rounds=3 if quick else 5)
    knobs = dict(lengths=(10.0,), tolerances=(0.01,), orders=()) if quick else {}
    rows = memory_cost.tradeoff(**size, **knobs)
    # the same at half the kernel's sample spacing (co-simulation steps are often finer; not in quick)
    half = [] if quick else memory_cost.tradeoff(**size, lengths=(), tolerances=(0.01,), orders=(), dt=0.025)
    write_csv(out / "memory_tradeoff.csv", rows + half)
    plot_memory_tradeoff(rows, out / "memory_tradeoff.png")
    good = [r for r in rows if r["evaluator"].startswith("state_space") and r["error"] <= 0.01]
    best = max(good, key=lambda r: r["cheaper"]) if good else None
    lines = [f"state-space vs full convolution at dt = TIMDEL: {best['cheaper']:.1f}× cheaper at "
             f"{100 * best['error']:.2f} % error ({best['knob']})" if best else "no state-space fit within 1 %"]
    lines += [f"at dt = TIMDEL/2: {half[-1]['cheaper']:.1f}× cheaper at {100 * half[-1]['error']:.2f} % error"] if half else []
    for lags in (400,) if quick else (600, 2000):
        f = memory_cost.filling(lags, repeats=1 if quick else 3)
        lines.append(f"full convolution, {lags} lags, while its history fills: {f['filling_us']:.0f} µs per step, "
                     f"{f['ratio']:.2f}× its cost once full ({f['steady_us']:.0f} µs)")
    return lines


def plot_memory_tradeoff(rows, path):
    """Error against cost per evaluator family (convolution: squares, state space: circles),
    each point labelled by its knob, labels kept apart; exact evaluators (error 0) on a
    line of their own at the bottom."""
    from ..cosim.report import annotate_apart, plain_log_ticks
    errors = [r["error"] for r in rows if r["error"] > 0]
    floor = min(errors) / 10 if errors else 1e-6
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for family, marker, colour in (("convolution", "s", "C0"), ("state_space", "o", "C1")):
        mine = sorted((r for r in rows if r["evaluator"].startswith(family)), key=lambda r: r["cost_us"])
        ax.loglog([r["cost_us"] for r in mine], [r["error"] or floor for r in mine], marker, color=colour,
                  label={"convolution": "convolution (memory length)", "state_space": "state space (tolerance, order)"}[family])
    ax.axhline(floor, color="0.6", ls=":", lw=1)
    exact = ax.text(0.01, floor, " error 0 (the reference, or equal to it)", transform=ax.get_yaxis_transform(), ha="left", va="bottom",
                    fontsize=7, color="0.4")
    ax.set_xlabel("cost per step [µs]")
    ax.set_ylabel("force error (normalised RMS, worst component)")
    ax.set_title("Memory evaluators on a full 6×6 interaction kernel")
    ax.grid(True, which="both", alpha=0.3)
    legend = ax.legend(fontsize=8, loc="upper right")
    ax.margins(x=0.25, y=0.15)
    plain_log_ticks(ax)
    if errors:   # no tick between the exact line and the smallest error: the line is 0, not floor
        lo, hi = ax.get_ylim()
        keep = lambda ticks: [t for t in ticks if min(errors) / 2 <= t <= hi]
        ax.set_yticks(keep(ax.get_yticks()) + [floor])
        ax.set_yticks(keep(ax.get_yticks(minor=True)), minor=True)
        ax.set_ylim(lo, hi)
        ax.yaxis.set_major_formatter(FuncFormatter(lambda v, _: "0" if v == floor else f"{v:g}"))
    fig.tight_layout()
    annotate_apart(ax, [r["cost_us"] for r in rows], [r["error"] or floor for r in rows],
                   [r["evaluator"].replace("convolution ", "conv. ").replace("state_space ", "") for r in rows],
                   avoid=(exact, legend))
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def part_sweep(out, quick):
    from . import ecco_cost
    steps = (0.2, 0.1) if quick else (0.2, 0.1, 0.05, 0.02, 0.01)
    stop = 10.0 if quick else 60.0
    rows = cosim_cost.step_sweep(out / "sweep", steps=steps, stop=stop)
    # libcosim's ECCO on the same scene (adaptive step), one point per energy tolerance
    rows = cosim_cost.pareto([{**r, "tolerance": ""} for r in rows]
                             + ecco_cost.sweep_rows(out / "sweep", stop, (1.0,) if quick else (10.0, 1.0, 0.1)))
    write_csv(out / "step_sweep.csv", rows)
    fig, ax = plt.subplots(figsize=(7, 5))
    for alg in ("jacobi", "gauss-seidel"):
        for kind in ("constant", "linear"):
            rs = [r for r in rows if r["algorithm"] == alg and r["load_hold"] == kind]
            ax.loglog([r["wall_s"] for r in rs], [r["error"] for r in rs], "o-" if alg != "jacobi" else "s--",
                      label=f"{alg}, {kind} hold")
    rs = sorted((r for r in rows if r["algorithm"] == "ecco"), key=lambda r: r["wall_s"])
    ax.loglog([r["wall_s"] for r in rs], [r["error"] for r in rs], "D-", color="C4",
              label="ECCO (libcosim), linear hold")
    front = sorted((r for r in rows if r["pareto"]), key=lambda r: r["wall_s"])
    ax.loglog([r["wall_s"] for r in front], [r["error"] for r in front], "k:", lw=2, label="Pareto front")
    ax.set_xlabel("wall time [s]")
    ax.set_ylabel("error vs monolithic (normalised RMS)")
    ax.set_title("Two bodies, SIMO interaction: communication step sweep\n"
                 "(labels: step [s]; ECCO: abs_tolerance [J])", fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    legend = ax.legend(fontsize=8)
    from ..cosim.report import annotate_apart, plain_log_ticks
    plain_log_ticks(ax)
    fig.tight_layout()
    annotate_apart(ax, [r["wall_s"] for r in rows], [r["error"] for r in rows],
                   [f"{r['tolerance']:g} J" if r["algorithm"] == "ecco" else f"{r['step']:g}" for r in rows],
                   avoid=(legend,))
    fig.savefig(out / "step_sweep.png", dpi=120)
    plt.close(fig)
    what = lambda r: (f"ECCO, abs_tolerance {r['tolerance']:g} J (mean step {r['step']:.3g} s)" if r["algorithm"] == "ecco"
                      else f"{r['algorithm']}, {r['load_hold']} hold, step {r['step']:g} s")
    return [f"Pareto: {what(r)}: {100 * r['error']:.3g} % in {r['wall_s']:.1f} s" for r in front]


def part_ecco(out, quick):
    from . import ecco_cost
    rows, traces = ecco_cost.measure(out / "ecco", stop=10.0 if quick else 60.0,
                                     steps=(0.1,) if quick else (0.1, 0.05, 0.02),
                                     tolerances=(1.0,) if quick else (10.0, 1.0, 0.1),
                                     fine=0.02 if quick else 0.005,
                                     scenes=("moored_barge",) if quick else None)
    rows = [r for case in dict.fromkeys(r["case"] for r in rows)
            for r in cosim_cost.pareto([r for r in rows if r["case"] == case], cost="steps")]
    write_csv(out / "ecco.csv", rows)
    plot_ecco(rows, out / "ecco.png")
    plot_ecco_steps(traces, out / "ecco_steps.png")
    lines = []
    for case in dict.fromkeys(r["case"] for r in rows):
        mine = [r for r in rows if r["case"] == case]
        for r in mine:
            if r["algorithm"] == "ecco" or r["pareto"]:
                lines.append(f"{case}: {r['algorithm']}, {r['knob']}: {100 * r['error']:.3g} % in {r['steps']} steps "
                             f"({r['min_step']:.3g}–{r['max_step']:.3g} s), {r['wall_s']:.2f} s, energy residual "
                             f"{r['residual_J']:.3g} J = {100 * r['residual_rel']:.2g} % of the bonds' energy"
                             + (" [Pareto]" if r["pareto"] else ""))
    return lines + ["wall times are single runs (not interleaved): compare the steps and errors, not the seconds, "
                    "on a shared machine"]


def plot_ecco(rows, path):
    """Error against the number of steps per case (deterministic, unlike the wall time of
    single runs on a shared machine): fixed steps per algorithm, ECCO per tolerance."""
    from ..cosim.report import plain_log_ticks
    cases = list(dict.fromkeys(r["case"] for r in rows))
    fig, axes = plt.subplots(1, len(cases), figsize=(4.2 * len(cases), 4.2), squeeze=False)
    style = {"jacobi": "s--", "gauss-seidel": "o-", "jacobi (libcosim)": "v:", "ecco": "D-"}
    for ax, case in zip(axes[0], cases):
        for alg, fmt in style.items():
            rs = sorted((r for r in rows if r["case"] == case and r["algorithm"] == alg), key=lambda r: r["steps"])
            ax.loglog([r["steps"] for r in rs], [r["error"] for r in rs], fmt, label=alg,
                      ms=4 if alg == "jacobi (libcosim)" else 6)
            for r in rs:
                ax.annotate(r["knob"].split()[-2],
                            (r["steps"], r["error"]), fontsize=6, xytext=(3, 3), textcoords="offset points")
        ax.set(xlabel="communication steps", title=case)
        ax.grid(True, which="both", alpha=0.3)
        plain_log_ticks(ax)
    axes[0][0].set_ylabel("error (normalised RMS)")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("ECCO (libcosim) beside fixed steps: two-body vs monolithic, models/ vs fine Gauss–Seidel "
                 "(labels: step [s], ECCO abs_tolerance [J]; Jacobi in fmpy and libcosim coincide)", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def plot_ecco_steps(traces, path):
    """The step ECCO took against time (left axis) with the power through the bonds
    |Σ F·v| (right axis), per case."""
    from ..cosim import bonds
    fig, axes = plt.subplots(len(traces), 1, figsize=(9, 2.6 * len(traces)), squeeze=False)
    for ax, (case, result) in zip(axes[:, 0], traces.items()):
        res = bonds.residual(result)
        t = result.time[1:]
        ax.semilogy(t, res.step, color="C0", lw=1)
        ax.set_ylabel("step [s]", color="C0")
        right = ax.twinx()
        right.semilogy(t, np.abs(res.power) + 1e-30, color="C3", lw=0.8, alpha=0.7)
        right.semilogy(t, np.abs(res.residual) / res.step + 1e-30, color="C2", lw=0.8, alpha=0.7)
        right.set_ylabel("power [W]")
        right.legend(handles=[plt.Line2D([], [], color="C0", label="ECCO's step"),
                              plt.Line2D([], [], color="C3", label="|Σ F·v| through the bonds"),
                              plt.Line2D([], [], color="C2", label="residual power |δE|/h")],
                     fontsize=7, loc="upper right")
        ax.set_title(f"{case}: {len(t)} steps, {res.step.min():.3g}–{res.step.max():.3g} s "
                     f"(abs_tolerance {result.settings['ecco']['abs_tolerance']:g} J)", fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
    axes[-1][0].set_xlabel("time [s]")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)
    return path


def part_growth(out, quick):
    lags = memory_cost.growth((100, 400) if quick else (100, 300, 1000, 3000, 10000),
                              calls=50 if quick else 300, rounds=3 if quick else 5)
    flat = cosim_cost.flatness(out / "flat", stop=40.0 if quick else 1000.0, chunks=4 if quick else 10)
    write_csv(out / "growth_lags.csv", lags)
    write_csv(out / "growth_time.csv", flat)
    fig, ax = plt.subplots(1, 2, figsize=(10, 4.5))
    ax[0].loglog([r["lags"] for r in lags], [r["convolution_us"] for r in lags], "s-", label="convolution")
    ax[0].loglog([r["lags"] for r in lags], [r["state_space_us"] for r in lags], "o-", label="state-space (1 %)")
    ax[0].set(xlabel="kernel length [lags]", ylabel="cost per step [µs]", title="6×6 memory")
    ax[1].plot([0.5 * (r["t_start"] + r["t_end"]) for r in flat], [r["us_per_step"] for r in flat], "o-")
    ax[1].set(xlabel="simulated time [s]", ylabel="cost per step [µs]", title="two bodies, convolution",
              ylim=(0, 1.3 * max(r["us_per_step"] for r in flat)))
    for a in ax:
        a.grid(True, which="both", alpha=0.3)
    ax[0].legend()
    fig.tight_layout()
    fig.savefig(out / "growth.png", dpi=120)
    plt.close(fig)
    late = [r["us_per_step"] for r in flat if r["t_start"] >= 60.0]
    return [growth_line(lags),
            f"cost per step after the memory fills: last/first = {late[-1] / late[0]:.2f}" if len(late) > 1 else ""]


def growth_line(lags):
    """Cost growth of each evaluator from the shortest kernel to the longest (rows of
    ``memory_cost.growth``); one whose rounds spread more than ``floor.NOISY`` at either end
    is said to be too noisy instead."""
    first, last = lags[0], lags[-1]
    parts = []
    for name, label, digits in (("convolution", "convolution", 1), ("state_space", "state-space", 2)):
        spread = max(first.get(f"{name}_spread", 0.0), last.get(f"{name}_spread", 0.0))
        parts.append(f"{label} too noisy ({over(spread, floor.NOISY)} between rounds), no figure"
                     if spread > floor.NOISY else
                     f"{label} ×{last[f'{name}_us'] / first[f'{name}_us']:.{digits}f}")
    return f"kernel {first['lags']} → {last['lags']} lags: " + "; ".join(parts)


def part_floor(out, quick):
    """Every scene of models/ and 2, 4, 8 coupled bodies against the pythonfmu floor."""
    from ..fmi.build import build_scene
    from ..scene import load_scene
    from .fleet import Fleet
    quiet = lambda *_: None
    fmu = floor.build_floor(out / "floor")
    candidates = {}
    for path in sorted(Path("models").glob("*.toml")):
        if quick and path.stem != "side_by_side":   # quick: the scene the targets are about
            continue
        scene = load_scene(path)
        candidates[scene.name] = build_scene(scene, out / "floor" / "scenes", log=quiet)
    counts = () if quick else (2, 4, 8)
    pairs = []
    for n in counts:
        fleet = Fleet(n)
        path = fleet.scene(out / "floor" / f"bodies{n}", run='preset = "design"', name=f"bodies{n}")
        candidates[f"{n} bodies"] = build_scene(load_scene(path), out / "floor" / f"bodies{n}" / "fmus", log=quiet)
        pairs.append(len(fleet.pairs()))
    # 2000 steps (100 s simulated): a loop of 400 (~0.1 s) varied by a third between rounds
    # even on a quiet machine, 2000 by a few per cent
    rows = floor.compare(candidates, fmu, out / "floor", rounds=2 if quick else 5, steps=100 if quick else 2000,
                         best_of=1 if quick else floor.STARTUP_BEST)
    write_csv(out / "floor.csv", rows)
    lines = [f"{r['fmus']} trivial pythonfmu FMUs (the reference): {r['step_floor_us']:.0f} µs per step, "
             f"startup {1e3 * r['startup_floor_s']:.0f} ms" for r in {r["fmus"]: r for r in rows}.values()]

    def figure(r, what, text):
        if r[f"{what}_noisy"]:
            return f"{what} too noisy ({over(r[f'{what}_spread'], floor.NOISY)} between rounds), no figure"
        return text

    for r in rows:
        lines.append(f"{r['label']} ({r['fmus']} FMUs): "
                     + figure(r, "step", f"{r['step_x']:.1f}× the floor per step ({r['step_us']:.0f} µs)") + "; "
                     + figure(r, "startup", f"{r['startup_x']:.1f}× at startup ({1e3 * r['startup_s']:.0f} ms)"))
    design = next((r for r in rows if r["label"] == "side_by_side"), None)
    met = lambda x: "met" if x <= 5.0 else "NOT met"
    for what, key in (("per step", "step"), ("at startup", "startup")):
        if design is not None and not design[f"{key}_noisy"]:
            lines.append(f"target side_by_side ≤ 5× {what}: {met(design[f'{key}_x'])} ({design[f'{key}_x']:.1f}×)")
    bodies = [r for r in rows if r["label"].endswith(" bodies")]
    noisy = [r["label"] for r in bodies if r["step_noisy"]]
    if len(bodies) > 1 and not noisy:
        marginal, ratio = floor.linearity(bodies, pairs)
        lines.append(f"bodies {' → '.join(str(n) for n in counts)} ({' → '.join(map(str, pairs))} coupled pairs): "
                     + " → ".join(f"{r['step_us']:.0f}" for r in bodies) + " µs per step; marginal cost per pair "
                     + " → ".join(f"{m:.0f}" for m in marginal) + " µs"
                     + (f" (last/first {ratio:.2f}; 1 = linear in the pairs)" if len(marginal) > 1 else ""))
    elif noisy:
        lines.append(f"too noisy for the body-count trend ({', '.join(noisy)})")
    return lines + compiled.part(out, quick, fmu)


def part_native(out, quick):
    """The pythonfmu floor and the FMUs of moored_barge and side_by_side, each alone in a native
    C host against fmpy (target: native ≤ 1.0× fmpy per step)."""
    from ..fmi.build import build_scene
    from ..scene import load_scene
    from ..fmi.shim import install_shim
    # the floor with hydrofmu's shim, which starts Python in a host that has none
    fmus = {"pythonfmu_floor": install_shim(floor.build_floor(out / "native"))}
    for name in ("moored_barge",) if quick else ("moored_barge", "side_by_side"):
        folder = build_scene(load_scene(Path("models") / f"{name}.toml"), out / "native" / "scenes", log=lambda *_: None)
        fmus.update({f.stem: f for f in sorted(folder.glob("*.fmu"))})
    rows = native.compare(fmus, rounds=2 if quick else 5, steps=500 if quick else 10_000, work=out / "native")
    # the design scene in libcosim, and three trivial FMUs in a ring: libcosim's own cost per step
    ring = floor.floor_system(out / "native", floor.build_floor(out / "native" / "plain"), 3, 0.1)
    design = out / "native" / "scenes" / ("moored_barge" if quick else "side_by_side")
    scenes = [native.compare_scene(f, rounds=2 if quick else 5, steps=200 if quick else 2000) for f in (design, ring)]
    write_csv(out / "native.csv", rows + scenes)
    lines = [native_line(r, r in scenes) for r in rows + scenes]
    crashes = native.exit_crashes()
    if crashes:
        lines.append(f"{len(crashes)} timing processes died at exit after their figures: " + "; ".join(crashes[:3]))
    return lines


def native_line(r, scene=False):
    """One line of the native part: a row of ``native.compare`` (or ``compare_scene``: ``scene``)."""
    step = native.step_figure(r, f"{r['step_x']:.2f}× fmpy per step ({r['step_us']:.1f} vs {r['step_fmpy_us']:.1f} µs, "
                                 f"{'met' if r['step_x'] <= 1.0 else 'NOT met'})")
    start = (f"startup {1e3 * r['startup_s']:.0f} ms native (Python started by the FMU) vs "
             f"{1e3 * r['startup_fmpy_s']:.0f} ms under fmpy (Python running)" if not scene else
             f"startup of a later run {1e3 * r['startup_s']:.0f} ms vs {1e3 * r['startup_fmpy_s']:.0f} ms "
             f"(our fmpy master)")
    return f"{r['label']}: {step}; {start}"


def part_startup(out, quick):
    """Every scene of models/ loaded again in a running process, against the pythonfmu floor."""
    from ..fmi.build import build_scene
    from ..scene import load_scene
    fmu = floor.build_floor(out / "startup")
    candidates = {}
    for path in sorted(Path("models").glob("*.toml")):
        scene = load_scene(path)
        candidates[scene.name] = build_scene(scene, out / "startup" / "scenes", log=lambda *_: None)
    rows = startup.compare(candidates, fmu, out / "startup", rounds=3 if quick else 10)
    write_csv(out / "startup.csv", rows)
    lines = []
    for r in rows:
        x = (f"too noisy ({over(r['startup_spread'], floor.NOISY)}), no figure" if r["startup_noisy"] else
             f"{r['startup_x']:.1f}× the floor ({1e3 * r['startup_s']:.1f} vs {1e3 * r['startup_floor_s']:.1f} ms)")
        lines.append(f"{r['label']} ({r['fmus']} FMUs), load + initialise again in a running process: {x}; "
                     f"free {1e3 * r['free_s']:.1f} ms; the process's first load {1e3 * r['first_s']:.0f} ms "
                     f"(floor {1e3 * r['first_floor_s']:.0f} ms)")
    design = next((r for r in rows if r["label"] == "side_by_side"), None)
    if design is not None and not design["startup_noisy"]:
        lines.append(f"target side_by_side ≤ 5× the floor in a running process: "
                     f"{'met' if design['startup_x'] <= 5 else 'NOT met'} ({design['startup_x']:.1f}×)")
    fmpy_rows = startup.fmpy_compare({k: v for k, v in candidates.items() if not quick or k == "side_by_side"},
                                     fmu, rounds=3 if quick else 10)
    write_csv(out / "startup_fmpy.csv", fmpy_rows)
    for r in fmpy_rows:
        x = (f"too noisy ({over(r['simulate_spread'], floor.NOISY)}), no figure" if r["simulate_noisy"] else
             f"{r['simulate_x']:.1f}× the floor ({1e3 * r['simulate_s']:.0f} vs {1e3 * r['simulate_floor_s']:.0f} ms)")
        lines.append(f"{r['label']} ({r['fmus']} FMUs), fmpy simulate_fmu of one step each (unzip and delete "
                     f"included) in a running process: {x}")
    return lines


def part_stability(out, quick):
    csv_path, png = stability.run(out, n_steps=100 if quick else 400)
    return [f"added-mass map: {csv_path.name}, {png.name}"]


def part_hold(out, quick):
    d = hold.decay(out, steps=(0.1,) if quick else (0.05, 0.1, 0.2))
    write_csv(out / "hold_decay.csv", d)
    s = hold.scenes(out, stop=60.0 if quick else 600.0, factors=(1,) if quick else (1, 2))
    write_csv(out / "hold_scenes.csv", s)
    return hold.summary(d, s)


def part_bem(out, quick):
    sizes = ((12, 50), (12, 100)) if quick else ((12, 50), (12, 100), (12, 200), (24, 100))
    rows = radiation_cost.measure(sizes, rounds=2 if quick else 5)
    write_csv(out / "bem_transform.csv", rows)
    return [f"BEM transform, {r['dofs']} dofs × {r['frequencies']} frequencies: {r['seconds']:.2f} s "
            f"(×{r['ratio']:.2f} of the first)" for r in rows]


def part_robust(out, quick):
    r = robust.deck_error_time(out / "robust", 2.0 if quick else 50.0)
    (out / "robust" / "big.sys").unlink()
    (out / "robust" / "bad_big.sys").unlink()
    from ..fmi.build import build_scene
    from ..scene import load_scene
    folder = build_scene(load_scene(Path("models") / "moored_barge.toml"),
                         out / "robust", log=lambda *_: None)
    cycles, warmup = (500, 200) if quick else (10_000, 1000)
    fmu = folder / "moored_barge_barge.fmu"
    off = robust.instantiate_cycles(fmu, cycles, warmup, pool=False)   # side by side, pool off first
    on = robust.instantiate_cycles(fmu, cycles, warmup)
    rows = [{**{k: v for k, v in r.items() if k != "error"}, "pool": p, "cycles": c["cycles"],
             "growth_kB": c["growth_kB"], "steady_kB": robust.growth(c["rss_kB"])[0],
             "kB_per_cycle": c["kB_per_cycle"], "cycle_s": c["cycle_s"]} for p, c in (("off", off), ("on", on))]
    write_csv(out / "robust.csv", rows)
    return [f"one bad number near the end of a {r['megabytes']:.0f} MB SIMO deck: reported in {r['bad_s']:.2f} s, "
            f"the good deck reads in {r['good_s']:.2f} s (ratio {r['ratio']:.2f}, best of 2, side by side)",
            pool_line(on, off, cycles, warmup)]


def pool_line(on, off, cycles, warmup=1000):
    """The instance pool's memory figure: growth with and without it, compared only when
    the run without it grew by more than the flatness bound (else the cycles were too few
    to tell the two apart, and the line says so)."""
    steady, total = robust.growth(on["rss_kB"])
    flat = steady < robust.FLAT_KB and total < robust.ARENA_KB
    head = f"{cycles} fmi2Instantiate/fmi2FreeInstance cycles of a load FMU through fmpy after {warmup} of warm-up: "
    if off["growth_kB"] <= robust.FLAT_KB:
        return head + (f"no growth to compare ({on['growth_kB']:.0f} kB with the shim's instance pool, "
                       f"{off['growth_kB']:.0f} kB without; below the {robust.FLAT_KB} kB flatness bound): too few "
                       f"cycles to measure the pool (the full run has 10⁴)")
    return head + (f"resident memory {on['growth_kB']:.0f} kB ({on['kB_per_cycle']:.3f} kB per cycle; "
                   f"steady part {steady:.0f} kB: {'flat' if flat else 'NOT flat'}) "
                   f"with the shim's instance pool, {off['growth_kB']:.0f} kB ({off['kB_per_cycle']:.2f} kB per "
                   f"cycle) without (HYDROFMU_POOL=0); {1e3 * on['cycle_s']:.1f} ms against "
                   f"{1e3 * off['cycle_s']:.1f} ms per cycle (×{off['cycle_s'] / on['cycle_s']:.1f})")


def part_batch(out, quick):
    from . import batch_cost
    rows, s = batch_cost.measure(out / "batch", cases=4 if quick else 16, stop=5.0 if quick else 60.0,
                                 rounds=2 if quick else 3)
    write_csv(out / "batch.csv", rows)
    return batch_lines(s, rows[0]["cases"])


def batch_lines(s, cases):
    """The batch part's lines: no speed-up figure when the rounds spread too much, no
    dispatch overhead when the one measured is below zero (the cases' own times vary more
    than the machinery costs)."""
    from . import batch_cost
    speedup = (f"too noisy ({over(s['spread'], batch_cost.NOISY)} between rounds), no figure" if s["noisy"]
               else f"{s['speedup']:.2f}×")
    overhead = (f"{1e3 * s['overhead_s']:.0f} ms = {100 * s['share']:.1f} % of a case's run time"
                if s["overhead_s"] > 0 and not s["noisy"] else
                "below the noise of the cases' own run times, no figure" if not s["noisy"] else
                "too noisy, no figure")
    return [f"speed-up 1 → 2 workers: {speedup} ({cases} cases of {s['case_s']:.2f} s each on one worker)",
            f"dispatch overhead per case: {overhead}; fixed cost of a batch (plan, table, plot): {s['fixed_s']:.2f} s"]


def part_longrun(out, quick):
    from . import longrun
    # quick: a smoke run of the streamed path only, not the 3-hour figures
    stop = 300.0 if quick else 10800.0
    rows = longrun.measure(out / "longrun", stop, ("stream",) if quick else ("floor", "stream", "memory"))
    write_csv(out / "longrun.csv", rows)
    by = {r["mode"]: r for r in rows}
    s = by["stream"]
    span = f"{stop / 3600:g} h" if stop >= 3600 else f"{stop / 60:g} min"
    line = (f"{s['steps']} steps of side_by_side ({span}): streamed peak {s['peak_mb']:.0f} MB "
            f"(its plot's process {s['child_peak_mb']:.0f} MB), {s['wall_s']:.0f} s, files {s['written_mb']:.0f} MB "
            f"(Parquet + CSV + PNG)")
    if "memory" in by:
        m, f = by["memory"], by["floor"]
        line += (f"; in memory peak {m['peak_mb']:.0f} MB, {m['wall_s']:.0f} s, {m['written_mb']:.0f} MB (CSV + PNG); "
                 f"FMUs loaded only: {f['peak_mb']:.0f} MB")
    return [line]


def part_waves(out, quick):
    rows = waves_cost.measure(out / "waves", rounds=2 if quick else 5, steps=200 if quick else 400)
    if rows is None:
        return [f"skipped: needs {waves_cost.DATA} (a repository checkout)"]
    write_csv(out / "waves.csv", rows)
    lines = waves_lines(rows)
    from . import kinematics_cost   # the shared phasors: the kernel per component, both flavours
    table = kinematics_cost.rows(kinematics_cost.python_costs(calls=300 if quick else 2000, rounds=2 if quick else 5),
                                 kinematics_cost.compiled_costs(steps=2000 if quick else 20000,
                                                                rounds=2 if quick else 5))
    lines += [line for line in kinematics_cost.lines(table) if "kinematics per point" not in line]
    from . import waves_motions
    motions = waves_motions.measure(out / "waves_motions", quick)
    if motions:
        write_csv(out / "waves_motions.csv", motions)
        lines += ["motions in regular waves, radiation damping only, against X(ω) of the dataset (% of each dof's "
                  "peak |X|): " + line for line in waves_motions.summary(motions)]
    return lines


def part_kinematics(out, quick):
    """The wave phasors and the incident-wave kinematics per step, Python and compiled flavours."""
    from . import kinematics_cost
    python = kinematics_cost.python_costs(calls=300 if quick else 2000, rounds=2 if quick else 5)
    compiled = kinematics_cost.compiled_costs(steps=2000 if quick else 20000, rounds=2 if quick else 5)
    table = kinematics_cost.rows(python, compiled)
    write_csv(out / "kinematics.csv", table)
    clump = kinematics_cost.joined_barges_clump(out / "kinematics", stop=60.0 if quick else 200.0)
    png = kinematics_cost.plot_clump(clump, out / "clump_in_waves.png")
    return kinematics_cost.lines(table) + [f"the joined barges' clump with and without waves: {png.name}"]


def waves_lines(rows):
    """The waves part's lines: a noisy scene cost and an effect at or below zero (the
    difference of two timings) are said to be noise, not printed."""
    lines = []
    if any(r["noisy"] for r in rows):
        lines.append(f"scene per step through fmpy (load + dynamics FMU): too noisy (spread between rounds above "
                     f"{100 * floor.NOISY:g} %), no figure")
    else:
        lines.append("scene per step through fmpy (load + dynamics FMU): without waves "
                     + f"{rows[0]['no_waves_us']:.0f} µs = {rows[0]['step_x_no_waves']:.2f}× the pythonfmu floor; "
                     + ", ".join(f"{r['components']} components {r['step_us']:.0f} µs = {r['step_x']:.2f}× "
                                 f"(floor {r['step_floor_us']:.0f} µs)" for r in rows))
    effect = ", ".join(f"{r['components']} components " + (f"{r['effect_us']:.0f} µs" if r["effect_us"] > 0
                                                           else "below the noise") for r in rows)
    if all(r["effect_us"] > 0 for r in rows):
        slope, ratio = waves_cost.linear(rows)
        effect += (f"; linear: {slope:.1f} µs per 100 components (cost per component at {rows[-1]['components']} / "
                   f"at {rows[0]['components']}: {ratio:.2f})")
    lines.append("the effect in the load FMU (in-process, with − without waves): " + effect + "; the kernel alone "
                 + ", ".join(f"{r['kernel_per_100_us']:.1f}" for r in rows) + " µs per 100 components")
    return lines


def part_drift(out, quick):
    from . import drift_cost
    counts = (50, 200) if quick else drift_cost.COUNTS
    rows = drift_cost.cost(counts, rounds=2 if quick else 5)
    crows = drift_cost.c_cost(counts, rounds=2 if quick else 5)
    err = drift_cost.newman_error(hours=0.5 if quick else 2.0)
    semi = drift_cost.semisub_cost(rounds=2 if quick else 5)
    write_csv(out / "drift.csv", [{**r, **c} for r, c in zip(rows, crows)])
    write_csv(out / "drift_newman.csv", [err])
    write_csv(out / "drift_semisub.csv", [semi])
    return drift_cost.lines(rows, err, crows, semi)


PARTS = {"overhead": part_overhead, "memory": part_memory, "sweep": part_sweep, "growth": part_growth,
         "floor": part_floor, "native": part_native, "startup": part_startup, "stability": part_stability,
         "hold": part_hold,
         "bem": part_bem, "robust": part_robust, "batch": part_batch, "ecco": part_ecco, "longrun": part_longrun, "waves": part_waves,
         "kinematics": part_kinematics, "drift": part_drift}


# --quick without --part: the parts whose quick size costs under ~12 s of CPU each (measured
# 2026-11-26, 2-core machine under load: 57 s of CPU in all); the others are smoke-run alone
# (memory 14 s, floor 15 s, batch 19 s, waves 20 s of CPU with --quick)
QUICK = ("overhead", "sweep", "growth", "native", "startup", "stability", "bem", "robust", "ecco", "longrun")


def main(out, parts=None, quick=False, log=print):
    """Run the benchmark ``parts`` (default all; with ``quick``: ``QUICK``) into folder
    ``out``; returns summary lines."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    lines = []
    if quick and not parts:
        parts = QUICK
        left = [name for name in PARTS if name not in QUICK]
        note = (f"quick: not run: {', '.join(left)} (each alone: --part NAME --quick, 15–20 s of CPU; "
                "all parts: without --quick)")
        log(note)
        lines.append(note)
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
