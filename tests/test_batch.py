"""Load-case batches (``hydrofmu batch``) on a local Dask cluster of 2 worker processes,
started once for the module.  Each case is checked against the single-run API on a scene
built with the case's values written into it, so FMU-exposed knobs (set at initialisation,
sharing one build) must give what a rebuilt scene gives."""
import json
import logging
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import dask
import numpy as np
import pandas as pd
import pytest
from distributed import Client, LocalCluster

import hydrofmu
from hydrofmu.batch import load_cases
from hydrofmu.errors import InputError
from hydrofmu.scene import load_scene

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "models" / "moored_barge.toml"
OUTPUTS = ["barge_dynamics.position[1]", "barge_dynamics.position[2]", "barge.force[2]"]


@pytest.fixture(scope="module")
def client():
    # a task whose worker dies is given up at once (KilledWorker), for the lost-worker test
    with dask.config.set({"distributed.scheduler.allowed-failures": 0}):
        cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=":0",
                               silence_logs=logging.ERROR)
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


def case_file(folder, body, stop=10.0):
    path = Path(folder) / "cases.toml"
    path.write_text(f'scene = "{SCENE}"\nstop = {stop}\noutputs = {json.dumps(OUTPUTS)}\n{body}')
    return path


def test_batch_equals_single_runs(client, tmp_path):
    cases = case_file(tmp_path, """
[matrix]
"environment.current_speed" = [0.5, 1.5]
"environment.current_direction" = [30.0, 200.0]
[[cases]]                      # a knob the build bakes in, with one the FMUs expose
"run.substep" = 0.05
"environment.current_speed" = 0.8
""")
    # through the scheduler's address, as `--scheduler ADDRESS` does
    table = hydrofmu.run_batch(cases, tmp_path / "out", scheduler=client.scheduler.address, progress=False)
    assert len(table) == 5 and (table["status"] == "ok").all(), table[["status", "error"]]
    # the workers ran the FMUs they were sent, unpacked in their own folders, not the build's
    shipped = client.run(lambda dask_worker: sorted(
        p.parent.name for p in Path(dask_worker.local_directory).glob("hydrofmu-batch/*/manifest.json")))
    assert set().union(*map(set, shipped.values())) == set(table["build"])
    # the four exposed-knob cases share one build, the substep case has its own
    assert table["build"].iloc[:4].nunique() == 1 and table["build"].iloc[4] != table["build"].iloc[0]
    assert len(list((tmp_path / "out" / "builds").iterdir())) == 2
    for _, row in table.iterrows():
        knobs = {k: row[k] for k in ("environment.current_speed", "environment.current_direction", "run.substep")
                 if pd.notna(row[k])}
        # the single-run API on the scene rebuilt with the case's values written into it
        ref = hydrofmu.run(load_scene(SCENE, {**knobs, "run.stop": 10.0}), out=tmp_path / "ref" / row["case"],
                           record=OUTPUTS, log=lambda *_: None)
        for j, name in enumerate(OUTPUTS):
            x = ref.values[:, j]
            want = {"max": x.max(), "min": x.min(), "mean": x.mean(), "std": x.std(), "final": x[-1], "initial": x[0]}
            for stat, value in want.items():
                assert row[f"{name}.{stat}"] == pytest.approx(value, rel=1e-12, abs=1e-12 * np.abs(x).max()), \
                    (row["case"], name, stat)
    # the cases really differ (the knobs reached the FMUs): the sway offset grows with speed
    sway = table["barge_dynamics.position[2].max"].to_numpy()
    assert sway[2] > 5 * sway[0] > 0
    written = pd.read_csv(tmp_path / "out" / "cases.csv")
    assert list(written["case"]) == list(table["case"])
    assert pd.read_parquet(tmp_path / "out" / "cases.parquet").shape == table.shape
    assert (tmp_path / "out" / "cases.png").stat().st_size > 0


def test_failing_cases_are_reported_and_the_others_finish(client, tmp_path):
    cases = case_file(tmp_path, """
[matrix]
"environment.current_speed" = [0.5, 1.0]
[[cases]]                      # 1 kg on the barge's mooring: the dynamics blow up
"bodies.barge.mass" = 1.0
[[cases]]                      # NaN water density: NaN loads
"barge.rho" = nan
[[cases]]                      # bad input, refused by the scene's own check
"environment.current_speed" = -1.0
""")
    table = hydrofmu.run_batch(cases, tmp_path / "out", client=client, progress=False, series=True)
    assert list(table["status"]) == ["ok", "ok", "failed", "failed", "failed"]
    assert table["error"].iloc[:2].isna().all() and table["error"].iloc[2:].str.len().min() > 0
    assert "environment.current_speed" in table["error"].iloc[4]
    ok = table.iloc[:2]
    assert np.isfinite(ok[[f"{o}.max" for o in OUTPUTS]].to_numpy()).all()
    # time series on request, for the cases that ran to the end
    series = pd.read_parquet(tmp_path / "out" / "series" / f"{ok['case'].iloc[1]}.parquet")
    assert list(series.columns) == ["time"] + OUTPUTS and len(series) == 101
    assert series[OUTPUTS[1]].max() == pytest.approx(ok[f"{OUTPUTS[1]}.max"].iloc[1], rel=1e-15)


def test_killed_batch_reruns_only_missing_cases(client, tmp_path):
    directions = list(range(0, 360, 30))
    cases = case_file(tmp_path, f'[matrix]\n"environment.current_direction" = {directions}\n', stop=20.0)
    out = tmp_path / "out"
    proc = subprocess.Popen([sys.executable, "-m", "hydrofmu.cli", "batch", str(cases), "-o", str(out),
                             "--workers", "1"], start_new_session=True,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.monotonic() + 180
        while len(list(out.glob("cases/*.json"))) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
    finally:
        os.killpg(proc.pid, signal.SIGKILL)   # the batch, its cluster and workers: one process group
        proc.wait()
    before = {p.name: p.read_text() for p in out.glob("cases/*.json")}
    assert 3 <= len(before) < len(directions), "the batch was not killed half-way"
    logs = []
    table = hydrofmu.run_batch(cases, out, client=client, progress=False, log=logs.append)
    assert (table["status"] == "ok").all() and len(table) == len(directions)
    assert not any(line.startswith("building") for line in logs)   # the killed run's build is reused
    after = {p.name: json.loads(p.read_text()) for p in out.glob("cases/*.json")}
    assert all(after[name] == json.loads(text) for name, text in before.items())   # untouched
    fresh = [r for name, r in after.items() if name not in before]
    assert len(fresh) == len(directions) - len(before) and len({r["batch"] for r in fresh}) == 1
    assert {r["batch"] for r in fresh}.isdisjoint(json.loads(t)["batch"] for t in before.values())
    # a third run has nothing left to do
    logs.clear()
    again = hydrofmu.run_batch(cases, out, client=client, progress=False, log=logs.append)
    assert {p.name: json.loads(p.read_text()) for p in out.glob("cases/*.json")} == after
    pd.testing.assert_frame_equal(again, table)


# on the workers: the co-simulation of a case with barge.g = 9.0001 kills its worker process
KILLER = """
import os, hydrofmu.cosim.master as m
if not hasattr(m, "_real_run"):
    m._real_run = m.run
def _run(folder, **kw):
    if (kw.get("parameters") or {}).get("barge.g") == 9.0001:
        os._exit(3)
    return m._real_run(folder, **kw)
m.run = _run
"""
HEAL = """
import hydrofmu.cosim.master as m
m.run = getattr(m, "_real_run", m.run)
"""


def test_lost_worker_is_recorded_and_rerun(client, tmp_path):
    cases = case_file(tmp_path, '[matrix]\n"barge.g" = [9.81, 9.0001, 9.80]\n', stop=5.0)
    client.run(exec, KILLER, {})
    try:
        table = hydrofmu.run_batch(cases, tmp_path / "out", client=client, progress=False)
    finally:
        client.run(exec, HEAL, {})
    # the killer's case is lost; a case the scheduler had queued on the same worker dies with
    # it (allowed-failures = 0 here; Dask's default retries it elsewhere), every other runs
    status = list(table["status"])
    assert status[1] == "lost" and "KilledWorker" in table["error"].iloc[1]
    assert set(status) == {"ok", "lost"} and status.count("ok") >= 1
    assert all(e for e, s in zip(table["error"], status) if s == "lost")   # each says why
    client.wait_for_workers(2, timeout=60)   # the nanny restarts the dead worker
    again = hydrofmu.run_batch(cases, tmp_path / "out", client=client, progress=False)
    assert (again["status"] == "ok").all() and list(again["case"]) == list(table["case"])
    assert again["barge_dynamics.position[1].max"].iloc[1] > 0


def test_case_file_errors(tmp_path):
    def error(body, scene=SCENE):
        path = tmp_path / "bad.toml"
        path.write_text(f'scene = "{scene}"\n{body}')
        with pytest.raises(InputError) as exc:
            load_cases(path)
        assert str(path) in str(exc.value)
        return exc.value
    assert error('outputs = []').field == "outputs"
    assert error('outputs = ["barge.force[1]"]\nmatrx = 1').field == "matrx"
    assert error('outputs = ["a.b"]', scene=tmp_path / "none.toml").field == "scene"
    assert error('outputs = ["a.b"]\n[matrix]\nbogus = [1]').field == "bogus"
    assert error('outputs = ["a.b"]\nstop = -1').field == "stop"
    # a name every case shares is checked on the first case, before any case runs
    path = case_file(tmp_path, '[matrix]\n"barge.no_such_parameter" = [1.0]\n')
    with pytest.raises(InputError, match="barge.no_such_parameter"):
        hydrofmu.run_batch(path, tmp_path / "out", progress=False)
    assert not (tmp_path / "out" / "cases").exists()


def test_sea_state_knobs_share_one_build(client, tmp_path):
    """hs, tp and seed (aliases of waves.hs, waves.tp, waves.seed) are FMU parameters: the
    cases share one build, each case's statistics are those of the in-process run with the
    same parameters, and `significant` is 4·std (for the elevation: the record's Hs)."""
    import shutil
    from hydrofmu.cosim import inprocess
    from hydrofmu.cosim.master import run
    data = ROOT / "tests" / "data" / "bem" / "wave_cylinder.nc"
    shutil.copy(data, tmp_path / data.name)
    scene = tmp_path / "sea.toml"
    from hydrofmu.bench.waves_cost import SCENE as TEXT, WAVES   # the bench's floating cylinder
    scene.write_text(TEXT.format(waves=WAVES.format(n=50) + "ramp = 5.0\n", data=data.name)
                     .replace("stop = 10.0", "stop = 60.0").replace("step = 0.05", "step = 0.1"))
    outputs = ["cyl.waves.elevation", "cyl_dynamics.position[3]"]
    cases = tmp_path / "cases.toml"
    cases.write_text(f'scene = "{scene}"\noutputs = {json.dumps(outputs)}\ntransient = 10.0\n'
                     '[matrix]\nhs = [0.5, 1.0]\ntp = [5.0, 8.0]\nseed = [3]\n')
    table = hydrofmu.run_batch(cases, tmp_path / "out", client=client, progress=False)
    assert len(table) == 4 and (table["status"] == "ok").all(), table[["status", "error"]]
    assert table["build"].nunique() == 1
    for _, row in table.iterrows():
        params = {"cyl.waves.hs": row["hs"], "cyl.waves.tp": row["tp"], "cyl.waves.seed": row["seed"]}   # as written
        ref = run(inprocess.system(load_scene(scene), params), progress=False, record=outputs)
        after = ref.time >= 10.0
        for name in outputs:
            x = ref[name][after]
            assert row[f"{name}.std"] == pytest.approx(x.std(), rel=1e-9)
            assert row[f"{name}.significant"] == pytest.approx(4 * x.std(), rel=1e-9)
        assert row["cyl.waves.elevation.significant"] == pytest.approx(row["hs"], rel=0.25)   # 50 s of record


def test_capsized_and_the_linear_range_in_the_table(client, tmp_path):
    """The wave-test cylinder, BEM hydrostatics only: a constant hold at 0.1 s grows its pitch
    (σ = ω²h/4, test_hold) until it capsizes (a failed case saying so); the linear hold keeps the
    free oscillation's amplitude, the initial pitch rate / ω (grown by its e^{ω(ωh)³/6·t}): 1.1°
    from 0.03 rad/s (in range), 18° from 0.5 rad/s (out of it; ω computed here from the dataset)."""
    import math
    from hydrofmu.bench.hold import cylinder_scene
    from test_hold import pitch_frequency
    scene = cylinder_scene(tmp_path, "linear", 0.1, 60.0, memory=False, velocity=0.03)
    cases = tmp_path / "cases.toml"
    cases.write_text(f'scene = "{scene.name}"\noutputs = ["cyl_dynamics.attitude[2]"]\n'
                     '[[cases]]\n"run.load_hold" = "constant"\n"run.stop" = 100.0\n'
                     '[[cases]]\n"run.load_hold" = "linear"\n'
                     '[[cases]]\n"bodies.cyl.velocity" = [0.0, 0.0, 0.0, 0.0, 0.5, 0.0]\n')
    said = []
    table = hydrofmu.run_batch(cases, tmp_path / "out", client=client, progress=False, log=said.append)
    assert list(table["status"]) == ["failed", "ok", "ok"], table[["status", "error"]]
    # the workers' warnings come back named by their case (id and knobs as the file wrote them)
    out_of_range = [line for line in said if "left the linear range" in line]
    assert len(out_of_range) == 2, said
    assert out_of_range[1].startswith(f"warning: case {table['case'].iloc[2][:8]} (bodies.cyl.velocity = "
                                      "[0.0, 0.0, 0.0, 0.0, 0.5, 0.0]): [WARNING] cyl_dynamics: left the linear range")
    assert "left the linear range" in table["warnings"].iloc[2] and table["warnings"].iloc[1] == ""
    assert table["error"].iloc[0].startswith("capsized: ") and "GimbalLock" not in table["error"].iloc[0]
    assert list(table["linear_range"]) == [False, True, False]
    w = pitch_frequency()
    grown = math.exp(w * (w * 0.1) ** 3 / 6 * 60.0)   # the linear hold's slow growth over the 60 s (test_hold)
    for k, rate in ((1, 0.03), (2, 0.5)):
        assert table["max_tilt_deg"].iloc[k] == pytest.approx(math.degrees(rate / w) * grown, rel=0.03)
