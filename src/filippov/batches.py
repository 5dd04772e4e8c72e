"""The pieces of a system defined once as numba loops over a batch of states: what the
reference driver evaluates (the columns of ``(n, b)`` states, or the times of a flow),
built from a user's functions of one state ``z`` and the parameters ``p``. Shared by
:class:`~filippov.FilippovSystem` (one switching surface) and
:mod:`filippov.surfaces_defined` (several)."""
from __future__ import annotations

from typing import Callable

import numpy as np
from numba import njit


_DOC_PIECE = ("write it for one state z (1-D float array) and the parameter array p, "
              "with numpy and math only (no Python objects, no closures over lists)")


def cannot_compile(exc: Exception, piece: str) -> ValueError:
    """numba's failure to compile ``piece`` as one readable line."""
    lines = [ln.strip() for ln in str(exc).splitlines() if ln.strip()]
    # numba's first line names the compiler stage; the next one names the problem
    detail = next((ln for ln in lines if not ln.startswith(("Failed in", "During:"))),
                  lines[0] if lines else type(exc).__name__)
    return ValueError(f"{piece}: numba cannot compile it ({detail}); {_DOC_PIECE}")


def jit(fn: Callable, piece: str):
    """``fn`` as a numba dispatcher (compiled on first call), itself if it is one."""
    if not callable(fn):
        raise TypeError(f"{piece}: expected a function, got {type(fn).__name__}")
    return fn if hasattr(fn, "py_func") else njit(fn)


def vector(user, n: int, piece: str = "a vector piece"):
    """A vector piece f(z, p) -> (n,) evaluated on (n,) or (n, m) states, compiled; a
    value of the wrong length is an error, never memory past its end."""
    wrong = f"{piece} returned the wrong number of values"

    @njit
    def batch(zs, p):
        m = zs.shape[1]
        out = np.empty((n, m))
        z = np.empty(n)
        for j in range(m):
            for i in range(n):
                z[i] = zs[i, j]
            v = user(z, p)
            if len(v) != n:
                raise ValueError(wrong)
            for i in range(n):
                out[i, j] = v[i]
        return out
    return batch


def scalar(user, n: int):
    @njit
    def batch(zs, p):
        m = zs.shape[1]
        out = np.empty(m)
        z = np.empty(n)
        for j in range(m):
            for i in range(n):
                z[i] = zs[i, j]
            out[j] = user(z, p)
        return out
    return batch


def flow(user, n: int, piece: str = "a flow"):
    wrong = f"{piece} returned the wrong number of values"

    @njit
    def batch(z0, taus, p):
        out = np.empty((n, taus.size))
        for j in range(taus.size):
            v = user(z0, taus[j], p)
            if len(v) != n:
                raise ValueError(wrong)
            for i in range(n):
                out[i, j] = v[i]
        return out
    return batch


def states(z, n):
    z = np.asarray(z, dtype=float)
    return np.ascontiguousarray(z.reshape(n, -1)), z.shape[1:]


def rows(user, n: int, size: int, piece: str):
    """A piece f(z, p) -> ``size`` values (a vector, or a matrix read row by row) on
    (n, b) states: (size, b), compiled; the wrong number of values is an error."""
    wrong = f"{piece} returned the wrong number of values"

    @njit
    def batch(zs, p):
        b = zs.shape[1]
        out = np.empty((size, b))
        z = np.empty(n)
        for j in range(b):
            for i in range(n):
                z[i] = zs[i, j]
            v = np.asarray(user(z, p)).flatten()
            if v.size != size:
                raise ValueError(wrong)
            for i in range(size):
                out[i, j] = v[i]
        return out
    return batch
