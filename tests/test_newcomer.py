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


def test_demo_outside_the_repository_finds_its_scenes_or_says_what_to_do(tmp_path, monkeypatch, capsys):
    from hydrofmu import cli
    monkeypatch.chdir(tmp_path)                    # no models/ here
    assert cli.scenes_in([]) == sorted((ROOT / "models").glob("*.toml"))
    monkeypatch.setattr(cli, "REPO_MODELS", tmp_path / "nowhere")
    assert cli.main(["demo"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and "models: models:" not in err
    assert err.startswith(f"error: {tmp_path / 'models'}: scenes: no scene files (*.toml) here")
    assert not (tmp_path / "build").exists()


def test_plot_panels_say_zero_and_clipping_where_they_cover_nothing():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from hydrofmu.cosim.report import _panel
    t = np.linspace(0, 100, 1001)
    fig, (zero, clipped) = plt.subplots(1, 2)
    _panel(zero, t, [("drag", 2, np.zeros_like(t)), ("total", 2, np.zeros_like(t))], "yaw moment Mz [kN·m]", {})
    assert [x.get_text() for x in zero.texts] == ["zero throughout"] and list(zero.get_yticks()) == [0]
    spike = np.where(t < 2, -700.0, 50.0 + np.sin(t))
    _panel(clipped, t, [("drag", 0, spike)], "Fx [kN]", {})
    assert not clipped.texts                                   # no box over the data or the ticks
    title = clipped.get_title()
    assert title.startswith("Fx [kN]\naxis clipped to the settled run; data span -700") and clipped.get_ylim()[0] > -700
    plt.close(fig)
