"""The incident wave field (physics/wave_kinematics.py and .c) by the laws it must obey, not by
its formula typed again: finite differences of the load FMU's own outputs at neighbouring
named points (``[waves.points]``, both flavours: the Python slave and the compiled FMU) and of
the kernel, for every spectrum (regular, JONSWAP, Pierson–Moskowitz, a spread sea), every
stretching and deep, finite and shallow-ish water.

The laws of linear (Airy) waves, and where each holds under each stretching:

- continuity ∇·u = 0, and the linearised Euler equation ∂u/∂t = −∇p_d/ρ (p_d the dynamic
  pressure: the total pressure is p_d − ρ·g·z);
- the acceleration output is the local acceleration: a = ∂u/∂t at a fixed point;
- the kinematic surface condition w = ∂η/∂t and the dynamic one p_d = ρ·g·η, linearised at
  z = 0 (stretchings none, vertical, extrapolation: a point at z = 0 while it is wet, η ≥ 0);
  with Wheeler stretching at the instantaneous surface z = η itself (the column is mapped onto
  it: there z' = 0), where the total pressure p_d − ρ·g·z vanishes;
- no flow through the bed: w = 0 and a_z = 0 at z = −h;
- the particle orbit's sense: forward (along the waves) under the crest, rising before it
  (u in phase with η, w with ∂η/∂t: clockwise seen with the waves going to the right).

Below z = 0, none, vertical and extrapolation are the Airy field itself: every law holds to
the finite differences' own error.  Above z = 0 (points under a crest): ``none`` continues the
Airy field analytically, every law holds; ``vertical`` (F(0) above z = 0) and
``extrapolation`` (F(0) + z·F'(0)) keep the horizontal Euler equation and a = ∂u/∂t but not
continuity nor the vertical Euler equation (∂w/∂z = 0, resp. off by k²z·ω·a: they are not
potential flows there; not asserted).  Wheeler's mapping z' = h(z − η)/(h + η) (deep water
z − η) is not a potential flow either: by the chain rule on an Airy field U(x, z', t), with
s = h/(h + η), |∇z'| ≤ s·|∇η| and |∂z'/∂t| ≤ s·|∂η/∂t| (z' ≤ 0),
    |∇·u|, |∂u/∂t + ∇p_d/ρ| ≤ (|η|/(h + η) + s·|∇η|)·S,  |a − ∂u/∂t| ≤ s·|∂η/∂t|·S1
with S = Σ k·ω·a·F_h(z') (S1, for velocity gradients) or Σ ω²·a·F_h(z') (S2, for the
accelerations), F_h = cosh k(z' + h)/sinh kh the Airy depth factor that bounds the others:
second order in the wave steepness, which is what these tests hold Wheeler to, with ∇η and
∂η/∂t from the elevation outputs themselves.

Tolerances: the central differences' error, δ²/6·max|f'''| per derivative (δ = D in space,
each component's third derivative ≤ k³ times its amplitude), the 5-point time difference's
h⁴/30·max|f⁽⁵⁾| (h = H), and the round-off of the outputs (1e-12 of their scale; 1e-9 for
the time differences, whose phasors carry ~1e-12·a of rotation round-off, divided by h).
A wrong sign of w or a_z puts the residual at O(1) of these scales.
"""
import math
import zipfile
from pathlib import Path

import numpy as np
import pytest

from airy import wave_number
from hydrofmu.physics import waves
from hydrofmu.physics.wave_kinematics import WaveKinematics
from hydrofmu.physics.waves import Phasors, SeaState

G, RHO = 9.81, 1025.0
D = 0.02      # m: the half-width of the spatial stencils
H = 0.01      # s: the step of the records (time differences)
STENCIL = {"c": (0, 0, 0), "xp": (D, 0, 0), "xm": (-D, 0, 0), "yp": (0, D, 0), "ym": (0, -D, 0),
           "zp": (0, 0, D), "zm": (0, 0, -D)}
# columns of a point's row (the kernel's ``at`` and the FMU's waves.NAME.* outputs alike)
U, A, P, ETA = slice(0, 3), slice(3, 6), 6, 7
OUTPUTS = [f"velocity[{i}]" for i in (1, 2, 3)] + [f"acceleration[{i}]" for i in (1, 2, 3)] + ["pressure", "elevation"]

SEAS = {   # [waves] lines of each spectrum (ramp 0: the laws hold from the first step)
    "regular": 'spectrum = "regular"\nheight = 2.0\nperiod = 6.0\ndirection = 30.0\nphase = 40.0',
    "jonswap": 'spectrum = "jonswap"\nhs = 2.0\ntp = 8.0\ndirection = -20.0\ncomponents = 40\nseed = 2',
    "pierson_moskowitz": 'spectrum = "pierson_moskowitz"\nhs = 1.5\ntp = 7.0\ndirection = 200.0\ncomponents = 40'
                         '\nseed = 5',
    "spread": 'spectrum = "jonswap"\nhs = 2.0\ntp = 9.0\ndirection = 60.0\nspreading = 4.0\ncomponents = 60'
              '\nseed = 7',
}
DEPTHS = (math.inf, 40.0, 8.0)   # deep, finite, shallow-ish (kh ≈ 0.6–1.5 over the spectra)


class Sea:
    """What the bounds need of a sea's components: amplitude, ω, k, the depth."""

    def __init__(self, comps, depth):
        self.a, self.w, self.depth = comps.amplitude, comps.omega, depth
        self.k = wave_number(self.w, depth)   # (tests/airy.py's, not the code's solver)

    def factor(self, z):
        """The Airy depth factor F_h = cosh k(z + h)/sinh kh (deep: e^{kz}) of each component
        at heights z (…) + D (a stencil's top), (…, N): it bounds F_v and F_p·coth kh, and
        every stretching's factors, from the bed to above z = 0."""
        z = np.asarray(z, dtype=float)[..., None] + D
        if math.isinf(self.depth):
            return np.exp(self.k * z)
        return np.cosh(self.k * (z + self.depth)) / np.sinh(self.k * self.depth)

    def scale(self, power_k, power_w, z=0.0):
        """Σ k^p·ω^q·a·F_h(z): a bound of the field's derivatives (k^p ω^q: which)."""
        return np.sum(self.k ** power_k * self.w ** power_w * self.a * self.factor(z), axis=-1)


def layout(x, y, depth):
    """The named points of a law check: stencils (c, ±x, ±y, ±z) below the troughs (``deep``)
    and above the mean level (``high``), a point at z = 0 (``mean``), one on the bed and
    D above it (finite depth)."""
    z_deep = -0.45 * depth if depth < 10 else -4.0
    pts = {}
    for name, z in (("deep", z_deep), ("high", 0.4)):
        pts.update({f"{name}_{k}": (x + o[0], y + o[1], z + o[2]) for k, o in STENCIL.items()})
    pts["mean"] = (x, y, 0.0)
    if not math.isinf(depth):
        pts["bed"] = (x, y, -depth)
    return pts


def d_dt(f):
    """The 5-point central time difference along axis 1 (records (B, L, ...) of step H), at
    the samples 2 … L−3."""
    return (-f[:, 4:] + 8 * f[:, 3:-1] - 8 * f[:, 1:-3] + f[:, :-4]) / (12 * H)


def inner(f):
    """The samples where d_dt is defined."""
    return f[:, 2:-2]


def all5(mask):
    """``mask`` (B, L) true at the 5 samples of each time difference (B, L − 4)."""
    return mask[:, :-4] & mask[:, 1:-3] & mask[:, 2:-2] & mask[:, 3:-1] & mask[:, 4:]


def check_laws(rec, pts, sea, stretching, surface=None):
    """Every law of the module docstring on a record ``rec`` {point name: (B, L, 8)} of the
    points ``pts`` (``layout``), bursts of L samples H apart; ``surface``: (B, L, 8) rows of a
    point held at z = η (Wheeler's surface condition; 1e-10 m under it).  Returns {law: samples checked}."""
    h = sea.depth
    wheeler = stretching == "wheeler"
    s2 = sea.scale(0, 2)
    checked = {}

    def stretched(name, z):
        """Wheeler's (factor |η|/(h + η) + s·|∇η|, s, z') at the stencil ``name``, per sample."""
        eta = rec[f"{name}_c"][..., ETA]
        grad = np.hypot((rec[f"{name}_xp"][..., ETA] - rec[f"{name}_xm"][..., ETA]) / (2 * D),
                        (rec[f"{name}_yp"][..., ETA] - rec[f"{name}_ym"][..., ETA]) / (2 * D))
        if math.isinf(h):
            return grad, 1.0, z - eta
        s = h / (h + eta)
        return np.abs(eta) / (h + eta) + s * grad, s, s * (z - eta)

    for name in ("deep", "high"):
        z = pts[f"{name}_c"][2]
        if name == "high" and stretching in ("vertical", "extrapolation"):
            laws = ("euler_h", "local")   # not potential flows above z = 0 (module docstring)
        else:
            laws = ("continuity", "euler_h", "euler_z", "local")
        rows = {k: rec[f"{name}_{k}"] for k in STENCIL}
        wet = np.all([rows[k][..., ETA] >= pts[f"{name}_{k}"][2] for k in STENCIL], axis=0)
        c1, c2 = sea.scale(1, 1, z), sea.scale(0, 2, z)
        fd1, fd2 = D ** 2 / 2 * sea.scale(3, 1, z), D ** 2 / 6 * sea.scale(2, 2, z)
        bound = w1 = w2 = 0.0
        if wheeler:   # the chain rule's terms, the Airy field's gradients at z'
            bound, s, zs = stretched(name, z)
            w1, w2 = sea.scale(1, 1, zs), sea.scale(0, 2, zs)
        div = sum((rows[f"{ax}p"][..., i] - rows[f"{ax}m"][..., i]) / (2 * D) for i, ax in enumerate("xyz"))
        grad_p = np.stack([(rows[f"{ax}p"][..., P] - rows[f"{ax}m"][..., P]) / (2 * D) for ax in "xyz"], axis=-1)
        euler = rows["c"][..., A] + grad_p / RHO
        residual = {"continuity": (np.abs(div), fd1 + 1e-12 * c1 + bound * w1),
                    "euler_h": (np.abs(euler[..., :2]).max(axis=-1), fd2 + 1e-12 * c2 + bound * w2),
                    "euler_z": (np.abs(euler[..., 2]), fd2 + 1e-12 * c2 + bound * w2)}
        for law in laws:
            if law == "local":   # a = ∂u/∂t at the fixed point (Wheeler: + ∂U/∂z'·∂z'/∂t)
                u = rows["c"][..., U]
                got, dudt = inner(rows["c"][..., A]), d_dt(u)
                tol = H ** 4 / 30 * sea.scale(0, 6, z) + 1e-9 * c2
                if wheeler:
                    tol = tol + inner(s * w1) * np.abs(d_dt(rows["c"][..., ETA]))
                err, ok = np.abs(got - dudt).max(axis=-1), all5(wet)
            else:
                err, tol = residual[law]
                ok = wet
            assert np.all(err[ok] <= np.broadcast_to(tol, err.shape)[ok]), \
                (name, law, stretching, float((err[ok] / np.broadcast_to(tol, err.shape)[ok]).max()))
            checked[f"{name}.{law}"] = int(ok.sum())
    # the surface conditions: at z = 0 (linearised), or at z = η (Wheeler)
    row = surface if wheeler else rec["mean"]
    wet = inner(row[..., P] != 0.0) if not wheeler else inner(np.ones(row.shape[:-1], bool))
    dedt = d_dt(row[..., ETA])
    tol = H ** 4 / 30 * sea.scale(0, 5) + 1e-9 * sea.scale(0, 1)
    err = np.abs(inner(row[..., 2]) - dedt)
    assert np.all(err[wet] <= tol), ("kinematic surface condition", stretching, float(err[wet].max() / tol))
    # the total pressure p_d − ρg·z vanishes at z = η (Wheeler); linearised: p_d(0) = ρg·η
    want = 0.0 if wheeler else RHO * G * row[..., ETA]
    total = row[..., P] - (RHO * G * row[..., ETA] if wheeler else 0.0)
    assert np.all(np.abs(inner(total - want)[wet]) <= 1e-9 * RHO * G * sea.a.sum()), ("dynamic surface condition",
                                                                                     stretching)
    checked["surface"] = int(wet.sum())
    if not math.isinf(h):   # no flow through the bed
        bed = rec["bed"]
        assert np.all(np.abs(bed[..., 2]) <= 1e-12 * sea.scale(0, 1)) and np.all(np.abs(bed[..., 5]) <= 1e-12 * s2)
        assert np.abs(bed[..., 0:2]).max() > 1e-3 * sea.scale(0, 1)   # (the flow slips along it)
        checked["bed"] = bed[..., 0].size
    return checked


def sea_state(name, depth, stretching):
    """The SeaState of SEAS[name] (as the scene reads it) at ``depth`` with ``stretching``."""
    values = dict(line.split(" = ") for line in SEAS[name].splitlines())
    kw = {k: (v.strip('"') if v.startswith('"') else float(v)) for k, v in values.items()}
    spectrum = kw.pop("spectrum")
    for key in ("components", "seed"):
        if key in kw:
            kw[key] = int(kw[key])
    return SeaState(spectrum, **kw, depth=depth, stretching=stretching)


def kernel_record(comps, depth, stretching, pts, times):
    """(rec, surface) of the kernel at the points ``pts`` for times (B, L): as check_laws
    takes them; ``surface``: the point (x, y, η(t)) of the first stencil's column."""
    kin, at_surface = WaveKinematics(comps, G, depth, stretching), WaveKinematics(comps, G, depth, stretching)
    ph = Phasors(comps)
    names = list(pts)
    xyz = np.array([pts[n] for n in names])
    out = np.empty(times.shape + (len(names), 8))
    surface = np.empty(times.shape + (8,))
    x, y = pts["deep_c"][:2]
    for idx in np.ndindex(times.shape):
        p = ph.at(times[idx])
        out[idx] = kin.at(p, 1.0, xyz, RHO)
        eta = out[idx][names.index("mean"), ETA]
        # (1e-10 m under it: η at another set of points may differ in the last bit)
        surface[idx] = at_surface.at(p, 1.0, [(x, y, eta - 1e-10)], RHO)[0]
    return {n: out[..., i, :] for i, n in enumerate(names)}, surface


@pytest.mark.parametrize("depth", DEPTHS)
@pytest.mark.parametrize("spectrum", list(SEAS))
def test_kernel_obeys_the_laws(spectrum, depth):
    """The kernel, every stretching: 40 bursts of 5 samples H apart at random times of a
    10-minute record, at stencils below the troughs, above the mean level, at z = 0, at the
    surface (Wheeler) and on the bed; each law checked on at least some samples."""
    rng = np.random.default_rng(3)
    times = rng.uniform(0.0, 600.0, 16)[:, None] + H * np.arange(-2, 3)[None, :]
    for stretching in waves.STRETCHING:
        comps = waves.components(sea_state(spectrum, depth, stretching))
        pts = layout(12.0, -7.0, depth)
        rec, surface = kernel_record(comps, depth, stretching, pts, times)
        checked = check_laws(rec, pts, Sea(comps, depth), stretching, surface)
        assert checked["deep.continuity"] > 40 and checked["surface"] > 3 and checked["high.euler_h"] > 3, \
            (stretching, checked)


@pytest.mark.parametrize("spectrum", ["jonswap", "pierson_moskowitz", "spread"])
def test_kernel_orbit_sense_in_irregular_seas(spectrum):
    """Forward under the crests, rising before them, in every sea: 2 m below the mean level
    the velocity along the mean direction correlates with η and the vertical velocity with
    ∂η/∂t (each component's contribution is positive: cos of its spread ≤ 90° here) — a
    wrong sign of w gives −1."""
    comps = waves.components(sea_state(spectrum, math.inf, "none"))
    kin, ph = WaveKinematics(comps, G), Phasors(comps)
    beta = math.radians(float(SEAS[spectrum].split("direction = ")[1].split("\n")[0]))
    times = np.random.default_rng(1).uniform(0, 1800, 400)
    rows = np.array([[kin.at(ph.at(t + j * H), 1.0, [(0.0, 0.0, -2.0)])[0] for j in (-1, 0, 1)] for t in times])
    u_beta = rows[:, 1, 0] * math.cos(beta) + rows[:, 1, 1] * math.sin(beta)
    detadt = (rows[:, 2, ETA] - rows[:, 0, ETA]) / (2 * H)
    assert np.corrcoef(u_beta, rows[:, 1, ETA])[0, 1] > 0.6
    assert np.corrcoef(rows[:, 1, 2], detadt)[0, 1] > 0.6


def scene_text(spectrum, depth, stretching, pts, surface=None, effects=""):
    """A held body and the named points ``pts`` (global) in SEAS[spectrum]; ``surface``:
    (x, y) of a point on the body (its position input moves it), for Wheeler's surface;
    ``effects``: the body's effect tables (TOML)."""
    lines = ["[scene]", 'name = "laws"', "[run]", f"step = {H}", "stop = 1.0",
             "[bodies.b]", "position = [0.0, 0.0, 0.0]", "mass = 1.0e6", "inertia = [1e8, 1e8, 1e8]",
             "stiffness = [1e5, 1e5, 1e7, 1e9, 1e9, 1e8]", effects,
             "[waves]", SEAS[spectrum], "ramp = 0.0", f'stretching = "{stretching}"']
    if not math.isinf(depth):
        lines.append(f"depth = {depth}")
    for name, p in pts.items():
        lines += [f"[waves.points.{name}]", f"position = [{p[0]!r}, {p[1]!r}, {p[2]!r}]"]
    if surface is not None:
        lines += ["[waves.points.surface]", 'body = "b"', f"offset = [{surface[0]!r}, {surface[1]!r}, 0.0]"]
    return "\n".join(lines) + "\n"


class Flavour:
    """A load FMU of one flavour behind one interface: the Python slave of the compiled FMU's
    description (fmi/slave.py) or the compiled FMU itself (fmpy)."""

    def __init__(self, fmu, unzipped, flavour, name="laws"):
        from test_compiled import compiled_slave, python_slave
        from fmpy import read_model_description
        md = read_model_description(str(fmu))
        self.vr = {v.name: v.valueReference for v in md.modelVariables}
        if flavour == "python":
            s = python_slave(unzipped)
            s.setup_experiment(0.0)
            s.enter_initialization_mode()
            s.exit_initialization_mode()
            self.set, self.get, self.step = s.set_real, s.get_real, s.do_step
        else:
            _, s = compiled_slave(fmu, unzipped, name)
            s.setupExperiment(startTime=0.0)
            s.enterInitializationMode()
            s.exitInitializationMode()
            self.set, self.get, self.step = s.setReal, s.getReal, s.doStep

    def outputs(self, names, steps, heave=None, dt=H):
        """(steps, len(names)) of the outputs ``names`` after each step of ``dt``; ``heave``:
        the body's position[3] set before each step (a sequence of ``steps``)."""
        refs = [self.vr[n] for n in names]
        out = np.empty((steps, len(names)))
        for i in range(steps):
            if heave is not None:
                self.set([self.vr["position[3]"]], [float(heave[i])])
            self.step(i * dt, dt)
            out[i] = self.get(refs)
        return out

    def record(self, names, steps, heave=None, dt=H):
        """{point name: (1, steps, 8)} of the named points' outputs (``outputs``)."""
        out = self.outputs([f"waves.{n}.{c}" for n in names for c in OUTPUTS], steps, heave, dt)
        return {n: out[None, :, 8 * j:8 * j + 8] for j, n in enumerate(names)}


def built(tmp, text):
    """(the load FMU, its unzipped folder) of a scene built in the compiled flavour."""
    from hydrofmu.fmi.build import build_scene
    from hydrofmu.scene import load_scene
    path = Path(tmp) / "laws.toml"
    path.write_text(text)
    folder = build_scene(load_scene(path), Path(tmp) / "fmus", log=lambda *_: None, runtime="c")
    fmu = folder / "laws_b.fmu"
    unzipped = Path(tmp) / "laws_b"
    with zipfile.ZipFile(fmu) as z:
        z.extractall(unzipped)
    return fmu, unzipped


# each spectrum, stretching and depth once (the kernel test above takes every combination)
FMU_CASES = [("regular", "none", math.inf), ("jonswap", "vertical", 40.0),
             ("pierson_moskowitz", "extrapolation", 8.0), ("spread", "wheeler", 40.0)]


@pytest.mark.parametrize("spectrum, stretching, depth", FMU_CASES)
def test_fmu_outputs_obey_the_laws(spectrum, stretching, depth, tmp_path):
    """The load FMU's waves.NAME.* outputs, both flavours, 3 s at steps of H: every law by
    finite differences of the outputs themselves (Wheeler's surface: a point on the body,
    its heave input set to the elevation the FMU gave there in a first run); both flavours'
    records agree to 1e-10 of their scale."""
    pts = layout(12.0, -7.0, depth)
    fmu, unzipped = built(tmp_path, scene_text(spectrum, depth, stretching, pts, surface=(12.0, -7.0)))
    comps = waves.components(sea_state(spectrum, depth, stretching))
    sea = Sea(comps, depth)
    steps = 300
    records = {}
    for flavour in ("python", "c"):
        fm = Flavour(fmu, unzipped, flavour)
        rec = fm.record(list(pts) + ["surface"], steps)
        surface = None
        if stretching == "wheeler":   # the same sea again, the body point riding on the surface
            ride = Flavour(fmu, unzipped, flavour, "ride")
            surface = ride.record(["surface"], steps, heave=rec["surface"][0, :, ETA] - 1e-10)["surface"]
        checked = check_laws(rec, pts, sea, stretching, surface)
        assert checked["deep.continuity"] > 100 and checked["surface"] > 50, (flavour, checked)
        records[flavour] = np.stack([rec[n] for n in pts])
    scale = np.abs(records["python"]).max(axis=(0, 1, 2))
    assert np.all(np.abs(records["python"] - records["c"]).max(axis=(0, 1, 2)) <= 1e-10 * scale)


def test_fmu_particle_orbit_sense(tmp_path):
    """A regular wave (H 2 m, T 6 s, going to 30°) in the load FMU's outputs, both flavours,
    7 s: 4 m down the water moves forward (along the waves) at the crest and rises a quarter
    period before it; the orbit turns clockwise seen with the waves going to the right
    (u_β·∂w/∂t − w·∂u_β/∂t < 0 at every step: −ω³a²F_h F_v for Airy)."""
    pts = {"p": (3.0, 5.0, -4.0)}
    fmu, unzipped = built(tmp_path, scene_text("regular", math.inf, "none", pts))
    beta, period = math.radians(30.0), 6.0
    quarter = round(period / 4 / H)
    for flavour in ("python", "c"):
        row = Flavour(fmu, unzipped, flavour).record(["p"], 700)["p"][0]
        u_beta = row[:, 0] * math.cos(beta) + row[:, 1] * math.sin(beta)
        a_beta = row[:, 3] * math.cos(beta) + row[:, 4] * math.sin(beta)
        crest = int(np.argmax(row[:, ETA]))
        assert quarter < crest and row[crest, ETA] > 0.99   # a crest (a = 1 m) inside the record
        assert u_beta[crest] > 0.999 * u_beta.max() > 0
        assert row[crest - quarter, 2] > 0.999 * row[:, 2].max() > 0
        assert np.all(u_beta * row[:, 5] - row[:, 2] * a_beta < 0)
