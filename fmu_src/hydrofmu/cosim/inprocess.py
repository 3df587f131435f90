"""A scene's system inside this Python process, stepped by the master itself.

``system(scene)`` assembles the scene (``hydrofmu.assembly``), writes each instance's typed
description into a scratch resources folder and instantiates the slaves the FMUs hold,
connected as the build connects them.  ``cosim.master.run(system(scene))`` then drives it
exactly as it drives the built FMUs (initialisation, Jacobi / Gauss–Seidel exchange,
sampling): only the transport differs, Python calls instead of fmpy and the FMI binary.
Made for many short runs (the stability maps of ``bench.stability``).  A System runs once.
Unlike a build, it leaves the dynamics' load inputs starting at zero (``fmi.starts`` would
evaluate every load slave once more): the master exchanges in initialization mode, so a
run is the same.
"""
import sys
import tempfile
from pathlib import Path

import numpy as np
from fmpy.fmi1 import FMICallException
from pythonfmu.enums import Fmi2Status

from .. import description
from ..assembly import assemble
from ..fmi import slave as slaves
from ..fmi.build import SLAVES, connections, manifest
from .master import System


class Port:
    """Value references and their values, for ``Local.read``/``write`` (the master's Port)."""

    def __init__(self, vrs):
        self.vr = np.array(vrs, dtype=int)
        self.n = len(self.vr)
        self.values = np.zeros(self.n)


class Calls:
    """The fmpy FMU2Slave calls the master makes at initialisation, on a slave; each one
    fails as through the FMU's shim when the slave logged an error (``Local.check``)."""

    def __init__(self, local):
        self.local, self.slave = local, local.slave

    def setupExperiment(self, startTime=0.0):
        self.local.check("fmi2SetupExperiment", self.slave.setup_experiment(startTime, None, None))

    def enterInitializationMode(self):
        self.local.check("fmi2EnterInitializationMode", self.slave.enter_initialization_mode())

    def exitInitializationMode(self):
        self.local.check("fmi2ExitInitializationMode", self.slave.exit_initialization_mode())

    def getReal(self, vrs):
        return self.local.check("fmi2GetReal", self.slave.get_real(np.asarray(vrs, dtype=int)))

    def setReal(self, vrs, values):
        self.local.check("fmi2SetReal", self.slave.set_real(np.asarray(vrs, dtype=int), values))


class Local:
    """A slave in this process as the master's ``Instance``."""

    def __init__(self, name, slave):
        self.name, self.slave = name, slave
        self.fmu = Calls(self)
        self.vr = {v.name: vr for vr, v in slave.vars.items()}
        self.causality = {v.name: v.causality.name for v in slave.vars.values()}
        self.units = slave.units
        self.feedthrough = any(slave.dependencies.values())
        self.errors = []   # error messages the slave logged (the master puts them in its RunError)

    def check(self, function, result):
        """``result``, unless the call logged an error or returned False (fmi2DoStep): then
        the FMICallException fmpy raises for fmi2Error, the messages kept in ``errors``."""
        queue = self.slave.log_queue
        errors = [m.msg for m in queue if m.status in (Fmi2Status.error, Fmi2Status.fatal)]
        for m in queue:   # warnings as the fmpy master's logger shows them
            if m.status == Fmi2Status.warning:
                sys.stderr.write(f"[WARNING] {m.msg}\n")
        queue.clear()
        if errors or result is False:
            self.errors += errors
            raise FMICallException(function=function, status=3)
        return result

    def outputs(self):
        return [n for n, c in self.causality.items() if c == "output"]

    def port(self, vrs):
        return Port(vrs)

    def read(self, port):
        port.values[:] = self.check("fmi2GetReal", self.slave.get_real(port.vr))

    def write(self, port):
        self.check("fmi2SetReal", self.slave.set_real(port.vr, port.values.copy()))

    def do_step(self, t, h):
        self.check("fmi2DoStep", self.slave.do_step(t, h))

    def free(self):
        pass


def system(scene, parameters=None) -> System:
    """The master's System of ``scene``'s slaves in this process (``parameters``:
    {'instance.variable': value} set in initialization mode)."""
    assembled = assemble(scene)
    made = {}
    with tempfile.TemporaryDirectory(prefix="hydrofmu-") as tmp:
        for inst in assembled.instances:
            folder = Path(tmp) / inst.name
            folder.mkdir()
            description.write(inst.fmu, folder)
            made[inst.name] = getattr(slaves, SLAVES[type(inst.fmu)])(instance_name=inst.name, resources=str(folder))
    conns = connections(assembled, made)
    return System(manifest(scene, assembled, conns), {n: Local(n, s) for n, s in made.items()}, parameters)
