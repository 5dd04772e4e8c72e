"""What one return of the iterated Hopf return map costs on the compiled engine.

Run ``python -m filippov_paper.benchmarks.attractor_cost`` (part of ``make bench``). For each
case (theta, eps, s) the map is iterated ``--returns`` times from the cycle's point in
one compiled call (:func:`filippov.fastmap.compute_returns` with ``iterations``), timed
by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`): one untimed call
first (it compiles or loads the kernel, and the build with the dP/dz code for the
timing with dP/dz), then at least ``--repeat`` timed calls, more until
:data:`MIN_TIME` seconds were timed. The table gives the median wall time per return
(the min is stored too) and the mean number of switches per return (what a return does).
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov.analytic import limit_map
from filippov.fastmap import OK, compute_returns
from filippov_paper.benchmarks import command_line, timing
from filippov.io import finalize
from filippov.models import hopf
from filippov_paper.report import FIT_BEGIN, FIT_END, Macros, num

#: (theta, eps, s): the cascade (theta < 0) and the chaos (theta > 0) at the scenes' eps
CASES = [(-0.5, 1e-2, 1.0), (-0.5, 1e-4, 1.0), (-0.5, 1e-6, 1.0),
         (0.2, 1e-2, 2.0), (0.2, 1e-3, 2.0), (0.2, 1e-4, 2.0), (0.7, 1e-4, 2.0)]
OMEGA = 8 * np.pi
#: seconds timed per case and variant at least (timing.measure's min_time)
MIN_TIME = 0.2


def case_coords(cases) -> dict:
    """The coordinates of (theta, eps, s) cases along a dimension "case", for the
    datasets of every benchmark that runs such cases."""
    return {"theta": ("case", [c[0] for c in cases], {"units": "1"}),
            "eps": ("case", [c[1] for c in cases], {"units": "1"}),
            "s": ("case", [c[2] for c in cases],
                  {"long_name": "(mu - 1)/eps (theta < 0), /eps^2 (theta > 0)",
                   "units": "1"})}


def measure(theta: float, eps: float, s: float, returns: int, repeat: int) -> dict:
    mu = 1.0 + s * limit_map.scale(eps, theta)
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0)
    start = np.array([[0.0, np.sqrt(mu), 0.0]])

    def iterate(jac: bool):
        def call():
            out = compute_returns(cm, start, 1.0, iterations=returns, keep=1, jacobian=jac)
            if out.status[0] != OK:
                raise RuntimeError(f"theta={theta}, eps={eps}, s={s}: a return failed")
            return out
        return call

    # each with its own untimed warm-up call (the dP/dz build is compiled or loaded there)
    plain = timing.measure(iterate(False), min_rounds=repeat, min_time=MIN_TIME)
    jac = timing.measure(iterate(True), min_rounds=repeat, min_time=MIN_TIME)
    switches = 0.0
    # switches per return: one more call, returns counted one by one
    z = start
    for _ in range(min(returns, 200)):
        r = compute_returns(cm, z, 1.0)
        switches += r.n_switches[0]
        z = r.state
    return {"per_return": plain.median / returns, "per_return_jac": jac.median / returns,
            "per_return_min": plain.min / returns, "per_return_jac_min": jac.min / returns,
            "rounds": plain.rounds, "rounds_jac": jac.rounds,
            "switches": switches / min(returns, 200)}


def run(returns: int = 2000, repeat: int = 5, log=print) -> xr.Dataset:
    rows = [measure(t, e, s, returns, repeat) for t, e, s in CASES]
    ds = xr.Dataset(
        {"time_per_return": ("case", [r["per_return"] for r in rows],
                             {"long_name": "median wall time per return", "units": "s"}),
         "time_per_return_jacobian": ("case", [r["per_return_jac"] for r in rows],
                                      {"long_name": "median wall time per return with dP/dz",
                                       "units": "s"}),
         "time_per_return_min": ("case", [r["per_return_min"] for r in rows],
                                 {"long_name": "min wall time per return (fastest call)",
                                  "units": "s"}),
         "time_per_return_jacobian_min": ("case", [r["per_return_jac_min"] for r in rows], {
             "long_name": "min wall time per return with dP/dz (fastest call)", "units": "s"}),
         "runs": ("case", [r["rounds"] for r in rows],
                  {"long_name": "timed calls (after a warm-up call)", "units": "1"}),
         "runs_jacobian": ("case", [r["rounds_jac"] for r in rows],
                           {"long_name": "timed calls with dP/dz (after a warm-up call)",
                            "units": "1"}),
         "switches_per_return": ("case", [r["switches"] for r in rows],
                                 {"long_name": "mean mode changes per return", "units": "1"})},
        coords=case_coords(CASES))
    log(f"{'theta':>6} {'eps':>7} {'s':>4} {'us/return':>10} {'with dP/dz':>11} "
        f"{'ratio':>6} {'switches':>9}")
    for (t, e, s), r in zip(CASES, rows):
        log(f"{t:6.2f} {e:7.0e} {s:4.1f} {1e6 * r['per_return']:10.1f} "
            f"{1e6 * r['per_return_jac']:11.1f} {r['per_return_jac'] / r['per_return']:6.2f} "
            f"{r['switches']:9.2f}")
    return finalize(ds, None, returns=returns, repeat=repeat,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME),
                    title="cost per return of the iterated Hopf return map (compiled engine)")


#: part of `make bench` (filippov_paper.product): rule bench_attractor_cost runs main(args + ['--out', 'results/bench_attractor_cost.nc'])
WORKFLOW = {"args": []}


# ============================================================================= report
# What the reproduction report quotes from this benchmark's dataset (filippov_paper.report
# calls `report`, in REPORT's order among the benchmarks). This part -- REPORT, report and
# the _report_* / _REPORT_* names -- is left out of the code hash of the jobs that run the
# benchmark: editing it rebuilds the report only.
REPORT = {"dataset": "bench_attractor_cost", "table": "tab_bench.tex", "order": 40}


def report(ds, m: Macros) -> str | None:
    """The cost of one iterated return: the last block of Table tab:bench (None when not
    measured)."""
    m.flag("rpHaveReturnCost", ds is not None)
    if ds is None:
        return None
    lines = [r"\medskip", "", FIT_BEGIN, r"\begin{tabular}{rrrrrr}", r"\toprule",
             r"$\theta$ & $\epsilon$ & $s$ & $\mu$s/return & with $DP$ & "
             r"switches/return \\", r"\midrule"]
    for k in range(ds.sizes["case"]):
        lines.append(" & ".join([
            f"${num(float(ds.theta.values[k]), 2)}$",
            f"${num(float(ds.eps.values[k]), 1)}$",
            f"${num(float(ds.s.values[k]), 2)}$",
            f"${num(1e6 * float(ds.time_per_return.values[k]), 3)}$",
            f"${num(1e6 * float(ds.time_per_return_jacobian.values[k]), 3)}$",
            f"${num(float(ds.switches_per_return.values[k]), 3)}$"]) + r" \\")
    return "\n".join(lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""])


def main(argv=None) -> None:
    command_line(__doc__, run, argv, returns=2000, repeat=5)


if __name__ == "__main__":
    main()
