"""FMU overhead: the load FMU of a body driven by fmpy against its kernels called in-process.

The body carries every effect (AQWA viscous drag, DeepLines current polar, RIFLEX BODY
with drag and added mass) and two SIMO couplings: its own radiation memory and a 12-DOF
interaction with a neighbour (full 6×6 realistic kernels, ``kernels.coupling_kernels``).
Per step, the FMU gets its inputs (setReal), gives its total load (getReal: the feedthrough
evaluation) and steps (doStep: commits the memory); in-process, the same kernel objects
compute the same loads from the same inputs.  overhead = FMU time / in-process time.  The
pythonfmu floor under the same three calls (a trivial FMU with as many inputs and outputs,
``floor.build_floor``) tells how much of the difference is fmpy's and pythonfmu's own.
"""
from pathlib import Path

import numpy as np

from ..decks.simo import format_coupling, write_couplings
from ..assembly import body_loads
from ..physics.state import Env, Motion
from .kernels import coupling_kernels, irregular_velocity
from .timing import per_round

TIMDEL = 0.05

SCENE = """
[scene]
name = "overhead"
[environment]
current_speed = 1.2
current_direction = 30.0
[run]
step = {dt}
[bodies.a]
mass = 1.28e7
inertia = [7.7e8, 1.08e10, 1.13e10]
[[bodies.a.effects]]
type = "aqwa_viscous_drag"
matrix = [6.4e4, 2.56e5, 1e6, 1e8, 1e9, 8.0e9]
option = "RELATIVE"
[[bodies.a.effects]]
type = "deeplines_current_polar"
point = [-5.0, 0.0, -2.0]
surface = 125.0
symmetry = "xz"
table = [[0, 0.6, 0.0, 0.0], [45, 0.4, 1.5, 4.0], [90, 0.0, 3.2, 0.0], [135, -0.4, 1.5, -4.0], [180, -0.6, 0.0, 0.0]]
[[bodies.a.effects]]
type = "riflex_body"
offset = [30.0, 0.0, -8.0]
am = 2.0e4
ae = 10.0
icoo = "LOCAL"
cd = [2.0e3, 4.0e3, 4.0e3]
added_mass = [1.0e4, 2.0e4, 2.0e4]
[bodies.b]
position = [0.0, 35.0, 0.0]
mass = 1.28e7
inertia = [7.7e8, 1.08e10, 1.13e10]
[[couplings]]
deck = "overhead.sim"
coupling = "SA"
method = "{method}"
[[couplings]]
deck = "overhead.sim"
coupling = "AB"
method = "{method}"
"""


def write_scene(folder, method="state_space", lags=400, dt=TIMDEL):
    """Deck and scene of the overhead case in ``folder``; returns the scene path."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    am = np.diag([1e6, 4e6, 8e6, 5e8, 5e9, 5e9])
    own = coupling_kernels(TIMDEL, lags, distance=0.0, seed=3)
    cross = coupling_kernels(TIMDEL, lags, distance=35.0, seed=4)
    one = lambda k: {(i + 1, j + 1): h for (i, j), h in k.items()}   # 1-based IDOF_A, IDOF_B
    write_couplings(folder / "overhead.sim", [
        format_coupling("SA", "a", "a", am, one({ij: h for ij, h in own.items() if ij[0] == ij[1]}), TIMDEL),
        format_coupling("AB", "a", "b", 0.2 * am, one(cross), TIMDEL)])
    path = folder / "overhead.toml"
    path.write_text(SCENE.format(method=method, dt=dt))
    return path


def motions(n, dt):
    """Input sequences: a's pose and velocity, b's velocity (irregular sea, small angles)."""
    t = dt * np.arange(n)
    va, vb = irregular_velocity(t, seed=5), irregular_velocity(t, seed=6)
    pose = np.cumsum(va, axis=0) * dt
    return pose[:, :3], pose[:, 3:], va, vb


def measure(folder, method="state_space", lags=400, steps=1000, rounds=5, dt=TIMDEL):
    """Seconds per step {'fmu', 'in_process', 'floor'} (medians of the rounds), the ratio
    FMU/in-process (median of each round's ratio), its ``spread`` between rounds and
    ``noisy`` (spread > floor.NOISY); builds into ``folder``."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    from ..fmi.build import build_scene
    from ..scene import load_scene
    from .floor import NOISY, build_floor, spread

    scene = load_scene(write_scene(folder, method, lags, dt))
    built = build_scene(scene, Path(folder) / "fmus", log=lambda *_: None)
    fmu_path = str(built / "overhead_a.fmu")
    md = read_model_description(fmu_path)
    unzipped = extract(fmu_path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    vec = lambda name, n: [vr[f"{name}[{i + 1}]"] for i in range(n)]
    inputs = vec("position", 3) + vec("attitude", 3) + vec("velocity", 6) + vec("b.velocity", 6)
    outputs = vec("force", 6)
    pos, att, va, vb = motions(steps + 1, dt)
    values = np.hstack([pos, att, va, vb])
    env = Env(scene.rho, scene.g, scene.current_speed, scene.current_direction)
    body = scene.bodies["a"]
    floor_path = str(build_floor(Path(folder) / "floor", len(inputs), len(outputs)))
    floor_md = read_model_description(floor_path)
    floor_unzipped = extract(floor_path)

    def fmpy_run(md, unzipped, inputs, outputs):
        slave = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, instanceName="a",
                          modelIdentifier=md.coSimulation.modelIdentifier)
        slave.instantiate(loggingOn=False)
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.setReal(inputs, values[0].tolist())
        slave.exitInitializationMode()
        slaves.append(slave)

        def step(k):
            slave.setReal(inputs, values[k + 1].tolist())
            slave.getReal(outputs)
            slave.doStep(k * dt, dt)
        return step

    def fmu_run():
        return fmpy_run(md, unzipped, inputs, outputs)

    def floor_run():
        fvr = {v.name: v.valueReference for v in floor_md.modelVariables}
        return fmpy_run(floor_md, floor_unzipped, [fvr[f"u[{i + 1}]"] for i in range(len(inputs))],
                        [fvr[f"y[{i + 1}]"] for i in range(len(outputs))])

    def kernel_run():
        loads = body_loads(body)
        memories = []
        for c in scene.couplings:
            model = c.model(v0_a=va[0], v0_b=vb[0])
            memories.append((model.memory["A"], va if c.b == "a" else vb))

        def step(k):
            m = Motion(pos[k + 1], att[k + 1], va[k + 1], np.zeros(6))
            total = loads.effect_loads(m, env).sum(axis=0)
            for memory, v in memories:
                total = total + memory.advance(dt, v[k + 1])
        return step

    slaves = []
    try:
        times = per_round({"fmu": fmu_run, "in_process": kernel_run, "floor": floor_run}, steps, rounds)
    finally:
        for slave in slaves:
            slave.terminate()
            slave.freeInstance()
    ratios = np.array(times["fmu"]) / np.array(times["in_process"])
    return {**{k: float(np.median(t)) for k, t in times.items()}, "ratio": float(np.median(ratios)),
            "spread": spread(ratios), "noisy": spread(ratios) > NOISY}
