"""Checks of a BEM result's conventions by laws its excitation and radiation obey together.

- **Haskind** (Newman 1962; energy: the power a body radiates equals what its excitation
  could absorb from waves of every heading):

      B_ij(ω) = k / (8π·ρ·g·c_g) · Re ∫_0^{2π} X_i(β)·conj(X_j(β)) dβ

  with X per unit wave amplitude [N/m, N·m/m], c_g = ω/(2k)·(1 + 2kh/sinh 2kh) the group
  velocity (deep water g/(2ω): B_ij = ω³/(4πρg³)·Re ∫X_i X̄_j dβ).  A dataset whose excitation
  or damping has the wrong scale (ρ, g, ULEN, a forgotten ω in WAMIT's B̄) or one dof's sign
  flipped (the couplings B_ij change sign) breaks it.  Its |X|² cannot see a conjugation, a
  sign flip of every dof or a heading measured the wrong way; the long-wave phase can:
- **long waves** (kL ≪ 1, the lowest frequency of the file): a body small against the wave
  moves with the water, its surge and sway excitation is the Froude–Krylov and added-mass
  force on the water's horizontal acceleration, which leads the elevation at the body by 90°:
  Im{X_1·e^{ik(x cos β + y sin β)}} has the sign of cos β, Im{X_2·…} that of sin β (e^{+iωt},
  β going to; a conjugated X, a sign-flipped one, headings coming-from or clockwise give the
  opposite).

The Haskind integral needs |X(β)|² around the circle: the headings themselves, or completed
by the body's symmetry, the largest gap at most MAX_GAP.  A single body's symmetry is read from
its radiation coefficients (a plane of symmetry decouples the dofs that are even from those
that are odd under its reflection: xz decouples {surge, heave, pitch} from {sway, roll, yaw},
yz {sway, heave, roll} from {surge, pitch, yaw}; both, with B_11 = B_22 and B_44 = B_55 and no
yaw damping, make it axisymmetric: one heading suffices, X rotating with the heading).
"""
from __future__ import annotations

import functools
import math
from pathlib import Path

import numpy as np

MAX_GAP = 45.0         # deg: the largest heading gap the integral takes (trapezoid exact to the 7th harmonic)
DECOUPLED = 0.03       # a coupling this small against √(peak B_ii·peak B_jj) is the panels' noise
DEAD = 1e-6            # a dof whose damping peaks below this of its kind's largest radiates nothing
RESOLVED = 0.03        # |X(β)|²'s top harmonics on the heading grid below this of its mean: resolved
TOLERANCE = 0.10       # of √(peak B_ii·peak B_jj): the Haskind misfit allowed (clean datasets: ≤ 4.5 %)
EVEN = {"xz": (1, 3, 5), "yz": (2, 3, 4)}   # the dofs (1…6) even under each plane's reflection
SIGN = {"xz": np.array([1, -1, 1, -1, 1, -1]), "yz": np.array([-1, 1, 1, 1, -1, -1])}


def group_velocity(omega, k, depth):
    """c_g [m/s] of ω, k at depth h (inf: deep water)."""
    if math.isinf(depth):
        return 0.5 * omega / k
    kh = k * depth
    return 0.5 * omega / k * (1 + 2 * kh / np.sinh(2 * kh))


def alive(damping):
    """The dofs (6,) with damping to speak of: a peak B_ii above DEAD of the largest of its
    kind (translations, rotations); a body radiates no yaw waves if it is round."""
    peak = np.abs(np.einsum("nii->ni", damping)).max(axis=0)
    kind = np.repeat([peak[:3].max(), peak[3:].max()], 3)
    return peak > DEAD * kind


def symmetry(damping, added_mass=None):
    """The symmetry of one body's 6×6 radiation coefficients (N, 6, 6): the planes "xz", "yz"
    whose even and odd dofs they decouple (every coupling of live dofs below DECOUPLED of
    √(peak_i·peak_j)), plus "axi" for both with B_11 = B_22, B_44 = B_55 (to 1 %) and no yaw."""
    live = alive(damping)
    found = []
    for plane, even in EVEN.items():
        ok = True
        for m in (damping, added_mass):
            if m is None:
                continue
            peak = np.abs(np.einsum("nii->ni", m)).max(axis=0)
            for i in even:
                for j in set(range(1, 7)) - set(even):
                    if live[i - 1] and live[j - 1]:
                        c = np.abs(m[:, [i - 1, j - 1], [j - 1, i - 1]]).max()
                        ok &= bool(c <= DECOUPLED * math.sqrt(peak[i - 1] * peak[j - 1]))
        if ok:
            found.append(plane)
    d = np.einsum("nii->ni", damping)
    same = lambda i, j: np.abs(d[:, i] - d[:, j]).max() <= 1e-2 * np.abs(d[:, [i, j]]).max()   # noqa: E731
    if len(found) == 2 and same(0, 1) and same(3, 4) and not live[5]:
        found.append("axi")
    return tuple(found)


def around(values, directions, omega, k, position, sym):
    """(headings [deg], X (nω, nβ', 6) at the body's own place) around the circle: the file's
    headings completed by the symmetry ``sym`` (``symmetry``), or None when they leave a gap
    wider than MAX_GAP.  ``values`` (nω, nβ, 6), X referred to the global origin; ``position``
    the body's (x, y); the products X_i·X̄_j are the same at either place."""
    beta = np.radians(np.asarray(directions, float))
    local = values * np.exp(1j * k[:, None] * (position[0] * np.cos(beta) + position[1] * np.sin(beta)))[..., None]
    if "axi" in sym:   # X of every heading from the first, rotated with it
        b = np.radians(np.arange(0.0, 360.0, 10.0))
        d = b - beta[0]
        c, s = np.cos(d)[None, :], np.sin(d)[None, :]
        x0 = local[:, 0, :][:, None, :]
        out = np.zeros((local.shape[0], b.size, 6), complex)
        out[..., 0], out[..., 1] = c * x0[..., 0] - s * x0[..., 1], s * x0[..., 0] + c * x0[..., 1]
        out[..., 2] = x0[..., 2]
        out[..., 3], out[..., 4] = c * x0[..., 3] - s * x0[..., 4], s * x0[..., 3] + c * x0[..., 4]
        return np.degrees(b), out
    heads, xs = [np.degrees(beta)], [local]
    for plane in ("xz", "yz"):
        if plane in sym:   # the reflection: β → −β (xz) or 180° − β (yz), each dof its parity
            heads = heads + [(-h if plane == "xz" else 180.0 - h) for h in heads]
            xs = xs + [x * SIGN[plane] for x in xs]
    h = np.mod(np.concatenate(heads), 360.0)
    x = np.concatenate(xs, axis=1)
    key = np.round(h, 6)
    _, first = np.unique(key, return_index=True)
    h, x = h[first], x[:, first]
    gaps = np.diff(np.r_[h, h[0] + 360.0])
    if gaps.max() > MAX_GAP + 1e-9:
        return None
    return h, x


def haskind(omega, directions, values, position, damping_omega, damping, depth, rho, g, sym=()):
    """(ω (M,), B from X (M, 6, 6), the file's B (M, 6, 6)) at the excitation's frequencies
    within the damping's that the heading grid resolves (on a uniform grid: the top two
    harmonics of every |X_i(β)|² below RESOLVED of its mean), or None when the headings do not
    go round (``around``) or resolve no frequency.  ``values``
    (nω, nβ, 6) X referred to the origin; ``damping`` (N, 6, 6) on ``damping_omega``."""
    from ..physics.waves import wave_number
    omega = np.asarray(omega, float)
    keep = (omega >= damping_omega[0]) & (omega <= damping_omega[-1])
    omega, values = omega[keep], np.asarray(values)[keep]
    if omega.size == 0:
        return None
    k = np.asarray(wave_number(omega, g, depth), float)
    found = around(values, directions, omega, k, position, sym)
    if found is None:
        return None
    h, x = found
    gaps = np.diff(np.r_[h, h[0] + 360.0])
    if np.ptp(gaps) < 1e-6 and h.size > 3:   # a uniform grid: keep the frequencies it resolves
        f = np.abs(np.fft.rfft(np.abs(x) ** 2, axis=1))
        top = f[:, -2:].max(axis=1) / np.where(f[:, 0] > 0, f[:, 0], 1.0)
        # (not yaw: a doubly symmetric body's |X_6|² ∝ sin²2β holds the 45° grid's top
        # harmonic itself, which the trapezoid integrates exactly)
        ok = np.all(top[:, :5][:, alive(damping)[:5]] <= RESOLVED, axis=-1)
        omega, k, x = omega[ok], k[ok], x[ok]
        if omega.size == 0:
            return None
    w = np.diff(np.r_[h, h[0] + 360.0])           # periodic trapezoid: each heading half of both gaps
    w = np.radians(0.5 * (w + np.roll(w, 1)))
    integral = np.einsum("b,nbi,nbj->nij", w, x, np.conj(x)).real
    from_x = (k / (8 * math.pi * rho * g * group_velocity(omega, k, depth)))[:, None, None] * integral
    file_b = np.array([[np.interp(omega, damping_omega, damping[:, i, j]) for j in range(6)] for i in range(6)])
    return omega, from_x, np.moveaxis(file_b, -1, 0)


def misfit(from_x, file_b):
    """The Haskind misfit of each dof pair: max over ω of |B from X − B| over √(peak B_ii·peak
    B_jj) (6, 6), NaN where a dof has no damping to speak of (``alive``)."""
    peak = np.abs(np.einsum("nii->ni", file_b)).max(axis=0)
    live = alive(file_b)
    scale = np.sqrt(np.outer(peak, peak))
    out = np.abs(from_x - file_b).max(axis=0) / np.where(scale > 0, scale, 1.0)
    out[~(live[:, None] & live[None, :])] = np.nan
    return out


def long_wave_phase(omega, directions, values, position, g, depth):
    """The headings (deg) at which the lowest frequency's surge or sway excitation does not
    lead the elevation at the body (module docstring): Im{X_1 e^{ik·x}}·cos β < 0 or
    Im{X_2 e^{ik·x}}·sin β < 0, where |cos β| (|sin β|) > 0.5 and the dof is excited."""
    from ..physics.waves import wave_number
    k = float(wave_number(np.asarray(omega[:1], float), g, depth)[0])
    beta = np.radians(np.asarray(directions, float))
    x = np.asarray(values)[0] * np.exp(1j * k * (position[0] * np.cos(beta) + position[1] * np.sin(beta)))[:, None]
    bad = []
    for dof, f in ((0, np.cos(beta)), (1, np.sin(beta))):
        big = np.abs(x[:, dof]).max()
        sel = (np.abs(f) > 0.5) & (np.abs(x[:, dof]) > 1e-3 * big) & (big > 0)
        bad += [float(d) for d in np.degrees(beta[sel & (x[:, dof].imag * f < 0)])]
    return sorted(set(bad))


DOF = ("surge", "sway", "heave", "roll", "pitch", "yaw")


@functools.lru_cache(maxsize=16)
def _radiation(path, stamp, ulen, rho, g, variable):
    """The radiation result of ``path`` (BemData) or None when it has none or cannot be read
    (a dataset with excitation alone is legal: nothing to check then); ``stamp``: the file's
    (mtime, size), so that a rewritten file is read again."""
    from ..errors import InputError
    from .bem import read_bem
    try:
        return read_bem(path, ulen, rho, g, variable)
    except (InputError, OSError, ValueError, KeyError):
        return None


def radiation_of(path, ulen=None, rho=1025.0, g=9.81, variable=None):
    """The radiation result that goes with an excitation file: a Capytaine dataset's own, a
    WAMIT .3 / .2 file's ``.1`` beside it (same stem); None without one."""
    p = Path(path)
    if p.suffix in (".2", ".3"):
        p = p.with_suffix(".1")
        if not p.is_file():
            return None
    elif not p.is_file():
        return None
    st = p.stat()
    return _radiation(str(p), (st.st_mtime_ns, st.st_size), ulen if p.suffix == ".1" else None,
                      rho if p.suffix == ".1" else None, g if p.suffix == ".1" else None,
                      variable if p.suffix == ".1" else None)


def body_block(data, body):
    """(damping, added mass) (N, 6, 6) of one body of a BemData, zero for dofs it leaves out."""
    idx = [data.index(body, k) for k in range(1, 7)]
    b, a = (np.zeros((len(data.omega), 6, 6)) for _ in range(2))
    for i, ii in enumerate(idx):
        for j, jj in enumerate(idx):
            if ii is not None and jj is not None:
                b[:, i, j], a[:, i, j] = data.damping[:, ii, jj], data.added_mass[:, ii, jj]
    return b, a


def excitation_problems(name, body, omega, directions, values, position, radiation, depth, rho, g):
    """The warnings (messages) of one body's excitation ``values`` (nω, nβ, 6) against its
    radiation result (BemData): the Haskind relation beyond TOLERANCE, the long-wave phase,
    or (once) why the Haskind relation could not be checked.  ``name``: the file's name."""
    said = []
    bad = long_wave_phase(omega, directions, values, position, g, depth)
    if bad:
        said.append(f"{name}: at its lowest frequency ({omega[0]:.3g} rad/s) the surge or sway excitation of body "
                    f"{body!r} lags the elevation at the body by 90° instead of leading it (headings "
                    f"{', '.join(f'{b:g}' for b in bad)}°): a long wave's Froude–Krylov and added-mass force follow "
                    "the water's acceleration.  A conjugated excitation (e^{−iωt} read as e^{+iωt}), a sign-flipped "
                    "one, or headings measured coming-from or clockwise?")
    if radiation is None or body not in radiation.bodies:
        return said
    damping, added = body_block(radiation, body)
    sym = symmetry(damping, added) if len(radiation.bodies) == 1 else ()
    found = haskind(omega, directions, values, position, radiation.omega, damping, depth, rho, g, sym)
    if found is None:
        said.append(f"{name}: the Haskind check of body {body!r} (its excitation against its radiation damping) is "
                    f"left out: the headings {', '.join(f'{b:g}' for b in directions)}° do not go round the circle in "
                    f"steps of at most {MAX_GAP:g}° at any frequency the grid resolves, even with the symmetry its "
                    f"radiation coefficients show ({', '.join(sym) or 'none'}"
                    f"{'; several bodies: no symmetry taken' if len(radiation.bodies) > 1 else ''})")
        return said
    w, from_x, file_b = found
    m = misfit(from_x, file_b)
    if np.nanmax(m, initial=0.0) > TOLERANCE:
        i, j = np.unravel_index(np.nanargmax(m), m.shape)
        scale = math.sqrt(abs(file_b[:, i, i]).max() * abs(file_b[:, j, j]).max())
        n = int(np.argmax(np.abs(from_x[:, i, j] - file_b[:, i, j])))
        pair = DOF[i] if i == j else f"{DOF[i]}–{DOF[j]}"
        said.append(f"{name}: the excitation and the radiation damping of body {body!r} break the Haskind relation "
                    f"B_ij = k/(8πρg·c_g)·Re∫X_i·X̄_j dβ by {100 * m[i, j]:.3g} % of √(B_ii·B_jj) in {pair} (at "
                    f"{w[n]:.3g} rad/s: {from_x[n, i, j]:.4g} from the excitation, {file_b[n, i, j]:.4g} in the file; "
                    f"scale {scale:.4g}; clean BEM results stay within 5 %): a dof's sign flipped, "
                    "the damping or the excitation scaled wrongly (ρ, g, ULEN), or results of two different runs?")
    return said
