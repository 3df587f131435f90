"""WAMIT's numeric outputs read as WAMIT writes them (issue 31, item 1): a header line
(NUMHDR = 1), the limit rows PER = −1 (ω = 0) and PER = 0 (ω = ∞), periods decreasing, and
the first column in the variable the run's IPEROUT chose (declared, never guessed).  The
files are written here from the Capytaine test data with WAMIT's documented scaling
(decks/bem.py, decks/bem_waves.py) and must give the Capytaine route's numbers."""
import math
import warnings

import numpy as np
import pytest

xr = pytest.importorskip("xarray")

from hydrofmu.decks.bem import read_bem, read_capytaine, read_wamit  # noqa: E402
from hydrofmu.decks.bem_waves import read_excitation, read_hydrostatics  # noqa: E402
from hydrofmu.errors import InputError, InputWarning  # noqa: E402

from conftest import ROOT  # noqa: E402

CYL = ROOT / "tests" / "data" / "bem" / "cylinders.nc"
PAIR = ROOT / "tests" / "data" / "bem" / "wave_pair.nc"
RHO, G, ULEN = 1025.0, 9.81, 2.0
DOFS = ("Surge", "Sway", "Heave", "Roll", "Pitch", "Yaw")
HEADER = "WAMIT Numeric Output -- Filename  {name}   06-Dec-2016  11:29:06"


def first_column(omega, variable):
    """What WAMIT writes in the first column for ω [rad/s] (IPEROUT 1, 2, 3; hz: converted)."""
    return {"period": 2 * np.pi / omega, "omega": omega, "hz": omega / (2 * np.pi),
            "wavenumber": omega ** 2 * ULEN / G}[variable]


def write_one(path, variable="period", header=True, a_zero=None, limits=True):
    """cylinders.nc as a WAMIT .1: Ā = A/(ρL^k), B̄ = B/(ρL^kω), rows in decreasing period,
    PER = −1 (``a_zero``) and PER = 0 (the dataset's ω = ∞) first, as WAMIT orders them."""
    ds = xr.load_dataset(CYL)
    names = [f"cyl{b}__{d}" for b in (1, 2) for d in DOFS]
    scale = np.array([[RHO * ULEN ** (3 + (i % 6 >= 3) + (j % 6 >= 3)) for j in range(12)] for i in range(12)])
    sel = lambda var, w: ds[var].sel(omega=w).sel(influenced_dof=names, radiating_dof=names).values
    lines = [HEADER.format(name=path.name)] if header else []
    blocks = []
    if limits:
        if a_zero is not None:
            blocks.append(("-1", a_zero / scale, None))
        blocks.append(("0", sel("added_mass", np.inf) / scale, None))
    for w in np.sort(ds.omega.values[np.isfinite(ds.omega.values)]):   # increasing ω: decreasing period
        blocks.append((f"{first_column(w, variable):.9E}", sel("added_mass", w) / scale,
                       sel("radiation_damping", w) / (scale * w)))
    for first, a, b in blocks:
        for i in range(12):
            for j in range(12):
                lines.append(f" {first} {i + 1:5d} {j + 1:5d} {a[i, j]:.9E}" + ("" if b is None else f" {b[i, j]:.9E}"))
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("variable", ["period", "omega", "hz", "wavenumber"])
def test_wamit_one_as_written_gives_the_capytaine_result(tmp_path, variable):
    """Header, limits (period form only: WAMIT's codes), every IPEROUT form: the Capytaine
    numbers within the 10 significant digits written."""
    cap = read_capytaine(CYL)
    a_zero = cap.added_mass[0] * 1.01
    f = write_one(tmp_path / "cyl.1", variable, a_zero=a_zero if variable == "period" else None,
                  limits=variable == "period")
    d = read_bem(f, ulen=ULEN, rho=RHO, g=G, period_variable=None if variable == "period" else variable)
    np.testing.assert_allclose(d.omega, cap.omega, rtol=1e-8)
    for got, want in ((d.added_mass, cap.added_mass), (d.damping, cap.damping)):
        scale = np.abs(want).max(axis=0)
        assert np.all(np.abs(got - want) <= 1e-8 * scale + 1e-12)
    if variable == "period":
        np.testing.assert_allclose(d.a_inf, cap.a_inf, rtol=1e-8, atol=1e-6)
        np.testing.assert_allclose(d.a_zero, a_zero, rtol=1e-8, atol=1e-6)
    else:
        assert d.a_inf is None


def test_wamit_a_inf_file_takes_the_per_zero_rows(tmp_path):
    """a_inf = "file" on a WAMIT .1 gives its PER = 0 rows (as the Capytaine ω = ∞ row)."""
    from hydrofmu.bem import couplings
    f = write_one(tmp_path / "cyl.1")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        w = couplings(read_bem(f, ulen=ULEN, rho=RHO), {"body1": "body1", "body2": "body2"}, a_inf_from="file")
        c = couplings(read_capytaine(CYL), {"cyl1": "cyl1", "cyl2": "cyl2"}, a_inf_from="file")
    assert w.radiation.a_inf_source == c.radiation.a_inf_source == "file"
    np.testing.assert_allclose(w.radiation.a_inf, c.radiation.a_inf, rtol=1e-8, atol=1e-6)


def test_wamit_one_column_variable_cannot_be_guessed(tmp_path):
    """A file of periods read as ω (or the other way) is not detectable from its numbers: the
    option decides, and the limit codes, meaningful only for periods, are refused with it."""
    f = write_one(tmp_path / "cyl.1")
    with pytest.raises(InputError) as err:
        read_wamit(f, ULEN, RHO, G, "omega")
    assert err.value.line == 2 and err.value.field == "PER" and "period codes −1 and 0" in err.value.message
    with pytest.raises(InputError, match="period_variable: expected one of 'period', 'omega'"):
        read_wamit(f, ULEN, RHO, G, "rad/s")
    with pytest.raises(InputError, match="period_variable: applies to a nondimensional WAMIT .1 file only"):
        read_bem(CYL, period_variable="omega")
    f = write_one(tmp_path / "k.1", "wavenumber", limits=False)
    with pytest.raises(InputError, match="g: a wavenumber column needs g"):
        read_wamit(f, ULEN, RHO, None, "wavenumber")


@pytest.mark.parametrize("text, line, field, said", [
    # a row with more fields than PER I J A B: the corpus's class (read from its first 5 before)
    ("HDR\n1.0 1 1 2.0 1.0\n1.0 1 1 2.0 1.0 0.5 0.1 7\n", 3, "PER I J A B", "found 8"),
    ("1.0 1 1 2.0 1.0 3.0\n", 1, "PER I J A B", "more fields than the format"),
    ("HDR\n1.0 1 1 2.0 1.0\nWAMIT again\n", 3, "PER", "not a number: 'WAMIT'"),   # text after the rows
    ("1.0x 1 1 2.0 1.0\n", 1, "PER", "a header line must not start like a number"),
    ("nan 1 1 2.0 1.0\n", 1, "PER", "non-finite"),
    ("HDR\n1.0 1 1\n", 2, "A", "expected 4 or 5 numbers"),
])
def test_wamit_one_rows_name_line_and_field(tmp_path, text, line, field, said):
    f = tmp_path / "bad.1"
    f.write_text(text.replace("HDR", HEADER.format(name="bad.1")))
    with pytest.raises(InputError) as err:
        read_wamit(f, 1.0, RHO)
    assert (err.value.path, err.value.line, err.value.field) == (str(f), line, field) and said in err.value.message


# --- .3 / .2 / .hst -------------------------------------------------------------------------

def write_three(path, variable="period", header=True, drop=(), extra=None, limits=True):
    """wave_pair.nc's excitation as WAMIT's .3 (conjugated: e^{+iωt}; X̄ = X/(ρgL^m)), periods
    decreasing, PER = −1 and 0 rows first (WAMIT writes the limits' Froude–Krylov/haskind
    values there: not excitation of a wave), ``drop``: dofs (1-based) left out everywhere;
    ``extra``: a number appended to that row index."""
    ds = xr.load_dataset(PAIR)
    f = ds["excitation_force"].sel(complex="re").values + 1j * ds["excitation_force"].sel(complex="im").values
    omega = ds["omega"].values
    lines = [HEADER.format(name=path.name)] if header else []
    if limits:
        lines += [f"{per} 0.0 {d} 1.0 0.0 1.0 0.0" for per in ("-1.0", "0.0") for d in range(1, 13)]
    for i in np.argsort(omega):
        if not np.isfinite(omega[i]):
            continue
        for j, beta in enumerate(np.degrees(ds["wave_direction"].values)):
            for d in range(12):
                if d + 1 in drop:
                    continue
                x = np.conj(f[i, j, d]) / (RHO * G * ULEN ** (2 if d % 6 < 3 else 3))
                lines.append(f"{first_column(omega[i], variable):.8E} {beta:.4f} {d + 1} {abs(x):.8E} "
                             f"{np.angle(x, deg=True):.6f} {x.real:.8E} {x.imag:.8E}")
    if extra is not None:
        lines[extra] += " 0.25"
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.mark.parametrize("variable", ["period", "omega", "hz", "wavenumber"])
def test_wamit_three_as_written_gives_the_capytaine_excitation(tmp_path, variable):
    three = write_three(tmp_path / "pair.3", variable, limits=variable == "period")
    w = read_excitation(three, ulen=ULEN, rho=RHO, g=G, period_variable=None if variable == "period" else variable)
    c = read_excitation(PAIR)
    np.testing.assert_allclose(w.omega, c.omega, rtol=1e-7)
    for wb, cb in (("body1", "cyl1"), ("body2", "cyl2")):
        scale = np.abs(c.body(cb)).max(axis=(0, 1))
        assert np.all(np.abs(w.body(wb) - c.body(cb)) <= 1e-6 * scale + 1e-9)
    assert w.reading.warnings == []


def test_wamit_three_row_with_more_fields_is_refused_at_its_line(tmp_path):
    """Before: an 8-number row read from its first 7 (excitation 110–330 % off, no error)."""
    three = write_three(tmp_path / "pair.3", extra=40)
    with pytest.raises(InputError) as err:
        read_excitation(three, ulen=ULEN, rho=RHO, g=G)
    assert err.value.line == 41 and err.value.field == "PER BETA I MOD PHA RE IM"
    assert "found 8" in err.value.message and "more fields than the format" in err.value.message


def test_wamit_three_dofs_missing_everywhere_are_said(tmp_path):
    """Before: a .3 without roll, pitch, yaw rows read them as zero without a word."""
    three = write_three(tmp_path / "pair.3", drop=(4, 5, 6))
    with pytest.warns(InputWarning, match=r"pair\.3: I: no rows for Roll, Pitch, Yaw of body1 \(I = 4, 5, 6\)"):
        w = read_excitation(three, ulen=ULEN, rho=RHO, g=G)
    assert not np.any(w.body("body1")[:, :, 3:]) and np.all(np.abs(w.body("body1")[:, :, 2]) > 0)
    assert len(w.reading.warnings) == 1 and "body2" not in w.reading.warnings[0]


def test_wamit_three_gap_is_refused(tmp_path):
    """A dof missing at one (period, heading) only: a truncated or spliced file, an error at
    the line where that block ends (read as a zero there before)."""
    three = write_three(tmp_path / "pair.3", header=False, limits=False)
    lines = three.read_text().splitlines()
    del lines[14]                           # ω_1, the second heading, dof 3
    three.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError) as err:
        read_excitation(three, ulen=ULEN, rho=RHO, g=G)
    assert err.value.field == "I" and "I = 3 missing at ω = 0.05 rad/s, heading 30°" in err.value.message
    assert err.value.line == 23


def test_wamit_hst_with_header_and_row_counts(tmp_path):
    ds = xr.load_dataset(PAIR)
    c = ds["hydrostatic_stiffness"].values
    rows = [f"{i + 1} {j + 1} {c[i, j] / (RHO * G * ULEN ** (2 + (i % 6 >= 3) + (j % 6 >= 3))):.10E}"
            for i in range(12) for j in range(12) if i // 6 == j // 6]
    hst = tmp_path / "pair.hst"
    hst.write_text(HEADER.format(name="pair.hst") + "\n" + "\n".join(rows) + "\n")
    h = read_hydrostatics(hst, ulen=ULEN, rho=RHO, g=G)
    np.testing.assert_allclose(h.stiffness["body2"], read_hydrostatics(PAIR).stiffness["cyl2"], rtol=1e-8, atol=1e-6)
    rows[5] += " 1.0"
    hst.write_text(HEADER.format(name="pair.hst") + "\n" + "\n".join(rows) + "\n")
    with pytest.raises(InputError) as err:
        read_hydrostatics(hst, ulen=ULEN, rho=RHO, g=G)
    assert (err.value.line, err.value.field) == (7, "I J C") and "found 4" in err.value.message


def test_wavenumber_conversion_is_the_deep_water_dispersion():
    """KL = ω²L/g (WAMIT's IPEROUT = 3): the reader's ω for a hand value."""
    from hydrofmu.decks.bem import wamit_omega
    assert wamit_omega("f", 1, 0.8, "wavenumber", ulen=2.0, g=9.81) == pytest.approx(math.sqrt(0.8 * 9.81 / 2.0))
    assert wamit_omega("f", 1, 0.5, "hz") == pytest.approx(math.pi)
    assert wamit_omega("f", 1, -1.0, "period") == 0.0 and wamit_omega("f", 1, 0.0, "period") == math.inf


# --- every row edited: read as written, refused at its line, or said ----------------------

def _small_files(tmp_path):
    """Small WAMIT files with a header: a .1 (one body, dofs 1 and 3, PER = 0 and three
    periods), a .3 (two periods, two headings, six dofs) and a .hst (36 pairs)."""
    rng = np.random.default_rng(3)
    head = HEADER.format(name="s")
    one = [head] + [f"0.0 {i} {j} {rng.uniform(1, 2):.6E}" for i in (1, 3) for j in (1, 3)]
    one += [f"{per} {i} {j} {rng.uniform(1, 2):.6E} {rng.uniform(0.1, 1):.6E}"
            for per in (12.0, 8.0, 5.0) for i in (1, 3) for j in (1, 3)]
    three = [head] + [f"{per} {beta} {i} 1.0 0.0 {rng.normal():.6E} {rng.normal():.6E}"
                      for per in (10.0, 6.0) for beta in (0.0, 90.0) for i in range(1, 7)]
    hst = [head] + [f"{i} {j} {rng.normal():.6E}" for i in range(1, 7) for j in range(1, 7)]
    out = {}
    for suffix, lines in ((".1", one), (".3", three), (".hst", hst)):
        out[suffix] = (tmp_path / f"s{suffix}", lines)
    return out


def _read(path):
    return {".1": lambda p: read_wamit(p, ULEN, RHO), ".3": lambda p: read_excitation(p, ulen=ULEN, rho=RHO, g=G),
            ".hst": lambda p: read_hydrostatics(p, ulen=ULEN, rho=RHO, g=G)}[path.suffix](path)


def _values(data):
    if hasattr(data, "added_mass"):
        return np.concatenate([data.added_mass.ravel(), data.damping.ravel(), data.a_inf.ravel()])
    if hasattr(data, "values"):
        return data.values.ravel()
    return np.concatenate([m.ravel() for m in data.stiffness.values()])


@pytest.mark.parametrize("suffix", [".1", ".3", ".hst"])
def test_every_row_edit_is_read_as_written_or_refused_or_said(tmp_path, suffix):
    """The deck mutation suite's edits on WAMIT rows: a number appended (a row with more
    fields than its format), a row dropped, a row doubled, two rows swapped, the header
    dropped.  Appended and doubled rows are refused at their line; a dropped row is refused
    (a gap at one period) or, in a .hst, said; swaps and the header change nothing."""
    path, lines = _small_files(tmp_path)[suffix]
    path.write_text("\n".join(lines) + "\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error", InputWarning)
        base = _values(_read(path))
    for k in range(1, len(lines)):
        edits = {"append": lines[:k] + [lines[k] + " 0.25"] + lines[k + 1:],
                 "double": lines[:k + 1] + lines[k:],
                 "drop": lines[:k] + lines[k + 1:]}
        for kind, text in edits.items():
            path.write_text("\n".join(text) + "\n")
            with warnings.catch_warnings(record=True) as said:
                warnings.simplefilter("always", InputWarning)
                try:
                    _read(path)
                except InputError as err:
                    assert err.path == str(path) and err.line is not None, (kind, k, err)
                    if kind == "append":
                        assert err.line == k + 1 and ("more fields than the format" in err.message
                                                      or "WAMIT writes Ā alone at the limits" in err.message)
                    continue
            assert kind == "drop" and suffix == ".hst" and len(said) == 1, (kind, k, "read without a word")
            assert f"({(k - 1) // 6 + 1}, {(k - 1) % 6 + 1})" in str(said[0].message)
    for text in (lines[1:], lines[:1] + lines[2:3] + lines[1:2] + lines[3:]):   # no header; two rows swapped
        path.write_text("\n".join(text) + "\n")
        np.testing.assert_array_equal(_values(_read(path)), base)


def test_bem2simo_reads_a_wamit_one_in_omega(tmp_path, capsys):
    """`bem2simo --period-variable omega` on a .1 whose first column is ω: the SIMO deck of the
    period form, written the same."""
    from hydrofmu import cli
    periods = write_one(tmp_path / "p.1", limits=False)
    omegas = write_one(tmp_path / "w.1", "omega", limits=False)
    assert cli.main(["bem2simo", str(periods), "-o", str(tmp_path / "p.sim"), "--ulen", "2"]) == 0
    assert cli.main(["bem2simo", str(omegas), "-o", str(tmp_path / "w.sim"), "--ulen", "2",
                     "--period-variable", "omega"]) == 0
    def numbers(path):
        words = [w for line in path.read_text().splitlines() if not line.startswith("'") for w in line.split()]
        return [float(w) for w in words if w[0].isdigit() or w[0] in "+-."]
    p, w = numbers(tmp_path / "p.sim"), numbers(tmp_path / "w.sim")
    assert len(p) == len(w) > 1000        # 9 digits written: ω from the period differs in the 9th
    np.testing.assert_allclose(w, p, rtol=1e-6, atol=1e-6 * np.max(np.abs(p)))
    capsys.readouterr()


def test_scene_period_variable_next_to_the_file(tmp_path):
    """`period_variable` beside a WAMIT file in a scene: a coupling's .1 written in ω gives the
    couplings of the same file written in periods; a wave_excitation's .3 in Hz the same
    transfer function; the key on a Capytaine dataset, or a value not in the list, is an error."""
    from conftest import write_scene
    from test_bem import bodies_text
    from hydrofmu.scene import load_scene
    write_one(tmp_path / "p.1", limits=False)
    write_one(tmp_path / "w.1", "omega", limits=False)
    coupling = lambda f, extra: bodies_text() + f"""
        [[couplings]]
        bem = "{f}"
        ulen = {ULEN}
        bodies = {{ body1 = "a", body2 = "b" }}
        rotation_centers = {{ body1 = [0.0, -4.0, 0.0], body2 = [0.0, 4.0, 0.0] }}
        kernel_length = 30.0
        {extra}
        """
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        p = load_scene(write_scene(tmp_path, coupling("p.1", ""), "p.toml"))
        w = load_scene(write_scene(tmp_path, coupling("w.1", 'period_variable = "omega"'), "w.toml"))
    for cp, cw in zip(p.couplings, w.couplings):
        np.testing.assert_allclose(cw.added_mass, cp.added_mass, rtol=1e-6, atol=1e-6 * np.abs(cp.added_mass).max())
        for kp, kw in zip(cp.kernels, cw.kernels):
            np.testing.assert_allclose(kw.values, kp.values, rtol=0, atol=1e-6 * np.abs(kp.values).max())
    with pytest.raises(InputError, match=r"couplings\[0\].period_variable: expected one of 'period', 'omega'"):
        load_scene(write_scene(tmp_path, coupling("w.1", 'period_variable = "Hz"'), "bad.toml"))
    with pytest.raises(InputError, match="period_variable: applies to a nondimensional WAMIT .1 file only"):
        load_scene(write_scene(tmp_path, bodies_text() + f"""
            [[couplings]]
            bem = "{CYL}"
            bodies = {{ cyl1 = "a", cyl2 = "b" }}
            period_variable = "omega"
            """, "cap.toml"))
    from hydrofmu.scene.effects import _wave_excitation
    from hydrofmu.scene.problems import Problems
    write_three(tmp_path / "h.3", "hz", limits=False)
    write_three(tmp_path / "t.3")
    got = {}
    for f, extra in (("h.3", {"period_variable": "hz"}), ("t.3", {})):
        problems = Problems(tmp_path / "s.toml")
        problems.env = {"rho": RHO, "g": G}
        got[f] = _wave_excitation(problems, {"type": "wave_excitation", "bem": f, "body": "body2", "ulen": ULEN,
                                             **extra}, "bodies.b.effects[0]")
        assert not problems.items, problems.items
    np.testing.assert_allclose(got["h.3"]["omega"], got["t.3"]["omega"], rtol=1e-7)
    np.testing.assert_allclose(got["h.3"]["re"], got["t.3"]["re"], rtol=0, atol=1e-6 * np.abs(got["t.3"]["re"]).max())
