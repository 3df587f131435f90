"""Start values: every input of a scene's FMUs starts at the value its source has at t = 0.

A master that exchanges outputs to inputs before the first step (ours, libcosim) and one that
steps first from the declared start values (fmpy's plain loops, many hand-written hosts)
then run the same system.  The start values live in the typed descriptions
(``hydrofmu.description``), which the slaves register as their inputs' starts:

- motion inputs (position, attitude, velocity of a body, its neighbours', a joint's sides):
  the body's state at t = 0, set by ``hydrofmu.assembly`` (what the dynamics partner
  outputs then);
- current inputs: the environment's speed and direction (``Environment``);
- a dynamics partner's load inputs: the loads its load and joint FMUs give at t = 0,
  ``fill_loads`` from those slaves evaluated here, the kernels the FMUs run;
- acceleration inputs (explicit mode) are the exception: the acceleration at t = 0 follows
  from the loads at t = 0, which in explicit mode depend on it.  They start at 0 and each
  slave lists them in ``unknown_start``.

``check`` holds every connection to the rule: the source's output at t = 0 (its slave
initialised with its own start values) equals the target's declared start.  It runs in
every build, so an FMU kind or effect that brings a new input without its start fails the
build instead of silently depending on the master.
"""
from __future__ import annotations

import math

import numpy as np
from pythonfmu.enums import Fmi2Status


class StartValueError(Exception):
    """An input's start value is not its source's value at t = 0 (a hydrofmu defect), or a
    source could not be evaluated at t = 0."""


def at_start(name: str, slave) -> dict[str, float]:
    """Every variable of ``slave`` at t = 0: set up at 0, through initialization mode with
    its start values, then read (the loads evaluated by the slave's own kernels)."""
    slave.setup_experiment(0.0, None, None)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    names = {vr: v.name for vr, v in slave.vars.items()}
    values = slave.get_real(list(names))
    errors = [m.msg for m in slave.log_queue if m.status in (Fmi2Status.error, Fmi2Status.fatal)]
    slave.log_queue.clear()
    if errors:
        raise StartValueError(f"{name}: cannot evaluate at t = 0: {'; '.join(errors)}")
    return {names[vr]: float(v) for vr, v in zip(names, values)}


def fill_loads(system, t0: dict[str, dict[str, float]]) -> None:
    """Set ``DynamicsBody.loads`` (the load inputs' starts) of every dynamics description of
    the ``assembly.System`` from its sources' outputs at t = 0 (``t0``: instance -> variable
    -> value, from ``at_start``), following each instance's force routes."""
    fmus = {inst.name: inst.fmu for inst in system.instances}
    for inst in system.instances:
        for out, body, inp in inst.forces:
            if inst.name not in t0:
                raise StartValueError(f"{inst.name}: its loads at t = 0 are needed before it is built")
            dyn, _ = system.dynamics[body]
            part = next(b for b in fmus[dyn].bodies if b.name == body)
            if len(part.loads) != len(part.load_sources):
                part.loads = [np.zeros(6) for _ in part.load_sources]
            k = [part.load_input(s) for s in part.load_sources].index(inp)
            part.loads[k] = np.array([t0[inst.name][f"{out}[{i}]"] for i in range(1, 7)])


def start_of(slave, variable: str) -> float:
    """The start value ``slave`` declares for ``variable``."""
    vr = next(vr for vr, v in slave.vars.items() if v.name == variable)
    return slave._start[vr]


def mismatches(connections, slaves, t0) -> list[str]:
    """Connections (source, output, target, input) whose input's declared start is not the
    output's value at t = 0, as lines; inputs a slave lists in ``unknown_start`` excepted."""
    bad = []
    for src, out, dst, inp in connections:
        if inp in slaves[dst].unknown_start:
            continue
        want, got = t0[src][out], start_of(slaves[dst], inp)
        if not math.isclose(got, want, rel_tol=1e-12, abs_tol=1e-12):
            bad.append(f"{dst}.{inp} starts at {got!r}, its source {src}.{out} is {want!r} at t = 0")
    return bad


def check(connections, slaves, t0) -> None:
    """Raise StartValueError naming every input whose start is not its source's t = 0 value."""
    bad = mismatches(connections, slaves, t0)
    if bad:
        raise StartValueError(f"{len(bad)} input start value(s) differ from their sources at t = 0 "
                              f"(a defect in hydrofmu, please report it): " + "; ".join(bad[:5])
                              + ("; …" if len(bad) > 5 else ""))
