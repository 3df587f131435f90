"""The system C compiler, for hydrofmu's two small C parts: the FMI shim (fmi/shim.c) and
the rigid-body kernel (physics/rigid.c).  Each source is compiled once per hash of its
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
    source = Path(source)
    key = hashlib.sha256(source.read_bytes() + " ".join(FLAGS + list(libs)).encode()).hexdigest()[:16]
    lib = cache_dir() / f"{source.stem}-{key}.so"
    if lib.is_file():
        return lib
    lib.parent.mkdir(parents=True, exist_ok=True)
    cc = compiler()
    fd, tmp = tempfile.mkstemp(prefix=lib.stem + ".", suffix=".so.tmp", dir=lib.parent)
    os.close(fd)
    try:
        run = subprocess.run(cc + FLAGS + [str(source), "-o", tmp] + list(libs), capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError(f"compiling {source} with {cc[0]} failed:\n{run.stderr.strip()}")
        os.replace(tmp, lib)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    return lib
