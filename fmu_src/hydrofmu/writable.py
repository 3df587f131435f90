"""Output paths: checked writable before any work starts, and results kept when a write
fails after the work is done.  One set of rules for every command and the batch:

- an output **file** (CSV, PNG, a deck) must not be a folder, and its folder must exist, be
  a folder and take a new file (probed by creating and removing one);
- an output **folder** (``-o``) must be a folder or not exist yet; then its nearest existing
  parent must be a folder that takes a new file (the folder is created when written);
- a **plot** file's suffix must name a format matplotlib writes (``.png``, ``.pdf``, ``.svg``…):
  no suffix, or ``.txt``, is refused up front, not after the run;
- no two outputs of one command may be the same file, and no output may be one of the
  command's inputs (the scene, its decks, the BEM result) or lie inside an input folder (the
  built scene folder, which a rebuild replaces whole): an output never overwrites what it is
  made from;
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


def check_plot(path, field: str = "plot file") -> Path:
    """InputError unless ``path`` ends in a format matplotlib writes (the suffix decides it)."""
    path = Path(path)
    from matplotlib.backend_bases import FigureCanvasBase
    formats = sorted(FigureCanvasBase.get_supported_filetypes())
    if path.suffix[1:].lower() not in formats:
        found = f"suffix {path.suffix!r}" if path.suffix else "no suffix"
        raise InputError(path, None, field, f"{found}: a plot is written in the format its suffix names "
                                            f"(one of {', '.join('.' + f for f in formats)})")
    return path


def _inside(path: Path, folder: Path) -> bool:
    return folder == path or folder in path.parents


def check_outputs(files=(), folders=(), plots=(), inputs=()) -> None:
    """``check_folder`` of every folder, ``check_plot`` of every plot, no two output files
    the same, none of them an input file or inside an input folder (``inputs``: the
    command's files and folders, including one it is about to build), then ``check_file``
    of every file and plot (None entries skipped)."""
    for d in folders:
        if d is not None:
            check_folder(d)
    outs = [Path(f) for f in (*files, *plots) if f is not None]
    for f in outs:
        if f.is_dir():
            check_file(f)   # says: a folder, not a file
    for f in plots:
        if f is not None:
            check_plot(f)
    seen = {}
    for f in outs:
        real = f.resolve()
        if real in seen:
            raise InputError(f, None, "output file", "two outputs of the command go to this one file: "
                                                     "the second would overwrite the first")
        seen[real] = f
    for i in (Path(i) for i in inputs if i is not None):
        real = i.resolve()   # an input folder the command is about to make (a build) counts too
        for f in outs:
            if _inside(f.resolve(), real):
                what = "is the input file" if real == f.resolve() else "lies inside the input folder"
                raise InputError(f, None, "output file", f"{what} {i}: writing it would overwrite what the "
                                                         "command reads or builds (choose another path)")
    for f in outs:
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
