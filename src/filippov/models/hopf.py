"""The minimal grazing-sliding example (eq:red; eq:exslow2, eq:exfast2).

Slow state x = (x1, x2), fast state y:

    x' = f_+(x) = (mu x1 - omega x2 - r^2 x1, omega x1 + mu x2 - r^2 x2)   if h >= 0
    x' = f_-    = (1, 0)                                                  if h < 0
    eps y' = g(x, y) = eps [mu x1 - omega x2 - r^2 x1] + x1 - y
    h = theta x1 + (1 - theta) y + 1

The reduced system (eps = 0) has y0(x) = x1 and h0 = x1 + 1.

Both regions have closed-form flows, derived here and checked against
integration in the tests:

* region +: in polar coordinates r' = mu r - r^3, phi' = omega, so
  r(t)^2 = mu r0^2 / (r0^2 + (mu - r0^2) exp(-2 mu t)); and since g = eps x1' + x1 - y,
  (y - x1)' = -(y - x1)/eps, i.e. y - x1 decays exactly like exp(-t/eps);
  M_+ = {y = x1} is invariant.
* region -: x1 = x1(0) + t, x2 constant, and y' = -y/eps + p(x1(t)) with p a cubic,
  whose polynomial solution is the slow manifold M_- (exactly, not only to O(eps)):

      y_m-(x) = x1 + eps [mu x1 - omega x2 - r^2 x1 - 1] - eps^2 [mu - 3 x1^2 - x2^2]
                - 6 eps^3 x1 + 6 eps^4,

  and y = y_m-(x(t)) + (y(0) - y_m-(x(0))) exp(-t/eps).

Sliding has no closed form; it is integrated on H_s with the Filippov field.
"""
from __future__ import annotations

import numpy as np

from ..model import TRANSIENT, SlowFastModel
from ..system import MINUS, PLUS


def check_parameters(eps: float, theta: float, mu: float, omega: float) -> None:
    if not (np.isfinite(eps) and eps >= 0):
        raise ValueError(f"eps must be finite and >= 0, got {eps!r}")
    if not (np.isfinite(theta) and theta < 1):
        raise ValueError(f"theta must be finite and < 1 (at theta = 1 the switching "
                         f"function no longer sees the fast variable's sign change), got {theta!r}")
    if not (np.isfinite(mu) and mu > 0):
        raise ValueError(f"mu must be finite and > 0, got {mu!r}")
    if not (np.isfinite(omega) and omega != 0):
        raise ValueError(f"omega must be finite and nonzero, got {omega!r}")


def hopf_rhs(x1, x2, mu, omega):
    r2 = x1 * x1 + x2 * x2
    return mu * x1 - omega * x2 - r2 * x1, omega * x1 + mu * x2 - r2 * x2


def polar_flow(x10, x20, tau, mu, omega):
    """Exact flow of the Hopf normal form from (x10, x20) over times tau."""
    r02 = x10 * x10 + x20 * x20
    if r02 == 0.0:
        z = np.zeros_like(tau)
        return z, z.copy()
    # r^2/r0^2 written with expm1 so that r0^2 = mu stays exact
    e = np.expm1(-2.0 * mu * tau)  # exp(-2 mu t) - 1
    scale = np.sqrt(mu / (mu + (mu - r02) * e))
    c, s = np.cos(omega * tau), np.sin(omega * tau)
    return scale * (c * x10 - s * x20), scale * (s * x10 + c * x20)


def slow_manifold_minus(x1, x2, eps, mu, omega):
    """y on M_-, the exact slow invariant manifold of the flow in region -."""
    r2 = x1 * x1 + x2 * x2
    return (x1 + eps * (mu * x1 - omega * x2 - r2 * x1 - 1.0)
            - eps ** 2 * (mu - 3.0 * x1 * x1 - x2 * x2) - 6.0 * eps ** 3 * x1 + 6.0 * eps ** 4)


def model(eps: float, theta: float, mu: float = 1.0, omega: float = 8 * np.pi) -> SlowFastModel:
    check_parameters(eps, theta, mu, omega)

    def f_plus(x, y):
        return np.stack(hopf_rhs(x[0], x[1], mu, omega))

    def f_minus(x, y):
        return np.stack([np.ones_like(x[0]), np.zeros_like(x[1])])

    def g(x, y):
        return eps * hopf_rhs(x[0], x[1], mu, omega)[0] + x[0] - y[0]

    g_ = lambda x, y: g(x, y)[None]

    def flow_plus_full(z0, tau):
        tau = np.asarray(tau, dtype=float)
        x1, x2 = polar_flow(z0[0], z0[1], tau, mu, omega)
        return np.stack([x1, x2, x1 + (z0[2] - z0[0]) * np.exp(-tau / eps)])

    def flow_minus_full(z0, tau):
        tau = np.asarray(tau, dtype=float)
        x1 = z0[0] + tau
        x2 = z0[1] + 0.0 * tau
        dev0 = z0[2] - slow_manifold_minus(z0[0], z0[1], eps, mu, omega)
        return np.stack([x1, x2, slow_manifold_minus(x1, x2, eps, mu, omega)
                         + dev0 * np.exp(-tau / eps)])

    def flow_plus_reduced(z0, tau):
        return np.stack(polar_flow(z0[0], z0[1], np.asarray(tau, dtype=float), mu, omega))

    def flow_minus_reduced(z0, tau):
        tau = np.asarray(tau, dtype=float)
        return np.stack([z0[0] + tau, z0[1] + 0.0 * tau])

    flows = {"reduced": {PLUS: flow_plus_reduced, MINUS: flow_minus_reduced}}
    if eps > 0:
        flows["full"] = {PLUS: flow_plus_full, MINUS: flow_minus_full}
    period = 2 * np.pi / abs(omega)
    return SlowFastModel(
        name="hopf", slow_names=("x1", "x2"), fast_names=("y",),
        f_minus=f_minus, f_plus=f_plus,
        h=lambda x, y: theta * x[0] + (1 - theta) * y[0] + 1.0,
        h_grad=lambda x, y: (np.stack([theta * np.ones_like(x[0]), np.zeros_like(x[1])]),
                             (1 - theta) * np.ones_like(y)),
        g_minus=g_, g_plus=g_, eps=eps,
        y0=lambda x: x[:1].copy(),
        y0_jac=lambda x: np.stack([np.stack([np.ones_like(x[0]), np.zeros_like(x[1])])]),
        exact_flows=flows,
        sample_step_full=min(eps / 4, period / 64) if eps > 0 else np.inf,
        sample_step_reduced=period / 64,
        # y - x1 (region +) and y - M_-(x) (region -) decay like exp(-t/eps) exactly:
        # after 40 eps (exp(-40) = 4e-18) only the slow dynamics is left
        slow_sample_step_full=period / 64, transient_time_full=TRANSIENT * eps,
        units={"t": "1", "x1": "1", "x2": "1", "y": "1"},
        parameters={"eps": eps, "theta": theta, "mu": mu, "omega": omega})


# --------------------------------------------------------------------------- compiled
def compiled(eps: float, theta: float, mu: float = 1.0, omega: float = 8 * np.pi, *,
             sliding: bool = True, exact: bool = True):
    """The slow-fast system z = (x1, x2, y) with its exact flows, compiled for
    the compiled engine (:mod:`filippov.abi`), with the section L1 of fig:retmaps (x1 = 0, x1
    decreasing, x2 > 0). The same formulas as :func:`model`, in scalar form.
    ``exact=False``: the kernel integrates regions + and - with DOP853 instead."""
    check_parameters(eps, theta, mu, omega)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    from ..abi import CompiledModel

    pieces = _compiled_pieces()
    period = 2 * np.pi / abs(omega)
    return CompiledModel(
        name="hopf", names=("x1", "x2", "y"),
        params=np.array([eps, theta, mu, omega], dtype=float), **pieces,
        section_direction=-1, sample_step=min(eps / 4, period / 64), sliding=sliding,
        slow_sample_step=period / 64, transient_time=TRANSIENT * eps, exact=exact,
        parameters={"eps": eps, "theta": theta, "mu": mu, "omega": omega})


_PIECES = {}


def _compiled_pieces() -> dict:
    """numba versions of the pieces; params p = (eps, theta, mu, omega). Each piece
    is self-contained (no calls to other compiled functions), so numba caches it."""
    if _PIECES:
        return _PIECES
    from numba import njit

    from ..abi import FIELD_SIG, FLOW_SIG, SCALAR_SIG, WHERE_SIG

    @njit(FLOW_SIG, cache=True)
    def flow_plus(z0, tau, p, out):
        eps, mu, omega = p[0], p[2], p[3]
        x10, x20 = z0[0], z0[1]
        r02 = x10 * x10 + x20 * x20
        if r02 == 0.0:
            x1, x2 = 0.0, 0.0
        else:
            e = np.expm1(-2.0 * mu * tau)
            scale = np.sqrt(mu / (mu + (mu - r02) * e))
            c, s = np.cos(omega * tau), np.sin(omega * tau)
            x1, x2 = scale * (c * x10 - s * x20), scale * (s * x10 + c * x20)
        out[0] = x1
        out[1] = x2
        out[2] = x1 + (z0[2] - z0[0]) * np.exp(-tau / eps)

    @njit(FLOW_SIG, cache=True)
    def flow_minus(z0, tau, p, out):
        eps, mu, omega = p[0], p[2], p[3]
        e2, e3, e4 = eps ** 2, eps ** 3, eps ** 4
        a1, a2 = z0[0], z0[1]
        r2 = a1 * a1 + a2 * a2
        ym0 = (a1 + eps * (mu * a1 - omega * a2 - r2 * a1 - 1.0)
               - e2 * (mu - 3.0 * a1 * a1 - a2 * a2) - 6.0 * e3 * a1 + 6.0 * e4)
        x1 = z0[0] + tau
        x2 = z0[1] + 0.0 * tau
        r2 = x1 * x1 + x2 * x2
        ym = (x1 + eps * (mu * x1 - omega * x2 - r2 * x1 - 1.0)
              - e2 * (mu - 3.0 * x1 * x1 - x2 * x2) - 6.0 * e3 * x1 + 6.0 * e4)
        out[0] = x1
        out[1] = x2
        out[2] = ym + (z0[2] - ym0) * np.exp(-tau / eps)

    @njit(FIELD_SIG, cache=True)
    def field_plus(z, p, out):
        eps, mu, omega = p[0], p[2], p[3]
        x1, x2 = z[0], z[1]
        r2 = x1 * x1 + x2 * x2
        f1 = mu * x1 - omega * x2 - r2 * x1
        out[0] = f1
        out[1] = omega * x1 + mu * x2 - r2 * x2
        out[2] = (eps * f1 + x1 - z[2]) / eps

    @njit(FIELD_SIG, cache=True)
    def field_minus(z, p, out):
        eps, mu, omega = p[0], p[2], p[3]
        x1, x2 = z[0], z[1]
        r2 = x1 * x1 + x2 * x2
        f1 = mu * x1 - omega * x2 - r2 * x1
        out[0] = 1.0
        out[1] = 0.0
        out[2] = (eps * f1 + x1 - z[2]) / eps

    @njit(SCALAR_SIG, cache=True)
    def h(z, p):
        theta = p[1]
        return theta * z[0] + (1 - theta) * z[2] + 1.0

    @njit(FIELD_SIG, cache=True)
    def grad_h(z, p, out):
        theta = p[1]
        out[0] = theta
        out[1] = 0.0
        out[2] = 1 - theta

    @njit(SCALAR_SIG, cache=True)
    def section(z, p):
        return z[0]

    @njit(WHERE_SIG, cache=True)
    def section_where(z, p):
        return z[1] > 0

    _PIECES.update(flow_plus=flow_plus, flow_minus=flow_minus, field_plus=field_plus,
                   field_minus=field_minus, h=h, grad_h=grad_h, section=section,
                   section_where=section_where)
    return _PIECES
