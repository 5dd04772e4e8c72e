"""The benchmarks' one timing convention: warm up, then time rounds; median and min.

What a wall time in a benchmark table means (the hygiene of pytest-benchmark and asv,
without their machinery):

* **warm-up**: ``warmup`` untimed calls first (default one), so that what a process
  pays once -- numba compiling or loading a kernel, the generated model pieces, imports
  and caches filled on first use -- is paid before the clock runs. A first call is a
  measurement of compilation, not of the method;
* **rounds**: then timed calls, at least ``min_rounds`` of them and more until
  ``min_time`` seconds were timed in all (a millisecond call is timed many times,
  a second-long one ``min_rounds`` times), never more than ``max_rounds``;
* **statistic**: the *median* of the rounds is the number shown (robust to a round
  disturbed by another process on a shared machine); the *min* (the run least
  disturbed) and the number of rounds are kept next to it.

A per-call time cap is the caller's business (the work-precision runners raise
:class:`filippov_paper.benchmarks.baseline.TimeCapExceeded` themselves). Write
:func:`describe` into a dataset's attributes to say which statistic it shows.
"""
from __future__ import annotations

import os
import statistics
import time
from dataclasses import dataclass, field
from typing import Any, Callable

#: the statistic a benchmark table shows (the min is stored next to it)
STATISTIC = "median"
#: the defaults of :func:`measure`
WARMUP, MIN_ROUNDS, MIN_TIME, MAX_ROUNDS = 1, 3, 0.2, 1000


@dataclass(frozen=True)
class Timing:
    """The timed rounds of one measurement (seconds)."""
    median: float
    min: float
    rounds: int
    warmup: int = 0
    total: float = 0.0  # seconds timed over all rounds (warm-up not included)
    value: Any = field(default=None, repr=False, compare=False)  # the last round's result

    @property
    def shown(self) -> float:
        """The statistic a table shows (:data:`STATISTIC`)."""
        return getattr(self, STATISTIC)


def measure(fn: Callable[[], Any], *, warmup: int = WARMUP, min_rounds: int = MIN_ROUNDS,
            min_time: float = MIN_TIME, max_rounds: int = MAX_ROUNDS,
            clock: Callable[[], float] = time.perf_counter) -> Timing:
    """Time ``fn()``: ``warmup`` untimed calls, then rounds until there are at least
    ``min_rounds`` and ``min_time`` seconds were timed, at most ``max_rounds``.
    An exception of ``fn`` (warm-up or round) propagates: nothing is timed half."""
    if warmup < 0 or min_rounds < 1 or max_rounds < min_rounds or not min_time >= 0:
        raise ValueError(f"measure: need warmup >= 0, 1 <= min_rounds <= max_rounds and "
                         f"min_time >= 0 (got {warmup}, {min_rounds}, {max_rounds}, {min_time})")
    for _ in range(warmup):
        fn()
    times, value = [], None
    while len(times) < min_rounds or (sum(times) < min_time and len(times) < max_rounds):
        t0 = clock()
        value = fn()
        times.append(clock() - t0)
    return Timing(statistics.median(times), min(times), len(times), warmup, sum(times), value)


def describe(*, warmup: int = WARMUP, min_rounds: int = MIN_ROUNDS, min_time: float = MIN_TIME,
             max_rounds: int = MAX_ROUNDS) -> dict:
    """The dataset attributes that say how its times were measured and which statistic
    it shows (``timing_statistic``)."""
    return {"timing_statistic": STATISTIC, "timing_warmup": int(warmup),
            "timing_min_rounds": int(min_rounds), "timing_min_time": float(min_time),
            "timing_max_rounds": int(max_rounds),
            "timing": f"{STATISTIC} of at least {min_rounds} timed rounds (more until "
                      f"{min_time:g} s were timed, at most {max_rounds}) after {warmup} "
                      f"untimed warm-up call(s); the min is stored as well"}


def load_attrs(load_before, load_after) -> dict:
    """The dataset attributes that say how loaded the machine was while a benchmark ran
    (``os.getloadavg()`` before and after it) and how many CPUs it has."""
    return {"load_average_before": float(load_before[0]),
            "load_average_after": float(load_after[0]), "cpus": os.cpu_count() or 1}
