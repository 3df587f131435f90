"""Retardation memory: F(t) = −∫₀^∞ h(s)·v(t − s) ds for a matrix of kernels h_ij.

Conventions (shared by both evaluators):

- ``h`` is a matrix of scalar kernels h_ij [N·s/m², N·s/rad, …]: output (load) component i,
  input (velocity) component j.  Each h_ij is sampled at s = 0, TIMDEL, 2·TIMDEL, … and is
  linear between samples and zero after its last sample (a kernel may jump to zero there;
  different elements may have different lengths).
- The velocity v(τ) [m/s, rad/s] is linear between communication points and zero before the
  start: the history begins at the first point with v0, so F(t) = −∫_{t0}^{t} h(t − τ)·v(τ) dτ.
- The sign is that of a load on the body: F = −∫ h·v (a positive definite kernel damps).
- ``advance(dt, v_new)`` moves to t + dt with the new velocity and returns F at t + dt.
  ``state()`` / ``set_state(s)`` give/restore everything needed to continue exactly
  (plain lists, deep copies).  Cost and memory per step are bounded by the kernel length,
  never by the run length.

Two evaluators, one interface:

- ``Convolution``: exact for the piecewise-linear kernel and velocity above, for any step
  (dt ≠ TIMDEL, variable dt).  ``memory_length`` truncates the kernel (h = 0 beyond it).
- ``StateSpace``: every h_ij realised as h(t) ≈ C·exp(A·t)·B (``realise``), advanced exactly
  for a velocity linear within each step; cost per step independent of the kernel length.
"""
from collections import OrderedDict
from dataclasses import dataclass

import numpy as np


class MemoryFitWarning(UserWarning):
    """A state-space realisation not used as asked (physics.coupling.Coupling falls back to
    the convolution): names the coupling, the kernel element and why."""


def _elements(kernels, shape=None):
    """Normalise kernels to (shape, [(i, j, samples), …]), zero kernels left out.

    ``kernels``: a 1-D array (a scalar kernel, shape (1, 1)), an array (n_out, n_in, N),
    or a dict {(i, j): 1-D samples} with 0-based indices (``shape`` then gives (n_out, n_in);
    by default the smallest that holds the keys).
    """
    if isinstance(kernels, dict):
        items = [(int(i), int(j), np.asarray(h, float).ravel()) for (i, j), h in kernels.items()]
        if shape is None:
            shape = (max((i for i, _, _ in items), default=-1) + 1,
                     max((j for _, j, _ in items), default=-1) + 1)
    else:
        arr = np.asarray(kernels, float)
        if arr.ndim == 1:
            arr = arr[None, None, :]
        if arr.ndim != 3:
            raise ValueError("kernels: expected a dict, a 1-D or a 3-D (n_out, n_in, N) array")
        shape = shape or arr.shape[:2]
        items = [(i, j, arr[i, j]) for i in range(arr.shape[0]) for j in range(arr.shape[1])]
    shape = tuple(int(n) for n in shape)
    for i, j, _ in items:
        if not (0 <= i < shape[0] and 0 <= j < shape[1]):
            raise ValueError(f"kernel index ({i}, {j}) outside shape {shape}")
    return shape, [(i, j, h) for i, j, h in items if h.size and np.any(h != 0.0)]


def _start(shape, v0):
    """Velocity at the start: v0, or zero."""
    return np.zeros(shape[1]) if v0 is None else np.array(v0, float).reshape(shape[1])


class Convolution:
    """Memory integral by exact convolution of piecewise-linear kernels and velocity.

    kernels, shape: see module docstring (``_elements``); timdel [s]: kernel sample spacing;
    v0: velocity at the start (default zero); memory_length [s]: optional truncation of the
    kernel (h = 0 for s > memory_length), for speed/accuracy trade studies.

    The velocity history is kept as breakpoints (step lengths and values) in a buffer that
    drops points older than the (truncated) kernel.  At each step the integral of the
    product of two piecewise-linear functions is evaluated exactly on the merged breakpoints;
    the resulting node weights are cached, so a constant step costs one weighted sum.
    """

    def __init__(self, kernels, timdel, shape=None, v0=None, memory_length=None):
        self.shape, elems = _elements(kernels, shape)
        self._out = np.array([i for i, _, _ in elems], int)
        self._in = np.array([j for _, j, _ in elems], int)
        n_max = max((h.size for _, _, h in elems), default=1)
        if elems and not timdel > 0:
            raise ValueError("timdel must be > 0")
        if memory_length is not None and not memory_length > 0:
            raise ValueError("memory_length must be > 0")
        g = float(timdel or 1.0) * np.arange(n_max)
        hl = np.zeros((max(n_max - 1, 0), len(elems)))
        hr = np.zeros_like(hl)
        for e, (_, _, h) in enumerate(elems):
            hl[: h.size - 1, e] = h[:-1]   # segment k runs from sample k to sample k + 1;
            hr[: h.size - 1, e] = h[1:]    # segments past an element's end stay zero (jump)
        if memory_length is not None and hl.shape[0] and memory_length < g[-1]:
            k = int(np.searchsorted(g, memory_length, "left"))  # g[k-1] < L ≤ g[k]
            w = (memory_length - g[k - 1]) / (g[k] - g[k - 1])
            hr[k - 1] = hl[k - 1] + w * (hr[k - 1] - hl[k - 1])
            g = np.append(g[:k], memory_length)
            hl, hr = hl[:k], hr[:k]
        self._g, self._hl, self._hr = g, hl, hr
        self._h2 = np.vstack([hl, hr])
        self.span = float(g[-1]) if hl.shape[0] else 0.0   # s beyond which h = 0 [s]
        v = _start(self.shape, v0)
        self._v = np.zeros((64, v.size))
        self._dt = np.zeros(64)           # _dt[k]: time from node k − 1 to node k
        self._v[0], self._lo, self._hi = v, 0, 1
        self._key = self._w = None        # cached node offsets and their weights
        self._grid = None                 # (dt, uniform grid, right and left half-hat weights)
        self._peeked = None               # (dt, v, force, lo) of the last peek
        self.force = np.zeros(self.shape[0])

    @property
    def velocity(self):
        """Velocity at the current time."""
        return self._v[self._hi - 1].copy()

    def restart(self, v0):
        """Set the velocity at the start: the history's first node (before any ``advance``)."""
        self._v[self._hi - 1] = _start(self.shape, v0)
        self._peeked = None

    @property
    def nodes(self):
        """Number of velocity breakpoints held (bounded by span / smallest dt + 2)."""
        return self._hi - self._lo

    def peek(self, dt, v_new):
        """The memory load F(t + dt) if the velocity reached v_new at t + dt, without
        moving: the history is unchanged, and a following ``advance`` with the same
        arguments reuses the result (an FMU's feedthrough output before its step)."""
        if not dt > 0:
            raise ValueError(f"dt must be > 0, got {dt}")
        if self._hi == self._v.shape[0]:
            self._make_room()
        self._v[self._hi] = v_new
        self._dt[self._hi] = dt
        force, lo = self._evaluate(self._hi + 1)
        self._peeked = (float(dt), self._v[self._hi].copy(), force, lo)
        return force.copy()

    def advance(self, dt, v_new, peeked=False):
        """Move to t + dt [s] with velocity v_new; return the memory load F(t + dt).
        ``peeked``: as for ``StateSpace.advance``."""
        p = self._peeked
        if p is None or not peeked and (p[0] != dt or p[1].tolist() != np.asarray(v_new).tolist()):   # (lists: cheaper)
            self.peek(dt, v_new)
        _, _, self.force, self._lo = self._peeked
        self._hi += 1
        self._peeked = None
        return self.force.copy()

    def _make_room(self):
        """Grow the buffer when over half full, else compact it (amortised O(1) per step)."""
        n = self._hi - self._lo
        if 2 * n > self._v.shape[0]:
            self._v = np.concatenate([self._v, np.zeros_like(self._v)])
            self._dt = np.concatenate([self._dt, np.zeros_like(self._dt)])
        else:
            self._v[:n] = self._v[self._lo:self._hi]
            self._dt[:n] = self._dt[self._lo:self._hi]
            self._lo, self._hi = 0, n

    def _evaluate(self, hi):
        """(F at the node hi − 1, first node still needed) from the nodes lo … hi − 1."""
        lo = self._lo
        s = np.zeros(hi - lo)                     # node offsets back in time, newest first
        np.cumsum(self._dt[hi - 1:lo:-1], out=s[1:])
        k = int(np.searchsorted(s, self.span, "left"))
        if k < s.size - 1:                        # nodes beyond the first past the span
            lo = hi - (k + 1)                     # never matter again
            s = s[: k + 1]
        if not self._out.size or s.size < 2 or self.span == 0.0:
            return np.zeros(self.shape[0]), lo
        if self._key is None or self._key.shape != s.shape or not np.array_equal(self._key, s):
            self._key, self._w = s, self._weights_of(s, self._dt[hi - 1:lo:-1])
        v = self._v[hi - 1:lo - 1 if lo else None:-1]   # newest first, like s
        f = np.einsum("ke,ke->e", self._w, v[:, self._in])
        return -np.bincount(self._out, weights=f, minlength=self.shape[0]), lo

    def _weights_of(self, s, steps):
        """The node weights of offsets s, made of the step lengths ``steps`` (newest first,
        one per node after the first).
        While the history fills at a constant step, s is the start of one uniform grid and
        only its last node's hat is cut short: the weights are the grid's, each node's two
        half-hats computed once for the whole grid (a rebuild at every step would cost ten
        times the weighted sum, for the first memory length)."""
        if steps.size and steps[0] > 0 and (steps == steps[0]).all():
            dt = float(steps[0])
            if self._grid is None or self._grid[0] != dt:
                n = int(np.ceil(self.span / dt)) + 2        # nodes of a full history, and one
                grid = np.zeros(n)
                np.cumsum(np.full(n - 1, dt), out=grid[1:])   # (the sums _evaluate makes)
                m = int(np.searchsorted(grid, self.span, "left")) + 1
                self._grid = (dt, grid[:m], *self._weights(grid[:m], halves=True))
            _, grid, right, left = self._grid
            m = s.size
            if m <= grid.size and grid[m - 1] == s[-1]:
                w = left[:m].copy()   # (the last node's right half is past the offsets: none)
                w[:m - 1] += right[:m - 1]
                return w
        return self._weights(s)

    def _weights(self, s, halves=False):
        """W[k, e] = ∫ h_e(σ)·φ_k(σ) dσ with φ_k the hat function of node k (offset s_k);
        ``halves``: (the part over [s_k, s_k+1], the part over [s_k-1, s_k]) apart."""
        g, hl = self._g, self._hl
        top = min(s[-1], g[-1])
        p = np.union1d(s, g)
        p = p[p <= top]
        p = p[np.append(True, np.diff(p) > 1e-12 * top)]  # merge round-off twins
        a, b = p[:-1], p[1:]
        length, mid = b - a, 0.5 * (a + b)
        j = np.minimum(np.searchsorted(g, mid, "right") - 1, hl.shape[0] - 1)  # kernel segment
        k = np.minimum(np.searchsorted(s, mid, "right") - 1, s.size - 2)       # nodes k, k + 1
        # h = (1 − α)·hl[j] + α·hr[j] and the far hat φ = λ are linear on each piece, so
        # ∫ h·φ = L/6·(h_a·(2φ_a + φ_b) + h_b·(φ_a + 2φ_b)) is a scalar combination of the
        # segment end values: W = S·[hl; hr] with a sparse S (node × segment end).
        glen = g[j + 1] - g[j]
        aa, ab = (a - g[j]) / glen, (b - g[j]) / glen
        slen = s[k + 1] - s[k]
        la, lb = (a - s[k]) / slen, (b - s[k]) / slen
        c = length / 6.0
        fa, fb = c * (2 * la + lb), c * (la + 2 * lb)              # far node (k + 1)
        na, nb = c * (2 * (1 - la) + 1 - lb), c * (1 - la + 2 * (1 - lb))  # near node (k)
        cols = np.concatenate([j, j + hl.shape[0]])

        # S·[hl; hr] summed row by row with numpy alone (no scipy.sparse: an FMU's Python
        # needs numpy only, and a host whose steps are not all equal comes here every step)
        def part(rows, at_a, at_b):
            data = np.concatenate([(1 - aa) * at_a + (1 - ab) * at_b, aa * at_a + ab * at_b])
            out = np.zeros((s.size, self._h2.shape[1]))
            np.add.at(out, np.concatenate([rows, rows]), data[:, None] * self._h2[cols])
            return out
        if halves:
            return part(k, na, nb), part(k + 1, fa, fb)
        return part(k, na, nb) + part(k + 1, fa, fb)

    C_TAG = "convolution"   # its record in a compiled FMU (memory.c)

    def c_params(self):
        """memory.c's convolution parameters: [segments, elements, span, g (segments + 1),
        hl and hr (segments × elements, row-major), output and input index per element]."""
        nseg, ne = self._hl.shape
        return ([float(nseg), float(ne), self.span] + self._g[:nseg + 1].tolist() + self._hl.ravel().tolist()
                + self._hr.ravel().tolist() + self._out.astype(float).tolist() + self._in.astype(float).tolist())

    def state(self):
        """Everything needed to continue exactly: step lengths, velocity breakpoints (oldest
        first) and the current load, as plain lists."""
        return {"dt": self._dt[self._lo + 1:self._hi].tolist(),
                "v": self._v[self._lo:self._hi].tolist(),
                "force": self.force.tolist()}

    def set_state(self, state):
        """Restore a ``state()``."""
        v = np.array(state["v"], float).reshape(-1, self.shape[1])
        cap = max(64, 2 * v.shape[0])
        self._v = np.zeros((cap, self.shape[1]))
        self._dt = np.zeros(cap)
        self._v[: v.shape[0]] = v
        self._dt[1: v.shape[0]] = state["dt"]
        self._lo, self._hi = 0, v.shape[0]
        self.force = np.array(state["force"], float)
        self._peeked = None


@dataclass
class Realisation:
    """State-space realisation of one scalar kernel: h(t) ≈ C·exp(A·t)·B, t ≥ 0 [s].

    A is block diagonal with one block per mode: [σ] for a real pole, [[σ, ω], [−ω, σ]] for a
    pole pair σ ± iω; B is 1 on the first state of each block, so C holds the amplitudes
    (h = Σ c·e^{σt} + Σ e^{σt}·(c₁·cos ωt − c₂·sin ωt)).  All σ < 0.
    ``error``: normalised RMS fit error over the samples, √(mean (ĥ − h)²) / √(mean h²).
    ``deviation``: ∫|ĥ − K| dt / ∫|K| dt with K the piecewise-linear kernel the convolution
    uses, between the samples too (``realise``): the memory load of this realisation is
    within deviation·∫|K| dt·max|v| of the convolution's, at any step (NaN: not judged, e.g.
    a fit given by hand).  ``refused``: the orders ``realise`` refused and why ("" none).
    """
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    error: float
    deviation: float = float("nan")
    refused: str = ""

    @property
    def order(self):
        return self.A.shape[0]

    def __call__(self, t):
        """ĥ(t) for an array of times [s] ≥ 0."""
        return _basis(self.A, np.asarray(t, float)) @ self.C

    def areas(self):
        """Per mode, |γ|/|σ| [kernel unit·s]: the largest ∫|mode| dt, so ∫|ĥ| ≤ their sum."""
        out, k = [], 0
        for sig, om in _modes(self.A):
            out.append((np.hypot(self.C[k], self.C[k + 1]) if om else abs(self.C[k])) / -sig)
            k += 2 if om else 1
        return np.array(out)


def _modes(a):
    """(σ, ω) per block of a block-diagonal realisation matrix (ω = 0 for a real pole)."""
    out, k = [], 0
    while k < a.shape[0]:
        if k + 1 < a.shape[0] and a[k, k + 1] != 0.0:
            out.append((a[k, k], a[k, k + 1]))
            k += 2
        else:
            out.append((a[k, k], 0.0))
            k += 1
    return out


def _basis(a, t):
    """Columns exp(A·t)·B for the block structure of ``a``: one per state."""
    cols = []
    for sig, om in _modes(a):
        e = np.exp(sig * t)
        cols += [e] if om == 0.0 else [e * np.cos(om * t), -e * np.sin(om * t)]
    return np.stack(cols, axis=-1) if cols else np.zeros(t.shape + (0,))


def _assemble(poles):
    """Block-diagonal A for continuous poles (real ones and one of each conjugate pair)."""
    n = sum(1 if p.imag == 0 else 2 for p in poles)
    a, k = np.zeros((n, n)), 0
    for p in poles:
        if p.imag == 0:
            a[k, k] = p.real
            k += 1
        else:
            a[k:k + 2, k:k + 2] = [[p.real, p.imag], [-p.imag, p.real]]
            k += 2
    return a


RESOLVED = 2.0     # largest |λ|·TIMDEL of a realised pole (λ = σ + iω_d): see realise
CANCEL = 1e6       # largest Σ|γ_k|/|σ_k| of a realisation over ∫|K| dt: see realise
BETWEEN = 8        # points per TIMDEL on which a fit is judged between the samples
SLACK = 3.0        # between samples a fit may miss K by SLACK·(its miss at the samples + what they leave open)


class _Judge:
    """The piecewise-linear kernel K of samples h (``Convolution``'s: linear between them, zero
    after the last) on the midpoint grid of BETWEEN points per TIMDEL over the fit's window
    [0, 2T] (T = (N − 1)·TIMDEL), with ∫|K| dt (``area``) and what the samples leave open
    between them (``open``, relative to the area): Δ/12·Σ|h_{k−1} − 2h_k + h_{k+1}| (a
    parabola through three samples differs from their chords by that area) plus Δ/2·|h_{N−1}|
    (the last step: the convolution's kernel jumps to zero there, a realisation decays)."""

    def __init__(self, h, timdel):
        n = h.size
        self.step = timdel / BETWEEN
        self.t = self.step * (np.arange(2 * (n - 1) * BETWEEN) + 0.5)
        self.k = np.interp(self.t, timdel * np.arange(n), h, right=0.0)
        self.area = self.step * np.abs(self.k).sum()
        self.timdel, self.h = timdel, h
        self.open = timdel * (np.abs(np.diff(h, 2)).sum() / 12.0 + 0.5 * abs(h[-1])) / self.area

    def verdict(self, fit):
        """(deviation ∫|ĥ − K|/∫|K|, "" or why the fit is refused)."""
        areas = fit.areas()
        cancel = areas.sum() / self.area
        if not cancel <= CANCEL:   # (NaN too)
            return np.inf, f"modes cancelling each other: Σ|c|/|σ| = {cancel:.3g}·∫|K| > {CANCEL:g}·∫|K|"
        sig = np.array([s for s, _ in _modes(fit.A)])
        tail = (areas * np.exp(sig * self.t[-1])).sum()   # ∫|ĥ| beyond the grid, at most
        dev = (self.step * np.abs(fit(self.t) - self.k).sum() + tail) / self.area
        n = self.h.size   # the same measure on the samples alone (both with the tail beyond the window)
        at = self.timdel * np.abs(fit(self.timdel * np.arange(2 * n - 1)) - np.append(self.h, np.zeros(n - 1))).sum()
        allowed = SLACK * ((at + tail) / self.area + self.open)
        if not dev <= allowed:
            return dev, (f"between the samples ∫|ĥ − K| = {dev:.3g}·∫|K|, more than {SLACK:g}× its miss at the "
                         f"samples and what they leave open ({allowed:.3g}·∫|K|)")
        return dev, ""


def realise(h, timdel, tol=0.002, order=None, max_order=40):
    """Realise a sampled kernel h(k·TIMDEL), k = 0…N−1, as h(t) ≈ C·exp(A·t)·B.

    The kernel is zero after its last sample (the convention ``Convolution`` follows), so
    the fit sees it followed by N − 1 zero samples: a realisation that goes on past the end
    shows up in its error instead of silently changing the memory load.
    Poles come from the eigenvalue realisation algorithm (ERA: SVD of the Hankel matrix of
    those samples, rows at a stride so they span half the window, shifted by one sample).
    Unstable poles are reflected into the left half plane (σ → −max(|σ|, 1/T), T the
    window) and poles on the negative real axis of the discrete plane (a pure sample-to-
    sample alternation) are dropped, so every realisation is stable; so are poles the
    sampling does not resolve, |λ|·TIMDEL > RESOLVED (= 2): linear interpolation between
    samples misses a mode e^{λt} by up to (|λ|·TIMDEL)²/8 of its size, half of it at the
    bound, and past it the samples say nothing of the mode's shape between them.  The
    amplitudes are then fitted by least squares to all samples, the zero tail included.

    A fit exact at the samples can still be far off between them (nearly equal fast poles
    with huge amplitudes of opposite signs), and the state-space memory steps the realised
    kernel, not the samples.  So each candidate is judged against the piecewise-linear
    kernel K the convolution uses, on a grid of BETWEEN points per TIMDEL (``_Judge``), and
    refused when its modes cancel each other beyond round-off's reach (Σ|γ_k|/|σ_k| >
    CANCEL·∫|K| dt: each mode's area |γ|/|σ| bounds its share of the load) or when it misses
    K between the samples by more than SLACK times its miss at the samples plus what the
    samples leave open there.  ``deviation`` = ∫|ĥ − K| dt/∫|K| dt bounds the difference of
    the two memory loads by deviation·∫|K| dt·max|v| whatever the step (both are exact for
    a velocity linear within each step).

    ``order``: the ERA order to use (the realisation may come out smaller when modes are
    dropped; when refused, the next lower order that is not); else the smallest order whose
    error ‖ĥ − h‖/‖h‖ over the window (samples and zero tail) is ≤ ``tol`` and that is not
    refused (or the best not refused up to ``max_order``).  Returns a ``Realisation``
    (check ``error`` against tol; ``refused`` says which orders were refused and why; order
    0 with error 1: none could be used).
    """
    h = np.asarray(h, float).ravel()
    if h.size < 2 or not np.any(h):   # one sample spans no time: no memory, as in Convolution
        return Realisation(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 0.0, 0.0)
    judge = _Judge(h, timdel)
    h = np.concatenate([h, np.zeros(h.size - 1)])
    t = timdel * np.arange(h.size)
    norm = np.linalg.norm(h)
    rows = min(100, (h.size - 1) // 2)
    stride = max(1, (h.size - 1) // (2 * rows))
    ncol = h.size - 1 - (rows - 1) * stride
    cstride = max(1, ncol // 1000)
    i = stride * np.arange(rows)[:, None] + cstride * np.arange((ncol + cstride - 1) // cstride)[None, :]
    u, sv, vt = np.linalg.svd(h[i], full_matrices=False)
    shifted = u.T @ h[i + 1] @ vt.T
    rank = int(np.sum(sv > sv[0] * 1e-12))
    if order is not None:
        orders = range(min(order, rank), 0, -1)     # the order asked, lower ones if refused
    else:
        orders = range(1, min(max_order, rank) + 1)
    refused, candidates = [], []

    def accept(fit, r):
        dev, why = judge.verdict(fit)
        if why:
            refused.append(f"order {r}: {why}")
            return None
        fit.deviation, fit.refused = float(dev), "; ".join(refused)
        return fit

    for r in orders:
        si = 1.0 / np.sqrt(sv[:r])
        mu = np.linalg.eigvals(si[:, None] * shifted[:r, :r] * si[None, :]).astype(complex)
        keep = (mu.imag >= 0) & ~((mu.imag == 0) & (mu.real <= 0))   # one of each pair, no Nyquist
        lam = np.log(mu[keep]) / timdel
        bad = lam.real >= 0                          # reflect into the left half plane
        lam[bad] = -np.maximum(lam[bad].real, 1.0 / t[-1]) + 1j * lam[bad].imag
        lam = lam[np.abs(lam) * timdel <= RESOLVED]  # what the sampling resolves
        if not lam.size:
            continue
        fit = _fit(lam, t, h, norm)
        if order is not None or fit.error <= tol:
            if (ok := accept(fit, r)) is not None:
                return ok
        else:
            candidates.append((fit.error, r, fit))
    for _, r, fit in sorted(candidates, key=lambda c: c[:2]):   # none met tol: the best not refused
        if (ok := accept(fit, r)) is not None:
            return ok
    return Realisation(np.zeros((0, 0)), np.zeros(0), np.zeros(0), 1.0, 1.0, "; ".join(refused))


def _fit(lam, t, h, norm):
    """Amplitudes for poles ``lam``: least squares on the samples h(t) (zero tail included)."""
    a = _assemble(lam)
    phi = _basis(a, t)
    c = np.linalg.lstsq(phi, h, rcond=None)[0]
    err = np.linalg.norm(phi @ c - h) / norm
    b = np.zeros(a.shape[0])
    k = 0
    for p in lam:
        b[k] = 1.0
        k += 1 if p.imag == 0 else 2
    return Realisation(a, b, c, float(err))


_F1 = 1.0 / np.cumprod(np.arange(1.0, 14.0))      # 1/1!, 1/2!, … 1/13!


def _phi(x):
    """φ₁(x) = (eˣ − 1)/x and φ₂(x) = (eˣ − 1 − x)/x² for complex x, without cancellation."""
    x = np.asarray(x, complex)
    p1, p2 = np.empty_like(x), np.empty_like(x)
    small = np.abs(x) < 0.1
    xb = x[~small]
    em = np.expm1(xb)
    p1[~small], p2[~small] = em / xb, (em - xb) / xb ** 2
    if small.any():                   # Taylor: φ₁ = Σ xⁿ/(n+1)!, φ₂ = Σ xⁿ/(n+2)!
        xs = x[small]
        s1, s2 = np.full_like(xs, _F1[11]), np.full_like(xs, _F1[12])
        for n in range(10, -1, -1):
            s1, s2 = s1 * xs + _F1[n], s2 * xs + _F1[n + 1]
        p1[small], p2[small] = s1, s2
    return p1, p2


DENSE_STATES = 64   # up to this many real states a step is one dense real product (StateSpace)


class StateSpace:
    """Memory integral by state-space realisations of the kernels.

    kernels, shape, timdel, v0, memory_length: as for ``Convolution`` (the kernel is cut at
    memory_length before it is realised).  tol, order, max_order: see ``realise``.
    ``fits``: optional {(i, j): Realisation} to reuse (e.g. the transposed side of a coupling).

    Per element, x' = A·x + B·v_j and F_i −= C·x.  Each block of A (pole σ, or pair σ ± iω)
    is one complex mode z = x₁ + i·x₂ with z' = μ·z + v_j, μ = σ − iω, so a step with v linear
    from v_old to v_new is exact in closed form (the same as the block exponential
    expm([[A, B, 0], [0, 0, 1], [0, 0, 0]]·dt)):
    z_new = e^{μdt}·z + dt·φ₁(μdt)·v_old + dt·φ₂(μdt)·(v_new − v_old),
    φ₁(x) = (eˣ − 1)/x, φ₂(x) = (eˣ − 1 − x)/x².  Coefficients are cached per distinct dt
    (the last 16).

    ``missed``: {(i, j): why} of the elements fitted here whose realisation misses ``tol``
    (``order`` not given) or is empty (every order refused, see ``realise``): their memory
    load is not the one asked for; ``physics.coupling.Coupling`` then uses ``Convolution``.
    """

    def __init__(self, kernels, timdel, shape=None, v0=None, tol=0.002, order=None,
                 max_order=40, memory_length=None, fits=None):
        self.shape, elems = _elements(kernels, shape)
        fits = dict(fits or {})
        self.fits, self.missed = {}, {}
        mu, inp, out, gam = [], [], [], []
        for i, j, h in elems:
            if (i, j) not in fits:
                if memory_length is not None:
                    h = h[: int(np.floor(memory_length / timdel + 1e-9)) + 1]
                f = fits[(i, j)] = realise(h, timdel, tol, order, max_order)
                why = f" (refused: {f.refused})" if f.refused else ""
                if f.order == 0 and f.error > 0.0:   # (error 0: a kernel with no memory)
                    self.missed[(i, j)] = "no realisation could be used" + why
                elif order is None and f.error > tol:
                    self.missed[(i, j)] = (f"the best realisation misses the tolerance: normalised RMS error "
                                           f"{f.error:.3g} > {tol:g} at order {f.order}{why}")
            f = self.fits[(i, j)] = fits[(i, j)]
            k = 0
            for sig, om in _modes(f.A):
                mu.append(complex(sig, -om))
                # output c·x₁ (+ c₂·x₂) = Re(γ·z) with γ = c₁ − i·c₂
                gam.append(complex(f.C[k], -f.C[k + 1]) if om else complex(f.C[k]))
                inp.append(j)
                out.append(i)
                k += 2 if om else 1
        self.order = sum(f.order for f in self.fits.values())   # real states
        self._set_modes(np.array(mu, complex), np.array(gam, complex), np.array(inp, int), np.array(out, int),
                        _start(self.shape, v0))

    def _set_modes(self, mu, gam, inp, out, v):
        """Set the modes (μ, γ, input and output index of each), a zero modal state and the
        velocity v.  The state is one real vector x = [z as (Re z₀, Im z₀, Re z₁, …); v]."""
        self._mu, self._gam, self._inp, self._out = mu, gam, inp, out
        m = len(mu)
        self._nz = 2 * m
        self._x = np.concatenate((np.zeros(2 * m), v))
        # Products on real views of the complex modal state, so each step is two small real
        # matrix products (or one, W below): F = −Re(Γ·z) = gain·z_real.
        self._gain = np.zeros((self.shape[0], 2 * m))
        self._gain[self._out, 2 * np.arange(m)] = -self._gam.real
        self._gain[self._out, 2 * np.arange(m) + 1] = self._gam.imag
        self._u = np.zeros(2 * m + 2 * self.shape[1])   # [z; v_old; v_new], W's operand
        self._cache = OrderedDict()
        self._last_dt, self._last = None, None
        self._peeked = None
        self.force = np.zeros(self.shape[0])

    @classmethod
    def stack(cls, parts):
        """One evaluator for several independent ones side by side, each taken at its current
        state: inputs and outputs concatenated in the order given (the velocities of part k
        follow those of parts 0…k−1, likewise its loads).  A step of the stack is one product
        for all of them (per-call cost paid once); its loads equal the parts' own to round-off
        (the same sums, as rows of one product).  ``fits`` keys are offset accordingly."""
        self = cls.__new__(cls)
        fits, at_out, at_in = {}, [0], [0]
        for p in parts:
            fits.update({(i + at_out[-1], j + at_in[-1]): f for (i, j), f in p.fits.items()})
            at_out.append(at_out[-1] + p.shape[0])
            at_in.append(at_in[-1] + p.shape[1])
        self.shape, self.fits = (at_out[-1], at_in[-1]), fits
        self.order = sum(p.order for p in parts)
        join = lambda arrays, dtype=float: np.concatenate([np.zeros(0, dtype)] + list(arrays))   # noqa: E731
        self._set_modes(join((p._mu for p in parts), complex), join((p._gam for p in parts), complex),
                        join((p._inp + a for p, a in zip(parts, at_in)), int),
                        join((p._out + a for p, a in zip(parts, at_out)), int),
                        join(p._x[p._nz:] for p in parts))
        self._x[:self._nz] = join(p._x[:p._nz] for p in parts)
        self.force = join(p.force for p in parts)
        return self

    @property
    def velocity(self):
        return self._x[self._nz:].copy()

    C_TAG = "statespace"   # its record in a compiled FMU (memory.c)

    def c_params(self):
        """memory.c's state-space parameters: [modes m, μ (real parts, then imaginary), γ
        (likewise), input and output index per mode]."""
        return ([float(len(self._mu))] + self._mu.real.tolist() + self._mu.imag.tolist() + self._gam.real.tolist()
                + self._gam.imag.tolist() + self._inp.astype(float).tolist() + self._out.astype(float).tolist())

    def restart(self, v0):
        """Set the velocity at the start (before any ``advance``; the states are still zero)."""
        self._x = np.concatenate((self._x[:self._nz], _start(self.shape, v0)))
        self._peeked = None

    def _discrete(self, dt):
        """(e^{μdt}, B, W) for a step dt: z_new = e·z + B·[v_old; v_new], with B (real view,
        2·modes × 2·n_in) holding dt·(φ₁ − φ₂) on v_old and dt·φ₂ on v_new of each mode's input;
        W (up to DENSE_STATES real states, else None) gives the new state and load
        [z_new; v_new; F] = W·[z; v_old; v_new] on the real view in one product (cheaper than
        four small numpy calls; v_new passes through an identity block)."""
        if dt == self._last_dt:                   # the usual case: a constant step
            return self._last
        key = float(dt)
        if key not in self._cache:
            x = self._mu * dt
            p1, p2 = _phi(x)
            m, n_in = len(x), self.shape[1]
            b = np.zeros((m, 2 * n_in), complex)
            b[np.arange(m), self._inp] = dt * (p1 - p2)
            b[np.arange(m), n_in + self._inp] = dt * p2
            real = np.empty((2 * m, 2 * n_in))
            real[0::2], real[1::2] = b.real, b.imag
            e = np.exp(x)
            whole = None
            if 2 * m <= DENSE_STATES:   # few states: the whole step as one real product
                rot = np.zeros((2 * m, 2 * m))      # e·z on the real view: blocks [[Re e, −Im e], [Im e, Re e]]
                i = 2 * np.arange(m)
                rot[i, i], rot[i, i + 1], rot[i + 1, i], rot[i + 1, i + 1] = e.real, -e.imag, e.imag, e.real
                top = np.hstack([rot, real])
                through = np.hstack([np.zeros((n_in, 2 * m + n_in)), np.eye(n_in)])
                whole = np.vstack([top, through, self._gain @ top])
            self._cache[key] = (e, real, whole)
            if len(self._cache) > 16:
                self._cache.popitem(last=False)
        self._cache.move_to_end(key)
        self._last_dt, self._last = key, self._cache[key]
        return self._last

    def _step(self, dt, v_new):
        """(dt, the state x after the step, the load F after it), nothing moved."""
        if not dt > 0:
            raise ValueError(f"dt must be > 0, got {dt}")
        nz, n = self._nz, self.shape[1]
        if type(v_new) is not np.ndarray or v_new.shape != (n,):
            v_new = np.asarray(v_new, dtype=float).reshape(n)
        if not nz:
            return float(dt), np.array(v_new, dtype=float), self.force
        e, b, whole = self._discrete(dt)
        u = self._u
        u[:nz + n] = self._x
        u[nz + n:] = v_new
        if whole is not None:           # [z_new; v_new; F] = W·[z; v_old; v_new]: one product
            out = whole.dot(u)          # (ndarray.dot: half the call cost of @ on small arrays)
            return float(dt), out[:nz + n], out[nz + n:]
        z = e * self._x[:nz].view(complex) + b.dot(u[nz:]).view(complex)
        return float(dt), np.concatenate((z.view(float), v_new)), self._gain.dot(z.view(float))

    def peek(self, dt, v_new):
        """The memory load F(t + dt) if the velocity reached v_new at t + dt, without
        moving (a following ``advance`` with the same arguments reuses the result)."""
        self._peeked = self._step(dt, v_new)
        return self._peeked[2].copy()

    def advance(self, dt, v_new, peeked=False):
        """Move to t + dt [s] with velocity v_new; return the memory load F(t + dt).
        ``peeked``: the caller knows (dt, v_new) are the last ``peek``'s arguments, which
        are then not compared (without a pending peek the step is computed all the same)."""
        p = self._peeked
        if p is None or not peeked and (p[0] != dt or p[1][self._nz:].tolist() != np.asarray(v_new).tolist()):
            p = self._step(dt, v_new)    # (compared as lists: cheaper than numpy on a few values)
        _, self._x, self.force = p
        self._peeked = None
        return self.force.copy()

    def state(self):
        """Modal states (real and imaginary parts), current velocity and load, as plain lists."""
        x, nz = self._x, self._nz
        return {"z_re": x[0:nz:2].tolist(), "z_im": x[1:nz:2].tolist(),
                "v": x[nz:].tolist(), "force": self.force.tolist()}

    def set_state(self, state):
        """Restore a ``state()``."""
        x, nz = np.empty(self._x.size), self._nz
        x[0:nz:2], x[1:nz:2] = state["z_re"], state["z_im"]
        x[nz:] = np.array(state["v"], float).reshape(self.shape[1])
        self._x = x
        self.force = np.array(state["force"], float)
        self._peeked = None
