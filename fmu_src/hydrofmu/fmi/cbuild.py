"""The compiled flavour of an FMU (``hydrofmu build --runtime c``): the same variables as the
Python flavour, run by plain C (fmi/fmu.c, fmi/models.c and the kernels physics/*.c), with
no Python at run time.

The Python slave of fmi/slave.py is built from the FMU's typed description as for the
Python flavour, and everything the C side needs is read off it: modelDescription.xml (the
slave's own, so names, units, causalities, start values and dependencies are the Python
flavour's), the variable list (``variables.txt``) and the model records (``model.bin``:
value references, start values and each kernel's ``c_params()``).  The FMU carries its C
sources (FMI 2.0 ``<SourceFiles>``) and binaries for linux64 and, where the mingw-w64 cross
compiler is installed, win64.
"""
from __future__ import annotations

import math
import shutil
import struct
import tempfile
import xml.etree.ElementTree as ET
import zipfile
from pathlib import Path

import numpy as np

from .. import description
from ..cc import cached_many, compiler
from ..errors import InputError
from . import model_description

PACKAGE = Path(__file__).resolve().parents[1]
# the FMU's C sources, relative to the package (and to the FMU's sources/ folder)
SOURCES = ["fmi/fmu.c", "fmi/models.c", "physics/kinematics.c", "physics/current.c", "physics/viscous_drag.c",
           "physics/current_polar.c", "physics/lumped.c", "physics/joint.c", "physics/memory.c", "physics/waves.c",
           "physics/wave_kinematics.c", "physics/drift.c",
           "physics/hydrostatics.c", "physics/rigid.c"]
HEADERS = ["fmi/fmu.h", "physics/kernels.h"]
KINDS = {description.LoadFMU: 0, description.ConnectorFMU: 1, description.DynamicsFMU: 2}
CAUSALITY = {"parameter": "p", "calculatedParameter": "c", "input": "i", "output": "o"}
WIN64_CC = "x86_64-w64-mingw32-gcc"
FLAGS = ["-O3", "-shared", "-std=c99", "-s"]   # (-O3: the small fixed loops of the kernels unrolled)


def fmi_headers() -> Path:
    """The FMI 2.0 headers (fmi2Functions.h …) the sources compile against: fmpy's copy."""
    import fmpy
    return Path(fmpy.__file__).parent / "c-code"


def binaries() -> dict[str, Path]:
    """{FMI platform: compiled library} for every platform a compiler is found for here."""
    src = [PACKAGE / s for s in SOURCES]
    out = {"linux64": cached_many(src, "hydrofmu_fmu", libs=["-lm"], includes=[fmi_headers()],
                                  flags=FLAGS + ["-fPIC", "-fvisibility=hidden"], cc=compiler())}
    if shutil.which(WIN64_CC):
        out["win64"] = cached_many(src, "hydrofmu_fmu_win64", includes=[fmi_headers()], suffix=".dll",
                                   flags=FLAGS + ["-static-libgcc", "-Wno-attributes"], cc=[WIN64_CC])
    return out


def _start(s):
    return -1 if s is None else s.start


def _motion(slices):
    """[position, attitude, velocity, acceleration (-1: none)] value references of motion slices."""
    return [s.start for s in slices[:3]] + [slices[3].start if len(slices) > 3 else -1]


def _env(slave):
    env = [("env", [_start(slave.current), slave.rho, slave.g])]
    p = slave.profile
    if p is not None:
        env.append(("profile", [len(p.z), *p.z, *p.ratio, *p.turn]))
    return env


# the sea-state knobs in the order of the 'waves' record (models.c reads them in this order)
SEA_KNOBS = ("height", "period", "phase", "hs", "tp", "gamma", "direction", "spreading", "components", "seed", "ramp")
SPECTRA = {"regular": 0, "jonswap": 1, "pierson_moskowitz": 2}
from ..physics.waves import STRETCHING  # noqa: E402  (wave_kinematics.c's codes: their indices)


def _waves(slave):
    """The waves' records: 'waves' [force, elevation and g value references, spectrum, depth,
    (value reference or -1, scene value) per SEA_KNOBS] and 'transfer' (the body's transfer
    function, physics/waves.c draws the components from the waves.* parameters at initialization)."""
    cfg, name = slave.wave_cfg, slave.wave_cfg.name
    vr = {v.name: k for k, v in slave.vars.items()}
    sea = cfg.sea_state()
    knobs = [x for k in SEA_KNOBS for x in (slave.wave_knobs.get(k, -1), float(getattr(sea, k)))]
    window = tuple(cfg.window) if cfg.window else (0.0, math.inf)
    transfer = cfg.transfer(float(slave.values[slave.g]), sea.depth)
    recs = [("waves", [vr[f"{name}.force[1]"] if name else -1, vr[f"{name}.elevation"] if name else -1, slave.g,
                       SPECTRA[cfg.spectrum], float(sea.depth)] + knobs),
            ("transfer", transfer.c_params(window) if transfer is not None else list(window) + [0.0] * 5)]
    if slave.kin_wanted:   # [stretching, feels, rho, npoints, (on_body, x, y, z, first output) per point]
        points = [x for where, on_body, block in slave.points for x in (float(on_body), *where.tolist(), block.start)]
        recs.append(("kinematics", [STRETCHING.index(sea.stretching), float(cfg.kinematics), slave.rho,
                                    len(slave.points)] + points))
    return recs


def records(slave, desc) -> list[tuple[str, list[float]]]:
    """The model records of a built Python slave (fmi/fmu.h, fmi/models.c read them)."""
    recs = [("kind", [KINDS[type(desc)]]), ("start", slave.values.tolist())]
    if isinstance(desc, description.LoadFMU):
        if getattr(desc, "waves", None) is not None:
            recs += _waves(slave)
        if getattr(desc, "drift", None) is not None:   # drift.c, on the components waves.c draws
            vr = {v.name: k for k, v in slave.vars.items()}
            recs.append(("drift", [vr[f"{desc.drift.name}.force[1]"]] + desc.drift.c_params()))
        recs += [("motion", _motion(slave.motion_inputs)), *_env(slave),
                 ("explicit", [desc.accel_mode == "explicit"]), ("total", [slave.force.start])]
        for e, out in zip(slave.loads.effects, slave.effect_force):
            if not hasattr(e, "C_TAG"):
                raise InputError(desc.description, None, f"effect {e.name}",
                                 f"{type(e).__name__} has no compiled kernel yet: build this scene with "
                                 "runtime = \"python\" ([build] runtime, or --runtime python)")
            recs.append((e.C_TAG, [out.start] + e.c_params()))
        for c in slave.couplings:
            side = c["cfg"]
            recs.append(("coupling", [c["force"].start, c["velocity"].start, _start(c["acceleration"])]
                         + np.asarray(c["mass"], float).ravel().tolist()))
            if side.coupling.kernels:
                ev = side.coupling.model().memory[side.side]
                recs.append((ev.C_TAG, ev.c_params()))
    elif isinstance(desc, description.ConnectorFMU):
        if desc.waves is not None:
            recs += _waves(slave)
        recs += [("sides", _motion(slave.side_a) + (_motion(slave.side_b) if slave.side_b else [-1] * 4)),
                 *_env(slave), ("explicit", [slave.explicit]),
                 ("joint", slave.joint.c_params()), ("node", slave.joint.node.c_params()),
                 ("outputs", [slave.force_a.start, slave.force_b.start, slave.gap.start, slave.rotation.start])]
    else:
        from ..physics.rigid_body import CAPSIZE, GIMBAL_TOL, LINEAR_RANGE
        for part in slave.parts:
            b = part["cfg"]
            recs.append(("body", [b.mass, *np.ravel(b.inertia), *np.ravel(b.cog), *np.ravel(b.stiffness),
                                  *np.ravel(b.damping)]
                         + [part[k].start for k in ("position", "attitude", "velocity", "acceleration", "added")]
                         + [len(part["loads"])] + [s.start for s in part["loads"]]))
        recs += [("cross", [i, j, s.start]) for (i, j), s in slave.cross.items()]
        recs.append(("dynamics", [desc.substep, desc.load_hold == "linear", GIMBAL_TOL, LINEAR_RANGE, CAPSIZE]))
    return recs


def write_records(recs, path: Path):
    """model.bin: per record a 32-byte tag, an int64 count and that many float64 (little endian)."""
    with open(path, "wb") as f:
        for tag, values in recs:
            f.write(struct.pack("<32sq", tag.encode(), len(values)))
            f.write(np.asarray(values, dtype="<f8").tobytes())


def variables(slave, guid) -> str:
    lines = [f"hydrofmu-c 1 {guid}"]
    for vr, var in slave.vars.items():
        assert vr == len(lines) - 1, "value references must count from 0"
        lines.append(f"{CAUSALITY.get(var.causality.name, 'l')} {var.name}")
    return "\n".join(lines) + "\n"


def model_xml(slave, model_id) -> bytes:
    """The Python flavour's modelDescription.xml with a C implementation's capabilities and
    its <SourceFiles>."""
    slave.modelName = model_id
    root = slave.to_xml({"needsExecutionTool": False, "canGetAndSetFMUstate": True, "canSerializeFMUstate": True})
    cs = root.find("CoSimulation")
    del cs.attrib["canNotUseMemoryManagementFunctions"]
    files = ET.SubElement(cs, "SourceFiles")
    for s in SOURCES:
        ET.SubElement(files, "File", name=s)
    root.set("generationTool", "hydrofmu (compiled flavour)")
    return model_description.complete(ET.tostring(root, encoding="unicode"), slave.units, slave.dependencies,
                                      {v.name: slave._start[vr] for vr, v in slave.vars.items()})


def build_c_fmu(instance, workdir):
    """Build the compiled FMU of an ``assembly.Instance`` into ``workdir/fmus``; returns (fmu
    path, slave introspection, every variable's value at t = 0 (``starts.at_start``))."""
    from . import slave as slaves, starts
    from .build import SLAVES
    stage = workdir / "cstage" / instance.model_id
    stage.mkdir(parents=True)
    description.write(instance.fmu, stage)
    slave = getattr(slaves, SLAVES[type(instance.fmu)])(instance_name="introspect", resources=str(stage))
    fmu = write_fmu(workdir / "fmus" / f"{instance.model_id}.fmu", slave, records(slave, instance.fmu),
                    [stage / description.FILE])
    return fmu, slave, starts.at_start(instance.name, slave)   # (initialises the slave: after the records)


def write_fmu(path: Path, slave, recs, resources=()) -> Path:
    """A compiled FMU at ``path`` (its model identifier the file's stem) with the variables of
    ``slave``, the model records ``recs`` and further ``resources`` files."""
    model_id = path.stem
    xml = model_xml(slave, model_id)
    guid = ET.fromstring(xml).get("guid")
    path.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        write_records(recs, Path(tmp) / "model.bin")
        with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as z:
            z.writestr("modelDescription.xml", xml)
            z.writestr("resources/variables.txt", variables(slave, guid))
            z.write(Path(tmp) / "model.bin", "resources/model.bin")
            for f in resources:
                z.write(f, f"resources/{Path(f).name}")
            for s in SOURCES + HEADERS:
                z.write(PACKAGE / s, f"sources/{s}")
            for platform, lib in binaries().items():
                z.write(lib, f"binaries/{platform}/{model_id}{lib.suffix}")
    return path
