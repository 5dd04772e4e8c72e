"""The units a run is measured in: one state scale, one time scale, one scale of H.

Every tolerance and floor of the engines that is not relative to something already is one
of these three: ``atol`` is a state error (times the state scale S), ``touch_tol`` a value
of H (times H's scale G), ``event_xtol`` and the time floor of the Zeno test are times
(times the time scale T), and the central-difference steps, the rate step and the
rounding floors of the rules grow with the state from S (where they grew from 1). A system
written in micrometres or in microseconds then gets the results of the same system in
metres and seconds, to rounding: docs/decisions.md#units.

A system declares its scale (``FilippovSystem(..., scale=...)``; the paper's models
declare :data:`UNIT`, the only value that restores the unit-scale arithmetic of before:
``scale=1.0`` declares S alone and still measures T and G) or has it measured at the
run's start (:func:`measure_system`, about 24n evaluations of the pieces): S is the
larger of the start's size and the fields' own length there (the length up to 1), T the
time the fields take to move the state by S (at the start's speed, or the fields' own
rate where that is faster), G the change of H over S (H's gradient at the start times
S); each is rounded to a power of two and taken as 1 within :data:`DEAD_BAND` of 1 --
the defaults were chosen at unit scale, and a system in its natural units runs exactly
as before. A measured scale is a power of two, so scaling a tolerance by it is exact. A
batch (a map, a sweep) runs at one scale, the smaller of those of its smallest and its
largest start (:func:`of_batch`). Components in units far apart (their extents at the
start spread beyond :data:`SPREAD`) get a scale each (:func:`component_scales`): atol per
component, G from each component's share of H, difference steps along a component from
its own scale, and T the fields' own time in no component's units.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

#: measured scales within this factor of 1 are 1 (a system in its natural units)
DEAD_BAND = 16.0
#: the exponents a measured scale is clamped to: products of a scale with tolerances and
#: with each other stay normal floats far from underflow and overflow
MAX_EXPONENT = 300


@dataclass(frozen=True)
class Scale:
    """A run's units: ``state`` (the size of the state), ``time`` (the time the state
    takes to move by ``state``), ``switch`` (the size of H at states of size ``state``);
    ``how``: "declared", "measured" or "unit"."""

    state: float = 1.0
    time: float = 1.0
    switch: float = 1.0
    how: str = "declared"
    #: the scale of each component (powers of two): measured where the components
    #: spread beyond SPREAD (:func:`component_scales`); None: every component at
    #: ``state``, which stays the scale measured for all (the rules' rounding floors)
    components: tuple | None = None

    @property
    def is_unit(self) -> bool:
        return (self.state == 1.0 and self.time == 1.0 and self.switch == 1.0
                and self.components is None)

    def of_components(self, n: int) -> np.ndarray:
        """The scale of each of ``n`` components (``state`` for all where not measured);
        a declared ``components`` of another length is refused naming it."""
        if self.components is None:
            return np.full(n, self.state)
        if len(self.components) != n:
            raise ValueError(f"scale.components: one scale a component, {n} of them; got "
                             f"{len(self.components)}: {self.components!r}")
        return np.array(self.components, dtype=float)

    def absolute(self, atol: float, n: int):
        """``atol`` (a state error in units of the scale) per component of ``n``: a number
        where every component has the scale ``state`` (the arithmetic of a single
        scale), else an array."""
        if self.components is None:
            return atol * self.state
        return atol * self.of_components(n)


#: the scale of a system written in units of its own size (the paper's models)
UNIT = Scale(1.0, 1.0, 1.0, "unit")


def power_of_two(x: float) -> float:
    """The power of two nearest ``x`` (> 0, finite; else 1), 1 within DEAD_BAND of 1."""
    if not (math.isfinite(x) and x > 0.0):
        return 1.0
    e = round(math.log2(x))
    e = max(-MAX_EXPONENT, min(MAX_EXPONENT, e))
    p = math.ldexp(1.0, e)
    return 1.0 if 1.0 / DEAD_BAND <= p <= DEAD_BAND else p


def _inf_norm(v) -> float:
    v = np.asarray(v, dtype=float)
    return float(np.max(np.abs(v))) if v.size else 0.0


#: a measured state size outside [2^-MAX_EXPONENT, 2^MAX_EXPONENT] (Scale.how begins so):
#: the run's tolerances cannot be measured in it, and :func:`resolve` refuses the run
OUT_OF_RANGE = "out of range: size"

#: how far (in powers of two) beyond the start's size, or 1, the probes of _rate reach
PROBE_REACH = 20


def _column(field, z0, f0, k: int, size: float) -> np.ndarray:
    """``dF/dz_k`` near z0 (a column of F's Jacobian), by the shortest step ``2^j`` along
    coordinate k (j by bisection, from ``sqrt(eps) |z0_k|`` up to ``2^PROBE_REACH`` times
    the start's ``size``: a dozen evaluations) that changes F by ``sqrt(eps) |F(z0)|``, above its rounding; 0
    where no step does, or F is not finite."""
    root, target = math.sqrt(np.finfo(float).eps), math.sqrt(np.finfo(float).eps) * _inf_norm(f0)
    zero = np.zeros(np.shape(f0))

    def change(j):   # a probe that raises or is not finite tells nothing: inf
        z = z0.copy()
        z[k] += math.ldexp(1.0, j)
        try:
            d = np.asarray(field(z), dtype=float) - f0
        except Exception:   # noqa: BLE001 -- a piece undefined there: the run never goes
            return math.inf, zero
        c = _inf_norm(d)
        return (c, d) if math.isfinite(c) else (math.inf, zero)

    # from the component's own size, not the start's: beside a constant of 1e14 a step
    # from the start's size (1.5e6) read a secant for the derivative, dF_y/dx 1.5e6
    own = abs(float(z0[k]))
    lo = max(-MAX_EXPONENT, math.frexp(root * own)[1] - 1) if own > 0.0 else -MAX_EXPONENT
    # probes stay within 2^PROBE_REACH of the start's size (or of 1): a piece written for
    # its own range (an angle wrapped by a loop) is never asked at 2^300
    hi = min(MAX_EXPONENT, math.frexp(max(size, 1.0))[1] + PROBE_REACH)
    if not change(hi)[0] >= target:
        return zero
    if change(lo)[0] >= target:
        hi = lo
    while hi - lo > 1:   # change(lo) below the target, change(hi) at or above it
        mid = (lo + hi) // 2
        if change(mid)[0] >= target:
            hi = mid
        else:
            lo = mid
    c, d = change(hi)
    return d / math.ldexp(1.0, hi) if math.isfinite(c) else zero


def _rate(field, z0, f0, k: int, size: float) -> float:
    """``|dF/dz_k|`` near z0 (:func:`_column`'s largest entry)."""
    return _inf_norm(_column(field, z0, f0, k, size))


def field_jacobian(field, z0) -> tuple[np.ndarray, np.ndarray]:
    """``(F(z0), dF/dz)`` of ``field`` (a function of one state) near ``z0``, each column
    from the shortest step that changes F above its rounding (:func:`_column`)."""
    z0 = np.asarray(z0, dtype=float)
    f0 = np.asarray(field(z0), dtype=float)
    if not math.isfinite(_inf_norm(f0)):
        return f0, np.zeros((f0.size, z0.size))
    size = _inf_norm(z0)
    cols = [_column(field, z0, f0, k, size) for k in range(z0.size)]
    return f0, (np.column_stack(cols) if cols else np.zeros((f0.size, 0)))


def field_rates(field, z0) -> tuple[float, float]:
    """``(|F(z0)|, max_k |dF/dz_k|)`` of ``field`` (a function of one state) near ``z0``,
    each rate from the shortest step that changes F above its rounding (:func:`_column`;
    at a zero of F, the change of F over the shortest probe). (0, 0) where F is not
    finite at z0."""
    return _speed_and_rate(*field_jacobian(field, z0))


def _speed_and_rate(f0, J) -> tuple[float, float]:
    """:func:`field_rates` from F and its Jacobian."""
    speed = _inf_norm(f0)
    if not math.isfinite(speed):
        return 0.0, 0.0
    return speed, _inf_norm(J)


def field_length(field, z0) -> float:
    """The length over which ``field`` (a function of one state) changes by its own size
    near ``z0``: ``|F| / max_k |dF/dz_k|`` (:func:`field_rates`). A length of the
    system, not of the start: a start at the origin (up to rounding) of a system whose
    orbits are of size one has the length of those orbits, where its own size would make
    every tolerance absurdly tight; and the largest rate, not the rate along F, so that a
    component nothing depends on (an integral of a cost) does not make it long. inf where
    F is zero, constant or not finite there."""
    return _length(*field_rates(field, z0))


def _length(speed: float, rate: float) -> float:
    """A field's length from its speed and its largest rate (inf where either is 0)."""
    return speed / rate if speed > 0.0 and rate > 0.0 else math.inf


def measure(z0, fields=None, grad=None, state=None, length=math.inf, rate=0.0) -> Scale:
    """The scale measured at a start ``z0``.

    - S: the larger of the start's largest component and the fields' ``length`` there
      (:func:`field_length`) up to 1, or ``state`` where declared: the length lifts a
      start at the origin (up to rounding) to its system's size, never above the unit
      scale -- a nearly uniform field, whose length is huge, must not loosen the
      tolerances of a start of size one;
    - T: the time the fields take to move the state by S, ``S / max(|F|, rate S)``
      (``fields``: the values of ``F_-`` and ``F_+`` at z0, or None; ``rate``: their
      largest ``|dF/dz_k|``) -- the shorter of the time at the start's speed and the
      fields' own time ``1 / rate``, so that a start next to an equilibrium (speed near
      0) does not make every time long;
    - G: S times the largest component of H's gradient (``grad``: at z0, or, where it
      vanishes there (the centre of a circle), rows at probes a distance S away, so that
      such a start still measures H's size; never the probes' where z0's is not 0: H may
      grow steeply beyond the surface, and G would loosen touch_tol by as much).

    Non-finite or zero measures give 1."""
    size = max(_inf_norm(z0), min(length, 1.0) if math.isfinite(length) else 0.0)
    S = power_of_two(size) if state is None else state
    how = "measured"
    if state is None and not 2.0 ** -MAX_EXPONENT <= size <= 2.0 ** MAX_EXPONENT \
            and size > 0.0:
        how = f"{OUT_OF_RANGE} {size:.3g}"   # resolve refuses it by name
    speed = max((_inf_norm(f) for f in fields), default=0.0) if fields is not None else 0.0
    moves = max(speed if math.isfinite(speed) else 0.0,
                rate * S if math.isfinite(rate) else 0.0)
    T = power_of_two(S / moves) if moves > 0.0 else 1.0
    g = _inf_norm(grad) if grad is not None else 0.0
    G = power_of_two(S * g) if math.isfinite(g) and g > 0.0 else 1.0
    return Scale(S, T, G, how)


def _finite_at(fn, z):
    """``fn(z)`` as an array, or None where it raises or is not finite (a probe that
    tells nothing)."""
    try:
        v = np.asarray(fn(z), dtype=float)
    except Exception:   # noqa: BLE001 -- a piece undefined there: the run never goes
        return None
    return v if np.all(np.isfinite(v)) else None


def measure_system(z0, field_minus, field_plus, switch_grad, state=None) -> Scale:
    """:func:`measure` at ``z0`` of a system given by its pieces (functions of one
    state): the fields there, their shorter length and largest rate
    (:func:`field_rates`), and H's gradient at z0 (where it vanishes, at ``z0 + S
    e_k``); with a scale per component where they spread (:func:`component_scales`,
    from the same probes). About ``2 (12 n + 1) + 1`` evaluations of the pieces."""
    z0 = np.asarray(z0, dtype=float).reshape(-1)
    try:
        fields = (field_minus(z0), field_plus(z0))
        jacobians = [field_jacobian(f, z0) for f in (field_minus, field_plus)]
    except Exception:   # noqa: BLE001 -- the run's own checks name a piece that fails
        return measure(z0, state=state)   # the start's size alone
    rates = [_speed_and_rate(f, J) for f, J in jacobians]
    length = min(_length(s, r) for s, r in rates)
    rate = max(r for _, r in rates)
    sized = measure(z0, state=state, length=length)   # S, or a size out of range
    S = sized.state
    grad = _finite_at(switch_grad, z0)
    if grad is None or grad.shape != z0.shape or not np.any(grad):
        # no gradient at the start (the centre of a circle): H's size a distance S away
        probes = [z0 + S * e for e in np.eye(z0.size)]
        grads = [g for g in (_finite_at(switch_grad, z) for z in probes)
                 if g is not None and g.shape == z0.shape]
        grad = np.array(grads) if grads else None
    out = measure(z0, fields, grad, S, length, rate)
    parts = None if state is not None else component_scales(z0, fields, jacobians, S)
    if parts is None:
        return Scale(out.state, out.time, out.switch, sized.how)
    # components in units far apart: the time the fields take to move each by its own
    # scale is 1/rho (component_scales), where S over the largest speed mixes units
    # S stays the scale measured for all: the rules' rounding floors grow from it, and
    # the largest component's (a fast integral of 2^18 beside a state of size 1) made
    # them lose a touch of H between samples (tests/test_sliding_exit_hidden.py)
    rho = system_rate(z0, jacobians, out.state)
    return Scale(out.state, power_of_two(1.0 / rho),
                 _switch_scale(grad, np.array(parts)), sized.how, parts)


def spectral_rate(jacobians) -> float:
    """The larger spectral radius of the fields' Jacobians (``jacobians``: pairs ``(F,
    dF/dz)``, :func:`field_jacobian`): a rate of the system in no component's units (a
    change of units of one component is a similarity of the Jacobian); 0 where there is
    none (a constant or nilpotent field, or a Jacobian not finite)."""
    rho = 0.0
    for _, J in jacobians:
        if J.size and J.shape[0] == J.shape[1] and np.all(np.isfinite(J)):
            rho = max(rho, float(np.max(np.abs(np.linalg.eigvals(J)))))
    return rho if math.isfinite(rho) else 0.0


def _own_rate(z0, jacobians, floor: float = 0.0) -> float:
    """The rate at which the start's largest component changes by its own size:
    ``|F_k| / |z0_k|`` to first order, ``sqrt(|(J F)_k| / |z0_k|)`` to second (J F the
    state's acceleration: a position at rest driven through its velocity), the faster over
    both fields (``jacobians``: pairs ``(F, J)``). In no unit (a ratio within one
    component), and the component the run's state scale S is measured from. A weak
    linear part (x'' = -sign(x) - 1e-8 x') has a spectral radius of 1e-8, over whose
    time every component's motion made S and T 2^26, events found to 1e-8 (a review);
    its largest component, x at rest, changes in time 1. Not every component's: one at
    a rounding of 0 (1e-82, a generated start) changes by its own size at once, and its
    rate said nothing of the orbit's time (T = 1e-81). Its size at least ``floor``, the
    scale measured for all (the fields' length up to 1): next to the origin, (1e-8, 1e-8,
    1e-8) of a spiral about (1, 0, 1), the position's rate through its velocity was
    sqrt(1 / 1e-8) and T 1.2e-4 for 1 (a review). 0 where the largest component is 0 or
    does not move."""
    z0 = np.abs(np.asarray(z0, dtype=float).reshape(-1))
    if not z0.size or not np.all(np.isfinite(z0)) or not z0.max() > 0.0:
        return 0.0
    k = int(np.argmax(z0))
    size = max(z0[k], floor)
    rate = 0.0
    for f, J in jacobians:
        f = np.asarray(f, dtype=float).reshape(-1)
        if f.shape != z0.shape or J.shape != (z0.size, z0.size):
            continue
        with np.errstate(all="ignore"):
            first = abs(f[k]) / size
            second = math.sqrt(abs(float(J[k] @ f)) / size)
        for r in (first, second):
            if math.isfinite(r):
                rate = max(rate, r)
    return rate


def system_rate(z0, jacobians, floor: float = 0.0) -> float:
    """The rate the component scales measure motion in: the larger of the fields'
    spectral radius (:func:`spectral_rate`) and the start's own rate (:func:`_own_rate`);
    the shorter time, so that no component's motion is measured over a time longer than
    the largest component takes to change. 0 where neither is."""
    return max(spectral_rate(jacobians), _own_rate(z0, jacobians, floor))


#: components whose measured scales spread beyond this factor are measured one by one
#: (:func:`component_scales`); within it the run keeps one scale for all of them
SPREAD = 2.0 ** 10


def component_scales(z0, fields, jacobians, S: float):
    """The scale of each component of a start ``z0`` (``fields``: ``F_-`` and ``F_+`` there,
    ``jacobians``: their Jacobians, :func:`field_jacobian`), or None where one scale
    ``S`` serves them all.

    Each component's extent is the larger of its size at the start and how far the fields
    move it in the time 1/rho (:func:`system_rate`: the larger of the two Jacobians'
    spectral radius and the start's own rate, rates that do not change with the units of
    any component, where the largest entry of the Jacobian, on which the run's time scale
    rests, does); its scale is that extent
    as a power of two (:func:`power_of_two`). Where the scales spread beyond
    :data:`SPREAD` (a clock counted in nanoseconds beside a position in metres, a large
    constant component, a velocity in units 1e9 smaller than its position), each
    component keeps its own, and a component with no extent (at 0 and not moving) the
    largest; else None, and a system written in one unit runs as before. A review found,
    with one scale for all: errors of 7.7e-6 for 1e-12 (a clock's scale for every
    component's atol), a start 1e-7 off H taken to be on it (G from a constant
    component), dP/dz off by 2.4e-4 (Richardson's steps from a scale 1e9 times the
    component's): docs/decisions.md#units."""
    z0 = np.abs(np.asarray(z0, dtype=float).reshape(-1))
    rho = system_rate(z0, jacobians, S)
    if rho == 0.0:
        return None   # no time of the system's own to measure the motion in
    extent = np.where(np.isfinite(z0), z0, 0.0)
    for f in fields:
        moved = np.abs(np.asarray(f, dtype=float).reshape(-1)) / rho
        if moved.shape == extent.shape:
            extent = np.maximum(extent, np.where(np.isfinite(moved), moved, 0.0))
    sized = [power_of_two(e) if 0.0 < e < math.inf else 0.0 for e in extent]
    top = max(sized, default=0.0)
    if top == 0.0:
        return None
    parts = _coupled(np.array([v if v > 0.0 else max(top, S) for v in sized]), jacobians,
                     rho)
    if parts.max() / parts.min() <= SPREAD:
        return None
    return tuple(float(v) for v in parts)


def _coupled(parts, jacobians, rho: float) -> np.ndarray:
    """``parts`` lifted where the fields' coupling says a component is larger: a
    component k that component j drives at ``|dF_k/dz_j|`` moves by
    ``|dF_k/dz_j| s_j / rho`` in the system's time, so its scale is at least that (a
    power of two, at most the largest). A start next to an equilibrium has components small only by where it
    lies -- (1, 1e-13) next to the focus (1, 0), whose y grows to 0.5 -- and their
    extents alone gave y a scale of 1e-13, an atol of 1e-27 and a step limit (an
    independent review's test); a component in units of its own (a velocity in units
    1e-9, a clock, a constant) is driven in its own units and keeps its scale. A few
    rounds: a lift may lift what it drives."""
    top = float(parts.max())
    for _ in range(parts.size):
        need = parts.copy()
        for _, J in jacobians:
            if J.shape != (parts.size, parts.size) or not np.all(np.isfinite(J)):
                continue
            drive = np.max(np.abs(J) * parts[None, :], axis=1) / rho
            need = np.maximum(need, drive)
        lifted = np.array([min(top, power_of_two(n)) if n > DEAD_BAND * p else p
                           for n, p in zip(need, parts)])
        if np.array_equal(lifted, parts):
            break
        parts = lifted
    return parts


def _switch_scale(grad, parts) -> float:
    """G of components of scales ``parts``: the largest change of H along one component
    over its own scale, ``max_k |dH/dz_k| s_k`` (``grad``: H's gradient, or rows of it at
    probes), a power of two; 1 where it is 0 or not finite."""
    if grad is None:
        return 1.0
    g = np.abs(np.atleast_2d(np.asarray(grad, dtype=float))) * parts
    top = float(g.max()) if g.size else 0.0
    return power_of_two(top) if math.isfinite(top) and top > 0.0 else 1.0


def of_system(system, z, value=None) -> Scale:
    """The units of a run of ``system`` (a :class:`~filippov.system.PiecewiseSystem`: its
    ``scale`` and its pieces) from ``z``: ``value`` (a run's option), else the system's
    declaration, each part it leaves open measured at z (:func:`measure_system`)."""
    def measure_at(state):
        return measure_system(z, system.field_minus, system.field_plus, system.switch_grad,
                              state)
    return resolve(system.scale if value is None else value, measure_at)


def of_batch(value, starts, pieces) -> Scale:
    """The units of a batch of runs (a map, a sweep): ``value`` (the run's option, else
    the system's declaration) with the parts it leaves open measured
    (:func:`measure_system`) at the batch's smallest and at its largest finite start
    (by largest component), and the smaller of the two taken part by part: a small start
    is never run at the tolerances of a large one. ``pieces(i)``: ``(field_minus,
    field_plus, switch_grad)`` of start i's system (functions of one state)."""
    starts = np.atleast_2d(np.asarray(starts, dtype=float))

    def measure_at(state):
        finite = np.flatnonzero(np.all(np.isfinite(starts), axis=1)) if starts.size else []
        if not len(finite):
            return measure(np.zeros(0), state=state)
        norms = np.max(np.abs(starts[finite]), axis=1) if starts.shape[1] else np.zeros(len(finite))
        rows = sorted({_by_value(starts, finite[norms == norms.min()]),
                       _by_value(starts, finite[norms == norms.max()])})
        found = [measure_system(starts[i], *pieces(i), state) for i in rows]
        bad = [s for s in found if s.how.startswith(OUT_OF_RANGE)]
        if bad:
            return bad[0]
        S, parts = min(s.state for s in found), None
        if any(s.components is not None for s in found):   # each component's smaller
            least = np.min([s.of_components(starts.shape[1]) for s in found], axis=0)
            parts = tuple(float(v) for v in least)
        return Scale(S, min(s.time for s in found), min(s.switch for s in found),
                     "measured", parts)
    return resolve(value, measure_at)


def _by_value(starts, rows) -> int:
    """The first of the tied ``rows`` of ``starts`` in the order of their values (last
    component first), not of their places: a batch's scale, and so every return of it, is
    the same in any order of its starts (a review: two starts tied for the largest, the
    first of them measured, and swapping them moved both returns by 2e-13)."""
    rows = np.asarray(rows)
    return int(rows[np.lexsort(starts[rows].T)[0]])


def declared(value, field: str = "scale"):
    """A user's ``scale=``: None (measured at the start), a :class:`Scale`, a positive
    number (the state's scale; time and H measured) or a mapping with any of "state",
    "time", "switch" (the rest measured). Returns a Scale, or a dict of the declared
    parts (possibly empty: all measured). A bad value is a ValueError naming the field."""
    if value is None:
        return {}
    if isinstance(value, Scale):
        parts = {"state": value.state, "time": value.time, "switch": value.switch}
    elif isinstance(value, dict):
        unknown = set(value) - {"state", "time", "switch"}
        if unknown:
            raise ValueError(f"{field}: unknown part(s) {sorted(unknown)}; a scale has "
                             f"'state', 'time' and 'switch'")
        parts = dict(value)
    else:
        parts = {"state": value}
    for k, v in parts.items():
        ok = (not isinstance(v, (bool, np.bool_)) and isinstance(v, (int, float, np.integer,
                                                                     np.floating))
              and math.isfinite(float(v)) and float(v) > 0.0)
        if not ok:
            raise ValueError(f"{field}.{k} must be a finite number > 0, got {v!r}")
    parts = {k: float(v) for k, v in parts.items()}
    if isinstance(value, Scale) and value.components is not None:
        c = np.asarray(value.components, dtype=float)
        if c.ndim != 1 or not np.all(np.isfinite(c) & (c > 0.0)):
            raise ValueError(f"{field}.components must be finite numbers > 0, one a "
                             f"component, got {value.components!r}")
    if isinstance(value, Scale):
        return Scale(parts["state"], parts["time"], parts["switch"], value.how,
                     value.components)
    return parts


def resolve(value, measure_at) -> Scale:
    """The scale a run uses: ``value`` as :func:`declared` reads it, with the parts it
    leaves open taken from ``measure_at(state)`` (called only then, with the declared
    state scale or None; returns a Scale). A measured size out of range
    (:data:`OUT_OF_RANGE`) is a ValueError naming the initial state."""
    parts = declared(value)
    if isinstance(parts, Scale):
        return parts
    if len(parts) == 3:
        return Scale(parts["state"], parts["time"], parts["switch"], "declared")
    m = measure_at(parts.get("state"))
    if m.how.startswith(OUT_OF_RANGE):
        size = m.how[len(OUT_OF_RANGE):].strip()
        raise ValueError(
            f"initial state: its size {size} (or the fields' length there) lies outside "
            f"2^-{MAX_EXPONENT} .. 2^{MAX_EXPONENT} (about 4.9e-91 .. 2e90), where a run's "
            f"tolerances can be measured (filippov.scale): write the system in other "
            f"units, or declare its scale (scale=...)")
    how = "measured" if not parts else "declared+measured"
    # components measured only with the state scale (a declared S is every component's)
    return Scale(parts.get("state", m.state), parts.get("time", m.time),
                 parts.get("switch", m.switch), how,
                 None if "state" in parts else m.components)


def tolerances(opts: dict, scale: Scale, n: int) -> dict:
    """``opts`` with the absolute tolerances in the run's units: atol x S (x each of the
    ``n`` components' scales, where measured), touch_tol x G, event_xtol x T (those
    present), and the floors the rules take (state_scale, time_scale)."""
    out = dict(opts)
    for name, factor in (("touch_tol", scale.switch), ("event_xtol", scale.time)):
        if name in out:
            out[name] = out[name] * factor
    if "atol" in out:
        out["atol"] = scale.absolute(out["atol"], n)
    out["state_scale"], out["time_scale"] = scale.state, scale.time
    return out
