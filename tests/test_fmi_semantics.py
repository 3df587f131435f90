"""FMI 2.0 semantics other masters rely on, checked through fmpy's FMU2Slave:

- an input set in step mode, after fmi2ExitInitializationMode and before the first
  fmi2DoStep(t0), is the value at t0 for every history-holding effect (SIMO retardation
  memory, convolution and state space): with the neighbour's velocity v = 1 m/s from t0
  on, the memory load is F(t) = −∫₀ᵗ h(s) ds · v, the kernel's integral computed here;
- fmi2Reset gives a fresh instance: the same run after a reset equals a new instance's.
"""
import numpy as np
import pytest
from scipy.integrate import quad

from conftest import build
from simo_decks import coupling_group, write_deck

C, A, W = 2.0e4, 0.8, 1.5          # h(t) = C e^(−A t) cos(W t) [N/(m/s)/s], surge from surge
TIMDEL, LENGTH, DT = 0.01, 20.0, 0.2


def h(t):
    return C * np.exp(-A * t) * np.cos(W * t)


@pytest.fixture(scope="module")
def pair(tmp_path_factory):
    """{method: load FMU of body a}: a cross coupling AB (one kernel, surge–surge) between
    two free-floating bodies, one build per memory method (state space of order 2: the
    kernel's exact order)."""
    out = {}
    for method in ("convolution", "state_space"):
        d = tmp_path_factory.mktemp(method)
        deck = write_deck(d / "ab.sim", [coupling_group("AB", "A", "B", np.zeros((6, 6)), {(1, 1): (C, A, W)},
                                                        TIMDEL, LENGTH)])
        bodies = "".join(f"""
            [bodies.{n}]
            position = [0.0, {y}, 0.0]
            mass = 1.0e6
            inertia = [1.0e8, 1.0e8, 1.0e8]
            stiffness = {np.diag([1e4] * 6).tolist()}
            """ for n, y in (("a", 0.0), ("b", 40.0)))
        folder = build(d, f"""
            [scene]
            name = "t0{method[:4]}"
            [run]
            step = {DT}
            stop = 10.0
            """ + bodies + f"""
            [[couplings]]
            deck = "{deck}"
            coupling = "AB"
            bodies = {{ A = "a", B = "b" }}
            method = "{method}"
            {"order = 2" if method == "state_space" else ""}
            """)
        out[method] = next(folder.glob("*_a.fmu"))
    return out


class Instance:
    """One fmpy FMU2Slave of an FMU, with variables by name."""

    def __init__(self, fmu, name):
        from fmpy import extract, read_model_description
        from fmpy.fmi2 import FMU2Slave
        md = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        self.s = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)),
                           modelIdentifier=md.coSimulation.modelIdentifier, instanceName=name)
        self.s.instantiate()

    def initialise(self):
        self.s.setupExperiment(startTime=0.0)
        self.s.enterInitializationMode()
        self.s.exitInitializationMode()

    def set(self, **values):
        self.s.setReal([self.vr[k.replace("__", ".").replace("_", "[", 1) + "]"] for k in values],
                       list(values.values()))

    def get(self, name):
        return self.s.getReal([self.vr[name]])[0]

    def free(self):
        self.s.terminate()
        self.s.freeInstance()


def run_memory(inst, steps):
    """Neighbour surge velocity 1 m/s set in step mode before the first step, then held:
    the coupling load on a after each step."""
    inst.initialise()          # the velocity inputs are 0 in initialization mode
    out = []
    for k in range(steps):
        inst.s.setReal([inst.vr["b.velocity[1]"]], [1.0])
        inst.s.doStep(k * DT, DT)
        out.append(inst.get("AB.force[1]"))
    return np.array(out)


@pytest.mark.parametrize("method, rtol", [("convolution", 1e-4), ("state_space", 5e-3)])
def test_input_before_first_step_is_the_value_at_t0(pair, method, rtol):
    inst = Instance(pair[method], "t0")
    try:
        got = run_memory(inst, 5)
    finally:
        inst.free()
    want = np.array([-quad(h, 0.0, (k + 1) * DT, limit=200)[0] for k in range(5)])
    # the first-step load: the whole step under v = 1 m/s (keeping the initialization
    # value 0 as the history's first node would give about half of it)
    np.testing.assert_allclose(got, want, rtol=rtol)


@pytest.mark.parametrize("method", ["convolution", "state_space"])
def test_reset_gives_a_fresh_instance(pair, method):
    """Run, fmi2Reset, run again: the second run equals a new instance's run, memory included."""
    used, fresh = Instance(pair[method], "used"), Instance(pair[method], "fresh")
    try:
        first = run_memory(used, 4)
        used.s.reset()
        again = run_memory(used, 4)
        new = run_memory(fresh, 4)
    finally:
        used.free()
        fresh.free()
    np.testing.assert_array_equal(again, new)
    np.testing.assert_array_equal(first, new)
    assert np.all(new != 0)
