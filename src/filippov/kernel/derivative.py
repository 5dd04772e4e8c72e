"""dP/dz of a return, carried along the orbit (compute_returns(jacobian=True))."""
from __future__ import annotations

import numpy as np

from .. import rules
from ..system import PLUS
from .base import (_dot, _flow_jacobian_minus, _flow_jacobian_plus, _flow_minus, _flow_plus,
                   _grad_h, _jacobian, _jit, _section)
from .dop853 import (_A, _B, _NS, _TRIAL, _checked_field, _stage)
from .state import Stages


# The derivative of a return, carried in w.deriv.M while the orbit runs (Settings.jac), as
# the reference driver's filippov.variational composes it: an exact-flow stay by the
# model's flow Jacobian from its mode entry where it has one (a SymbolicSystem's, generated),
# else by Richardson's extrapolation of central differences of the closed-form flow; an integrated stay (sliding, or a model without flows) by the variational
# equation taken through the very DOP853 steps of the state (internal differentiation:
# the derivative of the computed solution, the step sizes held); a switch by its
# saltation matrix; the end of sliding by the identity; the section hit by the projection
# along the field.
@_jit
def _apply(J, M, T):
    """M <- J M (T: workspace)."""
    n = M.shape[0]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += J[i, k] * M[k, j]
            T[i, j] = acc
    for i in range(n):
        for j in range(n):
            M[i, j] = T[i, j]


@_jit
def _rank_one(M, u, g, speed):
    """M <- M + u (g^T M) / speed: a saltation matrix (u = f_after - f_before, g = grad
    h, speed = g . f_before) or the section's projection (u = f, speed = -g . f). A zero
    speed (a tangential switch or hit: no derivative) makes M NaN."""
    n = M.shape[0]
    for j in range(n):
        r = 0.0
        for k in range(n):
            r += g[k] * M[k, j]
        r = r / speed if speed != 0.0 else np.nan
        for i in range(n):
            M[i, j] += u[i] * r


@_jit
def _flow_quotient(mode, za, k, d, tau, fns, p, dv):
    """dv.jz1 <- (flow(za + d e_k) - flow(za - d e_k)) / (up - down), the central
    difference of the closed-form flow over the steps as represented (za is restored bit
    for bit)."""
    orig = za[k]
    za[k] = orig + d
    up = za[k]
    if mode == PLUS:
        _flow_plus(fns, za, tau, p, dv.jz1)
    else:
        _flow_minus(fns, za, tau, p, dv.jz1)
    za[k] = orig - d
    down = za[k]
    if mode == PLUS:
        _flow_plus(fns, za, tau, p, dv.jz2)
    else:
        _flow_minus(fns, za, tau, p, dv.jz2)
    za[k] = orig
    for i in range(za.size):
        dv.jz1[i] = (dv.jz1[i] - dv.jz2[i]) / (up - down)


@_jit
def _flow_jacobian(mode, za, tau, fns, p, dv, exact):
    """dv.Mt = d flow(za, tau) / d za: the model's flow Jacobian (``exact``), else column
    by column by Richardson's extrapolation of two central differences of the closed-form
    flow (rules.richardson_step from the component's scale up, and half of it)."""
    n = za.size
    if exact:
        if mode == PLUS:
            _flow_jacobian_plus(fns, za, tau, p, dv.Jm)
        else:
            _flow_jacobian_minus(fns, za, tau, p, dv.Jm)
        for i in range(n):
            for k in range(n):
                dv.Mt[i, k] = dv.Jm[i * n + k]
        return
    for k in range(n):
        d = rules.richardson_step(max(dv.floors[k], abs(za[k])))
        _flow_quotient(mode, za, k, d, tau, fns, p, dv)
        for i in range(za.size):
            dv.Mt[i, k] = dv.jz1[i]
        _flow_quotient(mode, za, k, 0.5 * d, tau, fns, p, dv)
        for i in range(za.size):
            dv.Mt[i, k] = (4.0 * dv.jz1[i] - dv.Mt[i, k]) / 3.0


@_jit
def _jvp(mode, y, v, out, fns, p, fl, dv):
    """out = J(y) v, the field's Jacobian along v, by a central difference
    (rules.central_step along v), sized in the metric of the components' scales (ratios
    dv.floors / dv.floor, powers of two; 1 in a run of one scale): a step from the largest
    component's scale moved a position by 6e3 beside a velocity in units 1e-9, and dP/dz
    read -3.5e3 for -0.49 (tests/test_known_misses.py)."""
    n = y.size
    size, vmax = dv.floor, 0.0
    for k in range(n):
        r = dv.floors[k] / dv.floor
        size = max(size, abs(y[k]) / r)
        vmax = max(vmax, abs(v[k]) / r)
    d = rules.central_step(size, vmax)
    if d == 0.0:
        for k in range(n):
            out[k] = 0.0 if vmax == 0.0 else np.nan
        return
    for k in range(n):
        dv.jz1[k] = y[k] + d * v[k]
        dv.jz2[k] = y[k] - d * v[k]
    _checked_field(dv.jz1, mode, _TRIAL, fns, p, fl, dv.jf1)
    _checked_field(dv.jz2, mode, _TRIAL, fns, p, fl, dv.jf2)
    for k in range(n):
        out[k] = (dv.jf1[k] - dv.jf2[k]) / (2.0 * d)


@_jit
def _var_stage(s, mode, exact, fns, p, fl, dv):
    """dv.KP[s] = J(dv.ys) dv.Mt: with the model's exact Jacobian (one evaluation), or
    column by column with Jacobian-vector products by central differences."""
    n = dv.ys.size
    if exact:
        _jacobian(fns, mode, dv.ys, p, dv.Jm)
        for a in range(n):
            for b in range(n):
                acc = 0.0
                for k in range(n):
                    acc += dv.Jm[a * n + k] * dv.Mt[k, b]
                dv.KP[s, a, b] = acc
        return
    for b in range(n):
        for a in range(n):
            dv.jv[a] = dv.Mt[a, b]
        _jvp(mode, dv.ys, dv.jv, dv.jo, fns, p, fl, dv)
        for a in range(n):
            dv.KP[s, a, b] = dv.jo[a]


@_jit
def _var_step(mode, y0, h, fns, p, fl, dv, exact):
    """dv.M <- the DOP853 step of size h from y0 applied to the variational equation
    M' = J(z(t)) M, with the state's stages recomputed from y0 (the same numbers as the
    step of the state); J exact where the model has it (``exact``)."""
    n = y0.size
    for s in range(_NS):
        _stage(s, mode, y0, h, Stages(dv.KV, dv.ys), fns, p, fl)
        for a in range(n):
            for b in range(n):
                acc = 0.0
                for j in range(s):
                    acc += dv.KP[j, a, b] * _A[s, j]
                dv.Mt[a, b] = dv.M[a, b] + acc * h
        _var_stage(s, mode, exact, fns, p, fl, dv)
    for a in range(n):
        for b in range(n):
            acc = 0.0
            for j in range(_NS):
                acc += dv.KP[j, a, b] * _B[j]
            dv.M[a, b] += h * acc


@_jit
def _switch_derivative(mode, new_mode, fns, p, z, fl, dv):
    """dv.M <- S dv.M, S the saltation matrix of the switch mode -> new_mode at z."""
    _checked_field(z, mode, _TRIAL, fns, p, fl, dv.jf1)
    _checked_field(z, new_mode, _TRIAL, fns, p, fl, dv.jf2)
    _grad_h(fns, z, p, dv.jz1)
    speed = _dot(dv.jz1, dv.jf1)
    for k in range(z.size):
        dv.jf2[k] -= dv.jf1[k]
    _rank_one(dv.M, dv.jf2, dv.jz1, speed)


@_jit
def _section_quotient(fns, p, z, k, d):
    """(s(z + d e_k) - s(z - d e_k)) / (up - down), s the section (z restored bit for
    bit)."""
    orig = z[k]
    z[k] = orig + d
    up = z[k]
    s1 = _section(fns, z, p)
    z[k] = orig - d
    down = z[k]
    s2 = _section(fns, z, p)
    z[k] = orig
    return (s1 - s2) / (up - down)


@_jit
def _section_derivative(mode, fns, p, z, fl, dv):
    """dv.M <- (I - f g^T / (g . f)) dv.M at the section hit z: f the field there, g the
    section's gradient (Richardson's extrapolation of two central differences, as
    _flow_jacobian)."""
    _checked_field(z, mode, _TRIAL, fns, p, fl, dv.jf1)
    for k in range(z.size):
        d = rules.richardson_step(max(dv.floors[k], abs(z[k])))
        coarse = _section_quotient(fns, p, z, k, d)
        dv.jz1[k] = (4.0 * _section_quotient(fns, p, z, k, 0.5 * d) - coarse) / 3.0
    _rank_one(dv.M, dv.jf1, dv.jz1, -_dot(dv.jz1, dv.jf1))
