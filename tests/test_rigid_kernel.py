"""The rigid-body kernel in C (physics/rigid.c) against its reference, the Python equations
of physics/rigid_body.py: the same steps to round-off for coupled bodies with CoG offsets,
full inertia tensors and cross added mass, under held and linearly varying loads, in one
RK4 step and in RK6 substeps; its failures end in the Python path's errors; without a
compiler everything runs in Python; a built dynamics FMU carries the compiled kernel and
uses it in a fresh process that has no compiler."""
import os
import subprocess
import sys
import zipfile

import numpy as np
import pytest

from hydrofmu.errors import InputError
from hydrofmu.physics import rigid_kernel
from hydrofmu.physics.rigid_body import CoupledBodies, GimbalLockError, RigidBody

from conftest import ROOT, STEP_ONCE

if rigid_kernel.library() is None:
    pytest.skip("no C compiler for the rigid-body kernel", allow_module_level=True)


def body(rng, cog=True):
    off = rng.normal(0.0, 2e7, (3, 3))
    return RigidBody(mass=1.2e7, inertia=np.diag([5e9, 1.1e10, 1.2e10]) + (off + off.T) * (1.0 if cog else 0.0),
                     cog=rng.normal(0.0, 2.0, 3) if cog else None,
                     stiffness=np.diag([2e5, 3e5, 2.5e7, 9.9e8, 2e10, 5e8]) + rng.normal(0.0, 1e4, (6, 6)),
                     damping=np.diag([1e5, 1e5, 1e4, 1e6, 1e6, 1e8]),
                     added_mass=np.diag([1e6, 2e6, 3e6, 1e8, 2e9, 1e9]) + rng.normal(0.0, 1e4, (6, 6)),
                     attitude0=rng.normal(0.0, 0.1, 3), velocity0=rng.normal(0.0, 0.2, 6), max_substep=0.02)


def history(kernel, n, cog, dt, linear, steps=30):
    """States and accelerations after each step of n coupled bodies (seeded: the same
    bodies for both kernels)."""
    rng = np.random.default_rng(7)
    bodies = [body(rng, cog) for _ in range(n)]
    cross = {(i, j): rng.normal(0.0, 1e5, (6, 6)) for i in range(n) for j in range(n) if i != j}
    group = CoupledBodies(bodies, cross)
    if not kernel:
        group._eq.kernel = None
    assert (group._eq.kernel is not None) == kernel
    out = []
    for k in range(steps):
        load = 1e6 * np.sin(0.4 * k + np.arange(6 * n))
        rate = 1e5 * np.cos(np.arange(6 * n)) if linear else None
        acc = group.step(dt, load.reshape(n, 6), rate)
        out.append(np.concatenate([group.y, acc.ravel()]))
    return np.array(out)


@pytest.mark.parametrize("n, cog", [(1, True), (2, True), (3, False)])
@pytest.mark.parametrize("dt", [0.02, 0.25])          # one RK4 step; RK6 in 3 substeps
@pytest.mark.parametrize("linear", [False, True])
def test_kernel_steps_equal_the_python_equations(n, cog, dt, linear):
    c, py = history(True, n, cog, dt, linear), history(False, n, cog, dt, linear)
    assert np.ptp(py[:, 3:6], axis=0).max() > 1e-3    # the attitudes moved: rotation terms count
    worst = (np.abs(c - py) / np.abs(py).max(axis=0)).max()   # per column, relative to its size
    assert worst < 1e-11


def test_kernel_failures_end_in_the_python_errors():
    tipping = RigidBody(mass=1.0, inertia=np.eye(3), attitude0=[0.0, 1.5, 0.0],
                        velocity0=[0.0, 0.0, 0.0, 0.0, 2.0, 0.0], max_substep=0.01)
    assert tipping._eq.kernel is not None
    with pytest.raises(GimbalLockError, match="pitch"):
        for _ in range(100):
            tipping.step(0.05, np.zeros(6))
    a = np.zeros((6, 6))
    a[5, 5] = -1.0   # cancels the yaw inertia: M_rb + A singular
    flat = RigidBody(mass=1.0, inertia=np.eye(3), added_mass=a)
    with pytest.raises(InputError, match="singular"):
        flat.step(0.05, np.ones(6))


def test_without_a_compiler_everything_runs_in_python(tmp_path, monkeypatch):
    monkeypatch.setattr(rigid_kernel, "_lib", [])
    monkeypatch.setenv("HYDROFMU_CACHE", str(tmp_path / "empty-cache"))
    monkeypatch.setenv("PATH", str(tmp_path / "no-bin"))
    monkeypatch.delenv("CC", raising=False)
    assert rigid_kernel.library() is None
    rng = np.random.default_rng(3)
    plain = body(rng)
    assert plain._eq.kernel is None
    monkeypatch.setattr(rigid_kernel, "_lib", [])
    monkeypatch.setenv("HYDROFMU_KERNEL", "python")   # the switch, whatever the cache holds
    assert rigid_kernel.library() is None
    monkeypatch.setattr(rigid_kernel, "_lib", [])
    monkeypatch.undo()
    with_c = body(np.random.default_rng(3))
    assert with_c._eq.kernel is not None
    for k in range(20):
        load = 1e6 * np.sin(k + np.arange(6))
        np.testing.assert_allclose(plain.step(0.05, load), with_c.step(0.05, load), rtol=1e-11, atol=1e-300)


FRESH = """
import sys
FMU = sys.argv[1]
""" + STEP_ONCE + """
kernel = [m for name, m in sys.modules.items() if name.endswith(".physics.rigid_kernel")]
lib = kernel[0]._lib[0]
print(lib is not None and lib._name == str(kernel[0].BUILT))
s.terminate()
s.freeInstance()
import shutil
shutil.rmtree(unzipped)
"""


def test_a_dynamics_fmu_carries_the_kernel_and_uses_it_without_a_compiler(tmp_path):
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    folder = build_scene(load_scene(ROOT / "models" / "side_by_side.toml"), tmp_path, log=lambda *_: None)
    fmu = folder / "side_by_side_barge_a_barge_b_dynamics.fmu"
    with zipfile.ZipFile(fmu) as z:
        assert any(n.endswith("/physics/_rigid.so") for n in z.namelist())
    env = dict(os.environ, PATH=str(tmp_path / "no-bin"), HYDROFMU_CACHE=str(tmp_path / "empty-cache"))
    env.pop("CC", None)
    out = subprocess.run([sys.executable, "-c", FRESH, str(fmu)], capture_output=True, text=True,
                         timeout=120, env=env)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True"]
    assert not (tmp_path / "empty-cache").exists()   # nothing compiled
