"""What one return of the iterated Hopf return map costs on the compiled engine.

Run ``python -m filippov_paper.benchmarks.attractor_cost`` (part of ``make bench``). For each
case (theta, eps, s) the map is iterated ``--returns`` times from the cycle's point in
one compiled call (:func:`filippov.fastmap.compute_returns` with ``iterations``), without
and with dP/dz, timed by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`):
the calls of every case and variant interleaved in ``--repeat`` passes
(:func:`~filippov_paper.benchmarks.timing.measure_interleaved`: a spell of load falls on
all of them alike, not on the cases timed while it lasted), each with one untimed call
first (it compiles or loads the kernel, and the build with the dP/dz code for the
calls with dP/dz), then at least ``--repeat`` timed calls, more until :data:`MIN_TIME`
seconds were timed. The dataset keeps the median wall time per return with its
spread (``time_per_return_q1`` to ``_q3``) and the fastest and slowest call
(``_min``, ``_max``), the same for dP/dz (``time_per_return_jacobian...``), the machine
and its load average before and after; the table gives the median and the quartiles,
the cost of dP/dz as a range (the calls with it over those without, from the
quartiles) and the mean number of switches per return (what a return does).
"""
from __future__ import annotations

import os

import numpy as np
import xarray as xr

from filippov.analytic import limit_map
from filippov.fastmap import OK, compute_returns
from filippov_paper.benchmarks import command_line, timing
from filippov.io import finalize
from filippov.models import hopf
from filippov_paper.report import FIT_BEGIN, FIT_END, Macros, num, num_range

#: (theta, eps, s): the cascade (theta < 0) and the chaos (theta > 0) at the scenes' eps
CASES = [(-0.5, 1e-2, 1.0), (-0.5, 1e-4, 1.0), (-0.5, 1e-6, 1.0),
         (0.2, 1e-2, 2.0), (0.2, 1e-3, 2.0), (0.2, 1e-4, 2.0), (0.7, 1e-4, 2.0)]
OMEGA = 8 * np.pi
#: seconds timed per case and variant at least (measure_interleaved's min_time)
MIN_TIME = 0.2


def case_coords(cases) -> dict:
    """The coordinates of (theta, eps, s) cases along a dimension "case", for the
    datasets of every benchmark that runs such cases."""
    return {"theta": ("case", [c[0] for c in cases], {"units": "1"}),
            "eps": ("case", [c[1] for c in cases], {"units": "1"}),
            "s": ("case", [c[2] for c in cases],
                  {"long_name": "(mu - 1)/eps (theta < 0), /eps^2 (theta > 0)",
                   "units": "1"})}


def iterate(theta: float, eps: float, s: float, returns: int):
    """The case's timed call, without and with dP/dz (``call(jac)``: ``returns`` returns
    from the cycle's point in one compiled call), and its model and start point."""
    mu = 1.0 + s * limit_map.scale(eps, theta)
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0)
    start = np.array([[0.0, np.sqrt(mu), 0.0]])

    def call(jac: bool):
        def one():
            out = compute_returns(cm, start, 1.0, iterations=returns, keep=1, jacobian=jac)
            if out.status[0] != OK:
                raise RuntimeError(f"theta={theta}, eps={eps}, s={s}: a return failed")
            return out
        return one
    return call, cm, start


def switches_per_return(cm, start, returns: int) -> float:
    """The mean mode changes per return over the first ``returns`` (at most 200) returns,
    counted one return at a time (not timed)."""
    switches, z = 0.0, start
    for _ in range(min(returns, 200)):
        r = compute_returns(cm, z, 1.0)
        switches += r.n_switches[0]
        z = r.state
    return switches / min(returns, 200)


def measure(cases, returns: int, repeat: int) -> tuple[list, list]:
    """Per case the Timings of its call without and with dP/dz, all interleaved (each
    with its own untimed warm-up call: the dP/dz build is compiled or loaded there), and
    the switches per return. A failed call raises."""
    built = [iterate(t, e, s, returns) for t, e, s in cases]
    timings = timing.interleaved_rows([[call(jac) for jac in (False, True)]
                                       for call, _, _ in built],
                                      min_rounds=repeat, min_time=MIN_TIME, passes=repeat)
    return timings, [switches_per_return(cm, start, returns) for _, cm, start in built]


def run(returns: int = 2000, repeat: int = 5, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    timings, switches = measure(CASES, returns, repeat)
    load_after = os.getloadavg()
    plain, jac = [t[0] for t in timings], [t[1] for t in timings]
    ds = xr.Dataset(
        {**timing.variables("time_per_return", ("case",), plain, "wall time per return",
                            per=returns),
         **timing.variables("time_per_return_jacobian", ("case",), jac,
                            "wall time per return with dP/dz", per=returns),
         "runs": ("case", timing.rounds(plain),
                  {"long_name": "timed calls (after a warm-up call)", "units": "1"}),
         "runs_jacobian": ("case", timing.rounds(jac),
                           {"long_name": "timed calls with dP/dz (after a warm-up call)",
                            "units": "1"}),
         "switches_per_return": ("case", switches,
                                 {"long_name": "mean mode changes per return", "units": "1"})},
        coords=case_coords(CASES))
    log(f"load average {load_before[0]:.2f} before, {load_after[0]:.2f} after; "
        f"us/return: median (q1..q3)")
    log(f"{'theta':>6} {'eps':>7} {'s':>4} {'us/return':>22} {'with dP/dz':>22} "
        f"{'ratio (q1..q3)':>14} {'switches':>9}")
    us = 1e6 / returns
    for (t, e, s), (a, b), sw in zip(CASES, timings, switches):
        _, low, high = timing.ratio_range(b, a)
        log(f"{t:6.2f} {e:7.0e} {s:4.1f} "
            + " ".join(f"{us * x.median:8.2f} ({us * x.q1:5.2f}..{us * x.q3:5.2f})"
                       for x in (a, b))
            + f" {low:6.2f}..{high:6.2f} {sw:9.2f}")
    return finalize(ds, None, returns=returns, repeat=repeat,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME, passes=repeat),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="cost per return of the iterated Hopf return map (compiled engine)")


#: part of `make bench` (filippov_paper.product): rule bench_attractor_cost runs main(args + ['--out', 'results/bench_attractor_cost.nc'])
WORKFLOW = {"args": []}


# ============================================================================= report
# What the reproduction report quotes from this benchmark's dataset (filippov_paper.report
# calls `report`, in REPORT's order among the benchmarks). This part -- REPORT, report and
# the _report_* / _REPORT_* names -- is left out of the code hash of the jobs that run the
# benchmark: editing it rebuilds the report only.
REPORT = {"dataset": "bench_attractor_cost", "table": "tab_bench.tex", "order": 40}


#: the timed quantities of the table: (variable, its column head)
_REPORT_TIMES = (("time_per_return", r"$\mu$s/return"), ("time_per_return_jacobian", "with $DP$"))


def report(ds, m: Macros) -> str | None:
    """The cost of one iterated return: the last block of Table tab:bench (None when not
    measured, or measured before the benchmark kept the spread of its times). Each time is
    the stored median with its spread, the first to third quartile of the calls."""
    spread = [f"{v}_{q}" for v, _ in _REPORT_TIMES for q in ("q1", "q3")]
    if ds is not None and not all(name in ds for name in spread):
        ds = None  # measured by an older benchmark: measured again by make bench
    m.flag("rpHaveReturnCost", ds is not None)
    if ds is None:
        return None
    heads = " & ".join(f"{head} & $Q_1$--$Q_3$" for _, head in _REPORT_TIMES)
    lines = [r"\medskip", "", FIT_BEGIN, r"\begin{tabular}{rrrrrrrr}", r"\toprule",
             rf"$\theta$ & $\epsilon$ & $s$ & {heads} & switches/return \\", r"\midrule"]
    for k in range(ds.sizes["case"]):
        cells = [f"${num(float(ds.theta.values[k]), 2)}$",
                 f"${num(float(ds.eps.values[k]), 1)}$",
                 f"${num(float(ds.s.values[k]), 2)}$"]
        for v, _ in _REPORT_TIMES:
            cells += [f"${num(1e6 * float(ds[v].values[k]), 3)}$",
                      num_range(1e6 * float(ds[f"{v}_q1"].values[k]),
                                1e6 * float(ds[f"{v}_q3"].values[k]), 3)]
        cells.append(f"${num(float(ds.switches_per_return.values[k]), 3)}$")
        lines.append(" & ".join(cells) + r" \\")
    return "\n".join(lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""])


def main(argv=None) -> None:
    command_line(__doc__, run, argv, returns=2000, repeat=5)


if __name__ == "__main__":
    main()
