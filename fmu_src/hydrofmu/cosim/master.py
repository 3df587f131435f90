"""A fixed-step co-simulation master on fmpy for a built scene (its manifest.json).

Algorithms (communication step h, points t_k = k·h):

- ``jacobi``: all FMUs step from t_k with the inputs set at t_k; then every output is
  read and every input set, as libcosim's fixed-step algorithm does.  A load therefore
  reaches the dynamics one step late: F(x_{k-1}) acts over [t_k, t_{k+1}].
- ``gauss-seidel``: at t_k the inputs are set in the manifest's order (load FMUs before
  the dynamics), each from the latest outputs; load FMUs are direct feedthrough, so the
  dynamics receive F(x_k, t_k) — loads evaluated with the motion at t_k — and F(x_k)
  acts over [t_k, t_{k+1}]; then every FMU steps.

Initialisation resolves the feedthrough: connections are transferred twice inside
initialization mode, so at t = 0 every load output reflects the initial motion.
"""
import ctypes
import math
import numbers
import sys
import time as clock
from pathlib import Path

import numpy as np
from fmpy import read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)

from ..admissible import size_problem, whole_steps
from ..errors import InputError
from ..names import unknown
from .manifest import read_manifest
from .result import Result
from .unpacked import unpacked


class RunError(RuntimeError):
    """An FMU call failed during a run: names the instance, the call, the time and the
    FMU's own error messages."""


def run_settings(manifest, step=None, algorithm=None, stop=None):
    """The knobs a run uses: the scene's (its preset's, unless the scene set them) with
    the run's own step/algorithm/stop on top.  ``set``: knobs not from the preset."""
    cfg = manifest["run"]
    out = {k: cfg.get(k) for k in ("preset", "step", "stop", "algorithm", "substep", "load_hold")}
    out["set"] = list(cfg.get("set", []))
    out["chosen"] = list(cfg.get("chosen", []))   # defaults chosen for what the scene holds (scene.run)
    for key, value in (("step", step), ("algorithm", algorithm), ("stop", stop)):
        if value is not None and value != out[key]:
            out[key] = value
            # the run's value replaces the scene's in the list too ("stop (run)", not "stop, stop (run)")
            out["set"] = [k for k in out["set"] if k != key] + [f"{key} (run)"]
    out["couplings"] = manifest.get("couplings", {})
    out["flavour"] = manifest.get("flavour")   # 'python' or 'c': which FMUs ran
    if out["algorithm"] == "ecco":
        from ..scene import ECCO_DEFAULTS
        out["ecco"] = {**ECCO_DEFAULTS, **(cfg.get("ecco") or {})}
    return out


def describe(settings):
    """One line naming the preset (when there is one) and every knob of a run."""
    memory = "; ".join(
        f"{name}: {c['method']}" + (f" tol {c['tolerance']:g}" if c["method"] == "state_space" and not c["order"]
                                    else f" order {c['order']}" if c["order"] else "")
        + (f", memory {c['memory_length']:g} s" if c["memory_length"] else "")
        + (f" (set: {', '.join(c['set'])})" if c["set"] else "")
        for name, c in settings["couplings"].items())
    ecco = settings.get("ecco")
    algorithm = settings["algorithm"] + (
        f" (steps {ecco['min_step']:g}–{ecco['max_step']:g} s, energy tolerance rel {ecco['rel_tolerance']:g}, "
        f"abs {ecco['abs_tolerance']:g} J)" if ecco else "")
    return ((f"preset {settings['preset']}: " if settings["preset"] else "")
            + f"{'first ' if ecco else ''}step {settings['step']:g} s, {algorithm}, "
            f"{settings['load_hold']} load hold, substep {settings['substep']:g} s"
            + (f"; set by the scene/run: {', '.join(settings['set'])}" if settings["set"] else "")
            + (f"; chosen for the scene: {', '.join(settings['chosen'])}" if settings.get("chosen") else "")
            + (f"; memory {memory}" if memory else "")
            + {"python": "; Python flavour (pythonfmu FMUs)", "c": "; compiled flavour (C FMUs)"}.get(
                settings.get("flavour"), ""))


_descriptions = {}   # unzipped FMU folder (named by its content) -> its model description


def _model_description(folder):
    """fmpy's reading of an unzipped FMU's modelDescription.xml, once per process (the
    folder's content never changes: ``cosim.unpacked``)."""
    if folder not in _descriptions:
        _descriptions[folder] = read_model_description(folder)
    return _descriptions[folder]


class Instance:
    """One FMU instance with its value references by name."""

    def __init__(self, name, fmu_path, say=None):
        self.name = name
        self.errors = []   # error/fatal messages the FMU logged (they go into RunError)
        self.say = say     # where its other log lines go (default: stderr)
        self.dir = str(unpacked(fmu_path))   # unzipped once, shared with later runs (cosim.unpacked)
        self.md = _model_description(self.dir)
        self.vr = {v.name: v.valueReference for v in self.md.modelVariables}
        self.causality = {v.name: v.causality for v in self.md.modelVariables}
        self.units = {v.name: v.unit for v in self.md.modelVariables if v.unit}
        self.fmu = FMU2Slave(guid=self.md.guid, unzipDirectory=self.dir,
                             modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName=name)
        # Our own logger, given straight to the FMU: fmpy's default goes through a process-
        # global proxy that any other fmpy user may repoint.  hydrofmu's shim sends literal
        # text with '%' doubled (the message is a printf format for C hosts).
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        try:
            self.fmu.instantiate(callbacks=self.callbacks, loggingOn=False)
        except Exception as exc:   # fmpy: "Failed to instantiate model"
            raise RunError(f"{name}: cannot instantiate {Path(fmu_path).name} ({exc})"
                           + (": " + "; ".join(self.errors) if self.errors else "")) from None
        # outputs that depend on inputs (no dependency list: assume they all do)
        self.feedthrough = any(u.dependencies is None or u.dependencies for u in self.md.outputs)
        # the stepping loop calls the C functions itself: fmpy's wrappers build the value
        # reference array and the result list anew at every call
        dll = self.fmu.dll
        self._get, self._set, self._step = dll["fmi2GetReal"], dll["fmi2SetReal"], dll["fmi2DoStep"]
        self._get.argtypes = self._set.argtypes = [ctypes.c_void_p, ctypes.POINTER(ctypes.c_uint),
                                                   ctypes.c_size_t, ctypes.POINTER(ctypes.c_double)]
        self._step.argtypes = [ctypes.c_void_p, ctypes.c_double, ctypes.c_double, ctypes.c_int]
        self._get.restype = self._set.restype = self._step.restype = ctypes.c_int

    def _log(self, env, instance, status, category, message):
        text = (message or b"").decode("utf-8", "replace").replace("%%", "%")
        if status in (3, 4):   # error, fatal: reported once, in the RunError of the failed call
            self.errors.append(text)
            return
        label = ("OK", "WARNING", "DISCARD", "ERROR", "FATAL", "PENDING")[status] if 0 <= status < 6 else status
        if self.say is not None:
            self.say(f"[{label}] {text}")
        else:
            sys.stderr.write(f"[{label}] {text}\n")

    def outputs(self):
        return [n for n, c in self.causality.items() if c == "output"]

    def port(self, vrs):
        """A preallocated block of Reals (``values``, a numpy view) for ``read``/``write``."""
        return Port(vrs)

    def _check(self, status, function):
        if status > 1:  # above fmi2Warning
            raise FMICallException(function=function, status=status)

    def read(self, port):
        """fmi2GetReal of the port's variables into ``port.values``."""
        self._check(self._get(self.fmu.component, port.vr, port.n, port.buffer), "fmi2GetReal")

    def write(self, port):
        """fmi2SetReal of ``port.values``."""
        self._check(self._set(self.fmu.component, port.vr, port.n, port.buffer), "fmi2SetReal")

    def do_step(self, t, h):
        self._check(self._step(self.fmu.component, t, h, 1), "fmi2DoStep")

    def free(self):
        try:
            self.fmu.terminate()
        except FMICallException:
            pass   # a failed instance may refuse to terminate; it is freed all the same
        finally:
            self.fmu.freeInstance()


class Port:
    """Value references and a C buffer of Reals with a numpy view (``values``) on it."""

    def __init__(self, vrs):
        self.n = len(vrs)
        self.vr = (ctypes.c_uint * self.n)(*[int(v) for v in vrs])
        self.buffer = (ctypes.c_double * self.n)()
        self.values = np.ctypeslib.as_array(self.buffer) if self.n else np.zeros(0)


class Exchange:
    """The per-step traffic of a run, batched: one fmi2GetReal per FMU of every output that
    is connected or recorded, one fmi2SetReal per FMU of all its connected inputs."""

    def __init__(self, system, record):
        inst = system.instances
        reads = {name: set() for name in inst}
        for src, _, svr, _ in system.links:
            reads[src].update(svr.tolist())
        columns = {}
        for j, col in enumerate(record):
            name, var = col.split(".", 1)
            reads[name].add(inst[name].vr[var])
            columns.setdefault(name, ([], []))[0].append(j)
            columns[name][1].append(inst[name].vr[var])
        self.read = {name: inst[name].port(sorted(v)) for name, v in reads.items() if v}
        where = {name: {vr: k for k, vr in enumerate(port.vr)} for name, port in self.read.items()}
        self.record = [(self.read[name].values, np.array(cols), np.array([where[name][v] for v in vrs]))
                       for name, (cols, vrs) in columns.items()]
        self.write, self.gather, self.sources = {}, {}, {}
        for dst in inst:
            links = [(s, svr, dvr) for s, d, svr, dvr in system.links if d == dst]
            if not links:
                continue
            self.write[dst] = inst[dst].port([v for _, _, dvr in links for v in dvr.tolist()])
            at, self.gather[dst] = 0, []
            for s, svr, dvr in links:
                idx = np.array([where[s][v] for v in svr.tolist()])
                self.gather[dst].append((self.read[s].values, idx, slice(at, at + len(dvr))))
                at += len(dvr)
            self.sources[dst] = {s for s, _, _ in links}
        self.instances = inst

    def read_all(self, names=None):
        for name, port in self.read.items():
            if names is None or name in names:
                self.instances[name].read(port)

    def set_inputs(self, name):
        port = self.write[name]
        for values, idx, at in self.gather[name]:
            port.values[at] = values[idx]
        self.instances[name].write(port)

    def resolve(self, order):
        """Gauss–Seidel: set each FMU's inputs in ``order`` from the latest outputs (read
        when first needed, and again when the FMU's own inputs changed them)."""
        fresh = set()
        for inst in order:
            name = inst.name
            if name in self.write:
                stale = self.sources[name] - fresh
                self.read_all(stale)
                fresh |= stale
                self.set_inputs(name)
                if inst.feedthrough:
                    fresh.discard(name)
        self.read_all(set(self.read) - fresh)

    def jacobi(self):
        """Read every output, then set every input (libcosim's fixed-step exchange)."""
        self.read_all()
        for name in self.write:
            self.set_inputs(name)

    def sample(self, row):
        for values, cols, idx in self.record:
            row[cols] = values[idx]


class System:
    """Loaded instances ({name: Instance}, stepped in ``manifest['order']``) and the
    manifest's connections between them; ``parameters`` ({'instance.variable': value})
    are set in initialization mode.  ``load`` gives the System of a built scene,
    ``cosim.inprocess.system`` one of a scene's slaves in this process."""

    def __init__(self, manifest, instances, parameters=None):
        self.manifest, self.instances = manifest, instances
        self.order = manifest["order"]
        self.parameters = parameters or {}
        # links grouped by (source, target): one getReal and one setReal per pair
        links = {}
        for src, svar, dst, dvar in manifest["connections"]:
            links.setdefault((src, dst), ([], []))
            links[(src, dst)][0].append(instances[src].vr[svar])
            links[(src, dst)][1].append(instances[dst].vr[dvar])
        self.links = [(s, d, np.array(a), np.array(b)) for (s, d), (a, b) in links.items()]

    def transfer(self, targets=None):
        """Copy connected outputs to inputs (all reads first, then all writes)."""
        batch = []
        for src, dst, svr, dvr in self.links:
            if targets is None or dst in targets:
                batch.append((dst, dvr, self.instances[src].fmu.getReal(svr)))
        for dst, dvr, values in batch:
            self.instances[dst].fmu.setReal(dvr, values)

    def resolve(self, order):
        """Set every FMU's inputs, in ``order``, from the latest outputs: with load FMUs
        (direct feedthrough) before the dynamics, each load output then reflects the
        dynamics' state at this communication point."""
        for inst in order:
            self.transfer(targets={inst.name})

    def initialize(self, start=0.0):
        for inst in self.instances.values():
            inst.fmu.setupExperiment(startTime=start)
            inst.fmu.enterInitializationMode()
        for key, value in self.parameters.items():
            inst_name, var = key.split(".", 1)
            inst = self.instances[inst_name]
            inst.fmu.setReal([inst.vr[var]], [float(value)])
        self.transfer()
        self.transfer()
        for inst in self.instances.values():
            inst.fmu.exitInitializationMode()

    def units(self, columns):
        """Column 'instance.variable' -> unit, as the instances declare them."""
        out = {}
        for col in columns:
            name, var = col.split(".", 1)
            if var in self.instances[name].units:
                out[col] = self.instances[name].units[var]
        return out

    def free(self):
        for inst in self.instances.values():
            inst.free()
        self.instances = {}


def load(folder, parameters=None, say=None):
    """The System of a built scene's folder (its manifest.json and FMUs), loaded with fmpy;
    ``say``: where the FMUs' warnings go (a callable taking a line; default stderr)."""
    folder = Path(folder)
    manifest = read_manifest(folder)
    instances = {}
    try:
        for name in manifest["order"]:
            instances[name] = Instance(name, folder / manifest["instances"][name]["fmu"], say)
    except Exception:
        for inst in instances.values():
            inst.free()
        raise
    return System(manifest, instances, parameters)


def check_steps(stop, step, algorithm, where, fields=None):
    """The number of steps of a fixed-step run; InputError (naming ``where`` and the field,
    ``fields`` renaming 'stop'/'step', e.g. to '--stop') when ``stop`` is not a whole
    number ≥ 1 of ``step``.  ECCO (adaptive step, ``step`` its first one) ends at the first
    time point at or after ``stop``: any positive stop, None returned."""
    n, problems = whole_steps(stop, step)
    if algorithm == "ecco" and not (problems and problems[0][1].startswith("must")):
        return None
    if problems:
        field, message = problems[0]
        raise InputError(where, None, (fields or {}).get(field, field), message)
    return n


def check_names(names, valid, where, field, what="variable"):
    """InputError naming the first of ``names`` not in ``valid`` with the closest valid names."""
    valid = list(valid)
    known = set(valid)
    for name in names:
        if name not in known:
            raise InputError(where, None, field, unknown(what, name, valid))


def _check_algorithm(algorithm, where):
    if algorithm == "ecco":
        raise InputError(where, None, "algorithm", "ECCO (adaptive step) runs in libcosim only: use --engine "
                         "libcosim (engine='libcosim'), or --algorithm jacobi / gauss-seidel here")
    if algorithm not in ("jacobi", "gauss-seidel"):
        raise InputError(where, None, "algorithm", unknown("algorithm", algorithm, ("jacobi", "gauss-seidel", "ecco")))


def _check_parameters(parameters, manifest):
    """``run``'s parameters: finite numbers, none on a connected input (the master sets it at
    every step: the value would be lost).  Their names are checked once the FMUs are loaded."""
    connected = {f"{dst}.{dvar}": f"{src}.{svar}" for src, svar, dst, dvar in manifest["connections"]}
    for key, value in parameters.items():
        if key in connected:
            raise InputError("run", None, "parameters", f"{key} is an input connected to {connected[key]}: the "
                                                        "master sets it at every step, a value given here would be lost")
        if isinstance(value, bool) or not isinstance(value, numbers.Real) or not math.isfinite(value):
            raise InputError("run", None, "parameters", f"{key} = {value!r}: expected a finite number")


def run(folder, stop=None, step=None, algorithm=None, record=None, parameters=None, progress=None,
        on_step=None, outputs=None, interval=None, sink=None, say=None):
    """Run a built scene (its folder), or a loaded ``System`` (initialised here, left loaded
    for the caller to free; ``parameters`` are then the System's own); returns a Result.

    ``record``: 'instance.variable' columns (default: ``outputs``, else every output of every FMU).
    ``outputs``: output names (``cosim.stream.select``: body names, ``body.position``, …,
    ``instance.variable``; default: the scene's ``[run] outputs``).
    ``interval``: output interval [s], a whole number of steps (default: the scene's
    ``[run] interval``, else every step).
    ``sink``: a ``cosim.stream.Sink``: rows streamed to its files as the run goes (bounded
    memory) and a ``FileResult`` (read from the Parquet file) returned, when it has one.
    ``parameters``: {'instance.variable': value} set in initialization mode.
    ``progress``: print a progress line to stderr (default: when more than 2000 steps).
    ``on_step``: called with the step count after each communication step (benchmarks).
    ``say``: receives each warning line the FMUs log (default: stderr; a batch names its case).
    """
    own = not isinstance(folder, System)
    if own:   # refuse ECCO, and parameters on connected inputs or not numbers, before loading anything
        manifest = read_manifest(folder)
        _check_algorithm(algorithm or manifest["run"]["algorithm"], folder)
        _check_parameters(parameters or {}, manifest)
    system = load(folder, parameters, say) if own else folder
    t, rows, settings = 0.0, None, None
    try:
        cfg = system.manifest["run"]
        stop = cfg["stop"] if stop is None else stop
        step = cfg["step"] if step is None else step
        algorithm = algorithm or cfg["algorithm"]
        _check_algorithm(algorithm, system.manifest.get("source", "run"))
        n = check_steps(stop, step, algorithm, "run")
        variables = [f"{name}.{v}" for name, inst in system.instances.items() for v in inst.vr]
        where, field = ("run", "outputs") if outputs is not None else (system.manifest.get("source", "run"),
                                                                       "run.outputs")
        outputs = cfg.get("outputs") if outputs is None and record is None else outputs
        if record is None and outputs:
            from .stream import select
            record = select(system.manifest, outputs, [f"{name}.{v}" for name, inst in system.instances.items()
                                                       for v in inst.outputs()], where, field)
        if record is None:
            record = [f"{name}.{v}" for name, inst in system.instances.items() for v in inst.outputs()]
        check_names(record, variables, "run", "record", "'instance.variable'")
        from .stream import Recorder, output_every
        thin = output_every(*((interval, step) if interval is not None else (cfg.get("interval"), step,
                                                                              system.manifest.get("source", "run"),
                                                                              "run.interval")))
        if own:
            connected = {f"{dst}.{dvar}" for _, _, dst, dvar in system.manifest["connections"]}
            check_names(system.parameters, [f"{name}.{v}" for name, inst in system.instances.items()
                                            for v, c in inst.causality.items()
                                            if c == "parameter" or (c == "input" and f"{name}.{v}" not in connected)],
                        "run", "parameters", "parameter or unconnected input")
        settings = run_settings(system.manifest, step, algorithm, stop)
        too_big = None if sink is not None else size_problem((n // thin + 1) * (len(record) + 1), 8, "output values")
        if too_big:   # the rows are one array in memory: said before it is allocated, not a MemoryError
            raise InputError(system.manifest.get("source", "run"), None, "run.stop",
                             f"{too_big} ({n // thin + 1:.4g} rows of {len(record)} outputs): record fewer outputs "
                             "(run.outputs), a coarser run.interval, a shorter run.stop, or write to a file (--csv)")
        rows = Recorder(n, step, len(record), thin, sink)
        if sink is not None:
            sink.open(record, system.units(record), system.manifest, {**settings, "output_interval": thin * step})
        progress = n > 2000 if progress is None else progress
        tty = sys.stderr.isatty()
        every = max(1, n // (20 if tty else 4))  # a live line on a terminal, four lines in a log

        exchange = Exchange(system, record)
        system.initialize()
        order = [system.instances[name] for name in system.order]
        if algorithm != "jacobi":
            system.resolve(order)
        exchange.read_all()
        exchange.sample(rows.row(0))
        t0 = clock.perf_counter()
        for k in range(n):
            t = k * step
            for inst in order:
                inst.do_step(t, step)
            if algorithm == "jacobi":
                exchange.jacobi()  # sampled before the exchange, as libcosim's observers see it
            else:
                exchange.resolve(order)
            row = rows.row(k + 1)
            if row is not None:
                exchange.sample(row)
            if on_step is not None:
                on_step(k + 1)
            if progress and (k + 1) % every == 0:
                elapsed = clock.perf_counter() - t0
                line = (f"{system.manifest['scene']}: t = {(k + 1) * step:.1f} s of {stop:g} s "
                        f"({100 * (k + 1) / n:.0f} %, {elapsed:.0f} s elapsed)")
                sys.stderr.write("\r" + line if tty else line + "\n")
                sys.stderr.flush()
        if progress and tty:
            sys.stderr.write("\n")
        if sink is not None:
            rows.flush()
            sink.close()
            done, sink = sink, None
            if done.parquet:
                from .stream import read_parquet
                result = read_parquet(done.written[done.parquet])
            else:
                from .result import read_csv
                result = read_csv(done.written[done.csv], system.manifest)
            result.written = dict(done.written)
            return result
        return Result(np.arange(0, n + 1, thin) * step, list(record), rows.values, algorithm, thin * step,
                      system.manifest["dynamics"], settings, system.units(record), system.manifest)
    except FMICallException as exc:
        err = RunError(failure(system, exc, t) + advice(system.manifest["run"], settings, stop))
        # what the run computed up to the failure is kept: the rows streamed so far (in place of
        # the files asked for, said in the message), else the rows in memory (``err.partial``)
        err.partial, err.written = None, {}
        if rows is not None and sink is not None:
            rows.flush()
            sink.close()
            err.written, sink = dict(sink.written), None
            err.args = (err.args[0] + f"; the results up to t = {t:g} s are kept in "
                        + ", ".join(str(p) for p in err.written.values()),)
        elif rows is not None and rows.used:
            err.partial = Result(rows.time[:rows.used].copy(), list(record), rows.values[:rows.used].copy(), algorithm,
                                 thin * step, system.manifest["dynamics"], settings, system.units(record),
                                 system.manifest)
        raise err from None
    finally:
        if sink is not None:   # the run failed: no half-written file under the asked name
            sink.close(ok=False)
        if own:
            system.free()


_STATUS = {1: "warning", 2: "discard", 3: "error", 4: "fatal"}


def advice(cfg, settings, stop):
    """The likely cause of a failed run and the knob that would have held it (docs/tuning.md):
    the constant load hold (its half-step lag drives modes whose restoring is a load input),
    a step past the linear hold's damping budget, no ramp on the waves."""
    from ..physics.hold import damping_change, stable_step
    if not settings:
        return ""
    tips = []
    omega = cfg.get("restoring_omega")
    hold, step = settings["load_hold"], settings["step"]
    if hold == "constant" and (omega or cfg.get("waves") or settings.get("couplings")):
        lag = f" (−{100 * -float(damping_change(omega, step, 'constant')):.2g} % of critical at {omega:.3g} rad/s)" \
            if omega else ""
        tips.append(f'[run] load_hold = "linear": the constant hold lags the loads by half a step and takes '
                    f"ω·h/4 of critical damping from every mode whose restoring is a load input{lag}, more than "
                    "radiation gives roll and pitch")
    if omega and hold == "linear":
        good = stable_step(omega, stop or cfg["stop"])
        if good < step:
            tips.append(f"[run] step = {good:g}: at {step:g} s the linear hold takes "
                        f"{100 * -float(damping_change(omega, step, 'linear')):.2g} % of critical damping at "
                        f"{omega:.3g} rad/s")
    waves = cfg.get("waves")
    if waves and not waves.get("ramp"):
        tips.append(f"[waves] ramp = {3 * waves['period']:g}: a start without a ramp kicks the body")
    return ("; likely cause and the knob that would have held it: " + "; or ".join(tips)) if tips else ""


def failure(system, exc, t):
    """One line for a failed FMU call: the call, the time and what each FMU logged."""
    logged = [msg if msg.startswith(name) else f"{name}: {msg}" for name, inst in system.instances.items()
              for msg in inst.errors]
    return f"{exc.function} failed at t = {t:g} s ({_STATUS.get(exc.status, exc.status)})" + (
        ": " + "; ".join(logged) if logged else "")
