"""What the fig04 return maps cost: the project's solver against scipy's solve_ivp.

Run ``python -m filippov_paper.benchmarks.fig04_speed`` (``make bench-fig04``). Every
method computes P on the scene's full grid (or every k-th point with
``--every k``) for both theta and is scored by its maximal deviation from the
reference, the compiled exact flows; the reference itself is checked against
the project's DOP853 at rtol 1e-13 (the "reference check" row). Points within
1e-6 of the grazing value x2 = 1 are left out of the error (the map jumps
there). Times follow the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`):
one untimed run of each method per problem first (the kernel's compilation or cache
load, the model's pieces), then the median of at least ``--repeat`` timed runs in this
process (more until ``--min-time`` seconds were timed), one core; solve_ivp is timed
as often as the project's modes (on the full grid that takes minutes: ``--every``).
The tolerance sweep over every method is :mod:`filippov_paper.benchmarks.work_precision`.
"""
from __future__ import annotations

import argparse
import sys

import numpy as np

from filippov.fastmap import compile_kernel
from filippov_paper.benchmarks import baseline
from filippov_paper.benchmarks.timing import STATISTIC
from filippov_paper.benchmarks.work_precision import GRAZING_GAP, fig04_problems, runner, timed


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--every", type=int, default=1, help="use every k-th grid point")
    ap.add_argument("--repeat", type=int, default=3,
                    help="timed runs per method at least (median), after one untimed run")
    ap.add_argument("--min-time", type=float, default=0.2,
                    help="time more runs of a method until this many seconds")
    args = ap.parse_args(argv)
    compile_kernel()
    print(f"{STATISTIC} of at least {args.repeat} timed runs (more until {args.min_time:g} s "
          f"were timed) after one untimed run of each method; one core")
    print(f"{'problem':18s} {'method':44s} {'time [s]':>9s} {'max error':>10s} {'x ours':>8s}")
    total = 0.0
    for prob in fig04_problems(args.every):
        away = np.abs(prob.x2 - 1) > GRAZING_GAP

        warmed = set()  # methods run once untimed on this problem

        def one(family, tol):
            t = timed(lambda: runner(prob, family, tol, np.inf)()[0], args.repeat,
                      args.min_time, warmup=0 if family in warmed else 1)
            warmed.add(family)
            return t.shown, t.value

        t_ours, ref = one("project compiled exact", 1e-12)
        total += t_ours
        check = runner(prob, "project DOP853", 1e-13, np.inf)()[0]  # not timed
        rows = [("project compiled exact (reference)", t_ours, 0.0),
                ("reference check: project DOP853 rtol 1e-13", np.nan,
                 np.max(np.abs(check - ref)[away]))]
        for family, tol in (("project python exact", 1e-12), ("solve_ivp RK45", 1e-6),
                            ("solve_ivp RK45", 1e-10)):
            try:
                t, val = one(family, tol)
            except (RuntimeError, baseline.TimeCapExceeded) as err:  # listed, not dropped
                rows.append((f"{family} rtol {tol:g}", np.nan, f"failed: {err}"))
                continue
            rows.append((f"{family} rtol {tol:g}", t, np.max(np.abs(val - ref)[away])))
        for name, t, err in rows:
            ratio = t / t_ours if np.isfinite(t) else np.nan
            err = f"{err:10.2e}" if not isinstance(err, str) else err
            print(f"{prob.name + f' ({prob.x2.size})':18s} {name:44s} {t:9.3f} {err:>10s} {ratio:8.1f}")
        sys.stdout.flush()
    print(f"both panels, compiled exact flows: {total:.3f} s")


if __name__ == "__main__":
    main()
