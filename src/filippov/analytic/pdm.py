"""Asymptotic formulas for the discontinuity map P_DM (Lemma 3 and its appendix).

All maps act on the rescaled coordinate xi1 of a point of L2: x1 = -1 + eps xi1
for theta < 0 (Eq. (B.2), delta = sqrt(eps)), x1 = -1 + eps^2 xi1 for theta > 0
(Eq. (B.24)). P_DM is the identity for xi1 >= 0.

Two versions are given for each case: the formula *as printed* in the paper, and
a *corrected* one. The printed versions take the map Pi_3 as
xi_{1,4} = xi_{1,3} + O(delta) (Eq. (B.18), and its theta > 0 copy used in
Eq. (B.34)). But Pi_3 follows E_+ from p_3 = (xi_{1,3}, xi_{2,3}) with
xi_{2,3} = O(1) to the minimum of xi1 along that orbit, and to leading order the
orbits of E_+ in the rescaled coordinates are the parabolas
xi1 - xi2^2 / 2 = const (d xi1/d xi2 = xi2 from Eq. (B.3)). Hence

    xi_{1,4} = xi_{1,3} - xi_{2,3}^2 / 2 + O(delta),

an O(1) term the printed formulas lack. With it (and Eqs. (B.12), (B.14)
unchanged) one gets for theta < 0

    P_DM(xi1) = xi1 + s0 + delta s0 sqrt(-2 xi1) [omega/(theta + s0) - 2/omega] + O(delta^2),

(the O(delta) part of Pi_3 follows from the first integral
K = K0 - (delta/omega)(2 K0 + q) xi2, K0 = xi1 - xi2^2/2, of Eq. (B.3), which gives
P_DM = xi1 + s_* - 2 delta s_* xi_{2,1}/omega + O(delta^2); q drops out), and for
theta > 0, with xi_{2,2} = xi_{1,2}/omega (Eq. (B.32)),

    P_DM = xi_{1,2} - xi_{1,2}^2 / (2 omega^2) + O(eps)

along the curve parametrised by the sliding time t_2 (Eqs. (B.33), (B.31)).
Both corrections vanish as xi1 -> 0-, so s0 (theta < 0) and the slope
(theta - 1)/theta (theta > 0) at the grazing point are unaffected; the numerical
P_DM of :mod:`filippov.pdm` agrees with the corrected forms, not the printed ones.
"""
from __future__ import annotations

import numpy as np

from .s0 import s0_lambert


def _neg(xi1):
    xi1 = np.asarray(xi1, dtype=float)
    return xi1, np.sqrt(-2.0 * np.minimum(xi1, 0.0))


# ----------------------------------------------------------------------------- theta < 0
def pdm_theta_neg(xi1, theta: float, omega: float, eps: float, *, order: int = 1):
    """Corrected P_DM for theta < 0: order 0 is xi1 + s0, order 1 adds the delta term."""
    xi1, w = _neg(xi1)
    s0 = s0_lambert(theta)
    val = xi1 + s0
    if order >= 1:
        val = val + np.sqrt(eps) * s0 * w * (omega / (theta + s0) - 2.0 / omega)
    return np.where(xi1 >= 0, xi1, val)


def pdm_theta_neg_printed(xi1, theta: float, omega: float, eps: float, *, order: int = 1):
    """Eqs. (B.20) / (21) exactly as printed (order 0: the constant s0)."""
    xi1, w = _neg(xi1)
    s0 = s0_lambert(theta)
    val = s0 + 0.0 * xi1
    if order >= 1:
        val = val + np.sqrt(eps) * (omega * s0 / (theta + s0) * w + w ** 3 / omega)
    return np.where(xi1 >= 0, xi1, val)


def xi2_entry_theta_neg(xi1, omega: float, eps: float, q: float = 0.0):
    """xi_{2,1} where E_+ through L2 meets H_s backward in time (Eq. (B.12), to O(delta))."""
    xi1, w = _neg(xi1)
    return w - np.sqrt(eps) * (2.0 * xi1 + q) / omega


def hit_time_theta_neg(xi2_entry, theta: float, omega: float, eps: float):
    """s_*: fast time spent following E_- (Eq. (B.14), to O(delta))."""
    s0 = s0_lambert(theta)
    return s0 + np.sqrt(eps) * omega * s0 / (theta + s0) * np.asarray(xi2_entry, dtype=float)


# ----------------------------------------------------------------------------- theta > 0
def _check_pos(theta):
    if np.ndim(theta):   # an array of theta, one per point (limit_map.orbits)
        theta = np.asarray(theta)
        if not np.all((0 < theta) & (theta < 1)):
            raise ValueError(f"theta must lie in (0, 1) for the sliding case, got "
                             f"{theta.tolist()!r}")
    elif not 0 < theta < 1:
        raise ValueError(f"theta must lie in (0, 1) for the sliding case, got {theta!r}")


def sliding_curve(t2, theta: float, omega: float):
    """Zero-order pieces along the sliding time t2 >= 0 (rescaled time of Eq. (B.28)):
    (xi_{1,0}, xi_{2,1}, xi_{1,2}) from Eqs. (B.33), (B.30), (B.31)."""
    _check_pos(theta)
    t2 = np.asarray(t2, dtype=float)
    v = -t2 / theta
    e, xi21, den = _xi21(t2, v, theta, omega)
    xi12 = omega ** 2 * (1.0 - theta) * (theta * (-np.expm1(v)) - t2 * e) / den
    return -0.5 * xi21 ** 2, xi21, xi12


def _xi21(t2, v, theta, omega):
    """(e, xi_{2,1}, den) at the sliding times t2 (v = -t2/theta): the piece the
    inversion in xi1 needs, alone (half the operations of the whole curve)."""
    e = np.exp(v)
    den = theta + (1.0 - theta) * e
    return e, omega * theta * ((1.0 - theta) * (-np.expm1(v)) + t2) / den, den


def pdm_theta_pos_curve(t2, theta: float, omega: float, *, printed: bool = False):
    """(xi1, P_DM) along the sliding time t2: corrected (default) or as printed
    (Eq. (B.34), which is Eq. (23)'s s xi1)."""
    xi10, _, xi12 = sliding_curve(t2, theta, omega)
    if printed:
        return xi10, xi12
    return xi10, xi12 - 0.5 * (xi12 / omega) ** 2


def sliding_time_theta_pos(xi1, theta: float, omega: float, *, iterations: int = 60):
    """t2 >= 0 with xi_{1,0}(t2) = xi1 < 0 (inverse of Eq. (B.33)), vectorised
    bisection on log-spaced brackets; NaN for xi1 >= 0."""
    _check_pos(theta)
    xi1 = np.asarray(xi1, dtype=float)
    target = np.sqrt(-2.0 * np.minimum(xi1, 0.0))  # xi_{2,1}, increasing in t2
    lo = np.zeros_like(target)
    hi = np.ones_like(target)
    for _ in range(200):  # grow the bracket until it holds the root
        small = _xi21(hi, -hi / theta, theta, omega)[1] < target
        if not small.any():
            break
        hi = np.where(small, 2.0 * hi, hi)
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        below = _xi21(mid, -mid / theta, theta, omega)[1] < target
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    t2 = 0.5 * (lo + hi)
    return np.where(xi1 < 0, t2, np.nan)


def pdm_theta_pos(xi1, theta: float, omega: float, *, printed: bool = False):
    """Zero-order P_DM for theta > 0 on a grid of xi1 (identity for xi1 >= 0)."""
    xi1 = np.asarray(xi1, dtype=float)
    t2 = sliding_time_theta_pos(xi1, theta, omega)
    _, val = pdm_theta_pos_curve(np.nan_to_num(t2), theta, omega, printed=printed)
    return np.where(xi1 >= 0, xi1, val)


def pdm_theta_pos_linear(xi1, theta: float):
    """The piecewise-linear map from the ZDM, Eq. (B.23), in rescaled form: slope
    (theta - 1)/theta for xi1 < 0 (the form is the same in any scaling)."""
    _check_pos(theta)
    xi1 = np.asarray(xi1, dtype=float)
    return np.where(xi1 >= 0, xi1, (1.0 - 1.0 / theta) * xi1)


def pdm_reduced(xi1):
    """eps = 0: the quasi-static system maps every xi1 < 0 to the grazing point 0."""
    xi1 = np.asarray(xi1, dtype=float)
    return np.maximum(xi1, 0.0)
