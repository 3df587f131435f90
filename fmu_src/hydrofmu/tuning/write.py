"""``hydrofmu tune --write``: the choice put in place of the scene's ``[run]`` table."""
from __future__ import annotations

import re
from pathlib import Path

from ..errors import InputError
from .report import Tuning

RUN_TABLE = re.compile(r"^\s*\[\s*run\s*\]\s*(#.*)?$")
RUN_ECCO = re.compile(r"^\s*\[\s*run\s*\.\s*ecco\s*\]\s*(#.*)?$")
COUPLING = re.compile(r"^\s*\[\[\s*couplings\s*\]\]\s*(#.*)?$")
TABLE = re.compile(r"^\s*\[")


def _table_end(lines, start):
    """Index of the first line of the table after the one whose header is ``lines[start]``."""
    return next((i for i in range(start + 1, len(lines)) if TABLE.match(lines[i])), len(lines))


def write_run_block(scene_path, tuning: Tuning) -> Path:
    """Replace the scene's ``[run]`` table by the choice (its ``stop``, ``outputs`` and
    ``interval`` kept; ``[run.ecco]`` replaced by an ECCO choice's, else removed) and set the ``method``/``order`` of each coupling the choice
    gives an order, in its ``[[couplings]]`` table; the rest of the file untouched.  The file
    is checked to load before it is replaced."""
    from ..scene import load_scene
    path = Path(scene_path)
    lines = path.read_text().splitlines(keepends=True)
    import json
    run = load_scene(path).run
    # what the run writes is no run knob: kept
    block = tuning.run_block(stop=run["stop"], keep=[f"{k} = {json.dumps(run[k])}" for k in ("outputs", "interval")
                                                     if run.get(k) is not None])
    setting = tuning.choice.setting
    heads = [i for i, line in enumerate(lines) if COUPLING.match(line)]
    for i, n in sorted(setting.orders, reverse=True):   # from the end: the earlier heads stay put
        h = heads[i]
        end = _table_end(lines, h)
        rest = [line for line in lines[h + 1:end] if not re.match(r"^\s*(method|order|tolerance)\s*=", line)]
        lines[h + 1:end] = ['method = "state_space"   # hydrofmu tune\n', f"order = {n}\n"] + rest
    e = next((i for i, line in enumerate(lines) if RUN_ECCO.match(line)), None)
    if e is not None:   # ECCO settings are the choice's (as the tune ran them), or none
        del lines[e:_table_end(lines, e)]
    start = next((i for i, line in enumerate(lines) if RUN_TABLE.match(line)), None)
    if start is None:
        first = next((i for i, line in enumerate(lines) if TABLE.match(line) and not line.strip().startswith("[scene")
                      and not line.strip().startswith("[environment")), len(lines))
        new = lines[:first] + [block + "\n"] + lines[first:]
    else:
        end = _table_end(lines, start)
        trailing = [line for line in lines[start + 1:end] if not line.strip()]
        new = lines[:start] + [block] + (["\n"] if trailing else []) + lines[end:]
    tmp = path.with_name(f".{path.name}.tune")
    tmp.write_text("".join(new))
    try:
        load_scene(tmp)
    except InputError:
        tmp.unlink()
        raise
    tmp.replace(path)
    return path
