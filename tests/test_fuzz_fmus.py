"""FMU call fuzz: seeded random sequences of fmi2SetReal / fmi2GetReal / fmi2DoStep /
fmi2Get-/SetFMUstate / serialisation / fmi2Reset with values including NaN, ±inf and
1e300, on every FMU kind (load with retardation memory, dynamics of one body and of a
coupled group, joint), through fmpy.  Never a crash, never fmi2Fatal; every call returns
fmi2OK or fmi2Error, and every fmi2GetReal that returns fmi2OK returns finite values."""
import random

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import (FMU2Slave, calloc, fmi2CallbackAllocateMemoryTYPE, fmi2CallbackFreeMemoryTYPE,
                       fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, free)

from conftest import MODELS
from hydrofmu.fmi.build import build_scene
from hydrofmu.scene import load_scene

VALUES = [np.nan, np.inf, -np.inf, 1e300, -1e300, 0.0]
CALLS = 120   # per FMU


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    """Every FMU kind: joined_barges (load, joint, single-body dynamics) and side_by_side
    (load FMUs with SIMO memory, dynamics of the coupled group)."""
    out = tmp_path_factory.mktemp("fuzz")
    paths = []
    for name in ("joined_barges", "side_by_side"):
        folder = build_scene(load_scene(MODELS / f"{name}.toml"), out, log=lambda *_: None)
        paths += sorted(folder.glob("*.fmu"))
    return paths


class Fmu:
    def __init__(self, path):
        self.md = read_model_description(str(path))
        self.messages = []
        self.callbacks = fmi2CallbackFunctions()
        self.callbacks.logger = fmi2CallbackLoggerTYPE(self._log)
        self.callbacks.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        self.callbacks.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self.s = FMU2Slave(guid=self.md.guid, unzipDirectory=extract(str(path)),
                           modelIdentifier=self.md.coSimulation.modelIdentifier, instanceName="fuzz")
        self.s.instantiate(callbacks=self.callbacks)
        self.by = {c: [v.valueReference for v in self.md.modelVariables if v.causality == c]
                   for c in ("input", "output", "parameter")}

    def _log(self, env, instance, status, category, message):
        self.messages.append((status, message.decode()))

    def call(self, name, *args):
        """(status, result) of one fmpy call; a status other than OK/Error fails the test."""
        try:
            return 0, getattr(self.s, name)(*args)
        except FMICallException as exc:
            assert exc.status == 3, f"{name}{args}: status {exc.status}; log: {self.messages[-3:]}"
            return 3, None

    def start(self, t0=0.0):
        for name, args in (("setupExperiment", (None, t0)), ("enterInitializationMode", ()),
                           ("exitInitializationMode", ())):
            assert self.call(name, *args)[0] == 0, self.messages[-3:]


def test_random_fmi_call_sequences(fmus):
    kinds = {read_model_description(str(p)).description.split(" ")[0] for p in fmus}
    assert len(fmus) >= 7 and len(kinds) >= 3, kinds
    rng = random.Random(13)
    seen = {0: 0, 3: 0}
    for path in fmus:
        f = Fmu(path)
        f.start()
        t, states, serial = 0.0, [], []
        try:
            for _ in range(CALLS):
                op = rng.choice(["set", "set", "get", "get", "step", "step", "step", "param", "jump",
                                 "getstate", "setstate", "serialize", "garbage", "reset"])
                if op in ("set", "param") and f.by["input" if op == "set" else "parameter"]:
                    vrs = rng.sample(f.by["input" if op == "set" else "parameter"], 1)
                    value = rng.choice(VALUES) if rng.random() < 0.5 else rng.gauss(0.0, 1.0)
                    status, _ = f.call("setReal", vrs, [value])
                    if op == "param":
                        assert status == 3 and "fixed after initialization" in f.messages[-1][1]
                elif op == "get":
                    vrs = rng.sample(f.by["output"], min(6, len(f.by["output"])))
                    status, values = f.call("getReal", vrs)
                    if status == 0:
                        assert np.all(np.isfinite(values)), (path.name, values)
                    else:
                        assert "not finite" in f.messages[-1][1], f.messages[-1]
                elif op in ("step", "jump"):
                    h = rng.choice([0.05, 0.1, 0.1, 0.1, np.nan, -0.1]) if op == "step" else 0.1
                    status, _ = f.call("doStep", t + (0.37 if op == "jump" else 0.0), h)
                    if op == "jump":
                        assert status == 3 and "restore an FMU state" in f.messages[-1][1]
                    if status == 0:
                        t += h
                elif op == "getstate":
                    status, state = f.call("getFMUstate")
                    states.append((state, t))
                elif op == "setstate" and states:
                    state, t_state = rng.choice(states)
                    status, _ = f.call("setFMUstate", state)
                    t = t_state if status == 0 else t
                elif op == "serialize" and states:
                    state, t_state = rng.choice(states)
                    status, data = f.call("serializeFMUstate", state)
                    assert status == 0, f.messages[-3:]
                    status, copy = f.call("deSerializeFMUstate", data)
                    assert status == 0 and f.call("setFMUstate", copy)[0] == 0, f.messages[-3:]
                    serial.append(copy)
                    t = t_state
                elif op == "garbage" and states:
                    status, junk = f.call("deSerializeFMUstate", b"\x00not a state\xff" * 3)
                    assert status == 0
                    status, _ = f.call("setFMUstate", junk)
                    assert status == 3 and "not a state of this FMU" in f.messages[-1][1]
                    f.call("freeFMUstate", junk)
                elif op == "reset":
                    assert f.call("reset")[0] == 0, f.messages[-3:]
                    f.start()
                    t, states = 0.0, []          # states of the old instance are not reused
                else:
                    continue
                seen[status] += 1
            assert all(st in (0, 1, 3) for st, _ in f.messages), f.messages   # never fatal
        finally:
            f.s.terminate()
            f.s.freeInstance()
    assert seen[0] > 200 and seen[3] > 100, seen


def test_serialized_state_continues_the_run_exactly(fmus):
    """Every kind: serialise after 5 steps, run 5 more, restore the bytes, run them again:
    the same outputs to the last bit (the state is complete and JSON-plain)."""
    for path in fmus:
        f = Fmu(path)
        f.start()
        try:
            outs = f.by["output"]
            for k in range(5):
                f.call("doStep", 0.1 * k, 0.1)
            data = f.s.serializeFMUstate(f.s.getFMUstate())
            first = []
            for k in range(5, 10):
                f.s.doStep(0.1 * k, 0.1)
                first.append(f.s.getReal(outs))
            f.s.setFMUstate(f.s.deSerializeFMUstate(data))
            again = []
            for k in range(5, 10):
                f.s.doStep(0.1 * k, 0.1)
                again.append(f.s.getReal(outs))
            assert np.array_equal(first, again), path.name
        finally:
            f.s.terminate()
            f.s.freeInstance()
