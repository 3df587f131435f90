"""Unzipped FMUs shared across runs (cosim.unpacked).

One folder per FMU content, made once and reused by later runs; a changed FMU gets a folder
of its own; workers unzipping the same FMU at once all get the same complete folder; old
folders are pruned.
"""
import os
import shutil
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest

from hydrofmu.cosim import unpacked as cache
from hydrofmu.cosim.master import run


@pytest.fixture
def fresh_cache(tmp_path, monkeypatch):
    """An empty unzip cache of this test (HYDROFMU_CACHE also for child processes; the
    compiled shim and kernel are already in the FMUs)."""
    monkeypatch.setenv("HYDROFMU_CACHE", str(tmp_path / "cache"))
    return tmp_path / "cache" / "fmus"


def entries(fmu):
    with zipfile.ZipFile(fmu) as z:
        return {i.filename: z.read(i) for i in z.infolist() if not i.is_dir()}


def test_one_folder_per_content(demo_build, fresh_cache, tmp_path):
    """The same FMU at two paths: one folder, holding what a Linux host loads, byte for
    byte; the FMU with one byte of its resources changed, at the same path: a new folder,
    with the new bytes, the old one left for whoever still reads it."""
    fmu = demo_build / "moored_barge_barge.fmu"
    copy = tmp_path / "copy.fmu"
    shutil.copyfile(fmu, copy)
    a, b = cache.unpacked(fmu), cache.unpacked(copy)
    assert a == b and a.parent == fresh_cache
    inside = {str(p.relative_to(a)) for p in a.rglob("*") if p.is_file()}
    want = {n: data for n, data in entries(fmu).items() if n.startswith(cache.WANTED)}
    assert inside == set(want) and any(n.startswith("binaries/win64/") for n in entries(fmu))
    assert all((a / n).read_bytes() == data for n, data in want.items())
    changed = dict(entries(copy))
    changed["resources/slavemodule.txt"] += b" "
    time.sleep(0.01)
    with zipfile.ZipFile(copy, "w") as z:
        for name, data in changed.items():
            z.writestr(name, data)
    c = cache.unpacked(copy)
    assert c != a and (c / "resources/slavemodule.txt").read_bytes() == changed["resources/slavemodule.txt"]
    assert a.is_dir() and sorted(p.name for p in fresh_cache.iterdir()) == sorted([a.name, c.name])


WORKER = """
import sys, time
from pathlib import Path
from hydrofmu.cosim.unpacked import unpacked
go = Path(sys.argv[2])
while not go.exists():
    time.sleep(0.001)
print(unpacked(sys.argv[1]))
"""


def test_workers_unzipping_at_once(demo_build, fresh_cache, tmp_path):
    """Four processes unzip the same FMU into an empty cache at the same moment: all get
    the same folder, complete, and no private folder is left behind."""
    fmu = demo_build / "moored_barge_barge_dynamics.fmu"
    go = tmp_path / "go"
    procs = [subprocess.Popen([sys.executable, "-c", WORKER, str(fmu), str(go)], stdout=subprocess.PIPE,
                              text=True, env=dict(os.environ)) for _ in range(4)]
    time.sleep(1.0)   # every worker waiting
    go.touch()
    got = {p.communicate(timeout=120)[0].strip() for p in procs}
    assert all(p.returncode == 0 for p in procs)
    assert len(got) == 1
    folder = Path(got.pop())
    want = {n: data for n, data in entries(fmu).items() if n.startswith(cache.WANTED)}
    assert all((folder / n).read_bytes() == data for n, data in want.items())
    assert [p.name for p in fresh_cache.iterdir()] == [folder.name]


def test_prune_keeps_the_recent(demo_build, fresh_cache, monkeypatch):
    """Beyond KEEP folders, those not used for GRACE seconds go (and a dead worker's private
    folder); those used recently stay whatever their number."""
    monkeypatch.setattr(cache, "KEEP", 3)
    fresh_cache.mkdir(parents=True)
    old = time.time() - 2 * cache.GRACE
    for k, name in enumerate(["a", "b", "c", ".d.123.abc"]):
        (fresh_cache / name).mkdir()
        os.utime(fresh_cache / name, (old + k, old + k))
    (fresh_cache / "recent").mkdir()
    folder = cache.unpacked(demo_build / "moored_barge_barge.fmu")
    assert sorted(p.name for p in fresh_cache.iterdir()) == sorted([folder.name, "recent", "c"])


def test_runs_reuse_the_folder_and_repeat_bit_for_bit(demo_build, fresh_cache):
    """Two runs of the demo scene in one process: the second loads the folders the first
    unzipped (and the shim's pooled instances: same name, same resources) and every
    output equals the first run's, bit for bit."""
    first = run(demo_build, stop=3.0, progress=False)
    folders = sorted(fresh_cache.iterdir())
    stamps = [p.stat().st_mtime_ns for p in folders]
    second = run(demo_build, stop=3.0, progress=False)
    assert sorted(fresh_cache.iterdir()) == folders and len(folders) == 2
    assert all(p.stat().st_mtime_ns >= t for p, t in zip(folders, stamps))   # marked used
    assert np.abs(first.values).max() > 0
    np.testing.assert_array_equal(second.values, first.values)
