"""The symmetric chatter orbit of Eqs. (7)/(8) for theta < 0 (Sec. 2).

Let eps T be the time spent on each side and E = exp(-T). Following the flow of
f_+ from the switch point (x_s, y_s) for time eps T must land on (-x_s, -y_s),
which gives (derived here, checked against the solver in the tests)

    x_s = eps T / 2,   y_s = eps (T/2 - tanh(T/2)),   theta = 1 - (T/2) / tanh(T/2),

and period 2 eps T. The paper's y_switch = eps theta (E - 1)/(E + 1) agrees;
its printed theta(T) equals -theta tanh(T/2) instead (see the report).
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq


def theta_of_T(T):
    u = 0.5 * np.asarray(T, dtype=float)
    return 1.0 - u / np.tanh(u)


def theta_of_T_as_printed(T):
    """The paper's printed parametrisation, kept to document the slip."""
    T = np.asarray(T, dtype=float)
    E = np.exp(-T)
    return 0.5 * (T + 2 * E + E * T - 2) / (1 + E)


def half_time(theta: float) -> float:
    """T(theta): the root of theta_of_T(T) = theta, for theta < 0."""
    if not (np.isfinite(theta) and theta < 0):
        raise ValueError(f"the chatter orbit exists for theta < 0, got theta={theta!r}")
    # u coth u - 1 = -theta; u coth u >= max(1, u) so u <= 1 - theta brackets it
    f = lambda T: theta_of_T(T) - theta
    return brentq(f, 1e-8, 2.0 * (2.0 - theta), xtol=1e-300, rtol=4 * np.finfo(float).eps)


def orbit(eps: float, theta: float) -> dict:
    """Period and switch point (from f_- to f_+) of the chatter orbit."""
    T = half_time(theta)
    x_s = 0.5 * eps * T
    y_s = eps * (0.5 * T - np.tanh(0.5 * T))
    y_s_printed = eps * theta * np.expm1(-T) / (np.exp(-T) + 1)
    return {"T": T, "period": 2 * eps * T, "x_switch": x_s, "y_switch": y_s,
            "y_switch_printed": y_s_printed}
