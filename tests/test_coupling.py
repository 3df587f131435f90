"""Hydrodynamic coupling loads: element rule of the manual, the README's formula (SIMO
hydrodynamic coupling), transpose rule, self-coupling, and the explicit-coupling stability
indicator."""
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.decks.simo import CouplingData, read_couplings
from hydrofmu.physics.coupling import Coupling, stability_indicator

METHODS = ["convolution", "state_space"]


def random_data(rng, timdel=0.2, n=30, blocks=((1, 1), (1, 5), (2, 6), (3, 3), (5, 1), (4, 2))):
    t = timdel * np.arange(n)
    kernels = {(i, j): rng.normal() * np.exp(-rng.uniform(0.8, 1.5) * t) * np.cos(rng.uniform(0.3, 1.2) * t)
               for i, j in blocks}
    return CouplingData("c", ("", ""), "b1", "b2", rng.normal(size=(6, 6)) * 1e5, timdel, kernels)


def swapped(data):
    """The same coupling written with A and B exchanged: AM transposed, kernel indices swapped."""
    return CouplingData(data.name, data.text, data.body_b, data.body_a, data.added_mass.T.copy(),
                        data.timdel, {(j, i): h for (i, j), h in data.kernels.items()})


def step(c, dt, v_a, v_b):
    """(load on A, load on B) after both sides of a coupling advance by dt."""
    return c.memory["A"].advance(dt, v_b), c.memory["B"].advance(dt, v_a)


def trapezoid(h, timdel):
    """∫ of a kernel linear between samples and zero after the last."""
    return timdel * (np.sum(h) - 0.5 * (h[0] + h[-1]))


def test_added_mass_element_rule():
    am = np.zeros((6, 6))
    am[1, 4] = 3.0e5                                           # AM25: dof 2 of A with dof 5 of B
    c = Coupling.from_deck(CouplingData("c", ("", ""), "a", "b", am, None, {}))
    # acceleration of A in dof 2 → force on B in dof 5; acceleration of B in dof 5 → force on A in dof 2
    a_a, a_b = np.eye(6)[1] * 2.0, np.eye(6)[4] * 0.5
    np.testing.assert_array_equal(c.acceleration_load("B", a_a), -3.0e5 * 2.0 * np.eye(6)[4])
    np.testing.assert_array_equal(c.acceleration_load("A", a_b), -3.0e5 * 0.5 * np.eye(6)[1])
    assert not c.acceleration_load("A", a_a).any() and not c.acceleration_load("B", a_b).any()
    assert c.mass("A")[1, 4] == 3.0e5 and c.mass("B")[4, 1] == 3.0e5
    assert (c.source("A"), c.target("A"), c.source("B"), c.target("B")) == ("b", "a", "a", "b")


@pytest.mark.parametrize("method", METHODS)
def test_kernel_element_rule_steady_velocity(method):
    timdel = 0.1
    h = 4.0e4 * np.exp(-2.0 * timdel * np.arange(50))             # decays to 2e-5 of h(0)
    c = Coupling.from_deck(CouplingData("c", ("", ""), "a", "b", np.zeros((6, 6)), timdel, {(3, 6): h}),
                 method=method, tol=1e-4, v0_a=np.eye(6)[2] * 1.5, v0_b=np.eye(6)[5] * -0.4)
    assert c.method == method   # (a tolerance below the fit's floor, 5.5e-5, falls back to convolution)
    for _ in range(24):                                         # constant velocities, 12 s ≫ kernel
        f_b = c.memory["B"].advance(0.5, np.eye(6)[2] * 1.5)  # A's heave drives B's yaw
        f_a = c.memory["A"].advance(0.5, np.eye(6)[5] * -0.4)  # B's yaw drives A's heave
    # convolution: the piecewise-linear kernel's area; state space: ∫ 4e4·e^(−2t) dt = 2e4
    # (the fit sees the zero tail after the kernel's end, h(4.9)/h(0) = 5.5e-5: its floor)
    area = trapezoid(h, timdel) if method == "convolution" else 2.0e4
    rtol = 1e-9 if method == "convolution" else 1e-4
    np.testing.assert_allclose(f_b, -area * 1.5 * np.eye(6)[5], rtol=rtol, atol=rtol * area)
    np.testing.assert_allclose(f_a, area * 0.4 * np.eye(6)[2], rtol=rtol, atol=rtol * area)


def test_short_kernel_area_by_hand():
    h = [4.0e4, 3.0e4, 1.0e4, 0.0]                              # TIMDEL 0.5 s: area by hand
    c = Coupling.from_deck(CouplingData("c", ("", ""), "a", "b", np.zeros((6, 6)), 0.5, {(1, 2): h}), v0_b=np.eye(6)[1])
    for _ in range(4):
        f_a = c.memory["A"].advance(0.5, np.eye(6)[1])
    assert f_a[0] == pytest.approx(-0.5 * (4.0e4 / 2 + 3.0e4 + 1.0e4 + 0.0 / 2), rel=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_design_formula_full_matrices(method):
    rng = np.random.default_rng(7)
    data = random_data(rng)
    v_a, v_b = rng.normal(size=6), rng.normal(size=6)
    a_a, a_b = rng.normal(size=6), rng.normal(size=6)
    c = Coupling.from_deck(data, method=method, tol=1e-3, v0_a=v_a, v0_b=v_b)
    assert c.method == method   # (the fits reach 7.8e-4; below it: convolution)
    for _ in range(40):                                        # 8 s > kernel length (5.8 s)
        f_a = c.memory["A"].advance(0.2, v_b)
        f_b = c.memory["B"].advance(0.2, v_a)
    # element by element, the manual's wording, written out
    exp_a, exp_b = np.zeros(6), np.zeros(6)
    for (i, j), h in data.kernels.items():
        exp_a[i - 1] -= trapezoid(h, data.timdel) * v_b[j - 1]   # B's velocity in j → A in i
        exp_b[j - 1] -= trapezoid(h, data.timdel) * v_a[i - 1]   # A's velocity in i → B in j
    for i in range(6):
        for j in range(6):
            exp_a[i] -= data.added_mass[i, j] * a_b[j]
            exp_b[j] -= data.added_mass[i, j] * a_a[i]
    scale = np.abs(exp_a).max()
    tol = 1e-10 if method == "convolution" else 1e-3
    np.testing.assert_allclose(f_a + c.acceleration_load("A", a_b), exp_a, atol=tol * scale)
    np.testing.assert_allclose(f_b + c.acceleration_load("B", a_a), exp_b, atol=tol * scale)
    # the README's matrix form
    np.testing.assert_allclose(c.acceleration_load("B", a_a), -data.added_mass.T @ a_a, rtol=1e-12)


@pytest.mark.parametrize("method", METHODS)
def test_transpose_rule_swapping_bodies_gives_same_loads(method):
    rng = np.random.default_rng(8)
    data = random_data(rng)
    c1, c2 = Coupling.from_deck(data, method=method), Coupling.from_deck(swapped(data), method=method)
    assert (c2.body_a, c2.body_b) == ("b2", "b1")
    np.testing.assert_array_equal(c1.mass("A"), c2.mass("B"))      # both: on b1 from b2
    np.testing.assert_array_equal(c1.mass("B"), c2.mass("A"))
    for dt in rng.uniform(0.05, 0.4, size=60):
        v1, v2 = rng.normal(size=6), rng.normal(size=6)
        on_b1 = c1.memory["A"].advance(dt, v2), c2.memory["B"].advance(dt, v2)
        on_b2 = c1.memory["B"].advance(dt, v1), c2.memory["A"].advance(dt, v1)
        np.testing.assert_allclose(*on_b1, rtol=1e-12, atol=1e-9)
        np.testing.assert_allclose(*on_b2, rtol=1e-12, atol=1e-9)
    if method == "state_space":
        assert c1.fits and all(f.error <= 0.01 for f in c1.fits.values())


@pytest.mark.parametrize("method", METHODS)
def test_self_coupling(method):
    rng = np.random.default_rng(9)
    m = rng.normal(size=(6, 6))
    am = (m + m.T) * 1e5
    t = 0.2 * np.arange(40)                                                  # decays within 8 s
    data = CouplingData("own", ("", ""), "b", "b", am, 0.2,
                        {(3, 3): np.exp(-1.5 * t), (5, 3): 0.3 * np.exp(-t) * np.cos(2.0 * t)})
    c = Coupling.from_deck(data, method=method, tol=1e-3)
    assert c.self_coupling and c.sides == ("A",) and c.source("A") == c.target("A") == "b"
    a = rng.normal(size=6)
    np.testing.assert_allclose(c.acceleration_load("A", a), -am @ a)          # applied once
    with pytest.raises(ValueError):
        c.mass("B")
    v = np.eye(6)[2]                                                          # own heave velocity
    c = Coupling.from_deck(data, method=method, tol=1e-3, v0_a=v)
    assert c.method == method   # (the fits reach 1.3e-4; below it: convolution)
    for _ in range(50):
        f = c.memory["A"].advance(0.2, v)
    expected = np.zeros(6)
    expected[2] = -trapezoid(data.kernels[(3, 3)], 0.2)                       # F_i = −∫h_ij·v_j
    expected[4] = -trapezoid(data.kernels[(5, 3)], 0.2)
    # state space: realisation of the exponentials, vs the trapezoid of their samples (O(Δ²))
    np.testing.assert_allclose(f, expected, atol=5e-3 if method == "state_space" else 1e-12)


def test_state_round_trip_and_methods_agree():
    rng = np.random.default_rng(10)
    data = random_data(rng, timdel=0.1, n=200)
    conv, ss = Coupling.from_deck(data), Coupling.from_deck(data, method="state_space", tol=1e-3)
    steps, vels = rng.uniform(0.05, 0.2, size=150), rng.normal(size=(150, 2, 6))
    out = []
    for k, (dt, (v1, v2)) in enumerate(zip(steps, vels)):
        if k == 75:
            saved = conv.state(), ss.state()
        out.append(step(conv, dt, v1, v2) + step(ss, dt, v1, v2))
    out = np.array(out)
    rms = np.sqrt(np.mean(out[:, :2] ** 2))
    assert np.sqrt(np.mean((out[:, 2:] - out[:, :2]) ** 2)) < 0.01 * rms
    conv.set_state(saved[0])
    ss.set_state(saved[1])
    again = [step(conv, dt, v1, v2) + step(ss, dt, v1, v2) for dt, (v1, v2) in zip(steps[75:], vels[75:])]
    np.testing.assert_array_equal(np.array(again), out[75:])


def test_deck_to_coupling():
    data = read_couplings(Path(__file__).parent / "data" / "simo" / "two_barges.sys", bodies=["barge1"])
    v_a = np.eye(6)[0]                                       # barge1 surges at 1 m/s from the start
    c = Coupling.from_deck(data["cpl12"], v0_a=v_a)
    for _ in range(10):
        f_b = c.memory["B"].advance(0.5, v_a)
    # block (1, 1): 1e4, 8e3, 5e3, 2e3, 5e2 at 0.5 s → surge of barge1 into surge of barge2
    assert f_b[0] == pytest.approx(-0.5 * (1e4 / 2 + 8e3 + 5e3 + 2e3 + 5e2 / 2))
    assert not np.delete(f_b, 0).any()
    own = Coupling.from_deck(data["cpl22"])
    assert own.self_coupling and own.target("A") == "barge2"
    with pytest.raises(ValueError):
        Coupling.from_deck(data["cpl12"], method="fft")


def test_stability_indicator_scalar_and_staggered_iteration():
    # scalar: ρ = A_AB·A_BA / ((M_A + A_AA)(M_B + A_BB)), by hand
    assert stability_indicator(2.0, 1.0, 2.0, 4.0, 2.0, 3.0) == pytest.approx(2.0 * 3.0 / (3.0 * 6.0))
    rng = np.random.default_rng(11)
    m_a, m_b = np.diag(rng.uniform(1, 2, 6)), np.diag(rng.uniform(1, 2, 6))
    a_aa, a_bb = 0.5 * np.eye(6), 0.4 * np.eye(6)
    a0 = rng.normal(size=(6, 6))
    rho0 = stability_indicator(m_a, a_aa, a0, m_b, a_bb, a0.T)
    for target in (0.7, 1.4):
        a_ab = a0 * np.sqrt(target / rho0)                      # ρ scales with A_AB·A_BA
        rho = stability_indicator(m_a, a_aa, a_ab, m_b, a_bb, a_ab.T)
        assert rho == pytest.approx(target)
        # explicit staggered exchange: each body sees the other's acceleration one step late
        x_a, x_b = rng.normal(size=6), rng.normal(size=6)
        log_norm = []
        for _ in range(400):
            x_a, x_b = (np.linalg.solve(m_a + a_aa, -a_ab @ x_b),
                        np.linalg.solve(m_b + a_bb, -a_ab.T @ x_a))
            n = np.linalg.norm(x_a) + np.linalg.norm(x_b)
            x_a, x_b = x_a / n, x_b / n
            log_norm.append(np.log(n))
        growth = np.exp(np.mean(log_norm[200:]))                 # mean factor per step = √ρ
        assert growth == pytest.approx(np.sqrt(rho), rel=0.02)
        assert (growth > 1) == (rho > 1)
