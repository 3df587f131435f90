"""Run a built scene in libcosim (the Open Simulation Platform's engine) via libcosimpy.

Two of libcosim's algorithms:

- ``jacobi``: its fixed-step algorithm, a Jacobi scheme (all slaves step, then outputs are
  copied to inputs), so its results equal hydrofmu's fmpy master in ``jacobi`` mode.  A run
  asked to be Gauss–Seidel is refused rather than quietly run as Jacobi.
- ``ecco``: its energy-conservation-based algorithm (Sadjina & Pedersen 2020): Jacobi
  exchanges, with the step adapted after each one to the energy residual of the power bonds
  (``cosim.bonds``), which are added here through the API, one per force/velocity
  component.  The run's ``[run.ecco]`` settings (scene or preset) give its tolerances and
  step bounds; ``step`` is its first step.

libcosim counts time in integer nanoseconds.
"""
from pathlib import Path

import numpy as np

from ..admissible import MAX_STEPS
from ..errors import InputError
from .bonds import columns, power_bonds
from .manifest import read_manifest
from .master import check_names, check_steps, run_settings
from .result import Result, column_units
from .stream import output_every, select

NS = 1_000_000_000


def run(folder, stop=None, step=None, record=None, algorithm=None, ecco=None, outputs=None, interval=None,
        timing=None):
    """Run the scene built in ``folder`` (its manifest.json) in libcosim; returns a Result
    with the same columns and time points as cosim.master.run (default: every output of
    every FMU, every step).
    ``algorithm`` (default: the scene's) must be 'jacobi' or 'ecco': InputError otherwise.
    ``outputs``, ``interval``: as for ``cosim.master.run`` (default: the scene's ``[run]
    outputs`` and ``interval``): only the chosen columns are observed, and one row in
    ``interval / step`` is kept (libcosim's observer holds every step of those columns).
    ``ecco``: ECCO settings over the scene's (``{'rel_tolerance': 1e-4}``, keys of ``[run.ecco]``).
    An ECCO run's time points are the ones it chose (an output interval is refused); it
    ends at the first at or after ``stop``, and its Result records every power bond's
    force and velocity too.  ``timing``: a dict that receives ``stepping``, the seconds
    libcosim spent stepping (loading and initialisation excluded)."""
    from libcosimpy.CosimAlgorithm import CosimAlgorithm, EccoParams
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    folder = Path(folder)
    manifest = read_manifest(folder)
    wanted = algorithm or manifest["run"]["algorithm"]
    if wanted not in ("jacobi", "ecco"):
        where = "--algorithm" if algorithm else folder / "manifest.json"
        raise InputError(where, None, "algorithm", f"libcosim's fixed-step master is a Jacobi scheme and cannot "
                         f"run '{wanted}' (the scene's or the run's choice); run with the fmpy engine, "
                         "or ask for Jacobi explicitly (--algorithm jacobi, algorithm='jacobi'), or for "
                         "libcosim's adaptive ECCO (--algorithm ecco)")
    stop = manifest["run"]["stop"] if stop is None else stop
    step = manifest["run"]["step"] if step is None else step
    check_steps(stop, step, wanted, "run")
    source = manifest.get("source", folder / "manifest.json")
    # the scene's [run] outputs / interval unless the run names its own (as cosim.master.run)
    out_where = ("run", "outputs") if outputs is not None else (source, "run.outputs")
    outputs = manifest["run"].get("outputs") if outputs is None and record is None else outputs
    int_where = ("run", "interval") if interval is not None else (source, "run.interval")
    interval = manifest["run"].get("interval") if interval is None else interval
    if wanted == "ecco" and interval is not None:
        raise InputError(*int_where[:1], None, int_where[1],
                         f"an output interval ({interval:g} s) needs a fixed step: ECCO chooses its own time "
                         "points (run it without an interval, or with --algorithm jacobi)")
    thin = output_every(interval, step, *int_where) if wanted != "ecco" else 1
    step_ns = int(round(step * NS))
    settings = run_settings(manifest, step, wanted, stop)
    if wanted == "ecco":
        from ..scene import ECCO_DEFAULTS
        unknown = set(ecco or {}) - set(ECCO_DEFAULTS)
        if unknown:
            raise InputError("ecco", None, sorted(unknown)[0], f"not an ECCO setting ({', '.join(ECCO_DEFAULTS)})")
        settings["ecco"] = ecco = {**settings["ecco"], **(ecco or {})}
        if not ecco["min_step"] <= step <= ecco["max_step"]:
            raise InputError("--step", None, "step", f"ECCO's first step must lie within [min_step, max_step] = "
                             f"[{ecco['min_step']:g}, {ecco['max_step']:g}] s, found {step:g}")
        if stop > MAX_STEPS * ecco["min_step"]:   # ECCO may take stop/min_step steps, each kept in memory
            raise InputError("run", None, "stop", f"stop {stop:g} s is more than {MAX_STEPS:.0e} of ECCO's min_step "
                                                  f"({ecco['min_step']:g} s): raise min_step or shorten the run")
        algo = CosimAlgorithm.create_ecco_algorithm(ecco_params(EccoParams, ecco, step))
        execution = CosimExecution.from_algorithm(algo)
        capacity = int(np.ceil(stop / ecco["min_step"])) + 3   # most steps ECCO can take
    else:
        execution = CosimExecution.from_step_size(step_size=step_ns)
        n = int(round(stop / step))
        capacity = n + 1
    index, refs, outs = {}, {}, {}
    for name in manifest["order"]:
        fmu = str((folder / manifest["instances"][name]["fmu"]).resolve())
        slave = CosimLocalSlave(fmu_path=fmu, instance_name=name)
        index[name] = execution.add_local_slave(slave)
        if index[name] < 0:
            raise RuntimeError(f"libcosim could not load {fmu}")
        variables = execution.slave_variables(index[name])
        refs[name] = {v.name.decode(): v.reference for v in variables}
        outs[name] = [v.name.decode() for v in variables if v.causality == 2]  # 2 = output
    for src, svar, dst, dvar in manifest["connections"]:
        if execution.connect_real_variables(index[src], refs[src][svar], index[dst], refs[dst][dvar]) != 0:
            raise RuntimeError(f"libcosim could not connect {src}.{svar} -> {dst}.{dvar}")
    every = [f"{name}.{var}" for name in manifest["order"] for var in outs[name]]
    if record is None and outputs:
        record = select(manifest, outputs, every, *out_where)
    record = list(every if record is None else record)
    check_names(record, [f"{name}.{var}" for name in manifest["order"] for var in refs[name]], "run", "record",
                "'instance.variable'")
    if wanted == "ecco":
        bonds = power_bonds(manifest)
        if not bonds:
            raise InputError(folder / "manifest.json", None, "connections",
                             "ECCO needs power bonds (a force sent to a dynamics FMU and its velocity back); "
                             "this scene has none")
        for b in bonds:
            if algo.add_power_bond(index[b.load], refs[b.load][b.force], refs[b.load][b.velocity],
                                   index[b.dynamics], refs[b.dynamics][b.dyn_velocity],
                                   refs[b.dynamics][b.dyn_force]) != 0:
                raise RuntimeError(f"libcosim could not add the power bond {b.load}.{b.force} <-> "
                                   f"{b.dynamics}.{b.dyn_velocity}")
        record += [c for c in columns(bonds) if c not in record]

    series = CosimObserver.create_time_series(buffer_size=capacity + 1)
    execution.add_observer(series)
    for col in record:
        name, var = col.split(".", 1)
        series.start_time_series(index[name], refs[name][var], CosimVariableType.REAL)
    if wanted == "ecco":   # ECCO reads the bonds' inputs too, and libcosim reads only what is observed
        for b in bonds:
            for name, var in ((b.load, b.velocity), (b.dynamics, b.dyn_force)):
                series.start_time_series(index[name], refs[name][var], CosimVariableType.REAL)
    import time as clock
    end = int(round(stop * NS)) if wanted == "ecco" else n * step_ns
    ok = timing is None or end <= step_ns or execution.simulate_until(target_time=step_ns)
    started = clock.perf_counter()   # timed from the first step on (initialisation excluded)
    ok = ok and execution.simulate_until(target_time=end)
    if timing is not None:
        timing["stepping"] = clock.perf_counter() - started
    if not ok:
        from libcosimpy._internal import get_last_error_message
        why = "; ".join(line.strip() for line in get_last_error_message().splitlines() if line.strip())
        raise RuntimeError(f"libcosim stopped before the end time: {why}")

    values = []
    for col in record:
        name, var = col.split(".", 1)
        v, times = _samples(series, index[name], refs[name][var], capacity)
        if wanted != "ecco" and v.size != n + 1:
            raise RuntimeError(f"libcosim returned {v.size} samples for {n + 1} communication points")
        values.append(v)
    if wanted == "ecco":
        time = times / NS
        step = float(np.mean(np.diff(time))) if time.size > 1 else step
    else:   # the rows our master keeps: every point k with k % thin == 0
        time = np.arange(n + 1)[::thin] * step
        values = [v[::thin] for v in values]
        step = thin * step   # the Result's step: its rows' spacing, as our master's
    return Result(time, record, np.column_stack(values), wanted if wanted == "ecco" else "libcosim", step,
                  manifest["dynamics"], settings, column_units(folder, manifest, record), manifest)


def engine_for(folder, algorithm=None, engine=None):
    """The engine a run uses: ``engine`` when given, else libcosim for an ECCO run (the
    run's ``algorithm`` or the scene's) and hydrofmu's fmpy master otherwise."""
    if engine is not None:
        return engine
    if algorithm is None:
        algorithm = read_manifest(folder)["run"]["algorithm"]
    return "libcosim" if algorithm == "ecco" else "fmpy"


def ecco_params(params, ecco, step):
    """libcosimpy's EccoParams from a run's ``ecco`` settings and first step [s]."""
    return params(safety_factor=ecco["safety_factor"], step_size=step, min_step_size=ecco["min_step"],
                  max_step_size=ecco["max_step"], min_change_rate=ecco["min_change_rate"],
                  max_change_rate=ecco["max_change_rate"], abs_tolerance=ecco["abs_tolerance"],
                  rel_tolerance=ecco["rel_tolerance"], p_gain=ecco["p_gain"], i_gain=ecco["i_gain"])


def _samples(series, slave, ref, capacity):
    """(values, times in ns) of one time series, from step 0 on (every step recorded:
    ``capacity`` holds them all).  Called through the C API directly: libcosimpy's wrapper
    trims its result by counting step numbers equal to 0, which drops the initial sample."""
    from ctypes import POINTER, c_double, c_int, c_int64, c_size_t, c_uint32
    from libcosimpy._internal import libcosimc, wrap_function
    from libcosimpy.CosimObserver import CosimObserver

    get = wrap_function(lib=libcosimc(), funcname="cosim_observer_slave_get_real_samples",
                        argtypes=[POINTER(CosimObserver), c_int, c_uint32, c_int64, c_size_t,
                                  c_double * capacity, c_int64 * capacity, c_int64 * capacity],
                        restype=c_int64)
    values, steps, times = (c_double * capacity)(), (c_int64 * capacity)(), (c_int64 * capacity)()
    got = get(series.ptr(), slave, ref, 0, capacity, values, steps, times)
    if got < 1 or list(steps[:got]) != list(range(got)):
        raise RuntimeError(f"libcosim returned {got} samples that are not steps 0, 1, 2, …")
    return np.array(values[:got]), np.array(times[:got])
