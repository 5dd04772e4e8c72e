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
largest start (:func:`of_batch`).
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

    @property
    def is_unit(self) -> bool:
        return self.state == 1.0 and self.time == 1.0 and self.switch == 1.0


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


def _rate(field, z0, f0, k: int, size: float) -> float:
    """``|dF/dz_k|`` near z0, by the shortest step ``2^j`` along coordinate k (j by
    bisection, from ``sqrt(eps) size`` up to ``2^MAX_EXPONENT``: a dozen evaluations) that
    changes F by ``sqrt(eps) |F(z0)|``, above its rounding; 0 where no step does, or F is
    not finite."""
    root, target = math.sqrt(np.finfo(float).eps), math.sqrt(np.finfo(float).eps) * _inf_norm(f0)

    def change(j):   # a probe that raises or is not finite tells nothing: inf
        z = z0.copy()
        z[k] += math.ldexp(1.0, j)
        try:
            c = _inf_norm(np.asarray(field(z), dtype=float) - f0)
        except Exception:   # noqa: BLE001 -- a piece undefined there: the run never goes
            return math.inf
        return c if math.isfinite(c) else math.inf

    lo = max(-MAX_EXPONENT, math.frexp(root * size)[1] - 1) if size > 0.0 else -MAX_EXPONENT
    # probes stay within 2^PROBE_REACH of the start's size (or of 1): a piece written for
    # its own range (an angle wrapped by a loop) is never asked at 2^300
    hi = min(MAX_EXPONENT, math.frexp(max(size, 1.0))[1] + PROBE_REACH)
    if not change(hi) >= target:
        return 0.0
    if change(lo) >= target:
        hi = lo
    while hi - lo > 1:   # change(lo) below the target, change(hi) at or above it
        mid = (lo + hi) // 2
        if change(mid) >= target:
            hi = mid
        else:
            lo = mid
    c = change(hi)
    return c / math.ldexp(1.0, hi) if math.isfinite(c) else 0.0


def field_rates(field, z0) -> tuple[float, float]:
    """``(|F(z0)|, max_k |dF/dz_k|)`` of ``field`` (a function of one state) near ``z0``,
    each rate from the shortest step that changes F above its rounding (:func:`_rate`;
    at a zero of F, the change of F over the shortest probe). (0, 0) where F is not
    finite at z0."""
    z0 = np.asarray(z0, dtype=float)
    f0 = np.asarray(field(z0), dtype=float)
    speed = _inf_norm(f0)
    if not math.isfinite(speed):
        return 0.0, 0.0
    return speed, max((_rate(field, z0, f0, k, _inf_norm(z0)) for k in range(z0.size)),
                      default=0.0)


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
    e_k``). About ``2 (12 n + 1) + 1`` evaluations of the pieces."""
    z0 = np.asarray(z0, dtype=float).reshape(-1)
    try:
        fields = (field_minus(z0), field_plus(z0))
        rates = [field_rates(f, z0) for f in (field_minus, field_plus)]
    except Exception:   # noqa: BLE001 -- the run's own checks name a piece that fails
        return measure(z0, state=state)   # the start's size alone
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
    return Scale(out.state, out.time, out.switch, sized.how)


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
        return bad[0] if bad else Scale(min(s.state for s in found),
                                        min(s.time for s in found),
                                        min(s.switch for s in found), "measured")
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
    if isinstance(value, Scale):
        return Scale(parts["state"], parts["time"], parts["switch"], value.how)
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
    return Scale(parts.get("state", m.state), parts.get("time", m.time),
                 parts.get("switch", m.switch), how)


def tolerances(opts: dict, scale: Scale) -> dict:
    """``opts`` with the absolute tolerances in the run's units: atol x S, touch_tol x G,
    event_xtol x T (those present), and the floors the rules take (state_scale,
    time_scale)."""
    out = dict(opts)
    for name, factor in (("atol", scale.state), ("touch_tol", scale.switch),
                         ("event_xtol", scale.time)):
        if name in out:
            out[name] = out[name] * factor
    out["state_scale"], out["time_scale"] = scale.state, scale.time
    return out
