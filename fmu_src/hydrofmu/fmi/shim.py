"""Install the FMI status shim (shim.c) into a pythonfmu FMU.

pythonfmu maps a slave's ``do_step`` returning False to ``fmi2Discard``; hydrofmu
slaves return False only on bad input (they never complete a partial step), so the
shim turns that ``fmi2DoStep`` status into ``fmi2Error``.  pythonfmu also drops every
log message while the host's logging is off; the shim keeps the inner FMU's logging
on and passes warnings and errors to the host always, other messages only when the
host's logging is on for their category.  Everything else is forwarded unchanged.
In a host process without Python (a native FMI host such as libcosim's ``cosim``) the
shim starts the interpreter recorded at build time (``$HYDROFMU_PYTHON`` overrides it)
before loading pythonfmu's binary.  pythonfmu 0.7 leaks ~1.2 kB at every fmi2Instantiate,
so the shim pools freed instances and hands them back, after fmi2Reset, to an
fmi2Instantiate with the same arguments (HYDROFMU_POOL=0 turns that off); see shim.c.
Layout inside the FMU after
``install_shim``::

    binaries/linux64/<id>.so              the shim (compiled from shim.c)
    binaries/linux64/<id>_pythonfmu.so    pythonfmu's original binary, loaded by the shim
    resources/hydrofmu_python.txt         the interpreter to start where there is no Python

Linux only: other platforms' binaries are left untouched (they keep pythonfmu's
Discard mapping).
"""

from __future__ import annotations

import os
import shutil
import sys
import sysconfig
import tempfile
import time
import zipfile
from pathlib import Path
from xml.etree import ElementTree as ET

from .. import cc

SOURCE = Path(__file__).with_name("shim.c")
LIBS = ["-ldl", "-lpthread"]  # after the source: link order matters with --as-needed
INNER_SUFFIX = "_pythonfmu.so"
PLATFORM_DIR = "binaries/linux64"
RECORD = "resources/hydrofmu_python.txt"
ENV = "HYDROFMU_PYTHON"  # names another interpreter for the FMUs (read by shim.c)


def _cached_shim() -> Path:
    """shim.c compiled once per source/flags hash (``hydrofmu.cc``): the cached library."""
    if not sys.platform.startswith("linux"):
        raise RuntimeError(f"the hydrofmu FMI shim is built for Linux only, not {sys.platform}")
    return cc.cached(SOURCE, LIBS)


def compile_shim(out_path) -> Path:
    """Write the compiled shim library to ``out_path`` and return it as a Path.

    The compilation itself is cached (keyed by the hash of shim.c and the flags), so
    building many FMUs compiles once.  Raises RuntimeError when no C compiler is found
    or the compilation fails.
    """
    out = Path(out_path)
    out.parent.mkdir(parents=True, exist_ok=True)
    shutil.copyfile(_cached_shim(), out)
    os.chmod(out, 0o755)
    return out


def python_record() -> str:
    """resources/hydrofmu_python.txt: this interpreter (``sys.executable``, not resolved,
    so that a venv stays a venv), its libpython and version.  The libpython is the first
    of LIBDIR/INSTSONAME, LIBDIR/LDLIBRARY that exists, else the bare soname (found by the
    loader's search path); shim.c asks a $HYDROFMU_PYTHON interpreter the same way."""
    libdir = sysconfig.get_config_var("LIBDIR") or ""
    names = [sysconfig.get_config_var(k) for k in ("INSTSONAME", "LDLIBRARY")]
    candidates = [os.path.join(libdir, n) for n in names if n and ".so" in n]
    lib = next((p for p in candidates if os.path.isfile(p)), names[0] or "")
    version = "%d.%d" % sys.version_info[:2]
    return f"executable={sys.executable}\nlibpython={lib}\nversion={version}\n"


def _model_identifier(zin: zipfile.ZipFile, fmu: Path) -> str:
    """CoSimulation/@modelIdentifier from the FMU's modelDescription.xml."""
    try:
        root = ET.fromstring(zin.read("modelDescription.xml"))
    except KeyError:
        raise ValueError(f"{fmu}: no modelDescription.xml in the FMU") from None
    cs = root.find("CoSimulation")
    mid = cs.get("modelIdentifier") if cs is not None else None
    if not mid:
        raise ValueError(f"{fmu}: modelDescription.xml has no CoSimulation/@modelIdentifier")
    return mid


def _entry(name: str, like: zipfile.ZipInfo | None = None) -> zipfile.ZipInfo:
    """A zip entry called ``name``: a copy of ``like``'s metadata, or a fresh executable file."""
    if like is not None:
        info = zipfile.ZipInfo(name, date_time=like.date_time)
        info.compress_type, info.external_attr = like.compress_type, like.external_attr
        info.create_system = like.create_system
    else:
        info = zipfile.ZipInfo(name, date_time=time.localtime()[:6])
        info.compress_type = zipfile.ZIP_DEFLATED
        info.external_attr = (0o100755 & 0xFFFF) << 16  # regular file, rwxr-xr-x
        info.create_system = 3  # Unix, so the mode bits are honoured
    return info


def install_shim(fmu_path) -> Path:
    """Put the shim into the FMU at ``fmu_path`` (rewritten in place) and return the path.

    ``binaries/linux64/<id>.so`` moves to ``binaries/linux64/<id>_pythonfmu.so``, the
    shim takes its place and RECORD names this interpreter; every other entry is copied
    unchanged.  Running it again on a shimmed FMU only refreshes the shim and RECORD.  The new zip is written to a temporary file
    beside the FMU and swapped in at the end, so a failure leaves the FMU as it was.
    """
    fmu = Path(fmu_path)
    shim = _cached_shim().read_bytes()
    fd, tmp = tempfile.mkstemp(prefix=fmu.name + ".", suffix=".tmp", dir=fmu.parent)
    os.close(fd)
    try:
        with zipfile.ZipFile(fmu) as zin, zipfile.ZipFile(tmp, "w") as zout:
            mid = _model_identifier(zin, fmu)
            outer = f"{PLATFORM_DIR}/{mid}.so"
            inner = f"{PLATFORM_DIR}/{mid}{INNER_SUFFIX}"
            names = set(zin.namelist())
            if outer not in names:
                raise ValueError(f"{fmu}: no {outer} to wrap (not a Linux pythonfmu FMU?)")
            shimmed = inner in names  # already installed: keep the inner, refresh the shim
            for info in zin.infolist():
                if info.filename == outer:
                    if not shimmed:
                        zout.writestr(_entry(inner, info), zin.read(info))
                    zout.writestr(_entry(outer), shim)
                elif info.filename != RECORD:
                    zout.writestr(_entry(info.filename, info), zin.read(info))
            record = _entry(RECORD)
            record.external_attr = (0o100644 & 0xFFFF) << 16
            zout.writestr(record, python_record())
        shutil.copymode(fmu, tmp)
        os.replace(tmp, fmu)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return fmu
