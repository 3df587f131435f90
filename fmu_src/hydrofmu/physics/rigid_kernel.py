"""The rigid-body kernel in C (rigid.c): the equations of rigid_body._Equations and their
Runge–Kutta steps, for the dynamics partner's per-step path.

rigid_body.py is the reference and the fallback: a step the kernel cannot finish (gimbal
lock, a singular or non-finite system) is redone there, which raises the user's error, and
where there is no kernel at all (no C compiler, another platform, ``HYDROFMU_KERNEL=python``)
everything runs in Python.  Where the library comes from:

- ``_rigid.so`` next to this file: an FMU's runtime copy, compiled by the FMU build;
- else rigid.c compiled once into the cache (``hydrofmu.cc``) on first use.
"""
from __future__ import annotations

import ctypes
import os
from pathlib import Path

import numpy as np

SOURCE = Path(__file__).with_name("rigid.c")
BUILT = Path(__file__).with_name("_rigid.so")
OK, GIMBAL, NONFINITE = 0, 1, 2   # hf_rigid_steps' statuses
_lib = []   # [the loaded library or None], once per process


def library():
    """The kernel's ctypes library, or None when it cannot be had (then Python runs)."""
    if not _lib:
        lib = None
        if os.environ.get("HYDROFMU_KERNEL") != "python":
            try:
                lib = ctypes.PyDLL(str(BUILT if BUILT.is_file() else _compiled()))   # PyDLL: keeps the GIL
                fn = lib.hf_rigid_steps
                fn.argtypes = [ctypes.c_void_p] * 2 + [ctypes.c_int] + [ctypes.c_void_p] * 5
                fn.restype = ctypes.c_int
            except (OSError, RuntimeError, AttributeError, ImportError):
                lib = None
        _lib.append(lib)
    return _lib[0]


if BUILT.is_file():
    # an FMU's runtime: loaded now, while its folder exists (every FMU of a process with the
    # same runtime shares this module, and a host may delete the first one's folder early)
    library()


def _compiled():
    from .. import cc   # only outside an FMU: its runtime carries _rigid.so
    return cc.cached(SOURCE)


def _address(a):
    return a.ctypes.data


class Kernel:
    """hf_rigid_steps bound to the constants of n bodies (rigid.c's layout): ``gimbal_tol``
    (rigid_body.GIMBAL_TOL), ``props``
    (n, 11) [m, has_cog, c (3), I_O (6: xx, xy, xz, yy, yz, zz)], ``const`` (6n, 6n) the
    constant mass matrix, ``kd`` (6n, 12n) [K | D] on the natural state order, ``k_eta0``
    (6n,).  Buffers are allocated once; ``steps`` returns new arrays."""

    def __init__(self, lib, gimbal_tol, props, const, kd, k_eta0):
        n = len(props)
        self._fn = lib.hf_rigid_steps
        self.model = np.concatenate([[float(n), gimbal_tol], np.ravel(props), np.ravel(const), np.ravel(kd), k_eta0])
        self.y, self.acc = np.empty(12 * n), np.empty(6 * n)
        self.load, self.rate = np.empty(6 * n), np.empty(6 * n)
        self.work = np.empty(36 * n * n + 30 * n + 7 * 12 * n)   # up to 7 stages (RK6)
        self._ptr = [_address(a) for a in (self.model, self.load, self.rate, self.y, self.acc, self.work)]
        self._tables = {}

    def table(self, h, method):
        """rigid.c's table [ns, h, h·a, h·b, h·c] of ``method`` = (a, b, c), kept by (h, ns)."""
        key = (h, len(method[1]))
        t = self._tables.get(key)
        if t is None:
            a, b, c = method
            t = np.concatenate([[float(len(b)), h], h * np.ravel(a), h * b, h * c])
            if len(self._tables) > 8:
                self._tables.clear()
            self._tables[key] = t = (t, _address(t))
        return t[1]

    def steps(self, y, load, rate, h, n, method):
        """(state, accelerations at the end under the load there) after n internal steps h
        [s] of ``method`` from y under load + rate·t (rate None: held), or the kernel's
        status (GIMBAL, NONFINITE) when it could not finish."""
        model, load_p, rate_p, y_p, acc_p, work_p = self._ptr
        self.y[:] = y
        self.load[:] = load
        if rate is not None:
            self.rate[:] = rate
        status = self._fn(model, self.table(h, method), n, load_p, rate_p if rate is not None else None,
                          y_p, acc_p, work_p)
        return (self.y.copy(), self.acc.copy()) if status == OK else status
