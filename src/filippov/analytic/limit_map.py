"""The limit map: the return map to L1 of the Hopf example near grazing as the paper's
asymptotics give it, in scaled coordinates.

Scales: sigma = eps for theta < 0 (eq:scal), eps^2 for theta > 0 (eq:p:scal). On L1
(x1 = 0, x2 > 0) the coordinate is u = (x2 - 1)/sigma, the parameter s = (mu - 1)/sigma.
One return is composed of

* a quarter turn of the smooth flow from L1 to L2 (the minimum of x1 on the orbit,
  x1 = -r there): r - r* shrinks by lambda^(1/4), with lambda = exp(-4 pi mu/omega)
  the multiplier of the Hopf cycle r* = sqrt(mu) over one turn, so in scaled terms
  rho = u* + lambda^(1/4) (u - u*), u* = (sqrt(mu) - 1)/sigma;
* the discontinuity map at L2 in xi1 = (x1 + 1)/sigma = -rho: the corrected P_DM of
  :mod:`filippov.analytic.pdm` (identity for xi1 >= 0: the orbit misses H);
* three quarter turns back to L1: u' = u* + lambda^(3/4) (rho' - u*).

theta < 0: P_DM = xi1 + s0 (order 0, the eps -> 0 limit) plus the delta = sqrt(eps)
term delta s0 sqrt(-2 xi1) (omega/(theta + s0) - 2/omega) (order 1). Its coefficient
is large (58.7 at theta = -0.5, omega = 8 pi), so at eps = 1e-4 the order-1 term is
still comparable to s0: the eps -> 0 limit is approached like sqrt(eps), slowly.
theta > 0: P_DM along its curve (:func:`filippov.analytic.pdm.pdm_theta_pos`), slope
(theta - 1)/theta at 0-, no eps left at leading order.

Only numpy; the map is iterated for many s at once.
"""
from __future__ import annotations

import numpy as np

from .pdm import pdm_theta_neg, pdm_theta_pos


def multiplier(mu: float, omega: float) -> float:
    """lambda = exp(-4 pi mu/omega): the Hopf cycle's multiplier over one turn."""
    return float(np.exp(-4.0 * np.pi * mu / abs(omega)))


def scale(eps: float, theta: float) -> float:
    if theta == 0:
        raise ValueError("theta = 0 is the boundary between the two cases")
    return eps if theta < 0 else eps * eps


def step(u, s, *, eps: float, theta: float, omega: float, order: int = 1):
    """One return of the limit map: u -> u' (arrays broadcast; s scaled as u). Order 1
    keeps eps in the global part (mu = 1 + s sigma) and, for theta < 0, the sqrt(eps)
    term of P_DM; order 0 is the limit eps -> 0 of both."""
    sigma = scale(eps, theta)
    u, s = np.asarray(u, dtype=float), np.asarray(s, dtype=float)
    if order == 0:  # the eps -> 0 limit throughout: mu = 1 in lambda, u* = s/2
        lam, ustar = np.exp(-4.0 * np.pi / abs(omega)), 0.5 * s
    else:
        mu = 1.0 + s * sigma
        lam = np.exp(-4.0 * np.pi * mu / abs(omega))
        ustar = (np.sqrt(mu) - 1.0) / sigma
    rho = ustar + lam ** 0.25 * (u - ustar)
    xi = -rho
    if theta < 0:
        xi_new = pdm_theta_neg(xi, theta, omega, eps, order=order)
    else:
        xi_new = pdm_theta_pos(xi, theta, omega)
    return ustar + lam ** 0.75 * (-xi_new - ustar)


def orbit(s, *, eps: float, theta: float, omega: float, transient: int, keep: int,
          order: int = 1, start=None) -> np.ndarray:
    """The last ``keep`` of ``transient + keep`` returns for each s (shape (len(s), keep)),
    from u = u* (the cycle, as the slow-fast runs start) unless ``start`` is given."""
    s = np.atleast_1d(np.asarray(s, dtype=float))
    sigma = scale(eps, theta)
    cycle = 0.5 * s if order == 0 else (np.sqrt(1.0 + s * sigma) - 1.0) / sigma
    u = cycle if start is None else np.broadcast_to(
        np.asarray(start, dtype=float), s.shape).copy()
    out = np.empty((s.size, keep))
    for k in range(transient + keep):
        u = step(u, s, eps=eps, theta=theta, omega=omega, order=order)
        if k >= transient:
            out[:, k - transient] = u
    return out


def slopes(u, s, *, eps: float, theta: float, omega: float, order: int = 1,
           h: float = 1e-6) -> np.ndarray:
    """du'/du of one return by central differences of step h (in u): the map is
    piecewise smooth with O(1) second derivatives in these coordinates, so the
    truncation is ~h^2 and the rounding ~1e-16/h."""
    kw = dict(eps=eps, theta=theta, omega=omega, order=order)
    return (step(u + h, s, **kw) - step(u - h, s, **kw)) / (2.0 * h)
