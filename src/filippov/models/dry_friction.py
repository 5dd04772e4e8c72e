"""The autonomous dry-friction oscillator of Appendix C (Eqs. (C.1), (C.3)), M = K = 1.

Slow state x = (x1, x2) (block position and velocity), fast state y = (w,) with
w = gamma x2 + v (v: belt speed)::

    x1' = x2
    x2' = -x1 - F_c((1 + gamma) x2 - w)
    eps w' = -w + v0 + gamma x2 - eps gamma x1
    h = w - (1 + gamma) x2 = v - x2          (region + : h >= 0, block slower than belt)

The reduced system (eps = 0) has w = y0(x) = v0 + gamma x2, so h0 = v0 - x2 and
the slow equations become Eq. (C.1) with belt speed v = v0.

Friction law. The caption of Fig. C.2 prints
``F_c(nu) = f0 sgn(nu) + fv nu + fc (1 - exp(-|nu|)) sgn(nu)`` with f0 = -2,
fv = 0.3, fc = 2.5. Read literally with Eq. (C.1) (force -F_c on the block) this
gives F_c(0+) = -2: friction would push the block along its relative velocity,
sticking on x2 = v is repelling (Eq. (9) fails) and the equilibrium never loses
stability. The convention adopted here ("stribeck") is the one of the paper's
commented-out friction curve: F_c acts against the relative velocity with a
static level ``|f0| = 2`` that decays to -f0 - fc = -0.5 and then grows with fv::

    F_c(nu) = sgn(nu) [-f0 - fc (1 - exp(-|nu|))] + fv nu.

It is the printed formula with the signs of f0 and fc flipped. The literal
reading is kept ("literal") so that the evidence can be recomputed; see
paper/notes/dry_friction.md.

Each region's friction is a smooth (analytic) branch defined for all nu,
``F_plus`` (nu <= 0) and ``F_minus`` (nu > 0), so the fields extend smoothly
across H_s, as the slow-manifold construction needs.

No region has a closed-form flow: every mode is integrated (DOP853). The model is
written once, in SymPy: the friction law (:data:`FRICTION`), the fields (:data:`SLOW`,
:data:`FAST`) and the second-order slow manifold (:data:`W2_PLUS`), as text kept in its
written order. :data:`DEFINITION` (canonical) gives the reference driver's and the
compiled engine's pieces and the Jacobians; the NumPy helpers here (friction branches,
the reduced region-+ field for shooting, the relaxation onto M_+) are printed from the
same pieces in written order (:func:`filippov.codegen.lambdify_written`), so they round
exactly as that text does in NumPy (tests/test_dry_friction.py).
"""
from __future__ import annotations

import dataclasses
import functools

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp

from .. import codegen
from ..model import SlowFastModel
from ..scale import UNIT
from ..symbolic import SymbolicSlowFast

CONVENTIONS = ("stribeck", "literal")

#: the model's name in the registry (filippov.models.get) and in a scene's ``model:`` key
NAME = "dry_friction"


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
    nu < 0 (region +) and nu > 0 (region -), each extended to all nu; printed from
    :data:`FRICTION` (the slopes differentiated from it)."""
    a, c = _coefficients(f0, fc, convention)
    return tuple((lambda nu, fn=fn: fn(nu, a, c, fv)) for mode in ("plus", "minus")
                 for fn in _BRANCHES[mode])


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


# ----------------------------------------------------------------- the definition
x1, x2, w, eps, v0, gamma, s0, sc, fv, nu = sp.symbols("x1 x2 w eps v0 gamma s0 sc fv nu")
_F, _dF = sp.symbols("F dF")     # a friction branch's value and slope (in W2_PLUS)


class _Branch(sp.Function):
    """A friction branch F(nu, s0, sc, fv) left as a call (the NumPy helpers are told
    which function it is, e.g. continued by its tangent); d/dnu is ``slope``."""
    nargs = 4
    slope = None

    def fdiff(self, argindex=1):
        if argindex != 1:
            raise sp.ArgumentIndexError(self, argindex)
        return self.slope(*self.args)


F_plus = type("F_plus", (_Branch,), {"slope": sp.Function("dF_plus")})
F_minus = type("F_minus", (_Branch,), {"slope": sp.Function("dF_minus")})
_NAMES = {**{str(s): s for s in (x1, x2, w, eps, v0, gamma, s0, sc, fv, nu, _F, _dF)},
          "F_plus": F_plus, "F_minus": F_minus, "exp": sp.exp}


def _written(text: str):
    """``text`` in SymPy, unevaluated: the NumPy helpers print it with the same operations
    in the same order, so they round as that text does in NumPy (``.doit()``: canonical)."""
    return codegen.parse_written(text, _NAMES)


#: ``F_c(nu) = sgn(nu) [s0 + sc (1 - e^{-|nu|})] + fv nu`` (coefficients: :func:`_coefficients`):
#: its smooth branches for nu < 0 (region +) and nu > 0 (region -), each extended to all nu
FRICTION = {"plus": _written("-s0 - sc * (1 - exp(nu)) + fv * nu"),
            "minus": _written("s0 + sc * (1 - exp(-nu)) + fv * nu")}
#: nu = (1 + gamma) x2 - w, the block's velocity relative to the belt
NU = _written("(1 + gamma) * x2 - w")
#: x2' of regions + and -, the friction branch at nu (x1' = x2)
SLOW = {"plus": _written("-x1 - F_plus(nu, s0, sc, fv)"),
        "minus": _written("-x1 - F_minus(nu, s0, sc, fv)")}
#: eps w', the same in both regions
FAST = _written("-w + v0 + gamma * x2 - eps * gamma * x1")
#: w on the second-order expansion of the slow manifold M_+, F and dF being F_plus and its
#: slope at x2 - v0: the solution of the invariance equation of u = w - v0 - gamma x2,
#: eps u' = -u + eps gamma F(x2 - v0 - u), to O(eps^2) (tests/test_dry_friction.py)
W2_PLUS = _written("v0 + gamma * x2 + eps * gamma * F + eps ** 2 * gamma * dF * (x1 + (1 - gamma) * F)")


def _defined(expr):
    """``expr`` canonical, nu = :data:`NU` and the branches replaced by :data:`FRICTION`."""
    law = {F_plus: FRICTION["plus"].doit(), F_minus: FRICTION["minus"].doit()}
    out = expr.doit().replace(lambda e: isinstance(e, _Branch),
                              lambda e: law[type(e)].subs(nu, e.args[0]))
    return out.subs(nu, NU.doit())


#: Eq. (C.3) written once; the friction law enters through (s0, sc) (see :func:`_coefficients`)
DEFINITION = SymbolicSlowFast(
    (x1, x2), (w,), f_minus=(x2, _defined(SLOW["minus"])), f_plus=(x2, _defined(SLOW["plus"])),
    g_minus=(_defined(FAST),), g_plus=(_defined(FAST),), switch=-NU.doit(), eps=eps,
    params={eps: 0.01, v0: 1.0, gamma: 2.0, s0: 2.0, sc: -2.5, fv: 0.3}, name="dry_friction")

#: the section L of Fig. C.2: x2 = 0 crossed downward with x1 > 0 (the caller's choice)
L = {"section": x2, "direction": -1, "where": x1 > 0}


def law_coefficients(f0=-2.0, fv=0.3, fc=2.5, convention="stribeck") -> tuple:
    """(s0, sc, fv): the parameters of :data:`FRICTION` for a friction law."""
    return (*_coefficients(f0, fc, convention), fv)


def _coefficients(f0, fc, convention) -> tuple:
    """(s0, sc) of the branches: F_c(nu) = sgn(nu) [s0 + sc (1 - e^{-|nu|})] + fv nu."""
    if convention not in CONVENTIONS:
        raise ValueError(f"convention must be one of {CONVENTIONS}, got {convention!r}")
    return (-f0, -fc) if convention == "stribeck" else (f0, fc)


# ------------------------------------------------------------------ NumPy helpers, printed
#: mode -> (F(nu, s0, sc, fv), dF(nu, s0, sc, fv)): the branches printed from FRICTION
_BRANCHES = {mode: (codegen.lambdify_written((nu, s0, sc, fv), law),
                    codegen.lambdify_written((nu, s0, sc, fv), sp.diff(law.doit(), nu)))
             for mode, law in FRICTION.items()}
_W2_PLUS = codegen.lambdify_written((x1, x2, _F, _dF, eps, v0, gamma), W2_PLUS)


def _tangent_branch(nu, s0_, sc_, fv_):
    """F_plus for nu <= 0, beyond its tangent at nu = 0 (the analytic branch runs away
    like exp(nu)): what the relaxation onto M_+ follows (see :func:`slow_manifold_plus`)."""
    F, dF = _BRANCHES["plus"]
    F0, dF0 = float(F(0.0, s0_, sc_, fv_)), float(dF(0.0, s0_, sc_, fv_))
    return np.where(nu <= 0, F(np.minimum(nu, 0.0), s0_, sc_, fv_), F0 + dF0 * nu)


def _tangent_slope(nu, s0_, sc_, fv_):
    dF = _BRANCHES["plus"][1]
    return np.where(nu <= 0, dF(np.minimum(nu, 0.0), s0_, sc_, fv_), float(dF(0.0, s0_, sc_, fv_)))


def _region_plus(F, dF) -> dict:
    """Region +'s pieces in NumPy with the branch (F, dF) of F_plus: ``slow(x1, x2, w,
    gamma, s0, sc, fv)`` (x2'), ``fast(x1, x2, w, eps, v0, gamma)`` (w') and ``w2(x1,
    x2, eps, v0, gamma, s0, sc, fv)`` (:data:`W2_PLUS`), printed from the definition."""
    slow = codegen.lambdify_written((x1, x2, w, gamma, s0, sc, fv),
                                    SLOW["plus"].xreplace({nu: NU}), {"F_plus": F})
    fast = codegen.lambdify_written((x1, x2, w, eps, v0, gamma),
                                    codegen.parse_written("g / eps", {"g": FAST, "eps": eps}))

    def w2(a, b, eps_, v0_, gamma_, *law):
        return _W2_PLUS(a, b, F(b - v0_, *law), dF(b - v0_, *law), eps_, v0_, gamma_)

    return {"slow": slow, "fast": fast, "w2": w2}


#: region +'s pieces with the analytic branch F_plus, and with it continued by its tangent
REGION_PLUS = {"analytic": _region_plus(*_BRANCHES["plus"]),
               "tangent": _region_plus(_tangent_branch, _tangent_slope)}


@functools.lru_cache(maxsize=None)
def _quasi_static():
    """y0(x2, v0, gamma): w on the slow manifold at eps = 0, solved from the definition."""
    return codegen.lambdify_written((x2, v0, gamma), DEFINITION.quasi_static()[w])


@functools.lru_cache(maxsize=None)
def _reduced_plus():
    """(f, df/dx, df/dv) of the reduced region-+ field (x2, x2') in NumPy, functions of
    (x1, x2, v0, s0, sc, fv): w = y0(x), so nu simplifies to x2 - v0."""
    nu_reduced = sp.simplify(NU.doit().subs(DEFINITION.quasi_static()))
    f = [x2, SLOW["plus"].xreplace({nu: nu_reduced})]
    pieces = (f, [[sp.diff(fi.doit(), u) for u in (x1, x2)] for fi in f],
              [sp.diff(fi.doit(), v0) for fi in f])
    calls = {"F_plus": _BRANCHES["plus"][0], "dF_plus": _BRANCHES["plus"][1]}
    return tuple(codegen.lambdify_written((x1, x2, v0, s0, sc, fv), p, calls) for p in pieces)


def _values(eps, v0, gamma, f0, fv, fc, convention) -> dict:
    check_parameters(eps, v0, gamma, f0, fv, fc, convention)
    a, c = _coefficients(f0, fc, convention)
    return {"eps": eps, "v0": v0, "gamma": gamma, "s0": a, "sc": c, "fv": fv}


def model(eps: float, v0: float, gamma: float = 2.0, f0: float = -2.0, fv: float = 0.3,
          fc: float = 2.5, convention: str = "stribeck") -> SlowFastModel:
    """The reference driver's model (slow-fast and reduced), from :data:`DEFINITION`."""
    m = DEFINITION.model(_values(eps, v0, gamma, f0, fv, fc, convention),
                         units={"t": "1", "x1": "1", "x2": "1", "w": "1"})
    return dataclasses.replace(m, parameters={"eps": eps, "v0": v0, "gamma": gamma, "f0": f0,
                                              "fv": fv, "fc": fc, "convention": convention})


_FULL: dict = {}   # 'full' / 'reduced' -> the SymbolicSystem (derived once, then copied)


def system(eps, v0, gamma=2.0, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck", *,
           sliding=True):
    """The slow-fast system Eq. (C.3) for either engine (a
    :class:`~filippov.symbolic.GeneratedSystem`, no section). No region has a
    closed-form flow: every mode is integrated (DOP853)."""
    values = _values(eps, v0, gamma, f0, fv, fc, convention)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    if "full" not in _FULL:
        _FULL["full"] = DEFINITION.full()
    return _FULL["full"].with_params(**values).with_options(sliding=sliding,
                                                            scale=UNIT).system()


# --------------------------------------------------------------------------- slow manifold
def slow_manifold_plus(x1, x2, eps, v0, gamma=2.0, f0=-2.0, fv=0.3, fc=2.5,
                       convention="stribeck", relax=30.0, t_max=1.0, rtol=1e-12,
                       atol=1e-14, newton_tol=1e-13, max_iter=8):
    """w on the slow manifold M_+ of Eq. (C.3) above the points (x1, x2).

    M_+ attracts at rate 1/eps, so it is reached by relaxation: start at x_s
    with w on the second-order expansion :data:`W2_PLUS` of M_+, follow the region-+ field for a time T = min(relax * eps, t_max) and solve (Newton, all
    points at once) for x_s such that x(T) = (x1, x2). The deviation from M_+
    shrinks by exp(-T/eps) (T is capped: for eps = 0.1 a longer history would
    run through the sticking region, where the smooth region-+ field is fiction
    and unstable; there the estimate below is about 1e-9). Where that history reaches x2 > v0, the friction
    branch F_plus is continued by its tangent at nu = 0 (the analytic branch
    runs away like exp(nu)): M_+ is only defined up to terms of order
    exp(-(time since the switch)/eps) anyway, which is what the paper neglects.

    Returns (w, estimate): ``estimate`` = ``|w(T) - w(1.5 T)|``, the change when the
    relaxation is lengthened by half (an estimate of the distance to M_+ that
    includes that exponentially small ambiguity).
    """
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    x2 = np.atleast_1d(np.asarray(x2, dtype=float)) + 0.0 * x1
    if eps <= 0:
        return _quasi_static()(x2, v0, gamma), np.zeros_like(x2)   # M_+ is y0(x) at eps = 0
    flow = _PlusRelaxation(eps, v0, gamma, law_coefficients(f0, fv, fc, convention), x1.size)
    T = min(relax * eps, t_max)
    w = flow.solve(x1, x2, T, newton_tol, max_iter)
    w_long = flow.solve(x1, x2, 1.5 * T, newton_tol, max_iter)
    return w, np.abs(w - w_long)


class _PlusRelaxation:
    """The region-+ field of Eq. (C.3) for a batch of ``m`` points (states stacked as
    (x1, x2, w) blocks), F_plus continued by its tangent beyond nu = 0
    (:data:`REGION_PLUS`), the second-order expansion w2 of M_+, and the relaxation onto
    M_+ that :func:`slow_manifold_plus` solves for; ``law`` = (s0, sc, fv)."""

    def __init__(self, eps, v0, gamma, law, m: int):
        self.eps, self.v0, self.gamma, self.law, self.m = eps, v0, gamma, tuple(law), m
        self.pieces = REGION_PLUS["tangent"]
        # Fixed DOP853 steps (first_step = max_step, loose tolerances so every step is
        # accepted): the map x_s -> x(T) is then a smooth function of x_s, which
        # Newton needs; adaptive steps make it jitter at the 1e-10 level.
        self.h_fix = min(eps / 8, 0.0125)

    def w2(self, a, b):
        """w on the second-order expansion of M_+ above (a, b)."""
        return self.pieces["w2"](a, b, self.eps, self.v0, self.gamma, *self.law)

    def rhs(self, t, z):
        a, b, w = z.reshape(3, -1)
        return np.concatenate([b, self.pieces["slow"](a, b, w, self.gamma, *self.law),
                               self.pieces["fast"](a, b, w, self.eps, self.v0, self.gamma)])

    def back(self, t, z):
        """The slow flow on the expansion w2, backward in time ((x1, x2) blocks)."""
        a, b = z[:self.m], z[self.m:]
        return -np.concatenate([b, self.pieces["slow"](a, b, self.w2(a, b), self.gamma,
                                                       *self.law)])

    def forward(self, xs1, xs2, T):
        """The states at time T from (xs1, xs2) on the expansion: rows x1, x2, w."""
        z0 = np.concatenate([xs1, xs2, self.w2(xs1, xs2)])
        sol = solve_ivp(self.rhs, (0.0, T), z0, method="DOP853", rtol=1e-3, atol=1e3,
                        first_step=self.h_fix, max_step=self.h_fix)
        if not sol.success:
            raise RuntimeError(f"slow-manifold relaxation failed: {sol.message}")
        return sol.y[:, -1].reshape(3, self.m)

    def newton_start(self, x1, x2, T):
        """Where the backward slow flow on the expansion is at time T: the start of
        the Newton iteration for x_s."""
        m = self.m
        # fixed steps here too: an adaptive step size depends on an error norm over
        # the whole batch, a BLAS dot product whose last bit depends on where the
        # array sits in memory; the Newton start (and so, at its tolerance, the
        # result) would then differ between two runs of the same build
        s = solve_ivp(self.back, (0.0, T), np.concatenate([x1, x2]), method="DOP853",
                      rtol=1e-3, atol=1e3, first_step=self.h_fix, max_step=self.h_fix).y[:, -1]
        return s[:m].copy(), s[m:].copy()

    def solve(self, x1, x2, T, newton_tol, max_iter):
        """w at (x1, x2) after relaxing for T: Newton (all points at once, Jacobian by
        forward differences) for the start x_s with x(T) = (x1, x2)."""
        a, b = self.newton_start(x1, x2, T)
        d = 1e-6
        for _ in range(max_iter):
            z = self.forward(a, b, T)
            r1, r2 = z[0] - x1, z[1] - x2
            if np.max(np.abs(np.concatenate([r1, r2]))) <= newton_tol * max(1.0, np.max(np.abs(x1))):
                return z[2]
            za = self.forward(a + d, b, T)
            zb = self.forward(a, b + d, T)
            J11, J21 = (za[0] - z[0]) / d, (za[1] - z[1]) / d
            J12, J22 = (zb[0] - z[0]) / d, (zb[1] - z[1]) / d
            det = J11 * J22 - J12 * J21
            a = a - (J22 * r1 - J12 * r2) / det
            b = b - (-J21 * r1 + J11 * r2) / det
        z = self.forward(a, b, T)
        if np.max(np.abs(z[:2] - np.stack([x1, x2]))) > 1e-11:
            raise RuntimeError("slow-manifold Newton iteration did not converge")
        return z[2]


# --------------------------------------------------------------------------- fast forms
def plus_field_reduced(v, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """(f, df/dx, df/dv) of Eq. (C.1) in region + (friction branch F_plus, extended
    smoothly to x2 > v): for shooting and the variational equations; printed from
    :data:`DEFINITION` (:func:`_reduced_plus`)."""
    law = law_coefficients(f0, fv, fc, convention)
    f, dfdx, dfdv = _reduced_plus()

    def field(x):
        return np.array(f(x[0], x[1], v, *law), dtype=float)

    def jac(x):
        return np.array(dfdx(x[0], x[1], v, *law), dtype=float)

    def dv(x):
        return np.array(dfdv(x[0], x[1], v, *law), dtype=float)

    return field, jac, dv


def reduced_jacobian(v, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck"):
    """``jacobian(mode, x)`` of the reduced system's fields (region +, region - and
    Filippov's sliding field), for :func:`filippov.continuation.monodromy`:
    differentiated from :data:`DEFINITION` (the sliding field, with the region fields
    as functions of x, is (x2, 0) up to rounding: a = x1 + F_minus, b = x1 + F_plus and
    its second component cancels)."""
    a, c = _coefficients(f0, fc, convention)
    if "reduced" not in _FULL:
        _FULL["reduced"] = DEFINITION.reduced()
    return _FULL["reduced"].with_params(v0=v, s0=a, sc=c, fv=fv).with_options(
        scale=UNIT).system().jacobian


def full_system(eps, v0, gamma=2.0, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck",
                sliding=True):
    """The slow-fast system Eq. (C.3) as the reference driver's PiecewiseSystem: the
    generated pieces of :func:`system` (compiled loops over the samples; the same code
    as the compiled engine's, so the two engines see the same field values)."""
    return system(eps, v0, gamma, f0, fv, fc, convention, sliding=sliding).python()


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
    """:func:`system` on the compiled engine with the section :data:`L` of
    Fig. C.2 (x2 = 0 crossed downward, x1 > 0)."""
    return system(eps, v0, gamma, f0, fv, fc, convention, sliding=sliding).compiled(**L)
