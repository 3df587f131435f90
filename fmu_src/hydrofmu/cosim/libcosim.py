"""Run a built scene in libcosim (the Open Simulation Platform's engine) via libcosimpy.

libcosim's fixed-step algorithm is a Jacobi scheme: all slaves step, then outputs are
copied to inputs.  So its results equal hydrofmu's fmpy master in ``jacobi`` mode, and a
run asked to be Gauss–Seidel (by the scene or the caller) is refused rather than quietly
run as Jacobi.  libcosim counts time in integer nanoseconds.
"""
import json
from pathlib import Path

import numpy as np

from ..errors import InputError
from .master import run_settings
from .result import Result, column_units

NS = 1_000_000_000


def run(folder, stop=None, step=None, record=None, algorithm=None):
    """Run the scene built in ``folder`` (its manifest.json) in libcosim; returns a Result
    with the same columns as cosim.master.run (default: every output of every FMU).
    ``algorithm`` (default: the scene's) must be 'jacobi': InputError otherwise."""
    from libcosimpy.CosimEnums import CosimVariableType
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    from libcosimpy.CosimObserver import CosimObserver
    from libcosimpy.CosimSlave import CosimLocalSlave

    log_output_level(CosimLogLevel.WARNING)
    folder = Path(folder)
    manifest = json.loads((folder / "manifest.json").read_text())
    wanted = algorithm or manifest["run"]["algorithm"]
    if wanted != "jacobi":
        where = "--algorithm" if algorithm else folder / "manifest.json"
        raise InputError(where, None, "algorithm", f"libcosim's fixed-step master is a Jacobi scheme and cannot "
                         f"run '{wanted}' (the scene's or the run's choice); run with the fmpy engine, "
                         "or ask for Jacobi explicitly (--algorithm jacobi, algorithm='jacobi')")
    stop = manifest["run"]["stop"] if stop is None else stop
    step = manifest["run"]["step"] if step is None else step
    step_ns = int(round(step * NS))
    n = int(round(stop / step))

    execution = CosimExecution.from_step_size(step_size=step_ns)
    index, refs, outputs = {}, {}, {}
    for name in manifest["order"]:
        fmu = str((folder / manifest["instances"][name]["fmu"]).resolve())
        slave = CosimLocalSlave(fmu_path=fmu, instance_name=name)
        index[name] = execution.add_local_slave(slave)
        if index[name] < 0:
            raise RuntimeError(f"libcosim could not load {fmu}")
        variables = execution.slave_variables(index[name])
        refs[name] = {v.name.decode(): v.reference for v in variables}
        outputs[name] = [v.name.decode() for v in variables if v.causality == 2]  # 2 = output
    for src, svar, dst, dvar in manifest["connections"]:
        if execution.connect_real_variables(index[src], refs[src][svar], index[dst], refs[dst][dvar]) is False:
            raise RuntimeError(f"libcosim could not connect {src}.{svar} -> {dst}.{dvar}")
    if record is None:
        record = [f"{name}.{var}" for name in manifest["order"] for var in outputs[name]]

    series = CosimObserver.create_time_series(buffer_size=n + 2)
    execution.add_observer(series)
    for col in record:
        name, var = col.split(".", 1)
        series.start_time_series(index[name], refs[name][var], CosimVariableType.REAL)
    if not execution.simulate_until(target_time=n * step_ns):
        raise RuntimeError("libcosim stopped before the end time (an FMU reported an error)")

    values = np.empty((n + 1, len(record)))
    for j, col in enumerate(record):
        name, var = col.split(".", 1)
        values[:, j] = _samples(series, index[name], refs[name][var], n)
    return Result(np.arange(n + 1) * step, list(record), values, "libcosim", step, manifest["dynamics"],
                  run_settings(manifest, step, "jacobi", stop), column_units(folder, manifest, record), manifest)


def _samples(series, slave, ref, n):
    """Values at steps 0..n of one time series.  Called through the C API directly:
    libcosimpy's wrapper trims its result by counting step numbers equal to 0, which
    drops the initial sample."""
    from ctypes import POINTER, c_double, c_int, c_int64, c_size_t, c_uint32
    from libcosimpy._internal import libcosimc, wrap_function
    from libcosimpy.CosimObserver import CosimObserver

    count = n + 1
    get = wrap_function(lib=libcosimc(), funcname="cosim_observer_slave_get_real_samples",
                        argtypes=[POINTER(CosimObserver), c_int, c_uint32, c_int64, c_size_t,
                                  c_double * count, c_int64 * count, c_int64 * count],
                        restype=c_int64)
    values, steps, times = (c_double * count)(), (c_int64 * count)(), (c_int64 * count)()
    got = get(series.ptr(), slave, ref, 0, count, values, steps, times)
    if got != count or list(steps) != list(range(count)):
        raise RuntimeError(f"libcosim returned {got} samples for {count} communication points")
    return np.array(values[:])
