"""The package's top-level calls: scene file → FMUs → run → Result.

``hydrofmu.load_scene``, ``hydrofmu.build`` and ``hydrofmu.run`` are these functions; the
command line (``hydrofmu build``/``run``) is a thin layer over them.
"""
from __future__ import annotations

import hashlib
import json
import math
import sys
import tomllib
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Mapping, Sequence

from . import scene as _scene
from .errors import InputError
from .scene import Scene
from .scene.files import files_named

if TYPE_CHECKING:
    from .cosim.result import Result

DEFAULT_OUT = Path("build") / "fmus"

__all__ = ["load_scene", "build", "run", "outputs", "run_files", "inputs_hash", "built_folder"]
PACKAGE = Path(__file__).resolve().parent


def load_scene(path: str | Path) -> Scene:
    """Read and validate a scene file.

    Parameters
    ----------
    path : str or Path
        The scene (TOML; format in docs/scenes.md).  Vendor decks it names are read
        relative to it.

    Returns
    -------
    Scene
        Bodies (pose, mass properties, effects with their deck data read), joints,
        couplings, environment and run settings (preset resolved).

    Raises
    ------
    hydrofmu.InputError
        Every problem of the file at once, each named by file, key path and field.
    """
    return _scene.load_scene(path)


def build(scene: str | Path | Scene, out: str | Path = DEFAULT_OUT, *,
          log: Callable[[str], object] = print, runtime: str | None = None) -> Path:
    """Build the FMUs of a scene.

    Parameters
    ----------
    scene : str, Path or Scene
        A scene file (``.toml``, validated first) or a Scene from `load_scene`.
    out : str or Path, default ``build/fmus``
        Parent folder: the scene is built into ``out/<scene name>/`` (FMUs,
        ``manifest.json``, each FMU's ``<model>_OspModelDescription.xml``,
        ``OspSystemStructure.xml``, ``<scene>.ssp``), replacing an earlier build only
        when the whole build succeeded.
    log : callable, default print
        Receives one line per built FMU and the build's reports (fits, stability
        indicators); ``lambda s: None`` keeps it quiet.
    runtime : {'python', 'c'}, optional
        The FMUs' flavour: 'python' (pythonfmu, the reference) or 'c' (compiled, no
        Python at run time); default the scene's ``[build] runtime``, else 'python'.

    Returns
    -------
    Path
        The built scene folder.

    Raises
    ------
    hydrofmu.InputError
        The scene is invalid (the message names file, key path and field).
    """
    from .fmi.build import build_scene

    inputs = None
    if not isinstance(scene, Scene):
        inputs = inputs_hash(scene)
        scene = load_scene(scene)
    return Path(build_scene(scene, Path(out), log=log, inputs=inputs, runtime=runtime))


def inputs_hash(path: str | Path) -> str | None:
    """What a build of the scene file ``path`` depends on, as one hash: the scene's bytes,
    every file its values name (decks, BEM results, current files: any string that is a
    file relative to the scene), hydrofmu's own sources and the Python version.  None
    when the file cannot be read as TOML (the build then reports why)."""
    path = Path(path)
    try:
        data = path.read_bytes()
        doc = tomllib.loads(data.decode("utf-8-sig"))
    except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError):
        return None
    h = hashlib.sha256(sys.version.encode())
    h.update(data)
    for f in sorted(set(files_named(doc, path.resolve().parent))):
        h.update(str(f).encode())
        h.update(f.read_bytes())
    for f in sorted(PACKAGE.rglob("*")):
        if f.suffix in (".py", ".c", ".h") and f.is_file():
            h.update(f.relative_to(PACKAGE).as_posix().encode())
            h.update(f.read_bytes())
    return h.hexdigest()[:20]


def built_folder(path: str | Path, out: str | Path = DEFAULT_OUT) -> Path | None:
    """``out/<scene name>/`` when it holds a build of the scene file ``path`` that is up to
    date (its manifest records the same `inputs_hash`), else None."""
    h = inputs_hash(path)
    if h is None:
        return None
    try:
        name = tomllib.loads(Path(path).read_text(encoding="utf-8-sig")).get("scene", {}).get("name", Path(path).stem)
        folder = Path(out) / str(name)
        manifest = json.loads((folder / "manifest.json").read_text())
    except (OSError, ValueError, AttributeError):
        return None
    return folder if manifest.get("inputs") == h else None


def run(source: str | Path | Scene, *, stop: float | None = None, step: float | None = None,
        algorithm: str | None = None, engine: str | None = None, out: str | Path = DEFAULT_OUT,
        record: Sequence[str] | None = None, parameters: Mapping[str, float] | None = None,
        outputs: Sequence[str] | None = None, interval: float | None = None,
        parquet: str | Path | None = None, csv: str | Path | None = None,
        log: Callable[[str], object] = print) -> Result:
    """Run a scene: one call from a scene file (built first) or a built folder to a Result.

    Parameters
    ----------
    source : str, Path or Scene
        A scene file (``.toml``) or Scene, built into ``out/<scene name>/`` first, or a
        built scene folder (holding ``manifest.json``).  A scene file whose build in
        ``out`` is up to date (same scene, decks and hydrofmu: `built_folder`) is not
        built again.
    stop, step : float, optional
        End time and communication step [s]; default: the scene's ``[run]`` settings
        (its preset's, unless the scene sets them).
    algorithm : {'gauss-seidel', 'jacobi', 'ecco'}, optional
        Master algorithm; default: the scene's.  fmpy runs Jacobi and Gauss–Seidel,
        libcosim Jacobi and ECCO (adaptive step, the scene's ``[run.ecco]`` settings;
        ``step`` is then its first step).
    engine : {'fmpy', 'libcosim'}, optional
        hydrofmu's fmpy master, or the Open Simulation Platform's libcosim (needs
        libcosimpy, in the ``test`` extra); default: libcosim for an ECCO run, else fmpy.
    out : str or Path, default ``build/fmus``
        Where a scene file is built (see `build`).
    record : sequence of str, optional
        ``'instance.variable'`` outputs to record (default: every output of every FMU).
    parameters : mapping, optional
        ``{'instance.variable': value}`` set in initialization mode (fmpy engine).
    outputs : sequence of str, optional
        What to record by name: body names (position and attitude),
        ``body.position`` (``attitude``, ``velocity``, ``acceleration``) or
        ``instance.variable``; default: the scene's ``[run] outputs``, else every output.
    interval : float, optional
        Output interval [s], a whole number of steps (an ECCO run has none); default: the
        scene's ``[run] interval``, else every step.
    parquet, csv : str or Path, optional
        Stream the rows into these files as the run goes (fmpy engine; bounded memory): the
        Result is then a ``cosim.stream.FileResult`` reading its columns from the Parquet file.
    log : callable, default print
        Receives the build's lines when a scene file is built, or the line saying which
        build is reused.

    Returns
    -------
    Result
        Time, recorded columns with their units, the run's settings and the manifest
        (``Result.to_csv``, ``Result.plot``).

    Raises
    ------
    hydrofmu.InputError
        Before anything is built or run: an invalid scene, a broken built folder, a
        fixed-step ``stop`` that is not a whole number n ≥ 1 of ``step``, an unknown
        engine, algorithm, ``record`` or ``parameters`` name (with the closest valid ones).
    """
    from .cosim.manifest import read_manifest
    from .cosim.master import check_steps
    if engine not in (None, "fmpy", "libcosim"):
        raise InputError("run", None, "engine", f"must be 'fmpy' or 'libcosim', found {engine!r}")
    for key, value in (("stop", stop), ("step", step)):
        if value is not None and (isinstance(value, bool) or not isinstance(value, (int, float))
                                  or not math.isfinite(value) or value <= 0):
            raise InputError("run", None, key, f"must be a positive finite number, found {value!r}")
    folder = source
    if isinstance(source, Scene) or Path(source).suffix == ".toml":
        reuse = None if isinstance(source, Scene) else built_folder(source, out)
        if reuse is not None:
            cfg = read_manifest(reuse)["run"]
            check_steps(stop or cfg["stop"], step or cfg["step"], algorithm or cfg["algorithm"], "run")
            log(f"reusing {reuse}: the scene, its decks and hydrofmu are unchanged since it was built")
            folder = reuse
        else:
            from .fmi.build import build_scene
            inputs = None if isinstance(source, Scene) else inputs_hash(source)
            scene = source if isinstance(source, Scene) else load_scene(source)
            # the run's own stop/step checked against the scene's before anything is built
            check_steps(stop or scene.run["stop"], step or scene.run["step"], algorithm or scene.run["algorithm"],
                        "run")
            folder = Path(build_scene(scene, Path(out), log=log, inputs=inputs))
    else:
        read_manifest(folder)
    from .cosim.libcosim import engine_for
    engine = engine_for(folder, algorithm, engine)
    if engine == "libcosim":
        for key, value in (("parquet", parquet), ("csv", csv)):
            if value is not None:
                raise InputError("run", None, key, "the libcosim engine holds its run in memory and writes "
                                                   "nothing as it goes: use engine='fmpy', or Result.to_csv after it")
        from .cosim.libcosim import run as run_libcosim
        return run_libcosim(folder, stop=stop, step=step, record=record, algorithm=algorithm, outputs=outputs,
                            interval=interval)
    from .cosim.master import run as run_fmpy
    from .cosim.stream import Sink
    return run_fmpy(folder, stop=stop, step=step, algorithm=algorithm, record=record, parameters=parameters,
                    outputs=outputs, interval=interval, sink=Sink(parquet, csv) if parquet or csv else None)


def outputs(folder: str | Path, engine: str | None = None) -> tuple[Path, Path]:
    """Where ``hydrofmu run``/``demo`` write the CSV and PNG of a built scene folder: next to
    it, ``<folder>.csv`` and ``<folder>.png`` (``<folder>.libcosim.csv``, … for the libcosim
    engine: `run_files`)."""
    files = run_files(folder, engine)
    return files["csv"], files["png"]


def run_files(folder: str | Path, engine: str | None = None) -> dict:
    """Every file ``hydrofmu run`` writes by default for a built scene folder, next to it:
    ``csv``, ``parquet``, ``png``, ``summary`` (``.summary.json``), ``spectra``
    (``.spectra.csv``) and ``spectra_png`` (``.spectra.png``), named ``<folder>.<suffix>``
    for hydrofmu's fmpy master and ``<folder>.libcosim.<suffix>`` for libcosim, so that the
    two engines' runs of one build stand side by side."""
    folder = Path(folder)
    stem = folder.name + ("" if engine in (None, "fmpy") else f".{engine}")
    suffixes = {"csv": ".csv", "parquet": ".parquet", "png": ".png", "summary": ".summary.json",
                "spectra": ".spectra.csv", "spectra_png": ".spectra.png"}
    return {k: folder.with_name(stem + v) for k, v in suffixes.items()}
