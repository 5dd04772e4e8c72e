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
  disturbed by another process on a shared machine), always with its *spread*: the
  interquartile range (first to third quartile, :data:`SPREAD`); the *min* (the run
  least disturbed), the max and the number of rounds are kept next to it;
* **interleaving** (:func:`measure_interleaved`, as asv runs its rounds): several
  things timed against each other get their rounds in passes -- a share of the rounds
  of every one, then the next share of every one, ... -- so that a spell of load from
  another process falls on all of them alike, not on whichever was timed during it;
* **machine**: :func:`machine_attrs` and :func:`load_attrs` say where and under what
  load the times were taken (CPU model, cores, load average before and after, the
  versions of Python, numpy, scipy and numba).

A per-call time cap is the caller's business (the work-precision runners raise
:class:`filippov_paper.benchmarks.baseline.TimeCapExceeded` themselves). Write
:func:`describe` into a dataset's attributes to say which statistic it shows, and
:func:`variables` for the data variables of a timed quantity: the median under its own
name, its spread and extremes under ``_q1``, ``_q3``, ``_min`` and ``_max`` (the naming of
the work-precision dataset); a ratio of two timed quantities is a range
(:func:`ratio_range`), never one number alone.
"""
from __future__ import annotations

import math
import os
import platform
import statistics
import time
from dataclasses import dataclass, field
from typing import Any, Callable, Sequence, Union

import numpy as np

#: the statistic a benchmark table shows (the min is stored next to it)
STATISTIC = "median"
#: the spread shown with it: the first and third quartile of the rounds
SPREAD = "interquartile range"
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
    q1: float = math.nan   # first quartile of the rounds (the spread: q1 to q3)
    q3: float = math.nan   # third quartile
    max: float = math.nan  # the slowest round

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
    return of_rounds(times, warmup, value)


def quartiles(times: Sequence[float]) -> tuple[float, float, float]:
    """First quartile, median and third quartile of ``times`` (linear interpolation
    between the order statistics, numpy's default; of one round: that round thrice)."""
    x = sorted(float(t) for t in times)
    if not x:
        raise ValueError("quartiles of no rounds")

    def at(q):
        pos = q * (len(x) - 1)
        lo = math.floor(pos)
        hi = min(lo + 1, len(x) - 1)
        return x[lo] + (pos - lo) * (x[hi] - x[lo])
    return at(0.25), statistics.median(x), at(0.75)


def of_rounds(times: Sequence[float], warmup: int = 0, value: Any = None) -> Timing:
    """The :class:`Timing` of the timed rounds ``times`` (seconds)."""
    q1, med, q3 = quartiles(times)
    return Timing(med, min(times), len(times), warmup, sum(times), value, q1, q3, max(times))


def measure_interleaved(fns: Sequence[Callable[[], Any]], *,
                        warmup: Union[int, Callable[[int], int]] = WARMUP,
                        min_rounds: int = MIN_ROUNDS, min_time: float = MIN_TIME,
                        max_rounds: int = MAX_ROUNDS, passes: int | None = None,
                        clock: Callable[[], float] = time.perf_counter,
                        before: Callable[[int, int], None] | None = None) -> list:
    """Time every ``fns[k]()`` by the rule of :func:`measure` (at least ``min_rounds``
    rounds, more until ``min_time`` s were timed, at most ``max_rounds``), with the
    rounds of all of them interleaved in ``passes`` passes (default ``min_rounds``):
    pass p (of P) takes each function, in the order given, to ``p/P`` of that rule
    (at least ceil(p min_rounds / P) rounds, more until p min_time / P s were timed,
    at most ceil(p max_rounds / P)), so its rounds are spread over the whole
    measurement. A function's warm-up calls (``warmup``: a count, or a function of its
    index called just before them) come right before its first round, in the first
    pass. ``before(pass, k)``, if given, is called before each function's turn.

    Per function: its :class:`Timing`, or the exception it raised (warm-up or round;
    it is dropped from the later passes, nothing of it is timed half)."""
    passes = min_rounds if passes is None else passes
    if not (passes >= 1 and min_rounds >= 1 and max_rounds >= min_rounds and min_time >= 0):
        raise ValueError(f"measure_interleaved: need passes >= 1, 1 <= min_rounds <= "
                         f"max_rounds and min_time >= 0 (got {passes}, {min_rounds}, "
                         f"{max_rounds}, {min_time})")
    n = len(fns)
    times: list[list[float]] = [[] for _ in range(n)]
    values: list = [None] * n
    warmed = [0] * n
    failed: dict[int, BaseException] = {}
    for p in range(1, passes + 1):
        need = math.ceil(p * min_rounds / passes)
        cap = math.ceil(p * max_rounds / passes)
        budget = p * min_time / passes
        for k, fn in enumerate(fns):
            if k in failed:
                continue
            if before is not None:
                before(p, k)
            try:
                if p == 1:
                    warmed[k] = warmup(k) if callable(warmup) else int(warmup)
                    for _ in range(warmed[k]):
                        fn()
                got = times[k]
                while len(got) < need or (sum(got) < budget and len(got) < cap):
                    t0 = clock()
                    values[k] = fn()
                    got.append(clock() - t0)
            except Exception as exc:  # kept for the caller, never dropped silently
                failed[k] = exc
    return [failed[k] if k in failed else of_rounds(times[k], warmed[k], values[k])
            for k in range(n)]


def interleaved_rows(rows: Sequence[Sequence[Callable[[], Any]]], **options) -> list:
    """:func:`measure_interleaved` over a table of functions (``rows``: one list per case),
    all of them interleaved; the Timings in the table's shape. The first function that
    failed raises its exception (a benchmark's table has no hole). ``options`` as
    there."""
    got = iter(measure_interleaved([fn for row in rows for fn in row], **options))
    table = [[next(got) for _ in row] for row in rows]
    for t in (t for row in table for t in row):
        if not isinstance(t, Timing):
            raise t
    return table


#: the data variables of a timed quantity ``name`` (:func:`variables`): (suffix, the
#: Timing's field, long_name with ``{what}`` and ``{name}`` to fill in)
STORED = (("", "median", "median {what} over the timed rounds"),
          ("_q1", "q1", "first quartile of the {what} over the timed rounds (the spread of "
                        "{name}: q1 to q3)"),
          ("_q3", "q3", "third quartile of the {what} over the timed rounds"),
          ("_min", "min", "min {what} (the fastest timed round)"),
          ("_max", "max", "max {what} (the slowest timed round)"))


def variables(name: str, dims, timings, what: str, *, per: float = 1.0,
              units: str = "s") -> dict:
    """The data variables of the timed quantity ``name`` over ``dims``: ``name`` the
    median of the rounds, ``name_q1`` and ``name_q3`` its spread, ``name_min`` and
    ``name_max`` the fastest and slowest round (:data:`STORED`), each with long_name,
    units and ``statistic`` as in the work-precision dataset. ``timings``: nested lists
    (the shape of ``dims``) of :class:`Timing`, or of anything else (an exception, None)
    for what was not timed (NaN); ``per``: each time divided by it (e.g. the returns of a
    call, for a time per return); ``what``: the quantity in words ("wall time per return")."""
    cells = np.asarray(timings, dtype=object)  # a Timing is one cell (not a sequence)
    out = {}
    for suffix, stat, long_name in STORED:
        values = np.full(cells.shape, np.nan)
        for idx in np.ndindex(cells.shape):
            if isinstance(cells[idx], Timing):
                values[idx] = getattr(cells[idx], stat) / per
        out[name + suffix] = (tuple(dims), values, {
            "long_name": long_name.format(what=what, name=name), "units": units,
            "statistic": stat})
    return out


def rounds(timings) -> np.ndarray:
    """The timed rounds of each of ``timings`` (nested lists as for :func:`variables`;
    0 for what was not timed)."""
    cells = np.asarray(timings, dtype=object)
    out = np.zeros(cells.shape, dtype=np.int32)
    for idx in np.ndindex(cells.shape):
        if isinstance(cells[idx], Timing):
            out[idx] = cells[idx].rounds
    return out


def ratio_range(num: Timing, den: Timing) -> tuple[float, float, float]:
    """``num`` over ``den``: the ratio of the medians, and its range from the spread (the
    work-precision speed-ups' rule): ``num``'s first quartile over ``den``'s third, its
    third over ``den``'s first. The medians' ratio lies in the range."""
    return num.median / den.median, num.q1 / den.q3, num.q3 / den.q1


def describe(*, warmup: int = WARMUP, min_rounds: int = MIN_ROUNDS, min_time: float = MIN_TIME,
             max_rounds: int = MAX_ROUNDS, passes: int | None = None) -> dict:
    """The dataset attributes that say how its times were measured and which statistic
    it shows (``timing_statistic``) with which spread (``timing_spread``); ``passes``:
    the rounds were interleaved in that many passes (:func:`measure_interleaved`)."""
    out = {"timing_statistic": STATISTIC, "timing_spread": SPREAD, "timing_warmup": int(warmup),
           "timing_min_rounds": int(min_rounds), "timing_min_time": float(min_time),
           "timing_max_rounds": int(max_rounds),
           "timing": f"{STATISTIC} of at least {min_rounds} timed rounds (more until "
                     f"{min_time:g} s were timed, at most {max_rounds}) after {warmup} "
                     f"untimed warm-up call(s), with the {SPREAD} of the rounds; the min "
                     f"and max are stored as well"}
    if passes is not None:
        out["timing_passes"] = int(passes)
        out["timing_order"] = "interleaved"
        out["timing"] += (f"; the rounds of all configurations interleaved in {passes} "
                          f"passes (a share of every one's rounds per pass)")
    return out


def load_attrs(load_before, load_after) -> dict:
    """The dataset attributes that say how loaded the machine was while a benchmark ran
    (``os.getloadavg()`` before and after it) and how many CPUs it has."""
    return {"load_average_before": float(load_before[0]),
            "load_average_after": float(load_after[0]), "cpus": os.cpu_count() or 1}


def cpu_model() -> str:
    """The CPU's model name (Linux: /proc/cpuinfo; else what :mod:`platform` says)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, val = line.partition(":")
                if key.strip() in ("model name", "Processor", "cpu model") and val.strip():
                    return " ".join(val.split())
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def machine_attrs() -> dict:
    """The dataset attributes that say on what the times were taken: the CPU model
    (``machine_cpu``), its logical cores (``cpus``), the operating system and the
    versions of Python, numpy, scipy and numba (``python_version``, ...). Together with
    :func:`load_attrs`: what a reader needs to judge a measured time."""
    import numpy
    import scipy

    try:
        import numba
        numba_version = numba.__version__
    except ImportError:  # numba absent: nothing compiled
        numba_version = "none"
    return {"machine_cpu": cpu_model(), "cpus": os.cpu_count() or 1,
            "machine_system": f"{platform.system()} {platform.release()} {platform.machine()}",
            "python_version": platform.python_version(), "numpy_version": numpy.__version__,
            "scipy_version": scipy.__version__, "numba_version": numba_version}
