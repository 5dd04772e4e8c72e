"""
Stick-slip
==========

A block on a spring dragged by a belt: x'' + x = -F sign(x' - v) + d (x' - v).

Coulomb friction F, weakening with the slip speed (slope d > 0; with d = 0 the slip
circle through the release point only grazes x' = v: no stick phase, a continuum of
orbits). Sticking (x' = v) is sliding on H = v - x' = 0: a = x + F > 0 > b = x - F, so
the block sticks for ``|x| < F`` and is released at x = F. Closed form: slipping below
belt speed, u = x - x* (x* = F - d v) solves u'' - d u' + u = 0 from u = d v, u' = v:
u = e^{dt/2} (d v cos wt + C sin wt), x' = e^{dt/2} (v cos wt + K sin wt),
w = sqrt(1 - d^2/4), C = v (1 - d^2/2)/w, K = d C/2 - w d v. The slip ends at the
first root Ts > 0 of x'(Ts) = v (the release at t = 0 is tangential), at x_r =
x* + u(Ts); the stick lasts (F - x_r)/v, the period is Ts + (F - x_r)/v. The orbit crosses x' = 0 downwards at x* + u(tq), tan(w tq) = -v/K:
the fixed point of the return map to that section, which is flat there (nearby starts
all stick and are released at x = F): Floquet multipliers 1 and 0.

Run: python examples/stick_slip.py   (filippov installed, or PYTHONPATH=src)
"""
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


def closed_form():
    w, xs = np.sqrt(1 - D * D / 4), F - D * V
    C = V * (1 - D * D / 2) / w
    K = D * C / 2 - w * D * V
    u = lambda t: np.exp(D * t / 2) * (D * V * np.cos(w * t) + C * np.sin(w * t))
    du = lambda t: np.exp(D * t / 2) * (V * np.cos(w * t) + K * np.sin(w * t))
    Ts = brentq(lambda t: du(t) - V, np.pi / w, 2 * np.pi / w, xtol=1e-15)
    stick = (F - xs - u(Ts)) / V
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
            "multipliers": floquet_multipliers(SYSTEM, orbit)}


def main():
    got, want = computed(), closed_form()
    print(f"{'':15s} {'computed':>20s} {'closed form':>20s} {'|difference|':>12s}")
    for key in want:
        for i, (g, w) in enumerate(zip(np.ravel(got[key]), np.ravel(want[key]))):
            name = key + (f"[{i}]" if np.size(want[key]) > 1 else "")
            print(f"{name:15s} {g:20.15g} {w:20.15g} {abs(g - w):12.1e}")


if __name__ == "__main__":
    main()
