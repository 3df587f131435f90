"""Give another tool the same sea: a named wave point of a hydrofmu scene read by a second FMU.

    python examples/wave_probe.py [--stop T] [--out DIR]

The joined barges of models/ in a JONSWAP sea with two named points ([waves.points]): a
fixed point 20 m off barge A, 10 m down (`probe`), and one under barge A's stern
(`stern`).  Their kinematics are outputs of barge A's load FMU (waves.probe.velocity[1..3],
acceleration[1..3], pressure, elevation).  A second FMU, written here with pythonfmu as a
stand-in for a mooring, riser or crane tool (a small sphere held at the probe: Morison drag
and inertia on the water's velocity and acceleration it is given), reads them through our
own master loop with fmpy, the way MoorDyn's WaveKin = 1 takes its kinematics from outside.
The probe's velocity is checked against Airy theory of the scene's components (the same
sea), and the sphere's force written to probe.csv.
"""
import argparse
import math
import shutil
import textwrap
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

import hydrofmu

MODELS = Path(__file__).resolve().parents[1] / "models"
WAVES = """
[waves]
spectrum = "jonswap"
hs = 3.0
tp = 9.0
components = 100
seed = 7
ramp = 20.0
stretching = "wheeler"

[waves.points.probe]
position = [20.0, 5.0, -10.0]

[waves.points.stern]
body = "barge_a"
offset = [-40.0, 0.0, -8.0]
"""

SPHERE = '''
"""A small sphere held in the water: Morison drag and inertia on the water's motion it is given."""
from pythonfmu import Fmi2Causality, Fmi2Slave, Real


class Sphere(Fmi2Slave):
    author = "hydrofmu example"
    description = "sphere of radius 0.5 m held in the water, C_d = 1, C_m = 2"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.u = [0.0, 0.0, 0.0]
        self.a = [0.0, 0.0, 0.0]
        self.f = [0.0, 0.0, 0.0]
        for i in range(3):
            self.register_variable(Real(f"water_velocity[{i + 1}]", causality=Fmi2Causality.input,
                                        getter=lambda i=i: self.u[i], setter=lambda v, i=i: self.u.__setitem__(i, v)))
            self.register_variable(Real(f"water_acceleration[{i + 1}]", causality=Fmi2Causality.input,
                                        getter=lambda i=i: self.a[i], setter=lambda v, i=i: self.a.__setitem__(i, v)))
            self.register_variable(Real(f"force[{i + 1}]", causality=Fmi2Causality.output,
                                        getter=lambda i=i: self.f[i]))

    def do_step(self, t, dt):
        rho, r, cd, cm = 1025.0, 0.5, 1.0, 2.0
        area, volume = 3.141592653589793 * r * r, 4.0 / 3.0 * 3.141592653589793 * r ** 3
        speed = sum(x * x for x in self.u) ** 0.5
        self.f = [0.5 * rho * cd * area * speed * u + rho * cm * volume * a for u, a in zip(self.u, self.a)]
        return True
'''


def airy(comps, t, x, y, z, g=9.81, ramp=20.0):
    """Deep-water Airy horizontal and vertical velocity of the components, Wheeler-stretched
    (z' = z − η), ramped: the independent check of what the second FMU was given.  Per
    component η = a·cos θ, θ = ωt − k·x + φ: u = aω·e^{kz'}·cos θ along the wave, and
    w = ∂η/∂t at the surface = −aω·e^{kz'}·sin θ."""
    k = comps.omega ** 2 / g
    b = np.radians(comps.direction)
    th = comps.omega * t - k * (x * np.cos(b) + y * np.sin(b)) + comps.phase
    r = 0.5 * (1 - math.cos(math.pi * t / ramp)) if t < ramp else 1.0
    eta = r * np.sum(comps.amplitude * np.cos(th))
    e = r * comps.omega * comps.amplitude * np.exp(k * (z - eta))
    # w = ∂η/∂t (times the depth factor): −Σ ω a sin θ, the water rising under a rising surface
    return np.array([np.sum(e * np.cos(th) * np.cos(b)), np.sum(e * np.cos(th) * np.sin(b)), -np.sum(e * np.sin(th))])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--stop", type=float, default=60.0, help="end time [s]")
    parser.add_argument("--step", type=float, default=0.1, help="communication step [s]")
    parser.add_argument("--out", type=Path, default=Path("build") / "examples", help="build folder")
    args = parser.parse_args(argv)
    out = args.out / "wave_probe"
    out.mkdir(parents=True, exist_ok=True)

    # the scene: the joined barges in waves, with the named points
    text = (MODELS / "joined_barges.toml").read_text().replace('"decks/', f'"{(MODELS / "decks").as_posix()}/')
    (out / "joined_barges_waves.toml").write_text(text + WAVES)
    scene = hydrofmu.load_scene(out / "joined_barges_waves.toml")
    folder = hydrofmu.build(scene, out, log=lambda line: None)
    # the second tool's FMU
    (out / "sphere.py").write_text(textwrap.dedent(SPHERE))
    from pythonfmu import FmuBuilder
    sphere_fmu = FmuBuilder.build_FMU(out / "sphere.py", dest=out)

    def open_fmu(path, name):
        md = read_model_description(str(path))
        unzipped = extract(str(path))
        fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                        instanceName=name)
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        return fmu, {v.name: v.valueReference for v in md.modelVariables}, unzipped

    load, lvr, lzip = open_fmu(folder / "joined_barges_barge_a.fmu", "barge_a")
    sphere, svr, szip = open_fmu(sphere_fmu, "sphere")
    velocity = [lvr[f"waves.probe.velocity[{i}]"] for i in (1, 2, 3)]
    acceleration = [lvr[f"waves.probe.acceleration[{i}]"] for i in (1, 2, 3)]
    h, n = args.step, int(round(args.stop / args.step))
    rows, worst = [], 0.0
    from hydrofmu.physics.waves import components
    comps = components(scene.waves)
    try:
        for step in range(n):   # (barge A held at its start pose: the probe is a fixed point anyway)
            load.doStep(currentCommunicationPoint=step * h, communicationStepSize=h)
            t = (step + 1) * h
            u, a = load.getReal(velocity), load.getReal(acceleration)
            sphere.setReal([svr[f"water_velocity[{i}]"] for i in (1, 2, 3)], u)
            sphere.setReal([svr[f"water_acceleration[{i}]"] for i in (1, 2, 3)], a)
            sphere.doStep(currentCommunicationPoint=step * h, communicationStepSize=h)
            f = sphere.getReal([svr[f"force[{i}]"] for i in (1, 2, 3)])
            worst = max(worst, float(np.abs(np.array(u) - airy(comps, t, 20.0, 5.0, -10.0)).max()))
            rows.append([t, *u, *a, load.getReal([lvr["waves.probe.elevation"]])[0], *f])
    finally:
        for fmu, unzipped in ((load, lzip), (sphere, szip)):
            fmu.terminate()
            fmu.freeInstance()
            shutil.rmtree(unzipped, ignore_errors=True)
    rows = np.array(rows)
    header = "time,u1,u2,u3,a1,a2,a3,elevation,force1,force2,force3"
    np.savetxt(out / "probe.csv", rows, delimiter=",", header=header, comments="")
    print(f"probe 20 m off barge A, 10 m down, {n} steps: water speed up to {np.abs(rows[:, 1:4]).max():.2f} m/s, "
          f"sphere force up to {np.abs(rows[:, 8:11]).max() / 1e3:.2f} kN")
    print(f"the second FMU's water velocity against Airy of the scene's components: {worst:.1e} m/s at most")
    print(f"wrote {out / 'probe.csv'}")
    return worst, rows


if __name__ == "__main__":
    main()
