"""The load hold's damping change on a mode whose restoring is a load input (physics.hold):
the growth rate of a free pitch oscillation of the wave-test cylinder, BEM hydrostatics as a
load FMU and no other damping, against the half-step-lag estimate computed here from the
dataset's mass and stiffness (σ = ω²·h/4 constant hold, ω·(ω·h)³/6 linear hold)."""
import math

import numpy as np
import pytest
import xarray as xr

from hydrofmu.bench.hold import DATA, _run, cylinder_scene, growth
from hydrofmu.physics.hold import damping_change, held_gain, natural_frequencies, stable_step


def pitch_frequency():
    """ω of the pitch mode of the dry cylinder (no added mass: no memory in these runs),
    from the Capytaine file's inertia and hydrostatic stiffness."""
    ds = xr.load_dataset(DATA / "wave_cylinder.nc")
    m, c = ds["inertia_matrix"].values, ds["hydrostatic_stiffness"].values
    w2, modes = np.linalg.eig(np.linalg.solve(m, c))
    k = max((i for i in range(6) if w2[i].real > 1e-6), key=lambda i: abs(modes[4, i]))
    return math.sqrt(w2[k].real)


@pytest.mark.parametrize("hold, step", [("constant", 0.05), ("constant", 0.1), ("linear", 0.15), ("linear", 0.2)])
def test_free_pitch_grows_as_the_half_step_lag_predicts(tmp_path, hold, step):
    w = pitch_frequency()
    path = cylinder_scene(tmp_path, hold, step, 30.0, memory=False)
    r = _run(path, {"run.load_hold": hold}, ["cyl_dynamics.attitude[2]"])
    sigma, measured_w = growth(r.time, r.values[:, 0])
    a = w * step
    expected = w * a / 4 if hold == "constant" else w * a ** 3 / 6     # σ = −ζ·ω, ζ = Δζ of the hold
    # the hold's in-phase part changes the stiffness: ω·√Re g (linear hold 1 + 5a²/12)
    assert measured_w == pytest.approx(w * math.sqrt(held_gain(a, hold).real), rel=0.01)
    assert sigma == pytest.approx(expected, rel=0.1), (sigma, expected)
    assert sigma == pytest.approx(-w * float(damping_change(w, step, hold)), rel=0.1)


def test_linear_hold_of_a_small_step_leaves_the_mode_alone(tmp_path):
    w = pitch_frequency()
    path = cylinder_scene(tmp_path, "linear", 0.05, 30.0, memory=False)
    r = _run(path, None, ["cyl_dynamics.attitude[2]"])
    sigma, _ = growth(r.time, r.values[:, 0])
    assert abs(sigma) < 0.02 * w * w * 0.05 / 4   # under 2 % of the constant hold's growth at that step


def test_held_gain_series_and_stable_step():
    for a in (0.02, 0.1):
        assert held_gain(a, "constant") == pytest.approx(1 - 0.5j * a - a * a / 6, abs=a ** 3)
        assert held_gain(a, "linear") == pytest.approx(1 + 5 * a * a / 12 - 1j * a ** 3 / 3, abs=a ** 4)
        # the damping change is the phase of the gain over 2 (τ = −arg g / ω, Δζ = −ω·τ/2)
        for hold in ("constant", "linear"):
            assert np.angle(held_gain(a, hold)) / 2 == pytest.approx(float(damping_change(1.0, a, hold)), rel=0.05)
    assert natural_frequencies(np.diag([2.0] * 6), np.diag([8.0, 0, 0, 0, 0, 0])) == pytest.approx([2.0])
    assert stable_step(1.75, 1800.0) == 0.1                     # (0.175)³/6 = 0.09 % ≤ 0.1 %
    assert stable_step(4.0, 1800.0) == 0.02                     # 0.4³/6 = 1.1 % > 0.1 % at 0.1 s, 0.05 s: 0.13 %
    assert stable_step(1.75, 0.25) == 0.05                      # 0.1 s does not divide the stop
