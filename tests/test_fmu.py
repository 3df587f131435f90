"""The built FMUs: they validate, declare units and dependencies, give the kernels'
forces through fmpy, report bad inputs as fmi2Error, and keep instances apart."""
import xml.etree.ElementTree as ET
import zipfile

import numpy as np
import pytest
from fmpy import extract, read_model_description
from fmpy.fmi1 import FMICallException
from fmpy.fmi2 import FMU2Slave
from fmpy.validation import validate_fmu

from hydrofmu.physics.loads import make_effect
from hydrofmu.physics.state import Env, Motion
from hydrofmu.scene import load_scene

from conftest import MODELS

rng = np.random.default_rng(7)


class Fmu:
    """An fmpy instance with access by variable name."""

    def __init__(self, path, name="inst", logger=None):
        md = read_model_description(str(path))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.md = md
        self.slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(path)),
                               modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        kw = {"callbacks": None} if logger is None else {}
        self.slave.instantiate(**kw) if logger is None else self._instantiate(logger)
        self.slave.setupExperiment(startTime=0.0)
        self.slave.enterInitializationMode()
        self.slave.exitInitializationMode()

    def _instantiate(self, logger):
        from fmpy.fmi2 import fmi2CallbackFunctions, fmi2CallbackLoggerTYPE, fmi2CallbackAllocateMemoryTYPE, \
            fmi2CallbackFreeMemoryTYPE, calloc, free
        cb = fmi2CallbackFunctions()
        cb.logger = fmi2CallbackLoggerTYPE(lambda env, inst, status, cat, msg: logger(status, msg.decode()))
        cb.allocateMemory = fmi2CallbackAllocateMemoryTYPE(calloc)
        cb.freeMemory = fmi2CallbackFreeMemoryTYPE(free)
        self._cb = cb
        self.slave.instantiate(callbacks=cb)

    def set(self, name, values):
        values = np.atleast_1d(values)
        names = [name] if len(values) == 1 and name in self.vr else [f"{name}[{i + 1}]" for i in range(len(values))]
        self.slave.setReal([self.vr[n] for n in names], list(map(float, values)))

    def get(self, name, n=6):
        names = [name] if name in self.vr else [f"{name}[{i + 1}]" for i in range(n)]
        return np.array(self.slave.getReal([self.vr[n] for n in names]))

    def close(self):
        self.slave.terminate()
        self.slave.freeInstance()


def test_fmus_validate_with_units_and_dependencies(demo_build):
    fmus = sorted(demo_build.glob("*.fmu"))
    assert len(fmus) == 2
    for fmu in fmus:
        assert validate_fmu(str(fmu)) == []
        root = ET.fromstring(zipfile.ZipFile(fmu).read("modelDescription.xml"))
        units = {u.get("name") for u in root.find("UnitDefinitions")}
        reals = [sv for sv in root.iter("ScalarVariable")]
        assert all(sv.find("Real").get("unit") in units for sv in reals)
        outputs = root.find("ModelStructure/Outputs")
        initial = root.find("ModelStructure/InitialUnknowns")
        assert outputs is not None and initial is not None
    load = ET.fromstring(zipfile.ZipFile(demo_build / "moored_barge_barge.fmu").read("modelDescription.xml"))
    names = [sv.get("name") for sv in load.iter("ScalarVariable")]
    force1 = next(u for u in load.find("ModelStructure/Outputs") if names[int(u.get("index")) - 1] == "force[1]")
    deps = {names[int(i) - 1] for i in force1.get("dependencies").split()}
    assert {"position[1]", "attitude[3]", "velocity[6]", "current.speed", "current.direction"} <= deps
    # the FMU holds only what its effects need: no acceleration input, no mass export
    assert not any(n.startswith("acceleration") or n.startswith("mass_matrix") for n in names)
    assert {"viscous_drag.force[1]", "current_polar.force[6]", "rho", "g"} <= set(names)


def test_forces_through_fmpy_equal_kernels(demo_build):
    scene = load_scene(MODELS / "moored_barge.toml")
    effects = [make_effect(e.type, e.name, e.data) for e in scene.bodies["barge"].effects]
    fmu = Fmu(demo_build / "moored_barge_barge.fmu")
    try:
        for k in range(20):
            motion = Motion(rng.normal(size=3), rng.uniform(-0.4, 0.4, 3) + [0, 0, rng.uniform(-4, 4)],
                            rng.normal(size=6) * [1, 1, 0.3, 0.05, 0.05, 0.05])
            env = Env(1025.0, 9.81, rng.uniform(0, 2), rng.uniform(-360, 720))
            fmu.set("position", motion.position)
            fmu.set("attitude", motion.attitude)
            fmu.set("velocity", motion.velocity)
            fmu.set("current.speed", env.current_speed)
            fmu.set("current.direction", env.current_direction)
            expected = [e.load(motion, env) for e in effects]
            np.testing.assert_allclose(fmu.get("viscous_drag.force"), expected[0], rtol=1e-12, atol=1e-9)
            np.testing.assert_allclose(fmu.get("current_polar.force"), expected[1], rtol=1e-12, atol=1e-9)
            np.testing.assert_allclose(fmu.get("force"), expected[0] + expected[1], rtol=1e-12, atol=1e-9)
            fmu.slave.doStep(0.1 * k, 0.1)
    finally:
        fmu.close()


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_bad_input_gives_fmi2error_and_a_log_line(demo_build, bad):
    messages = []
    fmu = Fmu(demo_build / "moored_barge_barge.fmu", logger=lambda status, msg: messages.append((status, msg)))
    try:
        fmu.slave.doStep(0.0, 0.1)
        fmu.set("velocity", [0, bad, 0, 0, 0, 0])
        with pytest.raises(FMICallException) as exc:
            fmu.slave.doStep(0.1, 0.1)
        assert exc.value.status == 3  # fmi2Error
        assert any(status == 3 and "velocity[2]" in msg and "not finite" in msg for status, msg in messages)
        fmu.set("velocity", [0.5, 0, 0, 0, 0, 0])  # the instance is still usable: the step again
        fmu.slave.doStep(0.1, 0.1)
        assert np.all(np.isfinite(fmu.get("force")))
        with pytest.raises(FMICallException):
            fmu.slave.doStep(0.3, -0.1)  # a non-positive step is an error too
    finally:
        fmu.close()


def test_instances_do_not_collide(demo_build, tmp_path):
    """Two instances of one FMU and an FMU of another scene in one process."""
    from conftest import build
    other = build(tmp_path, """
        [scene]
        name = "other"
        [bodies.barge]
        mass = 1.0e6
        inertia = [1e8, 1e8, 1e8]
        [[bodies.barge.effects]]
        type = "aqwa_viscous_drag"
        matrix = [1.0, 0, 0, 0, 0, 0]
        """)
    a = Fmu(demo_build / "moored_barge_barge.fmu", "a")
    b = Fmu(demo_build / "moored_barge_barge.fmu", "b")
    c = Fmu(other / "other_barge.fmu", "c")
    try:
        a.set("velocity", [1, 0, 0, 0, 0, 0])
        b.set("velocity", [-1, 0, 0, 0, 0, 0])
        c.set("velocity", [2, 0, 0, 0, 0, 0])
        fa, fb, fc = a.get("viscous_drag.force"), b.get("viscous_drag.force"), c.get("viscous_drag.force")
        assert fa[0] != fb[0]
        assert fc[0] == pytest.approx(-4.0)  # −V11·v|v| with V11 = 1, absolute velocity
    finally:
        for f in (a, b, c):
            f.close()


def test_state_save_restore(demo_build):
    dyn = Fmu(demo_build / "moored_barge_barge_dynamics.fmu")
    try:
        dyn.set("force", [1e5, 2e5, 0, 0, 0, 1e6])
        for k in range(3):
            dyn.slave.doStep(0.1 * k, 0.1)
        state = dyn.slave.getFMUstate()
        run = []
        for _ in range(2):
            dyn.slave.setFMUstate(state)
            for k in range(3, 6):
                dyn.slave.doStep(0.1 * k, 0.1)
            run.append(np.concatenate([dyn.get("position", 3), dyn.get("velocity")]))
        dyn.slave.freeFMUstate(state)
        np.testing.assert_array_equal(run[0], run[1])
        assert run[0][0] > 0
    finally:
        dyn.close()
