"""The system C compiler, for hydrofmu's C parts: the FMI shim (fmi/shim.c), the rigid-body
kernel (physics/rigid.c) and the compiled FMUs (fmi/cbuild.py).  Each library is compiled once per hash of its
text and flags into a cache folder ($HYDROFMU_CACHE, else $XDG_CACHE_HOME/hydrofmu, else
~/.cache/hydrofmu), under a private name renamed into place, so that concurrent builds
(batch workers, parallel test processes) never see a partial library."""
from __future__ import annotations

import hashlib
import os
import shlex
import shutil
import subprocess
import tempfile
from pathlib import Path

FLAGS = ["-O2", "-shared", "-fPIC", "-fvisibility=hidden", "-std=c99"]


def compiler() -> list[str]:
    """The C compiler command: $CC if set, else `cc`, else `gcc`."""
    env = os.environ.get("CC")
    if env and shutil.which(shlex.split(env)[0]):
        return shlex.split(env)
    for name in ("cc", "gcc"):
        path = shutil.which(name)
        if path:
            return [path]
    raise RuntimeError(
        "hydrofmu needs a C compiler to build its FMI shim and rigid-body kernel, but neither "
        "$CC, `cc` nor `gcc` was found on PATH; install one (e.g. `apt-get install gcc`)"
    )


def cache_dir() -> Path:
    """$HYDROFMU_CACHE, else $XDG_CACHE_HOME/hydrofmu, else ~/.cache/hydrofmu."""
    root = os.environ.get("HYDROFMU_CACHE")
    if root:
        return Path(root)
    xdg = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(xdg) / "hydrofmu"


def cached(source: Path, libs: list[str] = ()) -> Path:
    """The shared library of C file ``source`` (FLAGS, then ``libs`` after the source: link
    order matters with --as-needed), compiled unless the cache holds it already."""
    return cached_many([Path(source)], Path(source).stem, libs=libs)


def cached_many(sources: list[Path], name: str, libs: list[str] = (), flags: list[str] = FLAGS,
                includes: list[Path] = (), cc: list[str] | None = None, suffix: str = ".so") -> Path:
    """The library ``name`` of the C files ``sources`` (their hash and that of every header
    next to them and in ``includes`` its key), compiled by ``cc`` (default ``compiler()``)
    with ``flags``, then ``libs`` after the sources (link order matters with --as-needed),
    unless the cache holds it already."""
    sources = [Path(s) for s in sources]
    cc = cc or compiler()
    h = hashlib.sha256(" ".join(cc + list(flags) + list(libs)).encode())
    for f in sources + sorted(p for d in {s.parent for s in sources} | {Path(i) for i in includes}
                              for p in Path(d).glob("*.h")):
        h.update(f.name.encode() + f.read_bytes())
    lib = cache_dir() / f"{name}-{h.hexdigest()[:16]}{suffix}"
    if lib.is_file():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=lib.stem + ".", suffix=suffix + ".tmp", dir=lib.parent)
    os.close(fd)
    try:
        run = subprocess.run(cc + list(flags) + [f"-I{i}" for i in includes] + [str(s) for s in sources]
                             + ["-o", tmp] + list(libs), capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"compiling {', '.join(s.name for s in sources)} with {cc[0]} failed:\n"
                               f"{run.stderr.strip()}")
        os.replace(tmp, lib)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return lib
