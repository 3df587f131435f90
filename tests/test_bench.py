"""Benchmark building blocks against independent answers: the realistic kernels against
their analytic cosine transform, the evaluator trade-off's bookkeeping, the Pareto front,
and the side-by-side timer."""
import math

import numpy as np
import pytest

from hydrofmu.bench import memory_cost
from hydrofmu.bench.cosim_cost import pareto
from hydrofmu.bench.kernels import damping_kernel, irregular_velocity
from hydrofmu.bench.timing import per_call


def test_own_damping_kernel_is_its_cosine_transform():
    """B(ω) = b·x²·e^(1 − x²), x = ω/ωp: (2/π)∫B·cos ωt dω = (2/π)·b·e·ωp·(√π/8)·(2 − k²)·e^(−k²/4),
    k = ωp·t (from ∫₀^∞ x²·e^(−x²)·cos(kx) dx = (√π/8)(2 − k²)·e^(−k²/4))."""
    b, wp = 3.0e5, 0.8
    t = np.linspace(0.0, 30.0, 301)
    k = wp * t
    exact = 2 / math.pi * b * math.e * wp * math.sqrt(math.pi) / 8 * (2 - k ** 2) * np.exp(-k ** 2 / 4)
    np.testing.assert_allclose(damping_kernel(t, b, wp), exact, atol=1e-6 * np.abs(exact).max())


def test_interaction_kernel_arrives_after_the_group_travel_time():
    """cos(k·d) with k = ω²/g: stationary phase puts the echo of frequency ω at t = 2ωd/g;
    with the damping peak near ωp the kernel's envelope peaks near 2·ωp·d/g, not at 0."""
    wp, d = 1.0, 100.0
    t = np.linspace(0.0, 60.0, 1201)
    h = damping_kernel(t, 1.0, wp, distance=d)
    t_peak = t[np.argmax(np.abs(h))]
    assert 0.6 * 2 * wp * d / 9.81 < t_peak < 1.6 * 2 * wp * d / 9.81


def test_irregular_velocity_has_the_requested_sea_state():
    """Hs = 4·√m0 of the wave elevation whose velocity this is: the linear velocity of each
    harmonic is ω·a, so its variance is Σ (ω·a)²/2 — recompute it from the samples."""
    t = np.arange(0.0, 3600.0, 0.25)
    v = irregular_velocity(t, hs=3.0, tp=10.0)
    assert v.shape == (t.size, 6)
    assert np.std(v[:, 0]) == pytest.approx(np.std(v[:, 1]), rel=0.2)   # same spectrum, other phases
    assert 0.5 * 0.75 < np.std(v[:, 0]) < 1.2 * 0.75   # ω between 0.5 and 1.2 rad/s times σ_η = Hs/4
    assert np.std(v[:, 3]) == pytest.approx(0.02 * np.std(v[:, 0]), rel=0.2)


def test_tradeoff_bookkeeping():
    rows = {r["evaluator"]: r for r in memory_cost.tradeoff(lags=600, duration=40.0, lengths=(2.0, 10.0),
                                                           tolerances=(0.05, 0.005), orders=(), calls=50, rounds=1)}
    full = rows["convolution full"]
    assert full["error"] == 0.0 and full["cheaper"] == 1.0
    # truncation: longer memory, smaller error (the kernel decays within ~20 s)
    assert rows["convolution 2 s"]["error"] > rows["convolution 10 s"]["error"]
    assert rows["convolution 10 s"]["states"] < full["states"]
    # state-space force error follows the kernel fit tolerance (same order of magnitude)
    assert rows["state_space tol 0.005"]["error"] < rows["state_space tol 0.05"]["error"] < 0.1
    assert rows["state_space tol 0.005"]["error"] < 0.02


def test_error_is_worst_component_nrms():
    ref = np.array([[1.0, 0.0, 2.0], [-1.0, 0.0, -2.0]])
    got = ref + [[0.1, 5.0, 0.0], [0.1, 5.0, 0.0]]
    assert memory_cost.error(got, ref) == pytest.approx(0.1)   # zero column skipped


def test_pareto_front():
    rows = pareto([{"wall_s": 1, "error": 0.1}, {"wall_s": 2, "error": 0.01}, {"wall_s": 3, "error": 0.05},
                   {"wall_s": 0.5, "error": 0.2}])
    assert [r["pareto"] for r in rows] == [True, True, False, True]
    # equal cost, more error: dominated (the quick ECCO part marked Jacobi at 100 steps and 0.49 %
    # Pareto beside Gauss–Seidel at 100 steps and 0.25 %); equal rows dominate neither
    rows = pareto([{"steps": 100, "error": 0.00493}, {"steps": 100, "error": 0.00246}, {"steps": 880, "error": 5e-5},
                   {"steps": 880, "error": 5e-5}], cost="steps")
    assert [r["pareto"] for r in rows] == [False, True, True, True]


def test_per_call_interleaves_and_restarts():
    calls = []
    res = per_call({"a": lambda: (lambda k: calls.append(("a", k))),
                    "b": lambda: (lambda k: calls.append(("b", k)))}, calls=2, rounds=2)
    assert calls == [("a", 0), ("a", 1), ("b", 0), ("b", 1)] * 2
    assert set(res) == {"a", "b"} and all(v >= 0 for v in res.values())


def floor_steps(fmu, u):
    """Outputs of a floor FMU before and after one step with inputs ``u``."""
    from fmpy import extract, read_model_description
    from fmpy.fmi2 import FMU2Slave

    md = read_model_description(str(fmu))
    vr = {v.name: v.valueReference for v in md.modelVariables}
    ys = [vr[n] for n in sorted(vr) if n.startswith("y[")]
    slave = FMU2Slave(guid=md.guid, unzipDirectory=extract(str(fmu)),
                      modelIdentifier=md.coSimulation.modelIdentifier, instanceName="f")
    slave.instantiate()
    try:
        slave.setupExperiment(startTime=0.0)
        slave.enterInitializationMode()
        slave.exitInitializationMode()
        slave.setReal([vr[f"u[{i + 1}]"] for i in range(len(u))], u)
        before = slave.getReal(ys)
        slave.doStep(0.0, 0.05)
        return sorted(vr), before, slave.getReal(ys)
    finally:
        slave.terminate()
        slave.freeInstance()


def test_floor_fmu_copies_its_inputs(tmp_path):
    """The floor FMU built on the fly does what it claims: after a step y = u; the floor
    system chains n of them in a ring (y of f_k feeds u of f_k+1) that the master runs.
    Other sizes (bench.overhead's floor under a load FMU's calls): y_i = u_(i mod n_in)."""
    from hydrofmu.bench import floor

    fmu = floor.build_floor(tmp_path)
    u = [1.5, -2.0, 3.25, 0.0, 7.0, -0.5]
    _, before, after = floor_steps(fmu, u)
    assert before == [0.0] * 6 and after == u   # not before the step
    folder = floor.floor_system(tmp_path, fmu, 3)
    assert floor.fmu_count(folder) == 3
    assert floor.per_step(folder, 20, 0.05) > 0 and floor.per_step(folder, 20, 0.05, fresh=True) > 0
    assert floor.startup(folder) > 0
    names, _, after = floor_steps(floor.build_floor(tmp_path / "sized", 4, 2), [1.0, 2.0, 3.0, 4.0])
    assert names == ["u[1]", "u[2]", "u[3]", "u[4]", "y[1]", "y[2]"] and after == [1.0, 2.0]


def test_fmpy_startup_rows_against_the_floor(tmp_path, demo_build):
    """bench.startup.fmpy_compare: simulate_fmu of a scene's FMUs against as many floor FMUs,
    one row per candidate: the median times and the median of the rounds' ratios."""
    from hydrofmu.bench import floor, startup
    rows = startup.fmpy_compare({"moored_barge": demo_build}, floor.build_floor(tmp_path), rounds=2, best=1)
    [r] = rows
    assert r["label"] == "moored_barge" and r["fmus"] == 2
    assert r["simulate_s"] > 0 and r["simulate_floor_s"] > 0 and r["simulate_x"] > 0
    assert r["simulate_noisy"] == (r["simulate_spread"] > floor.NOISY)


def test_floor_spread_and_linearity_bookkeeping():
    from hydrofmu.bench import floor
    assert floor.spread([1.0, 1.2, 0.9]) == pytest.approx(0.3)
    rows = [{"step_us": 100.0}, {"step_us": 160.0}, {"step_us": 400.0}]
    marginal, ratio = floor.linearity(rows, [3, 10, 36])
    assert marginal == pytest.approx([60 / 7, 240 / 26])
    assert ratio == pytest.approx((240 / 26) / (60 / 7))


def test_bench_lines_never_contradict_their_numbers():
    """No negative overhead, no 'spread 25 % > 25 %', no comparison of nothing with nothing:
    where a figure is noise the line says so instead of printing it."""
    import re
    from hydrofmu.bench.run import batch_lines, overhead_line, pool_line
    from hydrofmu.bench.timing import over
    for spread in (0.2500001, 0.2504, 0.251, 0.26, 0.9):
        shown, limit = map(float, re.match(r"spread ([\d.]+) % > ([\d.]+) %", over(spread, 0.25)).groups())
        assert shown > limit
    quiet = {"spread": 0.1, "noisy": False, "speedup": 1.8, "case_s": 0.2, "fixed_s": 0.3}
    lines = batch_lines({**quiet, "overhead_s": -0.029, "share": -0.128}, 4)
    assert not re.search(r"−|-\d", " ".join(lines)) and "below the noise" in lines[1] and "1.80×" in lines[0]
    assert "2 ms = 1.0 %" in batch_lines({**quiet, "overhead_s": 0.002, "share": 0.01}, 4)[1]
    noisy = batch_lines({**quiet, "noisy": True, "spread": 0.4, "overhead_s": 0.002, "share": 0.01}, 4)
    assert "1.80" not in noisy[0] and "too noisy" in noisy[0] and "2 ms" not in noisy[1]
    flat = {"growth_kB": 0.0, "rss_kB": [1e5, 1e5], "kB_per_cycle": 0.0, "cycle_s": 2e-3}
    line = pool_line(flat, flat, 500, 200)
    assert "too few cycles" in line and "against" not in line
    leak = {**flat, "growth_kB": 560.0, "kB_per_cycle": 1.12, "rss_kB": [1e5, 1e5 + 560]}
    assert "0 kB (0.000 kB per cycle; steady part 0 kB: flat) with" in pool_line(flat, leak, 500, 200)
    row = {"coupling_method": "state_space", "fmu_us": 1360.0, "in_process_us": 1385.0, "ratio": 0.98,
           "floor_us": 40.0, "ratio_above_floor": 0.95, "spread": 0.1, "noisy": False}
    assert "no figure" in overhead_line(row) and "0.98×" not in overhead_line(row)
    assert "too noisy (spread 46 % > 25 % between rounds), no figure" in overhead_line({**row, "noisy": True, "spread": 0.46})
    good = overhead_line({**row, "fmu_us": 37.0, "in_process_us": 23.0, "ratio": 1.6, "floor_us": 13.0,
                          "ratio_above_floor": -0.02})
    assert "1.60×" in good and "within the noise" in good and "-0.02" not in good
    # the native part: a marginal cost per step below zero in a round (seen in a quick run:
    # "spread -31 % > 25 %", "-3.45× fmpy per step ... met") is noise, said so
    from hydrofmu.bench.native import _row
    from hydrofmu.bench.run import native_line
    for rounds in ([[60e-6, 14e-6, 0.01, 0.1], [60e-6, -4e-6, 0.01, 0.1]], [[-1e-6, 1e-5, 0.01, 0.1]] * 2):
        line = native_line(_row("floor3 in libcosim", rounds), scene=True)
        assert "below the noise" in line and "met" not in line and not re.search(r"-\d", line), line
    line = native_line(_row("x", [[60e-6, 30e-6, 0.01, 0.1], [61e-6, 30e-6, 0.01, 0.1]]))
    assert "0.50× fmpy per step" in line and "met" in line
    # waves: a noisy scene cost and an effect below zero are not printed
    from hydrofmu.bench.run import waves_lines
    wave = {"components": 50, "no_waves_us": 90.0, "step_x_no_waves": 1.4, "step_us": 144.0, "step_x": 4.4,
            "step_floor_us": 46.0, "effect_us": 12.0, "kernel_per_100_us": 10.6, "noisy": False}
    rows = [wave, {**wave, "components": 1000, "effect_us": -3.0, "noisy": True}]
    text = " ".join(waves_lines(rows))
    assert "too noisy" in text and "144 µs" not in text and "below the noise" in text and "linear" not in text
    assert not re.search(r"-\d", text), text
    assert "linear: " in " ".join(waves_lines([wave, {**wave, "components": 1000, "effect_us": 33.0}]))
    # the flavours in our master against the floor: noisy figures not printed
    from hydrofmu.bench.compiled import flavour_line
    r = {"label": "side_by_side, Python flavour", "step_us": 322.0, "step_x": 3.2, "startup_s": 0.118,
         "startup_x": 2.88, "step_spread": 0.8, "step_noisy": True, "startup_spread": 0.1, "startup_noisy": False}
    line = flavour_line(r, 0.05)
    assert "322" not in line and "too noisy (spread 80 % > 25 %), no figure" in line and "118 ms" in line
    from hydrofmu.bench.run import growth_line
    rows = [{"lags": 100, "convolution_us": 10.0, "state_space_us": 5.0, "convolution_spread": 0.1, "state_space_spread": 0.4},
            {"lags": 400, "convolution_us": 14.0, "state_space_us": 4.3, "convolution_spread": 0.05, "state_space_spread": 0.1}]
    line = growth_line(rows)
    assert "convolution ×1.4" in line and "state-space too noisy (spread 40 % > 25 % between rounds), no figure" in line
    assert "0.86" not in line
    from hydrofmu.bench.compiled import libcosim_line
    line = libcosim_line("ring", _row("ring", [[60e-6, 14e-6, 0.01, 0.1], [60e-6, -4e-6, 0.01, 0.1]]), 0.05)
    assert "below the noise" in line and not re.search(r"-\d", line) and "14 µs" not in line, line
