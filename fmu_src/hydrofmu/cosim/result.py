"""The recorded run of a scene (`Result`), its CSV file and the units of its columns.

Light on purpose (numpy and the standard library only): reading a CSV back needs no
FMI library.  CSV layout: one header row ``time [s]``, ``<instance>.<variable> [<unit>]``
(the unit as the FMU's modelDescription.xml declares it: m, rad, m/s, N, N.m, …; ``[-]``
for a variable without unit), then one row per communication point.
"""
import csv
import json
import re
import zipfile
from dataclasses import dataclass, field
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

HEADER = re.compile(r"^(?P<name>.*\S)\s+\[(?P<unit>[^\[\]]*)\]$")  # name, blank, [unit]


@dataclass
class Result:
    """A recorded co-simulation run.

    Attributes
    ----------
    time : ndarray, shape (n,)
        Communication points [s].
    columns : list of str
        ``'instance.variable'`` names of the recorded outputs, e.g. ``'barge.force[1]'``.
    values : ndarray, shape (n, m)
        ``values[k, j]`` is column ``j`` at ``time[k]`` (SI units, see ``units``).
    algorithm : str
        ``'jacobi'``, ``'gauss-seidel'`` or ``'libcosim'``.
    step : float
        Communication step [s].
    dynamics : dict
        Body name -> [dynamics instance, variable prefix]: where each body's motion is.
    settings : dict
        Preset and knobs of the run (see ``cosim.master.describe``).
    units : dict
        Column -> unit string of the FMU's model description (``'m'``, ``'N'``, ``'N.m'``, …).
    manifest : dict
        The built scene's ``manifest.json`` (instances, connections, run settings), if known.
    """
    time: np.ndarray
    columns: list
    values: np.ndarray
    algorithm: str
    step: float
    dynamics: dict = None  # body -> [dynamics instance, variable prefix]
    settings: dict = None  # preset and knobs of the run (``run_settings``)
    units: dict = field(default_factory=dict)
    manifest: dict = None

    def __getitem__(self, column: str) -> np.ndarray:
        """The time series (n,) of one column, ``'instance.variable'``."""
        return self.values[:, self.columns.index(column)]

    def vector(self, instance: str, name: str, n: int) -> np.ndarray:
        """(n_times, n) array of ``instance.name[1..n]``."""
        return np.column_stack([self[f"{instance}.{name}[{i}]"] for i in range(1, n + 1)])

    def motion(self, body: str, name: str, n: int) -> np.ndarray:
        """(n_times, n) array of a body's dynamics output ``name[1..n]`` (``position``,
        ``attitude``, ``velocity``, ``acceleration``; global axes, SI), wherever the body's
        dynamics FMU is."""
        instance, prefix = self.dynamics[body]
        return self.vector(instance, f"{prefix}{name}", n)

    def unit(self, column: str) -> str:
        """The unit of a column (``''`` when the FMU declares none)."""
        return "s" if column == "time" else self.units.get(column, "")

    def to_csv(self, path) -> Path:
        """Write the run as CSV, headers with units (``time [s]``, ``barge.force[1] [N]``);
        returns the path.  Values are written with full precision (``repr``)."""
        path = Path(path)
        with open(path, "w", newline="") as f:
            w = csv.writer(f)
            w.writerow([f"{c} [{self.unit(c) or '-'}]" for c in ["time"] + self.columns])
            for t, row in zip(self.time, self.values):
                w.writerow([repr(float(t))] + [repr(float(x)) for x in row])
        return path

    def plot(self, path) -> Path:
        """Write the PNG of ``cosim.report.plot`` (needs ``manifest``); returns the path."""
        from .report import plot
        if self.manifest is None:
            raise ValueError("this Result has no manifest: plot it with cosim.report.plot(result, manifest, path)")
        plot(self, self.manifest, path)
        return Path(path)


def split_header(cell: str):
    """``'barge.force[1] [N]'`` -> ``('barge.force[1]', 'N')``; a cell without a trailing
    ``[unit]`` -> ``(cell, '')``; ``[-]`` means no unit."""
    m = HEADER.match(cell.strip())
    if not m:
        return cell.strip(), ""
    unit = m["unit"].strip()
    return m["name"], "" if unit == "-" else unit


def read_csv(path, manifest=None) -> Result:
    """Read a CSV written by `Result.to_csv` (or ``hydrofmu run``) back into a Result.

    Parameters
    ----------
    path : str or Path
        The CSV file.
    manifest : str, Path or dict, optional
        The built scene's ``manifest.json`` (or its folder), for ``Result.motion`` and
        ``Result.plot``.  By default the manifest of ``<csv stem>/`` next to the CSV, if
        there is one (where ``hydrofmu run`` writes it).

    Returns
    -------
    Result
        With ``units`` from the header; ``algorithm`` and ``step`` from the manifest's
        run settings when known (the step is also the spacing of the time column).
    """
    path = Path(path)
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = [split_header(c) for c in next(rows)]
        data = np.array([[float(x) for x in row] for row in rows if row], dtype=float).reshape(-1, len(header))
    if manifest is None and (path.with_suffix("") / "manifest.json").is_file():
        manifest = path.with_suffix("")
    if isinstance(manifest, (str, Path)):
        m = Path(manifest)
        manifest = json.loads((m / "manifest.json" if m.is_dir() else m).read_text())
    names = [n for n, _ in header[1:]]
    step = float(data[1, 0] - data[0, 0]) if len(data) > 1 else 0.0
    run = (manifest or {}).get("run", {})
    return Result(data[:, 0].copy(), names, data[:, 1:].copy(), run.get("algorithm", ""), step,
                  (manifest or {}).get("dynamics"), None, {n: u for n, u in header[1:] if u}, manifest)


def fmu_units(fmu) -> dict:
    """Variable name -> unit of the Real variables in an FMU's modelDescription.xml."""
    with zipfile.ZipFile(fmu) as z:
        root = ET.fromstring(z.read("modelDescription.xml"))
    out = {}
    for sv in root.iter("ScalarVariable"):
        real = sv.find("Real")
        if real is not None and real.get("unit"):
            out[sv.get("name")] = real.get("unit")
    return out


def column_units(folder, manifest, columns) -> dict:
    """Column ``'instance.variable'`` -> unit, from the FMUs of a built scene folder."""
    folder = Path(folder)
    per_instance = {}
    out = {}
    for col in columns:
        inst, var = col.split(".", 1)
        if inst not in per_instance:
            per_instance[inst] = fmu_units(folder / manifest["instances"][inst]["fmu"])
        if var in per_instance[inst]:
            out[col] = per_instance[inst][var]
    return out
