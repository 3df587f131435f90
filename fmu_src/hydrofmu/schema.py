"""JSON Schemas of the scene and case files, made from ``keys.py`` (the one definition of
their keys) and shipped as ``hydrofmu/schema/scene.schema.json`` and ``cases.schema.json``.

A TOML editor that reads JSON Schemas (taplo, VS Code's Even Better TOML) completes keys,
shows each key's description and flags unknown keys and wrong shapes while a file is
typed, before any build.  ``python -m hydrofmu.schema`` writes the files again (a test
checks they are up to date).
"""
import json
from pathlib import Path

from . import keys

FOLDER = Path(__file__).resolve().parent / "schema"
DRAFT = "http://json-schema.org/draft-07/schema#"


def _value(spec):
    """The schema of one key's value: a fragment as it is, or a nested table of keys."""
    if "table" in spec:
        return table(spec["table"])
    if "map" in spec:   # [bodies.NAME], [joints.NAME]: any name, each a table
        item = table(spec["map"]) if "variants" not in spec else _variants(spec["map"], spec["variants"])
        return {"type": "object", "propertyNames": keys.NAME, "additionalProperties": item}
    if "effects" in spec:
        return {"type": "array", "items": _effect(spec["effects"])}
    if "couplings" in spec:
        deck, bem = spec["couplings"]
        return {"type": "array", "items": {"oneOf": [{**table(deck), "required": ["deck", "coupling"]},
                                                     {**table(bem), "required": ["bem"]}]}}
    return spec


def table(keyset, required=()):
    """An object whose properties are exactly ``keyset``'s keys."""
    out = {"type": "object", "additionalProperties": False,
           "properties": {k: {**_value(v[0]), "description": v[1]} for k, v in keyset.items()}}
    if required:
        out["required"] = list(required)
    return out


def _variants(common, variants):
    """A table whose data come from a deck (with ``deck``) or inline (without)."""
    return {"oneOf": [{**table({**common, **variants["deck"]}), "required": ["deck"]},
                      {**table({**common, **variants["inline"]}), "not": {"required": ["deck"]}}]}


def _effect(effects):
    """An effect table: its ``type`` picks the keys (deck or inline)."""
    kinds = []
    for kind, variants in effects.items():
        common = {**keys.EFFECT_COMMON, "type": ({"const": kind}, keys.EFFECT_COMMON["type"][1])}
        kinds.append(_variants(common, variants))
    return {"type": "object", "required": ["type"],
            "properties": {"type": {"enum": list(effects), "description": keys.EFFECT_COMMON["type"][1]}},
            "oneOf": kinds}


def scene_schema():
    return {"$schema": DRAFT, "$id": "https://hydrofmu.invalid/scene.schema.json", "title": "hydrofmu scene",
            "description": "A hydrofmu scene file (TOML): bodies, load effects, joints, couplings, environment, "
                           "run settings. Format: docs/scenes.md.",
            **table(keys.SCENE, required=("bodies",))}


def cases_schema():
    return {"$schema": DRAFT, "$id": "https://hydrofmu.invalid/cases.schema.json", "title": "hydrofmu cases",
            "description": "A hydrofmu load-case file (TOML): one scene, many cases. Format: docs/batches.md.",
            **table(keys.CASES, required=("scene", "outputs"))}


SCHEMAS = {"scene.schema.json": scene_schema, "cases.schema.json": cases_schema}


def text(name):
    """The file ``name`` as written (sorted keys kept in definition order, 1-space indent)."""
    return json.dumps(SCHEMAS[name](), indent=1, ensure_ascii=False) + "\n"


def write(folder=FOLDER):
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    for name in SCHEMAS:
        (folder / name).write_text(text(name), encoding="utf-8")
    return folder


if __name__ == "__main__":
    print(f"wrote {write()}")
