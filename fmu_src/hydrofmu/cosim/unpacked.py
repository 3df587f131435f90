"""FMUs unzipped once and shared: each FMU is unzipped into the cache under the hash of its
bytes and every later load, in this process or another (our master, batch workers), uses
that folder.

fmpy's ``extract`` unzips every load into a new temporary folder, which the master deleted
again at free: in a running process that was most of the time an FMU took to start.  Here:

- the key is the SHA-256 of the FMU file: a rebuilt FMU gets a folder of its own, also at
  the same path; the same FMU copied elsewhere shares one;
- an FMU is unzipped into a private folder beside its final place and renamed into place:
  workers unzipping the same FMU at once all finish, one rename wins and the others drop
  their copy; nobody sees a partial folder;
- only what a Linux host loads is unzipped (``modelDescription.xml``, ``resources/``,
  ``binaries/linux64/``); nothing writes into the folder after (the FMU's runtime carries its
  bytecode), so every instance of every process can share it;
- the cache keeps the ``KEEP`` folders used last (each use touches its folder); a new folder
  removes older ones beyond that, never one used in the last ``GRACE`` seconds.
"""
from __future__ import annotations

import hashlib
import os
import shutil
import time
import uuid
import zipfile
from pathlib import Path

from ..cc import cache_dir

KEEP = 32         # unzipped FMUs kept
GRACE = 600.0     # s: a folder used this recently is never removed (a run may still read it)
WANTED = ("modelDescription.xml", "resources/", "binaries/linux64/")


def folder() -> Path:
    """Where unzipped FMUs live: ``fmus/`` in hydrofmu's cache (``hydrofmu.cc.cache_dir``)."""
    return cache_dir() / "fmus"


_digests = {}   # (path, inode, size, mtime) -> digest: each file version hashed once per process


def digest(fmu) -> str:
    """SHA-256 of the FMU file, hex."""
    st = os.stat(fmu)
    key = (os.path.abspath(fmu), st.st_ino, st.st_size, st.st_mtime_ns)
    if key not in _digests:
        h = hashlib.sha256()
        with open(fmu, "rb") as f:
            for block in iter(lambda: f.read(1 << 20), b""):
                h.update(block)
        _digests[key] = h.hexdigest()
    return _digests[key]


def unpacked(fmu) -> Path:
    """The folder holding ``fmu`` unzipped (made on first use); its modification time marks
    the use.  The hash of a file is computed once per process and version of the file (its
    inode, size and modification time)."""
    fmu = Path(fmu)
    target = folder() / digest(fmu)[:32]
    if (target / "modelDescription.xml").is_file():
        os.utime(target)
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = target.with_name(f".{target.name}.{os.getpid()}.{uuid.uuid4().hex[:8]}")
    try:
        with zipfile.ZipFile(fmu) as z:
            z.extractall(tmp, [n for n in z.namelist() if n.startswith(WANTED)])
        try:
            tmp.rename(target)
        except OSError:   # another process got there first: its copy is the same
            if not (target / "modelDescription.xml").is_file():
                raise
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    prune(keep=target)
    return target


def prune(keep=None):
    """Remove the folders beyond the KEEP used last, except those used within GRACE seconds
    (and ``keep``), and private folders left by a worker that died while unzipping.  A
    folder is renamed away first: nobody finds it half removed."""
    now = time.time()
    try:
        entries = sorted(((p.stat().st_mtime, p) for p in folder().iterdir()), reverse=True)
    except OSError:
        return
    done = [e for e in entries if not e[1].name.startswith(".")]
    old = [p for t, p in done[KEEP:] if now - t > GRACE and p != keep]
    old += [p for t, p in entries if p.name.startswith(".") and now - t > GRACE]
    for path in old:
        gone = path.with_name(f".gone.{path.name}.{uuid.uuid4().hex[:8]}")
        try:
            path.rename(gone)
        except OSError:
            continue   # another process removes it
        shutil.rmtree(gone, ignore_errors=True)
