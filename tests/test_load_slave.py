"""The load FMU's per-step shortcuts (fmi.slave.LoadSlave) against the plain path: its
state-space memories stacked into one evaluator, and the step taking the evaluation's peek
without comparing inputs.  The reference is one FeedthroughMemory per coupling around the
coupling's own evaluator, closed by the comparing ``advance``."""
import numpy as np

from hydrofmu.cosim import inprocess
from hydrofmu.fmi.slave import FeedthroughMemory
from hydrofmu.physics.memory import StateSpace
from hydrofmu.scene import load_scene

from conftest import MODELS


def test_stacked_memories_follow_their_own_evaluators_when_inputs_change_before_the_step():
    slave = inprocess.system(load_scene(MODELS / "side_by_side.toml")).instances["barge_a"].slave
    vr = {v.name: k for k, v in slave.vars.items()}
    own = [vr[f"velocity[{i}]"] for i in range(1, 7)]
    src = [vr[f"barge_b.velocity[{i}]"] for i in range(1, 7)]
    names = [c["cfg"].name for c in slave.couplings]
    outs = [[vr[f"{n}.force[{i}]"] for i in range(1, 7)] for n in names]
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    slave.exit_initialization_mode()
    assert names == ["SELFA", "AB"] and len(slave.memories) == 1          # both in one stack
    assert isinstance(slave.memories[0][0].ev, StateSpace) and slave.memories[0][0].ev.shape == (12, 12)
    vel = {n: v for n, v in zip(names, (own, src))}
    refs = {}
    for c in slave.couplings:
        v0 = slave.values[vel[c["cfg"].name]].copy()
        refs[c["cfg"].name] = FeedthroughMemory(c["cfg"].coupling.model(v0_a=v0, v0_b=v0).memory[c["cfg"].side])
    rng = np.random.default_rng(7)
    t, biggest = 0.0, 0.0
    for k in range(60):
        v = rng.normal(scale=0.5, size=12)
        slave.set_real(own + src, v.tolist())
        if k % 3 != 2:
            slave.get_real(outs[0] + outs[1])                 # evaluated: the memories peeked at v
        if k % 3 == 0:
            v = v + rng.normal(scale=0.5, size=12)            # new velocities after the read
            slave.set_real(own + src, v.tolist())
        dt = float(rng.uniform(0.02, 0.1))
        assert slave.do_step(t, dt)
        t += dt
        got = slave.get_real(outs[0] + outs[1])
        want = []
        for n, vn in zip(names, (v[:6], v[6:])):
            refs[n].commit(vn, dt)
            want += refs[n].force(vn).tolist()
        np.testing.assert_allclose(got, want, rtol=1e-11, atol=1e-9 * np.abs(want).max())
        biggest = max(biggest, np.abs(want).max())
    assert biggest > 1e3   # N: the memory loads are not trivially zero


def test_cached_value_references_follow_the_list_and_the_mode():
    """set_real/get_real keep the index arrays of the lists a master passes every step: a list
    changed in place gets its own values, and a parameter the cache accepted in initialization
    mode is refused after it (one error line naming it)."""
    slave = inprocess.system(load_scene(MODELS / "side_by_side.toml")).instances["barge_b"].slave
    vr = {v.name: k for k, v in slave.vars.items()}
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    vrs = [vr["rho"], vr["velocity[1]"]]
    slave.set_real(vrs, [1000.0, 0.1])
    assert slave.get_real(vrs) == [1000.0, 0.1]
    slave.exit_initialization_mode()
    slave.log_queue.clear()
    slave.set_real(vrs, [1025.0, 0.2])
    errors = [m.msg for m in slave.log_queue]
    assert len(errors) == 1 and "cannot set rho: a parameter, fixed after initialization" in errors[0]
    vrs[0] = vr["velocity[2]"]                  # the same list object, other contents
    slave.set_real(vrs, [0.3, 0.4])
    assert slave.get_real([vr["rho"]] + vrs) == [1000.0, 0.3, 0.4]


def test_a_running_state_restores_into_an_instance_not_yet_initialized():
    """fmi2SetFMUstate of a running load FMU's serialized state into a fresh instance (its
    memories not built yet): both continue with the same outputs."""
    def fresh():
        return inprocess.system(load_scene(MODELS / "side_by_side.toml")).instances["barge_b"].slave
    run, other = fresh(), fresh()
    vr = {v.name: k for k, v in run.vars.items()}
    vel = [vr[f"velocity[{i}]"] for i in range(1, 7)] + [vr[f"barge_a.velocity[{i}]"] for i in range(1, 7)]
    run.setup_experiment(0.0)
    run.enter_initialization_mode()
    run.exit_initialization_mode()
    rng = np.random.default_rng(2)
    for k in range(5):
        run.set_real(vel, rng.normal(size=12).tolist())
        assert run.do_step(0.05 * k, 0.05)
    data = run._fmu_state_to_bytes(run._get_fmu_state())
    other._set_fmu_state(other._fmu_state_from_bytes(data))
    assert not other.log_queue
    outs = run.output_vrs.tolist()
    for k in range(5, 10):
        v = rng.normal(size=12).tolist()
        for s in (run, other):
            s.set_real(vel, v)
            assert s.do_step(0.05 * k, 0.05)
        got, want = other.get_real(outs), run.get_real(outs)
        assert got == want and any(x != 0.0 for x in want)
