"""The ``[run]`` table: step, stop, algorithm, load hold, presets, ECCO settings, outputs."""
from .. import admissible, keys
from ..errors import InputError


RUN_DEFAULTS = {"step": 0.1, "stop": 100.0, "algorithm": "gauss-seidel", "substep": 0.01, "load_hold": "constant"}
ALGORITHMS = ("jacobi", "gauss-seidel", "ecco")
# libcosim's ECCO (energy-conservation-based co-simulation, Sadjina & Pedersen 2020): the
# step adapts to the power-bond energy residual; `step` is its first step.  Names as in
# OspSystemStructure.xml's <EccoConfiguration>, snake case; tolerances on the residual
# energy per step: abs [J], rel (to the energy the bonds carry in that step).
ECCO_DEFAULTS = {"rel_tolerance": 1e-3, "abs_tolerance": 1.0, "min_step": 0.005, "max_step": 0.2,
                 "safety_factor": 0.8, "min_change_rate": 0.2, "max_change_rate": 1.5,
                 "p_gain": 0.2, "i_gain": 0.15}
MEMORY_DEFAULTS = {"method": "convolution", "tolerance": 0.002, "memory_length": None}   # tolerance: see docs/bem.md (coarse grids)

# Speed/accuracy presets a scene names with [run] preset = "…": each sets the run knobs
# and the default memory evaluator of every coupling; knobs the scene sets still win.
# The figures behind each choice are in the README (measured by `hydrofmu bench`).
PRESETS = {
    "screening": {"step": 0.2, "algorithm": "gauss-seidel", "substep": 0.05, "load_hold": "linear",
                  "memory": {"method": "state_space", "tolerance": 0.05, "memory_length": None}},
    "design": {"step": 0.05, "algorithm": "gauss-seidel", "substep": 0.05, "load_hold": "linear",
               "memory": {"method": "state_space", "tolerance": 0.01, "memory_length": None}},
    "reference": {"step": 0.01, "algorithm": "gauss-seidel", "substep": 0.005, "load_hold": "linear",
                  "memory": {"method": "convolution", "tolerance": 0.01, "memory_length": None}},
    "adaptive": {"step": 0.01, "algorithm": "ecco", "substep": 0.01, "load_hold": "linear",
                 "memory": {"method": "state_space", "tolerance": 0.01, "memory_length": None},
                 "ecco": dict(ECCO_DEFAULTS)},
}


# what a run writes (not run knobs: no preset sets them): `outputs`, names of what to record
# (body names, body.position …, instance.variable; default every output), `interval`, the
# output interval [s] (a whole number of steps; default every step), and `split`, the period [s]
# between the statistics' low- and wave-frequency parts (default 2·Tp of the sea)
OUTPUT_KEYS = ("outputs", "interval", "split")


def _outputs(p, run):
    value = run.get("outputs")
    if value is not None and (not isinstance(value, list) or not value
                              or not all(isinstance(v, str) and v for v in value)):
        p.add("run.outputs", f"expected a non-empty array of output names (e.g. [\"barge\", \"barge.force[1]\"]), "
                             f"found {value!r}")
        return None
    return value


def _ecco(p, run, base, step):
    """The ECCO settings of ``[run.ecco]`` over the preset's (or the defaults), checked."""
    table = p.table(run, "ecco", "run.ecco", required=False) or {}
    p.known_keys(table, "run.ecco", keys.names(keys.ECCO))
    out = {k: p.number(table, k, f"run.ecco.{k}", v, positive=True)
           for k, v in base.get("ecco", ECCO_DEFAULTS).items()}
    if None in out.values():
        return out
    lo, hi = out["min_step"], out["max_step"]
    if lo > hi:
        p.add("run.ecco.min_step", f"must not exceed max_step ({hi:g} s), found {lo:g}")
    elif step is not None and not lo <= step <= hi:
        p.add("run.step", f"ECCO's first step must lie within [min_step, max_step] = [{lo:g}, {hi:g}] s, "
                          f"found {step:g}")
    if out["safety_factor"] > 1:
        p.add("run.ecco.safety_factor", f"must be in (0, 1], found {out['safety_factor']:g}")
    if out["min_change_rate"] > 1:
        p.add("run.ecco.min_change_rate", f"must be in (0, 1], found {out['min_change_rate']:g}")
    if out["max_change_rate"] < 1:
        p.add("run.ecco.max_change_rate", f"must be at least 1, found {out['max_change_rate']:g}")
    return out


def stable_defaults(run_cfg, bodies, couplings, sea, ramp_default=False, joints=None):
    """The knobs a scene with waves or memory (or a BEM restoring as a load input) gets unless
    the scene or its preset sets them: the linear load hold (the constant hold's half-step
    lag takes ω·h/4 of critical damping from every mode whose restoring is a load input,
    more than the 1–2 % radiation gives roll and pitch: physics.hold, docs/tuning.md) and a
    step that keeps the linear hold's −(ω·h)³/6 within physics.hold.ZETA_BUDGET for the
    fastest such mode (its dry frequency: an upper bound).  ``run_cfg["chosen"]`` lists what
    was chosen and why."""
    from ..physics.hold import natural_frequencies, stable_step
    restoring = [(b, e) for b in bodies.values() for e in b.effects
                 if e.type == "bem_hydrostatics" and e.data is not None]
    waves = sea is not None or any(e.type == "wave_excitation" for b in bodies.values() for e in b.effects)
    why = [w for w, has in (("waves", waves), ("radiation memory", bool(couplings)),
                            ("BEM hydrostatics as a load input", bool(restoring))) if has]
    run_cfg["chosen"] = []
    # what a failed run's advice needs (cosim.master.advice): the waves' ramp and peak period
    run_cfg["waves"] = None if sea is None else {
        "ramp": sea.ramp, "period": sea.period if sea.spectrum == "regular" else sea.tp, "spectrum": sea.spectrum}
    run_cfg["restoring_omega"] = None
    if sea is not None and ramp_default:
        run_cfg["chosen"].append(f"wave ramp {sea.ramp:g} s (3 peak periods)")
    if not why:
        return run_cfg
    because = " and ".join(why)
    free = run_cfg["preset"] is None and run_cfg["algorithm"] != "ecco"   # a preset's knobs are its own
    # explicit acceleration loads and joints have their stability limits measured with the
    # constant hold (docs/reliability.md): the linear hold extrapolates an inertia load that
    # alternates from step to step, and joints' default springs are designed for the constant one
    held = [w for w, has in (("explicit acceleration loads", any(b.accel_mode == "explicit" for b in bodies.values())),
                             ("joints", bool(joints))) if has]
    if free and "load_hold" not in run_cfg["set"] and held:
        run_cfg["chosen"].append(f"constant load hold kept (the scene has {' and '.join(held)})")
    elif free and "load_hold" not in run_cfg["set"]:
        run_cfg["load_hold"] = "linear"
        run_cfg["chosen"].append(f"linear load hold (the scene has {because})")
    if restoring and run_cfg["stop"]:
        import numpy as np
        from ..physics.rigid_body import RigidBody
        top = 0.0
        for body, effect in restoring:
            try:
                m = RigidBody(body.mass, np.diag(body.inertia) if np.ndim(body.inertia) == 1 else body.inertia,
                              body.cog).mass_matrix()
                w = natural_frequencies(m, effect.data["stiffness"])
            except (ValueError, ArithmeticError, np.linalg.LinAlgError, InputError):
                continue
            top = max([top, *w])
        if top > 0:
            run_cfg["restoring_omega"] = float(top)
            step = stable_step(top, run_cfg["stop"], hold=run_cfg["load_hold"])
            if free and "step" not in run_cfg["set"] and step != run_cfg["step"]:
                run_cfg["chosen"].append(f"step {step:g} s (the fastest mode of the BEM restoring, "
                                         f"{top:.3g} rad/s dry, keeps its load hold's damping change within "
                                         f"0.1 % of critical)")
                run_cfg["step"] = step
    return run_cfg


def read_run(p, run):
    """The run settings of ``[run]``: a preset's knobs under the ones the table sets, checked."""
    preset = run.get("preset")
    if preset is not None and preset not in PRESETS:
        p.add("run.preset", f"expected one of {', '.join(map(repr, PRESETS))}, found {preset!r}")
        preset = None
    base = {**RUN_DEFAULTS, **PRESETS.get(preset, {})}
    run_cfg = {
        "preset": preset,
        "step": p.number(run, "step", "run.step", base["step"], positive=True),
        "stop": p.number(run, "stop", "run.stop", base["stop"], positive=True),
        "algorithm": p.choice(run, "algorithm", "run.algorithm", ALGORITHMS, base["algorithm"]),
        "substep": p.number(run, "substep", "run.substep", base["substep"], positive=True),
        "load_hold": p.choice(run, "load_hold", "run.load_hold", ("constant", "linear"), base["load_hold"]),
        "memory": dict(base.get("memory", MEMORY_DEFAULTS)),
        "set": sorted(k for k in run if k != "preset" and k not in OUTPUT_KEYS),   # knobs the scene sets itself
        "outputs": _outputs(p, run),
        "interval": p.number(run, "interval", "run.interval", positive=True) if "interval" in run else None,
        "split": p.number(run, "split", "run.split", positive=True) if "split" in run else None,
    }
    run_cfg["ecco"] = _ecco(p, run, base, run_cfg["step"] if run_cfg["algorithm"] == "ecco" else None)
    if run_cfg["algorithm"] not in (None, "ecco") and None not in (run_cfg["step"], run_cfg["stop"]):
        for field_, message in admissible.whole_steps(run_cfg["stop"], run_cfg["step"])[1]:
            p.add(f"run.{field_}", message)
    if run_cfg["interval"] is not None and run_cfg["step"] and run_cfg["algorithm"] != "ecco":
        for field_, message in admissible.whole_interval(run_cfg["interval"], run_cfg["step"])[1]:
            p.add(f"run.{field_}", message)
    if "ecco" in run and run_cfg["algorithm"] not in (None, "ecco"):
        p.add("run.ecco", f"ECCO settings need algorithm = \"ecco\" (the run's algorithm is {run_cfg['algorithm']!r})")
    return run_cfg
