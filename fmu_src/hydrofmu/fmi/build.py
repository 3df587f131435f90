"""Build the FMUs of a scene: one load FMU per floating body, holding only the effects the
scene gives it, plus one dynamics-partner FMU per body; a manifest (instances,
connections, run settings, power bonds) for our masters, the OSP files for libcosim
(``<model>_OspModelDescription.xml`` per FMU and OspSystemStructure.xml, fmi/osp.py) and an
SSP file (``<scene>.ssp``, fmi/ssp.py) for any SSP importer.

Each FMU is self-contained: its resources carry the hydrofmu runtime under a content-hashed
name (two FMUs of different builds in one process never share code by accident) and
pythonfmu's slave API, both in one zip imported from memory (fmi/runtime_zip.py: an FMU
unpacks 10 files), and its typed description (hydrofmu.description); the host needs only
numpy.  What each FMU holds comes from ``hydrofmu.assembly``: this module only packages.
Everything is built in a temporary folder and moved into place at the end, so a failed
build leaves nothing half-written.
"""
import ast
import hashlib
import importlib
import json
import marshal
import shutil
import sys
import tempfile
import zipfile
from pathlib import Path

from . import model_description, osp, starts
from ..errors import InputError
from .ssp import write_ssp
from .. import description
from ..assembly import assemble, fit_memories, notes

PACKAGE = Path(__file__).resolve().parents[1]
# The FMU runtime is what the slaves import, and nothing else (no scene loader, deck
# readers, masters or benchmarks): the closure of the package-relative imports of
# fmi/slave.py (every one, module level or not), found in the sources.
RUNTIME_ENTRY = "fmi/slave.py"
RUNTIME_INIT = '"""hydrofmu FMU runtime: physics kernels, slaves, typed description, errors."""\n'
# C sources the runtime carries compiled, where its Python finds them (physics/rigid_kernel.py)
RUNTIME_C = {"physics/rigid.c": "physics/_rigid.so"}


def _module_file(name):
    """The file of package module ``name`` (dotted, relative to the package), or None."""
    path = PACKAGE.joinpath(*name.split(".")) if name else PACKAGE
    if path.with_suffix(".py").is_file():
        return path.with_suffix(".py")
    return path / "__init__.py" if (path / "__init__.py").is_file() else None


_IMPORTS = {}   # file -> ((mtime_ns, size), its relative imports): a build parses each file once


def _relative_imports(f):
    """The relative ``from … import`` nodes of source file ``f`` (every one, module level or not),
    parsed once per process while the file does not change (a batch or a test session builds
    hundreds of scenes; the parse was most of a build check's time)."""
    st = f.stat()
    key = (st.st_mtime_ns, st.st_size)
    known = _IMPORTS.get(f)
    if known is None or known[0] != key:
        nodes = [n for n in ast.walk(ast.parse(f.read_text(encoding="utf-8")))
                 if isinstance(n, ast.ImportFrom) and n.level]
        known = _IMPORTS[f] = (key, nodes)
    return known[1]


def runtime_files():
    """The runtime's source files, relative to the package (sorted)."""
    entry = PACKAGE / RUNTIME_ENTRY
    seen, todo = set(), [entry] + [d / "__init__.py" for d in entry.parents if PACKAGE in d.parents]
    while todo:
        f = todo.pop()
        rel = f.relative_to(PACKAGE)
        if rel in seen or rel == Path("__init__.py"):   # the runtime has an __init__ of its own
            continue
        seen.add(rel)
        if rel == Path("__init__.py"):
            continue   # replaced by RUNTIME_INIT: the package's own imports (its public API) stay out
        here = list(rel.parent.parts)
        for node in _relative_imports(f):
            base = here[:len(here) - (node.level - 1)] if node.level > 1 else here
            mod = ".".join(base + ([node.module] if node.module else []))
            parts = mod.split(".") if mod else []
            for k in range(len(parts) + 1):   # the packages on the way in
                init = _module_file(".".join(parts[:k]))
                if init is not None and init.name == "__init__.py" and k < len(parts):
                    todo.append(init)
            for target in [mod] + [f"{mod}.{a.name}" if mod else a.name for a in node.names]:
                found = _module_file(target)
                if found is not None:
                    todo.append(found)
    return sorted(seen)


def runtime_name():
    """'hydrofmu_rt_<hash>': the runtime copy's name, from the hash of its sources."""
    h = hashlib.sha256(RUNTIME_INIT.encode())
    for f in runtime_files() + sorted(Path(c) for c in RUNTIME_C):
        h.update(f.as_posix().encode())
        h.update((PACKAGE / f).read_bytes())
    return f"hydrofmu_rt_{h.hexdigest()[:10]}"


# pythonfmu's modules a slave imports (its slave API): the runtime zip holds these, not its builder
PYTHONFMU_RUNTIME = ("__init__", "_version", "default_experiment", "enums", "fmi2slave", "logmsg", "variables")
ZIP_DATE = (1980, 1, 1, 0, 0, 0)   # the zip's time stamps: the same runtime gives the same bytes


def pack_runtime(stage, runtime):
    """The FMU's runtime in ``stage``: ``<runtime>.zip`` (the runtime package and pythonfmu's
    package, each module's source and its bytecode for this Python; imported from memory by
    fmi/runtime_zip.py) and, as files, what only loads from a file: ``<runtime>/physics/
    _rigid.so``.  Returns both paths (the FMU's project files)."""
    import pythonfmu.builder
    from ..cc import cached
    members = {f"{runtime}/{f.as_posix()}": (PACKAGE / f).read_bytes() for f in runtime_files()}
    members[f"{runtime}/__init__.py"] = RUNTIME_INIT.encode()
    members.update({f"pythonfmu/{m}.py": (pythonfmu.builder.HERE / f"{m}.py").read_bytes() for m in PYTHONFMU_RUNTIME})
    tag = sys.implementation.cache_tag
    for name, source in list(members.items()):
        folder, _, module = name.rpartition("/")
        if tag:   # another Python (other cache tag) compiles the sources
            members[f"{folder}/__pycache__/{module[:-3]}.{tag}.pyc"] = bytecode(source, name)
    archive = stage / f"{runtime}.zip"
    with zipfile.ZipFile(archive, "w", zipfile.ZIP_STORED) as z:   # stored: the FMU's zip deflates it
        for name in sorted(members):
            z.writestr(zipfile.ZipInfo(name, ZIP_DATE), members[name])
    binaries = stage / runtime
    for src, lib in RUNTIME_C.items():
        (binaries / lib).parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(cached(PACKAGE / src), binaries / lib)
    return archive, binaries


SCRIPT = """# hydrofmu FMU {model_id}: {description}
# pythonfmu 0.7 executes this file again at every instantiation (in the module's globals,
# with fresh locals) and keeps for good whatever that creates: the class is defined once
# per runtime module (again only when a build in this process reloaded the runtime, or an
# FMU of the same name from another hydrofmu version ran in between).  Names used inside
# the class are looked up in the module's globals, which every FMU of this name shares:
# the class carries its own runtime.
import ctypes
import os
import sys

# The runtime ({runtime}) and pythonfmu come from {runtime}.zip beside this file, read
# into memory by the finder below (hydrofmu.fmi.runtime_zip), made once per process.
_RUNTIME_ZIP = r'''{finder}'''

_rz = sys.modules.get("{runtime}_zip")
if _rz is None:
    _rz = type(sys)("{runtime}_zip")
    exec(compile(_RUNTIME_ZIP, "{runtime}_zip", "exec"), _rz.__dict__)
    sys.modules["{runtime}_zip"] = _rz
for _folder in sys.path + [os.path.dirname(os.path.abspath(__file__))]:   # pythonfmu put ours first
    if isinstance(_folder, str) and os.path.isfile(os.path.join(_folder, "{runtime}.zip")):
        _rz.install("{runtime}", os.path.join(_folder, "{runtime}.zip"))
        break

_runtime = globals().get("_runtime")
if _runtime is None or sys.modules.get("{runtime}.fmi.slave") is not _runtime:
    from {runtime}.fmi import slave as _slave

    class {model_id}(_slave.{slave}):
        def __init__(self, **kwargs):
            # pythonfmu 0.7's loader drops one reference to this module's globals at every
            # instantiation (PythonFMU issue #228): give it back, or a second instance fails.
            ctypes.pythonapi.Py_IncRef(ctypes.py_object(globals()))
            # ... and puts the resources folder in front of sys.path every time: keep one
            resources = kwargs.get("resources")
            while sys.path.count(resources) > 1:
                sys.path.remove(resources)
            # ... and answers an exception here by releasing objects twice: never raise
            self._hydrofmu_runtime.start(self, super().__init__, kwargs)

    {model_id}._hydrofmu_runtime = _slave
    globals().update({model_id}={model_id}, _runtime=_slave)
{model_id} = globals()["{model_id}"]
"""


FINDER = (Path(__file__).with_name("runtime_zip.py")).read_text(encoding="utf-8")
assert "'''" not in FINDER and not FINDER.endswith("\\"), "runtime_zip.py must fit in SCRIPT's r'''…'''"

SLAVES = {description.LoadFMU: "LoadSlave", description.ConnectorFMU: "ConnectorSlave",
          description.DynamicsFMU: "DynamicsSlave"}


def build_fmu(instance, workdir, runtime, shim=True):
    """Build the FMU of an ``assembly.Instance`` into ``workdir``; returns (fmu path, slave
    introspection, every variable's value at t = 0 (``starts.at_start``))."""
    from pythonfmu.builder import FmuBuilder

    model_id = instance.model_id
    stage = workdir / "stage" / model_id
    stage.mkdir(parents=True)
    archive, binaries = pack_runtime(stage, runtime)
    config = description.write(instance.fmu, stage)
    script = stage / f"{model_id}.py"
    script.write_text(SCRIPT.format(model_id=model_id, runtime=runtime, slave=SLAVES[type(instance.fmu)],
                                    description=" ".join(instance.fmu.description.split()), finder=FINDER))
    saved_path = list(sys.path)
    loaded = {m for m in sys.modules if m.split(".")[0] == runtime}
    try:
        fmu = FmuBuilder.build_FMU(script, dest=workdir / "fmus", project_files=[archive, binaries, config],
                                   canGetAndSetFMUstate=True, canSerializeFMUstate=True)
        slave = getattr(importlib.import_module(model_id), model_id)(
            instance_name="introspect", resources=str(stage))
        if getattr(slave, "broken", None) is not None:
            raise slave.broken
        t0 = starts.at_start(instance.name, slave)   # here: lazy imports still find the staged runtime
    finally:
        sys.path[:] = saved_path
        # the modules this build loaded name the staging folder (their __file__, the compiled
        # kernel's path), deleted with the build folder: a later load of an FMU imports them
        # again (from the zip read into memory, named in that FMU's folder).  Modules of this
        # runtime loaded before the build stay: they belong to FMUs this process runs now
        for name in [m for m in sys.modules
                     if m == model_id or (m.split(".")[0] == runtime and m not in loaded)]:
            del sys.modules[name]
    rewrite_model_description(fmu, slave)
    if shim:
        from .shim import install_shim
        install_shim(fmu)
    return Path(fmu), slave, t0


def bytecode(source, name):
    """Bytecode of a module's source for this interpreter, as an unchecked-hash .pyc: valid
    whatever the extracted file's time stamp (FMU hosts unzip anew each time, so without it
    every instantiation compiles the runtime); other Python versions ignore it (their own
    cache tag) and compile the source."""
    import importlib.util
    code = compile(source, name, "exec", dont_inherit=True)
    flags = (0b01).to_bytes(4, "little")   # hash-based, not checked against the source
    return importlib.util.MAGIC_NUMBER + flags + importlib.util.source_hash(source) + marshal.dumps(code)


def rewrite_model_description(fmu, slave):
    """Replace modelDescription.xml in the FMU zip (via a temporary copy) and drop the loose
    copy of pythonfmu that pythonfmu's builder adds (the runtime zip holds it)."""
    tmp = Path(str(fmu) + ".tmp")
    with zipfile.ZipFile(fmu) as src, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as dst:
        for item in src.infolist():
            if item.filename.startswith("resources/pythonfmu/"):
                continue
            data = src.read(item)
            if item.filename == "modelDescription.xml":
                data = model_description.complete(data, slave.units, slave.dependencies,
                                                  {v.name: slave._start[vr] for vr, v in slave.vars.items()})
            if item.filename.endswith(".zip"):   # the runtime zip, stored inside: deflated here
                item.compress_type = zipfile.ZIP_DEFLATED
            dst.writestr(item, data)
    tmp.replace(fmu)


def connections(system, slaves):
    """Motion outputs of the dynamics FMUs → the motion inputs that exist (by name), and
    load outputs → the dynamics' load inputs, as each instance's routes say."""
    names = {i.name: {v.name for v in slaves[i.name].vars.values()} for i in system.instances}
    conns = []
    for inst in system.instances:
        for prefix, body in inst.motion.items():
            dyn, dp = system.dynamics[body]
            for group, n in (("position", 3), ("attitude", 3), ("velocity", 6), ("acceleration", 6)):
                for i in range(1, n + 1):
                    if f"{prefix}{group}[{i}]" in names[inst.name]:
                        conns.append([dyn, f"{dp}{group}[{i}]", inst.name, f"{prefix}{group}[{i}]"])
        for out, body, inp in inst.forces:
            dyn, dp = system.dynamics[body]
            conns += [[inst.name, f"{out}[{i}]", dyn, f"{dp}{inp}[{i}]"] for i in range(1, 7)]
    return conns


def input_starts(slaves, conns):
    """{instance: {connected input: start value}}: what the system files declare besides
    the FMUs' own modelDescription.xml."""
    out = {}
    for _, _, dst, inp in conns:
        out.setdefault(dst, {})[inp] = starts.start_of(slaves[dst], inp)
    return out


def manifest(scene, system, conns, inputs=None, flavour="python"):
    """What our masters read (manifest.json): instances, routes, run settings, connections
    and the power bonds (fmi.osp.scalar_bonds); ``inputs``: the hash of the scene file, its
    decks and hydrofmu's sources the build came from (``api.inputs_hash``), when known."""
    return {"inputs": inputs,
        "scene": scene.name, "source": str(scene.path), "run": scene.run,
        "flavour": flavour,   # the FMUs': 'python' (pythonfmu) or 'c' (compiled)
        "instances": {i.name: {"fmu": f"{i.model_id}.fmu", "kind": i.kind, "body": i.body}
                      for i in system.instances},
        "dynamics": {body: list(v) for body, v in system.dynamics.items()},
        "stability_indicators": system.indicators,
        "couplings": {c.name: {"method": c.method, "tolerance": c.tolerance, "order": c.order,
                               "memory_length": c.memory_length, "set": c.set} for c in scene.couplings},
        "order": [i.name for i in system.instances],
        "connections": conns,
        "bonds": osp.scalar_bonds(osp.bonds(system)),
        "warnings": list(scene.warnings),   # suspicious but legal input, as the build said it (each once)
        "warning_count": len(scene.warnings),
        "decks": [reading.as_dict() for reading in scene.decks],
    }


def bem_results(scene):
    """The BEM results behind the scene's couplings (each once)."""
    return list({id(c.bem): c.bem for c in scene.couplings if c.bem is not None}.values())


def report_bem(scene, log, folder):
    """BEM couplings: the transform's choices, time and quality, and a PNG of the rebuilt
    A(ω), B(ω) per result (``<folder>/<file stem>_quality.png``)."""
    from ..bem import plot_quality
    for result in bem_results(scene):
        for line in result.report():
            if not line.startswith("  WARNING: "):   # said as warnings by the scene already
                log(line)
        png = plot_quality(result, Path(folder) / f"{Path(result.data.path).stem}_quality.png")
        log(f"  wrote {png.name}")


def build_scene(scene, outdir, shim=True, log=print, check=False, inputs=None, runtime=None):
    """Build all FMUs of ``scene`` into ``outdir/<scene name>/``; returns that folder.
    The folder is replaced only when the whole build succeeded.  ``check``: stop before
    anything is written (every check of the build done), return None.  ``inputs``: recorded
    in the manifest (see `manifest`).  ``runtime``: 'python' (pythonfmu) or 'c' (compiled,
    fmi/cbuild.py); default the scene's ``[build] runtime``."""
    outdir = Path(outdir)
    flavour = runtime or scene.runtime
    if inputs is not None and flavour != scene.runtime:   # not the build a later run of the file would make
        inputs = f"{inputs}+{flavour}"
    target = outdir / scene.name
    system = assemble(scene)
    fit_memories(scene.couplings)   # once, here: the FMUs load the stored fits
    runtime = runtime_name() if flavour == "python" else None   # None: the compiled flavour
    for line in notes(scene, system):
        log(line)
    check_target(scene, target)
    if check:
        return None
    if outdir.exists() and not outdir.is_dir():
        raise InputError(outdir, None, "output folder", "is a file, not a folder")
    created = next((p for p in [outdir, *outdir.parents][::-1] if not p.exists()), None)
    try:
        outdir.mkdir(parents=True, exist_ok=True)
        _build_into(scene, outdir, target, system, runtime, shim, log, inputs)
    except OSError as exc:
        raise InputError(exc.filename or outdir, None, "output folder", f"cannot write ({exc.strerror})") from None
    finally:
        if created is not None and not target.exists():
            shutil.rmtree(created, ignore_errors=True)   # no empty folders left by a failed build
    return target


def check_target(scene, target):
    """A build replaces ``target`` (OUT/<scene name>) whole: refuse when that would delete
    what is not a build (a folder without manifest.json holding files, e.g. the scene's
    decks) or the scene's own files (a deck kept inside its build folder)."""
    from ..scene.files import scene_files
    target = Path(target)
    if target.exists() and not target.is_dir():
        raise InputError(target, None, "output folder", "is a file, where the build's folder goes")
    if target.is_dir() and any(target.iterdir()) and not (target / "manifest.json").is_file():
        raise InputError(target, None, "output folder", "exists and is not a built scene (no manifest.json): a "
                                                        "build replaces it whole and would delete what it holds; "
                                                        "move it or build elsewhere (-o)")
    real = target.resolve()
    for f in [Path(scene.path)] * bool(getattr(scene, "path", None)) + (
            scene_files(scene.path) if getattr(scene, "path", None) else []):
        if real in Path(f).resolve().parents:
            raise InputError(f, None, "output folder", f"lies inside {target}, which the build replaces whole: "
                                                       "keep the scene's files out of its build folder")


def _build_into(scene, outdir, target, system, runtime, shim, log, inputs=None):
    with tempfile.TemporaryDirectory(prefix=f".{scene.name}-", dir=outdir) as tmp:
        work = Path(tmp)
        slaves, t0 = {}, {}
        for inst in system.instances:   # load and joint FMUs first: the dynamics start at their loads
            if inst.kind == "dynamics":
                starts.fill_loads(system, t0)
            if runtime is None:   # the compiled flavour
                from .cbuild import build_c_fmu
                fmu, slaves[inst.name], t0[inst.name] = build_c_fmu(inst, work)
            else:
                fmu, slaves[inst.name], t0[inst.name] = build_fmu(inst, work, runtime, shim)
            log(f"built {fmu.name}")
        conns = connections(system, slaves)
        starts.check(conns, slaves, t0)
        bonds = osp.bonds(system)
        result = work / "fmus"
        report_bem(scene, log, result)
        (result / "manifest.json").write_text(json.dumps(manifest(scene, system, conns, inputs,
                                                                     "c" if runtime is None else "python"), indent=2))
        for model_id, text in osp.model_descriptions(system, slaves, bonds).items():
            (result / f"{model_id}_OspModelDescription.xml").write_bytes(text)
        (result / "OspSystemStructure.xml").write_text(
            osp.system_structure(system, conns, bonds, scene.run["step"], input_starts(slaves, conns)))
        write_ssp(result / f"{scene.name}.ssp", scene.name,
                  {i.name: result / f"{i.model_id}.fmu" for i in system.instances}, conns,
                  scene.run["stop"], scene.run["step"])
        old = outdir / f".{scene.name}.old"
        if target.exists():
            shutil.rmtree(old, ignore_errors=True)
            target.rename(old)
        result.rename(target)
        shutil.rmtree(old, ignore_errors=True)
