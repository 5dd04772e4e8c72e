"""What a return costs on several switching surfaces beside one (reference driver).

Run ``python -m filippov_paper.benchmarks.surfaces_cost`` (part of ``make bench``). One
planar return, from (0, 0.3) to the section x = 5, of the system of the tutorial's
section on several surfaces (h1 = y; above it F = (1, -1), below it F = (1, 1 - x)):
the orbit reaches y = 0, slides to x = 1, leaves below. Four ways of writing it:

- ``PiecewiseSystem``: one surface, today's system;
- ``SurfacesSystem m=1``: the same as a several-surface definition of one surface (the
  front door makes it today's system);
- ``m=2, h2 spectator``: a second surface x = 2 with the same fields on both sides, so
  the orbit is the same and crosses h2 once: the cost of running it stay by stay
  (filippov.several: one one-surface run per stay, the guard of the other surfaces);
- ``m=2, tutorial``: the tutorial's system, where beyond x = 2 the fields differ (a
  crossing of h2 at y = -1/2, then a slide on y = 0 from x = 4).

Times follow the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`): the
four returns interleaved in ``--repeat`` passes, each with one untimed run, then timed
runs until :data:`MIN_TIME` seconds; the dataset keeps the median with its quartiles,
the events and driver steps of each return, and the ratio to the one-surface return.
"""
from __future__ import annotations

import os

import numpy as np
import xarray as xr

from filippov import PiecewiseSystem, Section, SurfacesSystem, simulate
from filippov.io import finalize
from filippov_paper.benchmarks import command_line, timing

CASES = ["PiecewiseSystem", "SurfacesSystem m=1", "m=2, h2 spectator", "m=2, tutorial"]
START, T_MAX = (0.0, 0.3), 20.0
#: seconds timed per return at least (measure_interleaved's min_time)
MIN_TIME = 0.2


def _below(z):
    return np.array([np.ones_like(z[0]), 1.0 - z[0]])


def _above(z):
    return np.array([np.ones_like(z[0]), -np.ones_like(z[0])])


def _one_grad(z):
    return np.array([np.zeros_like(z[0]), np.ones_like(z[0])])


def _two_grads(z):
    zero, one = np.zeros_like(z[0]), np.ones_like(z[0])
    return np.array([[zero, one], [one, zero]])


def _tutorial(sigma, z):
    one = np.ones_like(z[0])
    if sigma[1] < 0:
        return _above(z) if sigma[0] > 0 else _below(z)
    return np.array([one, -0.1 * one]) if sigma[0] > 0 else np.array([one, 0.25 * one])


def systems() -> dict:
    """The return's system written each way of :data:`CASES`."""
    return {
        CASES[0]: PiecewiseSystem(("x", "y"), _below, _above, lambda z: z[1], _one_grad),
        CASES[1]: SurfacesSystem(("x", "y"), lambda z: z[1:2], lambda z: _one_grad(z)[None],
                                 {(1,): _above, (-1,): _below}, m=1),
        CASES[2]: SurfacesSystem(("x", "y"), lambda z: np.array([z[1], z[0] - 2.0]),
                                 _two_grads,
                                 lambda s, z: _above(z) if s[0] > 0 else _below(z), m=2),
        CASES[3]: SurfacesSystem(("x", "y"), lambda z: np.array([z[1], z[0] - 2.0]),
                                 _two_grads, _tutorial, m=2)}


def a_return(system):
    """The return to x = 5 as a function to time."""
    section = Section("x=5", lambda z: z[0] - 5.0, direction=1, terminal=1)

    def call():
        return simulate(system, list(START), T_MAX, method="integrate", sections=[section],
                        dense=False)
    return call


def run(repeat: int = 5, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    built = systems()
    got, = timing.interleaved_rows([[a_return(built[c]) for c in CASES]],
                                   min_rounds=repeat, min_time=MIN_TIME, passes=repeat)
    load_after = os.getloadavg()
    for c, t in zip(CASES, got):
        if t.value.status != "section:x=5":
            raise RuntimeError(f"{c}: no return ({t.value.status})")
    dims = ("case",)
    ratios = [timing.ratio_range(t, got[0]) for t in got]
    ds = xr.Dataset(
        {**timing.variables("time", dims, got, "wall time of the return"),
         "events": (dims, [len(t.value.events) for t in got], {
             "long_name": "events of the return (its start included)", "units": "1"}),
         "steps": (dims, [t.value.n_steps for t in got], {
             "long_name": "driver steps of the return", "units": "1"}),
         "ratio": (dims, [r[0] for r in ratios], {
             "long_name": "median time over the one-surface return's", "units": "1"}),
         "return_y": (dims, [float(t.value.z[1]) for t in got], {
             "long_name": "y at the return to x = 5", "units": "1"})},
        coords={"case": ("case", CASES)})
    log(f"load average {load_before[0]:.2f} before, {load_after[0]:.2f} after; ms: median "
        f"(q1..q3); ratio to {CASES[0]}: median (low..high)")
    log(f"{'case':>20} {'events':>6} {'steps':>5} {'ms (q1..q3)':>25} {'ratio':>21}")
    for c, t, (mid, low, high) in zip(CASES, got, ratios):
        log(f"{c:>20} {len(t.value.events):6d} {t.value.n_steps:5d} {1e3 * t.median:7.2f} "
            f"({1e3 * t.q1:7.2f}..{1e3 * t.q3:7.2f}) {mid:5.2f} ({low:5.2f}..{high:5.2f})")
    return finalize(ds, None, repeat=repeat, rtol=1e-12,
                    **timing.describe(min_rounds=repeat, min_time=MIN_TIME, passes=repeat),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="cost of one return on several switching surfaces beside one "
                          "(reference driver)")


#: part of `make bench` (filippov_paper.product): rule bench_surfaces_cost runs main(args + ['--out', 'results/bench_surfaces_cost.nc'])
WORKFLOW = {"args": []}


def main(argv=None) -> None:
    command_line(__doc__, run, argv, repeat=5)


if __name__ == "__main__":
    main()
