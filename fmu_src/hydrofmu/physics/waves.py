"""First-order waves: sea states, their components, and the excitation load of a body.

Conventions (README / user guide, Waves; DESIGN.md)
----------------------------------------------------
- One wave field per scene.  Direction β [deg]: where the waves go to, counter-clockwise
  from global +x (the current's convention).  Phase reference: the global origin.
- Elevation [m]: η(x, y, t) = r(t)·Σ_k a_k·cos(ω_k·t − k_k·(x·cos β_k + y·sin β_k) + φ_k),
  k_k from the dispersion relation ω² = g·k·tanh(k·h) (deep water: k = ω²/g).
- Excitation [N, N·m]: F(t) = r(t)·Σ_k a_k·Re{X(ω_k, β_k)·e^{i(ω_k·t + φ_k)}}, X the transfer
  function per unit amplitude referred to the global origin, global axes, moments about the
  body's reference point (= the BEM rotation centre).  Readers bring every source to this
  e^{+iωt} convention (Capytaine's e^{−iωt} values are conjugated).
- Ramp r(t) = ½·(1 − cos(π·t/T_r)) for t < T_r, 1 after (T_r = ``ramp`` [s]; 0: none).

Sea states (``SeaState``)
-------------------------
- regular: one component, a = H/2, ω = 2π/T, phase φ [deg], direction β (long-crested:
  ``spreading`` does not apply).
- jonswap (Hs, Tp, γ ≥ 1) and pierson_moskowitz (= jonswap with γ = 1):
  S(ω) = C·ω⁻⁵·exp(−5/4·(ω_p/ω)⁴)·γ^exp(−(ω − ω_p)²/(2σ²ω_p²)), σ = 0.07 (ω ≤ ω_p) or 0.09,
  C set so that 4·√m0 = Hs exactly (m0 integrated numerically).
- Frequency discretisation: the band [ω_lo, ω_hi] that leaves TAIL/2 of the spectrum's
  energy on each side (cut to the transfer functions' frequency window), split into N equal
  bins; component k gets a frequency drawn uniformly inside its bin, amplitude
  a_k = √(2·S(ω_k)·Δω) and a phase uniform in [0, 2π).  The frequencies are incommensurate,
  so the record does not repeat (equal spacing would repeat after 2π/Δω).
- Spreading cos-2s (``spreading`` = s > 0): D(θ) ∝ cos^{2s}((θ − β)/2); each component gets
  its own direction drawn from D (single summation: N components, no phase locking).
  s = 0: long-crested.
- Everything random comes from ``numpy.random.default_rng(seed)``, drawn in a fixed order:
  the same sea state gives the same components in every body's FMU (one wave field).

What is linear, what is not modelled: the excitation acts at the body's mean position (the
scene's pose), not where the body is; no second-order (drift, sum/difference-frequency)
loads here (a drift load takes the same ``Phasors``); the incident-wave kinematics of the
same components are physics/wave_kinematics.py's.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

SPECTRA = ("regular", "jonswap", "pierson_moskowitz")
STRETCHING = ("none", "vertical", "wheeler", "extrapolation")   # wave_kinematics.py's options
TAIL = 0.005           # share of the spectrum's energy the band leaves out (half on each side)
MAX_OUTSIDE = 0.02     # largest share of the spectrum allowed outside the transfer functions' frequencies
DIRECTION_TOL = 1e-6   # deg: a heading this close to a computed one is that one


class WaveError(ValueError):
    """A sea state or a transfer function that cannot be used; ``field`` names the knob."""

    def __init__(self, field, message):
        super().__init__(message)
        self.field = field


@dataclass
class SeaState:
    """A sea state's knobs (the FMU's ``waves.*`` parameters).

    spectrum: one of SPECTRA; regular waves: height H [m], period T [s], phase [deg];
    spectra: hs [m], tp [s], gamma (JONSWAP peak enhancement, ≥ 1); direction [deg, going to,
    counter-clockwise from +x]; spreading s (cos-2s, 0: long-crested); components N; seed;
    ramp [s]; depth [m] (inf: deep water); stretching: the kinematics above the mean water
    level (physics/wave_kinematics.py)."""
    spectrum: str = "jonswap"
    hs: float = 0.0
    tp: float = 10.0
    gamma: float = 3.3
    height: float = 0.0
    period: float = 10.0
    phase: float = 0.0
    direction: float = 0.0
    spreading: float = 0.0
    components: int = 200
    seed: int = 1
    ramp: float = 0.0
    depth: float = math.inf
    stretching: str = "wheeler"   # the kinematics above the mean water level (wave_kinematics.STRETCHING)

    def check(self):
        """Raise WaveError naming the first bad knob."""
        if self.spectrum not in SPECTRA:
            raise WaveError("spectrum", f"expected one of {', '.join(SPECTRA)}, found {self.spectrum!r}")
        finite = ("hs", "tp", "gamma", "height", "period", "phase", "direction", "spreading", "ramp")
        for name in finite:
            if not math.isfinite(getattr(self, name)):
                raise WaveError(name, f"must be finite, found {getattr(self, name)}")
        if self.spectrum == "regular":
            if self.height < 0:
                raise WaveError("height", f"must not be negative, found {self.height:g} m")
            if self.period <= 0:
                raise WaveError("period", f"must be positive, found {self.period:g} s")
        else:
            if self.hs < 0:
                raise WaveError("hs", f"significant wave height must not be negative, found {self.hs:g} m")
            if self.tp <= 0:
                raise WaveError("tp", f"peak period must be positive, found {self.tp:g} s")
            if self.spectrum == "jonswap" and self.gamma < 1:
                raise WaveError("gamma", f"JONSWAP peak enhancement must be at least 1, found {self.gamma:g}")
            if self.components != int(self.components) or self.components < 1:
                raise WaveError("components", f"must be a positive integer, found {self.components:g}")
        if self.spreading < 0:
            raise WaveError("spreading", f"cos-2s exponent s must not be negative, found {self.spreading:g}")
        if self.ramp < 0:
            raise WaveError("ramp", f"must not be negative, found {self.ramp:g} s")
        if not self.depth > 0:
            raise WaveError("depth", f"must be positive (inf: deep water), found {self.depth:g} m")
        if self.seed != int(self.seed) or self.seed < 0:
            raise WaveError("seed", f"must be a non-negative integer, found {self.seed:g}")
        if self.stretching not in STRETCHING:
            raise WaveError("stretching", f"expected one of {', '.join(STRETCHING)}, found {self.stretching!r}")


def wave_number(omega, g=9.81, depth=math.inf):
    """k [rad/m] with ω² = g·k·tanh(k·h) (Newton from the deep-water value); ω [rad/s]."""
    omega = np.asarray(omega, dtype=float)
    k = omega ** 2 / g
    if math.isinf(depth):
        return k
    k = np.maximum(k, omega / math.sqrt(g * depth))    # shallow-water start where deep is too small
    for _ in range(50):
        th = np.tanh(k * depth)
        f = g * k * th - omega ** 2
        df = g * th + g * k * depth * (1 - th ** 2)
        step = f / np.where(df > 0, df, 1.0)
        k = k - step
        if np.all(np.abs(step) <= 1e-13 * np.maximum(k, 1e-12)):
            break
    return k


def _shape(omega, tp, gamma):
    """Unscaled JONSWAP shape ω⁻⁵·exp(−5/4·(ω_p/ω)⁴)·γ^r(ω) (γ = 1: Pierson–Moskowitz)."""
    wp = 2 * math.pi / tp
    omega = np.asarray(omega, dtype=float)
    with np.errstate(divide="ignore", over="ignore", invalid="ignore"):
        base = np.where(omega > 0, omega ** -5.0 * np.exp(-1.25 * (wp / omega) ** 4), 0.0)
        sigma = np.where(omega <= wp, 0.07, 0.09)
        peak = gamma ** np.exp(-((omega - wp) ** 2) / (2 * sigma ** 2 * wp ** 2))
    return np.nan_to_num(base * peak)


def _grid(tp):
    """A fine frequency grid for integrals of a spectrum with peak period tp."""
    wp = 2 * math.pi / tp
    return np.linspace(wp * 0.2, wp * 12.0, 12000)


def spectrum(omega, hs, tp, gamma=1.0):
    """One-sided wave spectrum S(ω) [m²·s/rad] (JONSWAP; γ = 1 Pierson–Moskowitz), scaled so
    that 4·√(∫S dω) = hs [m]; tp [s] peak period."""
    w = _grid(tp)
    m0 = np.trapezoid(_shape(w, tp, gamma), w) if hasattr(np, "trapezoid") else np.trapz(_shape(w, tp, gamma), w)
    return (hs / 4) ** 2 / m0 * _shape(omega, tp, gamma)


def _cumulative(tp, gamma):
    """(ω grid, cumulative energy share) of the normalised spectrum (the grid's ends hold
    shares below 1e-12 and above 1 − 1e-5: a tail ω⁻⁴ beyond 12·ω_p)."""
    w = _grid(tp)
    s = _shape(w, tp, gamma)
    c = np.concatenate(([0.0], np.cumsum(0.5 * (s[1:] + s[:-1]) * np.diff(w))))
    tail = s[-1] * w[-1] / 4                # ∫ beyond w[-1] of the ω⁻⁵ tail
    return w, c / (c[-1] + tail)


def share_outside(tp, gamma, lo, hi):
    """Share of the spectrum's energy outside [lo, hi] rad/s."""
    w, c = _cumulative(tp, gamma)
    return float(1 - (np.interp(hi, w, c, right=1.0) - np.interp(lo, w, c, left=0.0)))


def band(tp, gamma, window=(0.0, math.inf)):
    """(ω_lo, ω_hi, share outside) of the discretised band: TAIL/2 of the energy left out on
    each side, cut to ``window`` (the transfer functions' frequency range) [rad/s]."""
    w, c = _cumulative(tp, gamma)
    lo, hi = np.interp([TAIL / 2, 1 - TAIL / 2], c, w)
    lo, hi = max(lo, window[0]), min(hi, window[1])
    if hi <= lo:
        return lo, hi, 1.0
    return float(lo), float(hi), share_outside(tp, gamma, lo, hi)


@dataclass
class Components:
    """The wave field's components: frequency omega [rad/s], amplitude [m], direction [deg,
    going to], phase [rad]; ``outside``: share of the spectrum's energy not represented."""
    omega: np.ndarray
    amplitude: np.ndarray
    direction: np.ndarray
    phase: np.ndarray
    outside: float = 0.0


def _spread(rng, s, n):
    """n direction offsets [deg] drawn from D(θ) ∝ cos^{2s}(θ/2), θ in (−180, 180)."""
    theta = np.linspace(-math.pi, math.pi, 4001)
    d = np.cos(theta / 2) ** (2 * s)
    c = np.concatenate(([0.0], np.cumsum(0.5 * (d[1:] + d[:-1]) * np.diff(theta))))
    return np.degrees(np.interp(rng.uniform(0, 1, n), c / c[-1], theta))


def components(sea: SeaState, window=(0.0, math.inf)) -> Components:
    """The components of a checked sea state (see the module docstring); ``window`` [rad/s]:
    the frequencies the transfer functions cover.  A spectrum with more than MAX_OUTSIDE of
    its energy outside the window raises WaveError('tp')."""
    rng = np.random.default_rng(int(sea.seed))
    if sea.spectrum == "regular":
        w = np.array([2 * math.pi / sea.period])
        if not window[0] - 1e-9 <= w[0] <= window[1] + 1e-9:
            raise WaveError("period", f"{sea.period:g} s (ω = {w[0]:.4g} rad/s) is outside the transfer functions' "
                                      f"frequencies {window[0]:.4g}…{window[1]:.4g} rad/s")
        return Components(w, np.array([sea.height / 2]), np.array([sea.direction]), np.radians([sea.phase]))
    gamma = 1.0 if sea.spectrum == "pierson_moskowitz" else sea.gamma
    lo, hi, outside = band(sea.tp, gamma, window)
    if outside > MAX_OUTSIDE:
        raise WaveError("tp", f"Tp = {sea.tp:g} s: {100 * outside:.3g} % of the spectrum's energy falls outside the "
                              f"transfer functions' frequencies {window[0]:.4g}…{window[1]:.4g} rad/s (at most "
                              f"{100 * MAX_OUTSIDE:g} % allowed)")
    n = int(sea.components)
    dw = (hi - lo) / n
    w = lo + (np.arange(n) + rng.uniform(0, 1, n)) * dw
    phase = rng.uniform(0, 2 * math.pi, n)
    beta = sea.direction + (_spread(rng, sea.spreading, n) if sea.spreading > 0 else np.zeros(n))
    amp = np.sqrt(2 * spectrum(w, sea.hs, sea.tp, gamma) * dw)
    return Components(w, amp, beta, phase, outside)


def ramp(t, length):
    """r(t) = ½(1 − cos(π·t/T_r)) for 0 ≤ t < T_r, 1 after (0 before the start)."""
    if t >= length:
        return 1.0
    if t <= 0:
        return 0.0
    return 0.5 * (1 - math.cos(math.pi * t / length))


class TransferFunction:
    """Excitation per unit wave amplitude of one body on a (frequency, direction) grid.

    omega (nω,) [rad/s] increasing; directions (nβ,) [deg, going to] increasing within
    [0, 360); values (nω, nβ, 6) complex [N/m, N·m/m] in the e^{+iωt} convention, referred to
    the global origin, global axes, moments about the body's reference point; position
    (x, y) [m] of the body (its mean position); g [m/s²], depth [m] for the wave number.

    ``at(ω, β)`` interpolates linearly in ω and in β (across 360° when the directions go round
    the circle: the wrap gap no larger than the largest step between computed directions) the
    values referred to the body's own position, X·e^{+ik(x cos β + y sin β)}, which vary
    slowly, and refers the result back to the origin: the k·x phase is exact, not interpolated.
    """

    def __init__(self, omega, directions, values, position=(0.0, 0.0), g=9.81, depth=math.inf):
        self.omega = np.asarray(omega, dtype=float)
        d = np.mod(np.asarray(directions, dtype=float), 360.0)
        d[d > 360.0 - DIRECTION_TOL] = 0.0
        order = np.argsort(d, kind="stable")
        keep = np.concatenate(([True], np.diff(d[order]) > DIRECTION_TOL))   # 0° and 360° solved both: one
        order = order[keep]
        self.directions = d[order]
        values = np.asarray(values, dtype=complex)[:, order]
        self.values = values
        self.position = np.asarray(position, dtype=float)[:2]
        self.g, self.depth = g, depth
        if not np.all(np.isfinite(values)):
            i, j, k = np.argwhere(~np.isfinite(values))[0]
            raise WaveError("values", f"non-finite transfer function at ω = {self.omega[i]:g} rad/s, direction "
                                      f"{self.directions[j]:g}°, dof {k + 1}")
        k = wave_number(self.omega, g, depth)[:, None, None]
        b = np.radians(self.directions)[None, :, None]
        self.local = values * np.exp(1j * k * (self.position[0] * np.cos(b) + self.position[1] * np.sin(b)))
        steps = np.diff(self.directions)
        gap = 360.0 - (self.directions[-1] - self.directions[0])
        self.closed = self.directions.size > 1 and gap <= (steps.max() if steps.size else 0.0) + DIRECTION_TOL
        if self.directions.size == 1:
            self.closed = False

    def c_params(self, window):
        """waves.c's transfer record: [window (2), x, y, closed, nω, nβ, ω, directions, Re X, Im X]
        (X in this object's order, (nω, nβ, 6) row-major); ``window`` [rad/s] the scene's."""
        return (list(map(float, window)) + self.position.tolist() + [float(self.closed), self.omega.size,
                self.directions.size] + self.omega.tolist() + self.directions.tolist()
                + self.values.real.ravel().tolist() + self.values.imag.ravel().tolist())

    @property
    def window(self):
        return float(self.omega[0]), float(self.omega[-1])

    def _direction_weights(self, beta):
        """(index pairs, weights) of the two computed directions around each β [deg]."""
        beta = np.mod(np.asarray(beta, dtype=float), 360.0)
        d = self.directions
        if self.closed:
            ext = np.concatenate((d, [d[0] + 360.0]))
            beta = np.where(beta < d[0], beta + 360.0, beta)   # below the first: across the wrap from the last
            j = np.clip(np.searchsorted(ext, beta, side="right") - 1, 0, d.size - 1)
            frac = (beta - ext[j]) / (ext[j + 1] - ext[j])
            return j, (j + 1) % d.size, frac
        near = np.abs((beta[:, None] - d[None, :] + 180) % 360 - 180) <= DIRECTION_TOL
        beta = np.where(near.any(axis=1), d[np.argmax(near, axis=1)], beta)
        bad = (beta < d[0] - DIRECTION_TOL) | (beta > d[-1] + DIRECTION_TOL)
        if bad.any():
            raise WaveError("direction", f"wave direction {float(beta[bad][0]):g}° is outside the computed directions "
                                         f"{d[0]:g}…{d[-1]:g}° (they do not go round the circle)")
        if d.size == 1:
            return np.zeros(beta.size, int), np.zeros(beta.size, int), np.zeros(beta.size)
        j = np.clip(np.searchsorted(d, beta, side="right") - 1, 0, d.size - 2)
        return j, j + 1, np.clip((beta - d[j]) / (d[j + 1] - d[j]), 0.0, 1.0)

    def at(self, omega, beta):
        """X(ω, β) (n, 6) complex for n components ω [rad/s], β [deg]."""
        omega = np.atleast_1d(np.asarray(omega, dtype=float))
        beta = np.broadcast_to(np.asarray(beta, dtype=float), omega.shape)
        w = self.omega
        if omega.min() < w[0] * (1 - 1e-9) or omega.max() > w[-1] * (1 + 1e-9):
            bad = omega[(omega < w[0] * (1 - 1e-9)) | (omega > w[-1] * (1 + 1e-9))][0]
            raise WaveError("omega", f"ω = {bad:g} rad/s is outside the transfer function's frequencies "
                                     f"{w[0]:g}…{w[-1]:g} rad/s")
        i = np.clip(np.searchsorted(w, omega, side="right") - 1, 0, max(w.size - 2, 0))
        fw = np.clip((omega - w[i]) / (w[i + 1] - w[i]), 0.0, 1.0) if w.size > 1 else np.zeros(omega.size)
        i1 = np.minimum(i + 1, w.size - 1)
        j0, j1, fb = self._direction_weights(beta)
        loc = self.local
        fw, fb = fw[:, None], fb[:, None]
        x = ((1 - fw) * ((1 - fb) * loc[i, j0] + fb * loc[i, j1])
             + fw * ((1 - fb) * loc[i1, j0] + fb * loc[i1, j1]))
        k = wave_number(omega, self.g, self.depth)[:, None]
        b = np.radians(beta)[:, None]
        return x * np.exp(-1j * k * (self.position[0] * np.cos(b) + self.position[1] * np.sin(b)))


RESYNC = 1024          # steps between two exact resynchronisations of the phasors
GRID_ULPS = 4          # a time this many ulp(t) from the phasors' step grid is on it


class Phasors:
    """The complex amplitudes of every wave component at the FMU's time, advanced once per
    step for the whole FMU and shared by every wave effect (excitation, kinematics, drift).

    p_k(t) = a_k·e^{i(ω_k·t + φ_k)} (un-ramped, complex (n,)); the ramp r(t) is ``ramp_factor``,
    and ``z`` = r(t)·p(t), so that η = Re Σ z_k·e^{−ik·x} at a point x and the excitation is
    Re Σ z_k·X_k (the e^{+iωt} convention of this module).

    Advancing: ``at(t)`` moves p to time t [s] and returns it (idempotent: every effect of a
    step calls it with the same t, the first call does the work).  A step of the same length h
    as the previous one costs one complex multiply per component, p ← p·e^{iω_k·h}.  Every
    ``resync`` steps, and whenever t is not the next point of the grid t_sync + j·h (a step of
    another length, a restored FMU state, a jump back), p is set exactly, a_k·e^{i(ω_k t + φ_k)}
    (N sines and cosines; a new step length costs N more for e^{iω_k h}).  Variable steps are
    therefore exact, at the cost of the trigonometry on each step that changes length.

    Round-off bound: each rotation adds at most ~4ε of |a_k| (ε = 2.2e-16: the product's
    rounding and that of e^{iω_k h}), so between two resynchronisations
    |p_k − a_k e^{i(ω_k t + φ_k)}| ≤ 4·ε·resync·|a_k| (≈ 1e-12·|a_k| for resync = 1024), plus the
    grid's time tolerance: a t within GRID_ULPS·ulp(t) of the grid point is taken as it (the
    master's t = n·h and t_sync + j·h differ by a rounding), a phase error ≤ ω_k·GRID_ULPS·ulp(t)
    (4e-11 rad at t = 3 h, ω = 5 rad/s); the exact evaluation itself carries the rounding of its
    argument ω_k·t + φ_k, ε·(ω_k t + 2π) (2e-12 rad at t = 3 h, ω = 1 rad/s), so the phasors are
    as accurate as the cosines they replace.  tests/test_wave_kinematics.py holds the sum of
    these over a 3-hour record with fixed and variable steps.
    """

    def __init__(self, comps: Components, ramp_length: float = 0.0, resync: int = RESYNC):
        self.omega = np.asarray(comps.omega, dtype=float)
        self.amplitude = np.asarray(comps.amplitude, dtype=float) * np.exp(1j * np.asarray(comps.phase, dtype=float))
        self.ramp_length = float(ramp_length)
        self.resync = int(resync)
        self.p = np.empty(self.omega.size, complex)
        self.t = math.nan
        self._sync, self._j, self._h, self._rot = 0.0, 0, 0.0, None
        self.rotations = self.exact = 0   # counts, for the tests and the bench

    def _exact(self, t):
        np.multiply(self.amplitude, np.exp(1j * (self.omega * t)), out=self.p)
        self.exact += 1
        self._sync, self._j = t, 0

    def at(self, t: float) -> np.ndarray:
        """p(t) (complex (n,), un-ramped; do not modify it)."""
        if t == self.t:
            return self.p
        prev, self.t = self.t, t
        if self._rot is not None and self._j < self.resync and self._h > 0:
            grid = self._sync + (self._j + 1) * self._h
            if abs(t - grid) <= GRID_ULPS * math.ulp(max(abs(t), abs(grid))):
                self.p *= self._rot
                self._j += 1
                self.rotations += 1
                return self.p
        h = t - prev
        self._exact(t)
        if not (math.isfinite(h) and h > 0):
            self._h, self._rot = 0.0, None
        elif self._rot is None or abs(h - self._h) > GRID_ULPS * math.ulp(abs(t)):
            # a new step length (one within the rounding of t of the old one is the old one:
            # t − t_prev of a master's t = n·h is h ± ulp(t), and the grid keeps the master's h)
            self._rot = np.exp(1j * (self.omega * h))
            self._h = h
        return self.p

    def state(self) -> dict:
        """The phasors' state (an FMU state holds it: a restored run continues bit for bit)."""
        return {"t": self.t, "sync": self._sync, "j": self._j, "h": self._h, "rot": self._rot is not None,
                "p": self.p.view(float).tolist()}

    def set_state(self, state: dict):
        self.t, self._sync, self._j, self._h = state["t"], state["sync"], state["j"], state["h"]
        self.p.view(float)[:] = state["p"]
        self._rot = np.exp(1j * (self.omega * self._h)) if state["rot"] else None

    @property
    def ramp_factor(self) -> float:
        """r(t) at the phasors' time."""
        return ramp(self.t, self.ramp_length) if self.t < self.ramp_length else 1.0

    def z(self, t: float) -> np.ndarray:
        """r(t)·a_k·e^{i(ω_k t + φ_k)} (a new array)."""
        p = self.at(t)
        return p * self.ramp_factor

    def c_params(self):
        """waves.c's phasor record: [n, resync, ramp length, ω (n), a e^{iφ} (re, im pairs)]."""
        return ([float(self.omega.size), float(self.resync), self.ramp_length] + self.omega.tolist()
                + self.amplitude.view(float).tolist())


class WaveLoad:
    """The per-step wave kernel of one body: excitation [N, N·m] (global axes, about the
    reference point) and the elevation [m] at the reference point, at time t [s].

    Built once per sea state: per component, T_k = [X(ω_k, β_k), e^{−ik·x}] (7 complex
    numbers), stacked as the real matrix whose rows 2k, 2k + 1 are Re T_k, −Im T_k (2N × 7), so
    that Re Σ_k p_k·T_k is p viewed as interleaved (re, im) floats times it.  A step costs the
    shared ``Phasors`` advance (one complex multiply per component, shared with every other
    wave effect of the FMU) and one (2N)·7 product.
    """

    def __init__(self, comps: Components, transfer: TransferFunction | None, point, ramp_length=0.0,
                 g=9.81, depth=math.inf, phasors: Phasors | None = None):
        w = np.asarray(comps.omega, dtype=float)
        b = np.radians(comps.direction)
        k = wave_number(w, g, depth)
        eta = np.exp(-1j * k * (point[0] * np.cos(b) + point[1] * np.sin(b)))
        x = transfer.at(w, comps.direction) if transfer is not None else np.zeros((w.size, 6), complex)
        table = np.column_stack((x, eta))
        self.omega = w
        self.table = np.empty((2 * w.size, 7))
        self.table[0::2], self.table[1::2] = table.real, -table.imag
        self.phasors = phasors if phasors is not None else Phasors(comps, ramp_length)
        self.ramp = self.phasors.ramp_length

    def __call__(self, t):
        """(7,) [Fx, Fy, Fz, Mx, My, Mz, η] at time t."""
        out = self.phasors.at(t).view(float).dot(self.table)
        if t < self.ramp:
            out *= ramp(t, self.ramp)
        return out
