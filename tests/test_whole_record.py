"""Every figure of a run is the whole record's, streamed or not: a synthetic moored body in
waves whose largest pitch comes in the first rows (past the 15° linear range), streamed to
Parquet through the master's Recorder in blocks of B rows for records of B − 1, B, B + 1 and
3B + 17 rows.  Each summary figure, the linear-range verdict, the spectra and
``Result.statistics`` read back from the file equal the same figure of the record held in
memory (to round-off), and the plain ones (mean, std, min, max, the largest tilt) equal numpy's
on the whole arrays.  A batch case's columns are its whole record's too."""
import math

import numpy as np
import pytest

from hydrofmu.cosim import statistics as st
from hydrofmu.cosim.result import Result
from hydrofmu.cosim.stream import Recorder, Sink, read_parquet

BLOCK = 64
STEP = 0.5
MANIFEST = {"scene": "synthetic", "dynamics": {"cyl": ["cyl_dynamics", ""]}, "connections": [],
            "run": {"waves": {"period": 6.0, "ramp": 0.0, "spectrum": "jonswap"}},
            "instances": {"cyl": {"kind": "load", "body": "cyl"}, "cyl_dynamics": {"kind": "dynamics", "body": "cyl"}}}


def record(n):
    """A Result of n rows: surge = 0.7 + slow drift + waves, pitch with a 0.5 rad spike at row 3,
    two load groups (waves, drift) and the elevation at the body."""
    rng = np.random.default_rng(n)
    t = np.arange(n) * STEP
    wave = np.sin(2 * np.pi * t / 6.0 + 0.4) + 0.3 * rng.normal(size=n)
    cols, vals, units = [], [], {}

    def add(name, unit, x):
        cols.append(name), vals.append(x), units.__setitem__(name, unit)
    pitch = 0.05 * wave
    pitch[min(3, n - 1)] = 0.5
    for i, x in enumerate((0.7 + 0.4 * np.sin(2 * np.pi * t / 100.0) + 0.2 * wave, 1e-4 * wave, 0.1 * wave)):
        add(f"cyl_dynamics.position[{i + 1}]", "m", x)
    for i, x in enumerate((1e-4 * wave, pitch, np.zeros(n))):
        add(f"cyl_dynamics.attitude[{i + 1}]", "rad", x)
    drift = (260.0 + 50 * np.sin(2 * np.pi * t / 90.0), np.zeros(n), np.zeros(n)) + (np.full(n, 0.05),) * 3
    for i in range(6):   # N, and N.m: the drift's moments numerical noise
        add(f"cyl.waves.force[{i + 1}]", "N" if i < 3 else "N.m", (1e5 if i < 3 else 2e5) * wave)
        add(f"cyl.drift.force[{i + 1}]", "N" if i < 3 else "N.m", drift[i])
    add("cyl.waves.elevation", "m", 0.5 * wave)
    return Result(t, cols, np.column_stack(vals), "gauss-seidel", STEP, MANIFEST["dynamics"], {"step": STEP},
                  units, MANIFEST)


def streamed(result, path):
    """``result`` through the master's Recorder into a Parquet file, ``BLOCK`` rows at a time."""
    sink = Sink(path)
    sink.open(result.columns, result.units, result.manifest, {"step": STEP, "algorithm": "gauss-seidel"})
    rows = Recorder(len(result.time) - 1, STEP, len(result.columns), 1, sink, block=BLOCK)
    for k, values in enumerate(result.values):
        rows.row(k)[:] = values
    rows.flush()
    sink.close()
    return read_parquet(sink.written[path])


def same(a, b):
    if isinstance(b, str):
        return a == b
    return (isinstance(a, float) and math.isnan(a) and math.isnan(b)) or a == pytest.approx(b, rel=1e-12, abs=1e-12)


@pytest.mark.parametrize("n", [BLOCK - 1, BLOCK, BLOCK + 1, 3 * BLOCK + 17])
def test_every_figure_is_the_whole_records(n, tmp_path):
    mem = record(n)
    got = streamed(mem, tmp_path / "r.parquet")
    assert got._file.num_row_groups == -(-n // BLOCK) and np.array_equal(got.values, mem.values)
    for transient in (0.0, 2.0):
        want, have = mem.summary(transient), got.summary(transient)
        assert (have.start, have.stop, have.points, have.split) == (want.start, want.stop, want.points, want.split)
        assert len(have.rows) == len(want.rows) == 6 + 1 + 3 * 6
        for w, h in zip(want.rows, have.rows):
            for key, value in w.items():
                assert same(h[key], value), (w["quantity"], w["dof"], key)
        assert have.notes == want.notes
        for key, s in want.spectra.items():
            np.testing.assert_allclose(have.spectra[key], s, rtol=1e-12, atol=1e-14 * max(np.abs(s).max(), 1e-300))
        both = got.statistics(transient=transient), mem.statistics(transient=transient)
        assert list(both[0]) == mem.columns
        assert all(same(both[0][c][k], v) for c, figures in both[1].items() for k, v in figures.items())
    # the plain figures against numpy on the whole arrays
    s = got.summary()
    x = mem["cyl_dynamics.position[1]"]
    assert s.row("cyl", "position", "x")["mean"] == pytest.approx(x.mean(), rel=1e-12)
    assert s.row("cyl", "position", "x")["std"] == pytest.approx(x.std(), rel=1e-12)
    total = mem["cyl.waves.force[1]"] + mem["cyl.drift.force[1]"]
    assert s.row("cyl", "total", "Fx")["max"] == total.max() and s.row("cyl", "total", "Fx")["min"] == total.min()
    assert s.row("cyl", "elevation", "eta")["std"] == pytest.approx(mem["cyl.waves.elevation"].std(), rel=1e-12)
    # the linear-range verdict: the 0.5 rad spike of row 3, whichever block it fell in
    assert s.notes[-1].endswith(f"|pitch| ≤ {math.degrees(0.5):.3g}°: cyl left it (linear_range = false)")
    assert s.row("cyl", "attitude", "pitch")["max"] == 0.5
    # the analyst's figures are those of cosim.statistics on the whole record
    assert s.row("cyl", "position", "x")["lf_std"] == st.describe(x, STEP, 12.0)["lf_std"]


def test_a_batch_case_columns_are_its_whole_records(demo_build, tmp_path):
    """``batch.run_case`` (a worker's call, here without Dask): its statistics, max_tilt_deg and
    linear_range are those of the same run held in memory, over the whole record."""
    import uuid
    from hydrofmu.batch import STATS, run_case
    from hydrofmu.cosim.master import run
    outputs = ["barge_dynamics.position[1]", "barge.force[1]"]
    blob = {"id": f"test-{uuid.uuid4().hex[:8]}", "files": {f.name: f.read_bytes() for f in demo_build.iterdir()
                                                             if f.is_file()}}
    task = {"case": "c", "run": {"stop": 20.0}, "parameters": {}, "outputs": outputs, "transient": 0.0,
            "series": False, "split": 12.0}
    out = run_case(task, blob)
    assert out["status"] == "ok", out["error"]
    ref = run(demo_build, stop=20.0, progress=False)
    for name in outputs:
        x = ref[name]
        figures = st.describe(x, ref.step, 12.0)
        want = {"max": x.max(), "min": x.min(), "mean": x.mean(), "std": x.std(), "significant": 4 * x.std(),
                "final": x[-1], "initial": x[0], **figures}
        for stat in STATS:
            assert same(out["stats"][f"{name}.{stat}"], float(want[stat])), (name, stat)
    tilt = np.degrees(np.abs(np.column_stack([ref["barge_dynamics.attitude[1]"], ref["barge_dynamics.attitude[2]"]])))
    assert out["max_tilt_deg"] == pytest.approx(tilt.max(), rel=1e-12) and out["linear_range"] is True


def test_the_plot_of_a_long_record_is_one_a_report_can_take(tmp_path, monkeypatch):
    """1000 rows (500 s, 83 peak periods): per quantity the whole run's min–max envelope of every
    sample (the pitch spike of row 3 in it) beside the last 8 peak periods; the elevation on its
    own axis; each axis with its unit; the 0.26 kN drift force on an axis of its own, not on the
    ±100 kN one; the negligible sway, roll, yaw and drift moments named below, not drawn."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figs = []
    monkeypatch.setattr(plt, "close", lambda fig=None: figs.append(fig))
    mem = record(1000)
    mem.plot(tmp_path / "r.png")
    (fig,) = figs
    whole = {a.get_title(loc="left").split("\n")[0]: a for a in fig.axes if not a.get_title(loc="left").startswith("last")}
    windows = [a for a in fig.axes if a.get_title(loc="left") == "last 48 s"]
    assert len(windows) == len(whole) and all(a.get_xlim()[0] >= 500 - 48 - 25 for a in windows)
    surge, pitch = "cyl: surge x from 0.7586 m", "cyl: pitch from 0.839 deg"
    assert list(whole) == ["cyl: wave elevation η at the body", surge, "cyl: heave z from 0.0293 m", pitch, "cyl: Fx",
                           "cyl: Fx, the smaller loads on their own scale", "cyl: Fy", "cyl: Fz", "cyl: Mx", "cyl: My",
                           "cyl: Mz"]
    assert whole[surge].get_ylabel() == "[m]" and whole[pitch].get_ylabel() == "[deg]"
    assert whole["cyl: Fx"].get_ylabel() == "[kN]" and whole["cyl: Mz"].get_ylabel() == "[kN·m]"
    assert all(a.get_xlabel() == "time [s]" for a in fig.axes)
    # the envelope counts every sample: the 28.6° spike is drawn, and the axis shows it
    band = whole[pitch].collections[0].get_paths()[0].vertices[:, 1]
    start = math.degrees(mem["cyl_dynamics.attitude[2]"][0])
    assert band.max() == pytest.approx(math.degrees(0.5) - start) and whole[pitch].get_ylim()[1] > band.max()
    small = whole["cyl: Fx, the smaller loads on their own scale"]
    assert [t.get_text() for t in small.get_legend().get_texts()] == ["drift"] and small.get_ylim()[1] < 1.0
    assert [t.get_text() for t in whole["cyl: Fx"].get_legend().get_texts()] == ["waves", "total"]
    (footer,) = [t.get_text() for t in fig.texts if t.get_text().startswith("not drawn")]
    for named in ("sway y ≤ ", "roll ≤ ", "yaw ≤ 0 deg", "Fy of drift ≤ 0 kN", "Mz of drift ≤ 5e-05 kN·m"):
        assert named in footer, footer
    assert fig.get_size_inches()[0] * fig.dpi == 1600


def test_the_split_is_a_scene_key_and_a_command_line_option(tmp_path, demo_build, capsys):
    """[run] split is read (not a run knob: no rebuild, not in `set`), a bad one is named by its
    key path; --split is checked before anything runs (exit 2, one line)."""
    from conftest import MODELS
    from hydrofmu.cli import main
    from hydrofmu.cosim.summary import split_period
    from hydrofmu.errors import InputError
    from hydrofmu.scene import load_scene
    text = (MODELS / "moored_barge.toml").read_text().replace('"decks/', f'"{MODELS}/decks/')
    scene = tmp_path / "s.toml"
    scene.write_text(text.replace("substep = 0.02", "substep = 0.02\nsplit = 30.0"))
    run = load_scene(scene).run
    assert run["split"] == 30.0 and "split" not in run["set"]
    assert split_period({"run": run}) == {"period": 30.0, "from": "[run] split"}
    scene.write_text(text.replace("substep = 0.02", "substep = 0.02\nsplit = -1.0"))
    with pytest.raises(InputError, match=r"run\.split"):
        load_scene(scene)
    assert main(["run", str(demo_build), "--split", "0", "--stop", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "--split: must be a period > 0 [s], found 0" in err
