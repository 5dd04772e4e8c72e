"""The limit map: the return map to L1 of the Hopf example near grazing as the paper's
asymptotics give it, in scaled coordinates.

Scales: sigma = eps for theta < 0 (Eq. (B.2)), eps^2 for theta > 0 (Eq. (B.24)). On L1
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

Only numpy; the map is iterated for many s at once (:func:`orbits`: for every theta and eps
of a scene too, bit for bit as one at a time).
"""
from __future__ import annotations

import numpy as np

from .pdm import pdm_theta_neg, pdm_theta_pos
from .s0 import s0_lambert


def multiplier(mu: float, omega: float) -> float:
    """lambda = exp(-4 pi mu/omega): the Hopf cycle's multiplier over one turn."""
    return float(np.exp(-4.0 * np.pi * mu / abs(omega)))


def scale(eps: float, theta: float) -> float:
    """sigma: eps for theta < 0, eps^2 for theta > 0 (elementwise for arrays)."""
    if np.ndim(theta) or np.ndim(eps):
        theta, eps = np.asarray(theta, dtype=float), np.asarray(eps, dtype=float)
        if np.any(theta == 0):
            raise ValueError("theta = 0 is the boundary between the two cases")
        return np.where(theta < 0, eps, eps * eps)
    if theta == 0:
        raise ValueError("theta = 0 is the boundary between the two cases")
    return eps if theta < 0 else eps * eps


def _negative(theta) -> bool:
    """theta < 0 (the case of P_DM), for a scalar or for an array of one sign."""
    neg = np.asarray(theta) < 0
    every = bool(neg.all())
    if neg.ndim and neg.any() != every:
        raise ValueError("theta: one sign per call of the map (the two cases differ)")
    return every


def _global(s, eps: float, theta: float, omega: float, order: int):
    """(lambda, u*) of the global part at s: the cycle's multiplier per turn and its point
    on L1 in scaled terms; order 0 is the eps -> 0 limit throughout (mu = 1 in lambda,
    u* = s/2)."""
    if order == 0:
        return np.exp(-4.0 * np.pi / abs(omega)), 0.5 * s
    sigma = scale(eps, theta)
    mu = 1.0 + s * sigma
    return np.exp(-4.0 * np.pi * mu / abs(omega)), (np.sqrt(mu) - 1.0) / sigma


def step(u, s, *, eps: float, theta: float, omega: float, order: int = 1):
    """One return of the limit map: u -> u' (arrays broadcast; s scaled as u). Order 1
    keeps eps in the global part (mu = 1 + s sigma) and, for theta < 0, the sqrt(eps)
    term of P_DM; order 0 is the limit eps -> 0 of both."""
    u, s = np.asarray(u, dtype=float), np.asarray(s, dtype=float)
    lam, ustar = _global(s, eps, theta, omega, order)
    rho = ustar + lam ** 0.25 * (u - ustar)
    xi = -rho
    if _negative(theta):
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


def orbits(s, thetas, eps, *, omega: float, transient: int, keep: int,
           order: int = 1) -> np.ndarray:
    """:func:`orbit` for every (theta, eps) on the grid ``s``, shape (len(thetas),
    len(eps), len(s), keep): one iteration of the map over all the points of each sign
    of theta at once. Each point is mapped by the arithmetic :func:`orbit` does for its own
    (theta, eps), elementwise (numpy's loops give an element the same bits wherever it
    sits), so the values are :func:`orbit`'s bit for bit (tests/test_instabilities.py);
    the inversion of the theta > 0 discontinuity map costs per call more than per point,
    and there are len(thetas) x len(eps) times fewer calls."""
    s, th, ep = (np.atleast_1d(np.asarray(a, dtype=float)).ravel() for a in (s, thetas, eps))
    if np.any(th == 0):
        raise ValueError("theta = 0 is the boundary between the two cases")
    out = np.empty((th.size, ep.size, s.size, keep))
    for group in (th < 0, th > 0):
        idx = np.flatnonzero(group)
        if idx.size:
            T, E, S = (a.ravel() for a in np.meshgrid(th[idx], ep, s, indexing="ij"))
            u = orbit(S, eps=E, theta=T, omega=omega, transient=transient, keep=keep,
                      order=order)
            out[idx] = u.reshape(idx.size, ep.size, s.size, keep)
    return out


def slopes(u, s, *, eps: float, theta: float, omega: float, order: int = 1,
           h: float = 1e-6) -> np.ndarray:
    """du'/du of one return by central differences of step h (in u): the map is
    piecewise smooth with O(1) second derivatives in these coordinates, so the
    truncation is ~h^2 and the rounding ~1e-16/h."""
    kw = dict(eps=eps, theta=theta, omega=omega, order=order)
    return (step(u + h, s, **kw) - step(u - h, s, **kw)) / (2.0 * h)


# ----------------------------------------------------------------------------- boundaries
# theta > 0, past grazing: near the border the map is piecewise linear (the border-collision
# normal form of Nusse & Yorke 1992), u' = tau_miss u + c on the side that misses H and
# tau_hit u + c on the side that slides, with tau_miss = lambda (one smooth turn) and
# tau_hit = lambda s(theta,0,0), s(theta,0,0) = (theta - 1)/theta the slope of P_DM at 0-.
# With 0 < tau_miss < 1 the attractor past grazing is (Banerjee, Yorke & Grebogi 1998):
#   tau_hit > -1                         the fixed point: period one;
#   -1/tau_miss < tau_hit < -1           the orbit of period two (multiplier tau_miss tau_hit);
#   tau_hit < -1/tau_miss                chaos (bands of a skew tent map).
# In theta: period one for theta > lambda/(1 + lambda), period two down to
# lambda^2/(1 + lambda^2), chaos below. The paper's s(theta,0,0) < -1 is necessary only.
def flip_threshold(lam: float) -> float:
    """theta where the period-one orbit of the normal form loses stability:
    lambda s(theta,0,0) = -1, theta = lambda/(1 + lambda)."""
    return lam / (1.0 + lam)


def chaos_threshold(lam: float) -> float:
    """theta where the period-two orbit of the normal form loses stability and chaos
    begins: lambda^2 s(theta,0,0) = -1, theta = lambda^2/(1 + lambda^2)."""
    return lam * lam / (1.0 + lam * lam)


def slope(u, s, *, eps: float, theta: float, omega: float, order: int = 1):
    """du'/du of one return for theta < 0 in closed form, on the piece u lies in:
    lambda dP_DM/dxi1 with dP_DM/dxi1 = 1 where the orbit misses H (xi1 >= 0) and
    1 - sqrt(eps) s0 (omega/(theta + s0) - 2/omega)/sqrt(-2 xi1) where it hits (order 1;
    1 at order 0). Unbounded as xi1 -> 0- at order 1: no central difference straddles
    the border here (the slope of :func:`slopes` averages the two pieces within h of it)."""
    if not theta < 0:
        raise ValueError("the closed-form slope is for theta < 0")
    u, s = np.asarray(u, dtype=float), np.asarray(s, dtype=float)
    lam, ustar = _global(s, eps, theta, omega, order)
    xi = -(ustar + lam ** 0.25 * (u - ustar))
    d = np.ones(np.broadcast(xi, s).shape)
    if order >= 1:
        s0 = s0_lambert(theta)
        k = np.sqrt(eps) * s0 * (omega / (theta + s0) - 2.0 / omega)
        with np.errstate(divide="ignore"):
            d = np.where(xi < 0, 1.0 - k / np.sqrt(-2.0 * np.minimum(xi, 0.0)), d)
    return lam * d


def cycle(u0: float, s: float, n: int, *, eps: float, theta: float, omega: float,
          order: int = 1, tol: float = 1e-13, max_iter: int = 50) -> tuple[np.ndarray, float]:
    """The period-n orbit of the map through the point near ``u0`` (Newton on
    step^n(u) - u, derivative by :func:`slope` for theta < 0 and central differences
    as in :func:`slopes` for theta > 0, along the orbit) and its multiplier, the
    product of the slopes: (orbit points (n,), multiplier). ValueError if Newton does
    not converge or the orbit touches the border (the kink at rho = 0: slopes undefined)."""
    kw = dict(eps=eps, theta=theta, omega=omega, order=order)
    h = 1e-6   # the central step of slopes() (theta > 0)
    u = float(u0)
    for _ in range(max_iter):
        pts, mult = [u], 1.0
        for _k in range(n):
            x = pts[-1]
            if theta < 0:   # the slope of the piece the point lies in, in closed form
                mult *= float(slope(x, s, **kw))
                pts.append(float(step(x, s, **kw)))
            else:
                # the point and its neighbours at +-h in one call per return (each step
                # solves the sliding time: its cost is per call, not per point)
                img = step(np.array([x - h, x, x + h]), s, **kw)
                mult *= float(img[2] - img[0]) / (2.0 * h)
                pts.append(float(img[1]))
        image = pts.pop()
        if abs(image - u) <= tol * (1.0 + abs(u)):
            return np.array(pts), mult
        if mult == 1.0 or not np.isfinite(mult):
            break
        u = u - (image - u) / (mult - 1.0)
    raise ValueError(f"no period-{n} orbit near u = {u0!r} at theta = {theta!r}, s = {s!r}")


def flip_point(s: float, n: int, inside: float, outside: float, *, eps: float, omega: float,
               order: int = 1, xtol: float = 1e-10) -> float:
    """theta between ``inside`` (where the map's attractor is the period-n orbit) and
    ``outside`` at which that orbit's multiplier crosses -1: the orbit followed in theta
    by Newton (:func:`cycle`) from the attractor at ``inside``, the crossing bracketed on
    eight steps towards ``outside`` and located by bisection to ``xtol``."""
    kw = dict(eps=eps, omega=omega, order=order)
    last = {"u": float(orbit([s], theta=inside, transient=300, keep=1, **kw)[0, -1])}

    def excess(theta):   # multiplier + 1 of the followed orbit: > 0 while it is stable
        pts, mult = cycle(last["u"], s, n, theta=theta, **kw)
        last["u"] = float(pts[0])
        return mult + 1.0

    return bisect_crossing(excess, inside, outside, xtol, what=f"period-{n} orbit")


def bisect_crossing(excess, inside: float, outside: float, xtol: float, *, what: str) -> float:
    """Where ``excess`` (> 0 at ``inside``) first falls to <= 0 on the way to ``outside``:
    bracketed on eight equal steps (so that a followed orbit moves a little at a time),
    then bisected to ``xtol``."""
    a = float(inside)
    if not excess(a) > 0:
        raise ValueError(f"the {what} at {a!r} is not stable")
    lo = a
    for th in np.linspace(a, float(outside), 9)[1:]:
        if not excess(th) > 0:
            hi = th
            break
        lo = th
    else:
        raise ValueError(f"the {what} stays stable up to {outside!r}")
    while abs(hi - lo) > xtol:
        mid = 0.5 * (lo + hi)
        if excess(mid) > 0:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def itinerary(points, s: float, *, eps: float, theta: float, omega: float,
              order: int = 1) -> tuple:
    """For each point u of an orbit, whether its return meets H (True: rho > 0 at L2,
    the discontinuity map's jump; False: the orbit misses H): the piece of the map the
    point lies in. A periodic orbit keeps its itinerary until one of its points reaches
    the border rho = 0 (a border collision)."""
    lam, ustar = _global(s, eps, theta, omega, order)
    rho = ustar + lam ** 0.25 * (np.asarray(points, dtype=float) - ustar)
    return tuple(bool(r > 0) for r in rho)
