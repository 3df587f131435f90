"""Write SIMO coupling decks whose kernels are h(t) = c·e^(−a·t)·cos(ω·t), sampled at
TIMDEL: one analytic family that a monolithic reference can integrate exactly."""
import numpy as np

from hydrofmu.decks.simo import format_coupling, write_couplings


def kernel(c, a, w, timdel, length):
    t = np.arange(int(round(length / timdel)) + 1) * timdel
    return c * np.exp(-a * t) * np.cos(w * t)


def coupling_group(name, body_a, body_b, added_mass, kernels, timdel, length, text="analytic kernels"):
    """``added_mass``: 6×6; ``kernels``: {(IDOF_A, IDOF_B): (c, a, ω)}."""
    sampled = {ij: kernel(*cawv, timdel, length) for ij, cawv in kernels.items()}
    return format_coupling(name, body_a, body_b, added_mass, sampled, timdel,
                           (text, "h(t) = c exp(-a t) cos(w t)"))


def write_deck(path, groups, header="SIMO hydrodynamic coupling data (SI units)"):
    return write_couplings(path, groups, header)
