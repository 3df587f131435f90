"""Reading a built scene folder's ``manifest.json`` (written by ``fmi.build``), the same way
for every master, the command line and the batch: a folder that is not a whole build (no
manifest, broken JSON, a key or an FMU missing) is one InputError naming the file and the key."""
import json
from pathlib import Path

from ..errors import InputError

RUN_KEYS = ("stop", "step", "algorithm")
KEYS = {"scene": str, "run": dict, "instances": dict, "order": list, "connections": list, "dynamics": dict}


def read_manifest(folder) -> dict:
    """The manifest of the built scene ``folder``, checked."""
    path = Path(folder) / "manifest.json"
    if not path.is_file():
        raise InputError(folder, None, "scene", "not a scene .toml nor a built scene folder (no manifest.json)")
    try:
        manifest = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError) as exc:
        raise InputError(path, None, "file", f"cannot read ({getattr(exc, 'strerror', None) or exc})") from None
    except json.JSONDecodeError as exc:
        raise InputError(path, exc.lineno, "json", f"not a manifest ({exc.msg}): rebuild the scene") from None
    if not isinstance(manifest, dict):
        raise InputError(path, None, "json", "not a manifest (expected an object): rebuild the scene")
    for key, kind in KEYS.items():
        if not isinstance(manifest.get(key), kind):
            raise InputError(path, None, key, f"missing or not a{'n' if kind is dict else ''} "
                                              f"{kind.__name__}: rebuild the scene (hydrofmu build)")
    for key in RUN_KEYS:
        if key not in manifest["run"]:
            raise InputError(path, None, f"run.{key}", "missing: rebuild the scene (hydrofmu build)")
    for name in manifest["order"]:
        inst = manifest["instances"].get(name)
        fmu = inst.get("fmu") if isinstance(inst, dict) else None
        if not isinstance(fmu, str) or not (Path(folder) / fmu).is_file():
            raise InputError(path, None, f"instances.{name}.fmu", f"{fmu!r} is not in the folder: rebuild the scene")
    return manifest
