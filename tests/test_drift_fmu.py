"""The `wave_drift` effect through the load FMU: a body held still in the scene's wave field
feels a²·Q·ρgL^k (regular wave, WAMIT .8), the full QTF of the same components as its
first-order waves (JONSWAP, WAMIT .12d), and bad set-ups are one error naming the key."""
import math
import shutil
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("xarray")

from hydrofmu.cosim import inprocess  # noqa: E402
from hydrofmu.errors import InputError  # noqa: E402
from hydrofmu.physics.drift import QTF, DriftLoad, phasors  # noqa: E402
from hydrofmu.physics.waves import components  # noqa: E402
from hydrofmu.scene import load_scene  # noqa: E402

from test_drift import f8, hermitian_qtf, mean_rows, turned_by_hand, write_12d  # noqa: E402

DATA = Path(__file__).parent / "data" / "bem"
ONE = DATA / "wave_cylinder.nc"
RHO, G, ULEN = 1025.0, 9.81, 2.0
DRIFT_PERIODS = [20.0, 12.0, 10.0, 8.0, 7.0, 6.0, 5.0, 4.0, 3.0, 2.0]


def scene(folder, waves, drift, runtime=None):
    """The wave dataset's cylinder, held (no dynamics run here), with excitation and a
    wave_drift effect (``drift``: its TOML lines)."""
    build = f'[build]\nruntime = "{runtime}"\n' if runtime else ""
    text = f"""{build}
[run]
step = 0.1
stop = 50.0

[waves]
{waves}

[bodies.cyl]
position = [0.0, 0.0, 0.0]
mass = 51190.0
inertia = [2e5, 2e5, 1e5]

[[bodies.cyl.effects]]
type = "wave_excitation"
bem = "wave_cylinder.nc"

[[bodies.cyl.effects]]
type = "wave_drift"
{drift}
"""
    path = Path(folder) / "drift.toml"
    path.write_text(text)
    return path


@pytest.fixture
def folder(tmp_path):
    shutil.copy(ONE, tmp_path / ONE.name)
    (tmp_path / "cyl.8").write_text("".join(mean_rows(DRIFT_PERIODS, [0.0, 45.0], [1, 2, 6], f8)))
    write_12d(tmp_path / "cyl.12d", DRIFT_PERIODS, hermitian_qtf(DRIFT_PERIODS))
    return tmp_path


def held(path, t_end, dt=0.1, knobs=None):
    """drift.force and force of the held body's load FMU: time, (n, 6), (n, 6), the slave."""
    system = inprocess.system(load_scene(path))
    slave = system.instances["cyl"].slave
    vr = {v.name: k for k, v in slave.vars.items()}
    slave.setup_experiment(0.0)
    slave.enter_initialization_mode()
    if knobs:
        slave.set_real([vr[f"waves.{k}"] for k in knobs], list(knobs.values()))
    slave.exit_initialization_mode()
    drift = [vr[f"drift.force[{i}]"] for i in range(1, 7)]
    waves = [vr[f"waves.force[{i}]"] for i in range(1, 7)]
    total = [vr[f"force[{i}]"] for i in range(1, 7)]
    t, rows = 0.0, []
    while t < t_end - 1e-9:
        assert slave.do_step(t, dt)
        t += dt
        d, w, f = slave.get_real(drift), slave.get_real(waves), slave.get_real(total)
        np.testing.assert_allclose(f, np.add(d, w), rtol=1e-12, atol=1e-6)     # held: waves + drift
        rows.append([t] + d)
    rows = np.array(rows)
    return rows[:, 0], rows[:, 1:], slave


REGULAR = 'spectrum = "regular"\nheight = 3.0\nperiod = 9.0\ndirection = 30.0\nramp = 10.0'


@pytest.mark.parametrize("method", ["mean", "newman"])
def test_held_body_in_a_regular_wave_feels_a2_q(folder, method):
    """drift.force = a²·Q(ω, ω; β)·ρgL^k after the ramp (Q interpolated by hand between the
    .8's 10 s and 8 s rows and its 0° and 45° headings, in the frame turning with the heading),
    r(t)² during it."""
    t, d, _ = held(scene(folder, REGULAR, f'bem = "cyl.8"\nulen = {ULEN}\nmethod = "{method}"'), 20.0)
    w = 2 * math.pi / 9.0
    fw = (w - 2 * math.pi / 10) / (2 * math.pi / 8 - 2 * math.pi / 10)
    after = t >= 10.0
    q = turned_by_hand(lambda b: [(1 - fw) * f8(10.0, b, i) + fw * f8(8.0, b, i) for i in (1, 2, 6)], 30.0)
    for c, (i, k) in enumerate(((1, 1), (2, 1), (6, 2))):
        want = 1.5 ** 2 * q[c] * RHO * G * ULEN ** k
        np.testing.assert_allclose(d[after, i - 1], want, rtol=1e-9)
        r = 0.5 * (1 - np.cos(np.pi * t[~after] / 10.0))
        np.testing.assert_allclose(d[~after, i - 1], r ** 2 * want, rtol=1e-9, atol=1e-12 * abs(want))
    assert np.all(d[:, 2:5] == 0.0)


def test_held_body_full_qtf_uses_the_sea_of_its_waves(folder):
    """JONSWAP: drift.force at each step = Σ_ij Re{Q z_i z̄_j} of the components the waves.*
    parameters draw (the same ones as the first-order waves), Q from the .12d; the seed and
    Hs set as parameters after the build change it (no rebuild)."""
    sea = 'spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ncomponents = 40\nseed = 3\nramp = 0.0'
    path = scene(folder, sea, f'bem = "cyl.12d"\nulen = {ULEN}\nmethod = "qtf"')
    t, d, _ = held(path, 30.0, dt=1.0, knobs={"seed": 11.0, "hs": 3.0})
    sc = load_scene(path)
    sc.waves.seed, sc.waves.hs = 11, 3.0
    w = 2 * np.pi / np.array(DRIFT_PERIODS)
    comps = components(sc.waves, (w[0], w[-1]))
    scale = RHO * G * ULEN ** np.array([1, 1, 1, 2, 2, 2])
    q = hermitian_qtf(DRIFT_PERIODS) * scale
    order = np.argsort(w)
    ref = DriftLoad("qtf", comps, QTF(w[order], [(0.0, 0.0)], q[order][:, order][:, :, None, :]))
    for s, row in zip(t, d):
        want = ref(phasors(comps, s))
        # (the .12d holds 7 significant digits: Q to ~1e-7)
        np.testing.assert_allclose(row, want, rtol=1e-6, atol=1e-6 * np.abs(want).max())


@pytest.mark.parametrize("case", ["qtf with spreading", "qtf from a .8", "cutoff without qtf", "no excitation"])
def test_bad_drift_set_ups_are_one_error(folder, case):
    sea = 'spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ncomponents = 40'
    drift, key = {
        "qtf with spreading": (f'bem = "cyl.12d"\nulen = {ULEN}\nmethod = "qtf"', "waves.spreading"),
        "qtf from a .8": (f'bem = "cyl.8"\nulen = {ULEN}\nmethod = "qtf"', "bodies.cyl.effects[1].bem"),
        "cutoff without qtf": (f'bem = "cyl.8"\nulen = {ULEN}\ncutoff = 0.3', "bodies.cyl.effects[1].cutoff"),
        "no excitation": (f'bem = "cyl.8"\nulen = {ULEN}', "bodies.cyl.effects[0].type"),
    }[case]
    if case == "qtf with spreading":
        sea += "\ndirection = 45.0\nspreading = 60.0"   # within the excitation's 0…90°
    path = scene(folder, sea, drift)
    if case == "no excitation":
        path.write_text(path.read_text().replace('type = "wave_excitation"\nbem = "wave_cylinder.nc"\n\n'
                                                 '[[bodies.cyl.effects]]\n', ''))
    with pytest.raises(InputError) as err:
        load_scene(path)
    assert key in str(err.value), str(err.value)


def test_a_full_qtf_is_used_as_one_and_newman_is_weighed_against_it(folder):
    """A .12d without a method is the full QTF; the build's notes hold Newman's slow-drift std
    against the QTF's per dof for this sea (slow_drift_std's figures); method = "newman" by
    choice is used, and where it departs beyond 10 % (heave here: the test QTF's diagonal
    changes sign where its off-diagonal does not) it is a warning naming the dof; a
    unidirectional QTF in a spread sea falls back to Newman by default, said."""
    import warnings as w

    from hydrofmu.assembly import assemble, notes
    from hydrofmu.errors import InputWarning
    from hydrofmu.physics.drift import slow_drift_std
    sea = 'spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ncomponents = 40\nseed = 3\nramp = 0.0'
    wv = 2 * np.pi / np.array(DRIFT_PERIODS)
    q = hermitian_qtf(DRIFT_PERIODS)
    q[np.arange(wv.size), np.arange(wv.size), 2] = np.sin(3 * wv) + 0.3        # heave's mean drift changes sign
    write_12d(folder / "cyl.12d", DRIFT_PERIODS, q)
    with w.catch_warnings(record=True) as said:
        w.simplefilter("always", InputWarning)
        sc = load_scene(scene(folder, sea, f'bem = "cyl.12d"\nulen = {ULEN}'))
    eff = sc.bodies["cyl"].effects[1]
    assert eff.data["method"] == "qtf" and not [m for m in said if "Newman" in str(m.message)]
    lines = [line for line in notes(sc, assemble(sc)) if "Newman / full QTF" in line]
    assert len(lines) == 1 and "40 components" in lines[0], lines
    comps = components(sc.waves, (wv.min(), wv.max()))
    order = np.argsort(wv)
    q = q * RHO * G * ULEN ** np.array([1, 1, 1, 2, 2, 2])
    sq, sn = slow_drift_std(comps, QTF(wv[order], [(0.0, 0.0)], q[order][:, order][:, :, None, :]))
    assert f"heave {sn[2] / sq[2]:.3f} ({sn[2]:.4g} / {sq[2]:.4g} N)" in lines[0]
    assert abs(sn[2] / sq[2] - 1) > 0.1
    with w.catch_warnings(record=True) as said:
        w.simplefilter("always", InputWarning)
        sc = load_scene(scene(folder, sea, f'bem = "cyl.12d"\nulen = {ULEN}\nmethod = "newman"'))
    assert sc.bodies["cyl"].effects[1].data["method"] == "newman"
    off = [str(m.message) for m in said if "Newman's slow-drift std departs" in str(m.message)]
    assert len(off) == 1 and "heave" in off[0] and "effects[1].method" in off[0], off
    rows = (folder / "cyl.12d").read_text().splitlines(keepends=True)[1:]     # the pairs (0°, 0°) and (90°, 90°)
    (folder / "uni.12d").write_text("".join(rows + [r[:28] + f"{90.0:14.6E}" * 2 + r[56:] for r in rows]))
    with w.catch_warnings(record=True) as said:
        w.simplefilter("always", InputWarning)
        sc = load_scene(scene(folder, sea + "\ndirection = 45.0\nspreading = 60.0", f'bem = "uni.12d"\nulen = {ULEN}'))
    assert sc.bodies["cyl"].effects[1].data["method"] == "newman"
    assert any("unidirectional heading pairs only" in str(m.message) for m in said)


# -------------------------------------------------------------- compiled flavour (drift.c)

PAIR = DATA / "wave_pair.nc"


def write_bidirectional_12d(path, periods, headings, seed=4):
    """A bidirectional .12d: every heading pair, one triangle of the periods, Q(ω_j, ω_i; β2, β1)
    the conjugate of Q(ω_i, ω_j; β1, β2) (so the file is a Hermitian QTF)."""
    rng = np.random.default_rng(seed)
    n, h = len(periods), len(headings)
    q = rng.normal(size=(n, n, h, h, 6)) + 1j * rng.normal(size=(n, n, h, h, 6))
    q = 0.5 * (q + np.conj(np.transpose(q, (1, 0, 3, 2, 4))))
    lines = []
    for a in range(n):
        for b in range(a + 1):
            for c in range(h):
                for d in range(h):
                    for i in range(6):
                        v = q[a, b, c, d, i]
                        if a == b and c == d:
                            v = v.real
                        lines.append(f"{periods[a]:14.6E}{periods[b]:14.6E}{headings[c]:14.6E}{headings[d]:14.6E}"
                                     f"{i + 1:6d}{abs(v):14.6E}{math.degrees(np.angle(v)):14.6E}{v.real:14.6E}"
                                     f"{v.imag:14.6E}\n")
    path.write_text("".join(lines))


def pair_scene(folder, waves, drift):
    """cyl2 of the pair dataset (10 m from the origin: the drift's phases matter), held."""
    shutil.copy(PAIR, Path(folder) / PAIR.name)
    text = f"""[build]
runtime = "c"

[run]
step = 0.1
stop = 100.0

[waves]
{waves}

[bodies.cyl2]
position = [10.0, 0.0, 0.0]
mass = 51190.0
inertia = [2e5, 2e5, 1e5]

[[bodies.cyl2.effects]]
type = "wave_excitation"
bem = "wave_pair.nc"
body = "cyl2"

[[bodies.cyl2.effects]]
type = "wave_drift"
{drift}
"""
    path = Path(folder) / "pair.toml"
    path.write_text(text)
    return path


SPREAD = ('spectrum = "jonswap"\nhs = 3.0\ntp = 9.0\ndirection = 200.0\nspreading = 6.0\ncomponents = 60\nseed = 5\n'
          'ramp = 15.0')
COMPILED_CASES = {   # (waves, drift, parameters at initialization, steps of 0.1 s)
    "mean, regular": ('spectrum = "regular"\nheight = 2.0\nperiod = 7.0\ndirection = 30.0\nramp = 10.0',
                      f'bem = "cyl.8"\nulen = {ULEN}\nmethod = "mean"', {"waves.period": 8.5}, 300),
    "newman, spread": (SPREAD, f'bem = "cyl.8"\nulen = {ULEN}\nmethod = "newman"', {"waves.seed": 11.0}, 300),
    # the full QTF by its blocks (physics.drift.DriftLoad.at): 80 s at the 1 rad/s cut-off, 42 s for
    # the spread sea's bandwidth; the records cross a block's end
    "qtf, long-crested, cut-off": (SPREAD.replace("spreading = 6.0", "spreading = 0.0").replace("200.0", "0.0"),
                                   f'bem = "cyl.12d"\nulen = {ULEN}\nmethod = "qtf"\ncutoff = 1.0', {"waves.hs": 2.0},
                                   900),
    "qtf, bidirectional, spread": (SPREAD, f'bem = "bi.12d"\nulen = {ULEN}\nmethod = "qtf"', {"waves.seed": 9.0},
                                   600),
}


@pytest.mark.parametrize("case", list(COMPILED_CASES))
def test_drift_compiled_equals_python(folder, case, tmp_path):
    """physics/drift.c on the components waves.c draws = physics/drift.py on Python's, every
    output of the load FMU to 1e-10 of its range over 300 steps (the full QTF: 600–900, across
    the end of a block), a body 10 m from the origin, the sea state changed through waves.* at
    initialization."""
    from hydrofmu.fmi.build import build_scene
    from test_compiled import assert_equal_flavours
    (folder / "cyl.8").write_text("".join(mean_rows(DRIFT_PERIODS, [0.0, 90.0, 180.0, 270.0], [1, 2, 6], f8)))
    write_bidirectional_12d(folder / "bi.12d", DRIFT_PERIODS, [0.0, 90.0, 180.0, 270.0])
    waves, drift, params, steps = COMPILED_CASES[case]
    built = build_scene(load_scene(pair_scene(folder, waves, drift)), folder / "fmus", log=lambda *_: None,
                        runtime="c")
    assert assert_equal_flavours(built, tmp_path, steps=steps, params=params, loads_only=True) <= 1e-10
