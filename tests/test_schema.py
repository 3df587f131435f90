"""The JSON Schemas of scene and case files: made from keys.py (the validator's own key
sets), shipped up to date with the package, and holding every scene and case file of the
repository; a key the validator refuses, the schema refuses too."""
import json
import tomllib

import jsonschema
import pytest

from conftest import MODELS, ROOT
from hydrofmu import schema
from hydrofmu.errors import InputError
from hydrofmu.scene import load_scene

TOML_FILES = sorted(p for p in ROOT.rglob("*.toml") if p.name not in ("pyproject.toml", ".taplo.toml")
                    and not any(part in (".venv", "build", ".git", "node_modules") for part in p.relative_to(ROOT).parts))


def shipped(name):
    return json.loads((schema.FOLDER / name).read_text(encoding="utf-8"))


def is_cases(doc):
    return "outputs" in doc or "matrix" in doc


def test_shipped_schemas_are_valid_and_up_to_date():
    for name in schema.SCHEMAS:
        jsonschema.Draft7Validator.check_schema(shipped(name))
        assert (schema.FOLDER / name).read_text(encoding="utf-8") == schema.text(name), \
            f"{name} is out of date: python -m hydrofmu.schema"


@pytest.mark.parametrize("path", TOML_FILES, ids=lambda p: str(p.relative_to(ROOT)))
def test_every_scene_and_case_file_of_the_repository_holds(path):
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    name = "cases.schema.json" if is_cases(doc) else "scene.schema.json"
    errors = [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
              for e in jsonschema.Draft7Validator(shipped(name)).iter_errors(doc)]
    assert not errors, errors


def test_the_repository_has_scenes_and_a_case_file():
    kinds = [is_cases(tomllib.loads(p.read_text(encoding="utf-8"))) for p in TOML_FILES]
    assert kinds.count(False) >= 3 and kinds.count(True) >= 1


@pytest.mark.parametrize("scene, key", [
    ("moored_barge", "environment"), ("moored_barge", "scene"), ("moored_barge", "run"),
    ("moored_barge", "bodies.barge"), ("moored_barge", "bodies.barge.effects[0]"),
    ("moored_barge", "bodies.barge.effects[1]"), ("joined_barges", "joints.hitch"),
    ("joined_barges", "bodies.barge_a.effects[2]"), ("side_by_side", "couplings[0]")])
def test_a_key_the_validator_refuses_the_schema_refuses(scene, key):
    path = MODELS / f"{scene}.toml"
    with pytest.raises(InputError) as exc:
        load_scene(path, {f"{key}.colour": 1.0})
    assert f"{key}.colour" in exc.value.unknown
    doc = tomllib.loads(path.read_text(encoding="utf-8"))
    table = doc
    for part in key.replace("]", "").replace("[", ".").split("."):
        table = table[int(part)] if part.isdigit() else table[part]
    validator = jsonschema.Draft7Validator(shipped("scene.schema.json"))
    assert not list(validator.iter_errors(doc))
    table["colour"] = 1.0
    assert list(validator.iter_errors(doc)), f"the schema takes {key}.colour"
    # and the keys the validator allows there are the schema's (one definition, keys.py)
    del table["colour"]
    assert set(exc.value.unknown[f"{key}.colour"]) == schema_keys(shipped("scene.schema.json"), key, table)


def schema_keys(root, key, table):
    """The property names the schema allows for the table at ``key`` (its branch that
    validates ``table`` where there are variants: deck or inline, effect type)."""
    node = root
    for part in key.replace("]", "").replace("[", ".").split("."):
        if part.isdigit():
            node = node["items"]
        elif part in node.get("properties", {}):
            node = node["properties"][part]
        else:   # a name of a [bodies.NAME] / [joints.NAME] map
            node = node["additionalProperties"]
    while "oneOf" in node:   # an effect's type, then deck or inline
        (node,) = [b for b in node["oneOf"] if jsonschema.Draft7Validator(b).is_valid(table)]
    return set(node["properties"])


def test_a_typo_in_a_case_file_is_flagged():
    doc = tomllib.loads((ROOT / "examples" / "cases.toml").read_text(encoding="utf-8"))
    doc["transeint"] = 10.0
    errors = list(jsonschema.Draft7Validator(shipped("cases.schema.json")).iter_errors(doc))
    assert any("transeint" in e.message for e in errors)


def test_the_validator_takes_its_keys_from_keys_py():
    """One definition: every key set the scene and case readers check against comes from
    keys.py (a literal set there would let the schema drift), every effect type has its keys."""
    import re
    from hydrofmu import keys, scene
    package = ROOT / "fmu_src" / "hydrofmu"
    for module in sorted((package / "scene").glob("*.py")) + [package / "batch.py"]:
        text = module.read_text(encoding="utf-8")
        literal = re.findall(r"known_keys\([^)]*[{\[]", text)
        assert not literal, f"{module.name}: key sets belong in keys.py: {literal}"
    assert set(scene.EFFECT_TYPES) == set(keys.EFFECTS), "an effect type without its keys in keys.py"
