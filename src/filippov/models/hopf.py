"""The minimal grazing-sliding example (Eq. (11); Eqs. (15), (16)).

Slow state x = (x1, x2), fast state y::

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
  ``M_+ = {y = x1}`` is invariant.
* region -: x1 = x1(0) + t, x2 constant, and y' = -y/eps + p(x1(t)) with p a cubic,
  whose polynomial solution is the slow manifold ``M_-`` (exactly, not only to O(eps))::

      y_m-(x) = x1 + eps [mu x1 - omega x2 - r^2 x1 - 1] - eps^2 [mu - 3 x1^2 - x2^2]
                - 6 eps^3 x1 + 6 eps^4,

  and y = y_m-(x(t)) + (y(0) - y_m-(x(0))) exp(-t/eps).

Sliding has no closed form; it is integrated on H_s with the Filippov field.

The model is written once, as SymPy expressions (:data:`DEFINITION`, with these
flows): the reference driver's :class:`~filippov.model.SlowFastModel` (:func:`model`,
NumPy) and the compiled engine's pieces (:func:`system`, numba) are generated from
it, with the switching gradient and the Jacobians (:mod:`filippov.symbolic`).
Sections are the caller's: :data:`L1` is the one of Fig. 4.
"""
from __future__ import annotations

import numpy as np
import sympy as sp
from sympy.codegen.cfunctions import expm1

from .. import codegen
from ..model import TRANSIENT, SlowFastModel
from ..scale import UNIT
from ..symbolic import SymbolicSlowFast

#: the model's name in the registry (filippov.models.get) and in a scene's ``model:`` key
NAME = "hopf"


# ----------------------------------------------------------------- the definition
x1, x2, y, eps, theta, mu, omega, t = sp.symbols("x1 x2 y eps theta mu omega t")
_r2 = x1 ** 2 + x2 ** 2
_NAMES = {str(s): s for s in (x1, x2, y, eps, theta, mu, omega)}


def _written(text: str, **parts):
    """``text`` in SymPy kept in its written order (``parts``: named written pieces), so a
    NumPy helper printed from it rounds as that text does; ``.doit()``: canonical."""
    return codegen.parse_written(text, {**_NAMES, **parts})


_FIELD_X1 = _written("mu * x1 - omega * x2 - (x1 ** 2 + x2 ** 2) * x1")
#: f_+ = the Hopf normal form (x1', x2')
HOPF_FIELD = (_FIELD_X1.doit(), _written("omega * x1 + mu * x2 - (x1 ** 2 + x2 ** 2) * x2").doit())
#: g = eps y', the same in both regions: y relaxes onto x1 + eps x1'
FAST = _written("eps * f1 + x1 - y", f1=_FIELD_X1)
#: y on ``M_-``, the exact slow invariant manifold of region - (a cubic in x1), by powers of eps
_M_MINUS = _written("x1 + eps * (mu * x1 - omega * x2 - (x1 ** 2 + x2 ** 2) * x1 - 1)"
                    " - eps ** 2 * (mu - 3 * x1 ** 2 - x2 ** 2) - 6 * eps ** 3 * x1 + 6 * eps ** 4")
SLOW_MANIFOLD_MINUS = _M_MINUS.doit()
#: the switching function h; H_s = {h = 0}
SWITCH = theta * x1 + (1 - theta) * y + 1


def _through_order(written, k: int):
    """The terms of the written sum ``written`` of order <= k in eps, in written order."""
    return sp.Add(*(a for a in written.args if sp.degree(a.doit(), eps) <= k), evaluate=False)


def _ascending_in_eps(expr):
    """A polynomial in eps with its terms in ascending order (the order printed)."""
    terms = sp.Add.make_args(sp.expand(expr))
    return sp.Add(*sorted(terms, key=lambda a: sp.degree(a, eps)), evaluate=False)


#: Eq. (18): y on ``M_-`` to O(eps) (its terms of order 1 and eps)
SLOW_MANIFOLD_MINUS_FIRST_ORDER = _through_order(_M_MINUS, 1)
#: y on H_s, the switching surface solved for the fast variable
SWITCHING_SURFACE_Y = sp.solve(SWITCH, y)[0]
#: ``y_m+ - y_m-`` at x = (-1, 0) for mu = 1 (``M_+ = {y = x1}``; the grazing point of theta < 0)
GRAZING_GAP = _ascending_in_eps((x1 - SLOW_MANIFOLD_MINUS).subs({x1: -1, x2: 0, mu: 1}))


def _polar_flow_exprs():
    """The Hopf normal form's flow from (x1, x2) over t: r'= mu r - r^3, phi' = omega;
    r(t)^2 / r0^2 written with expm1 so that r0^2 = mu stays exact."""
    scale = sp.sqrt(mu / (mu + (mu - _r2) * expm1(-2 * mu * t)))
    c, s = sp.cos(omega * t), sp.sin(omega * t)
    return scale * (c * x1 - s * x2), scale * (s * x1 + c * x2)


def _definition() -> SymbolicSlowFast:
    p1, p2 = _polar_flow_exprs()
    decay = sp.exp(-t / eps)
    g = FAST.doit()
    flows = {
        # region +: y - x1 decays like exp(-t/eps) exactly
        "full": {"plus": [p1, p2, p1 + (y - x1) * decay],
                 # region -: x drifts along (1, 0); y relaxes onto M_- exactly
                 "minus": [x1 + t, x2, SLOW_MANIFOLD_MINUS.subs(x1, x1 + t)
                           + (y - SLOW_MANIFOLD_MINUS) * decay]},
        "reduced": {"plus": [p1, p2], "minus": [x1 + t, x2]}}
    return SymbolicSlowFast(
        (x1, x2), (y,), f_minus=(1, 0), f_plus=HOPF_FIELD, g_minus=(g,), g_plus=(g,),
        switch=SWITCH, eps=eps,
        params={eps: 0.01, theta: 0.0, mu: 1.0, omega: 8 * np.pi}, time=t, flows=flows,
        name="hopf")


#: the minimal grazing-sliding example, written once (Eq. (11); Eqs. (15), (16))
DEFINITION = _definition()

#: the section L1 of Fig. 4: x1 = 0 crossed downwards with x2 > 0 (the caller's choice;
#: the model carries no section)
L1 = {"section": x1, "direction": -1, "where": x2 > 0}


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


# closed-form helpers for the scenes and tests, printed from the same expressions
hopf_rhs = sp.lambdify((x1, x2, mu, omega), HOPF_FIELD, "numpy")
hopf_rhs.__doc__ = "(x1', x2') of the Hopf normal form (f_+), elementwise."
slow_manifold_minus = sp.lambdify((x1, x2, eps, mu, omega), SLOW_MANIFOLD_MINUS, "numpy")
slow_manifold_minus.__doc__ = "y on ``M_-``, the exact slow invariant manifold of region -."
slow_manifold_minus_first_order = codegen.lambdify_written(
    (x1, x2, eps, mu, omega), SLOW_MANIFOLD_MINUS_FIRST_ORDER)
slow_manifold_minus_first_order.__doc__ = "Eq. (18): y on ``M_-`` to O(eps)."
fast_field = codegen.lambdify_written((x1, x2, y, eps, mu, omega), FAST)
fast_field.__doc__ = "g(x, y) = eps y', elementwise (both regions)."
switching_surface_y = sp.lambdify((x1, theta), SWITCHING_SURFACE_Y, "numpy")
switching_surface_y.__doc__ = "y on H_s = {h = 0} above x1."
grazing_gap = codegen.lambdify_written((eps,), GRAZING_GAP)
grazing_gap.__doc__ = "y_m+ - y_m- at x = (-1, 0), mu = 1, from the exact cubic."
_polar = sp.lambdify((x1, x2, t, mu, omega), _polar_flow_exprs(), "numpy")


def polar_flow(x10, x20, tau, mu, omega):
    """Exact flow of the Hopf normal form from (x10, x20) over times tau."""
    return _polar(x10, x20, tau, mu, omega)


def _values(eps, theta, mu, omega) -> dict:
    check_parameters(eps, theta, mu, omega)
    return {"eps": float(eps), "theta": float(theta), "mu": float(mu), "omega": float(omega)}


def model(eps: float, theta: float, mu: float = 1.0, omega: float = 8 * np.pi) -> SlowFastModel:
    """The reference driver's model (slow-fast and reduced), from :data:`DEFINITION`."""
    values = _values(eps, theta, mu, omega)
    period = 2 * np.pi / abs(omega)
    return DEFINITION.model(
        values,
        sample_step_full=min(eps / 4, period / 64) if eps > 0 else np.inf,
        sample_step_reduced=period / 64,
        # y - x1 (region +) and y - M_-(x) (region -) decay like exp(-t/eps) exactly:
        # after 40 eps (exp(-40) = 4e-18) only the slow dynamics is left
        slow_sample_step_full=period / 64, transient_time_full=TRANSIENT * eps,
        units={"t": "1", "x1": "1", "x2": "1", "y": "1"})


_FULL: dict = {}   # exact -> the slow-fast SymbolicSystem (derived once, then copied)


def system(eps: float, theta: float, mu: float = 1.0, omega: float = 8 * np.pi, *,
           sliding: bool = True, exact: bool = True):
    """The slow-fast system z = (x1, x2, y) from :data:`DEFINITION`, for either engine
    (a :class:`~filippov.symbolic.GeneratedSystem`; no section: the caller gives one,
    e.g. ``system(...).compiled(**L1)``). ``exact=False``: regions + and - are
    integrated instead of following their exact flows."""
    values = _values(eps, theta, mu, omega)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    if exact not in _FULL:
        _FULL[exact] = DEFINITION.full(exact=exact)
    period = 2 * np.pi / abs(omega)
    return _FULL[exact].with_params(**values).with_options(
        sample_step=min(eps / 4, period / 64), slow_sample_step=period / 64,
        transient_time=TRANSIENT * eps, sliding=sliding, scale=UNIT).system()


def compiled(eps: float, theta: float, mu: float = 1.0, omega: float = 8 * np.pi, *,
             sliding: bool = True, exact: bool = True):
    """The compiled engine's model of :func:`system` with the section :data:`L1` of
    Fig. 4 (x1 = 0, x1 decreasing, x2 > 0)."""
    return system(eps, theta, mu, omega, sliding=sliding, exact=exact).compiled(**L1)
