"""Where a stable periodic orbit of a map stops being the attractor: follow it in a
parameter until it loses stability or ends, and say how.

A window of period n in an orbit diagram is read from one start point per parameter
value, so its edges there are basin boundaries: where two attractors coexist, the start
decides which one is seen. The bifurcations that bound the window belong to the orbit
itself. :func:`follow` continues the period-n orbit from a parameter where it is the
attractor (Newton from the previous point, the caller's ``orbit_at``) in steps towards a
limit, and brackets and bisects the first parameter where the continued orbit

* has a multiplier crossing -1 (``FLIP``, period doubling),
* has a multiplier crossing +1 or cannot be continued with its multiplier near +1
  (``FOLD``, saddle-node),
* changes its itinerary or cannot be continued with a multiplier away from +-1
  (``BORDER``: an orbit point reaches the border of a piecewise-smooth map -- a
  grazing of the switching surface -- where P is not smooth and the orbit ends or
  jumps: a border collision),
* has complex multipliers leaving the unit circle (``TORUS``).

The engine-specific part (how an orbit is found, its multiplier, its itinerary) is the
caller's: the same bisection serves the slow-fast system and the limit maps.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
from .errors import BranchError  # noqa: F401  (re-exported)

FLIP, BORDER, FOLD, TORUS, BEYOND = -1, 0, 1, 3, 2
KINDS = {FLIP: "period doubling (multiplier -1)", BORDER: "border collision (grazing)",
         FOLD: "fold (multiplier +1)", TORUS: "torus (complex pair leaves the unit circle)",
         BEYOND: "stable up to the limit of the range"}
#: an orbit that cannot be continued while its multiplier lies within this of +1 ends at
#: a fold: near a fold the multiplier approaches 1 like the square root of the distance,
#: 1 - c sqrt(xtol) ~ 1 - 3e-5 c at xtol = 1e-9, while at a border collision it stays
#: where the smooth part of the map puts it (O(lambda^n), far from 1)
FOLD_NEAR = 1e-2


@dataclass(frozen=True)
class Orbit:
    """A periodic orbit as the caller's ``orbit_at`` finds it."""

    state: np.ndarray        # the point Newton starts from at the next parameter
    value: float             # the watched coordinate of that point
    multiplier: complex      # the nontrivial multiplier of largest modulus
    itinerary: tuple         # which pieces of the map the orbit's points lie in


@dataclass(frozen=True)
class BranchEnd:
    parameter: float         # where the orbit stops being stable (NaN: BEYOND)
    kind: int                # FLIP, BORDER, FOLD, TORUS or BEYOND
    inside: Orbit            # the last stable orbit, within xtol of ``parameter``
    outside: str             # what was found just past it (for messages and tests)
    evaluations: int


def _stable(o: Orbit) -> bool:
    return bool(abs(o.multiplier) < 1.0)


def follow(orbit_at: Callable[[float, np.ndarray], Orbit], start: float, guess,
           limit: float, *, step: float, xtol: float, near: float,
           max_evaluations: int = 2000) -> BranchEnd:
    """Follow the stable orbit found by ``orbit_at(start, guess)`` from ``start``
    towards ``limit`` in steps of ``step`` (> 0, the direction is limit's), and locate to
    ``xtol`` where it stops being stable (see the module docstring for the kinds).

    ``orbit_at(p, guess) -> Orbit`` raises (any Exception) where Newton fails. A
    continued orbit counts as the same one only if its itinerary is the same and its
    ``value`` moved by at most ``near`` from the last one (Newton may otherwise land on
    another orbit across a border)."""
    if not (step > 0 and xtol > 0 and near > 0):
        raise ValueError(f"need step, xtol, near > 0, got {step!r}, {xtol!r}, {near!r}")
    count = [0]

    def attempt(p, last: Orbit):
        count[0] += 1
        try:
            o = orbit_at(p, last.state)
        except Exception as exc:     # Newton failed or a return did not come back
            return None, f"no orbit ({type(exc).__name__}: {str(exc)[:120]})"
        if o.itinerary != last.itinerary:
            return o, f"itinerary {o.itinerary} instead of {last.itinerary}"
        if not abs(o.value - last.value) <= near:
            return o, f"jumped by {o.value - last.value:.3g} (> near = {near:g})"
        if not _stable(o):
            return o, f"multiplier {o.multiplier:.6g}"
        return o, ""

    try:
        first = orbit_at(start, np.asarray(guess, dtype=float))
    except Exception as exc:
        raise BranchError(f"no orbit at the start {start!r}: {exc}") from None
    if not _stable(first):
        raise BranchError(f"the orbit at the start {start!r} is not stable (multiplier "
                          f"{first.multiplier:.6g})")
    direction = np.sign(limit - start)
    lo, hi = min(start, limit), max(start, limit)
    a, last = float(start), first
    while True:
        b = None
        while b is None:
            if a == limit:
                return BranchEnd(np.nan, BEYOND, last, "", count[0])
            p = float(np.clip(a + direction * step, lo, hi))
            o, why = attempt(p, last)
            if why:
                b, out_o, out_why = p, o, why
            else:
                a, last = p, o
        while abs(b - a) > xtol:
            m = 0.5 * (a + b)
            o, why = attempt(m, last)
            if why:
                b, out_o, out_why = m, o, why
            else:
                a, last = m, o
        # b failed from a guess up to a step away; from next to it (within xtol) the
        # orbit may be there after all (Newton's basin, not the orbit's end): go on
        o, why = attempt(b, last)
        if why:
            out_o, out_why = o, why
            break
        a, last = b, o
        if count[0] > max_evaluations:
            raise BranchError(f"no end found in {max_evaluations} evaluations (from "
                              f"{start!r} to {a!r}): Newton keeps failing a little ahead")
    return BranchEnd(0.5 * (a + b), _kind(last, out_o, out_why), last, out_why, count[0])


def _kind(inside: Orbit, outside: Orbit | None, why: str) -> int:
    same = outside is not None and outside.itinerary == inside.itinerary and \
        why.startswith("multiplier")
    if same:
        m = outside.multiplier
        if abs(np.imag(m)) > 1e-12 * max(1.0, abs(m)):
            return TORUS
        return FLIP if np.real(m) < 0 else FOLD
    return FOLD if abs(inside.multiplier - 1.0) < FOLD_NEAR else BORDER
