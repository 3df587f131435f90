"""Long runs in bounded memory (cosim.stream): rows streamed to Parquet and CSV as the run goes
equal the in-memory run bit for bit; an output interval keeps every k-th point; outputs are
chosen by name (unknown names get the shared did-you-mean error); the master holds one buffer
of a fixed number of rows however long the run is."""
import json

import numpy as np
import pytest

from hydrofmu.cli import main
from hydrofmu.cosim import stream
from hydrofmu.cosim.master import run
from hydrofmu.cosim.result import read_csv
from hydrofmu.cosim.stream import Sink, read_parquet
from hydrofmu.errors import InputError
from hydrofmu.scene import load_scene

STOP = 3.0   # 30 steps of the demo scene's 0.1 s


def test_streamed_files_equal_the_in_memory_run(demo_build, tmp_path):
    mem = run(demo_build, stop=STOP, progress=False)
    got = run(demo_build, stop=STOP, progress=False, sink=Sink(tmp_path / "r.parquet", tmp_path / "r.csv"))
    assert np.array_equal(got.time, mem.time) and got.columns == mem.columns
    assert np.array_equal(got.values, mem.values)          # bit for bit, through Parquet
    assert got.units == mem.units and got.manifest == mem.manifest
    mem.to_csv(tmp_path / "mem.csv")
    assert (tmp_path / "r.csv").read_text() == (tmp_path / "mem.csv").read_text()
    again = read_parquet(tmp_path / "r.parquet")
    col = mem.columns[5]
    assert np.array_equal(again[col], mem[col])
    body = next(iter(mem.dynamics))
    assert np.array_equal(again.motion(body, "position", 3), mem.motion(body, "position", 3))
    assert not list(tmp_path.glob("*.part"))


def test_summary_read_block_by_block_equals_the_whole(demo_build, tmp_path, monkeypatch):
    monkeypatch.setattr(stream, "BLOCK", 7)   # 31 rows in 5 blocks
    mem = run(demo_build, stop=STOP, progress=False)
    got = run(demo_build, stop=STOP, progress=False, sink=Sink(tmp_path / "r.parquet"))
    assert got._file.num_row_groups == 5
    for transient in (0.0, 1.0):
        want, have = mem.summary(transient).to_dict(), got.summary(transient).to_dict()
        assert (have["from"], have["to"], have["points"]) == (want["from"], want["to"], want["points"])
        for body, quantities in want["bodies"].items():
            for q, dofs in quantities.items():
                for d, w in dofs.items():
                    h = have["bodies"][body][q][d]
                    assert (h["min"], h["max"], h["unit"]) == (w["min"], w["max"], w["unit"])
                    scale = max(abs(w["mean"]), w["std"], 1e-300)
                    assert abs(h["mean"] - w["mean"]) <= 1e-12 * scale and abs(h["std"] - w["std"]) <= 1e-9 * scale


def test_interval_keeps_every_kth_point(demo_build, tmp_path):
    full = run(demo_build, stop=STOP, progress=False)
    thin = run(demo_build, stop=STOP, interval=0.3, progress=False)
    assert np.array_equal(thin.time, full.time[::3]) and np.array_equal(thin.values, full.values[::3])
    assert thin.step == pytest.approx(0.3)
    streamed = run(demo_build, stop=STOP, interval=0.3, progress=False, sink=Sink(tmp_path / "t.parquet"))
    assert np.array_equal(streamed.values, full.values[::3]) and len(streamed) == 11
    with pytest.raises(InputError, match=r"interval: the output interval must be a whole number of steps \(0.1 s\)"):
        run(demo_build, stop=STOP, interval=0.25, progress=False)
    import hydrofmu   # the public call streams the same way
    public = hydrofmu.run(demo_build, stop=STOP, interval=0.3, parquet=tmp_path / "p.parquet", outputs=["barge"])
    assert isinstance(public, stream.FileResult) and np.array_equal(public.motion("barge", "position"),
                                                                    full.motion("barge", "position")[::3])


def test_outputs_by_name(demo_build):
    r = run(demo_build, stop=1.0, outputs=["barge", "barge.velocity", "barge.force[3]"], progress=False)
    inst, prefix = r.dynamics["barge"]
    want = [f"{inst}.{prefix}{w}[{i}]" for w in ("position", "attitude", "velocity") for i in (1, 2, 3)]
    assert r.columns == want + ["barge.force[3]"]
    full = run(demo_build, stop=1.0, progress=False)
    assert np.array_equal(r["barge.force[3]"], full["barge.force[3]"])
    with pytest.raises(InputError, match=r"unknown output 'barge.positon' \(did you mean 'barge.position'"):
        run(demo_build, stop=1.0, outputs=["barge.positon"], progress=False)


def test_the_master_holds_one_bounded_buffer(demo_build, monkeypatch, tmp_path):
    """However many steps, the rows pass through one buffer of BLOCK rows (here 8)."""
    monkeypatch.setattr(stream, "BLOCK", 8)
    buffers, sizes = set(), []

    class Spy(Sink):
        def write(self, time, values):
            buffers.add((id(values.base), values.base.shape[0]))
            sizes.append(len(time))
            super().write(time, values)
    for stop in (2.0, 6.0):
        buffers.clear(), sizes.clear()
        got = run(demo_build, stop=stop, progress=False, sink=Spy(tmp_path / "s.parquet"))
        assert len(buffers) == 1 and next(iter(buffers))[1] == 8, buffers
        assert max(sizes) <= 8 and sum(sizes) == len(got) == round(stop / 0.1) + 1


def test_scene_chooses_outputs_and_interval(tmp_path):
    scene = tmp_path / "s.toml"
    text = (stream_models() / "moored_barge.toml").read_text().replace(
        'substep = 0.02', 'substep = 0.02\noutputs = ["barge.position"]\ninterval = 0.2')
    scene.write_text(text.replace('"decks/', f'"{stream_models()}/decks/'))
    s = load_scene(scene)
    assert s.run["outputs"] == ["barge.position"] and s.run["interval"] == 0.2 and "interval" not in s.run["set"]
    scene.write_text(text.replace("interval = 0.2", "interval = 0.15").replace('"decks/', f'"{stream_models()}/decks/'))
    with pytest.raises(InputError, match=r"run.interval: the output interval must be a whole number of steps"):
        load_scene(scene)
    scene.write_text(text.replace('"decks/', f'"{stream_models()}/decks/').replace("stop = 600.0", "stop = 1.0"))
    out = tmp_path / "out"
    assert main(["run", str(scene), "-o", str(out)]) == 0
    r = read_parquet(out / "moored_barge.parquet")
    assert len(r.columns) == 3 and np.allclose(np.diff(r.time), 0.2) and len(r) == 6
    assert read_csv(out / "moored_barge.csv").values.shape == (6, 3)


def stream_models():
    from pathlib import Path
    return Path(__file__).resolve().parents[1] / "models"
