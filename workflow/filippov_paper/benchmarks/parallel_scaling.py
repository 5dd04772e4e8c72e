"""How a batch of returns scales with the threads of compute_returns(workers=...).

Run ``python -m filippov_paper.benchmarks.parallel_scaling`` (part of ``make bench``). For each
case (theta, eps, s) of the iterated Hopf return map, a batch of ``--starts`` start points
near the cycle is iterated ``--returns`` times each in one call of
:func:`filippov.fastmap.compute_returns`, with 1, 2, ... workers up to the cores this
process may use, timed by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`:
an untimed warm-up call, then at least ``--repeat`` timed calls; median and min).

Beside the wall clock, what a loaded machine does not distort as much:

* ``cpu``: the process's CPU time per call (all threads): the work, and what threads add
  to it (``cpu efficiency`` = CPU time with 1 worker / CPU time with N); ``busy`` = CPU
  time / wall time, the cores the call kept busy on average: above what 1 worker gets,
  the threads did run at once (the kernel releases the GIL);
* ``span``: the CPU time of the busiest thread of a call (each thread's own clock): the
  wall time the call would take with a core per thread and no one else on the machine,
  so ``span speedup`` = CPU time with 1 worker / span is the speedup that the cores
  would give unloaded.

The wall-clock speedup is measured too (median of calls with 1 worker / with N) but
depends on what else runs: the load average (``os.getloadavg``) before and after is
stored and printed with the table.
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


def measure(theta: float, eps: float, s: float, starts: int, returns: int, repeat: int,
            workers: list) -> list:
    mu = 1.0 + s * limit_map.scale(eps, theta)
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0)
    # start points along the section around the cycle's point (x2 = sqrt(mu))
    x2 = np.sqrt(mu) * np.linspace(0.98, 1.02, starts)
    z0 = np.stack([np.zeros(starts), x2, np.zeros(starts)], axis=1)
    rows, first = [], None
    for n in workers:
        cpu, spans = [], []

        def call():
            c0 = time.process_time()
            with _thread_clocks() as clocks:
                out = compute_returns(cm, z0, 1.0, iterations=returns, keep=1, workers=n)
            cpu.append(time.process_time() - c0)
            # the busiest thread of this call: the sum of its slices' CPU times
            per_thread = {}
            for ident, dt in clocks:
                per_thread[ident] = per_thread.get(ident, 0.0) + dt
            spans.append(max(per_thread.values()))
            return out

        t = timing.measure(call, min_rounds=repeat, min_time=MIN_TIME)
        out = t.value
        if first is None:
            first = out
        elif not all(np.array_equal(a, b, equal_nan=True) for a, b in
                     zip(vars(first).values(), vars(out).values()) if a is not None):
            raise RuntimeError(f"theta={theta}: {n} workers changed the results")
        ok = int(np.count_nonzero(out.status == OK))
        done = int(out.returns_done.sum())
        cpu, spans = cpu[t.warmup:], spans[t.warmup:]  # the timed rounds only
        rows.append({"workers": n, "wall": t.median, "wall_min": t.min, "rounds": t.rounds,
                     "cpu": float(np.median(cpu)), "span": float(np.median(spans)),
                     "returns": done, "ok": ok})
    return rows


def run(starts: int = 2000, returns: int = 10, repeat: int = 3, log=print) -> xr.Dataset:
    workers = list(range(1, cores() + 1))
    load_before = os.getloadavg()
    table = [measure(t, e, s, starts, returns, repeat, workers) for t, e, s in CASES]
    load_after = os.getloadavg()

    def var(key):
        return (("case", "workers"), np.array([[r[key] for r in rows] for rows in table]))

    ds = xr.Dataset(
        {"returns_per_second": (("case", "workers"),
                                np.array([[r["returns"] / r["wall"] for r in rows]
                                          for rows in table]),
                                {"long_name": "returns per second (median wall time of a call)",
                                 "units": "1/s"}),
         "wall_time": var("wall") + ({"long_name": "median wall time of a call", "units": "s"},),
         "wall_time_min": var("wall_min") + ({"long_name": "min wall time of a call",
                                              "units": "s"},),
         "cpu_time": var("cpu") + ({"long_name": "median CPU time of a call, all threads",
                                    "units": "s"},),
         "span": var("span") + ({"long_name": "median CPU time of a call's busiest thread",
                                 "units": "s"},),
         "runs": var("rounds") + ({"long_name": "timed calls (after a warm-up call)",
                                   "units": "1"},)},
        coords={"workers": ("workers", workers, {"units": "1"}), **case_coords(CASES)})
    log(f"batch: {starts} starts x {returns} returns; load average "
        f"{load_before[0]:.2f} before, {load_after[0]:.2f} after, on {os.cpu_count()} CPUs "
        f"({cores()} usable)")
    log(f"{'theta':>6} {'eps':>7} {'workers':>7} {'returns/s':>10} {'speedup':>8} "
        f"{'eff.':>5} {'busy':>5} {'cpu eff.':>8} {'span speedup':>12} {'span eff.':>9}")
    for (t, e, _), rows in zip(CASES, table):
        one = rows[0]
        for r in rows:
            n = r["workers"]
            speed = one["wall"] / r["wall"]
            span_speed = one["cpu"] / r["span"]
            log(f"{t:6.2f} {e:7.0e} {n:7d} {r['returns'] / r['wall']:10.0f} {speed:8.2f} "
                f"{speed / n:5.2f} {r['cpu'] / r['wall']:5.2f} {one['cpu'] / r['cpu']:8.2f} "
                f"{span_speed:12.2f} "
                f"{span_speed / n:9.2f}")
    return finalize(ds, None, starts=starts, returns=returns, repeat=repeat,
                    **timing.load_attrs(load_before, load_after),
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME),
                    title="returns per second of compute_returns with 1..N workers "
                          "(iterated Hopf return map, compiled engine)")


#: part of `make bench` (filippov_paper.product): rule bench_parallel_scaling runs main(args + ['--out', 'results/bench_parallel_scaling.nc'])
WORKFLOW = {"args": [], "threads": "all"}  # every core: no other job beside it


def main(argv=None) -> None:
    command_line(__doc__, run, argv, starts=2000, returns=10, repeat=3)


if __name__ == "__main__":
    main()
