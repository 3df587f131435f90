"""What a newcomer runs first: ``python -m hydrofmu``, the example case file."""
import subprocess
import sys

import pytest

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


def test_plot_panels_say_clipping_where_they_cover_nothing():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    from hydrofmu.cosim.report import Block, _whole
    t = np.linspace(0, 100, 1001)
    fig, clipped = plt.subplots()
    spike = np.where(t < 2, -700.0, 50.0 + np.sin(t))
    _whole(clipped, t, Block("Fx", "kN", [("drag", "C0", spike, False)]), None, False)
    assert not clipped.texts                                   # no box over the data or the ticks
    title = clipped.get_title(loc="left")
    assert title.startswith("Fx\naxis clipped to the settled run; data span -700") and clipped.get_ylim()[0] > -700
    assert clipped.get_ylabel() == "[kN]"
    plt.close(fig)


def _figures(monkeypatch):
    """The figures a plot function makes (kept open instead of closed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    figs = []
    monkeypatch.setattr(plt, "close", lambda fig=None: figs.append(fig))
    return figs


def test_batch_polar_plot_has_units_and_one_legend_off_the_panels(tmp_path, monkeypatch):
    import pandas as pd
    from hydrofmu.batch import load_cases, plot
    batch = load_cases({"scene": str(ROOT / "models" / "moored_barge.toml"), "outputs": ["barge.force[1]"],
                        "matrix": {"environment.current_speed": [0.5, 1.0],
                                   "environment.current_direction": [0.0, 90.0, 180.0]}}, tmp_path)
    rows = [{"environment.current_speed": s, "environment.current_direction": d, "status": "ok",
             "barge.force[1].max": s * 1e3, "barge.force[1].min": -s * 1e3} for s in (0.5, 1.0) for d in (0, 90, 180)]
    # a single case after the matrix that does not set the direction (NaN in the table)
    rows.append({"environment.current_speed": 1.0, "environment.current_direction": float("nan"), "status": "ok",
                 "barge.force[1].max": 5.0, "barge.force[1].min": 0.0})
    figs = _figures(monkeypatch)
    plot(pd.DataFrame(rows), batch, tmp_path / "cases.png", {"barge.force[1]": "N"})
    (fig,) = figs
    ax = fig.axes[0]
    assert ax.get_title() == "max |barge.force[1]| [kN]" and ax.get_legend() is None   # the run plots' unit
    (legend,) = fig.legends
    assert legend.get_title().get_text() == "environment.current_speed [m/s]"
    # the radial values in the sector without data (0–180° used: at 270°), not over the lines
    assert ax.get_rlabel_position() == 270.0
    assert [t.get_text() for t in legend.get_texts()] == ["0.5", "1.0"]
    # the legend sits below every panel
    fig.canvas.draw()
    assert legend.get_window_extent().y1 <= min(a.get_window_extent().y0 for a in fig.axes)


def test_batch_columns_are_the_knobs_as_written_and_poses_plot_without_their_offset(tmp_path, monkeypatch):
    """Knobs given as ``hs`` and ``wave_direction`` are the table's columns and the plot's names
    (not waves.hs, waves.direction); a reference point 6 m below the waterline heaving ±0.5 m
    plots as 0.5 m, not 6.5 m (its initial value taken off), a load as it is."""
    import pandas as pd
    from hydrofmu.batch import assemble_table, load_cases, plot
    batch = load_cases({"scene": str(ROOT / "models" / "buoy_in_waves.toml"),
                        "outputs": ["buoy_dynamics.position[3]", "buoy.force[3]"],
                        "matrix": {"hs": [1.0, 2.0], "wave_direction": [0.0, 90.0]}}, tmp_path)
    assert batch.keys == ["waves.hs", "waves.direction"] and batch.column("waves.direction") == "wave_direction"
    import json
    (tmp_path / "cases").mkdir()
    ids = []
    for hs in (1.0, 2.0):
        for d in (0.0, 90.0):
            cid = f"c{int(hs)}{int(d)}"
            ids.append(cid)
            stats = {"buoy_dynamics.position[3].max": -6.0 + hs / 2, "buoy_dynamics.position[3].min": -6.0 - hs / 2,
                     "buoy_dynamics.position[3].initial": -6.0,
                     "buoy.force[3].max": 1e3 * hs, "buoy.force[3].min": -2e3 * hs, "buoy.force[3].initial": 0.0}
            (tmp_path / "cases" / f"{cid}.json").write_text(json.dumps(
                {"case": cid, "knobs": {"waves.hs": hs, "waves.direction": d}, "status": "ok", "error": None,
                 "wall_s": 1.0, "stats": stats, "build": "b"}))
    figs = _figures(monkeypatch)
    table = assemble_table(tmp_path, ids, batch, {"buoy_dynamics.position[3]": "m", "buoy.force[3]": "N"})
    assert list(table.columns[:2]) == ["hs", "wave_direction"] and "waves.hs" not in table.columns
    figs.clear()
    plot(table, batch, tmp_path / "again.png", {"buoy_dynamics.position[3]": "m", "buoy.force[3]": "N"})
    (fig,) = figs
    pose, load = fig.axes[:2]
    assert pose.get_title() == "max |buoy_dynamics.position[3] − initial| [m]"
    assert load.get_title() == "max |buoy.force[3]| [kN]"
    assert sorted(max(line.get_ydata()) for line in pose.get_lines()) == [0.5, 1.0]   # not 6.5 and 7
    assert sorted(max(line.get_ydata()) for line in load.get_lines()) == [2.0, 4.0]   # kN, as the run plots say
    assert fig._suptitle.get_text().startswith("buoy_in_waves: largest value per case against wave_direction")
    assert fig.legends[0].get_title().get_text().startswith("hs")


def test_bem_quality_plot_has_y_units_and_readable_text(tmp_path, monkeypatch):
    from hydrofmu.bem import couplings, plot_quality
    from hydrofmu.decks.bem import read_bem
    data = read_bem(ROOT / "tests" / "data" / "bem" / "cylinders.nc")
    made = couplings(data, {b: b for b in data.bodies}, ["Sway", "Roll"])   # 4 dofs: each kind of pair
    figs = _figures(monkeypatch)
    plot_quality(made, tmp_path / "q.png")
    (fig,) = figs
    labels = {(a.get_title().split("\n")[0], a.get_ylabel()) for a in fig.axes if a.get_visible()}
    assert ("A: cyl1__Sway, cyl1__Sway", "A [kg]") in labels
    assert ("B: cyl1__Roll, cyl1__Roll", "B [kg·m²/s]") in labels
    assert ("A: cyl1__Sway, cyl1__Roll", "A [kg·m]") in labels
    assert min(a.title.get_fontsize() for a in fig.axes) >= 9


def test_a_missing_cross_compiler_skips_on_a_fresh_machine_and_fails_in_ci(tmp_path, monkeypatch):
    """A machine with Python and cc only (the README's prerequisites): a test that needs
    mingw-w64 or wine is skipped with its reason in one line; in CI (CI=true, .ci/run
    installs them) the same test fails."""
    from conftest import tools
    monkeypatch.setenv("PATH", str(tmp_path))   # nothing to be found
    monkeypatch.delenv("CI", raising=False)
    with pytest.raises(pytest.skip.Exception) as skipped:
        tools("wine", "x86_64-w64-mingw32-gcc", why="the win64 DLL run under wine")
    reason = str(skipped.value)
    assert "\n" not in reason and reason.startswith("needs wine and x86_64-w64-mingw32-gcc (the win64 DLL")
    monkeypatch.setenv("CI", "true")
    with pytest.raises(pytest.fail.Exception) as failed:
        tools("wine", why="the win64 DLL run under wine")
    assert str(failed.value).startswith("CI=true but needs wine")
    assert "export CI=true" in (ROOT / ".ci" / "run").read_text()
