"""The graph of s(theta, omega, ., 0) (Eq. (23), Lemma 3, case theta > 0).

The zero-order discontinuity map for 0 < theta < 1 is given parametrically by the
sliding time t_s > 0. With u = t_s/theta and e = exp(-u):

    xi1(t_s)     = -(omega^2 theta^2 / 2) * [((1 - theta)(1 - e) + t_s) / D]^2
    s xi1 (t_s)  =  omega^2 (1 - theta) * (theta - (theta + t_s) e) / D
    D            =  theta + (1 - theta) e  =  1 + (1 - theta) expm1(-u)

Numerics. Every quantity is written without cancellation for small t_s:

* 1 - e = -expm1(-u) and D = 1 + (1 - theta) expm1(-u) lie in (theta, 1];
* the numerator of s xi1 is theta * g(u) with g(u) = 1 - (1 + u) e^{-u}
  (= the integral of v e^{-v} over [0, u], ~ u^2/2 for u -> 0). g is summed
  from its Taylor series sum_{n>=2} (-1)^n (n - 1) u^n / n! for u < 1 and
  evaluated directly (cancellation at most one digit) for u >= 1;
* s itself is the ratio of the two accurate values, equivalently
  s = -2 (1 - theta) g(u) D / (theta N^2) with N = (1 - theta)(1 - e) + t_s.

Limits (checked in tests/test_fig03_fig06.py):

* t_s -> 0: xi1 ~ -omega^2 t_s^2 / 2, s xi1 ~ omega^2 (1 - theta) t_s^2 / (2 theta),
  hence s -> (theta - 1)/theta, the value the paper states at xi1 = 0. Expanding
  one order further, s = (theta - 1)/theta + 2 (1 - theta) t_s / (3 theta^2) + O(t_s^2),
  i.e. s - (theta - 1)/theta = O(sqrt(-xi1)) since t_s ~ sqrt(-2 xi1)/|omega|.
* t_s -> infinity: e -> 0, so D -> theta and s xi1 -> omega^2 (1 - theta), a
  constant, while xi1 ~ -omega^2 (t_s + 1 - theta)^2 / 2 -> -infinity. Hence
  s = (s xi1)/xi1 -> 0 like 1/xi1: the graph of s xi1 against xi1 becomes flat,
  the slope 0 of the reduced model (its return map is constant after sliding).
  Numerically, for omega = 8 pi, theta = 0.5 the image is within 1e-3 (relative)
  of omega^2 (1 - theta) = 315.83 for t_s >= 4.67 (the error decays like
  (t_s/theta) e^{-t_s/theta}), and xi1 is within 1e-3 of the asymptote for
  t_s >= 3.86; at t_s = 5, xi1 = -9552.8 and s = -0.0330.
"""
from __future__ import annotations

import math

import numpy as np

# Taylor coefficients of g(u) = 1 - (1 + u) e^{-u}: c_n = (-1)^n (n - 1)/n!, n >= 2.
_N_TERMS = 24  # for u < 1 the first neglected term is below 1e-24 relative
_G_COEF = np.array([(-1) ** n * (n - 1) / math.factorial(n) for n in range(2, 2 + _N_TERMS)])
_SERIES_BELOW = 1.0


def _check(theta: float, omega: float) -> tuple[float, float]:
    theta, omega = float(theta), float(omega)
    if not (np.isfinite(theta) and 0.0 < theta < 1.0):
        raise ValueError(f"Eq. (23) holds for 0 < theta < 1 (case theta > 0 of Lemma 3), "
                         f"got theta={theta!r}")
    if not (np.isfinite(omega) and omega != 0.0):
        raise ValueError(f"omega must be finite and nonzero, got {omega!r}")
    return theta, omega


def _times(t_s) -> np.ndarray:
    t = np.asarray(t_s, dtype=float)
    if not np.all(np.isfinite(t)) or np.any(t < 0):
        raise ValueError("sliding times t_s must be finite and >= 0")
    return t


def g(u) -> np.ndarray:
    """1 - (1 + u) exp(-u) for u >= 0, accurate to a few ulps also as u -> 0."""
    u = np.asarray(u, dtype=float)
    small = u < _SERIES_BELOW
    us = np.where(small, u, 0.0)
    # Horner on sum_k c_k u^k, k = 2..; factor u^2 out
    acc = np.zeros_like(us)
    for c in _G_COEF[::-1]:
        acc = acc * us + c
    series = acc * us * us
    direct = -np.expm1(-u) - u * np.exp(-u)
    return np.where(small, series, direct)


def _parts(t, theta):
    u = t / theta
    em1 = np.expm1(-u)                       # e - 1, exact sign and relative accuracy
    D = 1.0 + (1.0 - theta) * em1            # theta + (1 - theta) e, in (theta, 1]
    N = (1.0 - theta) * (-em1) + t           # (1 - theta)(1 - e) + t_s, >= 0
    return u, D, N


def xi1(t_s, theta: float, omega: float) -> np.ndarray:
    """xi1 of Eq. (23) as a function of the sliding time t_s (<= 0)."""
    theta, omega = _check(theta, omega)
    t = _times(t_s)
    _, D, N = _parts(t, theta)
    return -0.5 * omega ** 2 * theta ** 2 * (N / D) ** 2


def image(t_s, theta: float, omega: float) -> np.ndarray:
    """s(theta, omega, xi1, 0) * xi1 of Eq. (23), i.e. P_DM(xi1), as a function of t_s."""
    theta, omega = _check(theta, omega)
    t = _times(t_s)
    u, D, _ = _parts(t, theta)
    return omega ** 2 * (1.0 - theta) * theta * g(u) / D


def slope(t_s, theta: float, omega: float) -> np.ndarray:
    """s = (s xi1)/xi1, written without the 0/0 at small t_s (defined for t_s > 0)."""
    theta, omega = _check(theta, omega)
    t = _times(t_s)
    if np.any(t == 0):
        raise ValueError("s is a 0/0 limit at t_s = 0: use slope_at_zero(theta)")
    u, D, N = _parts(t, theta)
    return -2.0 * (1.0 - theta) * g(u) * D / (theta * N ** 2)


def slope_at_zero(theta: float) -> float:
    """lim s as t_s -> 0 (xi1 -> 0-): (theta - 1)/theta."""
    theta, _ = _check(theta, 1.0)
    return (theta - 1.0) / theta


def image_limit(theta: float, omega: float) -> float:
    """lim s xi1 as t_s -> infinity: omega^2 (1 - theta)."""
    theta, omega = _check(theta, omega)
    return omega ** 2 * (1.0 - theta)


def xi1_asymptote(t_s, theta: float, omega: float) -> np.ndarray:
    """Leading behaviour of xi1 for large t_s: -omega^2 (t_s + 1 - theta)^2 / 2."""
    theta, omega = _check(theta, omega)
    t = _times(t_s)
    return -0.5 * omega ** 2 * (t + 1.0 - theta) ** 2
