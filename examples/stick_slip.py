r"""
Stick-slip
==========

A block on a spring dragged by a belt:
:math:`\ddot x + x = -F \operatorname{sign}(\dot x - v) + d\, (\dot x - v)`.

Coulomb friction :math:`F`, weakening with the slip speed (slope :math:`d > 0`; with
:math:`d = 0` the slip circle through the release point only grazes :math:`\dot x = v`: no
stick phase, a continuum of orbits). Sticking (:math:`\dot x = v`) is sliding on
:math:`H = v - \dot x = 0`: :math:`a = x + F > 0 > b = x - F`, so the block sticks for
:math:`|x| < F` and is released at :math:`x = F`. Closed form: slipping below belt speed,
:math:`u = x - x^*` (:math:`x^* = F - d v`) solves :math:`\ddot u - d \dot u + u = 0` from
:math:`u = d v`, :math:`\dot u = v`:

.. math::

   u = e^{dt/2} (d v \cos \omega t + C \sin \omega t), \qquad
   \dot x = e^{dt/2} (v \cos \omega t + K \sin \omega t),

   \omega = \sqrt{1 - d^2/4}, \qquad C = v (1 - d^2/2)/\omega, \qquad
   K = d C/2 - \omega d v.

The slip ends at the first root :math:`T_s > 0` of :math:`\dot x(T_s) = v` (the release at
:math:`t = 0` is tangential), at :math:`x_r = x^* + u(T_s)`; the stick lasts
:math:`(F - x_r)/v`, the period is :math:`T_s + (F - x_r)/v`. The orbit crosses
:math:`\dot x = 0` downwards at :math:`x^* + u(t_q)`, :math:`\tan(\omega t_q) = -v/K`: the
fixed point of the return map to that section, which is flat there (nearby starts all
stick and are released at :math:`x = F`): Floquet multipliers 1 and 0.

Run: python examples/stick_slip.py   (filippov installed, or PYTHONPATH=src)
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy.optimize import brentq

from filippov import (FilippovSystem, Section, first_returns, fixed_points,
                      floquet_multipliers, simulate)

F, V, D = 1.0, 0.5, 0.2
# H = v - x' < 0 (faster than the belt): friction -F; H >= 0 (slower): +F
SYSTEM = FilippovSystem(
    ("x", "x'"), field_minus=lambda z, p: np.array([z[1], -z[0] - F + D * (z[1] - V)]),
    field_plus=lambda z, p: np.array([z[1], -z[0] + F + D * (z[1] - V)]),
    switch=lambda z, p: V - z[1], switch_grad=lambda z, p: np.array([0.0, -1.0]))
SECTION = Section("x' = 0 downwards", lambda z: z[1], direction=-1)


def closed_form(arcs=False):
    w, xs = np.sqrt(1 - D * D / 4), F - D * V
    C = V * (1 - D * D / 2) / w
    K = D * C / 2 - w * D * V
    u = lambda t: np.exp(D * t / 2) * (D * V * np.cos(w * t) + C * np.sin(w * t))
    du = lambda t: np.exp(D * t / 2) * (V * np.cos(w * t) + K * np.sin(w * t))
    Ts = brentq(lambda t: du(t) - V, np.pi / w, 2 * np.pi / w, xtol=1e-15)
    stick = (F - xs - u(Ts)) / V
    if arcs:   # the orbit in the plane: the slip from the release at (F, v), then the stick
        s = np.linspace(0.0, Ts, 300)
        return np.r_[xs + u(s), F], np.r_[du(s), V]
    return {"fixed_point": xs + u((np.arctan2(-V, K) % np.pi) / w), "period": Ts + stick,
            "stick_time": stick, "multipliers": np.array([1.0, 0.0])}


def computed():
    P = lambda x: first_returns(SYSTEM, np.column_stack([x, np.zeros_like(x)]), SECTION, 50.0,
                                method="integrate")
    grid = F + np.linspace(0.2, 1.6, 15)  # starts on the section, around the orbit
    xp = fixed_points(grid, P(grid).state[:, 0], refine=lambda x: P([x]).state[0, 0])
    ret = P(xp)
    orbit = simulate(SYSTEM, [xp[0], 0.0], ret.time[0], method="integrate")
    return {"fixed_point": xp, "period": ret.time, "stick_time": ret.sliding_time,
            "multipliers": floquet_multipliers(SYSTEM, orbit), "orbit": orbit}


def main():
    got, want = computed(), closed_form()
    print(f"{'':15s} {'computed':>20s} {'closed form':>20s} {'|difference|':>12s}")
    for key in want:
        for i, (g, w) in enumerate(zip(np.ravel(got[key]), np.ravel(want[key]))):
            name = key + (f"[{i}]" if np.size(want[key]) > 1 else "")
            print(f"{name:15s} {g:20.15g} {w:20.15g} {abs(g - w):12.1e}")
    orbit = got["orbit"]   # one period from the fixed point on x' = 0
    z = orbit.sample(np.linspace(0.0, orbit.t, 80))[1]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(*closed_form(arcs=True), "-", color="0.6", lw=3, label="closed form")
    ax.plot(z[0], z[1], ".", color="C0", label="simulate (DOP853)")
    ax.plot(got["fixed_point"][0], 0.0, "o", mfc="none", color="C3", ms=9,
            label="fixed point of the return map")
    ax.axhline(V, color="k", lw=0.5, ls="--")   # the belt speed: sticking
    ax.set(xlabel="position $x$", ylabel="velocity $\\dot x$",
           title=f"stick-slip: slip, then stick at $\\dot x = v = {V}$")
    ax.legend(loc="center")
    if "agg" not in plt.get_backend().lower():   # a window when run with a display
        plt.show()


if __name__ == "__main__":
    main()
