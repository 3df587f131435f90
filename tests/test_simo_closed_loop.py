"""SIMO hydrodynamic coupling in closed loop: two bodies side by side (load FMUs with
coupled added mass and retardation memory + the coupled dynamics partner) against a
monolithic scipy solution of the same Cummins equations."""
import numpy as np
import pytest
from scipy.integrate import solve_ivp

from hydrofmu.cosim.master import run

from conftest import build
from simo_decks import coupling_group, write_deck

M, I = 1.0e6, [1.0e8, 2.0e8, 2.0e8]
# 1000 t body, 20 m x 20 m waterplane: heave K = ρ·g·A_wp ≈ 4e6 N/m (heave period ≈ 4 s)
K = np.array([1.0e5, 1.2e5, 4.0e6, 1.0e9, 1.0e9, 1.0e9])
SELF_AM = np.diag([1.0e5, 5.0e5, 8.0e5, 0, 0, 0])
CROSS_AM = np.zeros((6, 6))
CROSS_AM[1, 1], CROSS_AM[2, 2], CROSS_AM[1, 2] = 2.0e5, 1.0e5, 5.0e4
SELF_K = {(1, 1): (1.0e5, 0.6, 1.0), (2, 2): (3.0e5, 0.5, 1.2), (3, 3): (6.0e5, 0.8, 1.5)}
CROSS_K = {(2, 2): (1.0e5, 0.5, 0.8), (3, 3): (1.5e5, 0.7, 1.1), (2, 3): (4.0e4, 0.6, 0.9)}
V0 = {"a": [0.1, 0.5, 0.2, 0, 0, 0], "b": [0.0] * 6}
TIMDEL, LENGTH = 0.1, 40.0


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
    """Cummins equations of both bodies (12 dofs), translations only (rotations stay at
    rest), kernels c·e^(−at)·cos(ωt) as exact complex first-order states:
    (M + A∞)·ẍ + Σ ∫ h(t−τ)·ẋ(τ)dτ + K·x = 0."""
    n = 12
    mass = np.diag(np.tile([M, M, M] + I, 2))
    mass[:6, :6] += SELF_AM
    mass[6:, 6:] += SELF_AM
    mass[:6, 6:] += CROSS_AM          # load on A from B's acceleration: A∞
    mass[6:, :6] += CROSS_AM.T        # load on B from A's acceleration: A∞ᵀ
    stiff = np.diag(np.tile(K, 2))
    # memory terms: (row dof, column dof, c, a, ω): load on row from velocity of column
    terms = []
    for (i, j), (c, a, w) in SELF_K.items():
        terms += [(i - 1, j - 1, c, a, w), (6 + i - 1, 6 + j - 1, c, a, w)]
    for (i, j), (c, a, w) in CROSS_K.items():
        terms += [(i - 1, 6 + j - 1, c, a, w), (6 + j - 1, i - 1, c, a, w)]
    inv = np.linalg.inv(mass)

    def rhs(_, y):
        x, v, z = y[:n], y[n:2 * n], y[2 * n:].view(complex) if False else y[2 * n:]
        force = -stiff @ x
        dz = np.empty_like(z)
        for k, (r, col, c, a, w) in enumerate(terms):
            zr, zi = z[2 * k], z[2 * k + 1]
            force[r] -= c * zr                     # Re(c·z), z' = (−a + iω)·z + v
            dz[2 * k] = -a * zr - w * zi + v[col]
            dz[2 * k + 1] = w * zr - a * zi
        return np.concatenate([v, inv @ force, dz])

    y0 = np.concatenate([np.zeros(n), V0["a"], V0["b"], np.zeros(2 * len(terms))])
    sol = solve_ivp(rhs, (0, t_eval[-1]), y0, t_eval=t_eval, rtol=1e-10, atol=1e-12, method="DOP853")
    return sol.y[:n].T


def positions(result):
    """Displacements from the initial positions: surge, sway, heave of a, then of b."""
    pos = np.hstack([result.motion(b, "position", 3) for b in ("a", "b")])
    return pos - pos[0]


def nrms(got, ref):
    return np.sqrt(np.mean((got - ref) ** 2, axis=0)) / np.ptp(ref, axis=0)


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
