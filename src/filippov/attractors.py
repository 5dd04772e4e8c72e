"""Attractors of a first-return map, iterated on the compiled engine.

An orbit diagram asks, for each parameter value, where the return map settles: the
map is iterated from a start (``transient`` returns discarded, ``keep`` returns
recorded, all in one compiled call: :func:`filippov.fastmap.compute_returns` with
``iterations``) and the recorded returns are classified:

* ``period``: decided by convergence, not by a count. The smallest p with
  ``|u_{k+p} - u_k| <= tol`` over the kept returns (or, for an orbit still converging, to
  LOOSE of the scale) is only a candidate; for each divisor d of it, smallest first,
  Newton on P^d(z) - z from the last return with the engine's dP/dz (:func:`confirm`)
  looks for the orbit, whose spectral radius decides stability and which the kept
  returns must approach. Found: the period is d, the width the orbit's and the
  exponent log(radius)/d, exact. Not found: 0 (chaotic, quasi-periodic or a repeat
  that is no stable orbit); a period with a positive exponent is refused;
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
from .fastmap import OK, STATUS, BatchReturns, compute_returns, sweep_returns

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
    lyapunov_err: float = np.nan  # standard error of ``lyapunov`` (0: a confirmed cycle's)
    cycle: "Cycle" = field(default=None, repr=False)   # the confirmed periodic orbit
    unconfirmed: int = 0        # a period the kept returns repeat with, not confirmed

    def __post_init__(self):
        if self.period > 0 and self.lyapunov > 0:
            raise ValueError(f"period {self.period} with a positive Lyapunov exponent "
                             f"{self.lyapunov!r}: a contradiction, not an attractor")


def period_of(values: np.ndarray, tol: float, max_period: int) -> int:
    """Smallest p <= max_period with ``|u_{k+p} - u_k| <= tol`` for every kept k (0: none).
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


def iterate_sweep(cmodels, starts, *, transient: int, keep: int, t_max: float,
                  jacobian: bool = False, **options) -> BatchReturns:
    """:func:`iterate` from ``starts[i]`` under ``cmodels[i]`` for every i, in one compiled
    call (:func:`filippov.fastmap.sweep_returns`: one model at different parameter
    values); row i of each output is what :func:`iterate` returns for that point, bit for
    bit (:func:`row` takes it out)."""
    if transient < 0 or keep < 1:
        raise ValueError(f"need transient >= 0 and keep >= 1, got {transient}, {keep}")
    return sweep_returns(cmodels, starts, t_max, iterations=transient + keep, keep=keep,
                         jacobian=jacobian, **options)


def row(batch: BatchReturns, i: int) -> BatchReturns:
    """Start i of a batch as a batch of its own (views of row i)."""
    return BatchReturns(**{name: None if value is None else value[i:i + 1]
                           for name, value in vars(batch).items()})


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


#: a cycle whose multipliers predict the returns' distance to it to shrink below this
#: fraction over the kept returns must be seen to shrink by its square root at least
#: (confirm); a slower one only to shrink (docs/decisions.md#attractor-approach)
STRONG = 1e-3
#: the kept returns of an orbit still converging repeat only to this fraction of the
#: attractor's scale: the candidate period Newton is asked to confirm (a multiplier of
#: -0.99 leaves 1e-2 of the start's offset after ~460 returns)
LOOSE = 1e-2
#: an exponent counts as positive (chaos) when it exceeds this many standard errors
LYAPUNOV_SIGMAS = 3.0
#: a run undecided after its kept returns (no confirmed cycle, no exponent clearly
#: positive) goes on, at most MAX_EXTENSIONS times, for EXTEND x keep more. Chaotic
#: transients before a stable cycle last up to ~1800 returns on fig12's grid (eps = 1e-2,
#: s = 0.575, 3.05); 12 x 8 x 60 = 5760 returns cover three times that (with 3, a start
#: and the same start with its transient doubled were typed differently)
EXTEND = 8
MAX_EXTENSIONS = 12
#: blocks of the returns over which the Lyapunov exponent's standard error is estimated
#: (batch means: the log-slopes are correlated over a few returns); twenty, not five,
#: for two standard errors to cover the exponent at about the nominal 95%
#: (docs/decisions.md#lyapunov-error; tests/test_instability_claims.py)
LYAPUNOV_BLOCKS = 20


def lyapunov_estimate(jacobians: np.ndarray, coordinate: int,
                      blocks: int = LYAPUNOV_BLOCKS) -> tuple[float, float]:
    """(exponent, standard error): :func:`lyapunov_exponent` over all of ``jacobians``
    and the spread of its value over ``blocks`` (:data:`LYAPUNOV_BLOCKS`) consecutive
    blocks (batch means), std/sqrt(blocks). NaN error with fewer than two returns per
    block."""
    lam = lyapunov_exponent(jacobians, coordinate)
    k = len(jacobians) // blocks
    if k < 2 or not np.isfinite(lam):
        return lam, np.nan
    means = [lyapunov_exponent(jacobians[b * k:(b + 1) * k], coordinate)
             for b in range(blocks)]
    return lam, float(np.std(means, ddof=1) / np.sqrt(blocks))


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


@dataclass(frozen=True)
class Cycle:
    """A periodic orbit of P confirmed by Newton (:func:`confirm`)."""

    period: int
    points: np.ndarray          # (period, dim): its points, the first nearest the iterates
    radius: float               # spectral radius of d(P^period)/dz: stable iff < 1
    distance: float             # max |last kept returns - orbit points| (watched coordinate)
    converging: bool            # the iterates approach it over the kept returns


def _divisors(p: int) -> list[int]:
    return [d for d in range(1, p + 1) if p % d == 0]


def _cycle_newton(cmodel: CompiledModel, z: np.ndarray, d: int, age: float, t_max: float,
                  tol: float, max_iter: int, options: dict):
    """Newton on P^d(z) - z with the engine's dP/dz (the product over the d returns):
    (point, d(P^d)/dz there) or None. Each iterate is put back on the section (one
    gradient step on the section function, as periodic_orbit does)."""
    from .fastmap import batch_scale
    from .periodic import _onto_section

    # the run's state scale (filippov.scale), fixed at the first iterate as periodic_orbit
    # fixes it at its guess: the stopping test and the step onto the section grow from it
    floor = batch_scale(cmodel, np.atleast_2d(z), options.get("scale")).state
    value = lambda x: float(cmodel.section(np.ascontiguousarray(x, dtype=float),  # noqa: E731
                                           cmodel.params))
    z = np.array(z, dtype=float)
    for _ in range(max_iter):
        run = compute_returns(cmodel, [z], t_max, iterations=d, keep=d, jacobian=True,
                              start_age=age, **options)
        if run.status[0] != OK:
            return None
        J = np.eye(z.size)
        for Jk in run.orbit_jacobian[0]:
            J = Jk @ J
        r = run.orbit[0, -1] - z
        if np.abs(r).max() <= tol * (floor + np.abs(z).max()):
            return z, J      # J may be non-finite: the orbit touches H (a grazing cycle)
        if not np.all(np.isfinite(J)):
            return None
        try:
            z = z - np.linalg.solve(J - np.eye(z.size), r)
        except np.linalg.LinAlgError:
            return None
        z = _onto_section(value, z, floor)
    return None


def confirm(cmodel: CompiledModel, states: np.ndarray, age: float, candidate: int, *,
            coordinate: int, t_max: float, scale: float, settled: float = 0.0,
            tol: float = 1e-13, max_iter: int = 12, **options) -> Cycle | None:
    """The periodic orbit the iterates ``states`` (the kept returns, full states) settle
    on, if any: Newton on P^d - z from the last state for each divisor d of
    ``candidate`` (smallest first: a period-one orbit converging with multiplier near -1
    repeats with period two before it repeats with period one), accepted when it
    converges and its points lie within ``scale`` of the last d kept returns. ``radius``
    then decides stability, and ``converging`` whether the iterates approach it (their
    distance at the end of the kept returns below that at the start, or below
    ``settled``: on it up to rounding; where its multipliers predict a contraction below
    STRONG over the kept returns, by at least its square root). None: no orbit
    of a divisor's period near the iterates. A stable, approached orbit of a larger
    divisor wins over an unstable or unapproached one of a smaller (reported if none is)."""
    states = np.asarray(states, dtype=float)
    first = None
    for d in _divisors(int(candidate)):
        found = _cycle_newton(cmodel, states[-1], d, age, t_max, tol, max_iter, options)
        if found is None:
            continue
        z, J = found
        pts = iterate(cmodel, z, transient=0, keep=d, t_max=t_max, start_age=age,
                      **options).orbit[0]
        pts = np.roll(pts, 1, axis=0)          # z first (P^d(z) = z is the last one)
        k = states.shape[0]
        # Newton may converge to any of the orbit's points: the last kept return sits at
        # the nearest one, j, and the kept return i at (j + i - k + 1) mod d
        j = int(np.argmin(np.abs(pts[:, coordinate] - states[-1, coordinate])))
        phase = np.array([pts[(j + i - k + 1) % d, coordinate] for i in range(k)])
        gap = np.abs(states[:, coordinate] - phase)
        tail = float(gap[-d:].max())
        if not tail <= scale:
            continue
        # approach measured over two periods at each end: with a multiplier near -1 the
        # returns alternate sides of the orbit, at distances that differ more between the
        # sides than they shrink in a period (fig12, eps = 1e-2, s = 3.225: -0.9988)
        two = min(2 * d, k)
        head, end = float(gap[:two].max()), float(gap[-two:].max())
        # NaN: P is not differentiable on the orbit (it touches H tangentially)
        radius = (float(np.max(np.abs(np.linalg.eigvals(J)))) if np.all(np.isfinite(J))
                  else np.nan)
        # approaching it (by half the contraction its multipliers predict over the kept
        # returns, in logarithm, where that is STRONG), or already on it up to the
        # returns' rounding (docs/decisions.md#attractor-approach)
        predicted = radius ** ((k - two) / d) if np.isfinite(radius) and radius < 1.0 else 1.0
        shrink = np.sqrt(predicted) if predicted < STRONG else 1.0
        cycle = Cycle(d, pts, radius, tail, bool(end < head * shrink or end <= settled))
        if cycle.converging and cycle.radius < 1.0:
            return cycle
        # an unstable orbit of a divisor's period can lie within ``scale`` of the returns
        # (a saddle the stable cycle winds around): the next divisor may be the attractor
        first = first or cycle
    return first


def _escape(run, values, window) -> Attractor | None:
    """An Attractor that escaped (a failed return, or kept returns out of the window)."""
    states = run.orbit[0]
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
    return None


def _repeat_gaps(values: np.ndarray, max_period: int) -> np.ndarray:
    """``max |u_{k+p} - u_k|`` over the kept returns for p = 1 .. max_period."""
    return np.array([np.abs(values[p:] - values[:-p]).max()
                     for p in range(1, max_period + 1)])


def _best_repeat(values: np.ndarray, max_period: int) -> int:
    """The p <= max_period with the smallest repeat gap (:func:`_repeat_gaps`): the
    period an orbit still converging (too slowly to repeat to any tolerance yet) comes
    closest to."""
    return int(np.argmin(_repeat_gaps(values, max_period))) + 1


def _periodic(cmodel, states, age, coordinate, scale, max_period, t_max, options,
              last_chance=False, lyapunov=True):
    """(the Attractor of a confirmed, stable cycle or None, the count's period). With
    ``last_chance`` (after the extension) the candidate is the best repeat and the cycle
    may lie up to the attractor's scale from the returns, as long as they approach it."""
    values = states[:, coordinate]
    period = period_of(values, period_tolerance(scale), max_period)
    # a count of repeats is only a candidate: the orbit is confirmed by Newton, its
    # multipliers decide stability and the iterates must approach it (module docstring)
    near = scale if last_chance else LOOSE * scale
    candidate = period or (_best_repeat(values, max_period) if last_chance
                           else period_of(values, near, max_period))
    cycle = (confirm(cmodel, states, age, candidate, coordinate=coordinate, t_max=t_max,
                     scale=near, settled=period_tolerance(scale), **options)
             if candidate else None)
    # a cycle on which P is not differentiable (grazing) has no multipliers: it counts
    # as the attractor only if the kept returns already repeat on it to the tolerance
    stable = cycle is not None and cycle.converging and (
        cycle.radius < 1.0 or (np.isnan(cycle.radius) and period == cycle.period))
    if not stable:
        return None, period
    u = cycle.points[:, coordinate]
    # the exponent only where asked for: a sweep without it keeps NaN throughout (a
    # point whose type another machine decides otherwise changes no NaN pattern)
    with np.errstate(divide="ignore", invalid="ignore"):
        lyap = float(np.log(cycle.radius) / cycle.period) if lyapunov else np.nan
    return Attractor(values, cycle.period, float(u.max() - u.min()), lyap, False,
                     states=states, lyapunov_err=0.0 if lyapunov else np.nan,
                     cycle=cycle), period


def _check_first(first: BatchReturns, transient: int, keep: int, lyapunov: bool) -> None:
    """``first`` must be the run settle would make: one start, ``keep`` kept returns
    (with their dP/dz when ``lyapunov``), ``transient + keep`` made unless it failed."""
    made = int(first.returns_done[0]) if first.returns_done.shape == (1,) else -1
    if (first.orbit.shape[:2] != (1, keep) or (lyapunov and first.orbit_jacobian is None)
            or (first.status[0] == OK and made != transient + keep)):
        raise ValueError(
            f"first: expected the run of one start with {transient} + {keep} returns "
            f"(keep {keep}{', with jacobian=True' if lyapunov else ''}), got orbit "
            f"{first.orbit.shape}, {made} returns made")


def settle(cmodel: CompiledModel, start, *, coordinate: int, transient: int, keep: int,
           t_max: float, scale: float, max_period: int, window: tuple[float, float],
           lyapunov: bool = False, first: BatchReturns | None = None,
           **options) -> Attractor:
    """Iterate, classify, and (``lyapunov``) the Lyapunov exponent from the engine's
    dP/dz along the kept returns. A scale too small to resolve is refused first
    (:func:`check_resolvable`).

    Without a stable cycle confirmed after ``transient + keep`` returns the run goes on
    for EXTEND x keep more returns and is judged again on the last ``keep`` of them, up
    to MAX_EXTENSIONS times or until (with ``lyapunov``) the exponent over all returns
    so far exceeds LYAPUNOV_SIGMAS standard errors: an orbit that converges slowly (a
    multiplier near one in modulus) or lingers near a saddle cycle -- whose exponent
    over a short window can look positive -- is then found, whatever the fixed
    transient was.

    ``first``: the first ``transient + keep`` returns already made (a row of
    :func:`iterate_sweep`, which makes them for many points in one call), instead of
    iterating here."""
    check_resolvable(scale)
    if first is not None:
        _check_first(first, transient, keep, lyapunov)
    run = first if first is not None else iterate(cmodel, start, transient=transient,
                                                  keep=keep, t_max=t_max,
                                                  jacobian=lyapunov, **options)
    states = run.orbit[0]
    values = states[:, coordinate]
    escaped = _escape(run, values, window)
    if escaped is not None:
        return escaped
    args = (coordinate, scale, max_period, t_max, options)
    kw = {"lyapunov": lyapunov}
    found, period = _periodic(cmodel, states, float(run.age[0]), *args, **kw)
    if found is not None:
        return found
    lyap, err = np.nan, np.nan
    # no cycle yet: iterate on, from where the run stopped, up to MAX_EXTENSIONS times (an
    # orbit converging with a multiplier near one, or lingering near a saddle cycle, whose
    # exponent over a short window can even look positive); chaos is called only after
    # at least one extension, on the exponent over all returns so far
    jacs = [run.orbit_jacobian[0]] if lyapunov else []
    last, age = states[-1], float(run.age[0])
    for _ in range(MAX_EXTENSIONS):
        more = iterate(cmodel, last, transient=0, keep=EXTEND * keep, t_max=t_max,
                       jacobian=lyapunov, start_age=age, **options)
        states2 = more.orbit[0][-keep:]
        values2 = states2[:, coordinate]
        escaped = _escape(more, values2, window)
        if escaped is not None:
            return escaped
        last, age = states2[-1], float(more.age[0])
        found, period2 = _periodic(cmodel, states2, age, *args, last_chance=True, **kw)
        if found is not None:
            return found
        if lyapunov:
            jacs.append(more.orbit_jacobian[0])
            lyap, err = lyapunov_estimate(np.concatenate(jacs), coordinate)
            if lyap > LYAPUNOV_SIGMAS * err:
                break
    if not (lyapunov and lyap > LYAPUNOV_SIGMAS * err):
        # last: a stable cycle next to the returns whose contraction is too slow for the
        # extensions (multipliers 0.997-0.999 per period at eps = 1e-2 in fig12): iterate
        # as long as its measured contraction says the transient needs, then judge again
        wait = _slow_cycle(cmodel, states2, age, coordinate, scale, max_period, t_max,
                           options)
        if wait:
            more = iterate(cmodel, last, transient=wait, keep=keep, t_max=t_max,
                           start_age=age, **options)
            if more.status[0] == OK:
                found, _ = _periodic(cmodel, more.orbit[0], float(more.age[0]), *args,
                                     last_chance=True, **kw)
                if found is not None:
                    return found
    return Attractor(values2, 0, float(values2.max() - values2.min()), lyap, False,
                     states=states2, lyapunov_err=err, unconfirmed=period2)


#: the most returns :func:`settle` waits for a slowly contracting cycle (SLOW_CAP x the
#: period's returns at a multiplier 0.999 leave 1e-4 of the start's distance)
SLOW_CAP = 20000


def _slow_cycle(cmodel, states, age, coordinate, scale, max_period, t_max, options):
    """Returns to wait for a stable cycle found by Newton within the attractor's scale of
    the last return -- tried for the periods of the three best repeats and their
    divisors (the best repeat need not be a multiple of the cycle's period) -- until its
    measured contraction brings the returns within the period tolerance:
    d ln(tol/dist)/ln(radius), capped at SLOW_CAP. None: no such cycle."""
    values = states[:, coordinate]
    gaps = _repeat_gaps(values, max_period)
    tol = period_tolerance(scale)
    tried = set()
    for p in np.argsort(gaps, kind="stable")[:3] + 1:
        for d in _divisors(int(p)):
            if d in tried:
                continue
            tried.add(d)
            found = _cycle_newton(cmodel, states[-1], d, age, t_max, 1e-13, 12, options)
            if found is None or not np.all(np.isfinite(found[1])):
                continue
            z, J = found
            radius = float(np.max(np.abs(np.linalg.eigvals(J))))
            if not radius < 1.0:
                continue
            pts = iterate(cmodel, z, transient=0, keep=d, t_max=t_max, start_age=age,
                          **options).orbit[0][:, coordinate]
            dist = float(np.min(np.abs(pts - values[-1])))
            if not dist <= scale:
                continue
            if dist <= tol:
                return d
            need = d * np.log(tol / dist) / np.log(radius) if radius > 0 else d
            return int(min(np.ceil(need) + d, SLOW_CAP))
    return None


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
