"""Cost of the `waves` effect: per step, against the pythonfmu floor, for 50, 200, 1000 components.

The scene: the freely floating cylinder of the wave tests (tests/data/bem/wave_cylinder.nc of
a repository checkout, excitation and hydrostatics from it, no radiation memory) in a
JONSWAP sea, built once per component count and once without [waves]; each run folder is
timed against its floor (``floor.compare``: 2 floor FMUs, same master, interleaved rounds).
The effect's own cost per step is the body's load slave stepped in-process with waves minus
without (interleaved: the difference of two fmpy runs drowned in their noise on a shared
machine); the kernel alone (``physics.waves.WaveLoad``, one call per step) beside it.
"""
import warnings
from pathlib import Path

import numpy as np

from ..errors import InputWarning

from . import floor, timing

DATA = Path(__file__).resolve().parents[3] / "tests" / "data" / "bem" / "wave_cylinder.nc"
COMPONENTS = (50, 200, 1000)

SCENE = """
[run]
step = 0.05
stop = 10.0
{waves}
[bodies.cyl]
mass = 51191.7
inertia = [204766.8, 204766.8, 115181.3]
cog = [0.0, 0.0, -3.0]
stiffness = [1e4, 1e4, 0.0, 0.0, 0.0, 1e5]
damping = [2e4, 2e4, 4e4, 3e5, 3e5, 1e5]
[[bodies.cyl.effects]]
type = "wave_excitation"
bem = "{data}"
[[bodies.cyl.effects]]
type = "bem_hydrostatics"
bem = "{data}"
"""
WAVES = '[waves]\nspectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ncomponents = {n}\nseed = 1\n'


def scenes(out, counts=COMPONENTS):
    """Build the scene for each component count and without waves: {label: run folder}."""
    from ..api import build
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    folders = {}
    for n in (0,) + tuple(counts):
        path = out / f"waves{n}.toml"
        path.write_text(SCENE.format(waves=WAVES.format(n=n) if n else "", data=DATA.as_posix()))
        with warnings.catch_warnings():   # the calm scene's excitation left out: meant here
            warnings.simplefilter("ignore", InputWarning)
            folders[n] = build(path, out / "fmus", log=lambda *_: None)
    return folders


def kernel(counts=COMPONENTS, calls=2000, rounds=5):
    """Seconds per WaveLoad call for each component count (in-process, no FMI)."""
    from ..decks.bem_waves import read_excitation
    from ..physics.waves import SeaState, TransferFunction, WaveLoad, components
    data = read_excitation(DATA)
    tf = TransferFunction(data.omega, data.directions, data.body(data.bodies[0]))

    def make(n):
        load = WaveLoad(components(SeaState(hs=2.0, tp=8.0, components=n), tf.window), tf, (0.0, 0.0))
        return lambda: (lambda k: load(0.05 * k))
    return timing.per_call({n: make(n) for n in counts}, calls, rounds)


def load_slave(out, counts=COMPONENTS, calls=2000, rounds=5, step=0.05):
    """Seconds per step of the body's load FMU's slave in-process (fmi2DoStep then
    fmi2GetReal of its total force, as a master does), for each component count and 0
    (no waves), interleaved: the effect's cost inside the FMU without the transport's noise."""
    from ..cosim import inprocess
    from ..scene import load_scene

    def make(n):
        def start():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", InputWarning)
                scene = load_scene(Path(out) / f"waves{n}.toml")
            slave = inprocess.system(scene).instances["cyl"].slave
            vr = [k for k, v in slave.vars.items() if v.name.startswith("force[")]
            slave.setup_experiment(0.0)
            slave.enter_initialization_mode()
            slave.exit_initialization_mode()
            return lambda k: (slave.do_step(k * step, step), slave.get_real(vr))
        return start
    return timing.per_call({n: make(n) for n in (0,) + tuple(counts)}, calls, rounds)


def measure(out, rounds=5, steps=400, counts=COMPONENTS):
    """Rows per component count: the scene's cost per step and its floor [µs] through
    fmpy, the effect's own cost in the load FMU's slave (with − without waves, in-process)
    [µs] and per 100 components, and the kernel alone."""
    if not DATA.is_file():
        return None
    folders = scenes(out, counts)
    slave = load_slave(out, counts, rounds=rounds)
    fmu = floor.build_floor(Path(out) / "floor")
    got = {r["label"]: r for r in floor.compare({str(n): f for n, f in folders.items()}, fmu, Path(out),
                                                rounds=rounds, steps=steps)}
    alone = kernel(counts)
    base = got["0"]
    rows = []
    for n in counts:
        r = got[str(n)]
        effect = 1e6 * (slave[n] - slave[0])
        rows.append({"components": n, "step_us": r["step_us"], "step_floor_us": r["step_floor_us"],
                     "step_x": r["step_x"], "no_waves_us": base["step_us"],
                     "step_x_no_waves": base["step_x"], "slave_us": 1e6 * slave[n], "slave_no_waves_us": 1e6 * slave[0],
                     "effect_us": effect, "effect_per_100_us": 100 * effect / n, "kernel_us": 1e6 * alone[n],
                     "kernel_per_100_us": 1e8 * alone[n] / n, "noisy": r["step_noisy"] or base["step_noisy"]})
    return rows


def linear(rows):
    """Slope [µs per 100 components] of the effect's cost between the first and last count,
    and the ratio of the last count's cost per component to the first's (1: linear)."""
    n = np.array([r["components"] for r in rows], float)
    c = np.array([r["effect_us"] for r in rows], float)
    return 100 * (c[-1] - c[0]) / (n[-1] - n[0]), (c[-1] / n[-1]) / (c[0] / n[0]) if c[0] > 0 else float("nan")
