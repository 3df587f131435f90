"""Build a scene's FMUs, run them, write the CSV and the plot, print what the bodies did.

    python examples/build_and_run.py [SCENE] [--stop T] [--out DIR]

SCENE defaults to models/moored_barge.toml; the scene's own [run] settings are used
except the end time, when given.
"""
import argparse
from pathlib import Path

import numpy as np

import hydrofmu

MODELS = Path(__file__).resolve().parents[1] / "models"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", default=MODELS / "moored_barge.toml", type=Path)
    parser.add_argument("--stop", type=float, help="end time [s] (default: the scene's)")
    parser.add_argument("--out", type=Path, default=Path("build") / "examples", help="build folder")
    args = parser.parse_args(argv)

    scene = hydrofmu.load_scene(args.scene)          # validated: an InputError names file, key path, field
    for body in scene.bodies.values():
        print(f"{body.name}: at {body.position} m, effects {[e.name for e in body.effects]}")

    folder = hydrofmu.build(scene, args.out, log=lambda line: None)   # quiet build
    result = hydrofmu.run(folder, stop=args.stop)
    csv = result.to_csv(folder.with_name(f"{scene.name}.csv"))
    png = result.plot(folder.with_name(f"{scene.name}.png"))
    print(f"{len(result.time) - 1} steps of {result.step:g} s ({result.algorithm}); wrote {csv} and {png}")

    for body in sorted(scene.bodies):
        pos = result.motion(body, "position", 3)
        moved = pos[-1] - pos[0]
        print(f"{body}: moved {np.round(moved, 3)} m, largest horizontal offset "
              f"{np.hypot(*(pos[:, :2] - pos[0, :2]).T).max():.3f} m")
    return result


if __name__ == "__main__":
    main()
