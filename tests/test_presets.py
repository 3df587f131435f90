"""Run presets: a scene names screening/design/reference instead of setting each knob;
the knobs it sets itself win; a run reports the preset and every knob; and the presets
order as promised against the monolithic two-body solution."""
import json
from pathlib import Path

import pytest

from hydrofmu.bench.fleet import Fleet, nrms
from hydrofmu.cosim.master import describe, run
from hydrofmu.errors import InputError
from hydrofmu.fmi.build import build_scene
from hydrofmu.scene import PRESETS, load_scene

ROOT = Path(__file__).resolve().parents[1]
MOVING = [0, 1, 2, 7, 8]   # body 1 surge, sway, heave; body 2 sway, heave


def fleet_scene(tmp_path, run_lines, coupling=""):
    return Fleet(2).scene(tmp_path, run=run_lines, coupling=coupling)


def test_preset_sets_every_knob(tmp_path):
    scene = load_scene(fleet_scene(tmp_path, 'preset = "design"'))
    want = PRESETS["design"]
    assert scene.run["preset"] == "design" and scene.run["set"] == []
    for key in ("step", "algorithm", "substep", "load_hold"):
        assert scene.run[key] == want[key]
    for c in scene.couplings:
        assert (c.method, c.tolerance, c.memory_length) == (want["memory"]["method"], want["memory"]["tolerance"],
                                                          want["memory"]["memory_length"])
        assert c.set == []


def test_scene_knobs_win_and_are_reported(tmp_path):
    path = fleet_scene(tmp_path, 'preset = "screening"\nstep = 0.1\nstop = 5.0', coupling='method = "convolution"')
    scene = load_scene(path)
    assert scene.run["step"] == 0.1 and scene.run["substep"] == PRESETS["screening"]["substep"]
    assert scene.run["set"] == ["step", "stop"]
    assert all(c.method == "convolution" and c.set == ["method"] for c in scene.couplings)
    folder = build_scene(scene, tmp_path / "out", log=lambda *_: None)
    manifest = json.loads((folder / "manifest.json").read_text())
    assert manifest["run"]["preset"] == "screening"
    result = run(folder, step=0.05, progress=False)
    s = result.settings
    assert (s["preset"], s["step"], s["algorithm"], s["load_hold"]) == ("screening", 0.05, "gauss-seidel", "linear")
    assert s["set"] == ["stop", "step (run)"] and s["couplings"]["C1_2"]["method"] == "convolution"
    line = describe(s)
    assert line.startswith("preset screening: step 0.05 s, gauss-seidel, linear load hold")
    assert "C1_2: convolution (set: method)" in line


def test_no_preset_keeps_the_defaults(tmp_path):
    """Without a preset: the defaults, but the linear load hold where the scene has memory (the
    constant hold's half-step lag against light damping, docs/tuning.md); a scene without
    memory, waves or BEM hydrostatics keeps the constant hold."""
    scene = load_scene(fleet_scene(tmp_path, "stop = 1.0"))
    assert scene.run["preset"] is None and scene.run["step"] == 0.1 and scene.run["load_hold"] == "linear"
    assert scene.run["chosen"] == ["linear load hold (the scene has radiation memory)"]
    assert all(c.method == "convolution" for c in scene.couplings)
    scene = load_scene(fleet_scene(tmp_path, 'stop = 1.0\nload_hold = "constant"'))
    assert scene.run["load_hold"] == "constant" and scene.run["chosen"] == []   # the scene's own word wins
    plain = load_scene(ROOT / "models" / "moored_barge.toml")
    assert plain.run["load_hold"] == "constant" and plain.run["chosen"] == []


def test_unknown_preset_is_named(tmp_path):
    path = fleet_scene(tmp_path, 'preset = "fastest"')
    with pytest.raises(InputError) as exc:
        load_scene(path)
    assert str(path) in str(exc.value) and "run.preset" in str(exc.value) and "'design'" in str(exc.value)


def test_presets_trade_speed_for_accuracy(tmp_path):
    """Each preset against the monolithic Cummins solution (20 s of the two-body scene):
    errors within the README's bounds and ordered screening > design > reference."""
    fleet, errors = Fleet(2), {}
    for name in ("screening", "design", "reference"):
        folder = build_scene(load_scene(fleet.scene(tmp_path / name, run=f'preset = "{name}"\nstop = 20.0')),
                             tmp_path / name / "out", log=lambda *_: None)
        result = run(folder, progress=False)
        ref = fleet.monolithic(result.time)
        errors[name] = nrms(fleet.displacements(result)[:, MOVING], ref[:, MOVING]).max()
    assert errors["screening"] > errors["design"] > errors["reference"]
    # measured: 1.3 %, 0.086 %, 0.064 % (reference: the floor of the kernels sampled at TIMDEL)
    assert errors["screening"] < 0.03 and errors["design"] < 0.003 and errors["reference"] < 0.0015, errors
