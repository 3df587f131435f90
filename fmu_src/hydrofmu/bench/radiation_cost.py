"""Cost of the BEM transform (``physics.radiation.transform``) on a synthetic multi-body result.

The result is made of three analytic Cummins modes K_m(t) = e^{−α_m t}·cos β_m t − c_m·e^{−γ_m t}
(c_m so that B_m(0) = 0) mixed by random symmetric positive matrices, so A(ω), B(ω) are
reciprocal and causal like a panel code's and their size is free (dofs × frequencies).
"""
import numpy as np

from ..physics.radiation import transform
from .timing import per_call

MODES = ((0.5, 1.5, 1.0), (0.3, 0.8, 0.6), (0.8, 2.5, 1.5))   # (α, β, γ) per mode


def synthetic(dofs=12, frequencies=100, top=5.0, seed=0):
    """(ω, A(ω), B(ω), A∞) of a synthetic result with ``dofs`` dofs on ``frequencies`` points."""
    rng = np.random.default_rng(seed)
    w = np.linspace(top / frequencies, top, frequencies)
    a_inf = np.eye(dofs) * 1e5
    a = np.tile(a_inf, (w.size, 1, 1))
    b = np.zeros_like(a)
    for alpha, beta, gamma in MODES:
        c = gamma * alpha / (alpha ** 2 + beta ** 2)
        lor = lambda x: alpha / (alpha ** 2 + x ** 2)
        bm = 0.5 * (lor(w - beta) + lor(w + beta)) - c * gamma / (gamma ** 2 + w ** 2)
        sm = 0.5 * ((w + beta) / (alpha ** 2 + (w + beta) ** 2) + (w - beta) / (alpha ** 2 + (w - beta) ** 2)) \
            - c * w / (gamma ** 2 + w ** 2)
        v = rng.normal(size=(dofs, dofs))
        mix = 1e4 * v @ v.T / dofs
        b += bm[:, None, None] * mix
        a -= (sm / w)[:, None, None] * mix
    return w, a, b, a_inf


def measure(sizes=((12, 50), (12, 100), (12, 200), (24, 100)), rounds=5):
    """Seconds per transform for each (dofs, frequencies), interleaved; rows for a CSV."""
    cases = {size: synthetic(*size) for size in sizes}
    times = per_call({size: (lambda c=c: (lambda k: transform(*c))) for size, c in cases.items()}, 1, rounds)
    base = times[sizes[0]]
    return [{"dofs": d, "frequencies": n, "seconds": times[(d, n)], "ratio": times[(d, n)] / base}
            for d, n in sizes]
