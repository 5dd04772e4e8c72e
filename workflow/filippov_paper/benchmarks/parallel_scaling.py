"""How a batch of returns scales with the threads of compute_returns(workers=...).

Run ``python -m filippov_paper.benchmarks.parallel_scaling`` (part of ``make bench``). For each
case (theta, eps, s) of the iterated Hopf return map, a batch of ``--starts`` start points
near the cycle is iterated ``--returns`` times each in one call of
:func:`filippov.fastmap.compute_returns`, with 1, 2, ... workers up to the cores this
process may use, timed by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`):
the calls of every case and worker count interleaved in ``--repeat`` passes
(:func:`~filippov_paper.benchmarks.timing.measure_interleaved`: a spell of load falls on
every worker count alike, not on the one timed while it lasted), each with an untimed
warm-up call, then at least ``--repeat`` timed calls, more until :data:`MIN_TIME` s were
timed. Every time is stored as the median of the calls with its spread (``_q1`` to
``_q3``) and the fastest and slowest call (``_min``, ``_max``).

Beside the wall clock, what a loaded machine does not distort as much:

* ``cpu``: the process's CPU time per call (all threads): the work, and what threads add
  to it (``cpu efficiency`` = CPU time with 1 worker / CPU time with N); ``busy`` = CPU
  time / wall time, the cores the call kept busy on average: above what 1 worker gets,
  the threads did run at once (the kernel releases the GIL);
* ``span``: the CPU time of the busiest thread of a call (each thread's own clock): the
  wall time the call would take with a core per thread and no one else on the machine,
  so ``span speedup`` = CPU time with 1 worker / span is the speedup that the cores
  would give unloaded.

The wall-clock speedup is measured too (calls with 1 worker over calls with N: the
ratio of the medians, ``speedup``, and its range from the quartiles, ``speedup_low`` to
``speedup_high``; the table gives every ratio as such a range) but depends on what else
runs: the machine and its load average (``os.getloadavg``) before and after are stored
and printed with the table.
"""
from __future__ import annotations

import os
import threading
import time
from contextlib import contextmanager

import numpy as np
import xarray as xr

from filippov import fastmap
from filippov.analytic import limit_map
from filippov.fastmap import OK, compute_returns
from filippov.io import finalize
from filippov.models import hopf
from filippov_paper.benchmarks import command_line, timing
from filippov_paper.benchmarks.attractor_cost import case_coords

#: (theta, eps, s): the cascade (theta < 0, exact flows) and the chaos (theta > 0,
#: sliding integrated), as in filippov_paper.benchmarks.attractor_cost
CASES = [(-0.5, 1e-2, 1.0), (0.2, 1e-3, 2.0)]
OMEGA = 8 * np.pi
#: seconds timed per case and worker count at least (timing.measure's min_time)
MIN_TIME = 1.0


@contextmanager
def _thread_clocks():
    """Record each kernel call's CPU time on its own thread (time.thread_time) while the
    block runs: yields the list the times go to. Wraps fastmap.kernel, which
    compute_returns looks up at each call; nothing else changes."""
    spans, lock, kernel = [], threading.Lock(), fastmap.kernel

    def timed_kernel(derivatives=False):
        batch = kernel(derivatives)

        def call(*args):
            t0 = time.thread_time()
            batch(*args)
            dt = time.thread_time() - t0
            with lock:
                spans.append((threading.get_ident(), dt))
        return call

    fastmap.kernel = timed_kernel
    try:
        yield spans
    finally:
        fastmap.kernel = kernel


def cores() -> int:
    """The cores this process may use (what compute_returns' default counts)."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:
        return os.cpu_count() or 1


class Batch:
    """One case's batch with ``workers`` threads: a call is one call of compute_returns,
    its process CPU time and the CPU time of its busiest thread recorded (``cpu``,
    ``spans``: one entry a call, the warm-up call's first)."""

    def __init__(self, cm, z0, returns: int, workers: int):
        self.cm, self.z0, self.returns, self.workers = cm, z0, returns, workers
        self.cpu, self.spans = [], []

    def __call__(self):
        c0 = time.process_time()
        with _thread_clocks() as clocks:
            out = compute_returns(self.cm, self.z0, 1.0, iterations=self.returns, keep=1,
                                  workers=self.workers)
        self.cpu.append(time.process_time() - c0)
        # the busiest thread of this call: the sum of its slices' CPU times
        per_thread = {}
        for ident, dt in clocks:
            per_thread[ident] = per_thread.get(ident, 0.0) + dt
        self.spans.append(max(per_thread.values()))
        return out


def batches(theta: float, eps: float, s: float, starts: int, returns: int,
            workers: list) -> list:
    """The case's :class:`Batch` for each worker count: ``starts`` start points along the
    section around the cycle's point (x2 = sqrt(mu))."""
    mu = 1.0 + s * limit_map.scale(eps, theta)
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0)
    x2 = np.sqrt(mu) * np.linspace(0.98, 1.02, starts)
    z0 = np.stack([np.zeros(starts), x2, np.zeros(starts)], axis=1)
    return [Batch(cm, z0, returns, n) for n in workers]


def measure(cases, starts: int, returns: int, repeat: int, workers: list) -> list:
    """Per case, per worker count: the Timings of the wall time, the process's CPU time
    and the busiest thread's CPU time of a call (the timed rounds: the warm-up call
    left out), the returns done and the start points that returned. The calls of all
    cases and worker counts are interleaved; a failed call, or results that differ
    between worker counts, raise."""
    table = [batches(t, e, s, starts, returns, workers) for t, e, s in cases]
    timings = timing.interleaved_rows(table, min_rounds=repeat, min_time=MIN_TIME,
                                      passes=repeat)
    rows = []
    for (theta, _, _), row, row_t in zip(cases, table, timings):
        rows.append([])
        for b, t in zip(row, row_t):
            first = rows[-1][0]["out"] if rows[-1] else t.value
            if not all(np.array_equal(a, c, equal_nan=True) for a, c in
                       zip(vars(first).values(), vars(t.value).values()) if a is not None):
                raise RuntimeError(f"theta={theta}: {b.workers} workers changed the results")
            rows[-1].append({"workers": b.workers, "wall": t, "out": t.value,
                             "cpu": timing.of_rounds(b.cpu[t.warmup:]),
                             "span": timing.of_rounds(b.spans[t.warmup:]),
                             "returns": int(t.value.returns_done.sum()),
                             "ok": int(np.count_nonzero(t.value.status == OK))})
    return rows


def run(starts: int = 2000, returns: int = 10, repeat: int = 3, log=print) -> xr.Dataset:
    workers = list(range(1, cores() + 1))
    load_before = os.getloadavg()
    table = measure(CASES, starts, returns, repeat, workers)
    load_after = os.getloadavg()
    dims = ("case", "workers")

    def of(key):
        return [[r[key] for r in rows] for rows in table]

    # the wall-clock speed-up over 1 worker, from the medians and as a range
    speedup = np.array([[timing.ratio_range(rows[0]["wall"], r["wall"]) for r in rows]
                        for rows in table])
    ds = xr.Dataset(
        {"returns_per_second": (dims, np.array([[r["returns"] / r["wall"].median for r in rows]
                                                for rows in table]),
                                {"long_name": "returns per second (median wall time of a call)",
                                 "units": "1/s"}),
         **timing.variables("wall_time", dims, of("wall"), "wall time of a call"),
         **timing.variables("cpu_time", dims, of("cpu"), "CPU time of a call, all threads"),
         **timing.variables("span", dims, of("span"), "CPU time of a call's busiest thread"),
         "speedup": (dims, speedup[..., 0], {
             "long_name": "wall time with 1 worker / with N, medians", "units": "1"}),
         "speedup_low": (dims, speedup[..., 1], {
             "long_name": "low end of the speed-up's range: 1 worker's first quartile over "
                          "N workers' third", "units": "1"}),
         "speedup_high": (dims, speedup[..., 2], {
             "long_name": "high end of the speed-up's range: 1 worker's third quartile over "
                          "N workers' first", "units": "1"}),
         "runs": (dims, timing.rounds(of("wall")),
                  {"long_name": "timed calls (after a warm-up call)", "units": "1"})},
        coords={"workers": ("workers", workers, {"units": "1"}), **case_coords(CASES)})
    _log_table(table, starts, returns, load_before, load_after, log)
    return finalize(ds, None, starts=starts, returns=returns, repeat=repeat,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME, passes=repeat),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="returns per second of compute_returns with 1..N workers "
                          "(iterated Hopf return map, compiled engine)")


def _log_table(table, starts, returns, load_before, load_after, log) -> None:
    """The table of :func:`run`: per case and worker count the wall time (median and
    quartiles), the returns per second, and every ratio of two timed quantities as its
    range (low..high, from the quartiles)."""
    log(f"batch: {starts} starts x {returns} returns; load average "
        f"{load_before[0]:.2f} before, {load_after[0]:.2f} after, on {os.cpu_count()} CPUs "
        f"({cores()} usable)")
    log(f"{'theta':>6} {'eps':>7} {'workers':>7} {'wall ms (q1..q3)':>26} {'returns/s':>10} "
        f"{'speedup':>13} {'busy':>5} {'cpu eff.':>13} {'span speedup':>13}")
    for (t, e, _), rows in zip(CASES, table):
        one = rows[0]
        for r in rows:
            w = r["wall"]
            ratios = [timing.ratio_range(one["wall"], w),
                      timing.ratio_range(one["cpu"], r["cpu"]),
                      timing.ratio_range(one["cpu"], r["span"])]
            speed, cpu_eff, span_speed = (f"{lo:6.2f}..{hi:5.2f}" for _, lo, hi in ratios)
            log(f"{t:6.2f} {e:7.0e} {r['workers']:7d} {1e3 * w.median:9.2f} "
                f"({1e3 * w.q1:6.2f}..{1e3 * w.q3:6.2f}) {r['returns'] / w.median:10.0f} "
                f"{speed} {r['cpu'].median / w.median:5.2f} {cpu_eff} {span_speed}")


#: part of `make bench` (filippov_paper.product): rule bench_parallel_scaling runs main(args + ['--out', 'results/bench_parallel_scaling.nc'])
WORKFLOW = {"args": [], "threads": "all"}  # every core: no other job beside it


def main(argv=None) -> None:
    command_line(__doc__, run, argv, starts=2000, returns=10, repeat=3)


if __name__ == "__main__":
    main()
