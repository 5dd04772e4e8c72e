"""Attractors of a first-return map, iterated on the compiled engine.

An orbit diagram asks, for each parameter value, where the return map settles: the
map is iterated from a start (``transient`` returns discarded, ``keep`` returns
recorded, all in one compiled call: :func:`filippov.fastmap.compute_returns` with
``iterations``) and the recorded returns are classified:

* ``period``: the smallest p with |u_{k+p} - u_k| <= tol over all kept returns
  (0: none up to ``max_period`` -- chaotic, quasi-periodic or not yet settled);
* ``width``: max - min of the kept values;
* ``lyapunov``: the largest Lyapunov exponent of the map along the kept returns: the
  mean log growth of a tangent vector carried by the derivative dP/dz that the engine
  returns with each return (:func:`lyapunov_exponent`; ``compute_returns(jacobian=True)``:
  variational equations and saltation matrices, no extra returns);
* ``escaped``: a return failed (no return within t_max: the orbit left for another
  attractor or infinity) or a kept value left the window the caller watches; such an
  attractor is reported as escaped with the reason, never as numbers.

Why this is the mean log-slope of x2: on a section of a slow-fast system the fast
coordinates are contracted by exp(-T/eps) per return (T the return time), so dP/dz is
rank one up to that factor and the vector's growth per return is the slope dP_x2/dx2.
:func:`slopes` gives that slope by central differences of P (two extra returns per
point) -- the independent check of the engine's derivative (tests/test_attractors.py).
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .abi import CompiledModel
from .fastmap import OK, STATUS, compute_returns

_UNIT = float(np.spacing(1.0))
#: status of a run whose kept returns left the watched window (beyond the engine's
#: status codes, :data:`filippov.fastmap.STATUS`)
LEFT_WINDOW = 100


@dataclass(frozen=True)
class Attractor:
    """Where the return map settled from one start (see the module docstring)."""

    values: np.ndarray          # kept returns, the watched coordinate (NaN: not reached)
    period: int                 # 0: none up to max_period
    width: float
    lyapunov: float             # NaN where not computed or escaped
    escaped: bool
    reason: str = ""            # why it escaped ('' if it did not)
    status: int = OK            # OK, the engine's status of the failed return, LEFT_WINDOW
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


#: the smallest central-difference step for slopes of a return map whose states are
#: of order one: one return carries rounding of ~1e-14 (event times to ~1e-15, summed
#: over the switches), which a step of 1e-11 turns into 1e-3 of an O(1) slope
MIN_FD_STEP = 1e-11


def check_resolvable(scale: float) -> None:
    """Refuse an attractor scale that double precision cannot resolve on states of
    order one: the period test needs 1000 ulp <= 1e-2 scale (e.g. theta > 0 at eps =
    1e-6: scale eps^2 = 1e-12, below it)."""
    if period_tolerance(scale) > 1e-2 * scale:
        raise ValueError(f"attractor scale {scale:.3g} is below what double precision "
                         f"resolves on states of order one (1000 ulp = {1e3 * _UNIT:.3g} "
                         f"must be <= 1e-2 of it): periods cannot be told apart")


def period_tolerance(scale: float) -> float:
    """Two returns are one point of a periodic orbit when they agree to 1e-4 of the
    attractor's scale (eps or eps^2 here), but never closer than 1000 ulp of 1: the
    returns themselves carry rounding of that order (event times to ~1e-15)."""
    return max(1e-4 * scale, 1e3 * _UNIT)


def iterate(cmodel: CompiledModel, start, *, transient: int, keep: int, t_max: float,
            jacobian: bool = False, **options):
    """``transient + keep`` returns from ``start`` (one compiled call); the raw
    :class:`filippov.fastmap.BatchReturns` with ``orbit`` of shape (1, keep, dim) (and
    with ``jacobian``: ``orbit_jacobian`` (1, keep, dim, dim), dP/dz of each)."""
    if transient < 0 or keep < 1:
        raise ValueError(f"need transient >= 0 and keep >= 1, got {transient}, {keep}")
    return compute_returns(cmodel, np.atleast_2d(start), t_max, iterations=transient + keep,
                           keep=keep, jacobian=jacobian, **options)


def lyapunov_exponent(jacobians: np.ndarray, coordinate: int) -> float:
    """The mean log growth of a tangent vector carried through ``jacobians`` ((k, n, n),
    dP/dz of consecutive returns), renormalized each return (Benettin's method), started
    along ``coordinate``. A return without a finite derivative (P not differentiable
    there: a switch met tangentially) is left out and the vector restarted; none left:
    NaN. A return that maps the vector to zero (sliding throughout: P flat) gives -inf."""
    n = jacobians.shape[-1]
    start = np.zeros(n)
    start[coordinate] = 1.0
    v, logs = start, []
    for J in jacobians:
        if not np.all(np.isfinite(J)):
            v = start
            continue
        w = J @ v
        g = float(np.sqrt(w @ w))
        with np.errstate(divide="ignore"):
            logs.append(np.log(g))
        v = w / g if g > 0 else start
    return float(np.mean(logs)) if logs else np.nan


#: one-sided slopes of P that differ by more than this (relative) put the point on a
#: kink of P (the grazing point): central differences straddling it average two
#: branches, so the slope there is refused (NaN). Smooth parts stay far below: the
#: curvature term is ~step/scale = 1e-4, the rounding ~1e-14/step <= 1e-2 for the
#: steps :func:`check_resolvable` admits.
KINK = 0.05


def slopes(cmodel: CompiledModel, states: np.ndarray, coordinate: int, step: float,
           t_max: float, images: np.ndarray | None = None, **options) -> np.ndarray:
    """dP_u/du at each state by central differences of step ``step`` in coordinate u
    (the other coordinates held), P_u the u-component of the first return: the check of
    the engine's derivative. NaN where a start fails to return or where the point lies
    on a kink of P (one-sided slopes differ by more than :data:`KINK`). Truncation ~
    step^2 times the third derivative of P, rounding ~ e/step with e the error of one
    return (~1e-14 here; ``step`` >= :data:`MIN_FD_STEP`): a step of 1e-4 of the
    attractor's scale keeps both below 1e-3 of a slope of order one for scales >= 1e-8.
    ``images``: P(states) where already known (rows with a NaN are computed here)."""
    if not step >= MIN_FD_STEP:
        raise ValueError(f"step {step!r} must be >= MIN_FD_STEP = {MIN_FD_STEP:g}: below, "
                         "the rounding of one return dominates the slope")
    states = np.atleast_2d(np.asarray(states, dtype=float))
    m = states.shape[0]
    plus, minus = states.copy(), states.copy()
    plus[:, coordinate] += step
    minus[:, coordinate] -= step
    known = (np.zeros(m, dtype=bool) if images is None
             else np.all(np.isfinite(np.atleast_2d(images)), axis=1))
    out = compute_returns(cmodel, np.concatenate([plus, minus, states[~known]]), t_max,
                          **options)
    fp, fm = out.state[:m, coordinate], out.state[m:2 * m, coordinate]
    f0 = np.empty(m)
    f0[~known] = out.state[2 * m:, coordinate]
    ok = (out.status[:m] == OK) & (out.status[m:2 * m] == OK)
    ok[~known] &= out.status[2 * m:] == OK
    if known.any():
        f0[known] = np.atleast_2d(images)[known, coordinate]
    # the steps actually taken (u +- step rounded), not the nominal one
    up = plus[:, coordinate] - states[:, coordinate]
    down = states[:, coordinate] - minus[:, coordinate]
    right, left = (fp - f0) / up, (f0 - fm) / down
    big = np.maximum(1.0, np.maximum(np.abs(right), np.abs(left)))
    kink = np.abs(right - left) > KINK * big
    return np.where(ok & ~kink, (fp - fm) / (up + down), np.nan)


def settle(cmodel: CompiledModel, start, *, coordinate: int, transient: int, keep: int,
           t_max: float, scale: float, max_period: int, window: tuple[float, float],
           lyapunov: bool = False, **options) -> Attractor:
    """Iterate, classify, and (``lyapunov``) the Lyapunov exponent from the engine's
    dP/dz along the kept returns. A scale too small to resolve is refused first
    (:func:`check_resolvable`)."""
    check_resolvable(scale)
    run = iterate(cmodel, start, transient=transient, keep=keep, t_max=t_max,
                  jacobian=lyapunov, **options)
    states = run.orbit[0]
    values = states[:, coordinate]
    lo, hi = window
    if run.status[0] != OK:
        reason = (f"{STATUS[int(run.status[0])]} after {int(run.returns_done[0])} returns "
                  f"(state {run.state[0].tolist()})")
        return Attractor(values, 0, np.nan, np.nan, True, reason, status=int(run.status[0]),
                         states=states)
    if np.any((values < lo) | (values > hi)):
        bad = values[(values < lo) | (values > hi)][0]
        return Attractor(values, 0, np.nan, np.nan, True,
                         f"left the window [{lo!r}, {hi!r}] (value {bad!r})",
                         status=LEFT_WINDOW, states=states)
    period = period_of(values, period_tolerance(scale), max_period)
    width = float(values.max() - values.min())
    lyap = lyapunov_exponent(run.orbit_jacobian[0], coordinate) if lyapunov else np.nan
    return Attractor(values, period, width, lyap, False, states=states)


def first_window(periods: np.ndarray, n: int) -> tuple[int, int] | None:
    """[i0, i1] (inclusive) of the first run of ``periods == n`` of at least two grid
    points, scanning the grid upwards; None if there is none."""
    hit = np.asarray(periods) == n
    i = 0
    while i < hit.size:
        if hit[i]:
            j = i
            while j + 1 < hit.size and hit[j + 1]:
                j += 1
            if j > i:
                return i, j
            i = j + 1
        else:
            i += 1
    return None


def edge(classify, inside: float, outside: float, n: int, tol: float) -> float:
    """Bisection for where the period ``n`` at ``inside`` stops (``classify(s)`` gives
    the period at s, ``outside`` has another one): the midpoint of the last bracket,
    no wider than ``tol``."""
    a, b = float(inside), float(outside)
    while abs(b - a) > tol:
        m = 0.5 * (a + b)
        if classify(m) == n:
            a = m
        else:
            b = m
    return 0.5 * (a + b)


def window_edges(grid: np.ndarray, periods: np.ndarray, n: int, classify,
                 tol: float) -> tuple[float, float]:
    """(left, right) edges of the first window of period n on ``grid`` (see
    :func:`first_window`), located by bisection to ``tol``; NaN where the window
    is not there or reaches the end of the grid (the edge lies outside)."""
    w = first_window(periods, n)
    if w is None:
        return np.nan, np.nan
    i0, i1 = w
    left = edge(classify, grid[i0], grid[i0 - 1], n, tol) if i0 > 0 else np.nan
    right = edge(classify, grid[i1], grid[i1 + 1], n, tol) if i1 + 1 < grid.size else np.nan
    return left, right
