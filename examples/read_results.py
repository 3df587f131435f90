"""Read a run's CSV back and work with it: units, motion, loads, statistics.

    python examples/read_results.py [CSV] [--settle FRACTION]

CSV defaults to build/examples/moored_barge.csv (written by build_and_run.py).  Prints
every column group with its unit, each body's mean offset and motion range after the
start (the first FRACTION of the run is skipped, default 0.2), and the mean and extreme
of each load effect there.  The same file reads into pandas or a spreadsheet as is: the
header row is ``time [s]``, ``<instance>.<variable> [<unit>]``.
"""
import argparse
from pathlib import Path

import numpy as np

import hydrofmu


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("csv", nargs="?", type=Path, default=Path("build") / "examples" / "moored_barge.csv")
    parser.add_argument("--settle", type=float, default=0.2, help="fraction of the run skipped as start")
    args = parser.parse_args(argv)

    # the built folder next to the CSV (<name>/manifest.json) tells where each body's motion is
    result = hydrofmu.read_csv(args.csv)
    print(f"{args.csv}: {len(result.time)} rows, t = {result.time[0]:g} … {result.time[-1]:g} s, "
          f"{len(result.columns)} columns")
    groups = {}
    for col in result.columns:
        groups.setdefault(col.split("[")[0], set()).add(result.unit(col))
    for name, units in groups.items():
        print(f"  {name} [{', '.join(sorted(units)) or '-'}]")

    late = result.time >= result.time[0] + args.settle * (result.time[-1] - result.time[0])
    summary = {}
    for body in sorted(result.dynamics or {}):
        pos = result.motion(body, "position", 3)
        offset = pos[late] - pos[0]
        summary[body] = offset.mean(axis=0)
        print(f"{body}: mean offset after t = {result.time[late][0]:g} s: {np.round(offset.mean(axis=0), 4)} m, "
              f"range {np.round(offset.max(axis=0) - offset.min(axis=0), 4)} m")
        instances = [name for name, i in result.manifest["instances"].items()
                     if i["kind"] == "load" and i["body"] == body]
        for effect in [c[:-len(".force[1]")] for c in result.columns
                       if c.split(".")[0] in instances and c.endswith(".force[1]")]:
            unit = result.unit(f"{effect}.force[1]")     # N: printed in kN
            fx, fy = result[f"{effect}.force[1]"][late], result[f"{effect}.force[2]"][late]
            horizontal = np.hypot(fx, fy) / (1e3 if unit == "N" else 1.0)
            label = effect if "." in effect else f"{effect} (total of the load FMU)"
            print(f"  {label}: horizontal force mean {horizontal.mean():.2f}, "
                  f"max {horizontal.max():.2f} {'kN' if unit == 'N' else unit}")
    return result, summary


if __name__ == "__main__":
    main()
