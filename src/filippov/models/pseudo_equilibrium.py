"""The pseudo-equilibrium example of Sec. 2 (Eqs. (7), (8)).

    x' = -sign(theta x + (1 - theta) y),    eps y' = x - y.

Region + (h >= 0) has x' = -1, region - has x' = +1; the fast variable relaxes to
x. Every region has a closed-form flow; so has the sliding flow on H_s for
0 < theta < 1 (x' = -x / (eps theta), a fact derived from Eq. (2)). Written once
(:data:`DEFINITION`); both engines' pieces are generated from it.
"""
from __future__ import annotations

import dataclasses

import numpy as np
import sympy as sp

from ..model import TRANSIENT, SlowFastModel
from ..scale import UNIT
from ..symbolic import SymbolicSlowFast
from ..system import SLIDING

#: the model's name in the registry (filippov.models.get) and in a scene's ``model:`` key
NAME = "pseudo_equilibrium"


def _check(eps: float, theta: float) -> None:
    if not np.isfinite(theta) or theta >= 1:
        raise ValueError(f"theta must be finite and < 1 (the fast equation degenerates "
                         f"at theta = 1), got {theta!r}")
    if not np.isfinite(eps) or eps < 0:
        raise ValueError(f"eps must be finite and >= 0, got {eps!r}")


# ----------------------------------------------------------------- the definition
x, y, eps, theta, t = sp.symbols("x y eps theta t")


def _slope(c):
    """Exact flow of x' = c, eps y' = x - y: y relaxes to x - c eps like exp(-t/eps)."""
    return [x + c * t, x + c * t - c * eps + (y - x + c * eps) * sp.exp(-t / eps)]


#: the example written once; sliding on H_s has x' = -x / (eps theta) (from Eq. (2),
#: for 0 < theta < 1) and y = -theta x / (1 - theta)
DEFINITION = SymbolicSlowFast(
    (x,), (y,), f_minus=(1,), f_plus=(-1,), g_minus=(x - y,), g_plus=(x - y,),
    switch=theta * x + (1 - theta) * y, eps=eps, params={eps: 0.01, theta: 0.5}, time=t,
    flows={"full": {"plus": _slope(-1), "minus": _slope(1),
                    "sliding": [x * sp.exp(-t / (eps * theta)),
                                -theta / (1 - theta) * x * sp.exp(-t / (eps * theta))]},
           "reduced": {"plus": [x - t], "minus": [x + t], "sliding": [x]}},
    name="pseudo_equilibrium")


def model(eps: float, theta: float) -> SlowFastModel:
    """The reference driver's model (slow-fast and reduced), from :data:`DEFINITION`."""
    _check(eps, theta)
    m = DEFINITION.model(
        {"eps": eps, "theta": theta},
        sample_step_full=eps / 4 if eps > 0 else np.inf, sample_step_reduced=0.25,
        # y - x relaxes like exp(-t/eps) after a mode entry; then x, y move at speed 1
        slow_sample_step_full=0.25, transient_time_full=TRANSIENT * eps,
        units={"t": "1", "x": "1", "y": "1"})
    if "full" in m.exact_flows and not 0 < theta < 1:   # sliding's flow needs 0 < theta < 1
        full = {k: v for k, v in m.exact_flows["full"].items() if k != SLIDING}
        m = dataclasses.replace(m, exact_flows=dict(m.exact_flows, full=full))
    return m


_FULL: dict = {}


def system(eps: float, theta: float):
    """The slow-fast system z = (x, y) with its exact flows, for either engine (no
    section; sliding is integrated on the compiled engine)."""
    _check(eps, theta)
    if eps <= 0:
        raise ValueError("eps must be > 0 for the slow-fast system")
    if not _FULL:
        _FULL[True] = DEFINITION.full()
    return _FULL[True].with_params(eps=eps, theta=theta).with_options(
        sample_step=eps / 4, slow_sample_step=0.25, transient_time=TRANSIENT * eps,
        scale=UNIT).system()


def compiled(eps: float, theta: float, *, section_x: float = 10.0):
    """:func:`system` on the compiled engine with the section ``x = section_x`` crossed
    with x decreasing (the default is never reached near the origin, so a run counts
    switches until ``t_max``)."""
    return system(eps, theta).compiled(x - float(section_x), direction=-1)
