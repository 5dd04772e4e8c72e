"""Where one return of the iterated Hopf map goes, and how far it is from its floor.

Run ``python -m filippov_paper.benchmarks.return_floor`` (part of ``make bench``). For each case
(theta, eps, s) of :mod:`filippov_paper.benchmarks.attractor_cost` the map is iterated
``--returns`` times from the cycle's point in one compiled call on one thread
(``workers=1``), and:

* ``us/return``: the call's CPU time on its thread (``time.thread_time``: a shared
  machine's other jobs do not count) divided by the returns, the min over ``--repeat``
  calls after a warm-up call; ``dP/dz``: the same with ``jacobian=True``;
* **what a return evaluates**: the same run once more with each model piece wrapped by
  a counter (the counters ride in extra slots at the end of the parameter vector, which
  the pieces never read; the returns are checked to be bit-identical to the plain
  run's): flows, fields (F_-, F_+, grad h) and scalars (h, section) per return;
  ``samples``, ``root`` and ``events`` split them by where the kernel calls them (an
  exact-flow sample evaluates the flow, h, grad h, the field and the section once each;
  a root-solver step the flow and h or the section; an integration stage the Filippov
  field: F_-, F_+ and grad h): samples = grad h calls outside sliding, root = the rest
  of the flow calls (all derived from the counts, see :func:`breakdown`);
* **the floor**: each piece's own cost, measured in a compiled loop that calls it the
  way the kernel does (at its compiled address, states from the orbit), times the
  number of calls a return makes: ``floor`` is what the evaluations alone cost, with no
  driver, scan, root-solver or event logic around them. Every one of these evaluations
  is one the reference semantics ask for (samples at the model's declared resolution,
  ``sample_step``/``slow_sample_step``, which the scan's event detection and so the
  datasets depend on; roots to ``event_xtol``; dP/dz only when asked), so the floor is
  the cost of a return that keeps today's results; ``x floor`` = us/return / floor, and
  ``over`` the microseconds above it (the kernel's own work: the scan's rules, the root
  solver's arithmetic, DOP853's stages while sliding, the bookkeeping); ``flows only``
  the part of the floor that is the flow evaluations themselves, the states at the
  samples and in the root solves, without the event functions evaluated at them (h, its
  rate along the orbit, the section), a bound no scan at this resolution gets below.

The table says, per case, the CPU time, the evaluations, the floor and the distance.

Not a wall-clock benchmark, so not timed by the convention of
:mod:`filippov_paper.benchmarks.timing` (median, quartiles, interleaved rounds): it reads
the CPU time of the calling thread and keeps the min, because it compares a call with
the sum of its parts measured alone -- the least-disturbed call of each, on a clock that
another process's work does not advance. The machine and its load average before and
after are dataset attributes all the same.

What the rest is (perf with a symbol map of the kernel, commit 92c2930 on the 2-core
development machine, share of the CPU time of 2000-return calls): at theta = -0.5,
eps = 1e-2 the flow of region + is half of a return (flow_plus 15%, and in libm expm1
21%, sincos 10%, exp 3%), the sample loop's own code 20% (mostly passing the work arrays
to five pieces a sample at their compiled addresses), root solves (brentq, _fval,
_refine) 10%, the scan 6%, the driver 6%, the other pieces 7%; at theta = 0.2, eps =
1e-4 the flow 36%, the sample loop 13%, sliding (DOP853's stages, dense output, the
Filippov field) 20%, root solves 10%, scan and driver 9%. So the targets of issue 33
(5 us at theta < 0, 10 us at theta > 0) lie at or below the floor where eps is small:
at theta < 0 the evaluations alone cost 3.8-6.5 us (eps = 1e-2 .. 1e-6) and the flows
alone 2.0-3.7 us; at theta > 0, 6-9 us before any DOP853 arithmetic. Fewer samples
(a coarser declared resolution) or a cheaper flow piece (the model's expm1 and sincos)
would move the floor, and the datasets with it.
"""
from __future__ import annotations

import dataclasses
import os
import time

import numpy as np
import xarray as xr
from numba import njit, types

from filippov.abi import FIELD_SIG, FLOW_SIG, JAC_SIG, PIECES, SCALAR_SIG, WHERE_SIG
from filippov.analytic import limit_map
from filippov.fastmap import OK, compute_returns, no_jacobian
from filippov.io import finalize
from filippov.models import hopf
from filippov_paper.benchmarks import command_line, timing
from filippov_paper.benchmarks.attractor_cost import CASES, OMEGA, case_coords

NAMES = [name for name, _ in PIECES]
#: the issue-33 targets per return on one core (theta < 0, theta > 0), seconds
TARGET = {False: 5e-6, True: 10e-6}


def _functions(cm) -> dict:
    """The model's compiled pieces by name (abi.PIECES order; no_jacobian where the model
    has none, no flow Jacobians where it has none: the kernel never calls those) -- the
    functions themselves, which the kernel is handed as addresses."""
    out = {}
    for name in NAMES:
        f = getattr(cm, name)
        if name == "jacobian" and f is None:
            f = no_jacobian
        if f is not None:
            out[name] = f
    return out


def _outputs(name: str, n: int) -> int:
    """How many values the piece ``name`` writes: n*n for a flow's Jacobian (abi), n for
    a flow or a field."""
    return n * n if name.startswith("flow_jacobian") else n


def _counted_piece(f, sig, slot):
    """``f`` with ``p[slot] += 1`` before each call (numba compiles the call to ``f`` in)."""
    if sig is FLOW_SIG:
        def counted(z0, tau, p, out):
            p[slot] += 1.0
            f(z0, tau, p, out)
    elif sig is FIELD_SIG:
        def counted(z, p, out):
            p[slot] += 1.0
            f(z, p, out)
    elif sig is JAC_SIG:
        def counted(mode, z, p, out):
            p[slot] += 1.0
            f(mode, z, p, out)
    else:
        def counted(z, p):
            p[slot] += 1.0
            return f(z, p)
    return njit(sig)(counted)


def counted_model(cm):
    """``cm`` with every piece counting its calls into ``params[base + k]`` (k the piece's
    index in abi.PIECES); (model, base)."""
    base = cm.params.size
    pieces = _functions(cm)
    new = {name: _counted_piece(pieces[name], sig, base + k)
           for k, (name, sig) in enumerate(PIECES)
           if name in pieces and not (name == "jacobian" and cm.jacobian is None)}
    params = np.concatenate([np.asarray(cm.params, dtype=float), np.zeros(len(PIECES))])
    return dataclasses.replace(cm, params=params, **new), base


_V, _M = types.float64[::1], types.float64[:, ::1]


@njit(types.float64(types.FunctionType(FLOW_SIG), _M, _V, _V, _V, _V, types.int64), _nrt=False)
def _loop_flow(f, zs, taus, p, z, out, reps):
    acc = 0.0
    for _ in range(reps):
        for i in range(zs.shape[0]):
            for c in range(z.size):
                z[c] = zs[i, c]
            f(z, taus[i], p, out)
            acc += out[0]
    return acc


@njit(types.float64(types.FunctionType(FIELD_SIG), _M, _V, _V, _V, types.int64), _nrt=False)
def _loop_field(f, zs, p, z, out, reps):
    acc = 0.0
    for _ in range(reps):
        for i in range(zs.shape[0]):
            for c in range(z.size):
                z[c] = zs[i, c]
            f(z, p, out)
            acc += out[0]
    return acc


@njit(types.float64(types.FunctionType(SCALAR_SIG), _M, _V, _V, types.int64), _nrt=False)
def _loop_scalar(f, zs, p, z, reps):
    acc = 0.0
    for _ in range(reps):
        for i in range(zs.shape[0]):
            for c in range(z.size):
                z[c] = zs[i, c]
            acc += f(z, p)
    return acc


@njit(types.float64(types.FunctionType(WHERE_SIG), _M, _V, _V, types.int64), _nrt=False)
def _loop_where(f, zs, p, z, reps):
    acc = 0.0
    for _ in range(reps):
        for i in range(zs.shape[0]):
            for c in range(z.size):
                z[c] = zs[i, c]
            acc += 1.0 if f(z, p) else 0.0
    return acc


def piece_costs(cm, states, window, reps: int = 100, repeat: int = 21) -> dict:
    """Seconds per call of each piece (but the Jacobian), called at its compiled address
    as the kernel calls it, at ``states`` (flows over times uniform in [0, window]); the
    min over ``repeat`` loops of ``reps`` passes over the states."""
    zs = np.ascontiguousarray(states, dtype=float)
    taus = np.random.default_rng(0).uniform(0.0, window, zs.shape[0])
    p = np.ascontiguousarray(cm.params, dtype=float)
    z = np.zeros(zs.shape[1])
    pieces = _functions(cm)
    costs = {}
    for name, sig in PIECES:
        if name not in pieces:
            continue
        f = pieces[name]
        # sized for what the piece writes (a flow's Jacobian n*n: an out of n was a heap
        # overflow, which numba does not check)
        out = np.zeros(_outputs(name, zs.shape[1]))
        if sig is FLOW_SIG:
            def call(): return _loop_flow(f, zs, taus, p, z, out, reps)
        elif sig is FIELD_SIG:
            def call(): return _loop_field(f, zs, p, z, out, reps)
        elif sig is SCALAR_SIG:
            def call(): return _loop_scalar(f, zs, p, z, reps)
        elif sig is WHERE_SIG:
            def call(): return _loop_where(f, zs, p, z, reps)
        else:
            continue
        call()
        best = np.inf
        for _ in range(repeat):
            t0 = time.thread_time()
            call()
            best = min(best, time.thread_time() - t0)
        costs[name] = best / (reps * zs.shape[0])
    return costs


def breakdown(counts: dict, sliding: bool) -> dict:
    """The evaluations per return split by where the kernel makes them, from the counts
    (kernel.scan._sample: an exact sample calls flow, h, grad h, field and section once;
    kernel.roots via segment._fval: a root step calls flow and h or section, an
    extremum step flow, grad h and a field; kernel.dop853: a stage of a sliding step
    calls F_-, F_+ and grad h; kernel.driver._event: a switch calls grad h, F_- and
    F_+). Without sliding: samples = grad h calls less those of the switches; with
    sliding the exact samples are the h calls less the root steps on h, which are not
    told apart from them, so ``samples`` counts both there."""
    flows = counts["flow_plus"] + counts["flow_minus"]
    if not sliding:
        samples = counts["switch_grad"] - min(counts["field_minus"], counts["field_plus"])
    else:
        samples = counts["switch"]
    return {"samples": samples, "root": max(flows - samples, 0.0),
            "stage_fields": (counts["field_minus"] + counts["field_plus"] - 2 * samples
                             if not sliding else counts["field_minus"])}


def measure(theta: float, eps: float, s: float, returns: int, repeat: int) -> dict:
    mu = 1.0 + s * limit_map.scale(eps, theta)
    sliding = theta > 0
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=sliding)
    start = np.array([[0.0, np.sqrt(mu), 0.0]])

    def run(model, jac=False, keep=1):
        out = compute_returns(model, start, 1.0, iterations=returns, keep=keep,
                              jacobian=jac, workers=1)
        if out.status[0] != OK:
            raise RuntimeError(f"theta={theta}, eps={eps}, s={s}: a return failed")
        return out

    def cpu(jac):
        run(cm, jac)  # warm-up: compiles or loads the kernel
        best = np.inf
        for _ in range(repeat):
            t0 = time.thread_time()
            run(cm, jac)
            best = min(best, time.thread_time() - t0)
        return best / returns

    per_return, per_return_jac = cpu(False), cpu(True)
    plain = run(cm, keep=returns)
    ccm, base = counted_model(cm)
    counted = run(ccm, keep=returns)
    if not (np.array_equal(counted.orbit, plain.orbit)
            and np.array_equal(counted.state, plain.state)):
        raise RuntimeError("the counting pieces changed the returns")
    counts = {name: ccm.params[base + k] / returns for k, name in enumerate(NAMES)}
    costs = piece_costs(cm, plain.orbit[0, -min(returns, 256):],
                        16 * cm.slow_sample_step)
    floor = sum(counts[name] * costs.get(name, 0.0) for name in NAMES)
    flow_floor = sum(counts[name] * costs[name] for name in ("flow_plus", "flow_minus"))
    return {"per_return": per_return, "per_return_jac": per_return_jac, "counts": counts,
            "costs": costs, "floor": floor, "flow_floor": flow_floor,
            **breakdown(counts, sliding)}


def run(returns: int = 2000, repeat: int = 5, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    rows = [measure(t, e, s, returns, repeat) for t, e, s in CASES]
    load_after = os.getloadavg()
    ds = xr.Dataset(
        {"cpu_per_return": ("case", [r["per_return"] for r in rows],
                            {"long_name": "CPU time per return (one thread, min of calls)",
                             "units": "s"}),
         "cpu_per_return_jacobian": ("case", [r["per_return_jac"] for r in rows],
                                     {"long_name": "CPU time per return with dP/dz",
                                      "units": "s"}),
         "floor": ("case", [r["floor"] for r in rows],
                   {"long_name": "cost of the model evaluations a return makes (each "
                                 "piece's cost alone times its calls)", "units": "s"}),
         "flow_floor": ("case", [r["flow_floor"] for r in rows],
                        {"long_name": "cost of the flow evaluations alone (samples and "
                                      "root solves: the state a return cannot do without)",
                         "units": "s"}),
         "target": ("case", [TARGET[t > 0] for t, _, _ in CASES],
                    {"long_name": "issue 33 target per return", "units": "s"}),
         "samples": ("case", [r["samples"] for r in rows],
                     {"long_name": "exact-flow samples per return (see breakdown)",
                      "units": "1"}),
         "root_flows": ("case", [r["root"] for r in rows],
                        {"long_name": "flow evaluations per return outside the samples "
                                      "(root solves, event states)", "units": "1"}),
         **{f"calls_{name}": ("case", [r["counts"][name] for r in rows],
                              {"long_name": f"calls of {name} per return", "units": "1"})
            for name in NAMES},
         **{f"cost_{name}": ("case", [r["costs"].get(name, np.nan) for r in rows],
                             {"long_name": f"time per call of {name} alone", "units": "s"})
            for name in NAMES}},
        coords=case_coords(CASES))
    log(f"{'theta':>6} {'eps':>7} {'us/ret':>7} {'dP/dz':>6} {'target':>6} {'floor':>6} "
        f"{'x floor':>7} {'over':>6} {'flows':>6} | {'flows':>6} {'fields':>6} {'h,sec':>6} "
        f"{'samples':>7} {'root':>5}")
    log(f"{'':>6} {'':>7} {'(CPU)':>7} {'':>6} {'':>6} {'(eval)':>6} {'':>7} {'':>6} "
        f"{'only':>6} | {'calls per return':^36}")
    for (t, e, _), r in zip(CASES, rows):
        c = r["counts"]
        log(f"{t:6.2f} {e:7.0e} {1e6 * r['per_return']:7.2f} {1e6 * r['per_return_jac']:6.2f} "
            f"{1e6 * TARGET[t > 0]:6.1f} {1e6 * r['floor']:6.2f} "
            f"{r['per_return'] / r['floor']:7.2f} {1e6 * (r['per_return'] - r['floor']):6.2f} "
            f"{1e6 * r['flow_floor']:6.2f} | "
            f"{c['flow_plus'] + c['flow_minus']:6.1f} "
            f"{c['field_plus'] + c['field_minus'] + c['switch_grad']:6.1f} "
            f"{c['switch'] + c['section']:6.1f} {r['samples']:7.1f} {r['root']:5.1f}")
    costs = rows[0]["costs"]
    log("times in us per return; floor (eval): every model evaluation the return makes, "
        "each at its cost alone; flows only: the flow evaluations alone (the states at the "
        "samples and in the root solves)")
    log("ns per call alone (case 1): " + ", ".join(
        f"{name} {1e9 * costs[name]:.1f}" for name in NAMES if name in costs))
    return finalize(ds, None, returns=returns, repeat=repeat,
                    timing="CPU time of the calling thread (time.thread_time), min over "
                           "repeat calls after a warm-up call, workers=1",
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="cost per return of the iterated Hopf map and its floor "
                          "(compiled engine)")


#: part of `make bench` (filippov_paper.product): rule bench_return_floor runs main(args + ['--out', 'results/bench_return_floor.nc'])
WORKFLOW = {"args": []}


def main(argv=None) -> None:
    command_line(__doc__, run, argv, returns=2000, repeat=5)


if __name__ == "__main__":
    main()
