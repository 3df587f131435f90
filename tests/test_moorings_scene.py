"""scene/moorings.py: ``[moorings.NAME]`` read and checked against the scene.  Every bad input
is one error naming both sides: the MoorDyn file's line and the scene's key path."""
import math
import warnings

import pytest

from conftest import MODELS, write_scene
from moordyn_files import moordyn_file

pytest.importorskip("moordyn", reason="needs the moordyn package (pip install hydrofmu[mooring])")

from hydrofmu.errors import InputError, InputWarning  # noqa: E402
from hydrofmu.scene import load_scene  # noqa: E402

DEPTH = 50.0


def lines_file(kind="point", length=120.0, options=((0.005, "dtM"), (DEPTH, "WtrDpth")), body_mass=0.0,
               anchor_z=-DEPTH):
    """Three lines at 120° from a hull at the origin: fairleads as coupled points (IDs 2, 4, 6)
    or as Body1 points of a coupled body; anchors (IDs 1, 3, 5) 100 m out."""
    points, lines = [], []
    for k in range(3):
        c, s = math.cos(2 * math.pi * k / 3), math.sin(2 * math.pi * k / 3)
        points.append(("Fixed", 102 * c, 102 * s, anchor_z))
        points.append(("Coupled" if kind == "point" else "Body1", 2 * c, 2 * s, -5.0))
        lines.append((2 * k + 1, 2 * k + 2, length, 8, "-"))
    bodies = [("Coupled", 0, 0, 0, 0, 0, 0, body_mass, 0)] if kind == "body" else ()
    return moordyn_file(points, lines, list(options), bodies=bodies)


POINTS = '{ Point2 = "hull", Point4 = "hull", Point6 = "hull" }'


def scene(tmp_path, deck=None, bodies=POINTS, extra="", waves="", name="lines.dat"):
    (tmp_path / name).write_text(deck if deck is not None else lines_file())
    return write_scene(tmp_path, f"""
        [bodies.hull]
        mass = 2.0e6
        inertia = [1.0e8, 1.0e8, 1.0e8]
        {waves}
        [moorings.spread]
        moordyn = "{name}"
        bodies = {bodies}
        {extra}
        """)


def row(text, *words):
    """The 1-based line of ``text`` whose words start with ``words``."""
    return next(i for i, t in enumerate(text.splitlines(), 1) if t.split()[:len(words)] == list(words))


def refused(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", InputWarning)
        with pytest.raises(InputError) as exc:
            load_scene(path)
    return str(exc.value)


def test_a_spread_on_coupled_points_and_one_on_a_coupled_body(tmp_path):
    """The couplings: each coupled point on the hull at its offset (file coordinates less the
    hull's initial position, in its axes); a coupled body as it is; the copy hydrofmu runs sets
    external water kinematics and the scene's water; the scene says the lines are not built yet."""
    with pytest.warns(InputWarning, match="not yet built"):
        s = load_scene(scene(tmp_path))
    spec = s.moorings["spread"]
    assert [(c.kind, c.id, c.body) for c in spec.couplings] == [("point", 2, "hull"), ("point", 4, "hull"),
                                                                   ("point", 6, "hull")]
    assert spec.couplings[1].offset == pytest.approx((-1.0, math.sqrt(3), -5.0))
    assert spec.lines == (1, 2, 3) and spec.depth == DEPTH
    for option in ("1  wavekin", "1025.0  rho", "9.81  g", "50.0  wtrdpth"):
        assert option in spec.text
    body = tmp_path / "b"
    body.mkdir()
    with pytest.warns(InputWarning):
        s = load_scene(scene(body, lines_file("body"), '{ Body1 = "hull" }'))
    assert [(c.kind, c.id, c.body) for c in s.moorings["spread"].couplings] == [("body", 1, "hull")]


def test_a_moordyn_error_keeps_its_message_and_names_the_users_line(tmp_path):
    """An unknown line type: MoorDyn's own message, at the line of the user's file (hydrofmu's
    copy adds option lines before it)."""
    deck = lines_file().replace("2     chain", "2     chian")
    text = refused(scene(tmp_path, deck))
    row = next(i for i, t in enumerate(deck.splitlines(), 1) if "chian" in t)
    assert f"lines.dat:{row}:" in text and "Unrecognized line type chian" in text
    assert "moorings.spread.moordyn" in text and "/project/source" not in text


POINT = {k: row(lines_file(), str(k)) for k in (5, 6)}


@pytest.mark.parametrize("bodies, says", [
    ('{ Point2 = "hull", Point4 = "hull" }', f"Point6 (lines.dat:{POINT[6]}) is coupled (moved by hydrofmu) but on no body"),
    ('{ Point2 = "hull", Point4 = "hull", Point6 = "barge" }', "moorings.spread.bodies.Point6: 'barge' is not a body"),
    ('{ Point2 = "hull", Point4 = "hull", Point6 = "hull", Point5 = "hull" }',
     f"moorings.spread.bodies.Point5: Point5 is Fixed (lines.dat:{POINT[5]})"),
    ('{ Point2 = "hull", Point4 = "hull", Point6 = "hull", Body1 = "hull" }',
     "moorings.spread.bodies.Body1: Body1 is not in lines.dat"),
    ('{ Point2 = "hull", Point4 = "hull", Fairlead6 = "hull" }', "expected Body<ID>"),
], ids=["fairlead on no body", "body the scene lacks", "not coupled", "not in the file", "not an object"])
def test_the_coupled_objects_and_the_scene_bodies_match(tmp_path, bodies, says):
    text = refused(scene(tmp_path, bodies=bodies))
    assert says in text and "; moorings" not in text, text   # one problem


@pytest.mark.parametrize("options, waves, says", [
    (((DEPTH, "WtrDpth"),), "[waves]\nspectrum = \"regular\"\nheight = 1.0\nperiod = 8.0\ndepth = 60.0",
     "{WtrDpth}: WtrDpth 50 m but waves.depth = 60 m in the scene"),
    (((DEPTH, "WtrDpth"),), "[waves]\nspectrum = \"jonswap\"\nhs = 2.0\ntp = 10.0",
     "{WtrDpth}: WtrDpth 50 m but the scene's waves are deep-water (no waves.depth) and its longest"),
    (((DEPTH, "WtrDpth"), (1000.0, "rho")), "", "{rho}: rho 1000 in the MoorDyn file but environment.rho"),
    (((DEPTH, "WtrDpth"), (7, "WaveKin")), "", "{WaveKin}: WaveKin 7 makes MoorDyn draw its own waves"),
    (((DEPTH, "WtrDpth"), (1, "Currents")), "", "{Currents}: Currents 1 is MoorDyn's own current"),
    (((30.0, "WtrDpth"),), "", "{anchor}: an anchor at z = -50 m is below the bed (WtrDpth 30 m)"),
], ids=["depth", "deep-water waves, shallow bed", "rho", "second sea", "second current", "anchor below the bed"])
def test_one_sea_one_water_one_bed(tmp_path, options, waves, says):
    """One error each, naming the file's line and the scene's key (an anchor below the bed: one
    per anchor)."""
    deck = lines_file(options=options)
    at = {name: f"lines.dat:{row(deck, str(value), name)}" for value, name in options}
    at["anchor"] = f"lines.dat:{row(deck, '1', 'Fixed')}"
    text = refused(scene(tmp_path, deck, waves=waves))
    assert says.format(**at) in text and text.count("moorings.spread.moordyn") == text.count("lines.dat:"), text
    assert text.count("lines.dat:") == (3 if "anchor" in says else 1), text


def test_deep_water_waves_over_a_deep_enough_bed_are_one_sea(tmp_path):
    """Deep-water waves (no waves.depth) over a bed deeper than half the longest wave: accepted."""
    with pytest.warns(InputWarning, match="not yet built"):
        load_scene(scene(tmp_path, waves="[waves]\nspectrum = \"regular\"\nheight = 1.0\nperiod = 4.0"))


def test_a_coupled_body_with_a_mass_of_its_own_is_refused(tmp_path):
    deck = lines_file("body", body_mass=5.0e4)
    text = refused(scene(tmp_path, deck, '{ Body1 = "hull" }'))
    assert f"moorings.spread.bodies.Body1: lines.dat:{row(deck, '1', 'Coupled')}: Body1 is coupled to the scene body 'hull' but has Mass" in text


def test_a_line_far_shorter_than_its_span_is_refused_a_little_shorter_is_taut(tmp_path):
    """The lines' ends are √(100² + 45²) = 109.66 m apart: 80 m would stretch 37 % (an error),
    108 m 1.5 % (a warning with the tension EA·strain at least, 153.6 kN)."""
    deck = lines_file(length=80.0)
    text = refused(scene(tmp_path, deck))
    assert f"lines.dat:{row(deck, '1', 'chain')}: line 1 is 80 m long (UnstrLen) but its ends are 109.659" in text
    assert "stretch 37.1 %, beyond any mooring line" in text
    with pytest.warns(InputWarning, match=r"line 1 is 108 m long.*taut, stretched 1.54 %.*EA·strain = 153.6 kN"):
        load_scene(scene(tmp_path, lines_file(length=108.0)))


def test_lengths_replace_the_files_unstretched_lengths(tmp_path):
    """``lengths`` (a batch knob) sets UnstrLen in the copy hydrofmu runs; a line the file lacks,
    or one then too short, is an error naming the knob."""
    with pytest.warns(InputWarning, match="not yet built"):
        spec = load_scene(scene(tmp_path, extra="lengths = { 2 = 130.0 }")).moorings["spread"]
    assert spec.lengths == {2: 130.0}
    copied = [t for t in spec.text.splitlines() if t.split()[:2] == ["2", "chain"]][0]
    assert copied.split()[4] == "130.0"
    text = refused(scene(tmp_path, extra="lengths = { 7 = 130.0 }"))
    assert "moorings.spread.lengths.7: lines.dat has no line 7 (its lines: 1, 2, 3)" in text
    text = refused(scene(tmp_path, extra="lengths = { 3 = 60.0 }"))
    assert f"moorings.spread.lengths.3: lines.dat:{row(lines_file(), '3', 'chain')}: line 3 is 60 m long" in text


def test_a_mooring_name_that_is_a_body_name_is_refused(tmp_path):
    path = scene(tmp_path)
    path.write_text(path.read_text().replace("[moorings.spread]", "[moorings.hull]"))
    assert "moorings.hull: mooring name must be an identifier that is not a body's name" in refused(path)


def test_the_worked_models_lines(tmp_path):
    """models/decks/cylinder_lines.dat on models/moored_cylinder.toml's cylinder, in its sea
    (deep-water JONSWAP of Tp 6 s over the file's 70 m bed: one sea): read without a warning
    of its own; its surge stiffness at rest (MoorDyn's equilibria 2 m either side) within
    15 % of the linear spring the scene has today, so that the surge period
    2π·√((m + A11)/k) stays near 100 s (m + A11 = 91 t: A11 of cylinder_drift.nc at 0.3 rad/s)."""
    import tomllib
    import numpy as np
    from hydrofmu.physics.mooring import Mooring
    from hydrofmu.physics.state import Motion
    model = tomllib.loads((MODELS / "moored_cylinder.toml").read_text())
    cyl, sea = model["bodies"]["cyl"], model["waves"]
    path = write_scene(tmp_path, f"""
        [bodies.cyl]
        position = {cyl["position"]}
        attitude = {cyl["attitude"]}
        mass = {cyl["mass"]}
        inertia = {cyl["inertia"]}
        [waves]
        spectrum = "{sea["spectrum"]}"
        hs = {sea["hs"]}
        tp = {sea["tp"]}
        [moorings.spread]
        moordyn = "{MODELS / 'decks' / 'cylinder_lines.dat'}"
        bodies = {{ Body1 = "cyl" }}
        """)
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always", InputWarning)
        spec = load_scene(path).moorings["spread"]
    assert [str(w.message) for w in said if "moorings.spread" in str(w.message)] == []
    loads = []
    # the offsets' equilibria to 1 % (the file's 0.1 % costs seconds each; k moves by 1.5 %)
    text = spec.text.replace("1.0e-3    threshIC", "1.0e-2    threshIC")
    assert text != spec.text
    with Mooring(text, spec.couplings) as m:
        for x in (-2.0, 2.0):
            loads.append(m.start(0.0, {"cyl": Motion(np.array([x, 0.0, 0.0]), np.zeros(3), np.zeros(6))})["cyl"])
        tension = m.tensions()[0]
    k = -(loads[1][0] - loads[0][0]) / 4.0
    spring = cyl["stiffness"][0]
    assert spring == 360.0 and abs(k / spring - 1) < 0.15, k
    assert 2 * math.pi * math.sqrt(91e3 / k) == pytest.approx(100.0, rel=0.1)
    assert np.all((tension > 5e3) & (tension < 1e4))   # a few kN: light chain on a 51 t buoy
