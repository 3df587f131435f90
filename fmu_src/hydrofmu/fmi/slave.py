"""pythonfmu slaves: the FMI face of the physics kernels.

Every Real of a slave lives in one numpy array indexed by value reference, so
fmi2GetReal/fmi2SetReal are one fancy-indexing each.  Variables are registered next to
the state they expose, with their unit and, for outputs, the inputs they depend on
(the build writes both into modelDescription.xml).

Load outputs are direct feedthrough: setting an input marks the outputs stale, and the
next fmi2GetReal (or fmi2DoStep) evaluates the kernels with the inputs as they are now.
Nothing raises into the host: pythonfmu 0.7 turns any Python exception in a callback into
fmi2Fatal, so every entry point is ``guarded``: a failure, a non-finite input or output,
a parameter set after initialization, a time jump, a bad FMU state is one error log line
naming the variable, and hydrofmu's binary shim returns fmi2Error for any call that
logged an error (and for fmi2DoStep's False, which pythonfmu reports as fmi2Discard).
"""
import functools
import json
import math
import os
import sys

if "numpy" not in sys.modules:
    # A host without numpy of its own (a native FMI host): BLAS starts here, one thread per
    # process.  A host's parallelism is across FMUs; these settings only take effect before
    # numpy loads, and a Python host's numpy is its own business (the slaves make no BLAS
    # call big enough to thread: no fit at instantiation, 6×6-sized products per step).
    for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
        os.environ.setdefault(_name, "1")

import numpy as np  # noqa: E402


def _light_pythonfmu():
    """Let the slave import pythonfmu's slave API without pythonfmu's package __init__,
    which imports its FMU builder (argparse, zipfile, shutil, xml.dom…: ~25 ms of the
    ~35 ms import, paid by every host that starts an FMU).  Unless pythonfmu is loaded
    already, the package module goes into sys.modules unexecuted; its submodules import as
    usual (in an FMU, from its runtime zip: fmi/runtime_zip.py, which also lists pythonfmu's
    copies on disk in ``__path__`` for the modules the zip does not hold); the first use of
    anything else (``pythonfmu.FmuBuilder``…) runs the real __init__ in it (PEP 562 module
    __getattr__)."""
    import importlib.util
    if "pythonfmu" in sys.modules:
        return
    spec = importlib.util.find_spec("pythonfmu")
    if spec is None or spec.loader is None or spec.submodule_search_locations is None:
        return
    pkg = importlib.util.module_from_spec(spec)

    def rest(name):
        del pkg.__dict__["__getattr__"]
        spec.loader.exec_module(pkg)
        return getattr(pkg, name)

    pkg.__getattr__ = rest
    sys.modules["pythonfmu"] = pkg


_light_pythonfmu()
from pythonfmu.enums import Fmi2Causality, Fmi2Initial, Fmi2Status, Fmi2Variability  # noqa: E402
from pythonfmu.fmi2slave import Fmi2Slave  # noqa: E402
from pythonfmu.variables import Real  # noqa: E402

from .. import description  # noqa: E402
from ..physics import quiet
from ..physics.joint import BallJoint
from ..physics.loads import BodyLoads, make_effect
from ..physics.lumped import LumpedBody
from ..physics.memory import StateSpace
from ..physics.rigid_body import CAPSIZE, LINEAR_RANGE, CoupledBodies, GimbalLockError, RigidBody
from ..physics.current import CurrentProfile
from ..physics.state import Env, Motion
from ..physics.waves import Phasors, WaveLoad, components as wave_components

# the sea-state knobs each spectrum exposes as waves.* parameters: (unit, description)
WAVE_KNOBS = {
    "height": ("m", "regular wave height H (crest to trough)"),
    "period": ("s", "regular wave period T"),
    "phase": ("deg", "regular wave phase at the global origin, t = 0"),
    "hs": ("m", "significant wave height Hs = 4·sqrt(m0)"),
    "tp": ("s", "spectral peak period Tp"),
    "gamma": (None, "JONSWAP peak enhancement factor (>= 1)"),
    "direction": ("deg", "wave direction, 'going to', counter-clockwise from global +x"),
    "spreading": (None, "cos-2s spreading exponent s (0: long-crested)"),
    "components": (None, "number of wave components"),
    "seed": (None, "random seed of frequencies, phases and directions"),
    "ramp": ("s", "length of the smooth start ramp"),
}
SPECTRUM_KNOBS = {"regular": ("height", "period", "phase", "direction", "ramp"),
                  "jonswap": ("hs", "tp", "gamma", "direction", "spreading", "components", "seed", "ramp"),
                  "pierson_moskowitz": ("hs", "tp", "direction", "spreading", "components", "seed", "ramp")}

AXES = ("x", "y", "z", "rx", "ry", "rz")


def _finite(values):
    """True if the sum of a short list of floats is finite (all are, barring an overflow of
    the sum; callers then look closer).  On a list: numpy's reductions cost ~2 µs a call."""
    return math.isfinite(sum(values))
LIN_ROT = {
    "velocity": ["m/s"] * 3 + ["rad/s"] * 3,
    "acceleration": ["m/s2"] * 3 + ["rad/s2"] * 3,
    "force": ["N"] * 3 + ["N.m"] * 3,
}
MASS_UNITS = [["kg"] * 3 + ["kg.m"] * 3] * 3 + [["kg.m"] * 3 + ["kg.m2"] * 3] * 3


def guarded(fallback=None, computes=True):
    """An FMI entry point that never raises: an exception is logged as an error (the shim
    then returns fmi2Error) and ``fallback(self, *args)`` is returned instead.  Floating-
    point warnings are off inside (non-finite results are checked, not warned), unless the
    entry point ``computes`` nothing (fmi2SetReal, a read of values already computed): the
    context variable costs ~0.4 µs per call on the per-step path."""
    def wrap(method):
        @functools.wraps(method)
        def call(self, *args):
            token = quiet.off() if computes else None
            try:
                return method(self, *args)
            except Exception as exc:
                self.fail(f"{method.__name__}: {type(exc).__name__}: {exc}")
                return fallback(self, *args) if fallback else None
            finally:
                if token is not None:
                    quiet.restore(token)
        return call
    return wrap


def start(slave, init, kwargs):
    """Run a slave's constructor for pythonfmu without letting an exception out.

    pythonfmu 0.7 answers an exception in the constructor (in fmi2Instantiate, or in the
    fmi2Reset with which the shim reuses an instance) by releasing the slave's class and
    message list, and releases them again when the instance is freed: in a Python host that
    corrupts the heap (a crash later, anywhere).  The failure is logged as an error instead
    and kept in ``slave.broken``; the shim then fails fmi2Instantiate with that message."""
    try:
        init(**kwargs)
    except Exception as exc:
        if not hasattr(slave, "log_queue"):   # pythonfmu's part did not run: its queue first
            Fmi2Slave.__init__(slave, **kwargs)
        slave.broken = exc
        slave.log(f"{kwargs.get('instance_name')}: cannot start: {type(exc).__name__}: {exc}",
                  Fmi2Status.error)
        # the shim reads pythonfmu's queued messages with an empty fmi2GetReal: answered here,
        # so that the one line above stays the host's only line about it
        slave.get_real = lambda vrs: [math.nan] * len(vrs)


class ArraySlave(Fmi2Slave):
    """Base slave: Reals in one array, units and output dependencies recorded."""

    author = "hydrofmu"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.config = description.read(self.resources)   # this FMU's typed description
        self.description = self.config.description
        self._start = []        # start values while registering
        self.unknown_start = set()   # inputs whose value at t = 0 the build cannot know (start 0)
        self.units = {}         # variable name -> unit
        self.dependencies = {}  # output name -> input names
        self.error = None       # message of a bad input seen since the last step
        self._inputs, self._params, self._outputs = [], [], []   # value references by causality
        self.running = False    # after exit_initialization_mode: parameters are fixed
        self.next_time = None   # the communication point the next fmi2DoStep must start from
        self.checked = False    # outputs known finite (set by an evaluation that checked them all)
        self._finite_idx = {}   # check_finite: id of a list of input slices -> (it, its value indices)
        self._vr_idx = {}       # tuple of value references -> (index array, settable in/after initialization)
        self._vr_last = {}      # "get"/"set" -> (the last list of value references, its _vr_idx entry)
        self.suspect = True     # inputs may be non-finite (set since the last check found them finite)

    # -- registration ------------------------------------------------------------------
    def add(self, name, causality, unit=None, start=0.0, description=None):
        vr = len(self._start)
        self._start.append(float(start))
        kw = {"causality": causality, "description": description,
              "getter": lambda: self.values[vr]}
        if causality in (Fmi2Causality.input, Fmi2Causality.parameter):
            kw["setter"] = lambda v: self.values.__setitem__(vr, v)
        if causality == Fmi2Causality.parameter:
            kw["variability"] = Fmi2Variability.fixed
        elif causality == Fmi2Causality.calculatedParameter:
            kw.update(variability=Fmi2Variability.fixed, initial=Fmi2Initial.calculated)
        self.register_variable(Real(name, **kw), nested=False)
        {Fmi2Causality.input: self._inputs, Fmi2Causality.parameter: self._params,
         Fmi2Causality.output: self._outputs}.get(causality, []).append(vr)
        if unit:
            self.units[name] = unit
        return vr

    def add_vector(self, name, n, causality, units, start=None, description=None):
        """Register name[1..n]; returns the slice of the value array."""
        start = np.zeros(n) if start is None else np.asarray(start, dtype=float)
        units = units if isinstance(units, (list, tuple)) else [units] * n
        first = len(self._start)
        for i in range(n):
            self.add(f"{name}[{i + 1}]", causality, units[i], start[i],
                     description if i == 0 else None)
        return slice(first, first + n)

    def add_motion(self, prefix, state, acceleration=False, who="reference point"):
        """Motion inputs <prefix>position/attitude/velocity[/acceleration], starting at
        ``state``'s (position, attitude, velocity: the body at t = 0); returns their slices."""
        In = Fmi2Causality.input
        slices = [
            self.add_vector(f"{prefix}position", 3, In, "m", state.position, f"{who} position, global axes"),
            self.add_vector(f"{prefix}attitude", 3, In, "rad", state.attitude,
                            "roll, pitch, yaw; R = Rz(yaw) Ry(pitch) Rx(roll)"),
            self.add_vector(f"{prefix}velocity", 6, In, LIN_ROT["velocity"], state.velocity,
                            f"{who} velocity and angular velocity, global axes"),
        ]
        if acceleration:
            slices.append(self.add_acceleration(f"{prefix}acceleration", f"{who} acceleration, global axes"))
        return slices

    def add_acceleration(self, name, description):
        """An acceleration input name[1..6]: its value at t = 0 follows from the loads at t = 0,
        which in explicit mode depend on it, so the build cannot know it: start 0, listed in
        ``unknown_start`` (the start-value check skips it)."""
        s = self.add_vector(name, 6, Fmi2Causality.input, LIN_ROT["acceleration"], None, description)
        self.unknown_start.update(f"{name}[{i}]" for i in range(1, 7))
        return s

    def add_environment(self, uses_current):
        """current.speed/direction inputs (if used) and rho, g parameters."""
        env = self.config.environment
        self.current = None
        self.profile = None if env.current_profile is None else CurrentProfile.from_rows(env.current_profile)
        if uses_current:
            self.current = slice(len(self._start), len(self._start) + 2)
            if self.profile is None:
                self.add("current.speed", Fmi2Causality.input, "m/s", env.current_speed, "uniform current speed")
                self.add("current.direction", Fmi2Causality.input, "deg", env.current_direction,
                         "current 'going to' direction, counter-clockwise from global +x")
            else:
                self.add("current.speed", Fmi2Causality.input, "m/s", env.current_speed,
                         "current speed at the surface; scales every level of the profile")
                self.add("current.direction", Fmi2Causality.input, "deg", env.current_direction,
                         "current 'going to' direction at the surface, counter-clockwise from global +x; "
                         "turns every level of the profile")
        self.rho = self.add("rho", Fmi2Causality.parameter, "kg/m3", env.rho, "water density")
        self.g = self.add("g", Fmi2Causality.parameter, "m/s2", env.g, "acceleration of gravity")
        self._env_vals = slice(self.current.start if self.current else self.rho, self.g + 1)   # registered together
        return [self.current] if self.current else []

    def add_matrix(self, name, causality, matrix, description):
        first = len(self._start)
        matrix = np.asarray(matrix, dtype=float)
        for i in range(6):
            for j in range(6):
                self.add(f"{name}[{i + 1},{j + 1}]", causality, MASS_UNITS[i][j], matrix[i, j],
                         description if i == j == 0 else None)
        return slice(first, first + 36)

    def add_mass_export(self, name, matrix):
        """Calculated parameters name[i,j]: a 6×6 mass contribution for the dynamics side."""
        return self.add_matrix(name, Fmi2Causality.calculatedParameter, matrix,
                               "exported added/point mass about the reference point, global axes (row = load dof)")

    def motion(self, slices, values=None):
        v = self.values if values is None else values
        acc = v[slices[3]] if len(slices) > 3 else np.zeros(6)
        return Motion(v[slices[0]], v[slices[1]], v[slices[2]], acc)

    def env(self):
        """Env of the current values (the same object while they do not change)."""
        key = self.values[self._env_vals].tolist()   # [current speed, direction,] rho, g
        if key != getattr(self, "_env_key", None):
            self._env_key, self._env = key, Env(key[-2], key[-1], *(key[:-2] or (0.0, 0.0)), self.profile)
        return self._env

    def finish_registration(self):
        self.values = np.array(self._start, dtype=float)
        self.output_vrs = np.array(self._outputs, dtype=int)
        self.settable = set(self._inputs) | set(self._params)
        self.settable_running = set(self._inputs)   # parameters are fixed after initialization

    def depends(self, outputs, inputs):
        names = [self.vars[vr].name for s in inputs for vr in range(s.start, s.stop)]
        for s in outputs:
            for vr in range(s.start, s.stop):
                self.dependencies[self.vars[vr].name] = names

    # -- FMI ---------------------------------------------------------------------------
    def fail(self, message):
        """Log one error line for the host (the shim turns the call's status into fmi2Error)."""
        self.log(f"{self.instance_name}: {message}", Fmi2Status.error)

    @guarded()
    def setup_experiment(self, start_time, stop_time=None, tolerance=None):
        self.next_time = float(start_time)

    @guarded()
    def enter_initialization_mode(self):
        pass

    @guarded()
    def exit_initialization_mode(self):
        self.running = True   # (before: an FMU whose physics cannot start fails its steps too, as in C)
        self.start_physics()

    def start_physics(self):
        pass

    @guarded()
    def terminate(self):
        pass

    def _refs(self, vrs, call):
        """(index array, settable in initialization, settable after it) of a ``call``'s value
        references: cached by their tuple, since a master passes the same ones every step
        (numpy's conversion of a list costs ~1 µs), and the last list of each call kept to
        compare with the next (cheaper than hashing a tuple)."""
        last = self._vr_last.get(call)
        if last is not None and type(vrs) is list and last[0] == vrs:
            return last[1]
        key = tuple(vrs)
        known = self._vr_idx.get(key)
        if known is None:
            if len(self._vr_idx) > 64:
                self._vr_idx.clear()
            idx = np.array(key, dtype=np.intp)
            if idx.size and not (0 <= idx.min() and idx.max() < self.values.size):
                raise IndexError(f"value reference out of range 0…{self.values.size - 1}: {list(key)}")
            known = self._vr_idx[key] = (idx, self.settable.issuperset(key), self.settable_running.issuperset(key))
        self._vr_last[call] = (list(key), known)
        return known

    @guarded(lambda self, vrs: [math.nan] * len(vrs), computes=False)
    def get_real(self, vrs):
        idx = self._refs(vrs, "get")[0]
        if self.stale:   # the one computing case: warnings off around it
            token = quiet.off()
            try:
                self.evaluate()
            finally:
                quiet.restore(token)
        if self.error is not None:   # kept: the next fmi2DoStep fails on it too
            self.fail(self.error)
            return self.values[idx].tolist()
        out = self.values[idx].tolist()
        if not _finite(out):
            self.check_outputs(idx)
        return out

    @guarded(computes=False)
    def set_real(self, vrs, values):
        idx, settable, settable_running = self._refs(vrs, "set")
        if not (settable_running if self.running else settable):
            fixed = [vr for vr in vrs if vr not in self.settable or (self.running and vr in self._params)]
            var = self.vars[fixed[0]]
            why = ("a parameter, fixed after initialization" if var.causality == Fmi2Causality.parameter
                   else f"not settable ({var.causality.name})")
            self.fail(f"cannot set {var.name}: {why}")
            return
        self.values[idx] = values
        if not self.suspect:
            self.suspect = not _finite(values.tolist() if isinstance(values, np.ndarray) else values)
        self.stale = True
        self.error = None   # new inputs: the next evaluation checks them afresh

    def check_outputs(self, vrs=None):
        """Log an error naming the first non-finite value among ``vrs`` (default: every
        output); True when all are finite."""
        if vrs is None and self.checked:
            return True
        vrs = self.output_vrs if vrs is None else vrs
        out = self.values[vrs]
        if _finite(out.tolist()) or np.isfinite(out).all():
            return True
        var = self.vars[int(np.asarray(vrs)[np.argmin(np.isfinite(out))])]
        self.fail(f"{var.causality.name} {var.name} = {self.values[var.value_reference]} is not finite")
        return False

    # other types: hydrofmu has only Reals; an unknown reference is an error, not a crash
    @guarded(lambda self, vrs: [0] * len(vrs))
    def get_integer(self, vrs):
        return super().get_integer(vrs)

    @guarded(lambda self, vrs: [False] * len(vrs))
    def get_boolean(self, vrs):
        return super().get_boolean(vrs)

    @guarded(lambda self, vrs: [""] * len(vrs))
    def get_string(self, vrs):
        return super().get_string(vrs)

    @guarded()
    def set_integer(self, vrs, values):
        return super().set_integer(vrs, values)

    @guarded()
    def set_boolean(self, vrs, values):
        return super().set_boolean(vrs, values)

    @guarded()
    def set_string(self, vrs, values):
        return super().set_string(vrs, values)

    def check_finite(self, slices):
        """Record an error naming the first non-finite input; True if all are finite."""
        known = self._finite_idx.get(id(slices))
        if known is not None and known[0] is slices:   # the same list as before: its indices
            idx = known[1]
        else:
            idx = np.r_[tuple(slices)] if slices else np.zeros(0, int)
            self._finite_idx[id(slices)] = (slices, idx)
        if _finite(self.values[idx].tolist()):   # one sum; the search below only on failure
            return True
        for s in slices:
            block = self.values[s]
            if not np.all(np.isfinite(block)):
                vr = s.start + int(np.argmin(np.isfinite(block)))
                self.error = f"input {self.vars[vr].name} = {self.values[vr]} is not finite"
                return False
        return True

    @guarded(lambda self, *_: False)
    def do_step(self, current_time, step_size):
        expected = self.next_time
        if not (step_size > 0 and math.isfinite(step_size)):
            self.error = f"communication step {step_size} must be positive and finite"
        elif expected is not None and abs(current_time - expected) > 1e-6 * step_size + 1e-12 * abs(expected):
            self.error = (f"communication point {current_time!r} is not where the last step ended "
                          f"({expected!r}); restore an FMU state (fmi2SetFMUstate) to go back or forward")
        try:
            if self.stale and self.error is None:
                self.evaluate()
            if self.error is None:
                if not self.check_outputs():      # logged: the step starts from non-finite outputs
                    return False
                self.step_physics(current_time, step_size)
                if not self.stale and not self.check_outputs():
                    return False
        except Exception as exc:  # never let a Python exception reach the C host
            self.error = f"{type(exc).__name__}: {exc}"
        if self.error is not None:
            self.fail(f"at t={current_time}: {self.error}")
            self.error = None
            return False
        self.next_time = current_time + step_size
        return True

    def evaluate(self):
        self.stale = False

    def step_physics(self, t, dt):
        pass

    # FMU state: the value array, the time and whatever the slave's physics holds, as plain
    # JSON values (fmi2SerializeFMUstate writes it as JSON).
    @guarded(lambda self: {"invalid": "the FMU state could not be taken"})
    def _get_fmu_state(self):
        return _plain({"values": self.values, "physics": self.physics_state(), "next_time": self.next_time,
                       "running": self.running})

    @guarded()
    def _set_fmu_state(self, state):
        if not isinstance(state, dict) or "invalid" in state or len(state.get("values", ())) != self.values.size:
            why = state.get("invalid") if isinstance(state, dict) and "invalid" in state else "wrong size or kind"
            self.fail(f"fmi2SetFMUstate: not a state of this FMU ({why})")
            return
        self.values[:] = state["values"]
        self.set_physics_state(state["physics"])
        self.next_time, self.running = state["next_time"], state["running"]
        self.stale, self.checked, self.suspect = True, False, True
        self.error = None

    @staticmethod
    def _fmu_state_to_bytes(state):
        return json.dumps(state).encode("utf-8")

    @staticmethod
    def _fmu_state_from_bytes(data):
        try:
            state = json.loads(data.decode("utf-8"))
            return state if isinstance(state, dict) else {"invalid": "not a hydrofmu FMU state"}
        except (UnicodeDecodeError, ValueError):   # garbage bytes: refused by _set_fmu_state
            return {"invalid": "the bytes are not a serialized hydrofmu FMU state"}

    def physics_state(self):
        return None

    def set_physics_state(self, state):
        pass

    # the scene's waves (load and connector FMUs): the waves.* parameters, one Phasors a step

    def _add_waves(self, cfg):
        """The sea-state parameters waves.* (start values: the scene's), the excitation's
        outputs <name>.force, <name>.elevation (with an excitation) and each named point's
        waves.<point>.velocity, acceleration, pressure, elevation; returns [the force slice] or []."""
        self.wave, self.wave_cfg, self.phasors, self.water, self.kin = None, cfg, None, None, None
        self.points = []
        self.kin_wanted = cfg is not None and (cfg.kinematics or bool(cfg.points))
        if cfg is None:
            return []
        Par, Out = Fmi2Causality.parameter, Fmi2Causality.output
        self.wave_knobs = {k: self.add(f"waves.{k}", Par, WAVE_KNOBS[k][0], cfg.sea[k], WAVE_KNOBS[k][1])
                           for k in SPECTRUM_KNOBS[cfg.spectrum]}
        for name, where in cfg.points.items():
            on_body = "offset" in where
            what = f"at point {name} ({'on the body' if on_body else 'fixed'})"
            first = self.add_vector(f"waves.{name}.velocity", 3, Out, "m/s", None,
                                    f"incident-wave particle velocity {what}, global axes")
            self.add_vector(f"waves.{name}.acceleration", 3, Out, "m/s2", None,
                            f"incident-wave particle acceleration (local, du/dt) {what}, global axes")
            self.add(f"waves.{name}.pressure", Out, "Pa", 0.0, f"incident-wave dynamic pressure {what}")
            self.add(f"waves.{name}.elevation", Out, "m", 0.0, f"incident-wave elevation above point {name}")
            block = slice(first.start, first.start + 8)
            self.points.append((np.asarray(where.get("offset", where.get("position")), float), on_body, block))
            self.depends([block], self.motion_inputs[:2] if on_body else [])
        if cfg.name is None:
            return []
        force = self.add_vector(f"{cfg.name}.force", 6, Out, LIN_ROT["force"], None,
                                "first-order wave excitation, global axes, about the reference point")
        self.elevation = self.add(f"{cfg.name}.elevation", Out, "m", 0.0,
                                  "wave elevation at the reference point's mean position")
        self.depends([force, slice(self.elevation, self.elevation + 1)], [])
        return [force]

    def _ready(self):
        """Whether an evaluation may go on: its inputs finite (checked when one set since the
        last check may not be) and its sea started; False after setting ``self.error``."""
        if self.suspect:
            if not self.check_finite(self.inputs):
                return False
            self.suspect = False
        if self.wave_cfg is not None and self.phasors is None and self.running:
            try:   # (initialization failed on the sea state: no step goes on without its waves)
                self._start_waves()
            except ValueError as exc:
                self.error = f"the waves.* parameters are not a usable sea state ({exc})"
                return False
        return True

    def _start_waves(self):
        """The phasors, excitation and kinematics of the sea state the waves.* parameters hold
        now (one error naming the knob when they are not a usable sea state)."""
        from ..physics.wave_kinematics import Water, WaveKinematics
        cfg = self.wave_cfg
        knobs = {k: float(self.values[vr]) for k, vr in self.wave_knobs.items()}
        for k in ("components", "seed"):
            if k in knobs and knobs[k] == int(knobs[k]):
                knobs[k] = int(knobs[k])
        sea = cfg.sea_state(**knobs)
        g = float(self.values[self.g])
        try:
            sea.check()
            comps = wave_components(sea, tuple(cfg.window) if cfg.window else (0.0, math.inf))
            self.phasors = Phasors(comps, sea.ramp)
            transfer = cfg.transfer(g, sea.depth)
            self.wave = None if transfer is None else WaveLoad(comps, transfer, cfg.position, sea.ramp, g, sea.depth,
                                                               phasors=self.phasors)
            # the points and the effects each their own kernel: each keeps the factors of its last points
            self.kin = WaveKinematics(comps, g, sea.depth, sea.stretching) if self.points else None
            self.water = (Water(WaveKinematics(comps, g, sea.depth, sea.stretching), self.phasors,
                                float(self.values[self.rho])) if cfg.kinematics else None)
            drift = getattr(self, "drift_cfg", None)   # a load FMU's wave drift: the same components
            self.drift = drift.kernel(comps, g, sea.depth) if drift is not None else None
        except ValueError as exc:
            self.phasors = self.wave = self.water = self.kin = self.drift = None
            raise ValueError(f"waves.{getattr(exc, 'field', 'sea state')}: {exc}") from None


class LoadSlave(ArraySlave):
    """Loads on one floating body: motion in, force out (global axes, about the
    reference point), one output group per effect plus the total."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        cfg = self.config
        explicit = cfg.accel_mode == "explicit"
        self.loads = BodyLoads([make_effect(e.type, e.name, e.data) for e in cfg.effects], explicit)
        Out, In = Fmi2Causality.output, Fmi2Causality.input
        own_acc = explicit and (self.loads.uses_acceleration or any(c.own for c in cfg.couplings))
        self.motion_inputs = self.add_motion("", cfg, own_acc)
        inputs = self.motion_inputs + self.add_environment(self.loads.uses_current)
        # hydrodynamic couplings: the source body's velocity (and acceleration) in
        self.couplings = []
        for c in cfg.couplings:
            src = c.source
            vel = self.motion_inputs[2] if c.own else self.add_vector(
                f"{src}.velocity", 6, In, LIN_ROT["velocity"], c.velocity, f"velocity of coupled body {src}, global")
            acc = None
            if explicit:
                acc = self.motion_inputs[3] if c.own else self.add_acceleration(
                    f"{src}.acceleration", f"acceleration of coupled body {src}, global")
            out = self.add_vector(f"{c.name}.force", 6, Out, LIN_ROT["force"], None,
                                  f"hydrodynamic coupling {c.name} (from {src}'s motion)")
            self.couplings.append({"cfg": c, "velocity": vel, "acceleration": acc, "force": out,
                                   "mass": c.mass})
            inputs = inputs + [s_ for s_ in (vel, acc) if s_ is not None and s_ not in inputs]
        self.force = self.add_vector("force", 6, Out, LIN_ROT["force"], None,
                                     "total load on the body, global axes, moments about the reference point")
        self.effect_force = [self.add_vector(f"{e.name}.force", 6, Out, LIN_ROT["force"], None,
                                             f"load of effect {e.name}")
                             for e in self.loads.effects]
        self.depends([self.force] + self.effect_force + [c["force"] for c in self.couplings], inputs)
        self.inputs = inputs
        wave_force = self._add_waves(cfg.waves)
        self._wave_row = int(bool(wave_force))   # the output block's rows after the couplings: the excitation,
        wave_force = wave_force + self._add_drift(getattr(cfg, "drift", None))   # then the drift
        # every load output in one block: total, each effect, each coupling, the waves
        self._load_out = np.r_[tuple([self.force] + self.effect_force + [c["force"] for c in self.couplings]
                                     + wave_force)]
        self._load_total = np.r_[0.0, np.ones(len(self.effect_force) + len(self.couplings) + len(wave_force))]
        # export mode: the mass contribution of acceleration loads, for the dynamics side
        if self.loads.uses_acceleration and not explicit:
            self.add_mass_export("mass_matrix", self.loads.mass_matrix(self.motion(self.motion_inputs,
                                                                                   np.array(self._start))))
        if not explicit:
            for c in self.couplings:
                self.add_mass_export(f"{c['cfg'].name}.mass_matrix", c["mass"])
        ne = len(self.loads.effects)   # (row k of the output block: see evaluate)
        self._explicit = [(k, c["mass"], c["acceleration"]) for k, c in enumerate(self.couplings, 1 + ne)
                          if c["acceleration"] is not None]
        self.finish_registration()
        self.memories = []   # set up by start_physics
        self.stale = True

    def _add_drift(self, cfg):
        """The output <name>.force of the body's wave drift (on the waves' sea state and
        phasors); returns [the force slice] or []."""
        self.drift, self.drift_cfg = None, cfg
        if cfg is None:
            return []
        force = self.add_vector(f"{cfg.name}.force", 6, Fmi2Causality.output, LIN_ROT["force"], None,
                                f"second-order wave drift ({cfg.method}), global axes, about the reference point")
        self.depends([force], [])
        return [force]

    def start_physics(self):
        """The couplings' retardation memories, as ``self.memories``: [(FeedthroughMemory,
        the velocity inputs it reads, the rows of the output block it gives)].  The state-space
        ones are stacked into one evaluator (one product a step for all of them); any other
        (convolution) is one of its own."""
        first = 1 + len(self.loads.effects)   # row of the first coupling in the output block
        stack, self.memories = [], []
        for k, c in enumerate(self.couplings):
            side = c["cfg"]
            if side.coupling.kernels:
                v0 = self.values[c["velocity"]].copy()
                ev = side.coupling.model(v0_a=v0, v0_b=v0).memory[side.side]
                (stack if isinstance(ev, StateSpace) else self.memories).append(([ev], [k]))
        if stack:
            self.memories.append(([ev for evs, _ in stack for ev in evs], [k for _, ks in stack for k in ks]))
        self.memories = [(FeedthroughMemory(evs[0] if len(evs) == 1 else StateSpace.stack(evs)),
                          _joined([self.couplings[k]["velocity"] for k in ks]), _joined([first + k for k in ks]))
                         for evs, ks in self.memories]
        if self.wave_cfg is not None:
            self._start_waves()
        self.stale = True

    def evaluate(self):
        self.stale = self.checked = False
        if not self._ready():
            return
        v = self.values
        ne = len(self.loads.effects)
        nd = self.drift_cfg is not None
        out = np.zeros((1 + ne + len(self.couplings) + self._wave_row + nd, 6))   # total, effects, couplings, waves, drift
        if self.phasors is not None:   # the FMU's one advance of the wave phasors this step
            p = self.phasors.at(self.next_time or 0.0)
        if ne:
            env = self.env()
            env.water = self.water
            self.loads.effect_loads(self.motion(self.motion_inputs), env, out[1:1 + ne])
        for mem, vel, rows in self.memories:
            out[rows] = mem.force(v[vel]).reshape(-1, 6)
        for k, mass, acc in self._explicit:
            out[k] -= mass.dot(v[acc])
        if self.wave is not None:   # a function of time only
            w = self.wave(self.next_time or 0.0)
            out[1 + ne + len(self.couplings)] = w[:6]
            v[self.elevation] = w[6]
        if self.drift is not None:   # the last row: quadratic in the ramped phasors r·p
            r = self.phasors.ramp_factor
            out[-1] = self.drift.at(self.next_time or 0.0, p) * (r * r)
        if self.points and self.kin is not None:
            m = self.motion(self.motion_inputs) if any(b for _, b, _ in self.points) else None
            where = [m.position + m.rot @ x if on_body else x for x, on_body, _ in self.points]
            rows = self.kin.at(p, self.phasors.ramp_factor, where, float(v[self.rho]))
            for (_, _, block), row in zip(self.points, rows):
                v[block] = row
        out[0] = self._load_total.dot(out)   # (ndarray.dot: half the call cost of @ here)
        v[self._load_out] = out.ravel()
        # the total sums every other output: if it is finite, so are they (an overflow of the
        # sum only sends do_step to check them one by one)
        self.checked = _finite(out[0].tolist())

    def step_physics(self, t, dt):
        # not stale: the inputs are those of the last evaluation, whose peek the step takes
        for mem, vel, _ in self.memories:
            mem.commit(self.values[vel], dt, peeked=not self.stale)
        self.stale = bool(self.couplings) or self.phasors is not None  # memory and wave outputs move with time

    def physics_state(self):
        return {"memory": [mem.state() for mem, _, _ in self.memories], "waves": self.phasors is not None,
                "phasors": self.phasors.state() if self.phasors is not None else None}

    def set_physics_state(self, state):
        if state.get("waves") and self.phasors is None:   # taken after initialization, restored before it
            self._start_waves()
        if state.get("phasors") and self.phasors is not None:
            self.phasors.set_state(state["phasors"])
        saved = state["memory"]
        if len(saved) != len(self.memories):   # taken after initialization and restored before it, or back
            if saved:
                self.start_physics()           # the memories, then their saved histories
            else:
                self.memories = []
        for (mem, _, _), s in zip(self.memories, saved):
            mem.set_state(s)


class DynamicsSlave(ArraySlave):
    """6-DOF rigid-body dynamics (the dynamics partner): load inputs in, motion out.

    One FMU integrates one body, or a group of bodies coupled by cross-body added mass
    (then every variable is prefixed by the body name and the cross blocks are parameters
    ``<i>.<j>.added_mass[r,c]``: load on i from the acceleration of j)."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        cfg = self.config
        In, Out, Par = Fmi2Causality.input, Fmi2Causality.output, Fmi2Causality.parameter
        group = len(cfg.bodies) > 1
        self.parts = []
        for b in cfg.bodies:
            p = f"{b.name}." if group else ""
            part = {"cfg": b}
            part["loads"] = [self.add_vector(p + b.load_input(src), 6, In, LIN_ROT["force"],
                                             b.loads[k] if b.loads else None,
                                             f"load from {src or 'the body FMU'}, global axes, "
                                             "about the reference point")
                             for k, src in enumerate(b.load_sources)]
            part["added"] = self.add_matrix(f"{p}added_mass", Par, b.added_mass,
                                            "mass contributions exported by load FMUs, global axes")
            part["position"] = self.add_vector(f"{p}position", 3, Out, "m", b.position)
            part["attitude"] = self.add_vector(f"{p}attitude", 3, Out, "rad", b.attitude)
            part["velocity"] = self.add_vector(f"{p}velocity", 6, Out, LIN_ROT["velocity"], b.velocity)
            part["acceleration"] = self.add_vector(f"{p}acceleration", 6, Out, LIN_ROT["acceleration"], None)
            self.depends([part[k] for k in ("position", "attitude", "velocity", "acceleration")], [])
            self.parts.append(part)
        names = [b.name for b in cfg.bodies]
        self.cross = {(names.index(c.target), names.index(c.source)): self.add_matrix(
                          f"{c.target}.{c.source}.added_mass", Par, c.mass,
                          f"cross added mass: load on {c.target} from {c.source}'s acceleration")
                      for c in cfg.cross}
        self.load_inputs = [s for part in self.parts for s in part["loads"]]
        # the summed load of every body from the load inputs in one product, and where each
        # body's motion goes: position, attitude, velocity (its state y), then acceleration
        self._load_vrs = np.r_[tuple(self.load_inputs)]
        self._load_sum = np.zeros((6 * len(self.parts), len(self._load_vrs)))
        at = 0
        for i, part in enumerate(self.parts):
            for s in part["loads"]:
                self._load_sum[6 * i:6 * i + 6, at:at + 6] = np.eye(6)
                at += 6
        if self._load_sum.shape[0] == self._load_sum.shape[1]:   # one load input per body: no sum
            self._load_sum = None
        self._motion_vrs = np.r_[tuple(part[k] for part in self.parts for k in ("position", "attitude", "velocity"))
                                 + tuple(part["acceleration"] for part in self.parts)]
        self.finish_registration()
        self.solver = None
        self.last_loads = None   # (summed loads, step) of the last step: the linear hold's slope
        # roll and pitch of every body in the motion outputs (12 per body: position, attitude,
        # velocity), the attitude variables they are, and the angle watched (LINEAR_RANGE until said)
        self._tilt = np.array([12 * i + k for i in range(len(self.parts)) for k in (3, 4)])
        self._tilt_vrs = [part["attitude"].start + k for part in self.parts for k in (0, 1)]
        self._watch = LINEAR_RANGE
        self.stale = False

    def start_physics(self):
        v = self.values
        bodies = []
        for part in self.parts:
            b = part["cfg"]
            bodies.append(RigidBody(
                mass=b.mass, inertia=b.inertia, cog=b.cog, stiffness=b.stiffness, damping=b.damping,
                added_mass=v[part["added"]].reshape(6, 6).copy(),
                position0=v[part["position"]].copy(), attitude0=v[part["attitude"]].copy(),
                velocity0=v[part["velocity"]].copy(), max_substep=self.config.substep))
        self.bodies = bodies
        if self.cross:
            self.solver = CoupledBodies(bodies, {k: v[s].reshape(6, 6).copy() for k, s in self.cross.items()})
        # the initial acceleration, under the loads the inputs hold now
        if self.check_finite(self.load_inputs):
            for body, load in zip(bodies, self._loads()):
                body.step(0.0, load)
            self._publish()
        self.error = None

    def _loads(self):
        x = self.values[self._load_vrs]
        return (x if self._load_sum is None else self._load_sum.dot(x)).reshape(-1, 6)

    def _publish(self, acc=None):
        """Motion outputs from the bodies' states and accelerations ``acc`` (default: computed)."""
        if acc is None:
            acc = self.solver.accelerations() if self.solver else self.bodies[0].acceleration
        y = self.solver.y if self.solver is not None and self.solver.y is not None else None
        self.values[self._motion_vrs] = np.concatenate(
            (y, acc.ravel()) if y is not None else [b._y for b in self.bodies] + [acc.ravel()])

    def step_physics(self, t, dt):
        x = self.values[self._load_vrs]
        if not _finite(x.tolist()) and not self.check_finite(self.load_inputs):
            return
        loads = x if self._load_sum is None else self._load_sum.dot(x)   # [F; M] of every body in turn
        rates = None
        if self.config.load_hold == "linear":
            # first-order hold: extrapolate the load with its slope over the last step
            last = self.last_loads
            rates = loads * 0.0 if last is None else (loads - last[0]) / last[1]
            self.last_loads = (loads, dt)
        try:
            if self.solver is not None:   # the group's state is one vector already
                acc = self.solver.step(dt, loads, rates).ravel()
                out = np.concatenate((self.solver.y, acc))
            else:
                acc = self.bodies[0].step(dt, loads, rates)
                out = np.concatenate((self.bodies[0]._y, acc))
        except GimbalLockError as exc:   # the Euler angles' singularity: the body went over
            self.error = f"capsized: {exc}"
            return
        self.values[self._motion_vrs] = out
        self.checked = len(out) == len(self.output_vrs) and _finite(out.tolist())   # every output, then
        tilt = out[self._tilt]
        if max(tilt.max(), -tilt.min()) > self._watch:
            self._watch_range(tilt, t + dt)

    def _watch_range(self, tilt, t):
        """Past the linear range: one warning per run; past CAPSIZE: the step fails, capsized."""
        k = int(np.argmax(np.abs(tilt)))
        var = self.vars[self._tilt_vrs[k]].name
        angle = f"{var} ({'roll' if k % 2 == 0 else 'pitch'}) = {math.degrees(tilt[k]):.1f}° at t = {t:g} s"
        if abs(tilt[k]) > CAPSIZE:
            self.error = (f"capsized: {angle}: |roll| or |pitch| past {math.degrees(CAPSIZE):g}°, far outside "
                          "the linear hydrostatics and first-order wave loads")
            return
        self.log(f"{self.instance_name}: left the linear range: {angle}, past {math.degrees(LINEAR_RANGE):g}°: "
                 "the hydrostatics and first-order wave loads assume small angles (said once per run)",
                 Fmi2Status.warning)
        self._watch = CAPSIZE

    def physics_state(self):
        if not hasattr(self, "bodies"):
            return None
        last = self.last_loads
        return {"bodies": [b.state() for b in self.bodies],
                "last_loads": None if last is None else (last[0].copy(), last[1])}

    def set_physics_state(self, state):
        if state is not None:
            for body, s in zip(self.bodies, state["bodies"]):
                body.set_state(s)
            last = state["last_loads"]
            self.last_loads = None if last is None else (np.asarray(last[0], dtype=float).ravel(), last[1])


class ConnectorSlave(ArraySlave):
    """RIFLEX CONB ball joint between side A and side B (or the earth): the motions of
    both sides in, A.force and B.force out (global axes, each about its own reference
    point), plus the joint's gap [m] and relative rotation [rad] for monitoring."""

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        cfg = self.config
        j = cfg.joint
        node = LumpedBody("node", j.point_a, **cfg.node)
        self.joint = BallJoint(cfg.name, j.point_a, j.point_b, j.k_lin, j.c_lin, j.k_rot, j.c_rot, tuple(j.free),
                               node, j.r_rel0)
        self.explicit = cfg.accel_mode == "explicit"
        Out = Fmi2Causality.output
        accel = self.explicit and self.joint.uses_acceleration
        self.side_a = self.add_motion("A.", cfg.a, accel, "side A")
        self.side_b = (self.add_motion("B.", cfg.b, False, "side B")
                       if cfg.b is not None else None)
        inputs = self.side_a + (self.side_b or []) + self.add_environment(self.joint.uses_current)
        self.motion_inputs = self.side_a
        self._add_waves(cfg.waves)   # the node feels the waves (no outputs of their own)
        self.force_a = self.add_vector("A.force", 6, Out, LIN_ROT["force"], None,
                                       "load on side A, global axes, about A's reference point")
        self.force_b = self.add_vector("B.force", 6, Out, LIN_ROT["force"], None,
                                       "load on side B (the reaction for the earth), about B's reference point")
        self.gap = self.add_vector("gap", 3, Out, "m", None, "joint point of B minus joint point of A, global")
        self.rotation = self.add_vector("rotation", 3, Out, "rad", None, "relative rotation vector, A's axes")
        self.depends([self.force_a, self.force_b, self.gap, self.rotation], inputs)
        self.inputs = inputs
        if self.joint.uses_acceleration and not self.explicit:
            self.add_mass_export("A.mass_matrix",
                                 self.joint.mass_matrix(self.motion(self.side_a, np.array(self._start))))
        self.finish_registration()
        self.stale = True

    def evaluate(self):
        self.stale = False
        if not self._ready():
            return
        env = self.env()
        if self.phasors is not None:
            self.phasors.at(self.next_time or 0.0)
            env.water = self.water
        a = self.motion(self.side_a)
        b = self.motion(self.side_b) if self.side_b else None
        load_a, load_b, gap, rotation = self.joint.loads_and_deformation(a, b, env)
        if self.joint.uses_acceleration:
            if self.explicit:
                load_a = load_a - self.joint.mass_matrix(a).dot(a.acceleration)
            load_a = load_a + self.joint.velocity_load(a)
        v = self.values
        v[self.force_a], v[self.force_b] = load_a, load_b
        v[self.gap], v[self.rotation] = gap, rotation

    def start_physics(self):
        if self.wave_cfg is not None:
            self._start_waves()
        self.stale = True

    def step_physics(self, t, dt):
        self.stale = self.phasors is not None   # the node's wave loads move with time

    def physics_state(self):
        return {"waves": self.phasors is not None,
                "phasors": self.phasors.state() if self.phasors is not None else None}

    def set_physics_state(self, state):
        if state and state.get("waves") and self.phasors is None:
            self._start_waves()
        if state and state.get("phasors") and self.phasors is not None:
            self.phasors.set_state(state["phasors"])


class FeedthroughMemory:
    """A retardation-memory evaluator seen through FMI: its output follows the current
    input before the step commits it.  The pending interval is the last communication
    step (velocity linear over it, ending at the current input); the evaluator's ``peek``
    evaluates it without moving, and ``commit`` moves it (reusing the peek) when the next
    step starts.  Intervals are the master's step sizes themselves, never differences of
    accumulated times, so a constant step stays bit-identical (and cached weights valid)."""

    def __init__(self, evaluator):
        self.ev, self.pending = evaluator, 0.0

    def force(self, v):
        if self.pending <= 0.0:
            return np.asarray(self.ev.force, dtype=float).copy()
        return self.ev.peek(self.pending, v)

    def commit(self, v, dt_next, peeked=False):
        """Close the pending interval at velocity v; the next one is dt_next long.  At the
        first step v is the velocity at t0: an input set after initialization and before the
        first fmi2DoStep is the value at t0 (FMI 2.0), so it starts the history.
        ``peeked``: v is the velocity of the last ``force`` (the caller's inputs have not
        changed since), whose evaluation the interval then keeps without comparing."""
        if self.pending > 0.0:
            self.ev.advance(self.pending, v, peeked)
        else:
            self.ev.restart(v)
        self.pending = float(dt_next)

    def state(self):
        return {"pending": self.pending, "ev": self.ev.state()}

    def set_state(self, state):
        self.pending = state["pending"]
        self.ev.set_state(state["ev"])


def _joined(indices):
    """A slice for consecutive indices (slices or ints), else an index array."""
    idx = np.r_[tuple(indices)]
    return slice(int(idx[0]), int(idx[-1]) + 1) if idx.size and (np.diff(idx) == 1).all() else idx


def _plain(obj):
    """JSON-able copy (lists instead of arrays) of a nested state."""
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, dict):
        return {k: _plain(v) for k, v in obj.items()}
    if isinstance(obj, (list, tuple)):
        return [_plain(v) for v in obj]
    return obj
