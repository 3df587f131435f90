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


def pair_deck(path, mass):
    """SA, SB (self) and AB (cross) couplings of bodies a and b of ``mass`` [kg]: A∞ a
    fraction of the mass, a few analytic kernels each (TIMDEL 0.1 s, 6 s long)."""
    am = np.diag([0.2, 0.3, 0.5, 0.0, 0.0, 0.0]) * mass
    cross = np.zeros((6, 6))
    cross[0, 0], cross[1, 2] = 0.1 * mass, 0.05 * mass
    return write_deck(path, [
        coupling_group("SA", "a", "a", am, {(1, 1): (2e5, 0.8, 1.0), (2, 2): (1e5, 0.5, 0.6)}, 0.1, 6.0),
        coupling_group("SB", "b", "b", am, {(3, 3): (3e5, 0.7, 0.9)}, 0.1, 6.0),
        coupling_group("AB", "a", "b", cross, {(1, 1): (5e4, 0.6, 0.8), (2, 3): (-2e4, 0.9, 1.2)}, 0.1, 6.0)])
