"""Two planar Filippov systems for Fig. 1, switching on H_s = {x2 = 0}.

* "crossing": both fields point upward through H_s (f_- = (1, 1 + x1/2),
  f_+ = (1, 1/2)); a trajectory crosses.
* "sliding": the fields point toward H_s from both sides (f_- = (1, 1),
  f_+ = (1, -1 - x1^2/4)); a trajectory reaching H_s slides along it with the
  Filippov field, which is (1, 0) here.

Every field has a closed-form flow, so the sketches are exact.
"""
from __future__ import annotations

import numpy as np

from ..system import MINUS, PLUS, SLIDING, PiecewiseSystem

#: the model's name in the registry (filippov.models.get) and in a scene's ``model:`` key
NAME = "planar_sketch"


def _h(z):
    return z[1]


def _grad(z):
    return np.stack([np.zeros_like(z[0]), np.ones_like(z[1])])


def _flow(rate_y):
    """Flow of x1' = 1, x2' = rate_y(x1) with rate_y a polynomial: x2 integrates it."""

    def flow(z0, tau):
        tau = np.asarray(tau, dtype=float)
        x1 = z0[0] + tau
        return np.stack([x1, z0[1] + rate_y(z0[0], tau)])

    return flow


def system(case: str) -> PiecewiseSystem:
    if case == "crossing":
        fm = lambda z: np.stack([np.ones_like(z[0]), 1 + 0.5 * z[0]])
        fp = lambda z: np.stack([np.ones_like(z[0]), 0.5 * np.ones_like(z[0])])
        flows = {MINUS: _flow(lambda a, t: t + 0.5 * (a * t + 0.5 * t**2)),
                 PLUS: _flow(lambda a, t: 0.5 * t)}
    elif case == "sliding":
        fm = lambda z: np.stack([np.ones_like(z[0]), np.ones_like(z[0])])
        fp = lambda z: np.stack([np.ones_like(z[0]), -1 - 0.25 * z[0] ** 2])
        flows = {MINUS: _flow(lambda a, t: t),
                 PLUS: _flow(lambda a, t: -t - ((a + t) ** 3 - a**3) / 12),
                 SLIDING: lambda z0, tau: np.stack([z0[0] + np.asarray(tau, float),
                                                   z0[1] + 0.0 * np.asarray(tau, float)])}
    else:
        raise ValueError(f"unknown planar sketch case {case!r}: expected 'crossing' or 'sliding'")
    return PiecewiseSystem(names=("x1", "x2"), field_minus=fm, field_plus=fp, switch=_h,
                           switch_grad=_grad, flows=flows, sliding=True, sample_step=0.05,
                           units={"x1": "1", "x2": "1", "t": "1"},
                           description=f"planar sketch system ({case})")
