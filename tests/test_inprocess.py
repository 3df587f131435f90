"""The in-process system (cosim.inprocess, used by the stability studies) against the built
FMUs of the same scene through fmpy: the same master, so the same numbers."""
import numpy as np
import pytest

from hydrofmu.cosim import inprocess
from hydrofmu.cosim.master import RunError, load, run
from hydrofmu.scene import load_scene

from conftest import build, write_scene
from simo_decks import pair_deck

M = 1.0e6


def scene_text(deck):
    """Body a (explicit, drag in a current, a soft ball joint with a massive node to the earth)
    and body b (export), coupled by SIMO self and cross added mass and memory."""
    body = lambda n, y, mode: f"""
        [bodies.{n}]
        position = [0.0, {y}, 0.0]
        velocity = [0.3, -0.2, 0.1, 0.0, 0.0, 0.01]
        mass = {M}
        inertia = [1e8, 1e8, 1e8]
        stiffness = [1e5, 1e5, 1e6, 1e8, 1e8, 1e8]
        acceleration_loads = "{mode}"
        """
    return """
        [environment]
        current_speed = 1.5
        current_direction = 30.0
        [run]
        step = 0.05
        stop = 4.0
        substep = 0.01
        """ + body("a", 0.0, "explicit") + """
        [[bodies.a.effects]]
        type = "aqwa_viscous_drag"
        matrix = [2e4, 3e4, 1e4, 0.0, 0.0, 1e6]
        option = "RELATIVE"
        """ + body("b", 40.0, "export") + """
        [joints.pin]
        a = "a"
        a_point = [10.0, 0.0, -2.0]
        stiffness = 2.0e5
        damping = 2.0e5
        am = 2.0e4
        cd = [1e3, 1e3, 1e3]
        added_mass = [1e4, 1e4, 1e4]
        acceleration_loads = "explicit"
        """ + "".join(f"""
        [[couplings]]
        deck = "{deck}"
        coupling = "{c}"
        method = "{method}"
        """ for c, method in (("SA", "convolution"), ("SB", "state_space"), ("AB", "convolution")))


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
