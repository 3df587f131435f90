"""Motions in regular waves next to lightly damped resonances: the long runs the unit tests leave out.

The freely floating cylinder and the pair 20 m apart of tests/data/bem/wave_*.nc (a
repository checkout; make_waves_data.py there), radiation damping only, in regular waves of
1 mm amplitude at the grid frequencies around the heave and pitch modes, each run to the
case's stop time at several co-simulation steps (the cylinder's modes decay in ~50 s: 400 s;
the pair's surge–pitch mode, ζ ≈ 0.45 %, in ~150 s: 800 s).  Per run: the steady amplitude and phase of surge,
heave and pitch (least squares over the last 3 periods) against the frequency-domain
X(ω) = F/(−ω²(M + A) + iωB + C) of the same dataset, the error in % of each dof's peak |X|,
and the settling time (from when the fitted amplitude stays within 0.3 % of the peak of its
final value).  X(ω) is also evaluated with A(ω), B(ω) rebuilt from the transform's A∞ and
kernels (what the FMU convolves): the part of the error the radiation model explains,
the rest being the step's.
"""
import math
import warnings
from pathlib import Path

import numpy as np

from ..errors import InputWarning

DATA = Path(__file__).resolve().parents[3] / "tests" / "data" / "bem"
CASES = {   # dataset, {body: x}, frequencies [rad/s], steps [s], stop [s]
    "cylinder": ("wave_cylinder.nc", {"cyl": 0.0}, (1.3, 1.35, 1.4, 1.45, 1.5, 1.55), (0.05, 0.025, 0.0125), 400.0),
    "pair": ("wave_pair.nc", {"cyl1": -10.0, "cyl2": 10.0}, (1.3, 1.4, 1.45, 1.5, 1.55, 1.6, 1.7), (0.05, 0.025),
             800.0),
}
QUICK = {"cylinder": ((1.35, 1.5), (0.05, 0.025)), "pair": ((1.45, 1.55), (0.05,))}


def body_table(name, m, x, bem, damping=None):
    """A freely floating cylinder of the wave datasets (tests/data/bem/make_waves_data.py):
    mass = displaced mass ``m`` [kg], centre of mass 3 m below the waterline, radii of gyration
    2, 2, 1.5 m, at x [m]; wave excitation and hydrostatics from ``bem``; ``damping``: an
    optional diagonal of added linear damping (six values, SI)."""
    extra = f"damping = {list(damping)}\n" if damping is not None else ""
    return f"""
[bodies.{name}]
position = [{x}, 0.0, 0.0]
mass = {m!r}
inertia = [{4 * m!r}, {4 * m!r}, {2.25 * m!r}]
cog = [0.0, 0.0, -3.0]
{extra}
[[bodies.{name}.effects]]
type = "wave_excitation"
bem = "{bem}"
body = "{name}"
[[bodies.{name}.effects]]
type = "bem_hydrostatics"
bem = "{bem}"
body = "{name}"
"""


def scene_text(bem, bodies, m, step, stop):
    """The wave tests' scene: bodies of the dataset's mass, radii of gyration 2, 2, 1.5 m,
    radiation memory by convolution (kernels cut at 40 s), regular wave H = 2 mm, 30 s ramp."""
    mapping = ", ".join(f'{n} = "{n}"' for n in bodies)
    return (f'[run]\nstep = {step}\nstop = {stop}\nsubstep = {step}\nload_hold = "linear"\n\n'
            '[waves]\nspectrum = "regular"\nheight = 0.002\nperiod = 5.0\ndirection = 0.0\nramp = 30.0\n'
            + "".join(body_table(n, m, x, bem) for n, x in bodies.items())
            + f'\n[[couplings]]\nbem = "{bem}"\nbodies = {{ {mapping} }}\nmethod = "convolution"\n'
              'memory_length = 40.0\ndofs = ["Surge", "Heave", "Pitch"]\n')


def frequency_domain(path, a=None, b=None, dofs=None):
    """(ω, X (ω, dofs)) of a Capytaine file, e^{+iωt}, beam sea 0°; A, B replaced on ``dofs`` when given."""
    import xarray as xr
    ds = xr.load_dataset(path)
    fin = np.isfinite(ds["omega"].values)
    w = ds["omega"].values[fin]
    am, bm = ds["added_mass"].values[fin].copy(), ds["radiation_damping"].values[fin].copy()
    if a is not None:
        ix = np.ix_(range(w.size), dofs, dofs)
        am[ix], bm[ix] = a, b
    f = ds["excitation_force"]
    f = np.conj(f.sel(complex="re").values + 1j * f.sel(complex="im").values)[fin][:, 0]
    h = -w[:, None, None] ** 2 * (ds["inertia_matrix"].values + am) + 1j * w[:, None, None] * bm \
        + ds["hydrostatic_stiffness"].values
    return w, np.linalg.solve(h, f[..., None])[..., 0]


def _steady(t, x, omega, periods=3):
    sel = t >= t[-1] - periods * 2 * math.pi / omega
    tt = t[sel]
    basis = np.column_stack((np.cos(omega * tt), -np.sin(omega * tt), np.ones_like(tt), tt - tt[0]))
    c = np.linalg.lstsq(basis, x[sel], rcond=None)[0]
    return c[0] + 1j * c[1]


def measure(out, quick=False):
    """Rows {case, omega, step, dof, error_pct, model_pct, phase_deg, settle_s, wall_s}; None
    without the datasets."""
    import shutil
    import time
    import xarray as xr
    from ..cosim import inprocess
    from ..cosim.master import run
    from ..physics.radiation import _rebuild
    from ..scene import load_scene
    if not (DATA / "wave_cylinder.nc").is_file():
        return None
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for case, (bem, bodies, freqs, steps, stop) in CASES.items():
        if quick:
            freqs, steps = QUICK[case]
        shutil.copy(DATA / bem, out / bem)
        m = float(xr.load_dataset(DATA / bem)["inertia_matrix"].values[0, 0])
        cols = [6 * n + d for n in range(len(bodies)) for d in (0, 2, 4)]
        w, x = frequency_domain(DATA / bem)
        peak = np.abs(x).max(axis=0)
        names = ([f"{'_'.join(bodies)}_dynamics.{b}.{v}" for b in bodies
                  for v in ("position[1]", "position[3]", "attitude[2]")] if len(bodies) > 1 else
                 [f"{b}_dynamics.{v}" for b in bodies for v in ("position[1]", "position[3]", "attitude[2]")])
        for step in steps:
            path = out / f"{case}_{round(step * 1e4):d}.toml"   # the scene name: an identifier
            path.write_text(scene_text(bem, bodies, m, step, stop))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", InputWarning)
                scene = load_scene(path)
            rad = scene.couplings[0].bem.radiation
            kern = rad.kernels[..., :int(40.0 / rad.timdel + 1e-9) + 1]
            _, xm = frequency_domain(DATA / bem, *_rebuild(rad.a_inf, kern, rad.timdel, w), cols)
            for omega in freqs:
                k = int(np.argmin(np.abs(w - omega)))
                t0 = time.perf_counter()
                res = run(inprocess.system(scene, {f"{b}.waves.period": 2 * math.pi / w[k] for b in bodies}),
                          progress=False, record=names)
                wall = time.perf_counter() - t0
                ends = np.arange(60.0, stop + 1e-9, 10.0)
                for name, col in zip(names, cols):
                    final = _steady(res.time, res[name], w[k]) / 0.001
                    drift = [abs(_steady(res.time[res.time <= e + 1e-9], res[name][res.time <= e + 1e-9], w[k])
                                 / 0.001 - final) / peak[col] for e in ends]
                    late = [i for i, d in enumerate(drift) if d >= 0.003]
                    rows.append({"case": case, "omega": float(w[k]), "step": step, "stop": stop,
                                 "dof": name.split(".", 1)[1],
                                 "error_pct": 100 * abs(final - x[k, col]) / peak[col],
                                 "model_pct": 100 * abs(xm[k, col] - x[k, col]) / peak[col],
                                 "phase_deg": float(np.angle(final / x[k, col], deg=True)),
                                 "rao_over_peak": float(abs(x[k, col]) / peak[col]),
                                 # settled: the fit moved < 0.3 % of the peak over (at least) the last 50 s
                                 "settle_s": (float(ends[late[-1] + 1]) if late else float(ends[0]))
                                 if not late or ends[late[-1] + 1] <= stop - 50.0 else math.inf,
                                 "wall_s": wall})
    return rows


def summary(rows):
    """One line per (case, ω): the worst error over the dofs at each step, with the model's share."""
    lines = []
    for case in dict.fromkeys(r["case"] for r in rows):
        for omega in dict.fromkeys(r["omega"] for r in rows if r["case"] == case):
            parts = []
            for step in dict.fromkeys(r["step"] for r in rows if r["case"] == case):
                rs = [r for r in rows if r["case"] == case and r["omega"] == omega and r["step"] == step]
                worst = max(rs, key=lambda r: r["error_pct"])
                ph = max((abs(r["phase_deg"]) for r in rs if r["rao_over_peak"] > 0.1), default=0.0)
                settle = max(r["settle_s"] for r in rs)
                parts.append(f"step {step:g} s: {worst['error_pct']:.2f} % ({worst['dof']}; radiation model "
                             f"{worst['model_pct']:.2f} %), phase ≤ {ph:.1f}°, "
                             + (f"settled {settle:.0f} s" if math.isfinite(settle) else "not settled"))
            stop = max(r["stop"] for r in rows if r["case"] == case)
            lines.append(f"{case} ω = {omega:.2f} rad/s, {stop:.0f} s runs: " + "; ".join(parts))
    return lines
