"""Long runs: peak memory and wall time of one long run of ``side_by_side``, streamed to disk
(``cosim.stream``: Parquet and CSV written as the run goes, the PNG and the summary read from
the Parquet file) against held in memory (the whole Result, then ``to_csv``, ``plot`` and
``summary``), as ``hydrofmu run`` does them, each in a fresh
Python process (peak RSS = the process's high-water mark ``VmHWM``, which includes the FMUs' interpreter
and libraries: the floor is a process that only loaded the FMUs; a streamed file longer than
``stream.PLOT_ROWS`` rows is plotted by a process of its own: its peak is ``child_peak_mb``).
"""
import json
import subprocess
import sys
from pathlib import Path

from ..fmi.build import build_scene
from ..scene import load_scene

MODELS = Path(__file__).resolve().parents[3] / "models"

SCRIPT = r"""
import json, resource, sys, time
from pathlib import Path
from hydrofmu.cosim.master import run, load
folder, stop, mode, out = Path(sys.argv[1]), float(sys.argv[2]), sys.argv[3], Path(sys.argv[4])
t0 = time.perf_counter()
if mode == "floor":
    load(folder).free()
elif mode == "stream":
    from hydrofmu.cosim.stream import Sink
    r = run(folder, stop=stop, progress=False, sink=Sink(out / "run.parquet", out / "run.csv"))
    r.plot(out / "run.png")
    r.summary().to_json(out / "run.summary.json")
else:
    r = run(folder, stop=stop, progress=False)
    r.to_csv(out / "run.csv")
    r.plot(out / "run.png")
    r.summary().to_json(out / "run.summary.json")
wall = time.perf_counter() - t0
size = sum(p.stat().st_size for p in out.glob("run.*"))
def peak_mb():
    # VmHWM: this process's own high-water mark since its exec; ru_maxrss also counts the RSS of
    # the process that forked it (the bench, 505 MB after its other parts, against 157 MB alone)
    try:
        for line in open("/proc/self/status"):
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
print(json.dumps({"mode": mode, "peak_mb": peak_mb(),
                  "child_peak_mb": resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024,
                  "wall_s": wall, "written_mb": size / 2**20}))
"""


def measure(out, stop=10800.0, modes=("floor", "stream", "memory")):
    """Rows {mode, stop_s, steps, peak_mb, wall_s, written_mb} of side_by_side run to ``stop``."""
    out = Path(out)
    folder = build_scene(load_scene(MODELS / "side_by_side.toml"), out / "fmus", log=lambda *_: None)
    step = load_scene(MODELS / "side_by_side.toml").run["step"]
    rows = []
    for mode in modes:
        work = out / mode
        work.mkdir(parents=True, exist_ok=True)
        for p in work.glob("run.*"):
            p.unlink()
        done = subprocess.run([sys.executable, "-c", SCRIPT, str(folder), str(stop), mode, str(work)],
                              capture_output=True, text=True, check=True)
        row = json.loads(done.stdout.strip().splitlines()[-1])
        rows.append({"mode": mode, "stop_s": stop, "steps": round(stop / step), **{k: row[k] for k in
                                                                                ("peak_mb", "child_peak_mb", "wall_s", "written_mb")}})
    return rows
