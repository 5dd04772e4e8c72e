"""The pseudo-equilibrium example of section sec:exmpl (eq:peqslow, eq:peqfast).

    x' = -sign(theta x + (1 - theta) y),    eps y' = x - y.

Region + (h >= 0) has x' = -1, region - has x' = +1; the fast variable relaxes to
x. Every region has a closed-form flow; so has the sliding flow on H_s for
0 < theta < 1 (x' = -x / (eps theta), a fact derived from eq:slide).
"""
from __future__ import annotations

import numpy as np

from ..model import TRANSIENT, SlowFastModel
from ..system import MINUS, PLUS, SLIDING


def _check(eps: float, theta: float) -> None:
    if not np.isfinite(theta) or theta >= 1:
        raise ValueError(f"theta must be finite and < 1 (the fast equation degenerates "
                         f"at theta = 1), got {theta!r}")
    if not np.isfinite(eps) or eps < 0:
        raise ValueError(f"eps must be finite and >= 0, got {eps!r}")


def _slope_flow(c: float, eps: float):
    """Exact flow of x' = c, eps y' = x - y: y relaxes to x - c eps."""

    def flow(z0, tau):
        tau = np.asarray(tau, dtype=float)
        x0, y0 = z0[0], z0[1]
        x = x0 + c * tau
        y = x - c * eps + (y0 - x0 + c * eps) * np.exp(-tau / eps)
        return np.stack([x, y])

    return flow


def model(eps: float, theta: float) -> SlowFastModel:
    _check(eps, theta)
    one = lambda x, y: np.ones_like(x)
    flows_full = {PLUS: _slope_flow(-1.0, eps), MINUS: _slope_flow(1.0, eps)} if eps > 0 else {}
    if eps > 0 and 0 < theta < 1:
        k = 1.0 / (eps * theta)

        def sliding_flow(z0, tau):
            x = z0[0] * np.exp(-k * np.asarray(tau, dtype=float))
            return np.stack([x, -theta / (1 - theta) * x])

        flows_full[SLIDING] = sliding_flow

    def reduced_flow(c):
        return lambda z0, tau: np.stack([z0[0] + c * np.asarray(tau, dtype=float)])

    flows_reduced = {PLUS: reduced_flow(-1.0), MINUS: reduced_flow(1.0),
                     SLIDING: lambda z0, tau: np.stack([z0[0] + 0.0 * np.asarray(tau, dtype=float)])}
    return SlowFastModel(
        name="pseudo_equilibrium", slow_names=("x",), fast_names=("y",),
        f_minus=one, f_plus=lambda x, y: -np.ones_like(x),
        h=lambda x, y: theta * x[0] + (1 - theta) * y[0],
        h_grad=lambda x, y: (theta * np.ones_like(x), (1 - theta) * np.ones_like(y)),
        g_minus=lambda x, y: x - y, g_plus=lambda x, y: x - y,
        eps=eps, y0=lambda x: x.copy(), y0_jac=lambda x: np.ones((1,) + np.shape(x)),
        exact_flows={"full": flows_full, "reduced": flows_reduced},
        sample_step_full=eps / 4 if eps > 0 else np.inf, sample_step_reduced=0.25,
        # y - x relaxes like exp(-t/eps) after a mode entry; then x, y move at speed 1
        slow_sample_step_full=0.25, transient_time_full=TRANSIENT * eps,
        units={"t": "1", "x": "1", "y": "1"}, parameters={"eps": eps, "theta": theta})


# --------------------------------------------------------------------------- compiled
def compiled(eps: float, theta: float, *, section_x: float = 10.0):
    """The slow-fast system z = (x, y) with its exact flows, compiled for
    the compiled engine (:mod:`filippov.abi`); the section is ``x = section_x`` crossed with x
    decreasing (the default is never reached near the origin, so a run counts
    switches until ``t_max``). Sliding is not compiled: the kernel integrates
    it with DOP853, as the reference driver does without ``method="exact"``."""
    _check(eps, theta)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    from ..abi import CompiledModel

    return CompiledModel(
        name="pseudo_equilibrium", names=("x", "y"),
        params=np.array([eps, theta, section_x], dtype=float), **_compiled_pieces(),
        section_direction=-1, sample_step=eps / 4, slow_sample_step=0.25,
        transient_time=TRANSIENT * eps,
        parameters={"eps": eps, "theta": theta})


_PIECES = {}


def _compiled_pieces() -> dict:
    """numba versions of the pieces; params p = (eps, theta, section_x)."""
    if _PIECES:
        return _PIECES
    from numba import njit

    from ..abi import FIELD_SIG, FLOW_SIG, SCALAR_SIG, always

    @njit(FLOW_SIG, cache=True)
    def flow_plus(z0, tau, p, out):  # x' = -1: y relaxes to x + eps
        eps = p[0]
        out[0] = z0[0] - tau
        out[1] = out[0] + eps + (z0[1] - z0[0] - eps) * np.exp(-tau / eps)

    @njit(FLOW_SIG, cache=True)
    def flow_minus(z0, tau, p, out):  # x' = +1: y relaxes to x - eps
        eps = p[0]
        out[0] = z0[0] + tau
        out[1] = out[0] - eps + (z0[1] - z0[0] + eps) * np.exp(-tau / eps)

    @njit(FIELD_SIG, cache=True)
    def field_plus(z, p, out):
        out[0] = -1.0
        out[1] = (z[0] - z[1]) / p[0]

    @njit(FIELD_SIG, cache=True)
    def field_minus(z, p, out):
        out[0] = 1.0
        out[1] = (z[0] - z[1]) / p[0]

    @njit(SCALAR_SIG, cache=True)
    def h(z, p):
        return p[1] * z[0] + (1 - p[1]) * z[1]

    @njit(FIELD_SIG, cache=True)
    def grad_h(z, p, out):
        out[0] = p[1]
        out[1] = 1 - p[1]

    @njit(SCALAR_SIG, cache=True)
    def section(z, p):
        return z[0] - p[2]

    _PIECES.update(flow_plus=flow_plus, flow_minus=flow_minus, field_plus=field_plus,
                   field_minus=field_minus, h=h, grad_h=grad_h, section=section,
                   section_where=always)
    return _PIECES
