"""What a parameter sweep in one call saves over one call per parameter point.

Run ``python -m filippov_paper.benchmarks.sweep_cost``. For each case (theta, eps) of the
attractor sweeps (fig12--fig14), ``--points`` values of s (mu = 1 + s * scale) are each
iterated ``--returns`` times from the start the sweeps use, the first phase of
:func:`filippov.attractors.settle` at every point, three ways:

* ``loop``: one :func:`filippov.fastmap.compute_returns` call per point (what the
  sweeps did before), one thread;
* ``sweep 1``: one :func:`filippov.fastmap.sweep_returns` call for all points, one thread:
  what the calls' own cost was (argument checks, unboxing, the kernel's work arrays);
* ``sweep N``: the same call with the cores this process may use.

Each is timed by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`):
the calls of the three ways and of every case interleaved in ``--repeat`` passes
(:func:`~filippov_paper.benchmarks.timing.measure_interleaved`: a spell of load falls on
all of them alike), each with an untimed warm-up call, then at least ``--repeat`` timed
calls, more until :data:`MIN_TIME` s were timed; with the CPU time of the process (all
threads) beside the wall clock. Both are stored as the median of the calls with its
spread (``_q1`` to ``_q3``) and the fastest and slowest call (``_min``, ``_max``); the
table gives the median with its quartiles, and each way against the loop as a range
(the loop's first quartile over the way's third, its third over the way's first); the
machine and its load average before and after are dataset attributes. The results of
the three are checked to be the same bit for bit. The models are built outside the
timing (each sweep point needs its model either way).
"""
from __future__ import annotations

import os
import time

import numpy as np
import xarray as xr

from filippov.analytic import limit_map
from filippov.attractors import row as row_of
from filippov.fastmap import compute_returns, sweep_returns
from filippov.io import finalize
from filippov.models import hopf
from filippov_paper.benchmarks import command_line, timing
from filippov_paper.benchmarks.attractor_cost import case_coords
from filippov_paper.benchmarks.parallel_scaling import cores

#: (theta, eps, s range): the cascade (theta < 0, exact flows) and the chaos (theta > 0,
#: sliding integrated), s over fig12's and fig13's grids
CASES = [(-0.5, 1e-2, (-1.0, 5.0)), (0.3, 1e-3, (-1.0, 5.0))]
OMEGA = 8 * np.pi
T_RETURN = 1.0  # each return well within (the period is 2 pi / OMEGA = 0.25)
MIN_TIME = 1.0  # seconds timed per variant at least (measure_interleaved's min_time)


def _points(theta, eps, s_range, points):
    scale = limit_map.scale(eps, theta)
    mus = 1.0 + np.linspace(*s_range, points) * scale
    cms = [hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0) for mu in mus]
    starts = np.array([[0.0, np.sqrt(mu), 0.0] for mu in mus])
    return cms, starts


def _same(a, b) -> bool:
    return all(np.array_equal(x, y, equal_nan=True)
               for x, y in zip(vars(a).values(), vars(b).values()) if x is not None)


class Way:
    """One way of running a case's sweep (``call``, ``threads``): a call of it runs the
    sweep once and records the process's CPU time (``cpu``: one entry a call, the
    warm-up call's first)."""

    def __init__(self, name: str, call, threads: int):
        self.name, self.call, self.threads, self.cpu = name, call, threads, []

    def __call__(self):
        c0 = time.process_time()
        out = self.call()
        self.cpu.append(time.process_time() - c0)
        return out


def ways(theta, eps, s_range, points, returns) -> list:
    """The case's three ways: a compute_returns call per point (``loop``), one
    sweep_returns call on one thread (``sweep 1``) and on every core (``sweep N``)."""
    cms, starts = _points(theta, eps, s_range, points)
    n = cores()

    def loop():
        return [compute_returns(c, z[None], T_RETURN, iterations=returns, keep=1, workers=1)
                for c, z in zip(cms, starts)]

    def sweep(workers):
        return lambda: sweep_returns(cms, starts, T_RETURN, iterations=returns, keep=1,
                                     workers=workers)
    return [Way("loop", loop, 1), Way("sweep 1", sweep(1), 1), Way("sweep N", sweep(n), n)]


def measure(cases, points, returns, repeat) -> list:
    """Per case, per way: the Timings of its wall time and CPU time (the timed calls),
    its threads. The calls of all cases and ways are interleaved; a failed call, or a
    sweep whose results differ from the loop's, raise."""
    table = [ways(t, e, s, points, returns) for t, e, s in cases]
    timings = timing.interleaved_rows(table, min_rounds=repeat, min_time=MIN_TIME,
                                      passes=repeat)
    rows = []
    for (theta, _, _), row, row_t in zip(cases, table, timings):
        rows.append([])
        for way, t in zip(row, row_t):
            if way.name == "loop":
                reference = t.value
            elif not all(_same(alone, row_of(t.value, i)) for i, alone in enumerate(reference)):
                raise RuntimeError(f"theta={theta}: {way.name} changed the results")
            rows[-1].append({"variant": way.name, "threads": way.threads, "wall": t,
                             "cpu": timing.of_rounds(way.cpu[t.warmup:])})
    return rows


def run(points: int = 200, returns: int = 40, repeat: int = 3, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    table = measure(CASES, points, returns, repeat)
    load_after = os.getloadavg()
    variants = [r["variant"] for r in table[0]]
    dims = ("case", "variant")

    def of(key):
        return [[r[key] for r in rows] for rows in table]

    ds = xr.Dataset(
        {**timing.variables("wall_time", dims, of("wall"), "wall time of the sweep"),
         **timing.variables("cpu_time", dims, of("cpu"), "CPU time of the sweep, all threads"),
         "threads": (dims, np.array(of("threads")),
                     {"long_name": "threads the variant used", "units": "1"}),
         "runs": (dims, timing.rounds(of("wall")),
                  {"long_name": "timed calls (after a warm-up call)", "units": "1"})},
        coords={"variant": ("variant", variants),
                **case_coords([(t, e, 0.0) for t, e, _ in CASES])})
    log(f"sweep: {points} points x {returns} returns; load average {load_before[0]:.2f} "
        f"before, {load_after[0]:.2f} after; {cores()} usable cores; median (q1..q3)")
    log(f"{'theta':>6} {'eps':>7} {'variant':>8} {'wall s':>24} {'cpu s':>24} "
        f"{'us/point cpu':>12} {'vs loop (cpu)':>13} {'vs loop (wall)':>14}")
    for (t, e, _), rows in zip(CASES, table):
        loop = rows[0]
        for r in rows:
            times = " ".join(f"{x.median:8.3f} ({x.q1:6.3f}..{x.q3:6.3f})"
                             for x in (r["wall"], r["cpu"]))
            vs = " ".join(f"{lo:6.2f}..{hi:6.2f}" for _, lo, hi in (
                timing.ratio_range(loop["cpu"], r["cpu"]),
                timing.ratio_range(loop["wall"], r["wall"])))
            log(f"{t:6.2f} {e:7.0e} {r['variant']:>8} {times} "
                f"{1e6 * r['cpu'].median / points:12.1f} {vs}")
    return finalize(ds, None, points=points, returns=returns, repeat=repeat,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME, passes=repeat),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="a parameter sweep of the Hopf return map: one call per point "
                          "against one sweep_returns call (compiled engine)")


#: part of `make bench` (filippov_paper.product): rule bench_sweep_cost runs main(args + ['--out', 'results/bench_sweep_cost.nc'])
WORKFLOW = {"args": [], "threads": "all"}  # "sweep N" takes every core: no other job beside it


def main(argv=None) -> None:
    command_line(__doc__, run, argv, points=200, returns=40, repeat=3)


if __name__ == "__main__":
    main()
