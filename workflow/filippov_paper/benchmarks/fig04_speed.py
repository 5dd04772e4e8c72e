"""What the fig04 return maps cost: the project's solver against scipy's solve_ivp.

Run ``python -m filippov_paper.benchmarks.fig04_speed`` (``make bench-fig04``). Every
method computes P on the scene's full grid (or every k-th point with
``--every k``) for both theta and is scored by its maximal deviation from the
reference, the compiled exact flows; the reference itself is checked against
the project's DOP853 at rtol 1e-13 (the "reference check" row). Points within
1e-6 of the grazing value x2 = 1 are left out of the error (the map jumps
there). Times follow the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`):
the runs of all methods on a problem interleaved in ``--repeat`` passes
(:func:`~filippov_paper.benchmarks.timing.measure_interleaved`: a spell of load falls on
every method alike), one untimed run of each method per problem first (the kernel's
compilation or cache load, the model's pieces), then at least ``--repeat`` timed runs
in this process (more until ``--min-time`` seconds were timed), one core; solve_ivp is
timed as often as the project's modes (on the full grid that takes minutes:
``--every``). The table prints each median with its quartiles and the ratio to the
project's time as a range (the method's first quartile over the project's third, its
third over the project's first); the machine and its load average before and after
head it. The tolerance sweep over every method is
:mod:`filippov_paper.benchmarks.work_precision`.
"""
from __future__ import annotations

import argparse
import os
import sys

import numpy as np

from filippov.fastmap import compile_kernel
from filippov_paper.benchmarks import timing
from filippov_paper.benchmarks.timing import STATISTIC
from filippov_paper.benchmarks.work_precision import GRAZING_GAP, fig04_problems, runner

#: what is timed on each problem (family, rtol): the reference (the project's compiled
#: exact flows) first, the others against it
METHODS = [("project compiled exact", 1e-12), ("project python exact", 1e-12),
           ("solve_ivp RK45", 1e-6), ("solve_ivp RK45", 1e-10)]


def time_methods(prob, repeat: int, min_time: float) -> list:
    """Every one of :data:`METHODS` on ``prob`` (P on its grid), the runs of all of them
    interleaved in ``repeat`` passes, one untimed run before the first timed run of
    each family; per method its Timing (its value: P) or the exception it raised."""
    families = [family for family, _ in METHODS]
    calls = [lambda family=family, tol=tol: runner(prob, family, tol, np.inf)()[0]
             for family, tol in METHODS]
    return timing.measure_interleaved(
        calls, warmup=lambda k: 0 if families[k] in families[:k] else 1,
        min_rounds=repeat, min_time=min_time, passes=repeat)


def problem_rows(prob, repeat: int, min_time: float) -> list:
    """The table's rows of ``prob``: (name, Timing or None, max error or a failure's
    text, ratio range to the project's time or None)."""
    away = np.abs(prob.x2 - 1) > GRAZING_GAP
    got = time_methods(prob, repeat, min_time)
    ours = got[0]
    if not isinstance(ours, timing.Timing):
        raise ours  # the reference itself failed: nothing to compare with
    check = runner(prob, "project DOP853", 1e-13, np.inf)()[0]  # not timed
    rows = [("project compiled exact (reference)", ours, 0.0, timing.ratio_range(ours, ours)),
            ("reference check: project DOP853 rtol 1e-13", None,
             np.max(np.abs(check - ours.value)[away]), None)]
    for (family, tol), t in zip(METHODS[1:], got[1:]):
        name = f"{family} rtol {tol:g}"
        if not isinstance(t, timing.Timing):  # listed, not dropped
            rows.append((name, None, f"failed: {t}", None))
            continue
        rows.append((name, t, np.max(np.abs(t.value - ours.value)[away]),
                     timing.ratio_range(t, ours)))
    return rows


def _row(problem: str, name: str, t, err, ratio) -> str:
    """A printed row: median (q1..q3) in seconds, the error, the ratio's range."""
    times = (f"{t.median:9.3f} ({t.q1:9.3f}..{t.q3:9.3f})" if t is not None
             else f"{'':9s}  {'':9s}  {'':9s} ")
    err = f"{err:10.2e}" if not isinstance(err, str) else err
    ratio = f"{ratio[1]:8.1f}..{ratio[2]:8.1f}" if ratio is not None else ""
    return f"{problem:18s} {name:44s} {times} {err:>10s} {ratio}"


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--every", type=int, default=1, help="use every k-th grid point")
    ap.add_argument("--repeat", type=int, default=3,
                    help="timed runs per method at least (median), after one untimed run; "
                         "also the passes they are interleaved in")
    ap.add_argument("--min-time", type=float, default=0.2,
                    help="time more runs of a method until this many seconds")
    args = ap.parse_args(argv)
    compile_kernel()
    machine, load_before = timing.machine_attrs(), os.getloadavg()
    print(f"{STATISTIC} (first..third quartile) of at least {args.repeat} timed runs (more "
          f"until {args.min_time:g} s were timed) after one untimed run of each method, the "
          f"runs of a problem's methods interleaved in {args.repeat} passes; one core")
    print(f"machine: {machine['machine_cpu']}, {machine['cpus']} cores; Python "
          f"{machine['python_version']}, numpy {machine['numpy_version']}, scipy "
          f"{machine['scipy_version']}, numba {machine['numba_version']}")
    print(f"{'problem':18s} {'method':44s} {'time [s] (q1..q3)':>32s} {'max error':>10s} "
          f"{'x ours (q1..q3)':>18s}")
    total = 0.0
    for prob in fig04_problems(args.every):
        rows = problem_rows(prob, args.repeat, args.min_time)
        total += rows[0][1].median
        for row in rows:
            print(_row(f"{prob.name} ({prob.x2.size})", *row))
        sys.stdout.flush()
    print(f"both panels, compiled exact flows: {total:.3f} s (sum of the medians)")
    load_after = os.getloadavg()
    print(f"load average {load_before[0]:.2f} before, {load_after[0]:.2f} after")


if __name__ == "__main__":
    main()
