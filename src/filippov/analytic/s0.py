"""s0(theta): the positive root of (1 - theta) exp(-s) - 1 + s + theta = 0 (Eq. (B.15)).

Two independent evaluations, used to check each other:

* closed form: with b = 1 - theta > 1 the equation is z e^z = -b e^{-b} for
  z = s - b. Its branch W_{-1} gives z = -b (the trivial root s = 0); the
  principal branch gives s0 = 1 - theta + W_0(-(1 - theta) e^{theta - 1}).
* root finding: Brent's method on the bracket [-theta, 1 - theta], where the
  left side of Eq. (B.15) is negative at s = -theta and positive at s = 1 - theta.
"""
from __future__ import annotations

import functools

import numpy as np
from scipy.optimize import brentq
from scipy.special import lambertw


def _check(theta: np.ndarray) -> np.ndarray:
    theta = np.asarray(theta, dtype=float)
    if not np.all(np.isfinite(theta)) or np.any(theta >= 0):
        raise ValueError("theta must be finite and < 0 for s0(theta) (Eq. (B.15))")
    return theta


def residual(s, theta):
    """Left-hand side of Eq. (B.15); expm1 keeps it accurate for small s."""
    return (1 - theta) * np.expm1(-s) + s


def s0_lambert(theta):
    if isinstance(theta, (float, np.floating)):
        return _s0_scalar(theta)
    return _s0(theta)


def _s0(theta):
    theta = _check(theta)
    b = 1.0 - theta
    return b + np.real(lambertw(-b * np.exp(-b), k=0))


@functools.lru_cache(maxsize=1024)
def _s0_scalar(theta):
    """s0 of one theta, computed once: the limit maps ask for the same theta at every
    return (160,000 times in fig12), and lambertw with the check costs 100 us a call.
    The same computation as for an array (bits and type: numpy's float64); NaN is never
    a cache hit (nan != nan), so the check still refuses it."""
    return _s0(theta)


def s0_root(theta):
    theta = _check(theta)
    out = np.empty_like(theta, dtype=float)
    for i, th in np.ndenumerate(theta):
        out[i] = brentq(residual, -th, 1.0 - th, args=(th,), xtol=1e-300,
                        rtol=4 * np.finfo(float).eps, maxiter=500)
    return out
