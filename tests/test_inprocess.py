"""The in-process system (cosim.inprocess, used by the stability studies) against the built
FMUs of the same scene through fmpy: the same master, so the same numbers."""
import numpy as np
import pytest

from hydrofmu.cosim import inprocess
from hydrofmu.cosim.master import RunError, load, run
from hydrofmu.scene import load_scene

from conftest import build, coupled_pair_scene, write_scene
from simo_decks import pair_deck

M = 1.0e6


def scene_text(deck):
    """Body a (explicit, drag in a current, a soft ball joint with a massive node to the earth)
    and body b (export), coupled by SIMO self and cross added mass and memory."""
    velocity = [0.3, -0.2, 0.1, 0.0, 0.0, 0.01]
    return coupled_pair_scene(deck, [("a", 0.0, "explicit", velocity, None, 0.0),
                                     ("b", 40.0, "export", velocity, None, 0.0)])


@pytest.fixture(scope="module")
def scene_and_build(tmp_path_factory):
    folder = tmp_path_factory.mktemp("inprocess")
    text = scene_text(pair_deck(folder / "pair.sim", M).name)
    return load_scene(write_scene(folder, text)), build(folder, text)


@pytest.mark.parametrize("algorithm", ["gauss-seidel", "jacobi"])
def test_inprocess_equals_built_fmus(scene_and_build, algorithm):
    """Every output of every instance (loads, joint, coupled dynamics) over 80 steps: the
    in-process slaves and the FMUs through fmpy agree to round-off."""
    scene, folder = scene_and_build
    fmus = run(folder, algorithm=algorithm, progress=False)
    local = run(inprocess.system(scene), algorithm=algorithm, record=fmus.columns, progress=False)
    assert {"a", "b", "pin", "a_b_dynamics"} <= {c.split(".")[0] for c in fmus.columns}
    assert np.abs(fmus.values).max() > 0 and np.all(np.isfinite(fmus.values))
    np.testing.assert_allclose(local.values, fmus.values, rtol=1e-12, atol=1e-9)
    assert local.units == fmus.units and fmus.units["a.force[4]"] == "N.m"


def test_inprocess_fails_as_the_fmus_do(scene_and_build):
    """A non-finite current input: the same RunError (call, time, the slave's message) in
    process as through fmpy and the FMUs' shim."""
    scene, folder = scene_and_build
    bad = {"a.current.speed": float("nan")}
    system = load(folder, bad)   # past run()'s own refusal of a non-finite parameter: the FMU's guard
    try:
        with pytest.raises(RunError) as fmus:
            run(system, progress=False)
    finally:
        system.free()
    with pytest.raises(RunError) as local:
        run(inprocess.system(scene, bad), progress=False)
    assert "not finite" in str(fmus.value)
    assert str(local.value) == str(fmus.value)
