"""The analyst's statistics of one response record: its mean, its low-frequency (LF) and
wave-frequency (WF) parts with their standard deviations, the expected extremes of the
record's duration and its response spectrum (numpy only; docs/running.md).

A record is n samples x_k = x(t_k) at a constant step dt [s].

- **Split** at the period T_s [s] (the default 2·Tp of the scene's sea: f_s = f_p/2, between
  a mooring's slow drift and the waves; a JONSWAP spectrum (γ 3.3) is 7e-8 of its peak there):
  x = x̄ + x_LF + x_WF.  x − x̄ followed by itself reversed (a record whose periodic
  extension is continuous: no jump between its end and its start leaks into every
  frequency), then held at its first value up to a length FFTs are fast at, is transformed
  (FFT); its lines below f_s, inverse transformed, are x_LF over the record (zero phase: a
  brick wall, no lag); x_WF is the rest.
- **Zero up-crossings** of a zero-mean part y: the k with y_k < 0 ≤ y_{k+1}, at the
  interpolated time; T_z = the mean spacing of the crossings; N = record / T_z cycles.
- **WF extreme, Rayleigh**: the WF part as a narrow-band Gaussian process, whose peaks are
  Rayleigh: most probable largest of N cycles = σ_WF·√(2 ln N), N from the WF part's T_z
  (the short-term extreme of a Gaussian response).
- **LF and total extremes, Weibull**: the peaks (the largest value between successive zero
  up-crossings, of the LF part, or of x − x̄; the troughs: the same of x̄ − x) fitted with
  F(p) = 1 − exp(−(p/α)^β) by least squares on Weibull paper (ln p against
  ln(−ln(1 − F)), F = i/(n+1) of the sorted peaks) over the upper half of the peaks (the
  tail, which the extreme depends on; all peaks when fewer than 20); the most probable
  largest of the record's N peaks is the value exceeded once in N: α·(ln N)^(1/β) (the
  statistical fit of a time-domain record's peaks that API RP 2SK recommends for mooring
  extremes).  For a Gaussian narrow-band record β = 2, α = σ√2: the Rayleigh figure.
- **Response spectrum**: Welch's estimate (scipy.signal.welch's: Hann window, segments of a
  quarter of the record (at least 64 samples), half overlap, mean removed), one-sided,
  as S(ω) [unit²·s/rad] = S(f)/(2π) at ω = 2πf, so that ∫S dω = the variance.
"""
from __future__ import annotations

import math

import numpy as np

SPLIT_TP = 2.0     # default split period = 2·Tp (f_s = f_p / 2)
MIN_PEAKS = 5      # fewer peaks: no fitted extreme (NaN)
TAIL = 0.5         # the Weibull fit uses the peaks with F ≥ 1 − TAIL ...
TAIL_FROM = 20     # ... when there are at least this many (else all of them)

# figure -> how it is computed (printed with the summary, kept in its JSON)
METHODS = {
    "mean": "mean of the record",
    "std": "standard deviation (population, 1/n) of the record",
    "min": "smallest recorded value",
    "max": "largest recorded value",
    "lf_std": "std of the LF part (zero-phase FFT brick wall below the split frequency, mirrored record)",
    "wf_std": "std of the WF part (the record less its mean and LF part)",
    "wf_tz": "mean zero up-crossing period of the WF part [s]",
    "wf_mpm": "most probable largest WF amplitude in the record: sigma_WF*sqrt(2 ln N), Rayleigh, N = record/Tz",
    "lf_mpm": "most probable largest LF amplitude: Weibull fitted to the LF peaks between zero up-crossings "
              "(least squares on Weibull paper, upper half), exceeded once in the record's N peaks",
    "mpm_max": "most probable largest value: mean + the same Weibull fit to the peaks of (x - mean)",
    "mpm_min": "most probable smallest value: mean - the same Weibull fit to the troughs of (x - mean)",
}
FIGURES = tuple(METHODS)


def parts(x, dt, period):
    """(x̄, x_LF, x_WF) of a record: x = x̄ + x_LF + x_WF, split at ``period`` [s] (None or
    inf: everything is LF; the module's docstring says how)."""
    x = np.asarray(x, float)
    mean = float(x.mean()) if x.size else math.nan
    y = x - mean
    n = y.size
    if n < 3 or period is None or not math.isfinite(period):
        return mean, y, np.zeros_like(y)
    m = fast_length(2 * n)   # the mirrored record, held at its first value up to a length FFTs are fast at
    spectrum = np.fft.rfft(np.concatenate([y, y[::-1], np.full(m - 2 * n, y[0])]))
    spectrum[np.fft.rfftfreq(m, dt) >= 1.0 / period] = 0.0
    low = np.fft.irfft(spectrum, m)[:n]
    return mean, low, y - low


def fast_length(n):
    """The smallest 2^a·3^b·5^c ≥ n (an FFT of a length with a large prime factor is many
    times slower: 216 002 points took 50 ms, 216 000 take 3 ms)."""
    best, p5 = 2 * n, 1
    while p5 < best:
        p35 = p5
        while p35 < best:
            p = p35 * (1 << max(0, (-(-n // p35) - 1).bit_length()))   # the power of 2 taking p35 to ≥ n
            best = min(best, p)
            p35 *= 3
        p5 *= 5
    return best


def upcrossings(y, dt=1.0):
    """Times [s, from the first sample] of the zero up-crossings of ``y`` (y_k < 0 ≤ y_{k+1},
    linearly interpolated)."""
    y = np.asarray(y, float)
    k = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0))
    return (k + y[k] / (y[k] - y[k + 1])) * dt


def zero_upcrossing_period(y, dt):
    """Mean spacing of the zero up-crossings of a zero-mean record [s] (NaN with fewer than 2)."""
    up = upcrossings(y, dt)
    return float((up[-1] - up[0]) / (up.size - 1)) if up.size > 1 else math.nan


def peaks(y):
    """The largest value of ``y`` between each pair of successive zero up-crossings (one per
    cycle: the peaks the extreme-value fit takes), positive ones only."""
    y = np.asarray(y, float)
    k = np.flatnonzero((y[:-1] < 0) & (y[1:] >= 0)) + 1
    if k.size < 2:
        return np.zeros(0)
    top = np.maximum.reduceat(y[k[0]:k[-1]], k[:-1] - k[0])
    return top[top > 0]


def weibull_fit(p):
    """(α, β) of F(p) = 1 − exp(−(p/α)^β) fitted to the peaks ``p`` by least squares of ln p on
    ln(−ln(1 − F)), F = i/(n+1), over the upper half of them (all when fewer than 20)."""
    p = np.sort(np.asarray(p, float))
    n = p.size
    f = np.arange(1, n + 1) / (n + 1)
    use = f >= 1 - TAIL if n >= TAIL_FROM else np.ones(n, bool)
    slope, intercept = np.polyfit(np.log(-np.log(1 - f[use])), np.log(p[use]), 1)
    if slope <= 0:   # equal peaks (a sine): no spread, the peak itself
        return float(p[use].max()), math.inf
    return float(math.exp(intercept)), float(1.0 / slope)


def weibull_mpm(p, n=None):
    """Most probable largest of ``n`` peaks (default: as many as ``p``) of the Weibull fitted
    to ``p``: α·(ln n)^(1/β); NaN with fewer than MIN_PEAKS peaks."""
    p = np.asarray(p, float)
    n = p.size if n is None else n
    if p.size < MIN_PEAKS or n < 2:
        return math.nan
    alpha, beta = weibull_fit(p)
    return alpha * math.log(n) ** (1.0 / beta) if beta > 0 else math.nan


def rayleigh_mpm(sigma, n):
    """Most probable largest of ``n`` cycles of a narrow-band Gaussian process of std
    ``sigma``: σ·√(2 ln n) (0 for n ≤ 1)."""
    return sigma * math.sqrt(2.0 * math.log(n)) if n > 1 else 0.0


def describe(x, dt, period=None) -> dict:
    """The figures of ``METHODS`` (and min, max) of a record at step ``dt`` [s], split at
    ``period`` [s] (None: no split, the LF and WF figures are NaN); also ``lf_peaks`` and
    ``peaks``, the numbers of peaks each fit took.  A flat record has zero spreads and its
    mean as its extremes."""
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if x.size == 0:
        return {**dict.fromkeys(FIGURES, math.nan), "lf_peaks": 0, "peaks": 0}
    mean, lf, wf = parts(x, dt, period)
    y = x - mean
    std = float(x.std())
    out = {"mean": mean, "std": std, "min": float(x.min()), "max": float(x.max())}
    duration = x.size * dt
    flat = std == 0.0
    up, down = peaks(y), peaks(-y)
    out["mpm_max"] = mean if flat else mean + weibull_mpm(up)
    out["mpm_min"] = mean if flat else mean - weibull_mpm(down)
    out["peaks"] = int(up.size)
    if period is None:
        out.update(lf_std=math.nan, wf_std=math.nan, wf_tz=math.nan, wf_mpm=math.nan, lf_mpm=math.nan, lf_peaks=0)
        return out
    out["lf_std"], out["wf_std"] = float(lf.std()), float(wf.std())
    tz = zero_upcrossing_period(wf, dt)
    out["wf_tz"] = tz
    out["wf_mpm"] = 0.0 if out["wf_std"] == 0 else rayleigh_mpm(out["wf_std"], duration / tz) if tz > 0 else math.nan
    lf_peaks = peaks(lf)
    out["lf_mpm"] = 0.0 if out["lf_std"] == 0 else weibull_mpm(lf_peaks)
    out["lf_peaks"] = int(lf_peaks.size)
    return out


def segment(n):
    """Samples per Welch segment of an n-sample record: a quarter (at least 64, at most n)."""
    return int(min(n, max(64, n // 4)))


def spectrum(x, dt, nperseg=None):
    """(ω [rad/s], S(ω) [unit²·s/rad]): Welch's one-sided estimate of the record's spectrum,
    as scipy.signal.welch makes it with a Hann window, half overlap and each segment's mean
    removed (numpy here: importing scipy.signal costs a run seconds); ∫S dω ≈ the variance."""
    x = np.asarray(x, float)
    m = nperseg or segment(x.size)
    starts = np.arange(0, x.size - m + 1, m - m // 2)
    window = 0.5 - 0.5 * np.cos(2 * np.pi * np.arange(m) / m)       # periodic Hann
    segments = x[starts[:, None] + np.arange(m)]
    segments = (segments - segments.mean(axis=1, keepdims=True)) * window
    power = (np.abs(np.fft.rfft(segments, axis=1)) ** 2).mean(axis=0) * dt / np.sum(window ** 2)
    power[1:(m + 1) // 2] *= 2   # one-sided: every line but 0 and (m even) Nyquist counted twice
    return 2 * np.pi * np.fft.rfftfreq(m, dt), power / (2 * np.pi)


def uniform(t, x):
    """(dt, x on a uniform grid): the record as it is when its steps are equal (to 1e-6 of the
    step), else linearly interpolated at its median step (an ECCO run's own time points)."""
    t = np.asarray(t, float)
    if t.size < 2:
        return 1.0, np.asarray(x, float)
    steps = np.diff(t)
    dt = float(np.median(steps))
    if np.ptp(steps) <= 1e-6 * dt:
        return float((t[-1] - t[0]) / (t.size - 1)), np.asarray(x, float)
    grid = t[0] + dt * np.arange(int(math.floor((t[-1] - t[0]) / dt)) + 1)
    return dt, np.interp(grid, t, x)
