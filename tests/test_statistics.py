"""The analyst's statistics (cosim.statistics) against answers found apart from the code:
a Gaussian narrow-band process whose most probable maximum is known in closed form (and held
against the mode of many realisations' observed maxima), a known LF sine under known WF noise,
the Welch estimate of a process of known spectrum within its statistical error (and equal to
scipy.signal.welch), and the default split from the scene's sea.

The synthetic records are sums of cosines at the FFT lines of the record (numpy's irfft), the
amplitudes from the target spectrum, the phases random: exact variance, exact spectral moments."""
import math

import numpy as np
import pytest

from hydrofmu.cosim import statistics as st
from hydrofmu.cosim.summary import split_period

DT = 0.2


def band_noise(n, lo, hi, sigma, rng, count=1):
    """``count`` records of n samples: a flat spectrum over [lo, hi] rad/s of variance sigma²
    (the lines' amplitudes a = σ·√(2/K) over the K lines of the band); also (m0, m2)."""
    w = 2 * np.pi * np.fft.rfftfreq(n, DT)
    band = (w >= lo) & (w <= hi)
    a = np.where(band, sigma * math.sqrt(2.0 / band.sum()), 0.0)
    phase = rng.uniform(0, 2 * np.pi, (count, w.size))
    x = np.fft.irfft(a * np.exp(1j * phase) * n / 2, n, axis=1)
    return x, float(np.sum(a ** 2) / 2), float(np.sum(a ** 2 * w ** 2) / 2)


def test_narrow_band_gaussian_most_probable_maximum():
    """Rice: a Gaussian process crosses zero upwards every T_z = 2π√(m0/m2); its N = T/T_z
    Rayleigh peaks have their most probable largest at σ√(2 ln N).  One hour of a 0.7–1.3 rad/s
    band: the Rayleigh figure of the WF part and the Weibull fit to the record's peaks give it;
    so does the mode of 400 records' observed maxima (a Gumbel fitted to them, scipy)."""
    from scipy.stats import gumbel_r
    rng = np.random.default_rng(5)
    n = int(3600 / DT)
    x, m0, m2 = band_noise(n, 0.7, 1.3, 1.0, rng, count=400)
    tz = 2 * math.pi * math.sqrt(m0 / m2)
    mpm = math.sqrt(2 * math.log(n * DT / tz))            # 3.57 (N = 581 cycles)
    figures = [st.describe(r, DT, period=20.0) for r in x[:40]]
    assert np.mean([f["wf_tz"] for f in figures]) == pytest.approx(tz, rel=0.01)
    assert np.mean([f["wf_mpm"] for f in figures]) == pytest.approx(mpm, rel=0.005)
    weibull = [f["mpm_max"] - f["mean"] for f in figures]
    assert np.mean(weibull) == pytest.approx(mpm, rel=0.02)      # one record's fit scatters by ~3 %
    assert np.mean([st.weibull_fit(st.peaks(r - r.mean()))[1] for r in x[:40]]) == pytest.approx(2.0, rel=0.05)
    mode, scale = gumbel_r.fit(x.max(axis=1))
    assert mode == pytest.approx(mpm, abs=3 * 1.1 * scale / math.sqrt(x.shape[0]))   # within 3 standard errors
    # the troughs as the peaks: the process is symmetric
    assert np.mean([f["mean"] - f["mpm_min"] for f in figures]) == pytest.approx(mpm, rel=0.02)


@pytest.mark.parametrize("period", [100.0, 113.7, 257.3])   # whole and fractional cycles in the record
def test_a_known_slow_sine_under_known_wave_noise(period):
    """x = 2 + 1.5·sin(2πt/T) + WF noise of std 0.5 (0.7–1.3 rad/s), split at 4π s (2·Tp of a
    2π s sea): the parts' std are 1.5/√2 and 0.5, the mean 2 (the sine's own mean over the record
    aside), and the LF extreme the sine's amplitude; the parts add up to the record."""
    rng = np.random.default_rng(7)
    n = int(3600 / DT)
    t = np.arange(n) * DT
    noise = band_noise(n, 0.7, 1.3, 0.5, rng)[0][0]
    slow = 1.5 * np.sin(2 * np.pi * t / period + 0.3)
    x = 2.0 + slow + noise
    d = st.describe(x, DT, period=4 * np.pi)
    assert d["mean"] == pytest.approx(2.0 + slow.mean(), abs=1e-12)
    assert d["lf_std"] == pytest.approx(slow.std(), rel=1e-3)
    assert d["wf_std"] == pytest.approx(0.5, rel=1e-3)
    assert d["lf_mpm"] == pytest.approx(1.5, rel=0.01)
    assert d["std"] ** 2 == pytest.approx(d["lf_std"] ** 2 + d["wf_std"] ** 2, rel=2e-3)   # the parts hardly correlate
    mean, lf, wf = st.parts(x, DT, 4 * np.pi)
    np.testing.assert_allclose(mean + lf + wf, x, atol=1e-12)
    assert abs(lf.mean()) < 1e-12 and abs(wf.mean()) < 1e-12
    # no split: no LF/WF figures, the extremes still from the peaks
    none = st.describe(x, DT, None)
    assert math.isnan(none["lf_std"]) and math.isnan(none["wf_mpm"]) and none["mpm_max"] > none["mean"]


def test_a_flat_or_empty_record():
    d = st.describe(np.full(100, 3.0), DT, 10.0)
    assert (d["std"], d["lf_std"], d["wf_std"], d["wf_mpm"], d["lf_mpm"]) == (0, 0, 0, 0, 0)
    assert d["mpm_max"] == d["mpm_min"] == d["mean"] == 3.0
    assert math.isnan(st.describe(np.array([np.nan]), DT, 10.0)["mean"])


def test_welch_estimate_of_a_known_spectrum():
    """A Gaussian process of the JONSWAP spectrum (Hs 2 m, Tp 7.85 s, γ 3.3; Rayleigh
    amplitudes, 3 h): Welch's estimate averages to the spectrum over its band and scatters by
    √(2/ν), ν = 2K/(1 + 2c²) equivalent degrees of freedom of K half-overlapping Hann segments
    (c = 0.167, Percival & Walden); ∫S dω is the record's variance; the estimate is
    scipy.signal.welch's with the same settings."""
    from scipy.signal import welch
    from hydrofmu.physics.waves import spectrum as jonswap   # any known shape would do
    rng = np.random.default_rng(11)
    spectrum = lambda sea, omega: jonswap(omega, 2.0, 7.85, 3.3)
    sea = None
    n = int(3 * 3600 / DT)
    w = 2 * np.pi * np.fft.rfftfreq(n, DT)
    s = np.where(w > 0, spectrum(sea, np.maximum(w, 1e-9)), 0.0)
    amp = np.sqrt(2 * s * w[1]) * (rng.normal(size=w.size) + 1j * rng.normal(size=w.size)) / math.sqrt(2)
    x = np.fft.irfft(amp * n / 2, n)
    omega, got = st.spectrum(x, DT)
    f, ref = welch(x, fs=1 / DT, window="hann", nperseg=st.segment(n), noverlap=st.segment(n) // 2,
                   detrend="constant")
    np.testing.assert_allclose(omega, 2 * np.pi * f)
    np.testing.assert_allclose(got * 2 * np.pi, ref, rtol=1e-10, atol=1e-14 * ref.max())
    band = spectrum(sea, np.maximum(omega, 1e-9)) > 0.1 * spectrum(sea, np.array([2 * np.pi / 7.85]))[0]
    ratio = got[band] / spectrum(sea, omega[band])
    k = len(range(0, n - st.segment(n) + 1, st.segment(n) - st.segment(n) // 2))
    nu = 2 * k / (1 + 2 * 0.167 ** 2)
    assert ratio.mean() == pytest.approx(1.0, abs=0.05)
    assert ratio.std() == pytest.approx(math.sqrt(2 / nu), rel=0.25)
    assert np.trapezoid(got, omega) == pytest.approx(x.var(), rel=0.03)


def test_the_split_comes_from_the_sea_unless_given():
    sea = {"run": {"waves": {"period": 6.0, "ramp": 30.0, "spectrum": "jonswap"}}}
    assert split_period(sea) == {"period": 12.0, "from": "2·Tp, Tp = 6 s of the scene's sea"}
    assert split_period({"run": {**sea["run"], "split": 30.0}})["period"] == 30.0     # the scene's [run] split
    assert split_period(sea, 25.0) == {"period": 25.0, "from": "given"}
    assert split_period({"run": {}})["period"] is None
    with pytest.raises(ValueError, match="split must be a period > 0"):
        split_period(sea, -1.0)
