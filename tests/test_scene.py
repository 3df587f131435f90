"""Scene validation: every problem named by file and key path, nothing written on error."""
import pytest

from hydrofmu.errors import InputError
from hydrofmu.scene import load_scene

from conftest import MODELS, write_scene

BODY = """
[bodies.barge]
mass = 1.0e6
inertia = [1e8, 1e8, 1e8]
"""
DECKS = MODELS / "decks"


def error(tmp_path, text):
    path = write_scene(tmp_path, text)
    with pytest.raises(InputError) as exc:
        load_scene(path)
    msg = str(exc.value)
    assert str(path) in msg
    return msg


def test_demo_scene_loads():
    scene = load_scene(MODELS / "moored_barge.toml")
    barge = scene.bodies["barge"]
    assert [e.name for e in barge.effects] == ["viscous_drag", "current_polar"]
    # the xz symmetry completed the 0..180 table to the full circle
    angles = barge.effects[1].data["angles"]
    assert min(angles) == 0 and max(angles) > 300
    assert barge.effects[0].data["relative"] is True


def test_unknown_key(tmp_path):
    msg = error(tmp_path, BODY + "colour = 'red'\n")
    assert "bodies.barge.colour" in msg and "unknown key" in msg


def test_wrong_matrix_shape(tmp_path):
    msg = error(tmp_path, BODY + "stiffness = [[1, 2], [3, 4]]\n")
    assert "bodies.barge.stiffness" in msg and "6x6" in msg


def test_negative_density(tmp_path):
    msg = error(tmp_path, "[environment]\nrho = -1025.0\n" + BODY)
    assert "environment.rho" in msg and "positive" in msg


def test_missing_deck(tmp_path):
    msg = error(tmp_path, BODY + """
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
deck = "nowhere.aqwa"
body = "BARGE"
""")
    assert "bodies.barge.effects[0].deck" in msg and "not found" in msg


def test_body_not_in_deck(tmp_path):
    msg = error(tmp_path, BODY + f"""
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
deck = "{DECKS / 'barge_viscous.aqwa'}"
body = "TUG"
""")
    assert "bodies.barge.effects[0].body" in msg and "'TUG' is not in" in msg and "BARGE" in msg


def test_polar_without_symmetry_is_rejected(tmp_path):
    msg = error(tmp_path, BODY + f"""
[[bodies.barge.effects]]
type = "deeplines_current_polar"
deck = "{DECKS / 'barge_current.dpl'}"
structure = "BARGE"
""")
    assert "bodies.barge.effects[0].symmetry" in msg and "'xz'" in msg


def test_all_problems_in_one_error(tmp_path):
    msg = error(tmp_path, "[environment]\ng = 0\n" + BODY + "mass = 'heavy'\n".replace("mass", "cog"))
    assert "environment.g" in msg and "bodies.barge.cog" in msg


def test_toml_syntax_error_names_line(tmp_path):
    msg = error(tmp_path, BODY + "stiffness = [1, 2\n")
    assert ":" in msg.split(str(tmp_path))[1]  # file:line


def test_unknown_effect_type(tmp_path):
    msg = error(tmp_path, BODY + "[[bodies.barge.effects]]\ntype = 'wind'\n")
    assert "bodies.barge.effects[0].type" in msg and "aqwa_viscous_drag" in msg


def test_inline_effects(tmp_path):
    path = write_scene(tmp_path, BODY + """
[[bodies.barge.effects]]
type = "aqwa_viscous_drag"
matrix = [1e4, 2e4, 3e4, 0, 0, 5e6]
option = "ABSOLUTE"

[[bodies.barge.effects]]
type = "deeplines_current_polar"
point = [0.0, 0.0, 0.0]
surface = 100.0
symmetry = "xz+yz"
table = [[0, 1.0, 0, 0], [45, 0.7, 0.7, 0.1], [90, 0, 1.2, 0]]
""")
    barge = load_scene(path).bodies["barge"]
    assert barge.effects[0].data["matrix"][1][1] == 2e4
    assert barge.effects[1].data["surface"] == 100.0


def test_failed_build_writes_nothing(tmp_path):
    from hydrofmu.cli import build
    good = write_scene(tmp_path, BODY, "good.toml")
    bad = write_scene(tmp_path, BODY + "colour = 1\n", "bad.toml")
    with pytest.raises(InputError):
        build([good, bad], tmp_path / "out")
    assert not (tmp_path / "out").exists()
