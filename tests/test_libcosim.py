"""libcosim (Open Simulation Platform) runs the same FMUs with the same results as our
fmpy master in Jacobi mode (libcosim's fixed-step algorithm is a Jacobi scheme)."""
import numpy as np
import pytest

from hydrofmu.cosim import libcosim, master

pytest.importorskip("libcosimpy")


def test_libcosim_equals_fmpy_jacobi(demo_build):
    kw = dict(stop=60.0, step=0.1)
    ours = master.run(demo_build, algorithm="jacobi", progress=False, **kw)
    theirs = libcosim.run(demo_build, algorithm="jacobi", **kw)
    assert theirs.columns == ours.columns
    np.testing.assert_array_equal(theirs.time, ours.time)
    moving = ours["barge_dynamics.position[1]"]
    assert np.ptp(moving) > 0.05  # the barge really moves
    np.testing.assert_allclose(theirs.values, ours.values, rtol=1e-9, atol=1e-9)


def test_osp_system_structure_runs_in_libcosim(demo_build):
    """The OspSystemStructure.xml written by the build is a valid libcosim configuration."""
    from libcosimpy.CosimExecution import CosimExecution
    from libcosimpy.CosimLogging import CosimLogLevel, log_output_level
    log_output_level(CosimLogLevel.WARNING)
    execution = CosimExecution.from_osp_config_file(str(demo_build / "OspSystemStructure.xml"))
    assert execution.num_slaves() == 2
    assert execution.simulate_until(target_time=int(2e9))


def test_gauss_seidel_is_refused_not_switched(demo_build, capsys):
    """libcosim's master is Jacobi: a Gauss–Seidel run (the scene's default or asked for)
    is a clear error (exit 2, one line), not a Jacobi run under the wrong name."""
    from hydrofmu.cli import main
    from hydrofmu.errors import InputError
    for given in (None, "gauss-seidel"):
        with pytest.raises(InputError, match="Jacobi scheme"):
            libcosim.run(demo_build, stop=0.2, algorithm=given)
    code = main(["run", str(demo_build), "--engine", "libcosim", "--algorithm", "gauss-seidel", "--stop", "0.2"])
    err = capsys.readouterr().err
    assert code == 2 and err.startswith("error: --algorithm: algorithm:") and "--algorithm jacobi" in err
    assert main(["run", str(demo_build), "--engine", "libcosim", "--algorithm", "jacobi", "--stop", "0.2"]) == 0
