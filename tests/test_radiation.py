"""physics.radiation: A∞ and K(t) from A(ω), B(ω), against an analytic Cummins pair."""
import numpy as np
import pytest

from hydrofmu.physics.radiation import AsymmetryError, GridError, cubic_transform, hat_transform, transform

# K(t) = e^{−αt}·cos βt − c·e^{−γt}, c = γα/(α² + β²) so that B(0) = ∫K dt = 0
ALPHA, BETA, GAMMA = 0.5, 1.5, 1.0
C = GAMMA * ALPHA / (ALPHA ** 2 + BETA ** 2)
A_INF = 7.0


def kernel(t):
    return np.exp(-ALPHA * t) * np.cos(BETA * t) - C * np.exp(-GAMMA * t)


def damping(w):
    """B(ω) = ∫₀^∞ K(t)·cos ωt dt."""
    lor = lambda x: ALPHA / (ALPHA ** 2 + x ** 2)
    return 0.5 * (lor(w - BETA) + lor(w + BETA)) - C * GAMMA / (GAMMA ** 2 + w ** 2)


def added_mass(w):
    """A(ω) = A∞ − (1/ω)·∫₀^∞ K(t)·sin ωt dt."""
    s = 0.5 * ((w + BETA) / (ALPHA ** 2 + (w + BETA) ** 2) + (w - BETA) / (ALPHA ** 2 + (w - BETA) ** 2)) \
        - C * w / (GAMMA ** 2 + w ** 2)
    return A_INF - s / w


def grid(n=200, top=10.0):
    w = np.linspace(top / n, top, n)
    return w, added_mass(w)[:, None, None], damping(w)[:, None, None]


def test_hat_transform_is_exact_for_piecewise_linear():
    """∫ of a piecewise-linear f times cos/sin, against a fine trapezoid sum of the same f."""
    nodes = np.array([0.0, 0.3, 1.0, 1.7, 4.0])
    f = np.array([0.0, 2.0, -1.0, 0.5, 0.25])
    x = np.array([0.0, 0.7, 3.0, 25.0])
    s = np.linspace(0, 4, 400001)
    fs = np.interp(s, nodes, f)
    for kind, trig in (("cos", np.cos), ("sin", np.sin)):
        ref = [np.trapezoid(fs * trig(xx * s), s) for xx in x]
        np.testing.assert_allclose(hat_transform(nodes, x, kind) @ f, ref, atol=1e-8)


def test_cubic_transform_is_exact_for_a_spline():
    """∫ of a cubic spline times cos(xs), against a fine trapezoid sum of the same spline (x = 0,
    small x where the series replace the closed forms, and large x)."""
    from scipy.interpolate import CubicSpline
    spline = CubicSpline([0.0, 0.3, 1.0, 1.7, 4.0], np.array([[0.0, 2.0, -1.0, 0.5, 0.25],
                                                              [1.0, 0.0, 3.0, -2.0, 0.0]]).T, axis=0)
    x = np.array([0.0, 1e-4, 0.9, 3.0, 25.0, 300.0])
    s = np.linspace(0, 4, 400001)
    fs = spline(s)
    ref = [[np.trapezoid(fs[:, k] * np.cos(xx * s), s) for k in range(2)] for xx in x]
    np.testing.assert_allclose(cubic_transform(spline.x, spline.c, x), ref, atol=1e-8)


def test_kernel_and_extrapolated_a_inf_match_the_analytic_pair():
    """B on 0.05…10 rad/s with its ω⁻² tail: K within 0.5 % of K(0), A∞ (Ogilvie) within
    0.5 %, the tail exponent near 2, and A, B rebuilt within 1 % of their peaks."""
    w, a, b = grid()
    r = transform(w, a, b)
    t = r.timdel * np.arange(r.kernels.shape[-1])
    assert 2.0 <= r.tail_exponent < 2.4        # B ~ 0.3/ω² + O(ω⁻⁴): a bit steeper at 8…10 rad/s
    assert np.abs(r.kernels[0, 0] - kernel(t)).max() < 0.005 * kernel(0.0)
    assert abs(r.a_inf[0, 0] - A_INF) < 0.005 * A_INF
    assert r.a_inf_source == "Ogilvie"
    assert r.err_a[0, 0] < 1.0 and r.err_b[0, 0] < 1.0
    assert abs(r.timdel - np.pi / (12 * 10.0)) < 1e-12       # TIMDEL from the highest frequency
    assert abs(kernel(r.length)) < 0.01 * kernel(0.0)          # the kernel ends where it has decayed


def test_file_a_inf_used_when_asked_and_asked_timdel_and_length_kept():
    """By default A∞ comes from Ogilvie's relation even when the file has it (here within
    0.5 % of the exact value); a_inf_from="file" keeps the file's value as it is."""
    w, a, b = grid()
    r = transform(w, a, b, a_inf=np.array([[A_INF]]), timdel=0.03, length=20.0, a_inf_from="file")
    assert r.a_inf_source == "file" and r.a_inf[0, 0] == A_INF
    assert r.timdel == 0.03 and abs(r.length - 20.0) < 0.03
    r = transform(w, a, b, a_inf=np.array([[A_INF]]))
    assert r.a_inf_source == "Ogilvie" and abs(r.a_inf[0, 0] - A_INF) < 0.005 * A_INF
    assert any("the file's ω = ∞ value differs by" in n for n in r.notes)


def test_short_range_warns_about_the_tail():
    """Stopping at 2 rad/s leaves a large share of ∫|B| to the tail: a warning says so."""
    w, a, b = grid(40, 2.0)
    r = transform(w, a, b)
    assert r.tail_share[0, 0] > 0.05
    assert any("tail" in m for m in r.warnings)


def test_timdel_too_coarse_for_the_grid():
    w, a, b = grid()
    with pytest.raises(GridError, match="TIMDEL = 0.5 s is too coarse") as exc:
        transform(w, a, b, timdel=0.5)
    assert exc.value.field == "timdel"


def test_asymmetry_within_tolerance_is_symmetrised_beyond_is_an_error():
    w = np.linspace(0.1, 5, 50)
    a = np.tile(np.array([[2.0, 0.3], [0.3, 1.0]]), (w.size, 1, 1))
    b = damping(w)[:, None, None] * np.array([[1.0, 0.1], [0.1, 0.5]])
    a_inf = np.array([[2.0, 0.301], [0.299, 1.0]])          # 0.14 % of √(2·1)
    r = transform(w, a, b, a_inf=a_inf, a_inf_from="file")
    assert r.a_inf[0, 1] == r.a_inf[1, 0] == pytest.approx(0.3)
    assert r.asymmetry == pytest.approx(0.002 / np.sqrt(2))
    with pytest.raises(AsymmetryError, match="asymmetry"):
        transform(w, a, b, a_inf=np.array([[2.0, 0.35], [0.25, 1.0]]))


def test_multi_dof_result_rebuilt_within_one_percent():
    """Three analytic modes mixed over 6 dofs (the bench's synthetic result): every pair's A
    and B rebuilt within 1 % of its peak, with A∞ from Ogilvie's relation (within 0.1 % of
    the exact one) and with the file's A∞ kept."""
    from hydrofmu.bench.radiation_cost import synthetic
    w, a, b, a_inf = synthetic(6, 200, top=8.0)
    r = transform(w, a, b, a_inf)
    assert r.active.all()
    assert r.err_a.max() < 1.0 and r.err_b.max() < 1.0
    scale = np.sqrt(np.outer(np.diag(a_inf), np.diag(a_inf)))
    assert np.abs(r.a_inf - a_inf).max() < 1e-3 * scale.min()
    r = transform(w, a, b, a_inf, a_inf_from="file")
    assert r.err_a.max() < 1.0 and r.err_b.max() < 1.0
    np.testing.assert_array_equal(r.a_inf, a_inf)


def test_a_feature_between_grid_points_does_not_move_a_inf():
    """A sharp feature the grid cannot carry (the analytic pair's A(ω) off by 30 % of A∞ at two
    neighbouring frequencies, as next to an unresolved gap resonance): A∞ (the median of
    Ogilvie's per-frequency values) stays within 0.5 % of the exact one and the rebuilt A(ω)
    within 1 % of its peak at every other frequency, and the report names where it strays.
    The midrange of before moved A∞ by half the miss (7.5 % here) at every frequency."""
    w, a, b = grid()
    a = a.copy()
    a[[80, 81]] += 0.3 * A_INF
    r = transform(w, a, b)
    assert abs(r.a_inf[0, 0] - A_INF) < 0.005 * A_INF
    others = np.ones(w.size, bool)
    others[[80, 81]] = False
    assert np.abs(r.a_fit[others, 0, 0] - added_mass(w[others])).max() < 0.01 * np.abs(added_mass(w)).max()
    note = [n for n in r.notes if "stray" in n]
    assert note and f"{w[80]:g}…{w[81]:g}" in note[0], r.notes
    est = a[:, 0, 0] - (r.a_fit[:, 0, 0] - r.a_inf[0, 0])        # Ogilvie's value at each frequency
    assert abs(0.5 * (est.max() + est.min()) - A_INF) > 0.05 * A_INF


def test_tail_warning_names_the_pairs_that_matter_once():
    """Two bodies' dofs with B cut at 2 rad/s (the tail carries > 5 % of each one's ∫|B|dω) and
    a cross pair of numerical noise (B_ab 1e-4 of the diagonals, the same shape, so the same
    share of its own ∫|B_ab|): one warning naming the two diagonals, not the noise pair (a
    pair's tail is judged against √(∫|B_ii|dω·∫|B_jj|dω)), saying what to do."""
    w, a, b = grid(40, 2.0)
    m = np.array([[1.0, 1e-4], [1e-4, 0.5]])
    r = transform(w, a * m, b * m, labels=["a", "b"], groups=[0, 1])
    tails = [t for t in r.warnings if "tail" in t]
    assert len(tails) == 1, r.warnings
    assert "for 2 dof pair(s)" in tails[0] and "(a, a)" in tails[0] and "(b, b)" in tails[0], tails
    assert "(a, b)" not in tails[0] and "higher frequencies" in tails[0]
    assert r.active[0, 1] and r.tail_share[0, 1] < 1e-3 < 0.05 < r.tail_share[0, 0]


def test_the_command_line_says_each_warning_once(monkeypatch, capsys):
    """`tune` and `batch` read the scene again per case: the command line prints each distinct
    warning once per command (here the same InputWarning raised three times, another once)."""
    import warnings
    from hydrofmu import cli
    from hydrofmu.errors import InputWarning

    def noisy(argv):
        for text in ("the tail beyond …", "the tail beyond …", "another", "the tail beyond …"):
            warnings.warn(InputWarning("scene.toml", None, "couplings[1].bem", text))
        return 0
    monkeypatch.setattr(cli, "_main", noisy)
    assert cli.main(["build"]) == 0
    err = capsys.readouterr().err
    assert err.count("the tail beyond") == 1 and err.count("another") == 1, err
    assert cli.main(["build"]) == 0 and capsys.readouterr().err.count("the tail beyond") == 1   # per command
