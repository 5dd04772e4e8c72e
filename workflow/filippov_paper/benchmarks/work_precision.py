"""Work against precision for the return maps: what each digit costs.

Run ``python -m filippov_paper.benchmarks.work_precision`` (``make bench`` or
``snakemake bench``). For every problem (the fig04 return maps, one per theta,
and the fig11 return maps of the slow-fast dry-friction oscillator, one per
panel) each method is swept over tolerances and scored by

* ``error_map``: max |P - P_ref| over the grid; for fig04 the points within
  ``1e-6`` of the grazing value x2 = 1 are left out (there the map jumps or has
  an infinite slope: the error measures the conditioning, not the method); the
  fig11 maps are continuous and every point is scored;
* ``error_switch``: max |t_switch - t_switch_ref| of the first change of mode;
* ``wall_time``: the median of ``runs`` timed runs in this process (one core), by
  the benchmarks' timing convention (:mod:`filippov_paper.benchmarks.timing`): one untimed
  run of each method on each problem first (the first tolerance of its family: it
  pays for compiling and loading the kernel and the model's generated pieces), then
  at least ``repeat`` timed runs per configuration, more until ``min_time`` seconds
  were timed, the runs of all configurations interleaved (``passes`` passes, each
  giving every configuration its share of the runs: load falls on all alike);
  ``wall_time_q1`` and ``wall_time_q3`` are the quartiles of the runs (the spread
  the report prints next to the median), ``wall_time_min`` and ``wall_time_max`` the
  fastest and slowest. For fig11 the start points on M_+ are computed once beforehand
  and not timed. The machine (CPU model, cores, versions of Python, numpy, scipy and
  numba) and its load average before and after the timing are dataset attributes;
* ``time_per_return``: ``wall_time`` over the map's start points, the cost of one
  return (also printed per configuration, in microseconds);
* ``speedup_vs_rk45``: at the target error, RK45's time over the fastest project
  configuration's, from the medians; ``speedup_vs_rk45_low`` and ``_high`` its range
  from the quartiles (RK45's first over the project's third, third over first);

against a reference computed independently of the method measured. fig04:
the compiled exact flows at rtol 1e-13 for every integrator, and the project's
DOP853 at rtol 1e-13 for the exact-flow modes themselves. fig11 (no exact
flows; the exact-flow families are "n/a" there): the project's DOP853 at rtol
1e-13 for every solve_ivp method, and solve_ivp DOP853 at rtol 1e-13 for the
project's driver. The difference of the two references, ``reference_check``,
is the floor no error below it can be trusted.

The project's methods: its compiled exact flows, the same algorithm in Python,
its DOP853 driver in Python and the compiled twin of that driver ("project
compiled DOP853": every mode integrated with DOP853 inside the numba kernel,
the only compiled mode for the dry-friction model).

A method that raises or runs over ``--time-cap`` seconds is kept in the table
with its status, never dropped. A table is printed; the dataset goes to
``--out`` (``results/bench_work_precision.nc``).
"""
from __future__ import annotations

import argparse
import math
import os
import re
import sys
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import xarray as xr
import yaml

from filippov.poincare import first_returns
from filippov.io import finalize, write_dataset
from filippov.models import dry_friction
from filippov.models import hopf
from filippov_paper.scenes.fig04_retmaps import return_map, x2_grid
from filippov_paper.benchmarks import baseline, timing
from filippov_paper.report import (FIT_BEGIN, FIT_END, Macros, absent, count_phrase, num,
                                   range_phrase, source, table_frame, tex_escape)

ROOT = Path(__file__).resolve().parents[3]
SCENE = ROOT / "config" / "scenes" / "fig04_retmaps.yaml"
SCENE11 = ROOT / "config" / "scenes" / "fig11_dfo_retmaps.yaml"
T_MAX11 = 200.0  # time limit of one fig11 return (the scene's)
TARGET_ERROR = 1e-8
GRAZING_GAP = 1e-6

# (family, tolerances): the project's modes first, then solve_ivp as a user would call it
PROJECT = [("project compiled exact", [1e-6, 1e-8, 1e-10, 1e-12]),
           ("project python exact", [1e-12]),
           ("project compiled DOP853", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-13]),
           ("project DOP853", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12, 1e-13])]
SCIPY = [("solve_ivp RK45", [1e-3, 1e-4, 1e-6, 1e-8, 1e-10]),
         ("solve_ivp DOP853", [1e-4, 1e-6, 1e-8, 1e-10, 1e-12]),
         ("solve_ivp Radau", [1e-4, 1e-6, 1e-8]),
         ("solve_ivp LSODA", [1e-4, 1e-6, 1e-8, 1e-10])]
QUICK = [("project compiled exact", [1e-10]), ("project DOP853", [1e-8]),
         ("solve_ivp RK45", [1e-6])]
#: the default build's sweep (rule work_precision, results/work_precision.nc): about
#: a minute on subgrids of both scenes (most of it the >= 3 timed runs of the Python
#: and solve_ivp configurations), with what a user reaches for first
#: (solve_ivp RK45 and DOP853) next to the project's modes; `make bench` runs the
#: full sweep
BUILD = {"families": [("project compiled exact", [1e-8, 1e-10, 1e-12]),
                      ("project compiled DOP853", [1e-6, 1e-8, 1e-10, 1e-12]),
                      ("project DOP853", [1e-8, 1e-12]),
                      # not rtol 1e-4: there RK45's steps are long enough to step over
                      # the section itself, and whether it does (no return: a failed row)
                      # flipped under a 1-ulp change of the field (measured); `make bench`
                      # still runs it
                      ("solve_ivp RK45", [1e-6, 1e-8, 1e-10]),
                      ("solve_ivp DOP853", [1e-6, 1e-8, 1e-10, 1e-12])],
         "every": 20, "every11": 3, "repeat": 3, "time_cap": 60.0, "min_time": 0.2,
         "passes": 3}
#: ``time_cap``: a guard against a run that hangs, not a budget: far above the slowest
#: cell of the build (project DOP853 rtol 1e-12 on fig04 theta = 0.5: 5 s a run on an
#: idle core, over 10 s at load 6, which tripped the former 10 s cap), since a cell that
#: trips it on one machine and not on another changes the NaN pattern the manifest checks
#: ``repeat``: timed runs per configuration at least (after the warm-up run of each
#: method on each problem); ``min_time``: more runs until that many seconds were timed;
#: ``passes``: the runs of all configurations interleaved in that many passes (one run of
#: each slow configuration per pass, a third of each fast one's runs): as many runs and
#: seconds as timing each configuration in one go, but a spell of load on the machine
#: falls on every configuration alike instead of on the ones timed during it
#: (docs/decisions.md#interleaved-timing)
PRESETS = {"full": {"families": PROJECT + SCIPY, "every": 10, "every11": 5, "repeat": 3,
                    "time_cap": 120.0, "min_time": 1.0, "passes": 3},
           "build": BUILD,
           "quick": {"families": QUICK, "every": 10, "every11": 5, "repeat": 3,
                     "time_cap": 120.0, "min_time": 0.2, "passes": 3}}

#: how closely two runs agree (filippov_paper.tolerance): times never do. An error
#: |P - P_ref| of an approximate method is not a well-conditioned result: it is decided
#: by the method's discrete choices (a step accepted or rejected at an error norm near
#: 1, a sign change of h seen or missed at a step end), which a last-bit change
#: re-draws, and local errors that cancel can leave any value below the error's
#: envelope. Only its order of magnitude is a result, so errors are compared by rule
#: "order": within a factor 10 either way (methods and tolerances differ by decades),
#: symmetric in the two builds, above a floor under which step choices decide them.
#: (Rule "close" with rtol 10, used before, let a value fall to 0 but rise only 11-fold
#: from the reference: whether two builds agreed depended on which wrote the manifest.)
#: Floors, measured by re-drawing the step sequence (rtol scaled by 1 + k 1e-9, 16
#: sequences, native) and with the emulated CPU of tests/crosscpu (seeds 1-3):
#: * error_map, 1e-9: the level where a method run at rtol 1e-12..1e-13 is decided by
#:   one step or event choice (below it, e.g. the fig11 (b) map error at rtol 1e-10:
#:   1.7e-10 <-> 1.9e-11); above it the map errors moved by a factor <= 1.2;
#: * error_switch, 1e-8: a switching time is conditioned by 1/(dh/dt) at the
#:   crossing, which grows as 1/sqrt(distance to grazing): the fig11 (b) start x1 =
#:   4.31875 lies 3.8e-3 past the grazing start 4.31495 (dt_sw/dx1 = -10.4 there,
#:   -1.1..-2.2 at the other starts), and its first-switch error at rtol 1e-10 is
#:   anything from 1.6e-9 to 2.6e-8 over the 16 step sequences (max over 5 builds:
#:   1.4e-9 .. 2.5e-8, a factor 16 apart); with the floor at 1e-8 that is a factor <= 2.6.
def tolerances() -> dict:
    from filippov_paper.tolerance import MEASURED, Tolerance

    why = ("error of an approximate method: decided by discrete step and event choices, "
           "re-drawn by a last-bit change; only its order is a result")
    err = Tolerance(10.0, 1e-9, why + "; floor: one step choice at rtol 1e-12 (measured)",
                    rule="order")
    err_switch = Tolerance(10.0, 1e-8, why + "; floor: step choices near grazing, "
                           "conditioning 1/sqrt(distance): 1.6e-9..2.6e-8 at rtol 1e-10 "
                           "(measured)", rule="order")
    # reference_check is itself the difference of two approximate solves (rtol 1e-13):
    # an error like error_map, decided by both solves' step choices, which a last-bit
    # change re-draws (each solve's map moves by ~3e-13, measured): its order is the
    # result; floor 1e-12, the sum of the two re-drawn errors (6e-13) rounded up. The
    # close rule before (atol 1e-12) gave one step choice of each solve no room: the
    # largest check, 1.6e-12, went to 9.7e-13 at +-2 ulps
    check = Tolerance(10.0, 1e-12, "difference of two solves at rtol 1e-13, an error of "
                                   "approximate methods like error_map: its order; floor: "
                                   "each map moves by ~3e-13 under a last-bit change "
                                   "(measured), two of them, rounded up", rule="order")
    # each missed switch is a discrete choice (does a step straddle a short excursion
    # into H_-?) that a step-size sequence changed in its last bits can flip
    missed = Tolerance(0.5, 2.0, "count of grazing excursions an approximate method steps "
                                 "over: each decided by where its steps end; 0 -> 2 under a "
                                 "1-ulp change of the field for RK45 at rtol 1e-4 (measured)")
    return {"wall_time": MEASURED, "wall_time_min": MEASURED, "wall_time_q1": MEASURED,
            "wall_time_q3": MEASURED, "wall_time_max": MEASURED, "time_per_return": MEASURED,
            "runs": MEASURED, "time_ours_at_target": MEASURED,
            "time_rk45_at_target": MEASURED, "speedup_vs_rk45": MEASURED,
            "speedup_vs_rk45_low": MEASURED, "speedup_vs_rk45_high": MEASURED,
            "error_map": err, "error_switch": err_switch, "reference_check": check,
            "missed_switches": missed}


@dataclass(frozen=True)
class Problem:
    """One return map to benchmark. fig04: ``x2`` is the start coordinate x2 on
    the section x1 = 0 (``model``: the Hopf model). fig11: ``x2`` holds the x1
    of the start points on L = {x2 = 0, x1 > 0} and ``start_states`` the full
    states (x1, 0, w on M_+), ``model`` the dry-friction PiecewiseSystem and
    ``compiled`` the same system for the compiled kernel."""
    name: str
    x2: np.ndarray
    model: object
    scored: np.ndarray  # grid points the error is taken over
    kind: str = "fig04"
    start_states: np.ndarray = None
    compiled: object = None

    @property
    def starts(self):
        if self.start_states is not None:
            return self.start_states
        return np.stack([np.zeros_like(self.x2), self.x2, np.zeros_like(self.x2)], axis=1)

    @property
    def reference(self):
        """(family, rtol) of the reference and of its independent check."""
        if self.kind == "fig11":
            return ("project DOP853", 1e-13), ("solve_ivp DOP853", 1e-13)
        return ("project compiled exact", 1e-13), ("project DOP853", 1e-13)

    def scored_by_check(self, family: str) -> bool:
        """Whether ``family`` is scored against the check (it is the reference's own method)."""
        if self.kind == "fig11":
            return family.startswith("project")
        return "exact" in family

    def subset(self, idx):
        """The problem on a subset of its start points."""
        return Problem(self.name, self.x2[idx], self.model, self.scored[idx], self.kind,
                       None if self.start_states is None else self.start_states[idx],
                       self.compiled)


class NotApplicable(RuntimeError):
    """The configuration does not apply to the problem (e.g. exact flows for fig11)."""


def fig04_problems(every: int) -> list[Problem]:
    p = yaml.safe_load(SCENE.read_text())["parameters"]
    x2 = x2_grid(p)[::every]
    return [Problem(f"fig04 theta={th:g}", x2, hopf.model(p["eps"], th, p["mu"], p["omega"]),
                    np.abs(x2 - 1.0) > GRAZING_GAP) for th in p["theta"]]


def fig11_problems(every: int) -> list[Problem]:
    """The two panels of fig11 (eq:dfo-sf) on every ``every``-th point of the
    scene's uniform base grid (n_x1 points). Start points on M_+ are computed
    once (by relaxation, :func:`dry_friction.slow_manifold_plus`), so every
    method maps the same states; all points are scored (the map is continuous)."""
    p = yaml.safe_load(SCENE11.read_text())["parameters"]
    x1 = np.linspace(float(p["x1_min"]), float(p["x1_max"]), int(p["n_x1"]))[::every]
    ml = {k: p[k] for k in ("gamma", "f0", "fv", "fc")}
    ml["convention"] = p.get("convention", "stribeck")
    out = []
    for k, (eps, v0) in enumerate(zip(p["eps"], p["v0"])):
        w, _ = dry_friction.slow_manifold_plus(x1, 0.0, float(eps), float(v0), **ml)
        starts = np.stack([x1, np.zeros_like(x1), w], axis=1)
        out.append(Problem(f"fig11 ({'ab'[k]}) eps={eps:g}", x1,
                           dry_friction.full_system(float(eps), float(v0), **ml),
                           np.ones(x1.size, dtype=bool), "fig11", starts,
                           dry_friction.compiled(float(eps), float(v0), **ml)))
    return out


def _fig11_project(problem: Problem, rtol: float, atol: float, time_cap: float):
    from filippov_paper.scenes.fig11_dfo_retmaps import section_L
    from filippov.simulate import simulate

    t0 = time.perf_counter()
    P, first = np.empty(len(problem.starts)), np.full(len(problem.starts), np.nan)
    for i, z0 in enumerate(problem.starts):
        traj = simulate(problem.model, z0, T_MAX11, method="integrate", rtol=rtol, atol=atol,
                        sections=[section_L()], dense=False, samples_per_step=1)
        if traj.status != "section:L":
            raise RuntimeError(f"start {z0.tolist()}: no return ({traj.status})")
        P[i] = traj.z[0]
        sw = traj.switches()
        if sw:
            first[i] = sw[0].t
        if time.perf_counter() - t0 > time_cap:
            raise baseline.TimeCapExceeded(f"over the {time_cap:g} s cap")
    return P, first


def _fig11_compiled(problem: Problem, rtol: float, atol: float):
    """fig11 on the compiled kernel (every mode integrated by DOP853), sampled as
    the scene runs it: one sample per step."""
    ret = first_returns(problem.compiled, problem.starts, None, T_MAX11, engine="compiled",
                        rtol=rtol, atol=atol, samples_per_step=1)
    return ret.state[:, 0], ret.first_switch


def runner(problem: Problem, family: str, tol: float, time_cap: float) -> Callable:
    """A function returning ``(P, first switch times)`` for one configuration.
    Raises :class:`NotApplicable` for a configuration the problem has no use for."""
    opts = {"rtol": tol, "atol": tol * 1e-2}
    if problem.kind == "fig11":
        if family == "project compiled DOP853":
            return lambda: _fig11_compiled(problem, opts["rtol"], opts["atol"])
        if family == "project DOP853":
            return lambda: _fig11_project(problem, opts["rtol"], opts["atol"], time_cap)
        if family.startswith("project"):
            raise NotApplicable(f"{family}: the dry-friction model has no exact flows")

        def run11():
            states, _, first = baseline.first_returns(
                problem.model, problem.starts, lambda z: z[1], lambda z: z[0] > 0, -1,
                T_MAX11, family.split()[-1], opts["rtol"], opts["atol"], time_cap=time_cap)
            return states[:, 0], first
        return run11
    if family.startswith("project"):
        method = "integrate" if "DOP853" in family else "exact"
        engine = "compiled" if "compiled" in family else "reference"

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


def run(problems, families, repeat: int, time_cap: float, log=print,
        min_time: float = timing.MIN_TIME, passes: int | None = None,
        **settings) -> xr.Dataset:
    """Every configuration on every problem; ``settings`` (preset, grid strides) are
    stored as attributes. Timing (:mod:`filippov_paper.benchmarks.timing`): the
    configurations' rounds are interleaved (:func:`filippov_paper.benchmarks.timing.
    measure_interleaved`, ``passes`` passes, default ``repeat``): each pass gives every
    configuration of every problem its share of the rounds before the next pass starts,
    so that a spell of load falls on all alike. Before the first configuration of a
    family on a problem, in the first pass, one untimed run of it (compilation and
    caches paid there; repeated at the next tolerance if that run fails); then at
    least ``repeat`` timed runs per configuration, more until ``min_time`` s were timed;
    ``wall_time`` is their median, ``wall_time_q1`` and ``wall_time_q3`` its spread
    (the quartiles), ``wall_time_min`` and ``wall_time_max`` their extremes. The
    machine and its load average before and after the timing are dataset attributes."""
    passes = repeat if passes is None else passes
    configs = [(fam, tol) for fam, tols in families for tol in tols]
    res = _Results.empty(len(problems), len(configs))
    ref_check = np.empty(len(problems))
    ref_names = [""] * len(problems)
    warmed = [set() for _ in problems]  # families run once (untimed or not) on each problem
    # Every configuration off the compiled engine first, then those on it (in every pass),
    # then the references and the scores. In a cold workflow build this job (started
    # first: the longest) times its Python and solve_ivp runs while another job compiles
    # the kernel, which it then loads, instead of waiting for that compile with a core idle.
    cells = [(i, j) for compiled in (False, True) for i in range(len(problems))
             for j, (fam, _) in enumerate(configs) if _compiled(fam) == compiled]
    fns, timed_cells = [], []
    for i, j in cells:
        fn = res.runner(i, j, problems[i], *configs[j], time_cap=time_cap, warmed=warmed[i])
        if fn is not None:
            fns.append(fn)
            timed_cells.append((i, j))

    def warmup(k):
        i, j = timed_cells[k]
        return 0 if configs[j][0] in warmed[i] else 1

    def before(p, k):
        if k == 0:
            log(f"pass {p} of {passes}: {len(fns)} configurations")

    load_before = os.getloadavg()
    t0 = time.perf_counter()
    got = {}
    for (i, j), t in zip(timed_cells, timing.measure_interleaved(
            fns, warmup=warmup, min_rounds=repeat, min_time=min_time, passes=passes,
            before=before)):
        got[i, j] = res.record(i, j, t)
    load_after = os.getloadavg()
    log(f"timed {len(fns)} configurations in {passes} interleaved passes, "
        f"{time.perf_counter() - t0:.1f} s; load average {load_before[0]:.2f} before, "
        f"{load_after[0]:.2f} after")
    for i, prob in enumerate(problems):
        ref, chk, ref_check[i], ref_names[i] = _reference(prob)
        log(f"{prob.name}: {prob.x2.size} start points; reference check "
            f"({ref_names[i]}): {ref_check[i]:.2e}")
        for j, (fam, tol) in enumerate(configs):
            # the reference's own method is scored against the independent check
            if got.get((i, j)) is not None:
                res.score(i, j, prob, got[i, j], chk if prob.scored_by_check(fam) else ref)
            log(res.line(i, j, fam, tol, prob.x2.size))
    fam_of = np.array([c[0] for c in configs])
    at_target = _at_target(fam_of, res.err_map, res.wall, res.wall_q1, res.wall_q3)
    ds = _dataset(problems, configs, fam_of, res, ref_check, ref_names, at_target)
    from filippov_paper.tolerance import annotate

    ds = annotate(ds, tolerances())
    return finalize(ds, None, target_error=TARGET_ERROR, time_cap=time_cap, repeat=repeat,
                    grazing_gap=GRAZING_GAP, min_time=min_time, **settings,
                    **timing.describe(min_rounds=repeat, min_time=min_time, passes=passes),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="work-precision of the fig04 and fig11 return maps: project vs solve_ivp")


def _compiled(family: str) -> bool:
    """Whether configurations of ``family`` run on the compiled kernel."""
    return family.startswith("project compiled")


def _reference(prob: Problem):
    """The problem's reference (P, switch times), its independent check, their max
    deviation and the pair's description."""
    (ref_fam, ref_tol), (chk_fam, chk_tol) = prob.reference
    ref = runner(prob, ref_fam, ref_tol, np.inf)()
    chk = runner(prob, chk_fam, chk_tol, np.inf)()
    check = max_dev(chk[0], ref[0], prob.scored)[0]
    return ref, chk, check, f"{ref_fam} rtol {ref_tol:g} vs {chk_fam} rtol {chk_tol:g}"


@dataclass
class _Results:
    """Per (problem, configuration): errors, wall times, timed runs and status."""
    err_map: np.ndarray
    err_sw: np.ndarray
    wall: np.ndarray
    wall_min: np.ndarray
    wall_q1: np.ndarray
    wall_q3: np.ndarray
    wall_max: np.ndarray
    runs: np.ndarray
    missed: np.ndarray
    status: np.ndarray

    @classmethod
    def empty(cls, n_problems: int, n_configs: int) -> "_Results":
        shape = (n_problems, n_configs)
        return cls(err_map=np.full(shape, np.nan), err_sw=np.full(shape, np.nan),
                   wall=np.full(shape, np.nan), wall_min=np.full(shape, np.nan),
                   wall_q1=np.full(shape, np.nan), wall_q3=np.full(shape, np.nan),
                   wall_max=np.full(shape, np.nan),
                   runs=np.zeros(shape, dtype=np.int32), missed=np.zeros(shape, dtype=np.int32),
                   status=np.full(shape, "ok", dtype=object))

    def runner(self, i, j, prob, fam, tol, *, time_cap, warmed):
        """Configuration j on problem i as a function to time (its first success marks
        ``fam`` warmed on the problem), or None when it does not apply there (``status``
        n/a)."""
        try:
            fn = runner(prob, fam, tol, time_cap)
        except NotApplicable:
            self.status[i, j] = "n/a"
            return None

        def call():
            value = fn()
            warmed.add(fam)
            return value
        return call

    def record(self, i, j, t):
        """The timing ``t`` of configuration j on problem i (a Timing, or the exception
        it raised): its (P, first switch times), or None after a failure, which is
        listed in ``status``, not dropped."""
        if isinstance(t, timing.Timing):
            self.wall[i, j], self.wall_min[i, j], self.runs[i, j] = t.median, t.min, t.rounds
            self.wall_q1[i, j], self.wall_q3[i, j], self.wall_max[i, j] = t.q1, t.q3, t.max
            return t.value
        if isinstance(t, NotApplicable):
            self.status[i, j] = "n/a"
        elif isinstance(t, baseline.TimeCapExceeded):
            self.status[i, j] = f"time cap: {t}"
        else:  # listed, not dropped
            self.status[i, j] = f"failed: {type(t).__name__}: {t}"[:200]
        return None

    def score(self, i, j, prob, got, want):
        """The errors of configuration j's (P, first switch times) ``got`` on problem i
        against ``want``."""
        (got_p, got_sw), (want_p, want_sw) = got, want
        self.err_map[i, j] = max_dev(got_p, want_p, prob.scored)[0]
        self.err_sw[i, j], self.missed[i, j] = max_dev(got_sw, want_sw, prob.scored)

    def line(self, i, j, fam, tol, n_points) -> str:
        """The log line of configuration j on problem i."""
        wall, status = self.wall[i, j], self.status[i, j]
        return (f"  {fam:24s} rtol {tol:7.0e}  {wall:9.4f} s (quartiles {self.wall_q1[i, j]:9.4f} "
                f"..{self.wall_q3[i, j]:9.4f} s, min {self.wall_min[i, j]:9.4f} s, "
                f"{self.runs[i, j]:4d} runs; {1e6 * wall / n_points:8.1f} us/return)  "
                f"map err {self.err_map[i, j]:9.2e}"
                f"  switch err {self.err_sw[i, j]:9.2e} ({self.missed[i, j]} missed)  "
                f"{status if status != 'ok' else ''}")


def _at_target(fam_of, err_map, wall, wall_q1=None, wall_q3=None):
    """Per problem: the fastest project configuration within TARGET_ERROR, RK45's time
    at that error, and their ratio (all of the medians ``wall``); and the ratio's range
    from the spread: RK45's first quartile over the project's third, RK45's third over
    the project's first (each time taken as the median is, from that quartile; the
    ratio of the medians lies in it). Without quartiles the range is NaN."""
    n = err_map.shape[0]
    q1 = np.full(wall.shape, np.nan) if wall_q1 is None else wall_q1
    q3 = np.full(wall.shape, np.nan) if wall_q3 is None else wall_q3
    ours = np.array([f.startswith("project") for f in fam_of])
    rk = fam_of == "solve_ivp RK45"
    out = {k: np.full(n, np.nan) for k in ("ours", "rk45", "ratio", "low", "high")}
    for i in range(n):
        ok = ours & (err_map[i] <= TARGET_ERROR)
        t = {}
        for name, times in (("med", wall), ("q1", q1), ("q3", q3)):
            t["ours", name] = times[i, ok].min() if ok.any() else np.nan
            t["rk", name] = time_at_error(err_map[i, rk], times[i, rk], TARGET_ERROR)
        out["ours"][i], out["rk45"][i] = t["ours", "med"], t["rk", "med"]
        out["ratio"][i] = t["rk", "med"] / t["ours", "med"]
        out["low"][i] = t["rk", "q1"] / t["ours", "q3"]
        out["high"][i] = t["rk", "q3"] / t["ours", "q1"]
    return out


def _dataset(problems, configs, fam_of, res: _Results, ref_check, ref_names,
             at_target) -> xr.Dataset:
    dims = ("problem", "config")
    n_points = np.array([p.x2.size for p in problems], dtype=np.int32)
    return xr.Dataset(
        {"error_map": (dims, res.err_map, {"long_name": "max |P - P_ref| over the grid",
                                           "units": "1"}),
         "error_switch": (dims, res.err_sw, {
             "long_name": "max error of the first switching time (points where both switch)",
             "units": "1"}),
         "missed_switches": (dims, res.missed, {
             "long_name": "start points where only one of method and reference switches "
                          "(a grazing excursion missed or invented)", "units": "1"}),
         "wall_time": (dims, res.wall, {
             "long_name": "median wall time of one map (timed runs after a warm-up run)",
             "units": "s", "statistic": timing.STATISTIC}),
         "wall_time_min": (dims, res.wall_min, {
             "long_name": "min wall time of one map (the fastest timed run)", "units": "s",
             "statistic": "min"}),
         "wall_time_q1": (dims, res.wall_q1, {
             "long_name": "first quartile of the wall times of one map (the spread of "
                          "wall_time: q1 to q3)", "units": "s", "statistic": "q1"}),
         "wall_time_q3": (dims, res.wall_q3, {
             "long_name": "third quartile of the wall times of one map", "units": "s",
             "statistic": "q3"}),
         "wall_time_max": (dims, res.wall_max, {
             "long_name": "max wall time of one map (the slowest timed run)", "units": "s",
             "statistic": "max"}),
         "time_per_return": (dims, res.wall / n_points[:, None], {
             "long_name": "cost of one return: median wall time of the map over its start "
                          "points", "units": "s", "statistic": timing.STATISTIC}),
         "runs": (dims, res.runs, {"long_name": "timed runs the median and min are taken over "
                                                "(the warm-up run not counted)", "units": "1"}),
         "status": (dims, res.status.astype(str),
                    {"long_name": "ok, failed: ..., or time cap: ..."}),
         "reference_check": ("problem", ref_check, {
             "long_name": "max |P_reference - P_check| (see reference_pair)", "units": "1"}),
         "reference_pair": ("problem", np.array(ref_names, dtype=str), {
             "long_name": "reference and its independent check"}),
         "n_points": ("problem", n_points,
                      {"long_name": "start points per map", "units": "1"}),
         "time_ours_at_target": ("problem", at_target["ours"], {
             "long_name": "fastest project configuration with error <= target", "units": "s"}),
         "time_rk45_at_target": ("problem", at_target["rk45"], {
             "long_name": "solve_ivp RK45 time at the target error (log-log interpolation; "
                          "NaN: not reached)", "units": "s"}),
         "speedup_vs_rk45": ("problem", at_target["ratio"], {
             "long_name": "RK45 time / project time at equal error (the target), medians",
             "units": "1"}),
         "speedup_vs_rk45_low": ("problem", at_target["low"], {
             "long_name": "low end of the speed-up's range: RK45's first quartile over the "
                          "project's third", "units": "1"}),
         "speedup_vs_rk45_high": ("problem", at_target["high"], {
             "long_name": "high end of the speed-up's range: RK45's third quartile over the "
                          "project's first", "units": "1"})},
        coords={"problem": ("problem", [p.name for p in problems],
                            {"long_name": "return map measured (scene and panel)"}),
                "method": ("config", fam_of, {"long_name": "method (project mode or solve_ivp)"}),
                "tolerance": ("config", [c[1] for c in configs],
                              {"long_name": "relative tolerance rtol (atol = rtol/100)",
                               "units": "1"})})


def merge(parts: list[xr.Dataset]) -> xr.Dataset:
    """Datasets of :func:`run` on disjoint problem sets (chunk jobs) as one, in the
    order given; they must share the configurations (methods, tolerances) and the
    settings (target error, time cap, repeats)."""
    if not parts:
        raise ValueError("nothing to merge")
    first = parts[0]
    for ds in parts[1:]:
        if not (np.array_equal(ds.method.values, first.method.values)
                and np.array_equal(ds.tolerance.values, first.tolerance.values)):
            raise ValueError("benchmark parts were run with different method/tolerance lists")
        for key in ("target_error", "time_cap", "repeat", "grazing_gap", "preset", "min_time",
                    "timing_statistic", "timing_warmup", "timing_max_rounds", "timing_passes"):
            if ds.attrs.get(key) != first.attrs.get(key):
                raise ValueError(f"benchmark parts differ in their setting {key!r}")
    names = np.concatenate([ds.problem.values for ds in parts])
    if len(set(names)) != len(names):
        raise ValueError(f"a problem appears in more than one part: {list(names)}")
    # what the parts measured of the machine (its load before and after each part's
    # timing) differs from part to part: the merged dataset states the largest
    attrs = dict(first.attrs)
    for key in attrs:
        values = [ds.attrs.get(key) for ds in parts]
        if any(not np.array_equal(v, values[0]) for v in values[1:]):
            numbers = [v for v in values if isinstance(v, (int, float, np.number))]
            attrs[key] = max(numbers) if len(numbers) == len(values) else values[0]
    parts = [ds.copy() for ds in parts]
    for ds in parts:
        ds.attrs = dict(attrs)
    return xr.concat(parts, dim="problem", data_vars="minimal", coords="minimal",
                     compat="identical", combine_attrs="override")


def table(ds: xr.Dataset) -> str:
    stat = ds.attrs.get("timing_statistic", "median")
    has_min, has_q = "wall_time_min" in ds, "wall_time_q1" in ds
    lines = [f"times: {ds.attrs.get('timing', stat)}"]
    if "machine_cpu" in ds.attrs:
        lines.append(f"machine: {ds.attrs['machine_cpu']}, {ds.attrs.get('cpus')} cores; "
                     f"load average {ds.attrs.get('load_average_before', math.nan):.2f} "
                     f"before, {ds.attrs.get('load_average_after', math.nan):.2f} after; "
                     f"Python {ds.attrs.get('python_version')}, numpy "
                     f"{ds.attrs.get('numpy_version')}, scipy {ds.attrs.get('scipy_version')}, "
                     f"numba {ds.attrs.get('numba_version')}")
    for i, prob in enumerate(ds.problem.values):
        lines.append(f"\n{prob}: {int(ds.n_points[i])} points, reference check "
                     f"{float(ds.reference_check[i]):.1e}")
        lines.append(f"{'method':26s} {'rtol':>7s} {stat + ' [s]':>10s} {'q1 [s]':>10s} "
                     f"{'q3 [s]':>10s} {'min [s]':>10s} "
                     f"{'runs':>5s} {'map error':>10s} {'switch err':>10s} {'missed':>6s}  status")
        for j in range(ds.sizes["config"]):
            st = str(ds.status.values[i, j])
            t_min = float(ds.wall_time_min[i, j]) if has_min else np.nan
            q1, q3 = ((float(ds.wall_time_q1[i, j]), float(ds.wall_time_q3[i, j])) if has_q
                      else (np.nan, np.nan))
            lines.append(f"{str(ds.method.values[j]):26s} {float(ds.tolerance[j]):7.0e} "
                         f"{float(ds.wall_time[i, j]):10.4f} {q1:10.4f} {q3:10.4f} {t_min:10.4f} "
                         f"{int(ds.runs[i, j]):5d} {float(ds.error_map[i, j]):10.2e} "
                         f"{float(ds.error_switch[i, j]):10.2e} {int(ds.missed_switches[i, j]):6d}  {'' if st == 'ok' else st}")
        lines.append(f"at error {TARGET_ERROR:g}: project {float(ds.time_ours_at_target[i]):.4f} s, "
                     f"RK45 {float(ds.time_rk45_at_target[i]):.4f} s, "
                     f"speed-up {float(ds.speedup_vs_rk45[i]):.2g}x"
                     + (f" ({float(ds.speedup_vs_rk45_low[i]):.2g}x to "
                        f"{float(ds.speedup_vs_rk45_high[i]):.2g}x from the quartiles)"
                        if "speedup_vs_rk45_low" in ds else ""))
    return "\n".join(lines)


# ============================================================================= report
# What the reproduction report quotes from the default build's sweep (filippov_paper.report
# calls `report`, in REPORT's order among the benchmarks): Table tab:bench's first blocks
# and the macros of sec_bench. This part -- REPORT, report and the _report_* / _REPORT_*
# names -- is left out of the code hash of the jobs that run the sweep: editing it rebuilds
# the report only.
REPORT = {"dataset": "work_precision", "table": "tab_bench.tex", "order": 20}

#: the methods as the work-precision table names them (short: the table fits the page)
_REPORT_METHOD_TEX = {"project compiled exact": "compiled, exact flows",
                      "project python exact": "Python, exact flows",
                      "project compiled DOP853": "compiled DOP853",
                      "project DOP853": "Python DOP853",
                      "solve_ivp RK45": "scipy RK45",
                      "solve_ivp DOP853": "scipy DOP853",
                      "solve_ivp Radau": "scipy Radau",
                      "solve_ivp LSODA": "scipy LSODA"}


def _report_has_spread(ds) -> bool:
    """Whether the sweep stored the spread of its times (the quartiles of the runs)."""
    return "wall_time_q1" in ds and "wall_time_q3" in ds


def _report_ms(seconds) -> str:
    """A time of the table, in milliseconds (two digits: the spread says the rest)."""
    return num(1e3 * float(seconds), 2)


def _report_tabular(ds, probs: list[int]) -> list[str]:
    """One tabular: a row per method and tolerance, for each problem in ``probs`` the
    error, the time (the statistic the sweep shows, ``timing_statistic``: the stored
    ``wall_time``), its spread (the quartiles ``wall_time_q1`` to ``wall_time_q3``, when
    the sweep has them) and the missed switches; a configuration that failed says so
    in its cells."""
    spread = _report_has_spread(ds)
    width = 4 if spread else 3
    head = " & ".join(rf"\multicolumn{{{width}}}{{c}}"
                      rf"{{{_report_problem_tex(str(ds.problem.values[i]))}}}" for i in probs)
    rules = "".join(rf"\cmidrule(lr){{{3 + width * k}-{2 + width * (k + 1)}}}"
                    for k in range(len(probs)))
    sub = " & ".join([r"error & ms & $Q_1$--$Q_3$ & missed" if spread
                      else "error & ms & missed"] * len(probs))
    lines = [FIT_BEGIN, r"\begin{tabular}{@{}ll" + ("r" * width) * len(probs) + "@{}}",
             r"\toprule", rf"method & rtol & {head} \\", rules, rf" & & {sub} \\", r"\midrule"]
    rows = [j for j in range(ds.sizes["config"])
            if any(str(ds.status.values[i, j]) != "n/a" for i in probs)]
    for j in rows:
        fam = str(ds.method.values[j])
        cells = [_REPORT_METHOD_TEX.get(fam, tex_escape(fam)),
                 f"${num(float(ds.tolerance.values[j]), 2)}$"]
        for i in probs:
            status = str(ds.status.values[i, j])
            if status != "ok":
                cells.append(rf"\multicolumn{{{width}}}{{c}}{{\emph{{"
                             + tex_escape(status.split(":")[0]) + "}}")
                continue
            cells += [f"${num(float(ds.error_map.values[i, j]), 2)}$",
                      f"${_report_ms(ds.wall_time.values[i, j])}$"]
            if spread:
                cells.append(f"${_report_ms(ds.wall_time_q1.values[i, j])}$--"
                             f"${_report_ms(ds.wall_time_q3.values[i, j])}$")
            cells.append(str(int(ds.missed_switches.values[i, j])))
        lines.append(" & ".join(cells) + r" \\")
    return lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""]


def _report_problem_tex(name: str) -> str:
    """'fig04 theta=-0.5' -> the paper's symbols ('$\theta=-0.5$')."""
    parts = name.split()
    rest = " ".join(parts[1:])
    for key, sym in (("theta", r"\theta"), ("eps", r"\epsilon")):
        rest = re.sub(rf"{key}=(\S+)", lambda mm: f"${sym}={mm.group(1)}$", rest)
    return rest


def _report_timing(ds, m: Macros) -> None:
    """How the sweep's times were measured (filippov_paper.benchmarks.timing): the statistic
    shown, the warm-up runs, the least rounds and seconds asked for, and the rounds the
    shown cells took. A sweep measured before the convention (no ``timing_statistic``)
    sets ``rpHaveBenchTiming`` false and quotes nothing."""
    have = "timing_statistic" in ds.attrs and "runs" in ds
    m.flag("rpHaveBenchTiming", have)
    if not have:
        return
    sid = "work_precision"
    stat = str(ds.attrs["timing_statistic"])
    m.add("rpBenchStatistic", None, f"{sid}:attrs.timing_statistic",
          text=r"\text{" + tex_escape(stat) + "}")
    for name, attr, sig in (("rpBenchWarmup", "timing_warmup", 4),
                            ("rpBenchMinRounds", "timing_min_rounds", 4),
                            ("rpBenchMinTime", "timing_min_time", 3)):
        m.add(name, float(ds.attrs[attr]), f"{sid}:attrs.{attr}", sig)
    # the counts as the prose says them ("one untimed run", "3 to 250 runs")
    m.add("rpBenchWarmupRuns", None, f"{sid}:attrs.timing_warmup",
          text=count_phrase(ds.attrs["timing_warmup"], "untimed run"))
    m.add("rpBenchMinRoundsRuns", None, f"{sid}:attrs.timing_min_rounds",
          text=count_phrase(ds.attrs["timing_min_rounds"], "timed run"))
    timed = np.asarray(ds.runs.values)[np.asarray(ds.status.values).astype(str) == "ok"]
    m.add("rpBenchRoundsLeast", float(timed.min()) if timed.size else math.nan,
          "derived: min of work_precision:runs over the configurations that ran", 4)
    m.add("rpBenchRoundsMost", float(timed.max()) if timed.size else math.nan,
          "derived: max of work_precision:runs over the configurations that ran", 4)
    m.add("rpBenchRoundsRange", None,
          "derived: min to max of work_precision:runs over the configurations that ran",
          text=range_phrase(timed.min(), timed.max(), "run") if timed.size else "no runs")
    passes = int(ds.attrs.get("timing_passes", 1))
    m.flag("rpHaveBenchPasses", "timing_passes" in ds.attrs)
    m.add("rpBenchPasses", None, f"{sid}:attrs.timing_passes",
          text=count_phrase(passes, "pass", "passes"))
    _report_machine(ds, m)


#: the machine as the report names it: (macro, attribute, kind): text, or a number (digits)
_REPORT_MACHINE = (("rpBenchCPU", "machine_cpu", None), ("rpBenchPython", "python_version", None),
                   ("rpBenchNumpy", "numpy_version", None), ("rpBenchScipy", "scipy_version", None),
                   ("rpBenchNumba", "numba_version", None),
                   ("rpBenchLoadBefore", "load_average_before", 3),
                   ("rpBenchLoadAfter", "load_average_after", 3), ("rpBenchCores", "cpus", 4))


def _report_machine(ds, m: Macros) -> None:
    """Where and under what load the sweep was timed (timing.machine_attrs, load_attrs):
    the CPU, its cores, the load average before and after, the versions. A sweep that
    did not record them sets ``rpHaveBenchMachine`` false and quotes nothing."""
    sid = "work_precision"
    have = all(attr in ds.attrs for _, attr, _ in _REPORT_MACHINE)
    m.flag("rpHaveBenchMachine", have)
    if not have:
        return
    for name, attr, digits in _REPORT_MACHINE:
        if digits is None:
            m.add(name, None, f"{sid}:attrs.{attr}", text=tex_escape(str(ds.attrs[attr])))
        else:
            m.add(name, float(ds.attrs[attr]), f"{sid}:attrs.{attr}", digits)
    m.add("rpBenchCoresPhrase", None, f"{sid}:attrs.cpus",
          text=count_phrase(ds.attrs["cpus"], "logical core"))


def _report_failed_sentence(n: int) -> str:
    """The sentence of the work-precision text on the configurations that failed."""
    if n == 0:
        return "No configuration failed outright on any map."
    return (count_phrase(n, "configuration", capital=True)
            + r" failed outright over all maps (cells marked \emph{failed}; the dataset's "
            r"\texttt{status} says why).")


def _report_problem_macros(ds, m: Macros, names) -> None:
    """Per problem (the first four: A-D) the speed-up, the reference floor, the points,
    and what solve_ivp's RK45 and DOP853 miss; then the failed configurations."""
    sid = "work_precision"
    fam = np.array([str(f) for f in ds.method.values])
    for i, p in enumerate(names[:4]):
        key = "ABCD"[i]
        # the speed-up as a range from the spread of the times (low, high), never one number
        for end in ("low", "high"):
            var = f"speedup_vs_rk45_{end}"
            value = float(ds[var].values[i]) if var in ds else math.nan
            m.add(f"rpBenchSpeedup{end.capitalize()}{key}", value, source(sid, f"{var}[{i}]"), 2)
        m.add(f"rpBenchFloor{key}", float(ds.reference_check.values[i]),
              source(sid, f"reference_check[{i}]"), 2)
        m.add(f"rpBenchPoints{key}", float(ds.n_points.values[i]),
              source(sid, f"n_points[{i}]"), 4)
        ok = ds.status.values[i] == "ok"
        for tag, family in (("RK", "solve_ivp RK45"), ("DOP", "solve_ivp DOP853")):
            sel = (fam == family) & ok
            m.add(f"rpBenchMissed{tag}{key}",
                  float(ds.missed_switches.values[i, sel].max()) if sel.any() else 0.0,
                  f"derived: max of work_precision:missed_switches[{i}] over {family}", 4)
            m.add(f"rpBenchBest{tag}{key}",
                  float(np.nanmin(ds.error_map.values[i, sel])) if sel.any() else math.nan,
                  f"derived: min of work_precision:error_map[{i}] over {family}", 2)
    failed = int(np.count_nonzero(np.char.startswith(ds.status.values.astype(str), "failed")))
    m.add("rpBenchFailed", float(failed),
          "derived: configurations of work_precision:status that failed", 4)
    m.add("rpBenchFailedSentence", None,
          "derived: configurations of work_precision:status that failed",
          text=_report_failed_sentence(failed))
    m.add("rpBenchConfigs", float(ds.sizes["config"]), "work_precision:config (size)", 4)
    m.add("rpBenchTarget", float(ds.attrs.get("target_error", TARGET_ERROR)),
          f"{sid}:attrs.target_error" if "target_error" in ds.attrs
          else "derived: work_precision.TARGET_ERROR (the sweep predates the attribute)", 2)


def report(ds, m: Macros) -> str:
    """The work-precision tables of the default build's sweep (results/work_precision.nc):
    per problem set (fig04, fig11), one row per method and tolerance, error / time /
    missed switches per problem; the speed-up at the target error and what the
    scipy solvers a user reaches for first get wrong (macros)."""
    missing = absent(m, "rpHaveBench", ds, "Work--precision sweep", "results/work_precision.nc")
    m.flag("rpHaveBenchTiming", False)  # set by _report_timing when the sweep says how it timed
    m.flag("rpHaveBenchSpread", ds is not None and _report_has_spread(ds))
    m.flag("rpHaveBenchPasses", False)   # ... when it interleaved its runs
    m.flag("rpHaveBenchMachine", False)  # ... when it recorded the machine and its load
    if missing:
        return missing
    if "method" not in ds.coords or "problem" not in ds.dims:
        return table_frame(ds)
    names = [str(p) for p in ds.problem.values]
    lines = []
    for prefix in ("fig04", "fig11"):
        probs = [i for i, p in enumerate(names) if p.startswith(prefix)]
        if probs:
            lines += ([r"\medskip", ""] if lines else []) + _report_tabular(ds, probs)
    _report_problem_macros(ds, m, names)
    _report_timing(ds, m)
    return "\n".join(lines)


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--preset", choices=sorted(PRESETS), default="full",
                    help="methods, tolerances, grids and repeats: full (make bench), build "
                         "(the default build's minute-long sweep) or quick (smoke test)")
    ap.add_argument("--every", type=int, help="use every k-th fig04 grid point")
    ap.add_argument("--every11", type=int, help="use every k-th point of the fig11 base grid")
    ap.add_argument("--problems", default="fig04,fig11",
                    help="comma-separated problem sets: fig04, fig11")
    ap.add_argument("--repeat", type=int,
                    help="timed runs per configuration at least (median and min; after one "
                         "untimed run of each method per problem)")
    ap.add_argument("--min-time", type=float,
                    help="time more runs of a configuration until this many seconds")
    ap.add_argument("--passes", type=int,
                    help="interleave the configurations' runs in this many passes (default: "
                         "--repeat)")
    ap.add_argument("--time-cap", type=float, help="seconds per configuration")
    ap.add_argument("--quick", action="store_true", help="same as --preset quick")
    ap.add_argument("--out", default=str(ROOT / "results" / "bench_work_precision.nc"))
    ap.add_argument("--merge", nargs="+", metavar="PART",
                    help="merge datasets of earlier runs (chunk jobs) into --out instead")
    args = ap.parse_args(argv)
    if args.merge:
        from filippov.io import read_dataset

        ds = merge([read_dataset(p) for p in args.merge])
        write_dataset(ds, args.out)
        print(table(ds))
        print(f"\nwrote {args.out}")
        return
    preset = dict(PRESETS["quick" if args.quick else args.preset])
    for key in ("every", "every11", "repeat", "time_cap", "min_time", "passes"):
        if getattr(args, key) is not None:
            preset[key] = getattr(args, key)
    if preset["every"] < 1 or preset["every11"] < 1 or preset["repeat"] < 1 \
            or not preset["time_cap"] > 0 or not preset["min_time"] >= 0 \
            or not preset.get("passes") or preset["passes"] < 1:
        ap.error("--every, --every11, --repeat and --passes must be >= 1, --time-cap > 0 "
                 "and --min-time >= 0")
    sets = [s.strip() for s in args.problems.split(",") if s.strip()]
    if not sets or set(sets) - {"fig04", "fig11"}:
        ap.error(f"--problems: choose from fig04, fig11, got {args.problems!r}")
    problems = ((fig04_problems(preset["every"]) if "fig04" in sets else [])
                + (fig11_problems(preset["every11"]) if "fig11" in sets else []))
    ds = run(problems, preset["families"], preset["repeat"], preset["time_cap"],
             log=lambda s: print(s, file=sys.stderr, flush=True), min_time=preset["min_time"],
             passes=preset["passes"],
             preset="quick" if args.quick else args.preset, every=preset["every"],
             every11=preset["every11"])
    write_dataset(ds, args.out)
    print(table(ds))
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
