"""Output paths: checked writable before any work starts, and results kept when a write
fails after the work is done.  One set of rules for every command and the batch:

- an output **file** (CSV, PNG, a deck) must not be a folder, and its folder must exist, be
  a folder and take a new file (probed by creating and removing one);
- an output **folder** (``-o``) must be a folder or not exist yet; then its nearest existing
  parent must be a folder that takes a new file (the folder is created when written);
- ``keep``: a write that fails after a run (disk full, folder removed meanwhile) goes to a
  fallback folder instead (the current folder, else the system's temporary folder) and the
  caller says where: results are never lost to an output path.
"""
from __future__ import annotations

import os
import tempfile
from pathlib import Path
from typing import Callable

from .errors import InputError


def _probe(folder: Path) -> str | None:
    """Why ``folder`` takes no new file, or None when it does."""
    try:
        fd, name = tempfile.mkstemp(prefix=".hydrofmu-probe-", dir=folder)
    except OSError as exc:
        return exc.strerror or str(exc)
    os.close(fd)
    os.unlink(name)
    return None


def check_file(path, field: str = "output file") -> Path:
    """InputError (naming ``path`` and ``field``) unless a file can be written at ``path``."""
    path = Path(path)
    if path.is_dir():
        raise InputError(path, None, field, "is a folder, not a file")
    parent = path.parent
    if not parent.exists():
        raise InputError(path, None, field, f"folder {parent} does not exist")
    if not parent.is_dir():
        raise InputError(path, None, field, f"{parent} is a file, not a folder")
    if path.exists() and not os.access(path, os.W_OK):
        raise InputError(path, None, field, "cannot write (permission denied)")
    why = _probe(parent)
    if why:
        raise InputError(path, None, field, f"cannot write in folder {parent} ({why})")
    return path


def check_folder(path, field: str = "output folder") -> Path:
    """InputError (naming ``path`` and ``field``) unless ``path`` is, or can be made, a
    folder that takes new files."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise InputError(path, None, field, "is a file, not a folder")
    existing = next((p for p in [path, *path.parents] if p.exists()), Path("."))
    if not existing.is_dir():
        raise InputError(path, None, field, f"{existing} is a file, not a folder")
    why = _probe(existing)
    if why:
        raise InputError(path, None, field, f"cannot write in folder {existing} ({why})")
    return path


def check_outputs(files=(), folders=()) -> None:
    """``check_file`` of every file, ``check_folder`` of every folder (None entries skipped)."""
    for d in folders:
        if d is not None:
            check_folder(d)
    for f in files:
        if f is not None:
            check_file(f)


def fallback_folders() -> list[Path]:
    return [Path.cwd(), Path(tempfile.gettempdir())]


def keep(write: Callable[[Path], object], path, log: Callable[[str], object]) -> tuple[Path, bool]:
    """``write(path)``; when it fails with an OSError, ``write`` into a fallback folder under
    the same name, and ``log`` one line saying why and where.  Returns (the path written,
    whether it is the one asked).  Raises the first OSError when no fallback takes it."""
    path = Path(path)
    try:
        write(path)
        return path, True
    except OSError as exc:
        first = exc
    for folder in fallback_folders():
        other = folder / path.name
        if other.resolve() == path.resolve():
            continue
        if other.exists():
            stem = f"{path.stem}-{os.getpid()}"
            other = folder / f"{stem}{path.suffix}"
        try:
            write(other)
        except OSError:
            continue
        log(f"warning: cannot write {path} ({first.strerror or first}); wrote {other} instead")
        return other, False
    raise first
