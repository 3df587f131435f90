"""A bad-input corpus tried as a new user would (issue 22's hidden corpus, played again):
each slip here once ran to the end without a word or ended in exit 3; now it is one clear
error (exit 2, the file and the field named, nothing written) before any work starts."""
import shutil

import pytest

from hydrofmu import cli
from hydrofmu.batch import check_knobs, load_cases
from hydrofmu.errors import InputError

from conftest import MODELS, ROOT

BEM = ROOT / "tests" / "data" / "bem" / "cylinders.nc"


@pytest.fixture
def barge(tmp_path):
    """The demo scene and its decks in a scratch folder (outputs may land beside them)."""
    shutil.copytree(MODELS, tmp_path / "models")
    return tmp_path / "models" / "moored_barge.toml"


def refused(capsys, argv):
    """Run the CLI; it must exit 2 with one ``error:`` line; returns that line."""
    code = cli.main([str(a) for a in argv])
    err = capsys.readouterr().err
    lines = [line for line in err.splitlines() if line.startswith("error:")]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    return lines[0]


# --- outputs: never over an input, never two in one file, a plot in a format it can be ----

def test_run_output_over_the_scene_or_a_deck_is_refused_before_the_build(barge, capsys):
    scene, deck = barge.read_bytes(), (barge.parent / "decks" / "barge_viscous.aqwa").read_bytes()
    out = barge.parent / "out"
    for target in (barge, barge.parent / "decks" / "barge_viscous.aqwa"):
        line = refused(capsys, ["run", barge, "-o", out, "--csv", target])
        assert f"{target.name}: output file: is the input file" in line
    assert barge.read_bytes() == scene and (barge.parent / "decks" / "barge_viscous.aqwa").read_bytes() == deck
    assert not out.exists()   # nothing built


def test_run_output_inside_the_built_folder_is_refused(barge, capsys):
    out = barge.parent / "out"
    line = refused(capsys, ["run", barge, "-o", out, "--csv", out / "moored_barge" / "manifest.json"])
    assert "output file: lies inside the input folder" in line and not out.exists()


def test_run_plot_suffix_is_checked_before_the_run(barge, capsys):
    out = barge.parent / "out"
    for png, said in (("plot.txt", "suffix '.txt'"), ("plot", "no suffix")):
        line = refused(capsys, ["run", barge, "-o", out, "--png", barge.parent / png])
        assert f"{png}: plot file: {said}" in line and ".png" in line and ".pdf" in line
    assert not out.exists()


def test_run_two_outputs_in_one_file_are_refused(barge, capsys):
    same = barge.parent / "same.png"
    line = refused(capsys, ["run", barge, "-o", barge.parent / "out", "--csv", same, "--png", same])
    assert "same.png: output file: two outputs of the command go to this one file" in line


def test_bem2simo_never_writes_over_its_bem_result(tmp_path, capsys):
    result = tmp_path / "cylinders.nc"
    shutil.copy(BEM, result)
    before = result.read_bytes()
    line = refused(capsys, ["bem2simo", result, "-o", result])
    assert "cylinders.nc: output file: is the input file" in line
    line = refused(capsys, ["bem2simo", result, "-o", tmp_path / "c.sim", "--png", tmp_path / "c.sim"])
    assert "plot file: suffix '.sim'" in line
    assert result.read_bytes() == before and not (tmp_path / "c.sim").exists()


def test_result_plot_refuses_a_format_it_cannot_write(tmp_path):
    from hydrofmu.cosim.result import Result
    import numpy as np
    r = Result(np.array([0.0, 0.1]), ["a.b"], np.zeros((2, 1)), "jacobi", 0.1, manifest={"fmus": []})
    with pytest.raises(InputError, match=r"plot file: suffix '\.csv'"):
        r.plot(tmp_path / "x.csv")


# --- batches: what every case would trip over is said once, up front --------------------

BASE = f"""scene = "{(MODELS / 'moored_barge.toml').as_posix()}"
stop = 30.0
outputs = ["barge_dynamics.position[1]", "barge.force[1]"]
"""


@pytest.mark.parametrize("extra, field, said", [
    ("transient = 30.0\n", "transient", "30 s leaves nothing of a case that ends at 30 s"),
    ('transient = 20.0\n[[cases]]\n"run.stop" = 10.0\n', "transient", "leaves nothing of a case that ends at 10 s"),
    ('[matrix]\n"environment.current_speed" = [0.5, 1.0, 0.5]\n', "matrix.environment.current_speed",
     "value 0.5 given twice"),
    ('[set]\n"run.algorithm" = "ecco"\n', "set.run.algorithm", "found 'ecco'"),
    ('[[cases]]\n"run.algorithm" = "ecco"\n', "cases[0].run.algorithm", "found 'ecco'"),
])
def test_batch_slips_refused_before_any_case(tmp_path, extra, field, said):
    cases = tmp_path / "cases.toml"
    cases.write_text(BASE + extra)
    with pytest.raises(InputError) as err:
        check_knobs(load_cases(cases))
    assert err.value.path == str(cases) and err.value.field == field and said in err.value.message


def test_batch_output_given_twice_is_refused(tmp_path):
    cases = tmp_path / "cases.toml"
    cases.write_text(BASE.replace('"barge.force[1]"]', '"barge.force[1]", "barge.force[1]"]'))
    with pytest.raises(InputError, match=r"outputs: 'barge.force\[1\]' given twice"):
        load_cases(cases)


# --- names that become FMU files, instances and variables never meet ----------------------

from hydrofmu.scene import load_scene

HULL = """
[bodies.{name}]
mass = 1.0e5
inertia = [1.0e6, 1.0e6, 1.0e6]
"""
DRAG = """
[[bodies.{body}.effects]]
type = "aqwa_viscous_drag"
name = "{name}"
matrix = [1.0e3, 1.0e3, 1.0e3, 1.0, 1.0, 1.0]
"""


def scene_error(tmp_path, text):
    path = tmp_path / "s.toml"
    path.write_text(text)
    with pytest.raises(InputError) as err:
        load_scene(path)
    return err.value


def test_bodies_differing_only_in_case_are_refused(tmp_path):
    """Barge.fmu and barge.fmu: one file on Windows and macOS."""
    err = scene_error(tmp_path, HULL.format(name="barge") + HULL.format(name="Barge"))
    assert err.field == "bodies.Barge" and "differs from bodies.barge only in case" in err.message


def test_a_body_named_earth_is_refused(tmp_path):
    """b = "earth" is a joint's fixed side: a body of that name made it mean two things."""
    err = scene_error(tmp_path, HULL.format(name="earth"))
    assert err.field == "bodies.earth" and "joint's fixed side" in err.message


def test_effect_named_like_a_joint_or_total_is_refused(tmp_path):
    joint = ('[joints.hitch]\na = "barge"\na_point = [1.0, 0.0, 0.0]\nam = 1.0\nae = 0.0\n'
             'icoo = "GLOBAL"\ncd = [0.0, 0.0, 0.0]\nadded_mass = [0.0, 0.0, 0.0]\ncodes = [0, 0, 0]\n')
    err = scene_error(tmp_path, HULL.format(name="barge") + DRAG.format(body="barge", name="hitch") + joint)
    assert err.field == "bodies.barge.effects[0].name" and "also joint hitch" in err.message
    err = scene_error(tmp_path, HULL.format(name="barge") + DRAG.format(body="barge", name="total"))
    assert err.field == "bodies.barge.effects[0].name" and "two loads total.force" in err.message


def test_effect_named_like_a_coupling_is_refused(tmp_path):
    """Before: a load FMU with two SELFA.force variable groups, built without a word."""
    text = (MODELS / "side_by_side.toml").read_text().replace('symmetry = "xz"', 'symmetry = "xz"\nname = "SELFA"', 1)
    shutil.copytree(MODELS / "decks", tmp_path / "decks")
    err = scene_error(tmp_path, text)
    assert err.field == "bodies.barge_a.effects[0].name" and "also coupling SELFA" in err.message


def test_inline_polar_table_problem_names_the_table_key(tmp_path):
    polar = ('\n[[bodies.barge.effects]]\ntype = "deeplines_current_polar"\npoint = [0.0, 0.0, 0.0]\n'
             'surface = 1.0\ntable = [[0.0, 1.0, 0.0, 0.0], [90.0, 0.0, 1.0, 0.0], [45.0, 1.0, 1.0, 0.0]]\n')
    err = scene_error(tmp_path, HULL.format(name="barge") + polar)
    assert err.field == "bodies.barge.effects[0].table" and err.message.startswith("ANGC: ")


# --- BEM datasets: scalars that would pass every later comparison -------------------------

@pytest.mark.parametrize("name, value, said", [
    ("rho", float("nan"), "rho: must be a positive finite number, found nan"),
    ("rho", 0.0, "rho: must be a positive finite number, found 0"),
    ("g", float("nan"), "g: must be a positive finite number"),
    ("water_depth", -10.0, "water_depth: must be positive (inf: deep water), found -10"),
])
def test_bem_scalars_must_be_physical(tmp_path, name, value, said):
    xr = pytest.importorskip("xarray")
    from hydrofmu.decks.bem import read_bem
    path = tmp_path / "r.nc"
    xr.load_dataset(BEM).assign_coords({name: value}).to_netcdf(path)
    with pytest.raises(InputError) as err:
        read_bem(path)
    assert str(path) in str(err.value) and said in str(err.value)


def test_bem_dataset_with_only_infinite_frequency_is_exit_2(tmp_path, capsys):
    """Before: exit 3 (a max over an empty frequency grid)."""
    xr = pytest.importorskip("xarray")
    path = tmp_path / "r.nc"
    xr.load_dataset(BEM).isel(omega=[-1]).to_netcdf(path)
    line = refused(capsys, ["bem2simo", path, "-o", tmp_path / "r.sim"])
    assert "r.nc: omega: 0 finite frequencies: at least 3 needed" in line
    assert not (tmp_path / "r.sim").exists()


# --- the Python API ------------------------------------------------------------------------

def test_run_parameters_refuse_a_connected_input_and_a_non_number(demo_build):
    """Before: a connected input's value was overwritten by the master at once (the run went
    on without it), a string was passed on, a NaN ended as a run failure at t = 0.  The check
    `run` makes before loading any FMU, on the built folder's manifest."""
    from hydrofmu.cosim.manifest import read_manifest
    from hydrofmu.cosim.master import _check_parameters
    manifest = read_manifest(demo_build)
    with pytest.raises(InputError, match=r"parameters: barge.position\[1\] is an input connected to "
                                         r"barge_dynamics.position\[1\]"):
        _check_parameters({"barge.position[1]": 1.0}, manifest)
    for value in ("1000", float("nan"), True):
        with pytest.raises(InputError, match=r"parameters: barge.rho = .*: expected a finite number"):
            _check_parameters({"barge.rho": value}, manifest)
    _check_parameters({"barge.rho": 1000.0}, manifest)


def test_result_to_csv_on_a_folder_and_vector_of_zero(tmp_path):
    from hydrofmu.cosim.result import Result
    import numpy as np
    r = Result(np.array([0.0, 0.1]), ["a.b[1]"], np.zeros((2, 1)), "jacobi", 0.1)
    with pytest.raises(InputError, match="output file: is a folder, not a file"):
        r.to_csv(tmp_path)
    with pytest.raises(ValueError, match="whole number ≥ 1, found 0"):
        r.vector("a", "b", 0)
    assert r.vector("a", "b").shape == (2, 1)


# --- wave excitation datasets ---------------------------------------------------------------

WAVE = ROOT / "tests" / "data" / "bem" / "wave_cylinder.nc"


@pytest.mark.parametrize("edit, field, said", [
    (lambda d: d.assign_coords(wave_direction=__import__("numpy").degrees(d.wave_direction)), "wave_direction",
     "Capytaine gives directions in radians"),
    (lambda d: d.assign_coords(wave_direction=list(d.wave_direction.values[:-1]) + [d.wave_direction.values[0]]),
     "wave_direction", "a direction given twice"),
    (lambda d: d.sel(complex="re", drop=True), "excitation_force", "the phase is missing"),
    (lambda d: d.assign_coords(g=0.0), "g", "must be a positive finite number, found 0"),
])
def test_wave_excitation_dataset_slips(tmp_path, edit, field, said):
    """Before: directions in degrees read as radians (×57), a heading twice, the real part
    alone (no phase) and g = 0 were all read without a word."""
    xr = pytest.importorskip("xarray")
    from hydrofmu.decks.bem_waves import read_excitation
    path = tmp_path / "w.nc"
    edit(xr.load_dataset(WAVE)).to_netcdf(path)
    with pytest.raises(InputError) as err:
        read_excitation(path)
    assert err.value.path == str(path) and err.value.field == field and said in err.value.message


@pytest.mark.parametrize("options, said", [
    (["--dofs", "Surge", "Surge"], "cylinders.nc: dofs: 'Surge' given twice"),
    (["--ulen", "3"], "cylinders.nc: ulen: applies to a nondimensional WAMIT .1 file only"),
    (["--rho", "1000"], "command line: --rho: applies to a nondimensional WAMIT .1 file only"),
    (["--symmetry-tolerance", "1e9"], "symmetry_tolerance: 1e+09 would accept any matrix"),
])
def test_bem2simo_options_that_would_change_nothing_or_defeat_a_check(tmp_path, capsys, options, said):
    """Before: each ran to exit 0 (a dof twice, WAMIT's scale options on a dataset ignored,
    an A∞ symmetry check that accepts anything)."""
    line = refused(capsys, ["bem2simo", BEM, "-o", tmp_path / "c.sim", *options])
    assert said in line and not (tmp_path / "c.sim").exists()


# --- numbers as Fortran reads them -----------------------------------------------------------

def test_deck_numbers_are_fortran_numbers_not_python_ones():
    """Python's float() reads '20_000' as 20000 and '１２' as 12: no deck writes them, so a
    deck value is refused unless Fortran would read it (D exponents, '.5', '2.' are fine)."""
    from hydrofmu.decks.lines import Line, fields, fortran_float
    assert [fortran_float(w) for w in ("12", "-1.5", ".5", "2.", "+1.5E3", "2.5D+03", "1d-2")] == \
        [12.0, -1.5, 0.5, 2.0, 1500.0, 2500.0, 0.01]
    for word in ("20_000", "0x10", "１２", "1.5E", "--1", "1e5.0"):
        with pytest.raises(InputError, match=f"AM: expected a number, found '{word}'"):
            fields(Line("deck.inp", 7, f"{word} 2.5"), ["AM", "AE"])


# --- a build replaces only a build ----------------------------------------------------------

def test_build_never_replaces_a_folder_that_is_not_a_build(barge, capsys):
    """Before: a scene named like its deck folder, built with -o next to it, had that folder
    (its decks) deleted and replaced by the build, exit 0."""
    folder = barge.parent
    barge.write_text(barge.read_text().replace('name = "moored_barge"', 'name = "decks"'))
    decks = sorted(p.name for p in (folder / "decks").iterdir())
    for extra in (["--check"], []):
        line = refused(capsys, ["build", barge, "-o", folder, *extra])
        assert "decks: output folder: exists and is not a built scene (no manifest.json)" in line
    assert sorted(p.name for p in (folder / "decks").iterdir()) == decks


def test_tune_plot_checked_before_the_search(barge, capsys):
    """Before: `tune --png x.txt` searched for minutes, then ended in exit 3."""
    line = refused(capsys, ["tune", barge, "--png", barge.parent / "x.txt"])
    assert "x.txt: plot file: suffix '.txt'" in line
    line = refused(capsys, ["tune", barge, "--png", barge.parent / "decks" / "barge_viscous.aqwa"])
    assert "plot file: suffix '.aqwa'" in line


def test_added_mass_outweighing_the_body_is_refused(barge, capsys):
    """Before: a self-coupling A∞ surge term of −2e7 kg on a 1.28e7 kg barge (a sign slip)
    built without a word; the total mass matrix is not positive definite."""
    folder = barge.parent
    deck = folder / "decks" / "side_by_side.sim"
    lines = deck.read_text().split("\n")
    assert lines[14].split()[0] == "1.300000e+06"   # SELFA's AM11
    lines[14] = lines[14].replace("1.300000e+06", "-2.000000e+07", 1)
    deck.write_text("\n".join(lines))
    line = refused(capsys, ["build", "--check", folder / "side_by_side.toml"])
    assert "side_by_side.toml: bodies.barge_a: mass + added mass is not positive definite" in line


def test_attitude_in_degrees_is_said_out_loud(tmp_path):
    """attitude is in radians: 90 (a quarter turn in degrees) is 90 rad; legal, so a warning
    naming the key, kept in the scene's warnings for the manifest."""
    from hydrofmu.errors import InputWarning
    path = tmp_path / "s.toml"
    path.write_text(HULL.format(name="barge") + "attitude = [0.0, 0.0, 90.0]\n")
    with pytest.warns(InputWarning, match=r"bodies.barge.attitude: 90 rad is beyond ±2π .* degrees written"):
        scene = load_scene(path)
    assert any("bodies.barge.attitude" in w for w in scene.warnings)


def test_coupling_map_key_naming_no_deck_body_is_refused(tmp_path):
    """Before: `bodies = { BARGEA = "barge_a", BARGE_B = "barge_b" }` mapped nothing with its
    second key, without a word (the body it meant kept its deck name)."""
    shutil.copytree(MODELS / "decks", tmp_path / "decks")
    text = (MODELS / "side_by_side.toml").read_text().replace(
        'bodies = { BARGEA = "barge_a", BARGEB = "barge_b" }', 'bodies = { BARGEA = "barge_a", BARGE_B = "barge_b" }', 1)
    err = scene_error(tmp_path, text)
    assert err.field == "couplings[0].bodies.BARGE_B" and "did you mean 'BARGEB'" in err.message


# --- issue 31's corpus, each by its class ----------------------------------------------------

def wave_scene(folder, waves, bem="wave_cylinder.nc", coupling=False):
    """A floating cylinder of the wave dataset (bench.waves_motions) under ``waves`` ([waves] body)."""
    import xarray as xr
    from hydrofmu.bench.waves_motions import body_table
    data = ROOT / "tests" / "data" / "bem"
    for f in (bem, "wave_cylinder.nc"):
        if not (folder / f).exists():
            shutil.copy(data / f, folder / f)
    m = float(xr.load_dataset(folder / bem)["inertia_matrix"].values[0, 0])
    text = f"[waves]\n{waves}\n" + body_table("cyl", m, 0.0, bem)
    if coupling:
        text += f'\n[[couplings]]\nbem = "{bem}"\nbodies = {{ cyl = "cyl" }}\n'
    path = folder / "w.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("scene_depth, file_depth, said", [
    (None, 50.0, "water depth 50 m in the BEM result but deep water (inf) in the scene"),
    (50.0, float("inf"), "water depth deep water (inf) in the BEM result but 50 m in the scene"),
    (50.0, 60.0, "water depth 60 m in the BEM result but 50 m in the scene"),
])
@pytest.mark.parametrize("coupling", [False, True])
def test_bem_depth_differing_from_the_scene_is_refused(tmp_path, capsys, scene_depth, file_depth, said, coupling):
    """Before: a dataset at 50 m in a scene without depth built as deep water (|50 − ∞| ≤ 1e-6·∞
    holds); the radiation couplings were never compared at all."""
    xr = pytest.importorskip("xarray")
    ds = xr.load_dataset(ROOT / "tests" / "data" / "bem" / "wave_cylinder.nc").assign_coords(water_depth=file_depth)
    ds.to_netcdf(tmp_path / "d.nc")
    if coupling:   # the excitation agrees with the scene: only the coupling's file differs
        shutil.copy(ROOT / "tests" / "data" / "bem" / "wave_cylinder.nc", tmp_path / "wave_cylinder.nc")
    waves = 'spectrum = "regular"\nheight = 1.0\nperiod = 8.0' + ("" if scene_depth is None else f"\ndepth = {scene_depth}")
    if coupling and scene_depth is not None:
        xr.load_dataset(tmp_path / "wave_cylinder.nc").assign_coords(water_depth=scene_depth).to_netcdf(
            tmp_path / "same.nc")
    path = wave_scene(tmp_path, waves, bem="d.nc" if not coupling else
                      ("same.nc" if scene_depth is not None else "wave_cylinder.nc"), coupling=False)
    if coupling:
        path.write_text(path.read_text() + '\n[[couplings]]\nbem = "d.nc"\nbodies = { cyl = "cyl" }\n')
    line = refused(capsys, ["build", "--check", path])
    assert said in line and ("couplings[0].bem" in line if coupling else "effects[0].bem" in line), line


@pytest.mark.parametrize("waves, key, said", [
    ('spectrum = "jonswap"\nhs = 2000.0\ntp = 8.0', "waves.hs", "2000 m is beyond any sea"),
    ('spectrum = "regular"\nheight = 150.0\nperiod = 8.0', "waves.height", "150 m is beyond any sea"),
    ('spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ncomponents = 1e17', "waves.components",
     "1e+17 wave components would need"),
])
def test_sea_values_beyond_any_sea_or_memory_are_exit_2(tmp_path, capsys, waves, key, said):
    """Before: hs = 2000 (mm meant) built without a word; components = 1e17 ended in a
    MemoryError, exit 3.  Now one error naming the key, before anything is allocated."""
    path = wave_scene(tmp_path, waves)
    line = refused(capsys, ["build", "--check", path])
    assert f"{key}: " in line and said in line, line


@pytest.mark.parametrize("waves, key, said", [
    ('spectrum = "regular"\nheight = 1.0\nperiod = 8.0\nhs = 2.0\ntp = 9.0', "waves.hs",
     "hs, tp are not read by spectrum = 'regular'"),
    ('spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\nheight = 1.0', "waves.height", "height is not read by spectrum = 'jonswap'"),
    ('spectrum = "pierson_moskowitz"\nhs = 2.0\ntp = 8.0\ngamma = 2.0', "waves.gamma",
     "gamma is not read by spectrum = 'pierson_moskowitz'"),
    ('spectrum = "regular"\nheight = 1.0\nperiod = 45.0', "waves.period", "45 s is outside 1…40 s"),
    ('spectrum = "regular"\nheight = 6.0\nperiod = 1.6', "waves.height", "steeper than the breaking limit"),
])
def test_sea_keys_ignored_or_odd_are_said(tmp_path, waves, key, said):
    """Before: hs and tp given for a regular wave were ignored without a word."""
    from hydrofmu.errors import InputWarning
    path = wave_scene(tmp_path, waves)
    with pytest.warns(InputWarning) as caught:
        try:
            load_scene(path)
        except InputError:
            pass     # a period outside the transfer functions is the build's error; the warning came first
    assert any(f"{key}: " in str(w.message) and said in str(w.message) for w in caught), [str(w.message) for w in caught]


def test_sea_thresholds_by_hand():
    """The thresholds of admissible.sea_problems at their edges (documented in docs/waves.md)."""
    from hydrofmu.admissible import HS_MAX, sea_problems
    assert sea_problems("jonswap", {"hs": HS_MAX, "tp": 15.0}) == ([], [])
    assert [k for k, _ in sea_problems("jonswap", {"hs": HS_MAX + 0.1, "tp": 15.0})[0]] == ["hs"]
    assert [k for k, _ in sea_problems("jonswap", {"hs": 0.1, "tp": 0.9})[1]] == ["tp"]
    assert sea_problems("jonswap", {"hs": 0.1, "tp": 1.0})[1] == []
    # deep water, T = 2 s: L = g·T²/2π = 6.245 m, the breaking height L/7 = 0.892 m
    assert sea_problems("regular", {"height": 0.89, "period": 2.0})[1] == []
    assert [k for k, _ in sea_problems("regular", {"height": 0.90, "period": 2.0})[1]] == ["height"]


def test_riflex_conb_codes_written_as_words_are_refused(tmp_path):
    """Before: 'FIX FIX FREE' was taken for another data group and skipped: a ball joint
    instead of the hinge written.  The manual's codes are 0 and 1."""
    from hydrofmu.decks.riflex import read_components
    deck = tmp_path / "c.inp"
    for codes, field in (("FIX FIX FREE", "IRX"), ("fixed", "IRX"), ("1 FIX 0", "IRY"), ("0 0 free", "IRZ")):
        deck.write_text(f"NEW COMPonent CONB\nhinge\n100.0 0.1\nGLOBAL 0 0 0 0 0 0\n{codes}\nEND\n")
        with pytest.raises(InputError) as err:
            read_components(deck)
        assert (err.value.path, err.value.line, err.value.field) == (str(deck), 5, field), err.value
    deck.write_text("NEW COMPonent CONB\nhinge\n100.0 0.1\nGLOBAL 0 0 0 0 0 0\n1 1 0\nEND\n")
    assert read_components(deck)["hinge"].codes == (1, 1, 0)


@pytest.mark.parametrize("table, field, said", [
    ('[matrix]\n"environment.current_speed" = [0.5, "fast"]\n', "matrix.environment.current_speed",
     "value 'fast' is not a number"),
    ('[matrix]\n"barge.rho" = ["fast"]\n', "matrix.barge.rho", "value 'fast' is not a number"),
    ('[matrix]\n"bodies.barge.mass" = [1.0e6, "fast"]\n', "matrix.bodies.barge.mass",
     "value 'fast' is a string among numbers"),
    ('[[cases]]\n"barge.rho" = "fast"\n', "cases[0].barge.rho", "value 'fast' is not a number"),
])
def test_batch_value_that_is_not_a_number_is_refused_before_any_case(tmp_path, table, field, said):
    """Before: the cases ran, then writing cases.parquet ended in an ArrowTypeError, exit 3."""
    cases = tmp_path / "cases.toml"
    cases.write_text(BASE + table)
    with pytest.raises(InputError) as err:
        load_cases(cases)
    assert err.value.path == str(cases) and err.value.field == field and said in err.value.message


def test_batch_first_value_the_scene_refuses_is_the_batch_error(tmp_path):
    """A knob value every case would trip over (all strings for a number) is said before any case."""
    cases = tmp_path / "cases.toml"
    cases.write_text(BASE + '[matrix]\n"bodies.barge.mass" = ["fast", "slow"]\n')
    with pytest.raises(InputError) as err:
        check_knobs(load_cases(cases))
    assert err.value.field == "bodies.barge.mass" and "value 'fast'" in err.value.message


def test_run_rows_beyond_memory_are_refused_before_the_run(demo_build, monkeypatch):
    """The rows of a run without a file sink are one array: more than the machine holds is
    an error naming run.stop before it is allocated (was a MemoryError, exit 3)."""
    from hydrofmu import admissible
    from hydrofmu.cosim.master import run
    monkeypatch.setattr(admissible, "memory_bytes", lambda: 1000)
    with pytest.raises(InputError) as err:
        run(demo_build, stop=1.0)
    assert err.value.field == "run.stop" and "output values would need" in err.value.message


def test_components_beyond_the_compiled_limit_are_refused(tmp_path):
    """More components than physics/waves.c takes (1e7) is the scene's error for both flavours."""
    with pytest.raises(InputError) as err:
        load_scene(wave_scene(tmp_path, 'spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ncomponents = 20000000'))
    assert "waves.components: 2e+07 wave components: more than 1e+07" in str(err.value)


@pytest.mark.parametrize("knob, said", [
    ('"waves.hs" = [2.0, 2000.0]', "value 2000.0: 2000 m is beyond any sea"),
    ('"waves.components" = [100, 1.0e17]', "value 1e+17: 1e+17 wave components would need"),
])
def test_batch_sea_knobs_beyond_a_sea_are_refused_before_any_case(tmp_path, knob, said):
    """waves.* knobs are FMU parameters: the scene's checks never see them; the batch checks
    each value against the scene's [waves] before any case runs."""
    shutil.copy(ROOT / "tests" / "data" / "bem" / "wave_cylinder.nc", tmp_path / "wave_cylinder.nc")
    scene = wave_scene(tmp_path, 'spectrum = "jonswap"\nhs = 2.0\ntp = 8.0')
    cases = tmp_path / "cases.toml"
    cases.write_text(f'scene = "w.toml"\nstop = 10.0\noutputs = ["cyl.waves.force[3]"]\n[matrix]\n{knob}\n')
    assert scene.exists()
    with pytest.raises(InputError) as err:
        check_knobs(load_cases(cases))
    assert err.value.field == knob.split('"')[1] and said in err.value.message, err.value
