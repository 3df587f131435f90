"""The results API an engineer reads a run with: names and units, short repr, pandas, the
summary's statistics (against sums written here), CSVs read without their build folder,
clear errors for unknown names and missing folders, and builds reused only while the
scene and its decks are unchanged."""
import json
import shutil

import numpy as np
import pytest

from conftest import MODELS
from hydrofmu.cosim.result import Result, read_csv
from hydrofmu.errors import InputError
from hydrofmu.names import UnknownName


def synthetic(n=2001, step=0.05):
    """A one-body run: dynamics outputs and two load groups with known series."""
    t = np.arange(n) * step
    cols, vals, units = [], [], {}

    def add(name, unit, series):
        cols.append(name), vals.append(series), units.__setitem__(name, unit)
    for i in range(3):
        add(f"barge_dynamics.position[{i + 1}]", "m", 10.0 * i + np.sin(t + i))
        add(f"barge_dynamics.attitude[{i + 1}]", "rad", 0.01 * np.cos(t * (i + 1)))
    for i in range(6):
        add(f"barge_dynamics.velocity[{i + 1}]", "m/s" if i < 3 else "rad/s", np.full(n, float(i)))
    drag = [1e3 * (i + 1) * np.sin(0.3 * t) ** 2 for i in range(6)]
    for i in range(6):
        add(f"barge.drag.force[{i + 1}]", "N" if i < 3 else "N.m", drag[i])
        add(f"barge.force[{i + 1}]", "N" if i < 3 else "N.m", drag[i] - 5.0)
    manifest = {"scene": "synthetic", "dynamics": {"barge": ["barge_dynamics", ""]}, "connections": [],
                "instances": {"barge": {"kind": "load", "body": "barge"},
                              "barge_dynamics": {"kind": "dynamics", "body": "barge"}}}
    return Result(t, cols, np.column_stack(vals), "gauss-seidel", step, manifest["dynamics"], None, units, manifest)


def test_names_time_counts_and_closest_names():
    r = synthetic()
    assert r["time"] is r.time and "time" in r and "barge.force[1]" in r
    np.testing.assert_array_equal(r.motion("barge", "position"), r.motion("barge", "position", 3))
    assert r.motion("barge", "velocity").shape == (len(r.time), 6)
    assert r.vector("barge", "drag.force").shape == (len(r.time), 6)
    with pytest.raises(UnknownName, match=r"unknown column 'barge.forc\[1\]' \(did you mean 'barge.force\[1\]'"):
        r["barge.forc[1]"]
    with pytest.raises(KeyError, match=r"unknown body 'barg' \(did you mean 'barge'\?\); valid: barge$"):
        r.motion("barg", "position")
    with pytest.raises(ValueError, match="unknown instance 'bargee' \\(did you mean 'barge'"):
        r.vector("bargee", "force")
    with pytest.raises(UnknownName, match="unknown variable 'drag.forc' of instance 'barge' \\(did you mean 'drag.force'"):
        r.vector("barge", "drag.forc")
    with pytest.raises(UnknownName, match=r"unknown column 'barge.force\[7\]'"):
        r.vector("barge", "force", 7)


def test_repr_is_one_short_line():
    text = repr(synthetic(n=100_001))
    assert "\n" not in text and len(text) < 200
    assert text.startswith("<Result synthetic: 100001 points, t = 0–5000 s, gauss-seidel, step 0.05 s")


def test_to_pandas_has_time_index_and_units():
    r = synthetic(n=11)
    df = r.to_pandas()
    assert df.index.name == "time" and list(df.columns) == r.columns
    np.testing.assert_array_equal(df.index.to_numpy(), r.time)
    np.testing.assert_array_equal(df["barge.force[2]"].to_numpy(), r["barge.force[2]"])
    assert df.attrs["units"]["time"] == "s" and df.attrs["units"]["barge.force[4]"] == "N.m"
    assert df.attrs["scene"] == "synthetic" and df.attrs["step"] == 0.05


def test_summary_statistics_per_body_and_dof():
    r = synthetic()
    s = r.summary(transient=20.0)
    keep = r.time >= 20.0
    rows = {(x["quantity"], x["dof"]): x for x in s.rows}
    for quantity, dof, column in (("position", "y", "barge_dynamics.position[2]"),
                                  ("attitude", "yaw", "barge_dynamics.attitude[3]"),
                                  ("drag", "Mz", "barge.drag.force[6]")):
        x = r[column][keep]
        n = len(x)
        mean = sum(x) / n
        std = (sum((x - mean) ** 2) / n) ** 0.5
        got = rows[(quantity, dof)]
        assert got["mean"] == pytest.approx(mean, rel=1e-12) and got["std"] == pytest.approx(std, rel=1e-12)
        assert (got["min"], got["max"]) == (min(x), max(x)) and got["unit"] == r.unit(column)
    # the total is the sum of the load groups, not the FMU's own total column
    assert rows[("total", "Fx")]["max"] == pytest.approx(max(r["barge.drag.force[1]"][keep]))
    assert s.points == keep.sum() and s.start == 20.0 and s.stop == r.time[-1]
    text = str(s)
    assert "summary of synthetic, t = 20–100 s" in text and "attitude in rad" in text
    assert "barge  drag" in text and text.count("\n") < 40
    assert json.loads(json.dumps(s.to_dict()))["bodies"]["barge"]["drag"]["Fz"]["unit"] == "N"
    with pytest.raises(ValueError, match="leaves no point"):
        r.summary(transient=1e6)


def test_csv_without_its_build_folder_gives_plain_columns(tmp_path):
    r = synthetic(n=101)
    path = r.to_csv(tmp_path / "alone.csv")
    back = read_csv(path)
    assert back.manifest is None and back.columns == r.columns
    np.testing.assert_array_equal(back.motion("barge", "attitude"), r.motion("barge", "attitude"))
    assert "no manifest (plot and joint loads need one)" in repr(back)
    summary = back.summary()
    assert "joint forces left out" in str(summary)
    assert {x["quantity"] for x in summary.rows} == {"position", "attitude", "drag", "total"}
    with pytest.raises(ValueError, match=r"read_csv\(path, manifest=BUILT_FOLDER\)"):
        back.plot(tmp_path / "x.png")


def test_csv_errors_name_the_file_line_and_folder(tmp_path):
    r = synthetic(n=5)
    with pytest.raises(InputError, match="folder .*missing does not exist"):
        r.to_csv(tmp_path / "missing" / "run.csv")
    assert not (tmp_path / "missing").exists()
    bad = tmp_path / "bad.csv"
    bad.write_text("time [s],a.x[1] [m]\n0.0,1.0\n0.1,oops\n")
    with pytest.raises(InputError, match=r"bad.csv:3: a.x\[1\]: expected a number, found 'oops'"):
        read_csv(bad)
    with pytest.raises(InputError, match="cannot read the CSV"):
        read_csv(tmp_path / "none.csv")


def test_run_reuses_the_build_until_the_scene_or_a_deck_changes(tmp_path):
    import hydrofmu
    from hydrofmu.api import built_folder, inputs_hash
    shutil.copy(MODELS / "moored_barge.toml", tmp_path)
    shutil.copytree(MODELS / "decks", tmp_path / "decks")
    scene, out, lines = tmp_path / "moored_barge.toml", tmp_path / "out", []
    first = hydrofmu.run(scene, out=out, stop=0.3, log=lines.append)
    manifest = json.loads((out / "moored_barge" / "manifest.json").read_text())
    assert manifest["inputs"] == inputs_hash(scene) and any(x.startswith("built") for x in lines)
    lines.clear()
    second = hydrofmu.run(scene, out=out, stop=0.3, log=lines.append)
    assert lines == [f"reusing {out / 'moored_barge'}: the scene, its decks and hydrofmu are unchanged since it "
                     "was built"]
    np.testing.assert_array_equal(first.values, second.values)
    deck = tmp_path / "decks" / "barge_current.dpl"
    deck.write_text(deck.read_text() + "\n")        # a deck the scene names changed
    assert built_folder(scene, out) is None
    deck.write_text(deck.read_text()[:-1])
    assert built_folder(scene, out) == out / "moored_barge"
    scene.write_text(scene.read_text().replace("stop = 600.0", "stop = 500.0"))   # the scene changed
    assert built_folder(scene, out) is None
