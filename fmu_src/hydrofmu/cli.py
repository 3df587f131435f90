"""Command line: ``hydrofmu build | run | tune | batch | validate | demo | bench | bem2simo | meandrift`` (a thin layer
over the library: ``hydrofmu.build``, ``hydrofmu.run``, ``Result.to_csv``, ``Result.plot``)."""
import argparse
import math
import os
import sys
import warnings
import zipfile
from pathlib import Path

from .api import DEFAULT_OUT, built_folder, inputs_hash, run_files
from .scene.files import scene_files
from .cosim.manifest import read_manifest
from .cosim.master import check_steps, describe
from .errors import InputError, InputWarning
from .names import did_you_mean
from .writable import check_folder, check_outputs, keep


# the repository's models/ when hydrofmu is installed from it (pip install -e .)
REPO_MODELS = Path(__file__).resolve().parents[2] / "models"


def scenes_in(paths, models=None):
    """Scene files named on the command line, or every *.toml in ``models`` (default:
    ./models, else the models/ of the repository hydrofmu was installed from)."""
    if paths:
        return [Path(p) for p in paths]
    folders = [Path(models)] if models else [Path("models"), REPO_MODELS]
    for folder in folders:
        found = sorted(folder.glob("*.toml"))
        if found:
            return found
    raise InputError(Path(folders[0]).resolve(), None, "scenes",
                     "no scene files (*.toml) here" + ("" if models else " nor in the hydrofmu repository's models/")
                     + ": name scene files, or run from a folder that has models/*.toml")


def build(paths, outdir=DEFAULT_OUT, log=print, check=False, runtime=None):
    """Validate every scene (files or loaded Scenes) first, then build each one; returns
    {scene name: folder} (``check``: every check of the build, nothing written; the folders are None;
    ``runtime``: 'python' or 'c', else each scene's [build] runtime)."""
    from .fmi.build import build_scene
    from .scene import Scene, load_scene

    # all validated before anything is written
    scenes = [p if isinstance(p, Scene) else load_scene(p) for p in paths]
    names = {}
    for scene in scenes:
        if scene.name in names:
            raise InputError(scene.path, None, "scene.name", f"{scene.name!r} is also the name of "
                                                             f"{names[scene.name]}: each scene builds into its own folder")
        names[scene.name] = scene.path
    if not check:
        check_folder(outdir)
    folders = {}
    for s in scenes:   # the inputs' hash lets a later run of the same scene file reuse the build
        folders[s.name] = build_scene(s, outdir, log=log, check=check, inputs=inputs_hash(s.path),
                                      runtime=runtime)
        if not check:
            log(f"built scene {s.name}: FMUs, manifest.json, OSP files and {s.name}.ssp in {folders[s.name]}")
    return folders


def check_run(folder=None, csv=None, png=None, step=None, stop=None, run=None, algorithm=None, out=None,
              summary=None, inputs=()):
    """Bad run arguments as one InputError, before anything is built or written: step and
    stop positive, stop a whole number of steps (``run``: the scene's or the built folder's
    [run] settings, for what the command line leaves out), every output writable, the PNG's
    suffix a plot format, no output twice nor one of the ``inputs`` (the scene file, its
    decks) or inside the built ``folder``."""
    for key, value in (("step", step), ("stop", stop)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InputError("command line", None, f"--{key}", f"must be a positive finite number, found {value:g}")
    if run is None and folder is not None:
        run = read_manifest(folder)["run"]
    if run is not None:
        given = [f"--{k}" for k, v in (("stop", stop), ("step", step)) if v is not None]
        check_steps(stop or run["stop"], step or run["step"], algorithm or run["algorithm"],
                    "command line" if given else run.get("source", folder),
                    {"stop": "--stop", "step": "--step"} if given else {"stop": "run.stop", "step": "run.step"})
    check_outputs(files=(csv, summary), plots=(png,), folders=(out,), inputs=(*inputs, folder))


def _stderr(text):
    print(text, file=sys.stderr)


def run_folder(folder, engine=None, csv=None, png=None, summary=None, transient=0.0, log=_stderr, say=print,
               parquet=None, inputs=(), split=None, spectra=None, spectra_png=None, **kw):
    """Run a built scene folder with fmpy (our master) or libcosim (default: libcosim for
    an ECCO run, else fmpy), its settings said once first (``say``); write CSV/PNG, the
    summary's JSON and the response spectra (``spectra`` CSV, ``spectra_png``), each checked
    writable first.  The Result's ``stats`` is its summary over t ≥ ``transient``, split at
    ``split`` [s] (default: the scene's).  fmpy runs stream their rows into the CSV and
    ``parquet`` (default: beside the CSV when pyarrow is installed) as they go, and the PNG
    and the summary are read from the file, whole; a libcosim run writes the same files after
    it ends.  A write that fails after the run goes to a fallback folder: ``written`` maps
    each asked path to the one written."""
    from .cosim.libcosim import engine_for
    from .cosim.master import run_settings
    folder = Path(folder)
    check_run(folder, csv, png, kw.get("step"), kw.get("stop"), algorithm=kw.get("algorithm"), summary=summary,
              inputs=inputs)
    if not (math.isfinite(transient) and transient >= 0):
        raise InputError("command line", None, "--transient", f"must be a finite time ≥ 0 [s], found {transient:g}")
    if split is not None and not (math.isfinite(split) and split > 0):
        raise InputError("command line", None, "--split", f"must be a period > 0 [s], found {split:g}")
    manifest = read_manifest(folder)
    if transient and transient >= (kw.get("stop") or manifest["run"]["stop"]):
        raise InputError("command line", None, "--transient",
                         f"{transient:g} s leaves nothing of a run that ends at {kw.get('stop') or manifest['run']['stop']:g} s")
    if parquet is None and csv is not None and _has_pyarrow():
        parquet = Path(csv).with_suffix(".parquet")
    files = (csv, summary, parquet, spectra)
    after = dict(summary=summary, transient=transient, split=split, spectra=spectra, spectra_png=spectra_png, log=log)
    if engine_for(folder, kw.get("algorithm"), engine) == "libcosim":
        from .cosim.libcosim import run
        check_outputs(files=files, plots=(png, spectra_png), inputs=(*inputs, folder))
        say(f"{folder.name}: {describe(run_settings(manifest, kw.get('step'), kw.get('algorithm'), kw.get('stop')))}")
        try:
            result = run(folder, **kw)
        except InputError as exc:   # the run's own --outputs/--interval, named as the command line says them
            raise _as_option(exc) from None
        result.written = {}
        if csv:
            result.written[Path(csv)] = keep(result.to_csv, csv, log)[0]
        if parquet:   # the files an fmpy run writes, written when the run ends
            from .cosim.stream import write_parquet
            result.written[Path(parquet)] = write_parquet(result, parquet, log)
        return _plot_and_summary(result, png, **after)
    from .cosim.master import run
    from .cosim.stream import Sink
    check_outputs(files=files, plots=(png, spectra_png), inputs=(*inputs, folder))   # the parquet too
    say(f"{folder.name}: {describe(run_settings(manifest, kw.get('step'), kw.get('algorithm'), kw.get('stop')))}")
    from .cosim.master import RunError
    try:
        result = run(folder, sink=Sink(parquet, csv) if parquet or csv else None, **kw)
    except InputError as exc:   # the run's own --outputs/--interval, named as the command line says them
        raise _as_option(exc) from None
    except RunError as exc:   # a run that failed keeps what it computed: its files, and the plot of them
        _plot_partial(exc, manifest, png, log)
        raise
    result.written = {Path(asked): Path(got) for asked, got in getattr(result, "written", {}).items()}
    return _plot_and_summary(result, png, **after)


def _plot_partial(exc, manifest, png, log):
    """The plot of a failed run's rows up to the failure (kept by the master), said in its message."""
    written = list(getattr(exc, "written", {}).values())
    if not png or not written:
        return
    try:
        from .cosim.result import read_csv
        from .cosim.stream import read_parquet
        got = written[-1]
        partial = read_parquet(got) if str(got).endswith(".parquet") else read_csv(got, manifest)
        if _unplotted(partial) is None and len(partial.time) > 1:
            drawn = keep(partial.plot, png, log)[0]
            exc.args = (exc.args[0] + f", the plot of them in {drawn}",)
    except Exception as why:   # the failure's own message matters more than the plot's
        log(f"warning: no plot of the failed run's rows ({type(why).__name__}: {why})")


def _as_option(exc):
    """An InputError about the run's own outputs/interval, named as the command line says them."""
    if exc.path == "run" and exc.field in ("outputs", "interval"):
        return InputError("command line", None, f"--{exc.field}", exc.message)
    return exc


def _plot_and_summary(result, png, summary, transient, log, split=None, spectra=None, spectra_png=None):
    """The summary (over the whole record), the PNG and the response spectra of a run (each
    engine's), when it recorded what they need."""
    missing = _unplotted(result)
    if png and missing:
        log(f"warning: no PNG: the plot needs every output of the bodies' FMUs, and {missing} was not "
            "recorded (--outputs / [run] outputs)")
    result.stats = result.summary(transient, split) if not missing else None
    if png and not missing:
        result.written[Path(png)] = keep(lambda p: result.plot(p, split=split), png, log)[0]
    if summary and result.stats is not None:
        result.written[Path(summary)] = keep(result.stats.to_json, summary, log)[0]
    if result.stats is not None and result.stats.spectra:
        from .cosim.report import plot_spectra
        if spectra:
            result.written[Path(spectra)] = keep(result.stats.write_spectra, spectra, log)[0]
        if spectra_png:
            drawn = keep(lambda p: plot_spectra(result.stats, result.manifest, p), spectra_png, log)[0]
            if drawn.exists():
                result.written[Path(spectra_png)] = drawn
    return result


def _unplotted(result):
    """The first output the run's plot needs that ``result`` did not record, or None."""
    from .cosim.stream import plot_columns
    have = set(result.columns)
    return next((c for c in plot_columns(result.manifest) if c not in have), None)


def _steps(result):
    """'N steps' of a run, with the rows written when an output interval thinned them."""
    n = len(result.time) - 1
    steps = round(result.settings["stop"] / result.settings["step"]) if result.settings and \
        result.settings.get("algorithm") != "ecco" else n
    return f"{steps} steps" + (f", {n + 1} rows written" if steps != n else "")


def _has_pyarrow():
    try:
        import pyarrow.parquet  # noqa: F401  (the batch extra)
    except ImportError:
        return False
    return True


def _wrote(result):
    """'wrote a and b' of a command's outputs (``result.written``: asked path → path written);
    the exit code: 1 when one went to a fallback folder."""
    moved = [asked for asked, got in result.written.items() if got != asked]
    paths = [str(p) for p in result.written.values()]
    text = ", ".join(paths[:-1]) + " and " + paths[-1] if len(paths) > 1 else "".join(paths)
    return f"wrote {text}" + (f" ({len(moved)} of them not where asked: see the warning)" if moved else ""), \
        (1 if moved else 0)


def validate(paths):
    """fmpy's validation of FMU files (or of every FMU in folders); returns problem count."""
    from fmpy.validation import validate_fmu
    missing = [p for p in map(Path, paths) if not p.exists()]
    if missing:
        raise InputError(missing[0], None, "path", "no such FMU or folder")
    fmus = [f for p in map(Path, paths) for f in (sorted(p.rglob("*.fmu")) if p.is_dir() else [p])]
    if not fmus:
        raise InputError(paths[0], None, "path", "no FMU (*.fmu) in the folder")
    for fmu in fmus:
        if not zipfile.is_zipfile(fmu):
            raise InputError(fmu, None, "FMU", "not an FMU (an FMU is a zip archive)")
    problems = 0
    for fmu in fmus:
        found = validate_fmu(str(fmu))
        problems += len(found)
        print(f"{fmu.name}: {'ok' if not found else f'{len(found)} problem(s)'}")
        for p in found:
            print(f"  {p}")
    print(f"{len(fmus)} FMU(s), {problems} problem(s)")
    return problems


def bem2simo(result, out, ulen=None, rho=None, dofs=None, timdel=None, kernel_length=None,
             symmetry_tolerance=None, png=None, log=print, a_inf="ogilvie", period_variable=None):
    """A BEM result (Capytaine .nc, WAMIT .1) → a SIMO deck with every self and cross coupling
    of its bodies (BODY DATA groups first); the transform's report goes to ``log``."""
    from .bem import couplings, plot_quality, write_simo
    from .decks.bem import read_bem
    from .physics.radiation import SYMMETRY_TOL
    for option, value in (("--ulen", ulen), ("--rho", rho), ("--timdel", timdel), ("--kernel-length", kernel_length),
                          ("--symmetry-tolerance", symmetry_tolerance)):
        if value is not None and not (math.isfinite(value) and value > 0):
            raise InputError("command line", None, option, f"must be a positive finite number, found {value:g}")
    if Path(result).suffix != ".1" and rho is not None:
        raise InputError("command line", None, "--rho", "applies to a nondimensional WAMIT .1 file only: a "
                                                         "Capytaine dataset carries its own rho")
    rho = 1025.0 if rho is None else rho
    check_outputs(files=(out,), plots=(png,), inputs=(result,))
    data = read_bem(result, ulen=ulen, rho=rho, g=9.81, period_variable=period_variable)
    made = couplings(data, {b: b for b in data.bodies}, dofs, timdel, kernel_length,
                     SYMMETRY_TOL if symmetry_tolerance is None else symmetry_tolerance, a_inf_from=a_inf)
    for line in made.report():
        log(line)
    made.written = {Path(out): keep(lambda p: write_simo(made, p), out, _stderr)[0]}
    log(f"wrote {made.written[Path(out)]}: couplings {', '.join(c.name for c in made.couplings)}")
    if png:
        made.written[Path(png)] = keep(lambda p: plot_quality(made, p), png, _stderr)[0]
        log(f"wrote {made.written[Path(png)]}")
    return made


def tolerance(text):
    """``'0.5%'`` -> 0.005, ``'0.005'`` -> 0.005; InputError naming --tolerance otherwise."""
    value = str(text).strip()
    try:
        number = float(value[:-1]) / 100 if value.endswith("%") else float(value)
    except ValueError:
        raise InputError("command line", None, "--tolerance", f"expected a fraction or a percentage "
                                                             f"(0.005 or 0.5%), found {text!r}") from None
    return number


def tune(args):
    """``hydrofmu tune``: exit 0 with a choice, 1 when no setting met the tolerance."""
    from .tuning import tune as run_tune, write_run_block
    from .scene import load_scene
    if args.repeats < 1:
        raise InputError("command line", None, "--repeats", f"must be at least 1, found {args.repeats}")
    name = load_scene(args.scene).name
    png = args.png or Path("build") / "tune" / f"{name}.png"
    if args.png is None:
        check_folder(png.parent)
        png.parent.mkdir(parents=True, exist_ok=True)
    # --write makes the scene an output; its decks (and the scene, without --write) are inputs
    check_outputs(files=(args.scene,) if args.write else (), plots=(png,),
                  inputs=(*scene_files(args.scene), *(() if args.write else (args.scene,))))
    found = run_tune(args.scene, tolerance(args.tolerance), outputs=args.outputs, window=args.window,
                     confirm=args.confirm,
                     repeats=args.repeats, png=png, log=lambda s: None)
    for line in found.report():
        print(line)
    print(f"wrote {png}")
    if found.choice is None:
        return 1
    if args.write:
        write_run_block(args.scene, found)
        print(f"wrote the [run] block into {args.scene}"
              + (" and the state-space orders into its [[couplings]] tables" if found.choice.setting.orders else ""))
    else:
        print("\n" + found.run_block().rstrip())
    return 0


def batch(args):
    """``hydrofmu batch``: exit 0 when every case ran, 1 when some failed."""
    try:
        from .batch import run_batch
        import distributed, pandas, pyarrow  # noqa: F401  (the batch extra)
    except ImportError as exc:
        print(f"error: hydrofmu batch needs the batch extra (pip install 'hydrofmu[batch]'): {exc}", file=sys.stderr)
        return 2
    out = args.out or Path("build") / "batch" / args.cases.stem
    table = run_batch(args.cases, out, workers=args.workers, scheduler=args.scheduler,
                      series=True if args.series else None, retry_failed=args.retry_failed)
    counts = table["status"].value_counts().to_dict()
    written = table.attrs.get("written", {})
    wrote = ", ".join(str(p) for p in written.values())
    print(f"batch: {len(table)} cases, " + ", ".join(f"{n} {s}" for s, n in sorted(counts.items()))
          + f"; wrote {wrote}")
    for _, row in table[table["status"] != "ok"].head(10).iterrows():
        print(f"  case {row['case']}: {row['status']}: {row['error']}")
    moved = any(asked != got for asked, got in written.items())
    return 0 if counts.get("ok", 0) == len(table) and not moved else 1


HELP = """\
examples:
  hydrofmu demo                              build and run every scene in models/
  hydrofmu run models/moored_barge.toml      build one scene, run it, write CSV + PNG
  hydrofmu run build/fmus/moored_barge --stop 60 --step 0.05
  hydrofmu <command> --help                  the options of one command"""


class Formatter(argparse.ArgumentDefaultsHelpFormatter):
    """Adds '(default: …)' to a help text that does not say its default already."""

    def _get_help_string(self, action):
        if action.default in (None, False) or "default" in (action.help or ""):
            return action.help
        return super()._get_help_string(action)


def make_parser():
    """The argument parser, every option with its help text and default."""
    fmt = Formatter
    parser = argparse.ArgumentParser(
        prog="hydrofmu", formatter_class=argparse.RawDescriptionHelpFormatter, epilog=HELP,
        description="Hydrodynamic loads on floating bodies as FMI 2.0 co-simulation FMUs: build the FMUs "
                    "of a scene, run it, check and benchmark them.")
    sub = parser.add_subparsers(dest="command", required=True, metavar="command")
    b = sub.add_parser("build", formatter_class=fmt, help="build the FMUs of scenes",
                       description="Validate every scene, then build each one into OUT/<scene name>/: one load FMU "
                                   "per body, joint FMUs, dynamics-partner FMUs, manifest.json (our masters), each "
                                   "FMU's <model>_OspModelDescription.xml (its OSP-IS ports) and "
                                   "OspSystemStructure.xml (libcosim), <scene>.ssp (SSP).  A build replaces the "
                                   "folder only when it succeeded.")
    b.add_argument("scenes", nargs="*", metavar="SCENE", help="scene files (.toml); none: every *.toml in models/")
    b.add_argument("-o", "--out", default=DEFAULT_OUT, type=Path, help="parent folder of the built scenes")
    b.add_argument("--check", action="store_true", help="check the scenes and their decks as the build does; "
                                                         "write nothing")
    b.add_argument("--runtime", choices=("python", "c"), default=None,
                   help="the FMUs' flavour: 'python' (pythonfmu, the reference) or 'c' (compiled: plain C, no "
                        "Python at run time, C sources inside); default each scene's [build] runtime, else python")
    r = sub.add_parser("run", formatter_class=fmt, help="run a scene (a .toml is built first) or a built scene folder",
                       description="Run a scene and write its results: the CSV (header 'instance.variable "
                                   "[unit]', one row per output point) and Parquet files, written as the run goes "
                                   "(bounded memory), and the PNG (motion from the initial pose, every load, joint "
                                   "gaps; a long record as its whole-run envelope beside its last peak periods) "
                                   "drawn from the whole file, next to the built folder: <folder>.csv, "
                                   "<folder>.parquet, <folder>.png, unless --csv/--parquet/--png say otherwise; the "
                                   "summary (mean, std, min, max of each body's motion and loads per dof, their "
                                   "low- and wave-frequency parts and expected extremes, with units): printed and "
                                   "written as <folder>.summary.json; the response spectra as <folder>.spectra.csv "
                                   "and .spectra.png.  The libcosim engine's files are <folder>.libcosim.csv, … "
                                   "(both engines' runs of a build stand side by side).  A scene file whose build "
                                   "in OUT is up to date is not built again.  Step, stop and algorithm "
                                   "default to the scene's [run] settings (its preset's).")
    r.add_argument("scene", metavar="SCENE", help="scene file (.toml, built into OUT first) or built scene folder")
    r.add_argument("-o", "--out", default=DEFAULT_OUT, type=Path, help="where a .toml scene is built")
    r.add_argument("--engine", choices=("fmpy", "libcosim"),
                   help="master: hydrofmu's fmpy master (Jacobi, Gauss-Seidel) or libcosim (Jacobi, ECCO); "
                        "default: libcosim for an ECCO run, else fmpy")
    r.add_argument("--algorithm", choices=("jacobi", "gauss-seidel", "ecco"),
                   help="master algorithm (default: the scene's); ecco: libcosim's adaptive step, with the "
                        "scene's [run.ecco] settings")
    r.add_argument("--step", type=float, metavar="S",
                   help="communication step [s], ECCO's first step (default: the scene's)")
    r.add_argument("--stop", type=float, metavar="T", help="end time [s] (default: the scene's)")
    r.add_argument("--csv", type=Path, metavar="FILE",
                   help="CSV file to write (default: <folder>.csv; libcosim: <folder>.libcosim.csv)")
    r.add_argument("--png", type=Path, metavar="FILE",
                   help="PNG file to write (default: <folder>.png; libcosim: <folder>.libcosim.png)")
    r.add_argument("--transient", type=float, default=0.0, metavar="T",
                   help="the summary's statistics leave out t < T [s]")
    r.add_argument("--split", type=float, metavar="T",
                   help="period [s] between the statistics' low- and wave-frequency parts (default: the scene's "
                        "[run] split, else 2·Tp of its sea)")
    r.add_argument("--parquet", type=Path, metavar="FILE",
                   help="Parquet file to write (default: <folder>.parquet, when pyarrow is installed)")
    r.add_argument("--outputs", nargs="+", metavar="NAME",
                   help="what to record: body names (position, attitude), body.position (attitude, velocity, "
                        "acceleration), instance.variable columns (default: the scene's [run] outputs, else every "
                        "output)")
    r.add_argument("--interval", type=float, metavar="S",
                   help="output interval [s], a whole number of steps (default: the scene's [run] interval, "
                        "else every step)")
    t = sub.add_parser("tune", formatter_class=fmt, help="the cheapest run settings of a scene within a tolerance",
                       description="Run a reference of the scene (the reference preset, checked by one halving), "
                                   "search step, algorithm, load hold, substep and memory evaluator for the cheapest "
                                   "settings whose error on the named outputs stays within the tolerance, print the "
                                   "choice against the presets (error, cost, timing spread) and its [run] block; "
                                   "draw every point run in a PNG.  See docs/tuning.md.")
    t.add_argument("scene", type=Path, metavar="SCENE", help="scene file (.toml)")
    t.add_argument("--tolerance", default="0.5%", metavar="TOL",
                   help="largest error: normalised RMS over each output's range, '0.5%%' or 0.005")
    t.add_argument("--outputs", nargs="+", metavar="NAME",
                   help="what the error is measured on: body names, body.position (attitude, velocity, "
                        "acceleration) or instance.variable columns (default: every body's position and attitude)")
    t.add_argument("--window", type=float, metavar="T", help="simulated time of each search run [s] (default: "
                                                            "the scene's stop, at most 60 s)")
    t.add_argument("--confirm", type=float, metavar="T", help="length of the runs that confirm the choice [s], "
                                                             "a whole number of windows (default: the scene's stop; "
                                                             "shorter: the error's drift is checked)")
    t.add_argument("--repeats", type=int, default=3, help="interleaved timing rounds of the final candidates")
    t.add_argument("--png", type=Path, metavar="FILE", help="plot of the points run (default: build/tune/<scene>.png)")
    t.add_argument("--write", action="store_true", help="write the choice into the scene's [run] table (the rest "
                                                       "of the file kept)")
    a = sub.add_parser("batch", formatter_class=fmt,
                       description="Run a matrix of load cases (a case file: a scene and the values to vary) on Dask: one table of results (cases.csv, cases.parquet) and plots; exit code 1 when a case failed.",
                       help="run a matrix of load cases (a case file) on Dask: one table, plots")
    a.add_argument("cases", type=Path, help="case file (TOML, see docs/batches.md; example: examples/cases.toml)")
    a.add_argument("-o", "--out", type=Path, help="results folder (default build/batch/<case file name>)")
    where = a.add_mutually_exclusive_group()
    where.add_argument("--workers", type=int, help="worker processes of the local Dask cluster (default: cores)")
    where.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://host:8786 "
                                           "(the FMUs are shipped to its workers)")
    a.add_argument("--series", action="store_true", help="write each case's time series (DIR/series/<case>.parquet)")
    a.add_argument("--retry-failed", action="store_true", help="rerun the cases that failed in an earlier run")
    v = sub.add_parser("validate", formatter_class=fmt, help="fmpy validation of built FMUs",
                       description="fmpy's validation of FMU files, or of every FMU under folders; exit code 1 "
                                   "when a problem is found.")
    v.add_argument("paths", nargs="*", default=[str(DEFAULT_OUT)], metavar="PATH",
                   help=f"FMU files or folders (default: {DEFAULT_OUT})")
    d = sub.add_parser("demo", formatter_class=fmt,
                       help="build every scene in models/, run each one, write CSV and PNG per scene",
                       description="Build every scene in models/ into OUT, run each one with its own settings "
                                   "and write OUT/<scene>.csv and OUT/<scene>.png.")
    d.add_argument("-o", "--out", default=DEFAULT_OUT, type=Path, help="parent folder of the built scenes and results")
    d.add_argument("--scene", action="append", metavar="NAME",
                   help="run only this scene (repeatable; default: all)")
    k = sub.add_parser("bench", formatter_class=fmt,
                       help="speed/accuracy benchmarks and the stability map: CSV + PNG per part",
                       description="Speed/accuracy benchmarks (timed side by side, reported as ratios) and the "
                                   "added-mass stability map; CSV + PNG per part and summary.txt in OUT.  About "
                                   "10 minutes in full.")
    k.add_argument("-o", "--out", default=Path("build") / "bench", type=Path, help="folder of the results")
    k.add_argument("--part", action="append",
                   choices=("overhead", "memory", "sweep", "growth", "floor", "native", "startup", "stability", "hold", "bem",
                            "robust", "batch", "ecco", "longrun", "waves", "kinematics", "drift"),
                   help="run only this part (repeatable; default: all)")
    k.add_argument("--quick", action="store_true", help="a smoke run of the cheaper parts at small sizes (about a minute of CPU; the "
                        "parts it leaves out are named), not the documented figures")
    m = sub.add_parser("bem2simo", formatter_class=fmt,
                       help="SIMO coupling deck (A∞ and retardation functions) from a BEM result",
                       description="Turn a BEM result (Capytaine NetCDF, WAMIT .1) into a SIMO deck with every self "
                                   "and cross coupling of its bodies (A∞ and retardation functions), with the "
                                   "transform's quality report.")
    m.add_argument("result", type=Path, help="Capytaine dataset (.nc) or WAMIT .1 file")
    m.add_argument("-o", "--out", required=True, type=Path, help="SIMO deck to write")
    m.add_argument("--ulen", type=float, help="WAMIT: the length ULEN [m] of the nondimensional file")
    m.add_argument("--rho", type=float, help="WAMIT: density [kg/m3] (default 1025)")
    m.add_argument("--dofs", nargs="+", help="dofs to keep, e.g. Surge Heave Pitch (default: all in the file)")
    m.add_argument("--timdel", type=float, help="kernel spacing [s] (default from the highest frequency)")
    m.add_argument("--kernel-length", type=float, help="kernel length [s] (default from the decay of K)")
    m.add_argument("--symmetry-tolerance", type=float, help="A∞ asymmetry tolerance (default 0.01)")
    m.add_argument("--a-inf", choices=("ogilvie", "file"), default="ogilvie",
                   help="A∞ from Ogilvie's relation, consistent with the kernels (default), or the file's ω = ∞ value")
    m.add_argument("--period-variable", choices=("period", "omega", "wavenumber", "hz"),
                   help="WAMIT: what the file's first column is, as the run's IPEROUT wrote it (default period; "
                        "wavenumber: KL = ω²L/g with g = 9.81)")
    m.add_argument("--png", type=Path, help="quality plot: A, B rebuilt from A∞ and K against the result")
    d = sub.add_parser("meandrift", formatter_class=fmt,
                       help="add Capytaine's far-field mean drift to a Capytaine dataset (needs the bem-solve extra)",
                       description="Solve the dataset's diffraction (and radiation) problems again on the body's mesh "
                                   "with Kochin functions, check the excitation against the dataset's, and write the "
                                   "dataset with post_pro.far_field_mean_drift_force's drift_force_surge/sway/yaw "
                                   "(read by the wave_drift effect).")
    d.add_argument("dataset", type=Path, help="Capytaine dataset (.nc) of one body, with its diffraction problems")
    d.add_argument("--mesh", required=True, type=Path, help="the body's mesh (any format cpt.load_mesh reads)")
    d.add_argument("-o", "--out", required=True, type=Path, help="dataset to write (the input plus the drift)")
    d.add_argument("--fixed", action="store_true", help="a held body: no motions (diffraction only)")
    d.add_argument("--ntheta", type=int, default=361, help="Kochin directions over the circle")
    d.add_argument("--no-lid", action="store_true", help="no interior lid (irregular frequencies not removed)")
    d.add_argument("--omega", nargs=2, type=float, metavar=("LO", "HI"),
                   help="only the dataset's frequencies in [LO, HI] rad/s (default: all)")
    d.add_argument("--every", type=int, default=1, help="every N-th of those frequencies")
    d.add_argument("--directions", nargs="+", type=float, help="only these headings [deg] of the dataset")
    return parser


def main(argv=None):
    """The command line; returns the exit code: 0 done, 1 a run or validation failed,
    2 bad input (one ``error:`` line naming the file, line or key path and field),
    3 an internal error (one line; HYDROFMU_DEBUG=1 shows the traceback)."""
    _SAID.clear()   # each warning once per command: `tune` and `batch` read the scene again per case
    with warnings.catch_warnings():
        warnings.simplefilter("always", InputWarning)
        warnings.showwarning = _show_warning
        try:
            return _main(argv)
        except InputError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        except RuntimeError as exc:   # a run that failed: RunError (fmpy) or libcosim stopping
            print(f"error: {exc}", file=sys.stderr)
            return 1
        except Exception as exc:
            if os.environ.get("HYDROFMU_DEBUG"):
                raise
            print(f"error: internal error ({type(exc).__name__}: {exc}); please report it "
                  "(HYDROFMU_DEBUG=1 shows the traceback)", file=sys.stderr)
            return 3


# the warnings this command said: each once, however often the scene is read (tune and batch
# read it once per candidate or variant)
_SAID = set()


def _show_warning(message, category, filename, lineno, file=None, line=None):
    _say_warning(f"warning: {message}" if issubclass(category, InputWarning) else
                 f"warning: {category.__name__}: {message}")


def _say_warning(text):
    if text not in _SAID:
        _SAID.add(text)
        print(text, file=sys.stderr)


def _main(argv):
    args = make_parser().parse_args(argv)
    if args.command == "build":
        for name in build(scenes_in(args.scenes), args.out, check=args.check, runtime=args.runtime):
            if args.check:
                print(f"checked {name}: ok")
    elif args.command == "validate":
        return 1 if validate(args.paths) else 0
    elif args.command == "run":
        folder = Path(args.scene)
        inputs = (folder, *scene_files(folder)) if folder.suffix == ".toml" else ()
        reuse = built_folder(folder, args.out) if folder.suffix == ".toml" else None
        if reuse is not None:
            folder = reuse
            print(f"reusing {folder}: the scene, its decks and hydrofmu are unchanged since it was built")
            for text in read_manifest(folder).get("warnings", []):   # the build's: said again, once
                _say_warning(f"warning: {text}")
        elif folder.suffix == ".toml":
            from .scene import load_scene
            scene = load_scene(folder)
            # the default CSV/PNG go into OUT, which the build makes: OUT is checked for them
            check_run(Path(args.out) / scene.name, args.csv, args.png, args.step, args.stop,
                      {**scene.run, "source": str(scene.path)}, args.algorithm, args.out,
                      inputs=inputs)
            folder = next(iter(build([scene], args.out).values()))
        from .cosim.libcosim import engine_for
        files = run_files(folder, engine_for(folder, args.algorithm, args.engine))   # each engine its own files
        csv, png = args.csv or files["csv"], args.png or files["png"]
        extra = {k: v for k, v in (("outputs", args.outputs), ("interval", args.interval)) if v is not None}
        result = run_folder(folder, args.engine, csv, png, files["summary"], args.transient, parquet=args.parquet,
                            inputs=inputs, split=args.split, spectra=files["spectra"],
                            spectra_png=files["spectra_png"], stop=args.stop, step=args.step,
                            algorithm=args.algorithm, **extra)
        if result.stats is not None:
            print(result.stats)
        wrote, code = _wrote(result)
        print(f"ran {folder.name}: {_steps(result)}; {wrote}")
        return code
    elif args.command == "tune":
        return tune(args)
    elif args.command == "batch":
        return batch(args)
    elif args.command == "demo":
        from .scene import load_scene
        scenes = [load_scene(p) for p in scenes_in([])]
        names = [s.name for s in scenes]
        for name in args.scene or []:
            if name not in names:
                raise InputError("command line", None, "--scene", f"no scene {name!r} in models/"
                                                                  f"{did_you_mean(name, names)} (scenes: {', '.join(names)})")
        folders = build(scenes, args.out)
        code = 0
        for name in args.scene or folders:
            files = run_files(folders[name])
            result = run_folder(folders[name], "fmpy", files["csv"], files["png"], files["summary"],
                                spectra=files["spectra"], spectra_png=files["spectra_png"])
            wrote, failed = _wrote(result)
            code = max(code, failed)
            print(f"ran {name}: {_steps(result)}; {wrote} (the summary: mean, std, min, max, the LF and WF parts "
                  f"and the expected extremes per body and dof)")
        return code
    elif args.command == "bem2simo":
        made = bem2simo(args.result, args.out, args.ulen, args.rho, args.dofs, args.timdel, args.kernel_length,
                        args.symmetry_tolerance, args.png, a_inf=args.a_inf, period_variable=args.period_variable)
        return _wrote(made)[1]
    elif args.command == "meandrift":
        from .bem_drift import add_mean_drift
        if args.ntheta < 16:
            raise InputError("command line", None, "--ntheta", f"at least 16 directions, found {args.ntheta}")
        check_outputs(files=(args.out,), inputs=(args.dataset, args.mesh))
        keep(lambda p: add_mean_drift(args.dataset, args.mesh, p, fixed=args.fixed, ntheta=args.ntheta,
                                      lid=not args.no_lid, omega_range=args.omega, every=args.every,
                                      directions=args.directions), args.out, _stderr)
    elif args.command == "bench":
        from .bench.run import main as bench
        check_folder(args.out)
        bench(args.out, args.part, args.quick)
    return 0


if __name__ == "__main__":
    sys.exit(main())
