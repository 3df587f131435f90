"""Startup of a built FMU: the build fits every state-space realisation once and stores it
in the FMU's description; instantiation only loads it (no SVD, no scipy, checked in a
fresh interpreter), the runtime copy holds only what a slave imports, with its bytecode,
and the slave imports no more (pythonfmu's builder stays out until asked for)."""
import io
import subprocess
import sys
import zipfile

import numpy as np

from hydrofmu import description
from hydrofmu.physics.memory import realise
from hydrofmu.scene import load_scene
from hydrofmu.fmi.build import build_scene

from conftest import ROOT, STEP_ONCE

FRESH = """
import sys, numpy
def refuse(*a, **k):
    raise AssertionError("an SVD at instantiation")
numpy.linalg.svd = refuse
sys.path.insert(0, sys.argv[1])
FMU = sys.argv[2]
""" + STEP_ONCE + """
s.terminate()
s.freeInstance()
print("pythonfmu.builder" in sys.modules, "argparse" in sys.modules)
import shutil
shutil.rmtree(unzipped)   # as fmpy and hydrofmu's master do after use
from pythonfmu import FmuBuilder   # the rest of pythonfmu still loads on first use
from pythonfmu.builder import FmuBuilder as same
print("pythonfmu.builder" in sys.modules and FmuBuilder is same)
print("scipy" in sys.modules)
"""


def test_fits_are_stored_at_build_and_only_loaded(tmp_path):
    folder = build_scene(load_scene(ROOT / "models" / "side_by_side.toml"), tmp_path, log=lambda *_: None)
    fmu = folder / "side_by_side_barge_a.fmu"
    with zipfile.ZipFile(fmu) as z:
        names = z.namelist()
        desc = description.loads(z.read("resources/hydrofmu.json").decode())
    # the stored fits are the realisations of the coupling's own kernels at its tolerance
    sides = {s.name: s.coupling for s in desc.couplings}
    assert set(sides) == {"SELFA", "AB"}
    for c in sides.values():
        assert c.method == "state_space" and c.fits
        kernels = {(k.dof_a, k.dof_b): k.values for k in c.kernels if np.any(k.values)}
        assert {(f.dof_a, f.dof_b) for f in c.fits} == set(kernels)
        for f in c.fits:
            ref = realise(kernels[(f.dof_a, f.dof_b)], c.timdel, c.tolerance)
            np.testing.assert_array_equal(f.A, ref.A)
            np.testing.assert_array_equal(f.C, ref.C)
            assert f.error == ref.error <= c.tolerance
    # the runtime (one zip, tests/test_runtime_zip.py): the slave, the physics, the description
    # and the errors, with bytecode
    rt = next(n for n in names if n.startswith("resources/hydrofmu_rt_") and n.endswith(".zip"))
    with zipfile.ZipFile(fmu) as z, zipfile.ZipFile(io.BytesIO(z.read(rt))) as inner:
        runtime = inner.namelist()
    prefix = rt[len("resources/"):-len(".zip")] + "/"
    held = {n[len(prefix):] for n in runtime if n.startswith(prefix) and n.endswith(".py")}
    assert {"__init__.py", "errors.py", "description.py", "fmi/slave.py", "physics/memory.py"} <= held
    assert not any(n.startswith(("scene", "decks/", "cosim/", "bench/", "cli", "assembly", "fmi/build"))
                   for n in held)
    tag = sys.implementation.cache_tag
    assert f"{prefix}physics/__pycache__/memory.{tag}.pyc" in runtime
    # a fresh interpreter instantiates, initialises and steps it without an SVD or scipy
    out = subprocess.run([sys.executable, "-c", FRESH, str(tmp_path), str(fmu)], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    lines = out.stdout.strip().splitlines()
    assert lines[-1] == "False"
    # ... nor pythonfmu's builder (its package __init__ is not run for the slave's imports)
    assert lines[-3:-1] == ["False False", "True"]
