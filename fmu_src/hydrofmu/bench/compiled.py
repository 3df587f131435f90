"""The compiled flavour's figures (``hydrofmu bench --part floor``): per step and at startup
in a native host, against the native floor.

The native floor is a trivial compiled FMU (6 inputs, 6 outputs, fmi2DoStep copies the
inputs to the outputs) built on the same FMI layer as every compiled hydrofmu FMU
(fmi/fmu.c): what a compiled FMU cannot beat.  The host is ``native_host.c`` (this folder,
bench/native.py), a C program that loads one FMU (dlopen), instantiates and initialises it,
then steps it: every step sets all its inputs, calls fmi2DoStep and reads all its outputs.
Startup is dlopen to the end of fmi2ExitInitializationMode in a fresh process (the FMU
unzipped before, as every host does), the best of ``STARTUP_BEST``; the cost per step is
the loop's time over its steps, also the best of ``STARTUP_BEST`` processes.  Candidate and floor alternate in ``rounds`` rounds; each multiple is
the median of the rounds' ratios, too noisy above ``floor.NOISY``.
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from . import native
from .floor import NOISY, STARTUP_BEST, spread


def build_floor(folder, n_in=6, n_out=6) -> Path:
    """The native floor FMU (``hydrofmu_cfloor.fmu``; 6 inputs, 6 outputs) in ``folder``, or a
    copy FMU with other port counts (output k copies input k mod n_in): what exchanging that
    many values costs on the same FMI layer, with no physics."""
    from pythonfmu import Fmi2Causality, Fmi2Slave, Real
    from ..fmi.cbuild import write_fmu

    class Floor(Fmi2Slave):
        author = "hydrofmu bench"
        description = "trivial compiled FMU: fmi2DoStep copies u to y"
        units, dependencies = {}, {}

        def __init__(self, **kwargs):
            super().__init__(**kwargs)
            for name, causality, n in (("u", Fmi2Causality.input, n_in), ("y", Fmi2Causality.output, n_out)):
                for i in range(n):
                    self.register_variable(Real(f"{name}[{i + 1}]", causality=causality, getter=lambda: 0.0,
                                                **({"setter": lambda v: None} if name == "u" else {})))

        def do_step(self, current_time, step_size):   # (the C floor's; this slave only describes it)
            return True

    slave = Floor(instance_name="floor")
    slave._start = [0.0] * (n_in + n_out)   # (the start values hydrofmu's slaves keep)
    recs = [("kind", [3]), ("start", [0.0] * (n_in + n_out)),
            ("copy", [k % n_in for k in range(n_out)] + [n_in + k for k in range(n_out)])]
    name = "hydrofmu_cfloor" if (n_in, n_out) == (6, 6) else f"hydrofmu_copy_{n_in}_{n_out}"
    return write_fmu(Path(folder) / f"{name}.fmu", slave, recs)


def _candidate(f):
    """(FMU, vary, (inputs, outputs)) of a candidate given as an FMU, (FMU, vary) or (FMU, vary, ports)."""
    f = f if isinstance(f, tuple) else (f, False)
    return f if len(f) == 3 else (*f, (None, None))


def compare(candidates, floor_fmu, out, rounds=5, steps=200_000, dt=0.05, best_of=STARTUP_BEST):
    """{label: compiled FMU, or (FMU, vary), or (FMU, vary, (inputs, outputs))} against the native
    floor in the C timing host, both with the same inputs every step or (vary) inputs that change
    at every step (native_host.c); every input set and every output read, or only the ports whose
    names start with one of ``inputs`` / ``outputs`` (None: all); rows {label, step_us,
    step_floor_us, step_x, startup_ms, startup_floor_ms, startup_x, *_spread, *_noisy, ports}."""
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    exe = native.host(out)
    floor_args = native.unpack(floor_fmu, out / "floor")
    candidates = {label: _candidate(f) for label, f in candidates.items()}
    unpacked = {label: (native.unpack(f, out / f"c{k}", *ports), vary)
                for k, (label, (f, vary, ports)) in enumerate(candidates.items())}

    def measure(args, vary):
        """(startup [s], seconds per step), each the best of ``best_of`` fresh processes (noise
        only adds time: a floor's loop of 200 000 steps lasts ~10 ms)."""
        args = list(map(str, args[:3])) + [str(steps), repr(dt)] + list(args[3:]) + [str(int(vary))]
        got = [native._json([str(exe), *args]) for _ in range(best_of)]
        return min(g["startup_s"] for g in got), min(g["step_s"] for g in got)

    got = {label: [] for label in candidates}
    for _ in range(rounds):
        for label, (args, vary) in unpacked.items():
            (fs, fp), (cs, cp) = measure(floor_args, vary), measure(args, vary)
            got[label].append([fs, cs, fp, cp])
    rows = []
    for label, t in got.items():
        t = np.array(t)
        start_x, step_x = t[:, 1] / t[:, 0], t[:, 3] / t[:, 2]
        rows.append({"label": label, "step_us": 1e6 * float(np.median(t[:, 3])),
                     "step_floor_us": 1e6 * float(np.median(t[:, 2])), "step_x": float(np.median(step_x)),
                     "startup_ms": 1e3 * float(np.median(t[:, 1])), "startup_floor_ms": 1e3 * float(np.median(t[:, 0])),
                     "startup_x": float(np.median(start_x)),
                     "step_spread": spread(step_x), "step_noisy": spread(step_x) > NOISY,
                     "startup_spread": spread(start_x), "startup_noisy": spread(start_x) > NOISY,
                     "ports": (unpacked[label][0][3].count(":"), len(unpacked[label][0][4].split(",")))})
    return rows


def design_scene(folder) -> Path:
    """models/side_by_side.toml with AQWA viscous drag on barge_a: its load FMU has the current
    polar, drag and state-space memories (own and cross), more than the target names."""
    models = Path(__file__).resolve().parents[3] / "models"
    text = (models / "side_by_side.toml").read_text().replace('deck = "decks/', f'deck = "{models.as_posix()}/decks/')
    text += f"""
[[bodies.barge_a.effects]]
type = "aqwa_viscous_drag"
deck = "{models.as_posix()}/decks/barge_viscous.aqwa"
body = "BARGE"
"""
    path = Path(folder) / "side_by_side_drag.toml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    return path


def target_scene(folder) -> Path:
    """The FMU the target names and nothing else: barge_a of models/side_by_side.toml (its mass,
    inertia, stiffness and current) with its own SIMO radiation memory (state space, the design
    preset) and AQWA viscous drag."""
    from ..textfile import read_toml
    models = Path(__file__).resolve().parents[3] / "models"
    scene = read_toml(models / "side_by_side.toml")
    barge, env = scene["bodies"]["barge_a"], scene["environment"]
    decks = (models / "decks").as_posix()
    path = Path(folder) / "drag_memory.toml"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(f"""[scene]
name = "drag_memory"
[environment]
current_speed = {env["current_speed"]!r}
current_direction = {env["current_direction"]!r}
[run]
preset = "design"
stop = 10.0
[bodies.barge]
mass = {barge["mass"]!r}
inertia = {barge["inertia"]!r}
stiffness = {barge["stiffness"]!r}
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
deck = "{decks}/barge_viscous.aqwa"
body = "BARGE"
[[couplings]]
deck = "{decks}/side_by_side.sim"
coupling = "SELFA"
bodies = {{ BARGEA = "barge" }}
""")
    return path


# the ports a master connects to a load FMU in a coupled scene (the OSP and SSP files we write):
# the body's motion in, the total load out (the current is set once, the per-effect loads are
# for recording)
COUPLED = (("position", "attitude", "velocity"), ("force[",))


def part(out, quick, pythonfmu_floor):
    """Lines of the compiled flavour's figures: the load FMU with state-space memory and drag,
    the joint and dynamics FMUs against the native floor in the C host; the two-body design
    scene in both flavours under our master (startup, per step, real-time factor) against
    the pythonfmu floor."""
    from ..fmi.build import build_scene
    from ..scene import load_scene
    from . import floor
    quiet = lambda *_: None   # noqa: E731
    out = Path(out) / "compiled"
    cfloor = build_floor(out)
    target = build_scene(load_scene(target_scene(out)), out / "scenes", log=quiet, runtime="c") / "drag_memory_barge.fmu"
    drag = build_scene(load_scene(design_scene(out)), out / "scenes", log=quiet, runtime="c")
    joined = build_scene(load_scene(Path(__file__).resolve().parents[3] / "models" / "joined_barges.toml"),
                         out / "scenes", log=quiet, runtime="c")
    load = drag / "side_by_side_barge_a.fmu"
    from fmpy import read_model_description
    causality = [v.causality for v in read_model_description(str(target)).modelVariables]
    n_in, n_out = causality.count("input"), causality.count("output")
    candidates = {
        "load FMU, state-space memory + drag, inputs changing every step": (target, True),
        "the same FMU as coupled (motion in, total load out), inputs changing every step": (target, True, COUPLED),
        f"copy FMU with the same ports ({n_in} in, {n_out} out): the FMI exchange alone, no physics":
            (build_floor(out, n_in, n_out), True),
        "side_by_side barge_a load FMU (current polar, drag, own and cross state-space memory), inputs changing "
        "every step": (load, True),
        "the same, the same inputs every step": load,
        "dynamics FMU, two coupled bodies, inputs changing every step":
            (drag / "side_by_side_barge_a_barge_b_dynamics.fmu", True),
        "joint FMU (CONB), inputs changing every step": (joined / "joined_barges_hitch.fmu", True)}
    rows = compare(candidates, cfloor, out / "unzipped", rounds=3 if quick else 5, steps=20_000 if quick else 200_000,
                   best_of=1 if quick else STARTUP_BEST)
    f = rows[0]   # the target's: inputs that change every step, as in a co-simulation
    lines = [f"native floor (trivial compiled FMU, C host): {f['step_floor_us']:.3f} µs per step "
             f"(set 6, doStep, get 6), startup {f['startup_floor_ms']:.2f} ms"]

    def figure(r, what, text):   # a noisy figure is said to be so, not printed
        from .timing import over
        return f"{what} too noisy ({over(r[f'{what}_spread'], NOISY)}), no figure" if r[f"{what}_noisy"] else text

    for r in rows:
        lines.append(f"compiled {r['label']} [set {r['ports'][0]}, get {r['ports'][1]}]: "
                     + figure(r, "step", f"{r['step_x']:.1f}× the native floor per step ({1e3 * r['step_us']:.0f} ns)")
                     + "; " + figure(r, "startup", f"{r['startup_x']:.1f}× at startup ({r['startup_ms']:.2f} ms)"))
    copy = rows[2]
    if not (f["step_noisy"] or copy["step_noisy"]):
        lines.append(f"of the load FMU's {1e3 * f['step_us']:.0f} ns per step, {1e3 * copy['step_us']:.0f} ns is the FMI "
                     f"exchange of its ports and {1e3 * (f['step_us'] - copy['step_us']):.0f} ns its physics "
                     f"({(f['step_us'] - copy['step_us']) / f['step_floor_us']:.1f}× the whole floor step)")
    met = lambda x: "met" if x <= 3.0 else "NOT met"   # noqa: E731
    for key, what in (("step", "per step"), ("startup", "at startup")):
        if not f[f"{key}_noisy"]:
            lines.append(f"target compiled load FMU ≤ 3× the native floor {what}: {met(f[f'{key}_x'])} "
                         f"({f[f'{key}_x']:.1f}×)")
    # the two-body design scene in both flavours, our master (fmpy), against the pythonfmu floor
    scene = load_scene(Path(__file__).resolve().parents[3] / "models" / "side_by_side.toml")
    both = {"side_by_side, Python flavour": build_scene(scene, out / "python", log=quiet, runtime="python"),
            "side_by_side, compiled flavour": build_scene(scene, out / "c", log=quiet, runtime="c")}
    step = scene.run["step"]
    rows = floor.compare(both, pythonfmu_floor, out / "master", rounds=3 if quick else 5,
                         steps=100 if quick else 2000, step=step, best_of=1 if quick else STARTUP_BEST)
    lines += [flavour_line(r, step) for r in rows]
    # the compiled design scene in libcosim (its C++ master, called through libcosimpy) against
    # our master on the same FMUs, and three native floors in a ring: libcosim's own cost
    # (every output recorded by both, and one: libcosim's time-series observer costs per variable)
    ring = floor.floor_system(out / "ring", cfloor, 3, step)
    design = both["side_by_side, compiled flavour"]
    for label, folder, record in (("side_by_side, compiled flavour", design, None),
                                  ("side_by_side, compiled flavour, one output recorded", design, ["barge_a.force[1]"]),
                                  ("3 native floor FMUs in a ring (libcosim's own cost)", ring, None)):
        r = native.compare_scene(folder, rounds=2 if quick else 5, steps=200 if quick else 2000, record=record)
        lines.append(libcosim_line(label, r, step))
    return lines


def flavour_line(r, step):
    """A flavour's run in our master against the pythonfmu floor (a row of ``floor.compare``):
    a noisy figure is said to be so, not printed."""
    from .timing import over
    per_step = (f"per step too noisy ({over(r['step_spread'], NOISY)}), no figure" if r["step_noisy"] else
                f"{r['step_us']:.0f} µs per step ({r['step_x']:.2f}× the pythonfmu floor), real-time factor "
                f"{step / (1e-6 * r['step_us']):.0f}")
    start = (f"startup too noisy ({over(r['startup_spread'], NOISY)}), no figure" if r["startup_noisy"] else
             f"startup {1e3 * r['startup_s']:.0f} ms ({r['startup_x']:.2f}× the floor)")
    return f"{r['label']} (our master, fmpy): {per_step}; {start}"


def libcosim_line(label, r, step):
    """A scene in libcosim against our master on the same FMUs (a row of
    ``native.compare_scene``): a noisy figure is said to be so, not printed."""
    from .timing import over
    per_step = native.step_figure(r, f"{r['step_us']:.0f} µs per step ({r['step_x']:.2f}× our master on the same "
                                     f"FMUs, {r['step_fmpy_us']:.0f} µs), real-time factor "
                                     f"{step / (1e-6 * r['step_us']):.0f}")
    start = (f"startup too noisy ({over(r['startup_spread'], NOISY)}), no figure" if r["startup_noisy"] else
             f"startup of a later run {1e3 * r['startup_s']:.0f} ms ({r['startup_x']:.2f}× ours)")
    return f"{label} in libcosim: {per_step}; {start}"
