"""Issue 22 guards: runs, batches, BEM input and every CLI command refuse bad input with one
clear error (exit 2, file and field named, nothing written) or say suspicious data out loud."""
import pytest

from hydrofmu.names import closest, did_you_mean, unknown
from hydrofmu.scene import load_scene
from hydrofmu.errors import InputError


def test_closest_names_rank_by_similarity_ignoring_case():
    valid = ["current_speed", "current_direction", "rho", "g"]
    assert closest("current_sped", valid)[0] == "current_speed"
    assert closest("CURRENT_SPEED", valid)[0] == "current_speed"
    assert closest("xyz", valid) == []
    assert did_you_mean("rh", ["rho", "g"]) == " (did you mean 'rho'?)"
    assert did_you_mean("zzz", ["rho"]) == ""
    msg = unknown("column", "barge.forse[1]", [f"barge.force[{i}]" for i in range(1, 7)] + ["time"], show=3)
    assert msg.startswith("unknown column 'barge.forse[1]' (did you mean 'barge.force[1]'")
    assert "… (4 more)" in msg


def test_unknown_scene_key_suggests_the_closest(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text("[environment]\ncurrent_sped = 1.0\n[bodies.barge]\nmass = 1e6\ninertia = [1e8, 1e8, 1e8]\n")
    with pytest.raises(InputError) as err:
        load_scene(scene)
    assert err.value.field == "environment.current_sped"
    assert "did you mean 'current_speed'" in str(err.value)
    assert err.value.unknown == {"environment.current_sped": sorted(err.value.unknown["environment.current_sped"])}
