"""The linear range said out loud: the dynamics partner (Python and compiled flavours) warns once
when |roll| or |pitch| passes rigid_body.LINEAR_RANGE (15°) and fails the step as capsized past
CAPSIZE (90°).  The body: the wave-test cylinder with BEM hydrostatics held constant over 0.1 s
steps and no other damping, whose pitch grows as e^{σt}, σ = ω²·h/4 (physics.hold, test_hold):
the times it passes 15° and 90° are computed here from that growth."""
import math

import numpy as np
import pytest

from hydrofmu.bench.hold import _run, cylinder_scene
from hydrofmu.cosim.master import RunError
from hydrofmu.physics.rigid_body import CAPSIZE, LINEAR_RANGE
from test_hold import pitch_frequency

RATE = 0.03   # initial pitch rate [rad/s]


def crossing(angle, step=0.1):
    """When the growing pitch oscillation's amplitude reaches ``angle`` [rad] (linear growth
    from the initial amplitude RATE/ω, then e^{σt})."""
    w = pitch_frequency()
    return math.log(angle / (RATE / w)) / (w * w * step / 4)


def test_python_flavour_warns_once_then_fails_as_capsized(tmp_path, capsys):
    path = cylinder_scene(tmp_path, "constant", 0.1, 100.0, memory=False, velocity=RATE)
    with pytest.raises(RunError) as caught:
        _run(path, None, ["cyl_dynamics.attitude[2]"])
    text = str(caught.value)
    # past 90° at a step's end, or at the Euler angles' singularity inside it: capsized either way
    assert "capsized: " in text and "pitch" in text and "GimbalLockError" not in text, text
    t = float(text.split("failed at t = ")[1].split(" s")[0])
    assert t == pytest.approx(crossing(CAPSIZE), abs=6.0)   # within about 1.5 periods of the growth's estimate
    err = capsys.readouterr().err
    assert err.count("left the linear range") == 1, err
    t15 = float(err.split("left the linear range: ")[1].split("at t = ")[1].split(" s")[0])
    assert t15 == pytest.approx(crossing(LINEAR_RANGE), abs=6.0)


def test_compiled_flavour_says_the_same(tmp_path, capfd):
    import warnings
    from hydrofmu.cosim.master import run
    from hydrofmu.errors import InputWarning
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    path = cylinder_scene(tmp_path, "constant", 0.1, 100.0, memory=False, velocity=RATE)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        folder = build_scene(load_scene(path), tmp_path / "fmus", log=lambda *_: None, runtime="c")
    with pytest.raises(RunError) as caught:
        run(folder, record=["cyl_dynamics.attitude[2]"], progress=False)
    text = str(caught.value)
    assert "capsized: " in text and "pitch" in text and "GimbalLock" not in text, text
    assert float(text.split("failed at t = ")[1].split(" s")[0]) == pytest.approx(crossing(CAPSIZE), abs=6.0)
    err = capfd.readouterr().err
    assert err.count("left the linear range: attitude[2] (pitch) = ") == 1, err


def test_a_failed_run_keeps_its_rows_and_names_the_knob(tmp_path):
    """The capsizing run above: the RunError names the constant hold as the likely cause with
    the linear hold as the cure and the damping it takes (ω·h/4 of the dry pitch mode, computed
    here), and carries the rows up to the failure."""
    path = cylinder_scene(tmp_path, "constant", 0.1, 100.0, memory=False, velocity=RATE)
    with pytest.raises(RunError) as caught:
        _run(path, {"run.load_hold": "constant"}, ["cyl_dynamics.attitude[2]"])
    text = str(caught.value)
    assert 'likely cause and the knob that would have held it: [run] load_hold = "linear"' in text, text
    from hydrofmu.scene import load_scene
    w = load_scene(path).run["restoring_omega"]                  # the fastest dry mode of the BEM restoring
    ds = pitch_frequency()
    assert w >= ds * (1 - 1e-9)                                  # an upper bound of the pitch mode's
    assert f"−{100 * w * 0.1 / 4:.2g} % of critical at {w:.3g} rad/s" in text
    partial = caught.value.partial
    t = float(text.split("failed at t = ")[1].split(" s")[0])
    assert partial.time[-1] == pytest.approx(t) and np.abs(partial.values[:, 0]).max() > LINEAR_RANGE
