"""Drive a hydrofmu load FMU from your own master loop, step by step, with fmpy.

    python examples/own_master.py [--stop T] [--out DIR]

The moored barge's load FMU (AQWA viscous drag + DeepLines current polar in a 1 m/s
current) is coupled to a vessel model of our own: surge and sway only, m·a = F − K·x − D·v
with the barge's mass, mooring stiffness and damping from the scene.  At each
communication point t_k: set the motion, read the load (the FMU is direct feedthrough:
its output already reflects the motion just set), let the FMU commit the step
(fmi2DoStep), then integrate the vessel over [t_k, t_k + h] with the load held (RK4 in
5 substeps).  For comparison the same scene is run by hydrofmu's master with its own
6-DOF dynamics partner FMU (Gauss–Seidel, the same constant hold).
"""
import argparse
import shutil
from pathlib import Path

import numpy as np
from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

import hydrofmu

MODELS = Path(__file__).resolve().parents[1] / "models"


def vessel_step(x, v, force, m, k, d, h, n=5):
    """RK4 of m·a = force − k·x − d·v over h in n substeps (per component, arrays)."""
    dt = h / n
    acc = lambda x_, v_: (force - k * x_ - d * v_) / m
    for _ in range(n):
        k1x, k1v = v, acc(x, v)
        k2x, k2v = v + dt / 2 * k1v, acc(x + dt / 2 * k1x, v + dt / 2 * k1v)
        k3x, k3v = v + dt / 2 * k2v, acc(x + dt / 2 * k2x, v + dt / 2 * k2v)
        k4x, k4v = v + dt * k3v, acc(x + dt * k3x, v + dt * k3v)
        x, v = x + dt / 6 * (k1x + 2 * k2x + 2 * k3x + k4x), v + dt / 6 * (k1v + 2 * k2v + 2 * k3v + k4v)
    return x, v


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--stop", type=float, default=100.0, help="end time [s]")
    parser.add_argument("--step", type=float, default=0.1, help="communication step [s]")
    parser.add_argument("--out", type=Path, default=Path("build") / "examples", help="build folder")
    args = parser.parse_args(argv)

    scene = hydrofmu.load_scene(MODELS / "moored_barge.toml")
    folder = hydrofmu.build(scene, args.out, log=lambda line: None)
    body = scene.bodies["barge"]
    m = np.array([body.mass, body.mass])
    k = np.array([body.stiffness[0][0], body.stiffness[1][1]])
    d = np.array([body.damping[0][0], body.damping[1][1]])

    path = str(folder / "moored_barge_barge.fmu")       # the load FMU of body "barge"
    md = read_model_description(path)
    vr = {v.name: v.valueReference for v in md.modelVariables}
    motion = [vr[f"position[{i}]"] for i in (1, 2, 3)] + [vr[f"attitude[{i}]"] for i in (1, 2, 3)] \
        + [vr[f"velocity[{i}]"] for i in range(1, 7)]
    force = [vr[f"force[{i}]"] for i in (1, 2)]
    unzipped = extract(path)
    fmu = FMU2Slave(guid=md.guid, unzipDirectory=unzipped, modelIdentifier=md.coSimulation.modelIdentifier,
                    instanceName="barge")
    h, n = args.step, int(round(args.stop / args.step))
    x, v = np.zeros(2), np.zeros(2)
    track = [x.copy()]
    try:
        fmu.instantiate()
        fmu.setupExperiment(startTime=0.0)
        fmu.enterInitializationMode()
        fmu.exitInitializationMode()
        for step in range(n):
            fmu.setReal(motion, [x[0], x[1], 0.0, 0.0, 0.0, 0.0, v[0], v[1], 0.0, 0.0, 0.0, 0.0])
            f = np.array(fmu.getReal(force))                 # load at t_k for the motion at t_k [N]
            fmu.doStep(currentCommunicationPoint=step * h, communicationStepSize=h)
            x, v = vessel_step(x, v, f, m, k, d, h)
            track.append(x.copy())
        fmu.terminate()
    finally:
        fmu.freeInstance()
        shutil.rmtree(unzipped, ignore_errors=True)
    track = np.array(track)

    reference = hydrofmu.run(folder, stop=args.stop, step=h, algorithm="gauss-seidel")
    theirs = reference.motion("barge", "position", 3)[:, :2]
    diff = np.abs(track - theirs).max()
    print(f"own master, {n} steps of {h:g} s: barge at x = {x[0]:.4f} m, y = {x[1]:.4f} m; "
          f"hydrofmu's master: x = {theirs[-1, 0]:.4f} m, y = {theirs[-1, 1]:.4f} m; "
          f"largest difference {diff * 1e3:.3g} mm of {np.abs(theirs).max():.3f} m")
    return track, theirs


if __name__ == "__main__":
    main()
