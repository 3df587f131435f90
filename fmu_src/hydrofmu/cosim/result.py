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
from functools import cached_property
from pathlib import Path
from xml.etree import ElementTree as ET

import numpy as np

from ..errors import InputError
from ..names import UnknownName

DYNAMICS = re.compile(r"^(?P<instance>[^.]+_dynamics)\.(?:(?P<body>[^.\[]+)\.)?position\[1\]$")
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

    def __repr__(self):
        n = len(self.time)
        span = f"t = {self.time[0]:g}–{self.time[-1]:g} s" if n else "no points"
        scene = " " + self.manifest["scene"] if self.manifest else ""
        how = ", ".join(filter(None, [self.algorithm, f"step {self.step:g} s" if self.step else ""]))
        bodies = ", ".join(sorted(self.layout()[0]["dynamics"])) or "none found"
        extra = "" if self.manifest else "; no manifest (plot and joint loads need one)"
        return (f"<Result{scene}: {n} points, {span}" + (f", {how}" if how else "")
                + f"; {len(self.columns)} columns; bodies {bodies}{extra}>")

    @cached_property
    def _index(self):
        return {c: i for i, c in enumerate(self.columns)}

    def __getitem__(self, column: str) -> np.ndarray:
        """The time series (n,) of one column, ``'instance.variable'``, or ``'time'``."""
        if column == "time":
            return self.time
        i = self._index.get(column)
        if i is None:
            raise UnknownName("column", column, ["time"] + self.columns)
        return self.values[:, i]

    def __contains__(self, column) -> bool:
        return column == "time" or column in self._index

    def instances(self) -> list:
        """The FMU instances that have recorded columns."""
        return sorted({c.split(".", 1)[0] for c in self.columns})

    def vector(self, instance: str, name: str, n: int | None = None) -> np.ndarray:
        """(n_times, n) array of ``instance.name[1..n]``; ``n`` defaults to every
        component recorded (``name[1]``, ``name[2]``, … as long as they exist)."""
        if n is not None and (isinstance(n, bool) or not isinstance(n, int) or n < 1):
            raise ValueError(f"n: the number of components must be a whole number ≥ 1, found {n!r}")
        if n is None:
            n = 0
            while f"{instance}.{name}[{n + 1}]" in self._index:
                n += 1
        missing = [k for k in range(1, n + 1) if f"{instance}.{name}[{k}]" not in self._index]
        if n == 0 or missing:
            if instance not in self.instances():
                raise UnknownName("instance", instance, self.instances())
            variables = {re.sub(r"\[\d+\]$", "", c.split(".", 1)[1]) for c in self.columns
                         if c.startswith(f"{instance}.")}
            if name in variables:
                raise UnknownName("column", f"{instance}.{name}[{missing[0]}]", self.columns)
            raise UnknownName("variable", name, variables, f" of instance {instance!r}")
        # column by column through __getitem__ (a FileResult reads each from its file)
        return np.column_stack([self[f"{instance}.{name}[{i}]"] for i in range(1, n + 1)])

    def motion(self, body: str, name: str, n: int | None = None) -> np.ndarray:
        """(n_times, n) array of a body's dynamics output ``name[1..n]`` (``position``,
        ``attitude``, ``velocity``, ``acceleration``; global axes, SI: m, rad, m/s, rad/s,
        m/s2, rad/s2), wherever the body's dynamics FMU is; ``n`` defaults to every
        component (3 for position and attitude, 6 for velocity and acceleration)."""
        dynamics = self.layout()[0]["dynamics"]
        if body not in dynamics:
            raise UnknownName("body", body, dynamics)
        instance, prefix = dynamics[body]
        return self.vector(instance, f"{prefix}{name}", n)

    def layout(self):
        """(manifest, notes): the built scene's manifest, or without one (a CSV read on its
        own) what the column names tell: each body's dynamics (``<body>_dynamics.position``,
        or ``<group>_dynamics.<body>.position``) and its load FMU (instance ``<body>``)."""
        if self.manifest is not None:
            return self.manifest, []
        dynamics = {}
        if self.dynamics:
            dynamics = dict(self.dynamics)
        else:
            for c in self.columns:
                m = DYNAMICS.match(c)
                if m:
                    body = m["body"] or m["instance"][:-len("_dynamics")]
                    dynamics[body] = [m["instance"], f"{m['body']}." if m["body"] else ""]
        instances = {b: {"kind": "load", "body": b} for b in dynamics if f"{b}.force[1]" in self._index}
        notes = ["no manifest: joint forces left out of the loads (read_csv(path, manifest=FOLDER) adds them)"]
        return {"scene": "", "dynamics": dynamics, "instances": instances, "connections": []}, notes

    def unit(self, column: str) -> str:
        """The unit of a column (``''`` when the FMU declares none)."""
        return "s" if column == "time" else self.units.get(column, "")

    def summary(self, transient: float = 0.0, split: float | None = None):
        """Per body and dof, over t ≥ ``transient`` [s]: mean, std, min, max of its motion
        (position [m], attitude [rad]) and of each load on it and their total [N, N.m], the
        low- and wave-frequency parts split at ``split`` [s] (default: the scene's ``[run]
        split``, else 2·Tp of its sea) with their std and the expected extremes, and the
        response spectra.  Returns a `cosim.summary.Summary` (``print`` it, ``to_json``,
        ``to_pandas``, ``write_spectra``)."""
        from .summary import summarize
        return summarize(self, transient, split)

    def statistics(self, columns=None, transient: float = 0.0, split: float | None = None) -> dict:
        """The figures of ``cosim.statistics.describe`` (mean, std, min, max, LF and WF std,
        WF zero up-crossing period, expected extremes) of recorded columns ({column: {figure:
        value}}, each with its ``unit``), over t ≥ ``transient`` [s], split at ``split`` [s]
        (default as ``summary``); ``columns``: a name or a list (default: every column)."""
        from . import statistics
        from .summary import split_period
        names = [columns] if isinstance(columns, str) else list(self.columns if columns is None else columns)
        time = self.time
        keep = time >= time[0] + transient
        if len(time) and not keep.any():
            raise ValueError(f"transient {transient:g} s leaves no point: the run ends at {time[-1]:g} s")
        period = split_period(self.layout()[0], split)["period"]
        out = {}
        for name in names:
            dt, x = statistics.uniform(time[keep], self[name][keep])
            out[name] = {"unit": self.unit(name), **statistics.describe(x, dt, period)}
        return out

    def to_pandas(self):
        """A pandas DataFrame: time [s] as the index, one column per recorded variable;
        ``df.attrs['units']`` maps each column (and ``'time'``) to its unit, ``attrs``
        also holds the scene, algorithm, step and run settings.  Needs pandas (the
        ``batch`` extra)."""
        try:
            import pandas as pd
        except ImportError as exc:
            raise ImportError(f"Result.to_pandas needs pandas (pip install 'hydrofmu[batch]'): {exc}") from None
        df = pd.DataFrame(self.values, index=pd.Index(self.time, name="time"), columns=list(self.columns))
        df.attrs.update({"units": {"time": "s", **{c: self.unit(c) for c in self.columns}},
                         "scene": (self.manifest or {}).get("scene"), "algorithm": self.algorithm,
                         "step": self.step, "settings": self.settings})
        return df

    def to_csv(self, path) -> Path:
        """Write the run as CSV, headers with units (``time [s]``, ``barge.force[1] [N]``,
        attitude in rad); returns the path.  Values are written with full precision
        (``repr``).  The file appears whole or not at all; a missing folder is an
        InputError naming it (another failure to write, an OSError)."""
        path = Path(path)
        if path.is_dir():
            raise InputError(path, None, "output file", "is a folder, not a file")
        if not path.parent.is_dir():
            raise InputError(path, None, "output file", f"folder {path.parent} does not exist")
        tmp = path.with_name(f".{path.name}.tmp")
        try:
            with open(tmp, "w", newline="") as f:
                w = csv.writer(f)
                w.writerow([f"{c} [{self.unit(c) or '-'}]" for c in ["time"] + self.columns])
                for t, row in zip(self.time, self.values):
                    w.writerow([repr(float(t))] + [repr(float(x)) for x in row])
            tmp.replace(path)
        finally:   # a failed write leaves nothing (the OSError goes on: writable.keep may try elsewhere)
            tmp.unlink(missing_ok=True)
        return path

    def plot(self, path, split: float | None = None) -> Path:
        """Write the PNG of ``cosim.report.plot`` (needs ``manifest``), the low-frequency parts
        split at ``split`` [s] (default as ``summary``); returns the path."""
        from .report import plot
        if self.manifest is None:
            raise ValueError("this Result has no manifest, which the plot needs (which FMU is which body's "
                             "load, joint or dynamics): read the CSV with read_csv(path, manifest=BUILT_FOLDER)")
        from ..writable import check_plot
        path = check_plot(path)
        if not path.parent.is_dir():
            raise InputError(path, None, "output file", f"folder {path.parent} does not exist")
        plot(self, self.manifest, path, split)
        return path


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
        The built scene's ``manifest.json`` (or its folder).  By default the manifest of
        ``<csv stem>/`` next to the CSV, if there is one (where ``hydrofmu run`` writes
        it).  Without one the Result has the plain columns: ``r[column]``, ``vector``,
        ``motion`` (each body's dynamics found from the column names), ``summary``
        (without the joints' forces) and ``to_pandas`` work; ``plot`` needs it.

    Returns
    -------
    Result
        With ``units`` from the header; ``algorithm`` from the manifest's run settings
        when known; ``step`` the spacing of the time column.

    Raises
    ------
    hydrofmu.InputError
        The file cannot be read, or a row is not numbers (file, line and column named).
    """
    path = Path(path)
    try:
        with open(path, newline="") as f:
            rows = csv.reader(f)
            header = [split_header(c) for c in next(rows, [])]
            data = []
            for row in rows:
                if not row:
                    continue
                if len(row) != len(header):
                    raise InputError(path, rows.line_num, "row", f"{len(row)} values for {len(header)} columns")
                try:
                    data.append([float(x) for x in row])
                except ValueError:
                    bad = next(i for i, x in enumerate(row) if not _is_number(x))
                    raise InputError(path, rows.line_num, header[bad][0], f"expected a number, found {row[bad]!r}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(path, None, "file", f"cannot read the CSV ({getattr(exc, 'strerror', None) or exc})") from None
    if not header or header[0][0] != "time":
        raise InputError(path, 1, "header", "expected a header row starting with 'time [s]' (a CSV of Result.to_csv)")
    data = np.array(data, dtype=float).reshape(-1, len(header))
    if manifest is None:   # <folder>.csv, or <folder>.libcosim.csv (the libcosim engine's)
        stem = path.with_suffix("")
        manifest = next((f for f in (stem, stem.with_suffix("")) if (f / "manifest.json").is_file()), None)
    if isinstance(manifest, (str, Path)):
        m = Path(manifest)
        manifest = json.loads((m / "manifest.json" if m.is_dir() else m).read_text())
    names = [n for n, _ in header[1:]]
    step = float(data[1, 0] - data[0, 0]) if len(data) > 1 else 0.0
    run = (manifest or {}).get("run", {})
    return Result(data[:, 0].copy(), names, data[:, 1:].copy(), run.get("algorithm", ""), step,
                  (manifest or {}).get("dynamics"), None, {n: u for n, u in header[1:] if u}, manifest)


def _is_number(text):
    try:
        float(text)
        return True
    except ValueError:
        return False


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
