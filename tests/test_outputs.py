"""Outputs people read: the plots' data choices on synthetic series (hand-computed), CSV
headers with units (parsed), `hydrofmu run` writing CSV + PNG next to the build, complete
--help texts, and the light public API."""
import argparse
import subprocess
import sys

import numpy as np
import pytest

from conftest import MODELS, ROOT
from hydrofmu.cosim.report import body_loads, effect_colours, joint_sides, relative_motion, robust_limits
from hydrofmu.cosim.result import Result, read_csv, split_header


def test_relative_motion_starts_at_zero_and_unwraps_yaw():
    # barge_b of joined_barges: starts at x = 100 m, y = 35 m and drifts by centimetres
    pos = np.array([[100.0, 35.0, 0.0], [100.02, 35.01, -0.001], [100.05, 35.0, 0.0]])
    # yaw through +π: 3.1 -> -3.1 rad is a turn of +(2π - 6.2) = +0.0832 rad, not -6.2
    att = np.array([[0.01, 0.0, 3.1], [0.0, 0.0, 3.14], [0.0, 0.02, -3.1]])
    dpos, datt = relative_motion(pos, att)
    np.testing.assert_allclose(dpos, [[0, 0, 0], [0.02, 0.01, -0.001], [0.05, 0.0, 0.0]], atol=1e-12)
    np.testing.assert_allclose(datt, [[0, 0, 0], [-0.01, 0.0, 0.04], [-0.01, 0.02, 2 * np.pi - 6.2]], atol=1e-12)


def test_robust_limits_clip_a_start_spike_and_say_so():
    # a −700 kN start spike before a steady load of 50..60 kN (ramp): t = 0..100 s
    t = np.arange(101.0)
    y = 50 + t / 10
    y[0] = -700.0
    lo, hi, clipped = robust_limits(t, [y])
    # settled part t >= 5 s: 50.5..60.0 in 96 samples; 1st/99th percentiles (linear
    # interpolation at position 0.01·95 = 0.95): 50.595 and 59.905; span 9.31; pad 10 %
    p_lo, p_hi = 50.5 + 0.95 * 0.1, 60.0 - 0.95 * 0.1
    pad = 0.1 * (p_hi - p_lo)
    assert lo == pytest.approx(p_lo - pad) and hi == pytest.approx(p_hi + pad)
    assert clipped == (-700.0, 60.0)


def test_robust_limits_keep_every_point_without_a_transient():
    # a decaying oscillation (amplitude 1 -> 0.5) is the signal, not a transient: whole span
    t = np.linspace(0.0, 100.0, 1001)
    y = np.exp(-t * np.log(2) / 100) * np.cos(t)
    lo, hi, clipped = robust_limits(t, [y, 0.5 * y])
    span = y.max() - y.min()
    assert clipped is None
    assert lo == pytest.approx(y.min() - 0.1 * span) and hi == pytest.approx(y.max() + 0.1 * span)
    # a flat line gets ±10 % of its value, a zero line ±1
    assert robust_limits(t, [np.full_like(t, 50.0)]) == (pytest.approx(45.0), pytest.approx(55.0), None)
    assert robust_limits(t, [np.zeros_like(t)]) == (-1.0, 1.0, None)


def test_one_colour_per_effect_in_every_row():
    row_a = ["viscous_drag", "current_polar", "clump", "total"]
    row_b = ["current_polar", "viscous_drag", "hitch", "total"]
    colours = effect_colours(row_a + row_b)
    assert colours["total"] == "black"
    named = [colours[e] for e in ("clump", "current_polar", "hitch", "viscous_drag")]
    assert len(set(named)) == 4 and "black" not in named


def test_joint_forces_join_the_loads_of_both_sides():
    manifest = {
        "dynamics": {"a": ["a_dyn", ""], "b": ["ab_dyn", "b."]},
        "instances": {"a": {"kind": "load", "body": "a"}, "hitch": {"kind": "joint", "body": "a"},
                      "anchor": {"kind": "joint", "body": "b"}},
        "connections": [["a_dyn", "position[1]", "hitch", "A.position[1]"],
                        ["ab_dyn", "b.position[1]", "hitch", "B.position[1]"],
                        ["ab_dyn", "b.position[1]", "anchor", "A.position[1]"]],
    }
    assert joint_sides(manifest) == {"hitch": ("a", "b"), "anchor": ("b", None)}
    t = np.arange(3.0)
    drag = np.arange(18.0).reshape(3, 6)
    cols = ([f"a.force[{i}]" for i in range(1, 7)] + [f"a.drag.force[{i}]" for i in range(1, 7)]
            + [f"hitch.{s}.force[{i}]" for s in "AB" for i in range(1, 7)])
    values = np.hstack([drag, drag, np.ones((3, 6)), -np.ones((3, 6))])
    result = Result(t, cols, values, "jacobi", 1.0)
    loads_a, loads_b = body_loads(result, manifest, "a"), body_loads(result, manifest, "b")
    assert sorted(loads_a) == ["drag", "hitch", "total"] and sorted(loads_b) == ["hitch", "total"]
    np.testing.assert_array_equal(loads_a["total"], drag + 1)
    np.testing.assert_array_equal(loads_b["total"], -np.ones((3, 6)))


def test_csv_headers_carry_units_and_read_back(demo_build, tmp_path):
    from hydrofmu.cosim.master import run
    result = run(demo_build, stop=0.5)
    path = result.to_csv(tmp_path / "run.csv")
    header = path.read_text().splitlines()[0].split(",")
    units = dict(split_header(cell) for cell in header)
    # the FMI units of the README: SI, forces N, moments N.m, angles rad
    assert units["time"] == "s"
    for i in range(1, 4):
        assert units[f"barge.force[{i}]"] == "N" and units[f"barge.force[{i + 3}]"] == "N.m"
        assert units[f"barge_dynamics.position[{i}]"] == "m"
        assert units[f"barge_dynamics.attitude[{i}]"] == "rad"
        assert units[f"barge_dynamics.velocity[{i}]"] == "m/s"
        assert units[f"barge_dynamics.velocity[{i + 3}]"] == "rad/s"
        assert units[f"barge.viscous_drag.force[{i + 3}]"] == "N.m"
    assert all(u for u in units.values()), [c for c, u in units.items() if not u]
    back = read_csv(path, demo_build)
    assert back.columns == result.columns and back.step == pytest.approx(0.1)
    np.testing.assert_array_equal(back.values, result.values)   # repr: full precision
    np.testing.assert_array_equal(back.motion("barge", "position", 3), result.motion("barge", "position", 3))
    assert split_header("x.force[1]") == ("x.force[1]", "") and split_header("a [-]") == ("a", "")


def test_time_axis_reads_minutes_and_hours_for_long_records():
    from hydrofmu.cosim.report import time_axis
    t, label = time_axis(np.arange(0.0, 600.1, 0.1))
    assert label == "time [s]" and t[-1] == pytest.approx(600.0)
    t, label = time_axis(np.arange(0.0, 1800.1, 0.1))            # 30 minutes
    assert label == "time [min]" and t[-1] == pytest.approx(30.0)
    t, label = time_axis(np.arange(0.0, 4 * 3600.0 + 1, 1.0))    # 4 hours
    assert label == "time [h]" and t[-1] == pytest.approx(4.0)


def test_negligible_dofs_and_small_loads_get_their_own_treatment():
    from hydrofmu.cosim.report import by_scale, negligible
    # a round body's yaw moment from BEM noise beside 300 kN·m of pitch: listed, not drawn
    assert negligible(6e-4, 300.0) and not negligible(0.5, 300.0)
    assert negligible(1e-10, 0.0) and not negligible(1e-3, 0.0)   # alone, a millimetre is no noise
    # a 0.26 kN drift force beside ±100 kN of waves: on an axis of its own
    t = np.linspace(0.0, 100.0, 1001)
    waves, drift = 100 * np.sin(t), 0.26 + 0.05 * np.sin(0.1 * t)
    curves = [("waves", "C0", waves, False), ("drift", "C1", drift, False), ("total", "k", waves + drift, True)]
    large, small = by_scale(curves)
    assert [c[0] for c in large] == ["waves", "total"] and [c[0] for c in small] == ["drift"]


def _hydrofmu(*args, cwd):
    return subprocess.run([sys.executable, "-m", "hydrofmu.cli", *args], cwd=cwd, capture_output=True,
                          text=True, timeout=300)


def test_run_writes_csv_png_and_summary_next_to_the_build_and_says_where(tmp_path):
    import json
    out = tmp_path / "fmus"
    done = _hydrofmu("run", str(MODELS / "moored_barge.toml"), "-o", str(out), "--stop", "1", cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    csv, png, summary = out / "moored_barge.csv", out / "moored_barge.png", out / "moored_barge.summary.json"
    assert f"in {out / 'moored_barge'}" in done.stdout             # where it built
    parquet = out / "moored_barge.parquet"
    spectra, spectra_png = out / "moored_barge.spectra.csv", out / "moored_barge.spectra.png"
    assert f"wrote {csv}, {parquet}, {png}, {summary}, {spectra} and {spectra_png}" in done.stdout   # where it wrote
    assert "warning" not in done.stderr.lower(), done.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    result = read_csv(csv)
    assert len(result.time) == 11
    # the run's settings once, without a "preset none"; the summary printed and written
    text = done.stdout + done.stderr
    assert text.count("step 0.1 s, gauss-seidel") == 1 and "preset none" not in text
    assert "summary of moored_barge (Python flavour)" in done.stdout and "barge  total" in done.stdout
    # which flavour ran: in the settings line, the summary's JSON and the manifest
    assert text.count("; Python flavour (pythonfmu FMUs)") == 1
    assert json.loads(summary.read_text())["flavour"] == "Python"
    stats = json.loads(summary.read_text())["bodies"]["barge"]
    fx = result["barge.force[1]"]
    assert stats["total"]["Fx"]["unit"] == "N" and stats["total"]["Fx"]["max"] == fx.max()
    assert stats["attitude"]["yaw"]["unit"] == "rad"
    # the same scene again: the FMUs are reused, not rebuilt
    manifest = out / "moored_barge" / "manifest.json"
    before = manifest.stat().st_mtime_ns
    again = _hydrofmu("run", str(MODELS / "moored_barge.toml"), "-o", str(out), "--stop", "1", cwd=tmp_path)
    assert again.returncode == 0 and f"reusing {out / 'moored_barge'}" in again.stdout, again.stderr
    assert "built scene" not in again.stdout and manifest.stat().st_mtime_ns == before


def test_every_option_has_a_help_text():
    from hydrofmu.cli import make_parser
    parser = make_parser()
    subs = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    assert {"bench", "bem2simo", "build", "demo", "run", "validate"} <= set(subs.choices)
    for name, sub in subs.choices.items():
        assert sub.description, name
        for action in sub._actions:
            assert action.help, f"{name} {action.dest}"
        text = sub.format_help()
        for action in sub._actions:   # a default worth saying is said once
            if action.default not in (None, False, argparse.SUPPRESS):
                assert text.count("default:") >= 1, name
        assert "(default: None)" not in text and text.count("(default: the scene's) (default") == 0


def test_public_api_is_light_and_complete():
    code = ("import sys, hydrofmu; heavy = [m for m in ('numpy', 'fmpy', 'matplotlib', 'scipy') if m in sys.modules]; "
            "print(heavy); [getattr(hydrofmu, n) for n in hydrofmu.__all__]; print('ok')")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT)
    assert done.stdout.split("\n")[:2] == ["[]", "ok"], done.stderr
    import hydrofmu
    from hydrofmu.physics.viscous_drag import ViscousDrag
    assert hydrofmu.ViscousDrag is ViscousDrag and hydrofmu.Result is Result
    for name in ("load_scene", "build", "run", "read_csv"):
        doc = getattr(hydrofmu, name).__doc__
        assert "Parameters" in doc and "Returns" in doc, name   # numpydoc sections


def test_labels_of_crowded_points_do_not_overlap():
    # the memory trade-off's crowd: state-space points within 1 µs of each other
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.transforms import Bbox
    from hydrofmu.cosim.report import annotate_apart
    xs = [4.9, 5.0, 5.0, 5.1, 5.3, 5.7, 12, 16, 23, 40, 100]
    ys = [1.0, 0.6, 0.05, 0.018, 0.0037, 0.0021, 0.9, 0.3, 0.0079, 1e-4, 1e-5]
    fig, ax = plt.subplots(figsize=(8, 5.5))
    ax.loglog(xs, ys, "o")
    ax.margins(x=0.25, y=0.15)
    fig.tight_layout()
    labels = annotate_apart(ax, xs, ys, [f"state_space tol {i}" for i in range(len(xs))])
    renderer = fig.canvas.get_renderer()
    boxes = [a.get_window_extent(renderer) for a in labels]
    points = ax.transData.transform(np.column_stack([xs, ys]))
    for i, box in enumerate(boxes):
        assert not any(box.overlaps(b) for b in boxes[:i]), labels[i].get_text()
        assert not any(Bbox([[px - 1, py - 1], [px + 1, py + 1]]).overlaps(box) for px, py in points)
    plt.close(fig)
