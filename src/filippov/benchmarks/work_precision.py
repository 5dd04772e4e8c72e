"""Work against precision for the return maps: what each digit costs.

Run ``python -m filippov.benchmarks.work_precision`` (``make bench`` or
``snakemake bench``). For every problem (the fig04 return maps, one per theta)
each method is swept over tolerances and scored by

* ``error_map``: max |P - P_ref| over the grid, points within ``1e-6`` of the
  grazing value x2 = 1 left out (there the map jumps or has an infinite slope:
  the error measures the conditioning, not the method);
* ``error_switch``: max |t_switch - t_switch_ref| of the first change of mode;
* ``wall_time``: the median of ``runs`` runs in this process (one core);

against a reference computed independently of the method measured: the
compiled exact flows at rtol 1e-13 for every integrator, and the project's
DOP853 at rtol 1e-13 for the exact-flow modes themselves (their difference,
``reference_check``, is the floor no error below it can be trusted).

A method that raises or runs over ``--time-cap`` seconds is kept in the table
with its status, never dropped. A table is printed; the dataset goes to
``--out`` (``results/bench_work_precision.nc``).
"""
from __future__ import annotations

import argparse
import statistics
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import xarray as xr
import yaml

from ..io import finalize, write_dataset
from ..models import hopf
from ..scenes.fig04_retmaps import return_map, x2_grid
from . import baseline

ROOT = Path(__file__).resolve().parents[3]
SCENE = ROOT / "config" / "scenes" / "fig04_retmaps.yaml"
TARGET_ERROR = 1e-8
GRAZING_GAP = 1e-6

# (family, tolerances): the project's modes first, then solve_ivp as a user would call it
PROJECT = [("project compiled exact", [1e-6, 1e-8, 1e-10, 1e-12]),
           ("project python exact", [1e-12]),
           ("project DOP853", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-13])]
SCIPY = [("solve_ivp RK45", [1e-3, 1e-4, 1e-6, 1e-8, 1e-10]),
         ("solve_ivp DOP853", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]),
         ("solve_ivp Radau", [1e-4, 1e-6, 1e-8]),
         ("solve_ivp LSODA", [1e-4, 1e-6, 1e-8, 1e-10])]
QUICK = [("project compiled exact", [1e-10]), ("project DOP853", [1e-8]),
         ("solve_ivp RK45", [1e-6])]


@dataclass(frozen=True)
class Problem:
    name: str
    x2: np.ndarray
    model: object
    scored: np.ndarray  # grid points the error is taken over

    @property
    def starts(self):
        return np.stack([np.zeros_like(self.x2), self.x2, np.zeros_like(self.x2)], axis=1)


def fig04_problems(every: int) -> list[Problem]:
    p = yaml.safe_load(SCENE.read_text())["parameters"]
    x2 = x2_grid(p)[::every]
    return [Problem(f"fig04 theta={th:g}", x2, hopf.model(p["eps"], th, p["mu"], p["omega"]),
                    np.abs(x2 - 1.0) > GRAZING_GAP) for th in p["theta"]]


def runner(problem: Problem, family: str, tol: float, time_cap: float) -> Callable:
    """A function returning ``(P, first switch times)`` for one configuration."""
    opts = {"rtol": tol, "atol": tol * 1e-2}
    if family.startswith("project"):
        method = "integrate" if family == "project DOP853" else "exact"
        engine = "compiled" if "compiled" in family else "python"

        def run():
            px2, _, ret = return_map(problem.model, problem.x2, method, opts, engine=engine)
            return px2, ret.first_switch
        return run
    solver = family.split()[-1]
    system = problem.model.full(exact=False)
    t_max = 4.0 * 2 * np.pi / abs(problem.model.parameters["omega"])

    def run():
        states, _, first = baseline.first_returns(
            system, problem.starts, lambda z: z[0], lambda z: z[1] > 0, -1, t_max, solver,
            opts["rtol"], opts["atol"], time_cap=time_cap)
        return states[:, 1], first
    return run


def timed(fn, repeat: int, time_cap: float):
    """Median wall time of up to ``repeat`` runs (one run if it is slow)."""
    times, out = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
        if sum(times) > min(10.0, time_cap):
            break
    return statistics.median(times), len(times), out


def max_dev(a, b, mask):
    """Max |a - b| where both are finite, and how many points only one has."""
    a, b = np.asarray(a)[mask], np.asarray(b)[mask]
    both = np.isfinite(a) & np.isfinite(b)
    odd = int(np.count_nonzero(np.isfinite(a) != np.isfinite(b)))
    return (float(np.max(np.abs(a[both] - b[both]))) if both.any() else 0.0), odd


def time_at_error(errors, times, target):
    """Wall time at ``target`` error on the family's log-log curve (interpolated);
    NaN if the family never reaches it."""
    ok = np.isfinite(errors) & np.isfinite(times) & (errors > 0)
    e, t = np.asarray(errors)[ok], np.asarray(times)[ok]
    if e.size == 0 or e.min() > target:
        return np.nan
    if np.any(e == target):
        return float(t[e == target].min())
    if e.max() < target:  # every configuration is more accurate: the cheapest one
        return float(t.min())
    order = np.argsort(e)
    e, t = np.log(e[order]), np.log(t[order])
    below, above = np.flatnonzero(e < np.log(target)), np.flatnonzero(e > np.log(target))
    i, j = below[-1], above[0]
    w = (np.log(target) - e[i]) / (e[j] - e[i])
    return float(np.exp(t[i] + w * (t[j] - t[i])))


def run(problems, families, repeat: int, time_cap: float, log=print) -> xr.Dataset:
    configs = [(fam, tol) for fam, tols in families for tol in tols]
    shape = (len(problems), len(configs))
    err_map, err_sw, wall = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    runs, missed = np.zeros(shape, dtype=np.int32), np.zeros(shape, dtype=np.int32)
    status = np.full(shape, "ok", dtype=object)
    ref_check = np.empty(len(problems))
    for i, prob in enumerate(problems):
        ref_p, ref_sw = runner(prob, "project compiled exact", 1e-13, np.inf)()
        chk_p, chk_sw = runner(prob, "project DOP853", 1e-13, np.inf)()
        ref_check[i] = max_dev(chk_p, ref_p, prob.scored)[0]
        log(f"{prob.name}: {prob.x2.size} start points; reference check "
            f"(compiled exact vs DOP853 rtol 1e-13): {ref_check[i]:.2e}")
        for j, (fam, tol) in enumerate(configs):
            # the exact-flow modes are scored against the independent DOP853 check
            want_p, want_sw = (chk_p, chk_sw) if "exact" in fam else (ref_p, ref_sw)
            try:
                wall[i, j], runs[i, j], (got_p, got_sw) = timed(
                    runner(prob, fam, tol, time_cap), repeat, time_cap)
            except baseline.TimeCapExceeded as exc:
                status[i, j] = f"time cap: {exc}"
            except Exception as exc:  # listed, not dropped
                status[i, j] = f"failed: {type(exc).__name__}: {exc}"[:200]
            else:
                err_map[i, j] = max_dev(got_p, want_p, prob.scored)[0]
                err_sw[i, j], missed[i, j] = max_dev(got_sw, want_sw, prob.scored)
            log(f"  {fam:24s} rtol {tol:7.0e}  {wall[i, j]:9.4f} s  map err {err_map[i, j]:9.2e}"
                f"  switch err {err_sw[i, j]:9.2e} ({missed[i, j]} missed)  {status[i, j] if status[i, j] != 'ok' else ''}")
    fam_of = np.array([c[0] for c in configs])
    ratio = np.full(len(problems), np.nan)
    t_ours, t_rk45 = np.full(len(problems), np.nan), np.full(len(problems), np.nan)
    for i in range(len(problems)):
        ours = np.array([f.startswith("project") for f in fam_of])
        ok = ours & (err_map[i] <= TARGET_ERROR)
        t_ours[i] = wall[i, ok].min() if ok.any() else np.nan
        rk = fam_of == "solve_ivp RK45"
        t_rk45[i] = time_at_error(err_map[i, rk], wall[i, rk], TARGET_ERROR)
        ratio[i] = t_rk45[i] / t_ours[i]
    dims = ("problem", "config")
    ds = xr.Dataset(
        {"error_map": (dims, err_map, {"long_name": "max |P - P_ref| over the grid", "units": "1"}),
         "error_switch": (dims, err_sw, {
             "long_name": "max error of the first switching time (points where both switch)",
             "units": "1"}),
         "missed_switches": (dims, missed, {
             "long_name": "start points where only one of method and reference switches "
                          "(a grazing excursion missed or invented)", "units": "1"}),
         "wall_time": (dims, wall, {"long_name": "median wall time of one map", "units": "s"}),
         "runs": (dims, runs, {"long_name": "runs the median is taken over", "units": "1"}),
         "status": (dims, status.astype(str), {"long_name": "ok, failed: ..., or time cap: ..."}),
         "reference_check": ("problem", ref_check, {
             "long_name": "max |P_exact(rtol 1e-13) - P_DOP853(rtol 1e-13)|", "units": "1"}),
         "n_points": ("problem", np.array([p.x2.size for p in problems], dtype=np.int32),
                      {"long_name": "start points per map", "units": "1"}),
         "time_ours_at_target": ("problem", t_ours, {
             "long_name": "fastest project configuration with error <= target", "units": "s"}),
         "time_rk45_at_target": ("problem", t_rk45, {
             "long_name": "solve_ivp RK45 time at the target error (log-log interpolation; "
                          "NaN: not reached)", "units": "s"}),
         "speedup_vs_rk45": ("problem", ratio, {
             "long_name": "RK45 time / project time at equal error (the target)", "units": "1"})},
        coords={"problem": [p.name for p in problems],
                "method": ("config", fam_of), "tolerance": ("config", [c[1] for c in configs])})
    return finalize(ds, None, target_error=TARGET_ERROR, time_cap=time_cap, repeat=repeat,
                    grazing_gap=GRAZING_GAP,
                    title="work-precision of the fig04 return maps: project vs solve_ivp")


def table(ds: xr.Dataset) -> str:
    lines = []
    for i, prob in enumerate(ds.problem.values):
        lines.append(f"\n{prob}: {int(ds.n_points[i])} points, reference check "
                     f"{float(ds.reference_check[i]):.1e}")
        lines.append(f"{'method':26s} {'rtol':>7s} {'time [s]':>10s} {'map error':>10s} "
                     f"{'switch err':>10s} {'missed':>6s}  status")
        for j in range(ds.sizes["config"]):
            st = str(ds.status.values[i, j])
            lines.append(f"{str(ds.method.values[j]):26s} {float(ds.tolerance[j]):7.0e} "
                         f"{float(ds.wall_time[i, j]):10.4f} {float(ds.error_map[i, j]):10.2e} "
                         f"{float(ds.error_switch[i, j]):10.2e} {int(ds.missed_switches[i, j]):6d}  {'' if st == 'ok' else st}")
        lines.append(f"at error {TARGET_ERROR:g}: project {float(ds.time_ours_at_target[i]):.4f} s, "
                     f"RK45 {float(ds.time_rk45_at_target[i]):.4f} s, "
                     f"speed-up {float(ds.speedup_vs_rk45[i]):.0f}x")
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--every", type=int, default=10, help="use every k-th fig04 grid point")
    ap.add_argument("--repeat", type=int, default=3, help="runs per configuration (median)")
    ap.add_argument("--time-cap", type=float, default=120.0, help="seconds per configuration")
    ap.add_argument("--quick", action="store_true", help="three configurations only (smoke test)")
    ap.add_argument("--out", default=str(ROOT / "results" / "bench_work_precision.nc"))
    args = ap.parse_args(argv)
    if args.every < 1 or args.repeat < 1 or not args.time_cap > 0:
        ap.error("--every and --repeat must be >= 1 and --time-cap > 0")
    families = QUICK if args.quick else PROJECT + SCIPY
    ds = run(fig04_problems(args.every), families, args.repeat, args.time_cap,
             log=lambda s: print(s, file=sys.stderr, flush=True))
    write_dataset(ds, args.out)
    print(table(ds))
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
