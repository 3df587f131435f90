"""SIMO hydrodynamic coupling in closed loop: two bodies side by side (load FMUs with
coupled added mass and retardation memory + the coupled dynamics partner) against a
monolithic scipy solution of the same Cummins equations."""
import numpy as np
import pytest

from hydrofmu.bench import fleet
from hydrofmu.bench.fleet import (CROSS_AM, CROSS_K, INERTIA as I, K, LENGTH, M, SELF_AM, SELF_K,  # noqa: F401
                                  TIMDEL, Fleet, nrms)
from hydrofmu.cosim.master import run

from conftest import build
from simo_decks import coupling_group, write_deck

V0 = {"a": list(fleet.V0), "b": [0.0] * 6}


def scene(tmp_path, method="convolution", mode="export", algorithm="gauss-seidel", step=0.05, extra="",
          hold="linear"):
    tmp_path.mkdir(parents=True, exist_ok=True)
    deck = write_deck(tmp_path / "pair.sim", [
        coupling_group("SELFA", "A", "A", SELF_AM, SELF_K, TIMDEL, LENGTH),
        coupling_group("SELFB", "B", "B", SELF_AM, SELF_K, TIMDEL, LENGTH),
        coupling_group("AB", "A", "B", CROSS_AM, CROSS_K, TIMDEL, LENGTH)])
    text = pair_text(deck, mode, f'method = "{method}"\n        {extra}', velocities=True)
    return build(tmp_path, f"""
        [scene]
        name = "pair"
        [run]
        step = {step}
        stop = 60.0
        algorithm = "{algorithm}"
        load_hold = "{hold}"
        substep = 0.01
        """ + text)


def pair_text(deck, mode, coupling_extra="", velocities=False):
    """Scene text of bodies a (y = 0) and b (y = 40 m) and the couplings SELFA, SELFB, AB."""
    body = lambda n, y: f"""
        [bodies.{n}]
        position = [0.0, {y}, 0.0]
        {f"velocity = {V0[n]}" if velocities else ""}
        mass = {M}
        inertia = {I}
        stiffness = {K.tolist()}
        acceleration_loads = "{mode}"
        """
    couplings = "".join(f"""
        [[couplings]]
        deck = "{deck}"
        coupling = "{c}"
        bodies = {{ A = "a", B = "b" }}
        {coupling_extra}
        """ for c in ("SELFA", "SELFB", "AB"))
    return body("a", 0.0) + body("b", 40.0) + couplings


def monolithic(t_eval):
    """Translations and rotations of both bodies from the monolithic scipy solution of the
    Cummins equations (bench.fleet: assembled by hand, kernels as exact complex states)."""
    return Fleet(2).monolithic(t_eval)


def positions(result):
    """Displacements from the initial positions: surge, sway, heave of a, then of b."""
    pos = np.hstack([result.motion(b, "position", 3) for b in ("a", "b")])
    return pos - pos[0]


def test_two_bodies_match_monolithic_cummins(tmp_path):
    """Recommended mode (export: coupled added mass in the dynamics' mass matrix;
    Gauss–Seidel; convolution) at dt = 0.05 s: < 1 % normalised RMS error."""
    folder = scene(tmp_path)
    result = run(folder, progress=False)
    ref = monolithic(result.time)
    got = positions(result)
    moving = [0, 1, 2, 4, 5]              # a: surge, sway, heave; b: sway, heave (b's surge stays 0)
    err = nrms(got[:, moving], ref[:, [0, 1, 2, 7, 8]])
    assert np.ptp(ref[:, 7]) > 0.05        # body b really moves, through the coupling only
    assert err.max() < 0.01, err


def test_state_space_close_to_convolution(tmp_path):
    conv = positions(run(scene(tmp_path / "c"), progress=False))
    ss = positions(run(scene(tmp_path / "s", method="state_space", extra="tolerance = 0.001"), progress=False))
    assert nrms(ss, conv)[[0, 1, 2, 4, 5]].max() < 0.005


def test_save_restore_with_memory(tmp_path):
    from test_fmu import Fmu
    folder = scene(tmp_path)
    fmu = Fmu(folder / "pair_a.fmu")
    try:
        rng = np.random.default_rng(3)
        def drive(k):
            fmu.set("velocity", rng.normal(size=6) * 0.1)
            fmu.set("b.velocity", rng.normal(size=6) * 0.1)
            fmu.slave.doStep(0.05 * k, 0.05)
        for k in range(50):
            drive(k)
        state = fmu.slave.getFMUstate()
        runs = []
        for _ in range(2):
            fmu.slave.setFMUstate(state)
            rng = np.random.default_rng(11)
            out = []
            for k in range(50, 80):
                drive(k)
                out.append(np.concatenate([fmu.get("AB.force"), fmu.get("SELFA.force"), fmu.get("force")]))
            runs.append(np.array(out))
        fmu.slave.freeFMUstate(state)
    finally:
        fmu.close()
    np.testing.assert_array_equal(runs[0], runs[1])
    assert np.abs(runs[0][:, :6]).max() > 1.0  # the memory is really there


@pytest.mark.parametrize("mode", ["export", "explicit"])
def test_build_reports_stability_indicator(tmp_path, mode):
    """ρ[(M_A+A_AA)⁻¹·A_AB·(M_B+A_BB)⁻¹·A_BA] by hand for diagonal blocks: the largest
    A_AB,ii² / ((M+A_AA,ii)(M+A_BB,ii)); a warning only when explicit coupling diverges."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    big = np.diag([0, 3.0e6, 0, 0, 0, 0])          # cross sway added mass larger than M + A_self
    deck = write_deck(tmp_path / "big.sim", [
        coupling_group("SELFA", "A", "A", SELF_AM, {}, TIMDEL, LENGTH),
        coupling_group("SELFB", "B", "B", SELF_AM, {}, TIMDEL, LENGTH),
        coupling_group("AB", "A", "B", big, {}, TIMDEL, LENGTH)])
    from conftest import write_scene
    path = write_scene(tmp_path, "[scene]\nname = 'unstable'\n" + pair_text(deck, mode))
    messages = []
    folder = build_scene(load_scene(path), tmp_path / "out", log=messages.append)
    import json
    rho = json.loads((folder / "manifest.json").read_text())["stability_indicators"]["AB"]
    expected = 3.0e6 ** 2 / ((M + 5.0e5) * (M + 5.0e5))     # sway: M + A_self = 1.5e6
    assert rho == pytest.approx(expected, rel=1e-12)
    warned = any("WARNING" in m and "AB" in m for m in messages)
    assert warned == (mode == "explicit")
