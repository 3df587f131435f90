"""Load-case batches: one scene, a matrix of cases, each case one co-simulation, run on Dask.

A case is a set of knobs (key → value):

- ``environment.current_speed``, ``environment.current_direction``, ``environment.rho``,
  ``environment.g``: the FMUs expose them (current.speed/direction inputs, rho/g
  parameters), so a case sets them at initialisation and shares the build;
- ``instance.variable`` (e.g. ``barge.rho``): any parameter or unconnected input of an FMU;
- any other scene key path (``run.preset``, ``run.substep``, ``bodies.barge.velocity``,
  ``couplings[0].method``; ``stop``, ``step``, ``algorithm`` stand for ``run.…``): the scene
  is read with the override.  Cases whose FMUs come out identical (same typed description)
  share one build, so ``run.stop`` or ``run.step`` (without default joint springs) do not
  rebuild; what the build bakes in (substep, load hold, preset, masses…) is built once per
  distinct variant.

The client builds each variant once, ships its FMUs to the workers as bytes (no shared
disk needed) and keeps a bounded number of cases in flight.  Each case's result (knobs,
status, error, wall time, statistics of the named outputs) is written to
``DIR/cases/<case>.json`` atomically as it finishes; the case id is a hash of everything
that determines the result (build, parameters, run settings, outputs), so a rerun skips
finished cases.  The table (``DIR/cases.csv`` and ``.parquet``) is assembled from those
files at the end.  Needs the ``batch`` extra (Dask distributed, pandas, pyarrow).
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
import shutil
import sys
import tempfile
import threading
import time
import uuid
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .errors import InputError, InputWarning
from . import keys as file_keys
from .names import did_you_mean, unknown
from .physics.rigid_body import LINEAR_RANGE
from .cosim.manifest import read_manifest
from .textfile import read_toml
from .writable import check_folder

RUN_ALIASES = {"stop": "run.stop", "step": "run.step", "algorithm": "run.algorithm",
               "hs": "waves.hs", "tp": "waves.tp", "seed": "waves.seed", "wave_direction": "waves.direction"}
ALGORITHMS = ("jacobi", "gauss-seidel")   # the fmpy master's, which runs every case
# scene keys the FMUs expose: key -> FMU variable name (in every FMU that has it)
EXPOSED = {"environment.current_speed": "current.speed", "environment.current_direction": "current.direction",
           "environment.rho": "rho", "environment.g": "g",
           **{f"waves.{k}": f"waves.{k}" for k in ("hs", "tp", "gamma", "direction", "spreading", "components",
                                                   "seed", "ramp", "height", "period", "phase")}}
# statistics of each output; significant = 4·std (the significant value of a narrow-band
# response, as Hs = 4·sqrt(m0) of the elevation); then the low- and wave-frequency parts and
# the expected extremes of cosim.statistics (docs/running.md)
ANALYST = ("lf_std", "wf_std", "wf_mpm", "lf_mpm", "mpm_max", "mpm_min")
STATS = ("max", "min", "mean", "std", "significant", "final", "initial") + ANALYST
FILE_KEYS = file_keys.names(file_keys.CASES)
SCENE_SECTIONS = ("scene", "environment", "run", "bodies", "joints", "couplings", "waves")


@dataclass
class Batch:
    """A validated case file.  ``scene``: scene file or built scene folder; ``outputs``:
    'instance.variable' names; ``fixed``: knobs of every case; ``matrix``: key → values
    (cases are the cross product); ``extra``: single cases after the matrix ones;
    ``transient`` [s]: statistics leave out t < transient; ``series``: write time series;
    ``split`` [s]: the period between the statistics' LF and WF parts (default 2·Tp of each
    case's sea)."""
    path: Path
    scene: Path
    outputs: list
    fixed: dict = field(default_factory=dict)
    matrix: dict = field(default_factory=dict)
    extra: list = field(default_factory=list)
    transient: float = 0.0
    series: bool = False
    names: dict = field(default_factory=dict)   # canonical key -> the key as the file wrote it (the table's column)
    split: float = None   # period [s] between the LF and WF parts (None: 2·Tp of each case's sea)

    def __len__(self):
        n = math.prod(len(v) for v in self.matrix.values()) if self.matrix else (0 if self.extra else 1)
        return n + len(self.extra)

    def cases(self):
        """Knobs of every case, matrix cases first (lazily: a batch may be large)."""
        if self.matrix or not self.extra:
            keys = list(self.matrix)
            for values in itertools.product(*self.matrix.values()):
                yield {**self.fixed, **dict(zip(keys, values))}
        for case in self.extra:
            yield {**self.fixed, **case}

    @property
    def keys(self):
        out = dict.fromkeys(self.fixed)
        out.update(dict.fromkeys(self.matrix))
        for case in self.extra:
            out.update(dict.fromkeys(case))
        return list(out)

    def column(self, key):
        """The table's column of a knob: its key as the case file wrote it (``hs``, not ``waves.hs``)."""
        return self.names.get(key, key)


def _canonical(key):
    return RUN_ALIASES.get(key, key)


def _flat(table, prefix=""):
    """(key path, value) of a table of knobs: a TOML dotted key (``run.stop = 5``, a nested
    table) reads as the quoted one (``"run.stop" = 5``)."""
    for key, value in table.items():
        path = f"{prefix}.{key}" if prefix else str(key)
        if isinstance(value, dict) and value:
            yield from _flat(value, path)
        else:
            yield path, value


def _knobs(p, table, where, seen=None):
    """A table of knobs with canonical keys; values must be numbers, strings, booleans or
    arrays of numbers (what a scene holds).  ``seen`` (canonical key → how it was written
    and where) spans the tables that make one case: a knob given twice is an error."""
    out = {}
    seen = {} if seen is None else seen
    for key, value in _flat(table):
        if not key:
            p.add(f"{where}.{key}", "expected a key path")
            continue
        canonical = _canonical(key)
        if canonical in seen:
            p.add(f"{where}.{key}", f"given twice: also {seen[canonical]} (one value per knob)")
            continue
        seen[canonical] = f"{where + '.' if where else ''}{key}"
        out[canonical] = value
    return out


def _kind(value):
    if isinstance(value, bool):
        return "a boolean"
    if isinstance(value, (int, float)):
        return "a number"
    return "a string" if isinstance(value, str) else "an array" if isinstance(value, list) else "a table"


def _one_kind(p, where, key, values):
    """The values of one knob: one kind (the table's column holds one type: a string among
    numbers ended the batch after every case had run), and numbers where the knob is an FMU
    parameter (``instance.variable``, or a scene key the FMUs expose as one).  Recorded in
    ``p`` naming the key and the value, before any case runs."""
    first = key.split(".", 1)[0].split("[", 1)[0]
    real = key in EXPOSED or (first not in SCENE_SECTIONS and "." in key and not key.startswith("run."))
    for value in values:
        if real and _kind(value) != "a number":   # NaN passes: the case fails, the others run
            p.add(where, f"value {value!r} is not a number: {key} is a real parameter of the FMUs")
            return
    kinds = [_kind(v) for v in values]
    odd = next((k for k, kind in enumerate(kinds) if kind != kinds[0]), None)
    if odd is not None:
        p.add(where, f"value {values[odd]!r} is {kinds[odd]} among {kinds[0].split()[1]}s ({values[0]!r}, …): every case's "
                     "value of a knob is one kind (the table's column)")


def load_cases(source, base=None) -> Batch:
    """Read and check a case file (path) or the same content as a dict (paths in it relative
    to ``base``, default the current folder).  Raises one InputError naming every problem."""
    from .scene import Problems
    if isinstance(source, dict):
        path, doc = Path(base or ".") / "<cases>", source
    else:
        path = Path(source)
        doc = read_toml(path, "case file")
    p = Problems(path)
    p.known_keys(doc, "", FILE_KEYS)
    name = p.string(doc, "scene", "scene")
    scene = (path.parent / name).resolve() if name else None
    if scene is not None and not (scene.is_file() or (scene / "manifest.json").is_file()):
        p.add("scene", f"no scene file or built scene folder (manifest.json) at {scene}")
    outputs = doc.get("outputs")
    if (not isinstance(outputs, list) or not outputs
            or not all(isinstance(o, str) and "." in o for o in outputs)):
        p.add("outputs", "expected a non-empty array of 'instance.variable' names")
        outputs = []
    twice = sorted({o for o in outputs if outputs.count(o) > 1})
    if twice:
        p.add("outputs", f"{', '.join(map(repr, twice))} given twice (one column per output)")
    fixed, seen = {}, {}
    for key in ("stop", "step"):
        if key in doc and p.number(doc, key, key, positive=True) is not None:
            fixed[f"run.{key}"] = float(doc[key])
            seen[f"run.{key}"] = f"{key} (top level)"
    if "algorithm" in doc and p.choice(doc, "algorithm", "algorithm", ALGORITHMS):
        fixed["run.algorithm"] = doc["algorithm"]
        seen["run.algorithm"] = "algorithm (top level)"
    transient = p.number(doc, "transient", "transient", 0.0, nonneg=True)
    series = doc.get("series", False)
    if not isinstance(series, bool):
        p.add("series", f"expected true or false, found {series!r}")
    fixed.update(_knobs(p, p.table(doc, "set", "set", required=False) or {}, "set", seen))
    matrix = {}
    shared = dict(seen)   # the top level, [set] and [matrix] make every case
    for key, values in _knobs(p, p.table(doc, "matrix", "matrix", required=False) or {}, "matrix", shared).items():
        values = values if isinstance(values, list) else [values]
        if not values:
            p.add(f"matrix.{key}", "expected at least one value")
        again = next((v for k, v in enumerate(values) if v in values[:k]), None)
        if again is not None:
            p.add(f"matrix.{key}", f"value {again!r} given twice (two cases would be one)")
        _one_kind(p, f"matrix.{key}", key, values)
        matrix[key] = values
    extra = doc.get("cases", [])
    if not isinstance(extra, list) or not all(isinstance(c, dict) for c in extra):
        p.add("cases", "expected an array of tables ([[cases]])")
        extra = []
    # a single case may override a shared knob (its own value), not give one twice itself
    extra = [_knobs(p, c, f"cases[{i}]") for i, c in enumerate(extra)]
    for where, knobs in [("set", fixed)] + [(f"cases[{i}]", c) for i, c in enumerate(extra)]:
        for key, value in knobs.items():
            _one_kind(p, f"{where}.{key}", key, [value])
    # the algorithm is one knob wherever it is written: checked the same in every table
    for where, value in ([("set.run.algorithm", fixed.get("run.algorithm"))]
                         + [("matrix.run.algorithm", v) for v in matrix.get("run.algorithm", [])]
                         + [(f"cases[{i}].run.algorithm", c.get("run.algorithm")) for i, c in enumerate(extra)]):
        if value is not None and value not in ALGORITHMS:
            p.add(where, f"expected one of {', '.join(map(repr, ALGORITHMS))} (a batch runs on the fmpy master), "
                         f"found {value!r}")
    split = p.number(doc, "split", "split", positive=True) if "split" in doc else None
    batch = Batch(path, scene, outputs, fixed, matrix, extra, transient or 0.0, series is True, _written(doc),
                  split)
    built = scene is not None and scene.is_dir()
    for key in batch.keys:
        first = key.split(".", 1)[0].split("[", 1)[0]
        if built and key.startswith("run.") and key not in RUN_ALIASES.values():
            p.add(key, "a built folder runs with stop, step and algorithm only: name the scene file to change "
                       f"{key}{did_you_mean(key, RUN_ALIASES.values())}")
        elif first in SCENE_SECTIONS and built and key not in EXPOSED and not key.startswith("run."):
            p.add(key, "the build bakes this in: name the scene file, not a built folder")
        elif first not in SCENE_SECTIONS and "." not in key:
            p.add(key, f"expected a scene key path ({', '.join(SCENE_SECTIONS)}…), 'instance.variable', "
                       "or stop/step/algorithm")
    p.raise_if_any()
    return batch


def _written(doc):
    """{canonical key: the key as written} of a case file's knobs (the first spelling met)."""
    names = {k: k for k in ("stop", "step", "algorithm") if k in doc}
    tables = [doc.get("set"), doc.get("matrix")] + list(doc.get("cases") or [])
    for table in tables:
        if isinstance(table, dict):
            for key, _ in _flat(table):
                names.setdefault(_canonical(key), key)
    return {_canonical(k): v for k, v in names.items()}


def _first_values(batch):
    """{knob: its first value in the file} (matrix knobs: their first value)."""
    out = {}
    for case in [batch.fixed, {k: v[0] for k, v in batch.matrix.items() if v}, *batch.extra]:
        for key, value in case.items():
            out.setdefault(key, value)
    return out


def _steps_of(key):
    import re
    return [int(x[1:-1]) if x.startswith("[") else x for x in re.findall(r"\[\d+\]|[^.\[\]]+", key)]


def _near(doc, key):
    """Key paths of the scene ``doc`` near ``key``: the names at the first step it misses."""
    node, prefix = doc, ""
    for step in _steps_of(key):
        if isinstance(step, int):
            if not isinstance(node, list) or step >= len(node):
                return [f"{prefix}[{i}]" for i in range(len(node))] if isinstance(node, list) else []
            node, prefix = node[step], f"{prefix}[{step}]"
            continue
        if not isinstance(node, dict) or step not in node:
            return [f"{prefix}.{k}" if prefix else k for k in node] if isinstance(node, dict) else []
        node, prefix = node[step], f"{prefix}.{step}" if prefix else step
    return []


def check_knobs(batch):
    """Every knob of a case file checked against its scene before anything is built or run:
    a scene key path must exist in the scene (or be a key its table allows), a stop must be a
    whole number of steps.  One InputError naming the case file, the knob and the closest
    valid names."""
    import copy
    from .scene import load_scene, override
    if batch.scene.is_dir():
        run = read_manifest(batch.scene)["run"]
        _check_transient(batch, run)
    else:
        doc = read_toml(batch.scene, "scene")
        _check_sea_knobs(batch, doc)
        first = {k: v for k, v in _first_values(batch).items()
                 if k.split(".", 1)[0].split("[", 1)[0] in SCENE_SECTIONS and k not in EXPOSED}
        for key, value in first.items():
            try:
                override(copy.deepcopy(doc), key, value, batch.scene)
            except InputError as exc:
                raise InputError(batch.path, None, key, f"not in scene {batch.scene.name}: {exc.message}"
                                                        f"{did_you_mean(key, _near(doc, key))}") from None
        with warnings.catch_warnings():   # the scene's warnings are said by the cases' own loads
            warnings.simplefilter("ignore", InputWarning)
            if first:
                _check_scene_keys(batch, first)
            if not {"run.stop", "run.step"} & set(batch.keys) and not batch.transient:
                return None
            try:
                run = load_scene(batch.scene).run
            except InputError:
                return None   # the scene's own error is every case's
        _check_transient(batch, run)
    _check_case_steps(batch, run)


def _check_sea_knobs(batch, doc):
    """Every value of a ``waves.*`` knob (FMU parameters: the scene's checks never see them)
    against what a sea can be and the memory (admissible.sea_problems, the scene's component
    limit), the scene's other [waves] values kept: one InputError naming the knob and value."""
    from .admissible import sea_problems, size_problem
    from .scene.waves import COMPONENT_BYTES, MAX_COMPONENTS
    waves = doc.get("waves")
    if not isinstance(waves, dict):
        return
    spectrum = waves.get("spectrum", "jonswap")
    for key in batch.keys:
        if not key.startswith("waves."):
            continue
        name = key.split(".", 1)[1]
        values = list(batch.matrix.get(key, [])) + [c[key] for c in [batch.fixed, *batch.extra] if key in c]
        for value in values:
            if _kind(value) != "a number":
                continue
            errors = [m for k, m in sea_problems(spectrum, {**waves, name: value})[0] if k == name]
            if name == "components" and spectrum != "regular":
                big = size_problem(value, COMPONENT_BYTES, "wave components")
                errors += [big] if big else [f"more than {MAX_COMPONENTS:.0e}"] if value > MAX_COMPONENTS else []
            if errors:
                raise InputError(batch.path, None, key, f"value {value!r}: {errors[0]}")


def _check_transient(batch, run):
    """The statistics' ``transient`` must leave part of every case's run (t < stop)."""
    if not batch.transient:
        return
    stops = {knobs.get("run.stop", run["stop"]) for knobs in batch.cases()}
    short = min((s for s in stops if isinstance(s, (int, float)) and not isinstance(s, bool)), default=None)
    if short is not None and batch.transient >= short:
        raise InputError(batch.path, None, "transient", f"{batch.transient:g} s leaves nothing of a case that ends "
                                                        f"at {short:g} s (the statistics keep t ≥ transient)")


def _check_scene_keys(batch, first):
    """Scene knobs ``first`` ({key: a value}) whose key the scene does not allow: InputError."""
    from .scene import load_scene
    try:
        load_scene(batch.scene, first)
    except InputError as exc:
        unknown = getattr(exc, "unknown", {})
        if exc.field in first and exc.field not in unknown:   # the knob's own value refused: every case's error
            raise InputError(batch.path, None, exc.field, f"value {first[exc.field]!r}: "
                                                          f"{exc.message.split('; ')[0]}") from None
        for key in first:
            if key in unknown:
                parent = key.rsplit(".", 1)[0]
                valid = [f"{parent}.{k}" for k in exc.unknown[key]]
                raise InputError(batch.path, None, key, f"unknown knob: {batch.scene.name} has no key {key}"
                                                        f"{did_you_mean(key, valid)}") from None


def _check_case_steps(batch, run):
    """stop a whole number of steps in every case that sets stop or step."""
    from .admissible import whole_steps
    number = lambda v: isinstance(v, (int, float)) and not isinstance(v, bool)
    def check(stop, step, knobs):
        if not ({"run.stop", "run.step"} & set(knobs)) or "run.preset" in knobs:
            return   # the scene's own settings (checked by the scene), or a preset's step per case
        if number(stop) and number(step) and stop > 0 and step > 0:
            for field_, message in whole_steps(stop, step)[1]:
                raise InputError(batch.path, None, f"run.{field_}", f"{message} (stop {stop:g}, step {step:g})")
    fixed = batch.fixed
    if batch.matrix or not batch.extra:
        stops = batch.matrix.get("run.stop", [fixed.get("run.stop", run["stop"])])
        steps = batch.matrix.get("run.step", [fixed.get("run.step", run["step"])])
        knobs = set(fixed) | set(batch.matrix)
        for stop, step in itertools.product(stops, steps):
            check(stop, step, knobs)
    for case in batch.extra:
        knobs = {**fixed, **case}
        check(knobs.get("run.stop", run["stop"]), knobs.get("run.step", run["step"]), knobs)


def check_names(batch, variables):
    """Outputs and 'instance.variable' knobs against the FMUs' variables ({name: causality}):
    one InputError naming the case file, the name and the closest valid names."""
    for name in batch.outputs:
        if name not in variables:
            raise InputError(batch.path, None, "outputs", unknown("output", name, list(variables)))
    settable = [n for n, c in variables.items() if c in ("input", "parameter")]
    direct = [k for k in batch.keys if k not in EXPOSED and k.split(".", 1)[0].split("[", 1)[0] not in SCENE_SECTIONS]
    for key in direct:
        if key not in settable:
            raise InputError(batch.path, None, key, unknown("parameter or unconnected input", key, settable))
        for exposed in EXPOSED:
            if exposed in batch.keys and key.split(".", 1)[1] == EXPOSED[exposed]:
                raise InputError(batch.path, None, key, f"given twice: {exposed} sets {EXPOSED[exposed]} of every FMU, "
                                                        f"{key} too (one value per knob)")


# --- variants: one build per distinct set of FMUs -------------------------------------

def _digest(obj):
    return hashlib.sha256(json.dumps(obj, sort_keys=True, default=str).encode()).hexdigest()[:16]


@dataclass
class Variant:
    """A build shared by cases: ``id`` (hash of its FMU descriptions and runtime), its
    ``folder``, run settings of the scene read with the case's overrides, the FMU
    variables a case may set (name → causality) or the ``error`` that stops its cases."""
    id: str = None
    folder: Path = None
    run: dict = None
    variables: dict = None
    error: str = None
    blob: object = None   # the scattered FMU bytes (a Dask future), on the shared build


class Variants:
    """Scene variants of a batch, read and built on first use, each built once."""

    def __init__(self, batch, out, log):
        from .fmi.build import runtime_name
        self.batch, self.out, self.log = batch, Path(out), log
        self.runtime = runtime_name()
        self.groups = {}      # scene overrides (json) -> Variant
        self.builds = {}      # variant id -> Variant
        self.checked = {}     # (exposed key, value) -> error or None

    def scene(self, overrides):
        from .scene import load_scene
        return load_scene(self.batch.scene, overrides)

    def get(self, overrides) -> Variant:
        key = json.dumps(overrides, sort_keys=True, default=str)
        if key not in self.groups:
            self.groups[key] = self._make(overrides)
        return self.groups[key]

    def _make(self, overrides):
        if self.batch.scene.is_dir():
            folder = self.batch.scene
            manifest = read_manifest(folder)
            files = sorted(str(f.relative_to(folder)) for f in folder.iterdir() if f.is_file())
            vid = _digest([self.runtime, str(folder), files, [(folder / f).stat().st_mtime for f in files]])
            run = {k: manifest["run"][k] for k in ("step", "stop", "algorithm")}
            run.update({k[4:]: v for k, v in overrides.items()})
            if vid not in self.builds:
                self.builds[vid] = Variant(vid, folder, None, _variables(folder))
            return Variant(vid, folder, run, self.builds[vid].variables)
        from .assembly import assemble
        from .description import to_plain
        from .fmi.build import build_scene
        try:
            scene = self.scene(overrides)
            vid = _digest([self.runtime, [[i.name, i.model_id, i.motion, i.forces, to_plain(i.fmu)]
                                          for i in assemble(scene).instances]])
        except InputError as exc:
            return Variant(error=str(exc))
        run = {k: scene.run[k] for k in ("step", "stop", "algorithm")}
        if vid not in self.builds:
            home = self.out / "builds" / vid
            folder = home / scene.name
            try:
                if not (folder / "manifest.json").is_file():
                    self.log(f"building variant {vid} ({_describe(overrides) or 'the scene as it is'})")
                    build_scene(scene, home, log=lambda *_: None)
                self.builds[vid] = Variant(vid, folder, None, _variables(folder))
            except Exception as exc:  # a build failure stops this variant's cases only
                self.builds[vid] = Variant(vid, error=f"build failed: {type(exc).__name__}: {exc}")
        built = self.builds[vid]
        return Variant(vid, built.folder, run, built.variables, built.error)

    def exposed_error(self, key, value):
        """The scene's own verdict on an exposed value (read once per distinct value)."""
        if (key, repr(value)) not in self.checked:
            error = None
            if self.batch.scene.is_dir():
                if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                    error = f"{key}: expected a finite number, found {value!r}"
            else:
                try:
                    self.scene({key: value})
                except InputError as exc:
                    error = str(exc)
            self.checked[(key, repr(value))] = error
        return self.checked[(key, repr(value))]


def _variables(folder):
    """{'instance.variable': causality} of a built scene's FMUs."""
    from fmpy import read_model_description
    manifest = read_manifest(folder)
    out = {}
    for name, inst in manifest["instances"].items():
        for v in read_model_description(str(Path(folder) / inst["fmu"])).modelVariables:
            out[f"{name}.{v.name}"] = v.causality
    connected = {f"{dst}.{dvar}" for _, _, dst, dvar in manifest["connections"]}
    return {k: c for k, c in out.items() if not (c == "input" and k in connected)}


def _describe(knobs):
    return ", ".join(f"{k} = {v}" for k, v in knobs.items())


def _blob(variant):
    """The built folder as bytes: what the workers receive."""
    return {"id": variant.id, "files": {f.name: f.read_bytes() for f in sorted(variant.folder.iterdir())
                                        if f.is_file()}}


# --- one case, on a worker ----------------------------------------------------------

_LOCK = threading.Lock()   # one co-simulation at a time per process (pythonfmu hosts in-process)


def _materialize(blob):
    """The shipped FMUs in a folder of this worker (written once per variant)."""
    try:
        from distributed import get_worker
        base = Path(get_worker().local_directory)
    except (ImportError, ValueError):
        base = Path(tempfile.gettempdir())
    folder = base / "hydrofmu-batch" / blob["id"]
    if not (folder / "manifest.json").is_file():
        tmp = folder.with_name(f".{blob['id']}.{os.getpid()}.{uuid.uuid4().hex[:8]}")
        tmp.mkdir(parents=True)
        for name, data in blob["files"].items():
            (tmp / name).write_bytes(data)
        try:
            tmp.rename(folder)
        except OSError:   # another process got there first
            shutil.rmtree(tmp, ignore_errors=True)
    return folder


def statistics(time_, values, outputs, transient=0.0, split=None):
    """{'<output>.<stat>': value} of ``STATS`` over the samples with t ≥ transient: max, min, mean,
    std (plain sample statistics, the steps being equal), significant = 4·std, final; ``initial``:
    the value at the start of the run (a body's position: its static pose, which the plot leaves
    out); and the figures ``ANALYST`` of ``cosim.statistics.describe``, split at ``split`` [s]
    (None: the LF and WF figures are NaN)."""
    from .cosim.statistics import describe
    at = time_ >= transient - 1e-9 * max(1.0, abs(transient))
    keep = values[at]
    t = time_[at]
    dt = float((t[-1] - t[0]) / (t.size - 1)) if t.size > 1 else 1.0
    out = {}
    for j, name in enumerate(outputs):
        col = keep[:, j]
        more = describe(col, dt, split)
        for stat, value in zip(STATS, (col.max(), col.min(), col.mean(), col.std(), 4 * col.std(), col[-1],
                                       values[0, j]) + tuple(more[k] for k in ANALYST)):
            out[f"{name}.{stat}"] = float(value)
    return out


# the cases' linear_range column: false past the dynamics partner's linear range (15°)
LINEAR_RANGE_DEG = math.degrees(LINEAR_RANGE)


def _tilt_columns(folder):
    """The roll and pitch columns of every body of a built scene (its manifest's dynamics)."""
    from .cosim.manifest import read_manifest
    return [f"{inst}.{prefix}attitude[{k}]" for inst, prefix in read_manifest(folder)["dynamics"].values()
            for k in (1, 2)]


def _max_tilt(columns, values, tilt):
    """The largest |roll| or |pitch| [deg] over the run, of the ``tilt`` columns recorded."""
    cols = [columns.index(c) for c in tilt if c in columns]
    return float(np.degrees(np.nanmax(np.abs(values[:, cols])))) if cols and len(values) else 0.0


def run_case(task, blob):
    """Run one case on a worker; never raises for a failing case (status 'failed', error)."""
    from .cosim.master import run
    with _LOCK:
        t0 = time.perf_counter()
        out = {"case": task["case"], "status": "ok", "error": None, "wall_s": None, "stats": {}, "series": None,
               "linear_range": None, "max_tilt_deg": None}
        tilt = []
        said = out["warnings"] = []   # the FMUs' warnings: the client says them with the case's name
        try:
            folder = _materialize(blob)
            tilt = _tilt_columns(folder)
            record = list(task["outputs"]) + [c for c in tilt if c not in task["outputs"]]
            t0 = time.perf_counter()
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                result = run(folder, record=record, parameters=task["parameters"], progress=False, say=said.append,
                             **task["run"])
            said += [f"{w.category.__name__}: {w.message}" for w in caught]
        except Exception as exc:   # a failing case is reported, the batch goes on
            text = str(exc)
            # capsized (the dynamics partner's word): said first, not as an exception's class
            error = f"capsized{text.split('capsized', 1)[1]} ({text.split(':', 1)[0]})" if "capsized:" in text \
                else f"{type(exc).__name__}: {text}"
            out.update(status="failed", error=error, wall_s=time.perf_counter() - t0)
            partial = getattr(exc, "partial", None)
            if "capsized:" in text:
                out.update(linear_range=False, max_tilt_deg=90.0 if partial is None else
                           max(90.0, _max_tilt(partial.columns, partial.values, tilt)))
            return out
        out["wall_s"] = time.perf_counter() - t0
        worst = _max_tilt(record, result.values, tilt)
        out.update(max_tilt_deg=worst, linear_range=bool(worst <= LINEAR_RANGE_DEG))
        values = result.values[:, :len(task["outputs"])]
        bad = ~np.isfinite(values)
        if bad.any():
            k, j = np.argwhere(bad)[0]
            out.update(status="failed", error=f"diverged: {task['outputs'][j]} = {values[k, j]} at t = "
                                              f"{result.time[k]:g} s")
        out["stats"] = statistics(result.time, values, task["outputs"], task["transient"], task.get("split"))
        if task["series"]:
            out["series"] = (result.time, values)
        try:
            from distributed import get_worker
            out["worker"] = get_worker().address
        except (ImportError, ValueError):
            pass
        return out


# --- the batch ----------------------------------------------------------------------

def _write_json(path, obj):
    """Atomic: a killed batch leaves whole files or none."""
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    tmp.write_text(json.dumps(obj, default=str))
    os.replace(tmp, path)


def _done(path, retry_failed):
    try:
        status = json.loads(path.read_text())["status"]
    except (OSError, ValueError, KeyError):
        return False
    return status == "ok" or (status == "failed" and not retry_failed)


class Progress:
    """A progress line on stderr: cases done, failed, skipped, the estimated time left."""

    def __init__(self, total, stream=None, enabled=True):
        self.total, self.stream, self.enabled = total, stream or sys.stderr, enabled
        self.done = self.failed = self.skipped = 0
        self.t0, self.last = time.perf_counter(), 0.0
        self.tty = hasattr(self.stream, "isatty") and self.stream.isatty()

    def update(self, ok=None, skipped=False, force=False):
        if skipped:
            self.skipped += 1
        elif ok is not None:
            self.done += 1
            self.failed += not ok
        now = time.perf_counter()
        if not self.enabled or (not force and now - self.last < (0.2 if self.tty else 10.0)):
            return
        self.last = now
        finished = self.done + self.skipped
        eta = ((now - self.t0) / self.done * (self.total - finished)) if self.done else float("nan")
        bar = "#" * int(30 * finished / max(self.total, 1))
        line = (f"batch [{bar:<30}] {finished}/{self.total} cases, {self.failed} failed"
                + (f", {self.skipped} from an earlier run" if self.skipped else "")
                + (f", {_clock(eta)} left" if math.isfinite(eta) and finished < self.total else ""))
        self.stream.write(("\r" + line) if self.tty else line + "\n")
        self.stream.flush()

    def close(self):
        self.update(force=True)
        if self.enabled and self.tty:
            self.stream.write("\n")


def _clock(seconds):
    seconds = int(round(seconds))
    return f"{seconds // 3600}:{seconds // 60 % 60:02d}:{seconds % 60:02d}" if seconds >= 3600 else \
        f"{seconds // 60}:{seconds % 60:02d}"


def _open_client(client, scheduler, workers):
    """(client, things to close): the given client, one on ``scheduler``, or a LocalCluster."""
    import logging
    from distributed import Client, LocalCluster
    if client is not None:
        return client, []
    if scheduler:
        try:
            c = Client(scheduler, timeout=30)
        except (OSError, TimeoutError, ValueError) as exc:
            raise InputError("command line", None, "--scheduler",
                             f"no Dask scheduler answers at {scheduler!r} ({exc})") from None
        return c, [c]
    cluster = LocalCluster(n_workers=workers or os.cpu_count() or 1, threads_per_worker=1, processes=True,
                           dashboard_address=":0", silence_logs=logging.ERROR)
    c = Client(cluster)
    return c, [c, cluster]


def _sea_split(variant, exposed, seas):
    """A case's default split period [s]: 2·Tp of its sea (the build's, or the case's own
    ``waves.tp`` / ``waves.period``); None without a sea.  ``seas`` caches each build's sea."""
    from .cosim.statistics import SPLIT_TP
    if variant.folder is None:
        return None
    if variant.folder not in seas:
        try:
            seas[variant.folder] = read_manifest(variant.folder)["run"].get("waves")
        except (OSError, KeyError, ValueError, InputError):
            seas[variant.folder] = None
    sea = seas[variant.folder]
    if not sea:
        return None
    period = exposed.get("waves.period" if sea.get("spectrum") == "regular" else "waves.tp", sea.get("period"))
    return SPLIT_TP * period if isinstance(period, (int, float)) and period > 0 else None


def _plan(batch, variants, log):
    """(case id, knobs, variant, task, error) of every case, lazily.  Names every case
    shares (outputs, FMU variables) are checked on the first case: a wrong one is an
    InputError; a bad value is the error of its case only."""
    first, unused, seas = True, set(), {}
    for knobs in batch.cases():
        exposed = {k: v for k, v in knobs.items() if k in EXPOSED}
        direct = {k: v for k, v in knobs.items()
                  if k not in EXPOSED and k.split(".", 1)[0].split("[", 1)[0] not in SCENE_SECTIONS}
        overrides = {k: v for k, v in knobs.items() if k not in exposed and k not in direct}
        variant = variants.get(overrides)
        errors = [variant.error] if variant.error else []
        errors += [e for e in (variants.exposed_error(k, v) for k, v in exposed.items()) if e]
        parameters = {}
        if variant.variables is not None:
            if first:
                check_names(batch, variant.variables)
            wrong = [k for k in direct if variant.variables.get(k) not in ("input", "parameter")]
            missing = [o for o in batch.outputs if o not in variant.variables]
            problems = ([f"{k}: not a parameter or unconnected input of the FMUs" for k in wrong]
                        + ([f"not outputs of the FMUs: {', '.join(missing)}"] if missing else []))
            errors += problems
            for key, value in exposed.items():
                names = [n for n, c in variant.variables.items()
                         if n.split(".", 1)[1] == EXPOSED[key] and c in ("input", "parameter")]
                if not names and key not in unused:
                    unused.add(key)
                    log(f"note: {key} changes nothing: no FMU of the scene has {EXPOSED[key]}")
                parameters.update(dict.fromkeys(names, value))
            parameters.update(direct)
            first = False
        split = batch.split or _sea_split(variant, exposed, seas)
        cid = _digest([sorted(knobs.items()), variant.id, variant.error, variant.run, parameters,
                       batch.outputs, batch.transient, split])
        task = {"case": cid, "run": variant.run, "parameters": parameters, "outputs": batch.outputs,
                "transient": batch.transient, "series": batch.series, "split": split}
        yield cid, knobs, variant, task, "; ".join(errors) or None


def run_batch(cases, out, workers=None, scheduler=None, client=None, series=None, retry_failed=False,
              progress=True, log=None, window=None):
    """Run a batch; returns its table (pandas DataFrame, one row per case).

    ``cases``: a case file, a dict of the same content or a ``Batch``; ``out``: results
    folder (``cases/``, ``cases.csv``, ``cases.parquet``, ``cases.png``, ``series/``, ``builds/``);
    ``workers``: LocalCluster size (default: this machine's cores); ``scheduler``: address
    of an existing Dask scheduler; ``client``: an existing ``distributed.Client``;
    ``series``: write each case's time series (default: the case file's ``series``);
    ``retry_failed``: rerun failed cases too (cases that lost their worker always rerun);
    ``window``: cases in flight at once (default: twice the worker threads).
    """
    if workers is not None and (isinstance(workers, bool) or not isinstance(workers, int) or workers < 1):
        raise InputError("command line", None, "--workers", f"expected a positive whole number, found {workers!r}")
    batch = cases if isinstance(cases, Batch) else load_cases(cases)
    if series is not None:
        batch.series = series
    log = log or (lambda text: print(text, file=sys.stderr))
    out = Path(check_folder(out))
    check_knobs(batch)
    # a batch refused before its first case is recorded leaves no folder it made
    made = next((p for p in [out, *out.parents][::-1] if not p.exists()), None)
    try:
        return _run_batch(batch, out, workers, scheduler, client, retry_failed, progress, log, window)
    except InputError:
        if made is not None and not (out / "cases").exists():
            shutil.rmtree(made, ignore_errors=True)
        raise


def _run_batch(batch, out, workers, scheduler, client, retry_failed, progress, log, window):
    variants = Variants(batch, out, log)
    token = uuid.uuid4().hex[:12]
    ids = []
    bar = Progress(len(batch), enabled=progress)
    client_, closing = None, []
    if scheduler and client is None:   # a wrong address is told before anything is built
        client_, closing = _open_client(None, scheduler, None)

    kept = {}   # case rows that could not be written to cases/ (disk full, folder gone): the table has them

    def record(cid, knobs, variant, result):
        said = result.get("warnings") or []
        name = case_name(batch, cid, knobs)
        for text in said:   # a worker's warning, named by its case
            log(f"warning: {name}: {text}")
        row = {"case": cid, "knobs": knobs, "status": result["status"], "error": result["error"],
               "wall_s": result["wall_s"], "stats": result["stats"], "build": variant.id, "batch": token,
               "linear_range": result.get("linear_range"), "max_tilt_deg": result.get("max_tilt_deg"),
               "worker": result.get("worker"), "warnings": said}
        try:
            (out / "cases").mkdir(parents=True, exist_ok=True)   # here: a batch refused at its first case writes none
            if result.get("series") is not None:
                (out / "series").mkdir(exist_ok=True)
                _write_series(out / "series" / f"{cid}.parquet", *result["series"], batch.outputs)
            _write_json(out / "cases" / f"{cid}.json", row)
        except OSError as exc:
            if not kept:
                log(f"warning: cannot write in {out} ({exc.strerror or exc}): the cases' results are kept for "
                    "the table (written elsewhere if need be), time series are lost")
            kept[cid] = row
        bar.update(ok=result["status"] == "ok")

    try:
        inflight, seen, ac = {}, set(), None
        for cid, knobs, variant, task, error in _plan(batch, variants, log):
            ids.append(cid)
            if cid in seen:   # the same case twice in the file: run once
                bar.update(skipped=True)
                continue
            seen.add(cid)
            path = out / "cases" / f"{cid}.json"
            if _done(path, retry_failed) and (not batch.series or (out / "series" / f"{cid}.parquet").is_file()):
                bar.update(skipped=True)
                continue
            if error:
                record(cid, knobs, variant, {"status": "failed", "error": error, "wall_s": None, "stats": {}})
                continue
            if ac is None:
                from distributed import as_completed
                if client_ is None:
                    client_, closing = _open_client(client, scheduler, workers)
                bar.t0 = time.perf_counter()   # the estimate counts case time, not start-up
                ac = as_completed()
                threads = sum(client_.nthreads().values())
                window = window or max(2, 2 * threads)
            shared = variants.builds[variant.id]
            if shared.blob is None:   # the FMUs go to the workers once per build, as bytes
                # on every worker: a worker lost takes no build with it (a dict would scatter by key)
                shared.blob = client_.scatter([_blob(shared)], hash=False, broadcast=True)[0]
            while len(inflight) >= window:
                _collect(next(ac), inflight, record)
            future = client_.submit(run_case, task, shared.blob, key=f"case-{cid}-{token}", pure=False)
            inflight[future] = (cid, knobs, variant)
            ac.add(future)
        while inflight:
            _collect(next(ac), inflight, record)
    finally:
        for c in closing:
            c.close()
        bar.close()
    return assemble_table(out, ids, batch, _output_units(variants, batch.outputs), kept, log)


def case_name(batch, cid, knobs):
    """'case 1a2b3c4d (hs = 3, wave_direction = 45)': a case as its warnings name it (the
    first 8 characters of its id, its knobs as the case file wrote them)."""
    return f"case {cid[:8]} (" + ", ".join(f"{batch.column(k)} = {_cell(v)}" for k, v in knobs.items()) + ")"


def _output_units(variants, outputs):
    """Output -> unit, from the FMUs of the first build that succeeded ({} if none did)."""
    from .cosim.result import column_units
    for v in variants.builds.values():
        if v.folder is not None and v.error is None:
            try:
                return column_units(v.folder, json.loads((v.folder / "manifest.json").read_text()), outputs)
            except (OSError, KeyError, ValueError):
                return {}
    return {}


def _collect(future, inflight, record):
    cid, knobs, variant = inflight.pop(future)
    try:
        result = future.result()
    except Exception as exc:   # the worker was lost (KilledWorker, connection closed…)
        result = {"status": "lost", "error": f"{type(exc).__name__}: {exc}", "wall_s": None, "stats": {}}
    future.release()
    record(cid, knobs, variant, result)


def _write_series(path, time_, values, outputs):
    import pandas as pd
    frame = pd.DataFrame(values, columns=outputs)
    frame.insert(0, "time", time_)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    frame.to_parquet(tmp, index=False)
    os.replace(tmp, path)


def read_series(out, case):
    """The time series of one case (DataFrame: time and the outputs)."""
    import pandas as pd
    return pd.read_parquet(Path(out) / "series" / f"{case}.parquet")


def assemble_table(out, ids, batch, units=None, kept=None, log=print):
    """The batch table from the per-case files (or ``kept``: rows that could not be written):
    one row per case (knobs, status, wall time, statistics, error, case id, build id); written
    as cases.csv, cases.parquet and the plot, each to a fallback folder when ``out`` refuses
    it (``table.attrs['written']``: asked path → path written)."""
    import pandas as pd
    from .writable import keep
    rows = []
    for cid in ids:
        r = (kept or {}).get(cid) or json.loads((Path(out) / "cases" / f"{cid}.json").read_text())
        rows.append({**{batch.column(k): _cell(v) for k, v in r["knobs"].items()}, "status": r["status"],
                     "wall_s": r["wall_s"], "linear_range": r.get("linear_range"), "max_tilt_deg": r.get("max_tilt_deg"),
                     **r["stats"], "error": r["error"], "warnings": "; ".join(r.get("warnings") or []),
                     "case": r["case"], "build": r["build"]})
    stats = [f"{o}.{s}" for o in batch.outputs for s in STATS]
    columns = ([batch.column(k) for k in batch.keys] + ["status", "wall_s", "linear_range", "max_tilt_deg"] + stats
               + ["error", "warnings", "case", "build"])
    table = pd.DataFrame(rows, columns=columns)
    written = {}
    for name, write in (("cases.csv", lambda p: table.to_csv(p, index=False)),
                        ("cases.parquet", lambda p: table.to_parquet(p, index=False)),
                        ("cases.png", lambda p: plot(table, batch, p, units))):
        path, _ = keep(write, Path(out) / name, log)
        if path.exists():   # no plot without a numeric knob
            written[Path(out) / name] = path
    table.attrs["written"] = written
    return table


def _cell(value):
    return json.dumps(value) if isinstance(value, (list, dict)) else value


DIRECTION_HINTS = ("direction", "heading")


def _with_unit(knob, written=None):
    """``'environment.current_speed [m/s]'``: a knob (named ``written``, default its key) with the
    unit its key states."""
    from .keys import unit
    u = unit(knob)
    name = written or knob
    return f"{name} [{u}]" if u else name


def _emptiest(directions):
    """The middle [deg] of the widest sector between the directions (degrees) a plot has data at."""
    d = np.asarray(directions, float)
    d = np.sort(np.unique(np.mod(d[np.isfinite(d)], 360.0)))   # single cases may not set the knob
    if d.size == 0:
        return 100.0
    gaps = np.diff(np.r_[d, d[0] + 360.0])
    k = int(np.argmax(gaps))
    return float(np.mod(d[k] + gaps[k] / 2, 360.0))


def _is_pose(output):
    """A dynamics partner's position or attitude column: its static pose is not a response."""
    return "_dynamics." in output and any(f".{w}[" in output or output.split(".")[-1].startswith(f"{w}[")
                                          for w in ("position", "attitude"))


# the run plots' units (cosim.report): the table holds SI, its plot what a run's plot shows
DISPLAY = {"rad": ("deg", 180 / math.pi), "rad/s": ("deg/s", 180 / math.pi), "rad/s2": ("deg/s2", 180 / math.pi),
           "N": ("kN", 1e-3), "N.m": ("kN·m", 1e-3)}


def plot(table, batch, path, units=None):
    """Largest |output| per case: a polar plot against the first direction knob (one line per
    combination of the other knobs, one legend for the figure below the panels), else against
    the first numeric knob; ``units``: output -> unit (SI, as the FMUs declare it), shown as the
    run's plots show it (``DISPLAY``: deg, kN, kN·m) in each panel's title.  A body's position
    and attitude are taken from their initial value (the static pose: a reference point 6 m
    below the waterline is no 6 m response).  Knobs are named as the case file wrote them;
    at most three panels to a row.  None if there is nothing to plot."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    ok = table[table["status"] == "ok"]
    numeric = [k for k in batch.matrix if len(batch.matrix[k]) > 1
               and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in batch.matrix[k])]
    if ok.empty or not numeric:
        return None
    key = next((k for k in numeric if any(h in batch.column(k).lower() or h in k.lower() for h in DIRECTION_HINTS)),
               numeric[0])
    polar = any(h in batch.column(key).lower() or h in key.lower() for h in DIRECTION_HINTS)
    axis = batch.column(key)
    other_keys = [k for k in batch.matrix if k != key and len(batch.matrix[k]) > 1]
    others = [batch.column(k) for k in other_keys]
    units = units or {}
    n = len(batch.outputs)
    cols = min(n, 3)
    rows = -(-n // cols)
    legend_room = 1.1 if others else 0.0
    fig, axes = plt.subplots(rows, cols, figsize=(5.6 * cols, 5.2 * rows + legend_room + 0.6), squeeze=False,
                             subplot_kw={"projection": "polar"} if polar else {})
    for ax, name in zip(axes.flat, batch.outputs):
        pose = _is_pose(name) and f"{name}.initial" in ok
        start = ok[f"{name}.initial"].fillna(0.0) if pose else 0.0
        unit, factor = DISPLAY.get(units.get(name), (units.get(name), 1.0))
        peak = np.maximum((ok[f"{name}.max"] - start).abs(), (ok[f"{name}.min"] - start).abs()) * factor
        groups = ok.groupby(others, sort=True) if others else [((), ok)]
        for label, g in groups:
            g = g.sort_values(axis)
            x = np.radians(g[axis].to_numpy(float)) if polar else g[axis].to_numpy(float)
            y = peak[g.index].to_numpy()
            label = ", ".join(f"{v}" for v in (label if isinstance(label, tuple) else (label,)))
            ax.plot(x, y, "o-", label=label or None)
        what = f"max |{name} − initial|" if pose else f"max |{name}|"
        ax.set_title(what + (f" [{unit}]" if unit else " [unit unknown]"), fontsize=11, pad=16)
        ax.tick_params(labelsize=10)
        if polar:   # radial values in the middle of the widest sector without data: they cover no line
            ax.set_rlabel_position(_emptiest(ok[axis].to_numpy(float)))
        else:
            ax.set_xlabel(_with_unit(key, axis), fontsize=10)
            ax.grid(True, alpha=0.3)
    for ax in list(axes.flat)[n:]:
        ax.set_visible(False)
    height = fig.get_figheight()
    if others:   # one legend for the figure, below the panels: it covers no label
        handles, labels = axes[0][0].get_legend_handles_labels()
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 6), fontsize=10, frameon=False,
                   title=", ".join(_with_unit(k, c) for k, c in zip(other_keys, others)), title_fontsize=10)
    fig.suptitle(f"{batch.scene.stem}: largest value per case against {axis}"
                 + (" (degrees, counter-clockwise from +x)" if polar else ""), fontsize=12, y=1 - 0.15 / height)
    fig.tight_layout(rect=(0, (legend_room + 0.1) / height if others else 0, 1, 1 - 0.55 / height))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
