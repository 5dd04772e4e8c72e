"""Attractors of a first-return map, iterated on the compiled engine.

An orbit diagram asks, for each parameter value, where the return map settles: the
map is iterated from a start (``transient`` returns discarded, ``keep`` returns
recorded, all in one compiled call: :func:`filippov.fastmap.compute_returns` with
``iterations``) and the recorded returns are classified:

* ``period``: the smallest p with |u_{k+p} - u_k| <= tol over all kept returns
  (0: none up to ``max_period`` -- chaotic, quasi-periodic or not yet settled);
* ``width``: max - min of the kept values;
* ``lyapunov``: the mean of log |dP/du| along the kept returns, the slope of the
  map in the coordinate u by central differences (:func:`slopes`);
* ``escaped``: a return failed (no return within t_max: the orbit left for another
  attractor or infinity) or a kept value left the window the caller watches; such an
  attractor is reported as escaped with the reason, never as numbers.

Why one coordinate is enough for the Lyapunov exponent: on a section of a slow-fast
system the fast coordinates are contracted by exp(-T/eps) per return (T the return
time), so the derivative of the return map is rank one up to that factor and the
largest exponent is the mean log-slope of the slow coordinate along the attractor,
with the fast coordinates held at their values on the orbit. The check against the
variational equations with saltation matrices (filippov.variational, reference
driver) is a test (tests/test_attractors.py).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .abi import CompiledModel
from .fastmap import OK, STATUS, compute_returns

_UNIT = float(np.spacing(1.0))


@dataclass(frozen=True)
class Attractor:
    """Where the return map settled from one start (see the module docstring)."""

    values: np.ndarray          # kept returns, the watched coordinate (NaN: not reached)
    period: int                 # 0: none up to max_period
    width: float
    lyapunov: float             # NaN where not computed or escaped
    escaped: bool
    reason: str = ""            # why it escaped ('' if it did not)
    states: np.ndarray = field(default=None, repr=False)  # kept returns, full state


def period_of(values: np.ndarray, tol: float, max_period: int) -> int:
    """Smallest p <= max_period with |u_{k+p} - u_k| <= tol for every kept k (0: none).
    Needs at least 2 max_period values, so that each candidate is seen to repeat."""
    u = np.asarray(values, dtype=float)
    if u.size < 2 * max_period:
        raise ValueError(f"need at least 2 max_period = {2 * max_period} kept values to "
                         f"test periods up to {max_period}, got {u.size}")
    for p in range(1, max_period + 1):
        if np.all(np.abs(u[p:] - u[:-p]) <= tol):
            return p
    return 0


def period_tolerance(scale: float) -> float:
    """Two returns are one point of a periodic orbit when they agree to 1e-4 of the
    attractor's scale (eps or eps^2 here), but never closer than 1000 ulp of 1: the
    returns themselves carry rounding of that order (event times to ~1e-15)."""
    return max(1e-4 * scale, 1e3 * _UNIT)


def iterate(cmodel: CompiledModel, start, *, transient: int, keep: int, t_max: float,
            **options):
    """``transient + keep`` returns from ``start`` (one compiled call); the raw
    :class:`filippov.fastmap.BatchReturns` with ``orbit`` of shape (1, keep, dim)."""
    if transient < 0 or keep < 1:
        raise ValueError(f"need transient >= 0 and keep >= 1, got {transient}, {keep}")
    return compute_returns(cmodel, np.atleast_2d(start), t_max, iterations=transient + keep,
                           keep=keep, **options)


def slopes(cmodel: CompiledModel, states: np.ndarray, coordinate: int, step: float,
           t_max: float, **options) -> np.ndarray:
    """dP_u/du at each state by central differences of step ``step`` in coordinate u
    (the other coordinates held), P_u the u-component of the first return. NaN where a
    perturbed start fails to return. Truncation ~ step^2 P'''/6, rounding ~ e/step
    with e the error of one return (~1e-14 here): a step of 1e-4 of the attractor's
    scale keeps both below 1e-3 of a slope of order one for scales >= 1e-8."""
    states = np.atleast_2d(np.asarray(states, dtype=float))
    plus, minus = states.copy(), states.copy()
    plus[:, coordinate] += step
    minus[:, coordinate] -= step
    out = compute_returns(cmodel, np.concatenate([plus, minus]), t_max, **options)
    m = states.shape[0]
    fp, fm = out.state[:m, coordinate], out.state[m:, coordinate]
    ok = (out.status[:m] == OK) & (out.status[m:] == OK)
    # the step actually taken (u +- step rounded), not the nominal one
    du = plus[:, coordinate] - minus[:, coordinate]
    return np.where(ok, (fp - fm) / du, np.nan)


def settle(cmodel: CompiledModel, start, *, coordinate: int, transient: int, keep: int,
           t_max: float, scale: float, max_period: int, window: tuple[float, float],
           lyapunov_step: float | None = None, **options) -> Attractor:
    """Iterate, classify, and (``lyapunov_step`` given) the Lyapunov exponent."""
    run = iterate(cmodel, start, transient=transient, keep=keep, t_max=t_max, **options)
    states = run.orbit[0]
    values = states[:, coordinate]
    lo, hi = window
    if run.status[0] != OK:
        reason = (f"{STATUS[int(run.status[0])]} after {int(run.returns_done[0])} returns "
                  f"(state {run.state[0].tolist()})")
        return Attractor(values, 0, np.nan, np.nan, True, reason, states)
    if np.any((values < lo) | (values > hi)):
        bad = values[(values < lo) | (values > hi)][0]
        return Attractor(values, 0, np.nan, np.nan, True,
                         f"left the window [{lo!r}, {hi!r}] (value {bad!r})", states)
    period = period_of(values, period_tolerance(scale), max_period)
    width = float(values.max() - values.min())
    lyap = np.nan
    if lyapunov_step is not None:
        s = slopes(cmodel, states, coordinate, lyapunov_step, t_max, **options)
        lyap = float(np.mean(np.log(np.abs(s)))) if np.all(np.isfinite(s)) else np.nan
    return Attractor(values, period, width, lyap, False, "", states)
