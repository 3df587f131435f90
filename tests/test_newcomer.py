"""What a newcomer runs first: ``python -m hydrofmu``, the example case file."""
import subprocess
import sys

from conftest import ROOT


def test_python_dash_m_runs_the_command_line():
    done = subprocess.run([sys.executable, "-m", "hydrofmu", "run", "--help"], capture_output=True, text=True)
    assert done.returncode == 0 and "usage: hydrofmu run" in done.stdout
    done = subprocess.run([sys.executable, "-m", "hydrofmu", "nonsense"], capture_output=True, text=True)
    assert done.returncode == 2 and "Traceback" not in done.stderr


def test_example_case_file_is_a_valid_batch_of_a_repository_scene():
    from hydrofmu.batch import load_cases
    batch = load_cases(ROOT / "examples" / "cases.toml")
    assert batch.scene == (ROOT / "models" / "moored_barge.toml").resolve()
    assert len(list(batch.cases())) == 3 * 5 + 1
