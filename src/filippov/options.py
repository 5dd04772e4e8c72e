"""The solver options both engines take, checked once, by one rule each.

:func:`filippov.simulate.simulate` and :func:`filippov.fastmap.compute_returns` share
their tolerances and limits; before this module each checked them on its own and the two
disagreed (``zeno_count >= 2`` on one side, ``>= 1`` on the other; ``rtol``, ``atol``,
``touch_tol``, ``event_xtol``, ``zeno_span``, ``max_events`` and ``max_steps`` checked
by the reference driver only). A bad value is refused with its name and the bound.
"""
from __future__ import annotations

import math

import numpy as np

#: (lower bound, strict, infinity allowed) of each real option
NUMBERS = {
    "rtol": (0.0, True, False),
    "atol": (0.0, True, False),
    "max_step": (0.0, True, True),
    "touch_tol": (0.0, False, False),
    "event_xtol": (0.0, True, False),
    "zeno_span": (0.0, False, False),
}
#: the largest value of the options that have one: an event's time and a touch of H are
#: tolerances of the event rules, which a value near the scale itself (T, G) silently
#: turns into other events (a review: event_xtol = 1 moved a relay's return from 4.021 to
#: 4.037 with no word)
UPPER = {"touch_tol": 1e-6, "event_xtol": 1e-6}
#: the options that are True or False (a string "no" is refused, not read as true)
FLAGS = ("stiff", "dense", "jacobian", "sliding")
#: the least value of each integer option; zeno_count: the Zeno ring compares the
#: newest switch with the zeno_count-th before it, so one switch is no accumulation
INTEGERS = {
    "max_events": 1,
    "max_steps": 1,
    "samples_per_step": 1,
    "zeno_count": 2,
}


def number(v) -> float | None:
    """``v`` as a float if it is a real number a float holds, else None (a bool, a string,
    an int too large for a float). Then math's tests, not numpy's: a ufunc on a scalar
    costs a microsecond, and compute_returns checks its options at every call (fig12
    makes 72,000 calls)."""
    if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer,
                                                                 np.floating)):
        return None
    try:
        return float(v)
    except OverflowError:
        return None


def finite(v) -> bool:
    """A finite real number (:func:`number`)."""
    x = number(v)
    return x is not None and math.isfinite(x)


def flag(name: str, v) -> bool:
    """``v`` as True or False: a bool, or the integers 0 and 1; anything else (a string
    such as "no", which Python reads as true) refused naming ``name``."""
    if isinstance(v, (bool, np.bool_)) or (isinstance(v, (int, np.integer)) and v in (0, 1)):
        return bool(v)
    raise ValueError(f"{name} must be True or False, got {v!r}")


def check(**opts) -> None:
    """Refuse any of ``opts`` (the names above) out of range, naming it."""
    for name, v in opts.items():
        if name in NUMBERS:
            low, strict, allow_inf = NUMBERS[name]
            x = number(v)
            ok = (x is not None and not math.isnan(x) and (allow_inf or math.isfinite(x))
                  and (x > low if strict else x >= low))
            high = UPPER.get(name, math.inf)
            if not ok or x > high:
                bound = f"> {low}" if strict else f">= {low}"
                if high < math.inf:
                    bound += f" and <= {high:g} (in units of the run's scale, filippov.scale)"
                raise ValueError(f"{name} must be a {'' if allow_inf else 'finite '}number "
                                 f"{bound}, got {v!r}")
        elif name in INTEGERS:
            low = INTEGERS[name]
            if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, np.integer)) \
                    or v < low:
                raise ValueError(f"{name} must be an integer >= {low}, got {v!r}")
        elif name in FLAGS:
            flag(name, v)
        else:
            raise TypeError(f"unknown solver option {name!r}")
