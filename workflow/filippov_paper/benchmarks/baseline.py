"""The baseline a user would write: scipy's solve_ivp with events, one region at a time.

Integrate the current mode with terminal events on ``h`` and on the section;
at each hit of ``h = 0`` decide from the two normal speeds (eq:atSl) whether to
cross or to slide; integrate sliding with the Filippov field and terminal
events where a sliding condition fails. Nothing here is tuned for speed beyond
what the scipy documentation suggests.
"""
from __future__ import annotations

import time

import numpy as np
from scipy.integrate import solve_ivp

from filippov.system import MINUS, PLUS, SLIDING, PiecewiseSystem


class TimeCapExceeded(RuntimeError):
    """A configuration ran longer than the benchmark allows."""


def first_return(system: PiecewiseSystem, z0, section, where, direction: int, t_max: float,
                 method: str, rtol: float, atol: float, max_events: int = 200):
    """First return of ``z0`` to ``section(z) = 0`` (with ``where(z)``).

    Returns ``(state, time, first_switch_time)``; the last is NaN when the
    trajectory never changes mode.
    """
    z, t = np.asarray(z0, dtype=float), 0.0
    H = float(system.switch(z))
    mode = PLUS if H >= 0 else MINUS
    t_switch = np.nan
    for _ in range(max_events):
        sec = lambda _t, zz: section(zz) if where(zz) else 1.0
        sec.terminal, sec.direction = True, direction
        if mode == SLIDING:
            exit_a = lambda _t, zz: system.normal_speeds(zz)[0]
            exit_b = lambda _t, zz: system.normal_speeds(zz)[1]
            exit_a.terminal = exit_b.terminal = True
            exit_a.direction, exit_b.direction = -1, 1
            events = [sec, exit_a, exit_b]
        else:
            switch = lambda _t, zz: system.switch(zz)
            switch.terminal = True
            switch.direction = -1 if mode == PLUS else 1
            events = [sec, switch]
        sol = solve_ivp(lambda _t, zz, m=mode: system.field(m, zz), (t, t_max), z,
                        method=method, rtol=rtol, atol=atol, events=events)
        if sol.status != 1:
            raise RuntimeError(f"solve_ivp {method}: no return from {np.asarray(z0).tolist()} "
                               f"({sol.message})")
        hit = [i for i, te in enumerate(sol.t_events) if te.size]
        i = min(hit, key=lambda j: sol.t_events[j][0])
        t_new, z = sol.t_events[i][0], sol.y_events[i][0]
        if i == 0 and t_new > 1e-9:  # the section, not the start point on it
            return z, t_new, t_switch
        if i == 0:
            z = z + 1e-12 * system.field(mode, z)  # step off the start point
            continue
        t = t_new
        a, b = system.normal_speeds(z)
        if mode == SLIDING:
            mode = MINUS if i == 1 else PLUS
        elif mode == PLUS:
            mode = SLIDING if (a > 0 and system.sliding) else MINUS
        else:
            mode = SLIDING if (b < 0 and system.sliding) else PLUS
        if np.isnan(t_switch):
            t_switch = t
    raise RuntimeError(f"solve_ivp {method}: more than {max_events} events from "
                       f"{np.asarray(z0).tolist()}")


def first_returns(system, starts, section, where, direction, t_max, method, rtol, atol,
                  time_cap: float = np.inf):
    """:func:`first_return` for each start point; stops with
    :class:`TimeCapExceeded` once ``time_cap`` seconds have passed."""
    t0 = time.perf_counter()
    states, times, switches = [], [], []
    for z0 in starts:
        z, t, ts = first_return(system, z0, section, where, direction, t_max, method, rtol, atol)
        states.append(z), times.append(t), switches.append(ts)
        if time.perf_counter() - t0 > time_cap:
            raise TimeCapExceeded(f"over the {time_cap:g} s cap")
    return np.array(states), np.array(times), np.array(switches)
