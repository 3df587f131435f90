"""A JONSWAP sea on a floating body: motion statistics of the time-domain run against the
frequency domain of the same BEM dataset, and the response spectra.

    python examples/waves_statistics.py [SCENE] [--stop T] [--transient T] [--out DIR]

SCENE defaults to models/buoy_in_waves.toml (a buoy, BEM data from Capytaine).  The
frequency domain uses the dataset's mass M, added mass A(ω), radiation damping B(ω),
excitation F(ω, β) and hydrostatics C, with the scene body's own linear damping D and
stiffness K (its mooring):

    X(ω) = [−ω²·(M + A(ω)) + iω·(B(ω) + D) + C + K]⁻¹ · F(ω, β)     (per metre of wave amplitude)

Per dof three standard deviations, after ``--transient`` (default: the ramp + 60 s):
  time domain   the run's record (the FMUs: convolution memory, hydrostatics, excitation);
  same sea      x(t) = Σ a_k·Re{X(ω_k)·e^{i(ω_k t + φ_k)}}: the linear response to the very
                components the FMU sums (same seed), over the same times;
  spectral      √∫|X(ω)|²·S(ω) dω: the expectation over every sea of this spectrum.
The first two differ by what the time domain does differently (memory, step, the start);
the last differs from them by the record's length (a short record is one sample).
Writes <scene>_spectra.png: the response spectra (Welch of the record) against |X|²·S.
"""
import argparse
import math
from pathlib import Path

import numpy as np

import hydrofmu

MODELS = Path(__file__).resolve().parents[1] / "models"
DOFS = {"heave": ("position", 2, 2, "m"), "roll": ("attitude", 0, 3, "deg"), "pitch": ("attitude", 1, 4, "deg")}


def frequency_domain(scene, body):
    """(ω grid [rad/s], X on it (n, 6) complex, transfer at any ω, the dataset path) of the
    body's BEM dataset, long-crested at the sea's direction."""
    import xarray as xr
    effect = next(e for e in body.effects if e.type == "wave_excitation")
    path = Path(effect.data["bem"])
    ds = xr.load_dataset(path)
    finite = np.isfinite(ds["omega"].values)
    w = ds["omega"].values[finite]
    a = ds["added_mass"].values[finite]
    b = ds["radiation_damping"].values[finite]
    f = ds["excitation_force"].sel(wave_direction=math.radians(scene.waves.direction), method="nearest")
    if abs(math.degrees(float(f["wave_direction"])) - scene.waves.direction) > 1e-6:
        raise SystemExit(f"{path.name}: no direction {scene.waves.direction:g}° solved (this example needs it)")
    f = f.transpose("complex", "omega", "influenced_dof").values
    f = np.conj(f[0] + 1j * f[1])[finite]   # Capytaine's e^{-iωt} -> e^{+iωt}
    m = ds["inertia_matrix"].values
    six = lambda m: np.diag(m) if np.ndim(m) == 1 else np.asarray(m, float)   # a diagonal or a 6×6 matrix
    c = ds["hydrostatic_stiffness"].values + six(body.stiffness)
    d = six(body.damping)

    def transfer(omega):
        """X at ``omega`` (n,) [rad/s]: A, B and F interpolated linearly in ω, then solved."""
        omega = np.atleast_1d(omega)
        lerp = lambda y: np.stack([np.interp(omega, w, y[:, i, j]) for i in range(6) for j in range(6)],
                                  axis=-1).reshape(-1, 6, 6)
        fx = np.stack([np.interp(omega, w, f[:, i].real) + 1j * np.interp(omega, w, f[:, i].imag)
                       for i in range(6)], axis=-1)
        h = (-omega[:, None, None] ** 2 * (m + lerp(a)) + 1j * omega[:, None, None] * (lerp(b) + d) + c)
        return np.linalg.solve(h, fx[..., None])[..., 0]

    return w, transfer, path


def statistics(scene, result, transient):
    """{dof: (time-domain std, same-sea std, spectral std)} [m or deg], and the spectra's data."""
    from hydrofmu.physics.waves import components, spectrum
    (name, body), = [(n, b) for n, b in scene.bodies.items() if any(e.type == "wave_excitation" for e in b.effects)]
    sea = scene.waves
    w, transfer, _ = frequency_domain(scene, body)
    comps = components(sea, (float(w[0]), float(w[-1])))   # the FMU's components: same seed, same window
    t = result.time
    keep = t >= transient
    x_td = {"position": result.motion(name, "position", 3), "attitude": result.motion(name, "attitude", 3)}
    x_comp = transfer(comps.omega)                             # (N, 6)
    phase = comps.omega[None, :] * t[keep, None] + comps.phase[None, :]
    fine = np.linspace(w[0], w[-1], 4000)
    gamma = 1.0 if sea.spectrum == "pierson_moskowitz" else sea.gamma
    s = spectrum(fine, sea.hs, sea.tp, gamma)
    x_fine = transfer(fine)
    out, spectra = {}, {}
    for dof, (kind, i, j, unit) in DOFS.items():
        scale = math.degrees(1.0) if unit == "deg" else 1.0
        td = x_td[kind][keep, i] * scale
        same = (np.cos(phase) @ (comps.amplitude * x_comp[:, j]).real
                - np.sin(phase) @ (comps.amplitude * x_comp[:, j]).imag) * scale
        response = np.abs(x_fine[:, j] * scale) ** 2 * s
        out[dof] = (float(td.std()), float(same.std()), float(math.sqrt(np.trapezoid(response, fine))))
        spectra[dof] = (td, fine, response, unit)
    return out, spectra, name


def plot_spectra(spectra, step, path, title):
    """The response spectra: Welch's estimate of each record against |X|²·S [unit²·s/rad]."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from scipy.signal import welch
    fig, axes = plt.subplots(1, len(spectra), figsize=(4.6 * len(spectra), 3.8), squeeze=False)
    for ax, (dof, (td, fine, response, unit)) in zip(axes[0], spectra.items()):
        f, p = welch(td - td.mean(), fs=1.0 / step, nperseg=min(len(td), max(256, len(td) // 4)))   # ~7 segments
        ax.plot(2 * math.pi * f, p / (2 * math.pi), color="C0", label="time domain (Welch)")
        ax.plot(fine, response, color="black", ls="--", label="|X|²·S (frequency domain)")
        ax.set_xlim(0, min(3.0, fine[-1]))
        ax.set_xlabel("ω [rad/s]")
        ax.set_title(f"{dof} response spectrum [{unit}²·s/rad]", fontsize=9)
        ax.grid(True, alpha=0.3)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("scene", nargs="?", default=MODELS / "buoy_in_waves.toml", type=Path)
    parser.add_argument("--stop", type=float, help="end time [s] (default: the scene's)")
    parser.add_argument("--transient", type=float, help="statistics from this time on [s] (default: ramp + 60 s)")
    parser.add_argument("--out", type=Path, default=Path("build") / "examples", help="build folder")
    args = parser.parse_args(argv)

    scene = hydrofmu.load_scene(args.scene)
    sea = scene.waves
    if sea is None or sea.spectrum == "regular" or sea.spreading:
        raise SystemExit(f"{args.scene}: this example needs a long-crested JONSWAP or Pierson-Moskowitz sea")
    result = hydrofmu.run(scene, out=args.out, stop=args.stop)
    transient = sea.ramp + 60.0 if args.transient is None else args.transient
    stats, spectra, body = statistics(scene, result, transient)
    print(f"{scene.name}: {sea.spectrum} Hs {sea.hs:g} m, Tp {sea.tp:g} s, heading {sea.direction:g}°, "
          f"{sea.components} components; body {body}, statistics over t = {transient:g}–{result.time[-1]:g} s "
          f"(step {result.step:g} s)")
    print(f"{'std':8} {'time domain':>12} {'same sea':>10} {'spectral':>10}")
    for dof, (td, same, spectral) in stats.items():
        unit = DOFS[dof][3]
        print(f"{dof + ' [' + unit + ']':8} {td:12.4g} {same:10.4g} {spectral:10.4g}   "
              f"time domain / same sea {100 * (td / same - 1):+.2f} %")
    png = plot_spectra(spectra, result.step, args.out / f"{scene.name}_spectra.png",
                       f"{scene.name}: response spectra, t = {transient:g}–{result.time[-1]:g} s")
    print(f"wrote {png}")
    return stats


if __name__ == "__main__":
    main()
