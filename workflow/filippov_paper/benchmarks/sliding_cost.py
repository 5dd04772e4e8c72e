"""What one sliding return of the Hopf example costs as eps shrinks (reference driver).

Run ``python -m filippov_paper.benchmarks.sliding_cost`` (part of ``make bench``). The
return is the hard-case sweep's (theta = 0.5 from (0, 1.2, 0) to L1, rtol 1e-12):
the sliding field is stiff for eps <= 1e-3 and the driver hands the stay to the
implicit Radau IIA method. For each eps and each number of stages of that method
(3 = the order of scipy's Radau, 5 = the driver's default) the table gives the
driver steps, the median wall time (the benchmarks' convention,
:mod:`filippov_paper.benchmarks.timing`: one untimed run, then at least ``--repeat`` timed
runs, more until :data:`MIN_TIME` seconds were timed; the min is stored too) and its
ratio to the time at the largest eps with the default method (not stiff there: DOP853
only).
"""
from __future__ import annotations

import importlib

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
#: seconds timed per return at least (timing.measure's min_time)
MIN_TIME = 0.2


def measure(eps: float, stages: int, repeat: int) -> dict:
    model = hopf.model(eps, THETA, PARAMETERS["mu"], PARAMETERS["omega"])
    saved = driver.STIFF_STAGES
    driver.STIFF_STAGES = stages
    try:
        t = timing.measure(lambda: driver.simulate(model.full(), list(START), T_MAX,
                                                   sections=[section_L1()], dense=False),
                           min_rounds=repeat, min_time=MIN_TIME)
    finally:
        driver.STIFF_STAGES = saved
    traj = t.value
    if traj.status != "section:L1":
        raise RuntimeError(f"eps={eps}, stages={stages}: no return ({traj.status})")
    return {"time": t.median, "time_min": t.min, "runs": t.rounds, "steps": traj.n_steps,
            "P": float(traj.z[1]), "stiff": int("sliding" in traj.stiff_modes)}


def run(repeat: int = 5, log=print) -> xr.Dataset:
    rows = {(e, s): measure(e, s, repeat) for s in STAGES for e in EPS}
    base = rows[(EPS[0], driver.STIFF_STAGES)]["time"]

    def table(key):
        return (("eps", "stages"), np.array([[rows[(e, s)][key] for s in STAGES] for e in EPS]))

    ds = xr.Dataset(
        {"time": (*table("time"), {"long_name": "median wall time of the return",
                                   "units": "s"}),
         "time_min": (*table("time_min"), {"long_name": "min wall time of the return "
                                                        "(fastest run)", "units": "s"}),
         "runs": (*table("runs"), {"long_name": "timed runs (after a warm-up run)",
                                   "units": "1"}),
         "steps": (*table("steps"), {"long_name": "driver steps of the return", "units": "1"}),
         "return_P": (*table("P"), {"long_name": "x2 at the return to L1", "units": "1"}),
         "stiff": (*table("stiff"), {"long_name": "1 if the slide went to Radau IIA",
                                     "units": "1"})},
        coords={"eps": ("eps", EPS, {"units": "1"}),
                "stages": ("stages", STAGES, {"long_name": "stages of Radau IIA",
                                              "units": "1"})})
    log(f"{'eps':>7} " + " ".join(f"{'s=' + str(s) + ' steps':>12} {'ms':>7} {'ratio':>6}"
                                   for s in STAGES))
    for e in EPS:
        log(f"{e:7.0e} " + " ".join(
            f"{rows[(e, s)]['steps']:12d} {1e3 * rows[(e, s)]['time']:7.1f} "
            f"{rows[(e, s)]['time'] / base:6.2f}" for s in STAGES))
    return finalize(ds, None, repeat=repeat, theta=THETA, rtol=1e-12,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME),
                    title="cost of one sliding return of the Hopf example per eps "
                          "(reference driver)")


#: part of `make bench` (filippov_paper.product): rule bench_sliding_cost runs main(args + ['--out', 'results/bench_sliding_cost.nc'])
WORKFLOW = {"args": []}


def main(argv=None) -> None:
    command_line(__doc__, run, argv, repeat=5)


if __name__ == "__main__":
    main()
