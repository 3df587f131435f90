"""Write SIMO coupling decks whose kernels are h(t) = c·e^(−a·t)·cos(ω·t), sampled at
TIMDEL: one analytic family that a monolithic reference can integrate exactly."""
import numpy as np


def kernel(c, a, w, timdel, length):
    t = np.arange(int(round(length / timdel)) + 1) * timdel
    return c * np.exp(-a * t) * np.cos(w * t)


def coupling_group(name, body_a, body_b, added_mass, kernels, timdel, length, text="analytic kernels"):
    """``added_mass``: 6×6; ``kernels``: {(IDOF_A, IDOF_B): (c, a, ω)}."""
    lines = ["HYDRodynamic COUPling DATA", name, text, "h(t) = c exp(-a t) cos(w t)", body_a, body_b,
             "COUPled ADDEd MASS"]
    lines += ["  " + "  ".join(f"{x:.6e}" for x in row) for row in np.asarray(added_mass, float)]
    if kernels:
        lines += ["COUPled RETArdation FUNCtion", f"{timdel}", "RETArdation ELEment DATA"]
        for (i, j), (c, a, w) in kernels.items():
            h = kernel(c, a, w, timdel, length)
            lines.append(f"{len(h)} {i} {j}")
            rows = [" ".join(f"{x:.9e}" for x in h[k:k + 6]) for k in range(0, len(h), 6)]
            lines += [r + " &" for r in rows[:-1]] + [rows[-1]]
    return lines


def write_deck(path, groups, header="SIMO hydrodynamic coupling data (SI units)"):
    text = [f"' {header}"]
    for g in groups:
        text += ["'"] + g
    path.write_text("\n".join(text) + "\n")
    return path
