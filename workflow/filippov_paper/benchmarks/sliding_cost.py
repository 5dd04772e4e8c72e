"""What one sliding return of the Hopf example costs as eps shrinks (reference driver).

Run ``python -m filippov_paper.benchmarks.sliding_cost`` (part of ``make bench``). The
return is the hard-case sweep's (theta = 0.5 from (0, 1.2, 0) to L1, rtol 1e-12):
the sliding field is stiff for eps <= 1e-3 and the driver hands the stay to the
implicit Radau IIA method. For each eps and each number of stages of that method
(3 = the order of scipy's Radau, 5 = the driver's default) the table gives the
driver steps, the wall time of the return and its ratio to the time at the largest eps
with the default method (not stiff there: DOP853 only). Times follow the benchmarks'
convention (:mod:`filippov_paper.benchmarks.timing`): the returns of every eps and
stage count interleaved in ``--repeat`` passes
(:func:`~filippov_paper.benchmarks.timing.measure_interleaved`: a spell of load falls on
all of them alike), each with one untimed run, then at least ``--repeat`` timed runs,
more until :data:`MIN_TIME` seconds were timed. The dataset keeps the median
(``time``) with its spread (``time_q1`` to ``time_q3``), the fastest and slowest run
(``time_min``, ``time_max``), the machine and its load average before and after; the
table prints the median with its quartiles and the ratio as a range (this return's
first quartile over the base's third, its third over the base's first).
"""
from __future__ import annotations

import importlib
import os

import numpy as np
import xarray as xr

from filippov_paper.hard_cases import PARAMETERS
from filippov_paper.benchmarks import command_line, timing
from filippov.io import finalize
from filippov.models import hopf
from filippov_paper.scenes.fig04_retmaps import section_L1

# the module, not the function that filippov exports under the same name
driver = importlib.import_module("filippov.simulate")

EPS = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8]
STAGES = [3, 5]
# the hard-case sweep's sliding return (hard_cases.sliding_return), timed alone
THETA, START, T_MAX = (PARAMETERS["return_theta"], (0.0, PARAMETERS["return_x2"], 0.0),
                       PARAMETERS["hopf_t_max"])
#: seconds timed per return at least (measure_interleaved's min_time)
MIN_TIME = 0.2


def sliding_return(eps: float, stages: int):
    """The return at ``eps`` with Radau IIA of ``stages`` stages, as a function to time
    (the driver's stage count set for the call and restored after it, so that the
    calls of all eps and stage counts can be interleaved)."""
    model = hopf.model(eps, THETA, PARAMETERS["mu"], PARAMETERS["omega"])

    def call():
        saved = driver.STIFF_STAGES
        driver.STIFF_STAGES = stages
        try:
            return driver.simulate(model.full(), list(START), T_MAX, sections=[section_L1()],
                                   dense=False)
        finally:
            driver.STIFF_STAGES = saved
    return call


def measure(repeat: int) -> dict:
    """{(eps, stages): Timing} of every return, their runs interleaved; a return that
    fails or does not reach L1 raises."""
    cells = [(e, s) for s in STAGES for e in EPS]
    got, = timing.interleaved_rows([[sliding_return(e, s) for e, s in cells]],
                                   min_rounds=repeat, min_time=MIN_TIME, passes=repeat)
    for (e, s), t in zip(cells, got):
        if t.value.status != "section:L1":
            raise RuntimeError(f"eps={e}, stages={s}: no return ({t.value.status})")
    return dict(zip(cells, got))


def run(repeat: int = 5, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    rows = measure(repeat)
    load_after = os.getloadavg()
    base = rows[(EPS[0], driver.STIFF_STAGES)]

    def table(get):
        return np.array([[get(rows[(e, s)]) for s in STAGES] for e in EPS])

    dims = ("eps", "stages")
    ds = xr.Dataset(
        {**timing.variables("time", dims, [[rows[(e, s)] for s in STAGES] for e in EPS],
                            "wall time of the return"),
         "runs": (dims, table(lambda t: t.rounds), {
             "long_name": "timed runs (after a warm-up run)", "units": "1"}),
         "steps": (dims, table(lambda t: t.value.n_steps), {
             "long_name": "driver steps of the return", "units": "1"}),
         "return_P": (dims, table(lambda t: float(t.value.z[1])), {
             "long_name": "x2 at the return to L1", "units": "1"}),
         "stiff": (dims, table(lambda t: int("sliding" in t.value.stiff_modes)), {
             "long_name": "1 if the slide went to Radau IIA", "units": "1"})},
        coords={"eps": ("eps", EPS, {"units": "1"}),
                "stages": ("stages", STAGES, {"long_name": "stages of Radau IIA",
                                              "units": "1"})})
    log(f"load average {load_before[0]:.2f} before, {load_after[0]:.2f} after; ms: median "
        f"(q1..q3); ratio to eps {EPS[0]:g}, {driver.STIFF_STAGES} stages: low..high")
    log(f"{'eps':>7} " + " ".join(f"{'s=' + str(s) + ' steps':>12} {'ms (q1..q3)':>25} "
                                   f"{'ratio':>13}" for s in STAGES))
    for e in EPS:
        cells = []
        for s in STAGES:
            t = rows[(e, s)]
            _, low, high = timing.ratio_range(t, base)
            cells.append(f"{t.value.n_steps:12d} {1e3 * t.median:7.1f} ({1e3 * t.q1:7.1f}.."
                         f"{1e3 * t.q3:7.1f}) {low:6.2f}..{high:5.2f}")
        log(f"{e:7.0e} " + " ".join(cells))
    return finalize(ds, None, repeat=repeat, theta=THETA, rtol=1e-12,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME, passes=repeat),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="cost of one sliding return of the Hopf example per eps "
                          "(reference driver)")


#: part of `make bench` (filippov_paper.product): rule bench_sliding_cost runs main(args + ['--out', 'results/bench_sliding_cost.nc'])
WORKFLOW = {"args": []}


def main(argv=None) -> None:
    command_line(__doc__, run, argv, repeat=5)


if __name__ == "__main__":
    main()
