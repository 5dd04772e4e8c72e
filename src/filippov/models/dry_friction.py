"""The autonomous dry-friction oscillator of sec:dfo1 (eq:dfo1, eq:dfo-sf), M = K = 1.

Slow state x = (x1, x2) (block position and velocity), fast state y = (w,) with
w = gamma x2 + v (v: belt speed):

    x1' = x2
    x2' = -x1 - F_c((1 + gamma) x2 - w)
    eps w' = -w + v0 + gamma x2 - eps gamma x1
    h = w - (1 + gamma) x2 = v - x2          (region + : h >= 0, block slower than belt)

The reduced system (eps = 0) has w = y0(x) = v0 + gamma x2, so h0 = v0 - x2 and
the slow equations become eq:dfo1 with belt speed v = v0.

Friction law. The caption of fig:dfo-retmap prints
F_c(nu) = f0 sgn(nu) + fv nu + fc (1 - exp(-|nu|)) sgn(nu) with f0 = -2,
fv = 0.3, fc = 2.5. Read literally with eq:dfo1 (force -F_c on the block) this
gives F_c(0+) = -2: friction would push the block along its relative velocity,
sticking on x2 = v is repelling (eq:atSl fails) and the equilibrium never loses
stability. The convention adopted here ("stribeck") is the one of the paper's
commented-out friction curve: F_c acts against the relative velocity with a
static level |f0| = 2 that decays to -f0 - fc = -0.5 and then grows with fv:

    F_c(nu) = sgn(nu) [-f0 - fc (1 - exp(-|nu|))] + fv nu.

It is the printed formula with the signs of f0 and fc flipped. The literal
reading is kept ("literal") so that the evidence can be recomputed; see
paper/notes/dry_friction.md.

Each region's friction is a smooth (analytic) branch defined for all nu,
``F_plus`` (nu <= 0) and ``F_minus`` (nu > 0), so the fields extend smoothly
across H_s, as the slow-manifold construction needs.

No region has a closed-form flow: every mode is integrated (DOP853).
"""
from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp

from ..model import SlowFastModel

CONVENTIONS = ("stribeck", "literal")


def check_parameters(eps, v0, gamma, f0, fv, fc, convention) -> None:
    for name, val in (("eps", eps), ("v0", v0), ("gamma", gamma), ("f0", f0), ("fv", fv),
                      ("fc", fc)):
        if not np.isfinite(val):
            raise ValueError(f"{name} must be finite, got {val!r}")
    if eps < 0:
        raise ValueError(f"eps must be >= 0, got {eps!r}")
    if v0 <= 0:
        raise ValueError(f"v0 (belt speed) must be > 0, got {v0!r}")
    if gamma < 0:
        raise ValueError(f"gamma (block/belt mass ratio) must be >= 0, got {gamma!r}")
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {CONVENTIONS}, got {convention!r}")


def friction_branches(f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """``(F_plus, dF_plus, F_minus, dF_minus)``: the smooth branches of F_c for
    nu < 0 (region +) and nu > 0 (region -), each extended to all nu."""
    if convention == "stribeck":
        s0, sc = -f0, -fc   # sgn(nu) [-f0 - fc (1 - e^{-|nu|})]
    elif convention == "literal":
        s0, sc = f0, fc     # sgn(nu) [f0 + fc (1 - e^{-|nu|})]
    else:
        raise ValueError(f"convention must be one of {CONVENTIONS}, got {convention!r}")

    def F_plus(nu):   # sgn = -1, |nu| = -nu
        return -s0 - sc * (1.0 - np.exp(nu)) + fv * nu

    def dF_plus(nu):
        return sc * np.exp(nu) + fv

    def F_minus(nu):  # sgn = +1
        return s0 + sc * (1.0 - np.exp(-nu)) + fv * nu

    def dF_minus(nu):
        return sc * np.exp(-nu) + fv

    return F_plus, dF_plus, F_minus, dF_minus


def friction(nu, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """F_c(nu); at nu = 0 the set-valued law is reported as NaN."""
    Fp, _, Fm, _ = friction_branches(f0, fv, fc, convention)
    nu = np.asarray(nu, dtype=float)
    out = np.where(nu < 0, Fp(np.minimum(nu, 0.0)), Fm(np.maximum(nu, 0.0)))
    return np.where(nu == 0, np.nan, out)


def hopf_speed(fv=0.3, fc=2.5, convention="stribeck") -> float:
    """Belt speed where the equilibrium's damping F_c'(-v) = fv - fc exp(-v)
    vanishes (trace of the Jacobian zero, frequency sqrt(K/M) = 1)."""
    if convention != "stribeck" or not (fc > fv > 0):
        return float("nan")  # literal law: damping fv + fc e^{-v} > 0, no Hopf point
    return float(np.log(fc / fv))


def equilibrium(v, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """(x1, x2) = (-F_c(-v), 0), in region + for v > 0."""
    Fp = friction_branches(f0, fv, fc, convention)[0]
    return np.stack([-Fp(-np.asarray(v, dtype=float)), np.zeros_like(np.asarray(v, float))])


def model(eps: float, v0: float, gamma: float = 2.0, f0: float = -2.0, fv: float = 0.3,
          fc: float = 2.5, convention: str = "stribeck") -> SlowFastModel:
    check_parameters(eps, v0, gamma, f0, fv, fc, convention)
    Fp, dFp, Fm, dFm = friction_branches(f0, fv, fc, convention)
    g1 = 1.0 + gamma

    def slow(F):
        def f(x, y):
            return np.stack([x[1] + 0.0 * y[0], -x[0] - F(g1 * x[1] - y[0])])
        return f

    def g(x, y):
        return (-y[0] + v0 + gamma * x[1] - eps * gamma * x[0])[None]

    def h_grad(x, y):
        return (np.stack([np.zeros_like(x[0]), -g1 * np.ones_like(x[1])]),
                np.ones_like(y))

    return SlowFastModel(
        name="dry_friction", slow_names=("x1", "x2"), fast_names=("w",),
        f_minus=slow(Fm), f_plus=slow(Fp),
        h=lambda x, y: y[0] - g1 * x[1], h_grad=h_grad,
        g_minus=g, g_plus=g, eps=eps,
        y0=lambda x: (v0 + gamma * x[1])[None],
        y0_jac=lambda x: np.stack([np.stack([np.zeros_like(x[0]), gamma * np.ones_like(x[1])])]),
        units={"t": "1", "x1": "1", "x2": "1", "w": "1"},
        parameters={"eps": eps, "v0": v0, "gamma": gamma, "f0": f0, "fv": fv, "fc": fc,
                    "convention": convention})


# --------------------------------------------------------------------------- slow manifold
def _plus_field_batch(eps, v0, gamma, Fp):
    """Region-+ field of eq:dfo-sf for m states stacked as (3m,): [x1..., x2..., w...]."""
    g1 = 1.0 + gamma

    def rhs(t, z):
        x1, x2, w = z.reshape(3, -1)
        return np.concatenate([x2, -x1 - Fp(g1 * x2 - w),
                               (-w + v0 + gamma * x2 - eps * gamma * x1) / eps])
    return rhs


def slow_manifold_plus(x1, x2, eps, v0, gamma=2.0, f0=-2.0, fv=0.3, fc=2.5,
                       convention="stribeck", relax=30.0, t_max=1.0, rtol=1e-12,
                       atol=1e-14, newton_tol=1e-13, max_iter=8):
    """w on the slow manifold M_+ of eq:dfo-sf above the points (x1, x2).

    M_+ attracts at rate 1/eps, so it is reached by relaxation: start at x_s
    with w on the second-order expansion of M_+ (derived from the invariance
    equation for u = w - v0 - gamma x2, i.e. eps u' = -u + eps gamma F(x2 - v0 - u)):

        w2(x) = v0 + gamma x2 + eps gamma F + eps^2 gamma F' (x1 + (1 - gamma) F),
        F = F_plus(x2 - v0),

    follow the region-+ field for a time T = min(relax * eps, t_max) and solve (Newton, all
    points at once) for x_s such that x(T) = (x1, x2). The deviation from M_+
    shrinks by exp(-T/eps) (T is capped: for eps = 0.1 a longer history would
    run through the sticking region, where the smooth region-+ field is fiction
    and unstable; there the estimate below is about 1e-9). Where that history reaches x2 > v0, the friction
    branch F_plus is continued by its tangent at nu = 0 (the analytic branch
    runs away like exp(nu)): M_+ is only defined up to terms of order
    exp(-(time since the switch)/eps) anyway, which is what the paper neglects.

    Returns (w, estimate): ``estimate`` = |w(T) - w(1.5 T)|, the change when the
    relaxation is lengthened by half (an estimate of the distance to M_+ that
    includes that exponentially small ambiguity).
    """
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float)) + 0.0 * x1
    if eps <= 0:
        return v0 + gamma * x2, np.zeros_like(x2)
    Fp0, dFp0 = friction_branches(f0, fv, fc, convention)[:2]
    F0, dF0 = float(Fp0(0.0)), float(dFp0(0.0))

    def Fp(nu):
        return np.where(nu <= 0, Fp0(np.minimum(nu, 0.0)), F0 + dF0 * nu)

    def dFp(nu):
        return np.where(nu <= 0, dFp0(np.minimum(nu, 0.0)), dF0)

    g1 = 1.0 + gamma
    m = x1.size

    def w2(a, b):
        F = Fp(b - v0)
        return v0 + gamma * b + eps * gamma * F + eps ** 2 * gamma * dFp(b - v0) * (a + (1 - gamma) * F)

    def rhs(t, z):
        a, b, w = z.reshape(3, -1)
        return np.concatenate([b, -a - Fp(g1 * b - w), (-w + v0 + gamma * b - eps * gamma * a) / eps])

    # Fixed DOP853 steps (first_step = max_step, loose tolerances so every step is
    # accepted): the map x_s -> x(T) is then a smooth function of x_s, which
    # Newton needs; adaptive steps make it jitter at the 1e-10 level.
    h_fix = min(eps / 8, 0.0125)

    def forward(xs1, xs2, T):
        z0 = np.concatenate([xs1, xs2, w2(xs1, xs2)])
        sol = solve_ivp(rhs, (0.0, T), z0, method="DOP853", rtol=1e-3, atol=1e3,
                        first_step=h_fix, max_step=h_fix)
        if not sol.success:
            raise RuntimeError(f"slow-manifold relaxation failed: {sol.message}")
        return sol.y[:, -1].reshape(3, m)

    def solve(T):
        # backward slow flow on the expansion: the Newton start
        back = lambda t, z: -np.concatenate([z[m:], -z[:m] - Fp(g1 * z[m:] - w2(z[:m], z[m:]))])
        # fixed steps here too: an adaptive step size depends on an error norm over
        # the whole batch, a BLAS dot product whose last bit depends on where the
        # array sits in memory; the Newton start (and so, at its tolerance, the
        # result) would then differ between two runs of the same build
        s = solve_ivp(back, (0.0, T), np.concatenate([x1, x2]), method="DOP853",
                      rtol=1e-3, atol=1e3, first_step=h_fix, max_step=h_fix).y[:, -1]
        a, b = s[:m].copy(), s[m:].copy()
        d = 1e-6
        for _ in range(max_iter):
            z = forward(a, b, T)
            r1, r2 = z[0] - x1, z[1] - x2
            if np.max(np.abs(np.concatenate([r1, r2]))) <= newton_tol * max(1.0, np.max(np.abs(x1))):
                return z[2]
            za = forward(a + d, b, T)
            zb = forward(a, b + d, T)
            J11, J21 = (za[0] - z[0]) / d, (za[1] - z[1]) / d
            J12, J22 = (zb[0] - z[0]) / d, (zb[1] - z[1]) / d
            det = J11 * J22 - J12 * J21
            a = a - (J22 * r1 - J12 * r2) / det
            b = b - (-J21 * r1 + J11 * r2) / det
        z = forward(a, b, T)
        if np.max(np.abs(z[:2] - np.stack([x1, x2]))) > 1e-11:
            raise RuntimeError("slow-manifold Newton iteration did not converge")
        return z[2]

    T = min(relax * eps, t_max)
    w = solve(T)
    w_long = solve(1.5 * T)
    return w, np.abs(w - w_long)


# --------------------------------------------------------------------------- fast forms
def plus_field_reduced(v, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """(f, df/dx, df/dv) of eq:dfo1 in region + (friction branch F_plus, extended
    smoothly to x2 > v): for shooting and the variational equations."""
    Fp, dFp = friction_branches(f0, fv, fc, convention)[:2]

    def f(x):
        return np.array([x[1], -x[0] - Fp(x[1] - v)])

    def dfdx(x):
        return np.array([[0.0, 1.0], [-1.0, -dFp(x[1] - v)]])

    def dfdv(x):
        return np.array([0.0, dFp(x[1] - v)])

    return f, dfdx, dfdv


def reduced_jacobian(v, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """``jacobian(mode, x)`` of the reduced system's fields, for
    :func:`filippov.continuation.monodromy`. The Filippov sliding field,
    written with the region fields as functions of x, is (x2, 0) identically:
    a = x1 + F_minus, b = x1 + F_plus and its second component
    (a f_+2 - b f_-2)/(a - b) cancels."""
    from ..system import MINUS, PLUS

    _, dFp, _, dFm = friction_branches(f0, fv, fc, convention)

    def jac(mode, x):
        if mode == PLUS:
            return np.array([[0.0, 1.0], [-1.0, -dFp(x[1] - v)]])
        if mode == MINUS:
            return np.array([[0.0, 1.0], [-1.0, -dFm(x[1] - v)]])
        return np.array([[0.0, 1.0], [0.0, 0.0]])

    return jac


def full_system(eps, v0, gamma=2.0, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck",
                sliding=True):
    """The slow-fast system eq:dfo-sf as a PiecewiseSystem, identical to
    ``model(...).full()`` but with the fields written out: the solver calls them
    thousands of times per return, and the generic stacking costs 5x more."""
    from ..system import PiecewiseSystem

    check_parameters(eps, v0, gamma, f0, fv, fc, convention)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    Fp, _, Fm, _ = friction_branches(f0, fv, fc, convention)
    g1, ie, eg = 1.0 + gamma, 1.0 / eps, eps * gamma

    def field(F):
        def fn(z):
            x1, x2, w = z[0], z[1], z[2]
            return np.array([x2, -x1 - F(g1 * x2 - w), (v0 + gamma * x2 - w - eg * x1) * ie])
        return fn

    grad = np.array([0.0, -g1, 1.0])
    return PiecewiseSystem(
        names=("x1", "x2", "w"), field_minus=field(Fm), field_plus=field(Fp),
        switch=lambda z: z[2] - g1 * z[1],
        switch_grad=lambda z: grad.copy() if np.ndim(z) == 1 else
        np.broadcast_to(grad[:, None], np.shape(z)).copy(),
        sliding=sliding, units={"t": "1", "x1": "1", "x2": "1", "w": "1"},
        description=f"dry_friction: slow-fast system, eps={eps!r}, v0={v0!r}")


def _barycentric(nodes, weights, values, x):
    """The barycentric interpolant at the points ``x``, its sums taken with
    math.fsum: exactly rounded, so the result does not depend on how a SIMD
    reduction splits the sum (which varies with memory alignment, i.e. between
    two runs of the same build)."""
    import math

    out = np.empty(np.size(x))
    for i, xi in enumerate(np.atleast_1d(x)):
        hit = np.flatnonzero(nodes == xi)
        if hit.size:
            out[i] = values[hit[0]]
            continue
        t = weights / (xi - nodes)
        out[i] = math.fsum(t * values) / math.fsum(t)
    return out


def slow_manifold_plus_on_L(x1_lo, x1_hi, eps, v0, n=33, **kwargs):
    """w on M_+ along the half-line x2 = 0, x1 in [x1_lo, x1_hi], as a callable.

    :func:`slow_manifold_plus` costs about a second per call whatever the number
    of points (the relaxation runs all points in one batch with fixed steps),
    so a root search that asks for one or three points at a time pays that
    second every time. Here it is called once, on ``n`` Chebyshev points of the
    interval; w_+(x1, 0) is analytic in x1, so barycentric interpolation is
    accurate to the relaxation's own Newton tolerance (about 1e-13; see
    tests/test_dry_friction.py). Returns ``start(x1) -> (w, estimate)``, the
    estimate (distance to M_+, see :func:`slow_manifold_plus`) interpolated
    the same way. Points outside the interval raise ValueError.
    """
    k = np.arange(n)
    nodes = 0.5 * (x1_lo + x1_hi) + 0.5 * (x1_hi - x1_lo) * np.cos(np.pi * (k + 0.5) / n)
    w, est = slow_manifold_plus(nodes, 0.0, eps, v0, **kwargs)
    # barycentric weights of Chebyshev points of the first kind, in closed form
    weights = (-1.0) ** k * np.sin(np.pi * (2 * k + 1) / (2 * n))
    iw, ie = (lambda x: _barycentric(nodes, weights, w, x)), \
        (lambda x: _barycentric(nodes, weights, est, x))

    def start(x1):
        x1 = np.atleast_1d(np.asarray(x1, dtype=float))
        if np.any((x1 < x1_lo) | (x1 > x1_hi)):
            raise ValueError(f"x1 outside [{x1_lo}, {x1_hi}]: {x1[(x1 < x1_lo) | (x1 > x1_hi)]}")
        return np.asarray(iw(x1), dtype=float), np.abs(np.asarray(ie(x1), dtype=float))
    start.interval = (x1_lo, x1_hi)
    return start


# --------------------------------------------------------------------------- compiled
def compiled(eps, v0, gamma=2.0, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck", *,
             sliding=True):
    """The slow-fast system eq:dfo-sf, compiled for the compiled engine (:mod:`filippov.abi`), with
    the section L of fig:dfo-retmap (x2 = 0 crossed downward, x1 > 0). No region
    has a closed-form flow, so every mode is integrated (DOP853) inside the
    kernel. The same formulas as :func:`full_system`, operation for operation."""
    check_parameters(eps, v0, gamma, f0, fv, fc, convention)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    from ..abi import CompiledModel, no_flow

    s0, sc = (-f0, -fc) if convention == "stribeck" else (f0, fc)
    return CompiledModel(
        name="dry_friction", names=("x1", "x2", "w"),
        params=np.array([eps, v0, gamma, s0, sc, fv], dtype=float),
        flow_plus=no_flow, flow_minus=no_flow, **_compiled_pieces(),
        section_direction=-1, sample_step=np.inf, sliding=sliding, exact=False,
        parameters={"eps": eps, "v0": v0, "gamma": gamma, "f0": f0, "fv": fv, "fc": fc})


_PIECES = {}


def _compiled_pieces() -> dict:
    """numba versions of the pieces; p = (eps, v0, gamma, s0, sc, fv) with the
    friction branches F_+(nu) = -s0 - sc (1 - e^nu) + fv nu (region +) and
    F_-(nu) = s0 + sc (1 - e^-nu) + fv nu (region -), nu = (1 + gamma) x2 - w."""
    if _PIECES:
        return _PIECES
    from numba import njit

    from ..abi import FIELD_SIG, SCALAR_SIG, WHERE_SIG

    @njit(FIELD_SIG, cache=True)
    def field_plus(z, p, out):
        eps, v0, gamma, s0, sc, fv = p[0], p[1], p[2], p[3], p[4], p[5]
        x1, x2, w = z[0], z[1], z[2]
        nu = (1.0 + gamma) * x2 - w
        out[0] = x2
        out[1] = -x1 - (-s0 - sc * (1.0 - np.exp(nu)) + fv * nu)
        out[2] = (v0 + gamma * x2 - w - (eps * gamma) * x1) * (1.0 / eps)

    @njit(FIELD_SIG, cache=True)
    def field_minus(z, p, out):
        eps, v0, gamma, s0, sc, fv = p[0], p[1], p[2], p[3], p[4], p[5]
        x1, x2, w = z[0], z[1], z[2]
        nu = (1.0 + gamma) * x2 - w
        out[0] = x2
        out[1] = -x1 - (s0 + sc * (1.0 - np.exp(-nu)) + fv * nu)
        out[2] = (v0 + gamma * x2 - w - (eps * gamma) * x1) * (1.0 / eps)

    @njit(SCALAR_SIG, cache=True)
    def h(z, p):
        return z[2] - (1.0 + p[2]) * z[1]

    @njit(FIELD_SIG, cache=True)
    def grad_h(z, p, out):
        out[0] = 0.0
        out[1] = -(1.0 + p[2])
        out[2] = 1.0

    @njit(SCALAR_SIG, cache=True)
    def section(z, p):
        return z[1]

    @njit(WHERE_SIG, cache=True)
    def section_where(z, p):
        return z[0] > 0

    _PIECES.update(field_plus=field_plus, field_minus=field_minus, h=h, grad_h=grad_h,
                   section=section, section_where=section_where)
    return _PIECES
