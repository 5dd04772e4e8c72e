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

Each is timed by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`:
an untimed warm-up, then at least ``--repeat`` timed calls; median), with the CPU time
of the process (all threads) beside the wall clock; the results of the three are
checked to be the same bit for bit. The models are built outside the timing (each
sweep point needs its model either way).
"""
from __future__ import annotations

import os
import time

import numpy as np
import xarray as xr

from filippov.analytic import limit_map
from filippov.attractors import row
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
MIN_TIME = 1.0  # seconds timed per variant at least


def _points(theta, eps, s_range, points):
    scale = limit_map.scale(eps, theta)
    mus = 1.0 + np.linspace(*s_range, points) * scale
    cms = [hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0) for mu in mus]
    starts = np.array([[0.0, np.sqrt(mu), 0.0] for mu in mus])
    return cms, starts


def _same(a, b) -> bool:
    return all(np.array_equal(x, y, equal_nan=True)
               for x, y in zip(vars(a).values(), vars(b).values()) if x is not None)


def measure(theta, eps, s_range, points, returns, repeat) -> list:
    cms, starts = _points(theta, eps, s_range, points)
    n = cores()

    def loop():
        outs = [compute_returns(c, z[None], T_RETURN, iterations=returns, keep=1, workers=1)
                for c, z in zip(cms, starts)]
        return outs

    def sweep(workers):
        return lambda: sweep_returns(cms, starts, T_RETURN, iterations=returns, keep=1,
                                     workers=workers)

    rows, reference = [], None
    for name, call, threads in (("loop", loop, 1), ("sweep 1", sweep(1), 1),
                                ("sweep N", sweep(n), n)):
        cpu = []

        def timed(call=call):
            c0 = time.process_time()
            out = call()
            cpu.append(time.process_time() - c0)
            return out

        t = timing.measure(timed, min_rounds=repeat, min_time=MIN_TIME)
        out = t.value
        if name == "loop":
            reference = out
        elif not all(_same(alone, row(out, i)) for i, alone in enumerate(reference)):
            raise RuntimeError(f"theta={theta}: {name} changed the results")
        rows.append({"variant": name, "threads": threads, "wall": t.median,
                     "cpu": float(np.median(cpu[t.warmup:])), "rounds": t.rounds})
    return rows


def run(points: int = 200, returns: int = 40, repeat: int = 3, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    table = [measure(t, e, s, points, returns, repeat) for t, e, s in CASES]
    load_after = os.getloadavg()
    variants = [r["variant"] for r in table[0]]

    def var(key, attrs):
        return (("case", "variant"), np.array([[r[key] for r in rows] for rows in table]),
                attrs)

    ds = xr.Dataset(
        {"wall_time": var("wall", {"long_name": "median wall time of the sweep",
                                   "units": "s"}),
         "cpu_time": var("cpu", {"long_name": "median CPU time of the sweep, all threads",
                                 "units": "s"}),
         "threads": var("threads", {"long_name": "threads the variant used", "units": "1"}),
         "runs": var("rounds", {"long_name": "timed calls (after a warm-up call)",
                                "units": "1"})},
        coords={"variant": ("variant", variants),
                **case_coords([(t, e, 0.0) for t, e, _ in CASES])})
    log(f"sweep: {points} points x {returns} returns; load average {load_before[0]:.2f} "
        f"before, {load_after[0]:.2f} after; {cores()} usable cores")
    log(f"{'theta':>6} {'eps':>7} {'variant':>8} {'wall s':>8} {'cpu s':>8} "
        f"{'us/point cpu':>12} {'vs loop (cpu)':>13} {'vs loop (wall)':>14}")
    for (t, e, _), rows in zip(CASES, table):
        loop = rows[0]
        for r in rows:
            log(f"{t:6.2f} {e:7.0e} {r['variant']:>8} {r['wall']:8.3f} {r['cpu']:8.3f} "
                f"{1e6 * r['cpu'] / points:12.1f} {loop['cpu'] / r['cpu']:13.2f} "
                f"{loop['wall'] / r['wall']:14.2f}")
    return finalize(ds, None, points=points, returns=returns, repeat=repeat,
                    **timing.load_attrs(load_before, load_after),
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME),
                    title="a parameter sweep of the Hopf return map: one call per point "
                          "against one sweep_returns call (compiled engine)")


#: part of `make bench` (filippov_paper.product): rule bench_sweep_cost runs main(args + ['--out', 'results/bench_sweep_cost.nc'])
WORKFLOW = {"args": [], "threads": "all"}  # "sweep N" takes every core: no other job beside it


def main(argv=None) -> None:
    command_line(__doc__, run, argv, points=200, returns=40, repeat=3)


if __name__ == "__main__":
    main()
