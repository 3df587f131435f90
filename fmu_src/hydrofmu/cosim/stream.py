"""Results of long runs in bounded memory: the master's rows go to disk as the run goes.

- ``Recorder``: where the master puts the sampled rows.  In memory (no sink) it is the whole
  (rows × columns) array of a Result; with a ``Sink`` it is a buffer of ``BLOCK`` rows,
  written out whenever it fills, so a run holds the same few megabytes however long it is.
  ``every``: keep one communication point in ``every`` (the output interval / the step).
- ``Sink``: the files written as the run goes: Parquet (pyarrow, the ``batch`` extra; one row
  group per block, the units and the manifest in the file's metadata) and/or CSV (the layout of
  ``Result.to_csv``: ``time [s]``, ``instance.variable [unit]``, values at full precision).
  Each is written to a ``.part`` file beside it and renamed when the run ends, so a file
  under the asked name is always complete.
- ``read_parquet``: a written file back as a ``FileResult``: the columns read from the file
  when asked (``result['barge.force[1]']``), never all at once unless ``values`` is asked;
  its summary and plot read each column whole (every figure is the whole record's);
  ``thinned`` gives an in-memory Result of every k-th row.
"""
from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np

from ..errors import InputError
from .result import Result

BLOCK = 4096       # rows buffered between writes (84 columns: 2.8 MB)
PLOT_ROWS = 4000    # a streamed run longer than this is plotted by a process of its own


def output_every(interval, step, where="run", field="interval"):
    """Communication points per output row: ``interval`` / ``step``, a whole number ≥ 1
    (None: every point)."""
    if interval is None:
        return 1
    from ..admissible import whole_interval
    every, problems = whole_interval(interval, step)
    if problems:
        raise InputError(where, None, field, problems[0][1])
    return every


class Sink:
    """Parquet and/or CSV files a run streams its rows into (``parquet``, ``csv``: paths or None)."""

    def __init__(self, parquet=None, csv_path=None):
        if parquet is None and csv_path is None:
            raise ValueError("a Sink needs a Parquet or a CSV path")
        self.parquet = Path(parquet) if parquet else None
        self.csv = Path(csv_path) if csv_path else None
        self._pq = self._csv = self._file = None
        self.rows = 0

    @staticmethod
    def _part(path):
        return path.with_name(path.name + ".part")

    def open(self, columns, units, manifest=None, settings=None):
        self.columns = ["time"] + list(columns)
        if self.parquet:
            import pyarrow as pa
            import pyarrow.parquet as pq
            meta = {"hydrofmu.units": json.dumps({c: units.get(c, "") for c in columns}),
                    "hydrofmu.manifest": json.dumps(manifest or {}),
                    "hydrofmu.settings": json.dumps(settings or {}, default=str)}
            self._schema = pa.schema([pa.field(c, pa.float64()) for c in self.columns], metadata=meta)
            self._pq = pq.ParquetWriter(self._part(self.parquet), self._schema)
        if self.csv:
            self._file = open(self._part(self.csv), "w", newline="")
            self._csv = csv.writer(self._file)
            self._csv.writerow([f"{c} [{'s' if c == 'time' else units.get(c) or '-'}]" for c in self.columns])

    def write(self, time, values):
        """Rows ``time[k]``, ``values[k]`` (as ``Result.to_csv`` writes them)."""
        try:
            self._write(time, values)
        except OSError as exc:   # the disk filled during the run: the run fails, saying why
            raise RuntimeError(f"cannot write the results as the run goes ({exc.strerror or exc}: "
                               f"{exc.filename or ''})") from None

    def _write(self, time, values):
        if self._pq is not None:
            import pyarrow as pa
            arrays = [pa.array(time)] + [pa.array(values[:, j]) for j in range(values.shape[1])]
            self._pq.write_table(pa.Table.from_arrays(arrays, schema=self._schema))
        if self._csv is not None:
            for t, row in zip(time, values):
                self._csv.writerow([repr(float(t))] + [repr(float(x)) for x in row])
        self.rows += len(time)

    def close(self, ok=True, log=None):
        """Close the files; move each into place when the run ended well (one that cannot go
        where asked goes to a fallback folder, ``writable.keep``; ``written`` maps each asked
        path to the one written), else remove them."""
        from ..writable import keep
        if self._pq is not None:
            self._pq.close()
        if self._file is not None:
            self._file.close()
        self.written = {}
        for path in (self.csv, self.parquet):
            part = self._part(path) if path is not None else None
            if part is None or not part.exists():
                continue
            if ok:
                self.written[path] = keep(lambda target: _move(part, target), path, log or _warn)[0]
            else:
                part.unlink()


def write_parquet(result, path, log=None) -> Path:
    """An in-memory Result (a libcosim run) as the Parquet file a streamed run writes: the same
    columns, units, manifest and settings in its metadata, written to ``.part`` and moved into
    place (a fallback folder when ``path`` refuses it); returns the path written."""
    sink = Sink(path)
    sink.open(result.columns, result.units or {}, result.manifest, result.settings)
    ok = False
    try:
        sink.write(result.time, result.values)
        ok = True
    finally:
        sink.close(ok, log)
    return sink.written[Path(path)]


def _move(part, target):
    import shutil
    shutil.move(str(part), str(target))


def _warn(text):
    import sys
    print(text, file=sys.stderr)


class Recorder:
    """The rows of a run of ``n`` steps: point ``k`` is kept when ``k % every == 0``.

    Without a sink the rows are one array (``time``, ``values``); with one they pass through a
    buffer of ``block`` rows: the memory a run holds does not grow with its length."""

    def __init__(self, n, step, columns, every=1, sink=None, block=None):
        self.step, self.every, self.sink = step, every, sink
        rows = n // every + 1
        self.size = min(rows, block or BLOCK) if sink else rows
        self.values = np.empty((self.size, columns))
        self.time = np.empty(self.size)
        self.used = 0   # rows of the buffer filled

    def row(self, k):
        """The buffer row to fill for communication point k, or None when k is not kept."""
        if k % self.every:
            return None
        if self.used == self.size:
            self.flush()
        self.time[self.used] = k * self.step
        self.used += 1
        return self.values[self.used - 1]

    def flush(self):
        if self.sink is not None and self.used:
            self.sink.write(self.time[:self.used], self.values[:self.used])
            self.used = 0


class FileResult(Result):
    """A Result whose rows stay in a Parquet file (``path``): ``time`` and each column are read
    when asked; ``values`` reads them all (the whole run in memory)."""

    def __init__(self, path, columns, units, algorithm, step, dynamics, settings, manifest):
        import pyarrow.parquet as pq
        self.path = Path(path)
        self._file = pq.ParquetFile(self.path)
        self._time = None
        super().__init__(None, list(columns), None, algorithm, step, dynamics, settings, units, manifest)

    # the rows stay in the file: ``time`` is read once, ``values`` at each use (the whole run)
    time = property(lambda self: self._read_time(), lambda self, value: None)
    values = property(lambda self: np.column_stack([self._column(c) for c in self.columns])
                      if self.columns else np.empty((len(self), 0)), lambda self, value: None)

    def _read_time(self):
        if self._time is None:
            self._time = self._column("time")
        return self._time

    def _column(self, name):
        return self._file.read(columns=[name]).column(0).to_numpy()

    def __getitem__(self, column):
        if column == "time":
            return self.time
        if column not in self._index:
            return super().__getitem__(column)   # Result's error for an unknown column
        return self._column(column)

    def __len__(self):
        return self._file.metadata.num_rows

    def blocks(self):
        """The rows as in-memory Results of one Parquet row group (``BLOCK`` rows) each."""
        for g in range(self._file.num_row_groups):
            table = self._file.read_row_group(g, columns=["time"] + self.columns)
            block = np.column_stack([table.column(j).to_numpy() for j in range(table.num_columns)])
            yield Result(block[:, 0], list(self.columns), block[:, 1:], self.algorithm, self.step, self.dynamics,
                         self.settings, self.units, self.manifest)

    def thinned(self, rows=PLOT_ROWS) -> Result:
        """An in-memory Result of every k-th row (k the smallest giving at most ``rows``),
        read row group by row group."""
        k = max(1, -(-len(self) // rows))
        keep_t, keep_v, at = [], [], 0
        for block in self.blocks():
            idx = np.arange((-at) % k, len(block.time), k)
            keep_t.append(block.time[idx])
            keep_v.append(block.values[idx])
            at += len(block.time)
        # the run's communication step kept (the plot's title names it), not the rows' spacing
        return Result(np.concatenate(keep_t), list(self.columns), np.concatenate(keep_v), self.algorithm,
                      (self.settings or {}).get("step", self.step), self.dynamics, self.settings, self.units,
                      self.manifest)

    def plot(self, path, split: float | None = None) -> Path:
        """The PNG of ``cosim.report.plot``.  A file longer than ``PLOT_ROWS`` is drawn by a
        fresh Python process that reads it column by column, whole (the envelopes and the
        low-frequency parts count every row): the run's process (its FMUs loaded) then never
        also holds matplotlib and the plotted columns."""
        if len(self) <= PLOT_ROWS:
            return self.thinned().plot(path, split)
        import subprocess
        import sys
        package = __name__.rsplit(".", 2)[0]
        done = subprocess.run([sys.executable, "-c", f"import sys; from {package}.cosim.stream import read_parquet; "
                                                     "s = None if sys.argv[3] == 'None' else float(sys.argv[3]); "
                                                     "read_parquet(sys.argv[1]).plot_here(sys.argv[2], s)",
                               str(self.path), str(path), repr(split)], capture_output=True, text=True)
        if done.returncode:
            last = (done.stderr.strip().splitlines() or ["no message"])[-1]
            raise RuntimeError(f"plotting {self.path} failed: {last}")
        return Path(path)

    def plot_here(self, path, split=None) -> Path:
        """``cosim.report.plot`` of the whole file in this process."""
        return Result.plot(self, path, split)

    def __repr__(self):
        return f"FileResult({self.path}, {len(self)} rows, {len(self.columns)} columns)"


def read_parquet(path) -> FileResult:
    """A Parquet file written by a streamed run (``hydrofmu run``) as a FileResult."""
    import pyarrow.parquet as pq
    meta = pq.read_schema(path).metadata or {}
    get = lambda key: json.loads(meta.get(key.encode(), b"{}"))
    units, manifest, settings = get("hydrofmu.units"), get("hydrofmu.manifest"), get("hydrofmu.settings")
    names = [n for n in pq.read_schema(path).names if n != "time"]
    return FileResult(path, names, {c: u for c, u in units.items() if u}, settings.get("algorithm", ""),
                      float(settings.get("output_interval") or settings.get("step") or 0.0),
                      manifest.get("dynamics"), settings or None, manifest or None)


def select(manifest, names, valid, where="run", field="outputs"):
    """Recorded columns of output names: a body name (its position and attitude),
    ``body.position`` (or attitude, velocity, acceleration), or an ``instance.variable``
    column of ``valid``; an unknown name is an InputError with the closest names."""
    from ..names import unknown
    dynamics = manifest["dynamics"]
    kinds = ("position", "attitude", "velocity", "acceleration")
    cols = []
    for name in names:
        body, _, what = name.partition(".")
        if body in dynamics and (not what or what in kinds):
            inst, prefix = dynamics[body]
            cols += [f"{inst}.{prefix}{w}[{i}]" for w in ([what] if what else kinds[:2]) for i in (1, 2, 3)]
        elif name in valid:
            cols.append(name)
        else:
            named = list(dynamics) + [f"{b}.{w}" for b in dynamics for w in kinds]
            raise InputError(where, None, field, unknown("output", name, named + list(valid)))
    return list(dict.fromkeys(cols))


def plot_columns(manifest):
    """The columns ``cosim.report.plot`` cannot do without: each body's position and attitude,
    each joint's gap, rotation and force on side A (loads it draws as they were recorded)."""
    from .report import joint_sides
    cols = [f"{inst}.{prefix}{w}[{i}]" for inst, prefix in manifest["dynamics"].values()
            for w in ("position", "attitude") for i in (1, 2, 3)]
    for joint in joint_sides(manifest):
        cols += [f"{joint}.{w}[{i}]" for w, n in (("gap", 3), ("rotation", 3), ("A.force", 6)) for i in range(1, n + 1)]
    return cols
