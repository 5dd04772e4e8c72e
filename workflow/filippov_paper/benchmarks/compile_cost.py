"""What the compiled engine costs before its first return: compile and load times.

Run ``python -m filippov_paper.benchmarks.compile_cost`` (part of ``make bench``). Each run is
a fresh Python process with its own empty caches (numba's, ``NUMBA_CACHE_DIR``, and the
generated model pieces', ``FILIPPOV_CACHE_DIR``): it imports the engine, compiles the
kernel (:func:`filippov.fastmap.compile_kernel`: the build without the dP/dz code), builds
the Hopf model's compiled pieces, makes one batch call of first returns, then compiles the
kernel's build with the dP/dz code (what ``jacobian=True`` runs on; the helpers both builds
share are compiled by then). A second process on the same caches does the same: the loads
a user sees from the second session on. Each stage is timed on its own (wall time); the
kernel is one numba compilation, so a second core does not help it.

Of the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`) this one keeps
the statistic and its spread: per stage the median over ``--repeat`` pairs of processes
(``cold``, ``warm``) with its first and third quartile (``_q1``, ``_q3``) and the fastest
and slowest process (``_min``, ``_max``), the machine and its load average before and
after. It has no warm-up and no interleaving, by design: what it times is the first
call of a process (a warm-up would pay exactly that), and a round is a cold process and
then a warm one on the caches the cold one wrote, so the two alternate already and
cannot be reordered; every round needs fresh processes and fresh caches.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile

import xarray as xr

from filippov_paper.benchmarks import command_line, timing
from filippov_paper.report import Macros, count_phrase, var
from filippov.io import finalize

#: the stages one process times, in order (name, what it is)
STAGES = [("import", "import filippov.fastmap (numba, the rule book, the kernel's types)"),
          ("kernel", "compile_kernel(): the kernel, compiled or loaded from numba's cache"),
          ("model", "hopf.compiled(...): the model's pieces, generated and compiled or loaded"),
          ("first_call", "one batch of 8 first returns, the first call of the process"),
          ("kernel_dpdz", "compile_kernel(derivatives=True): the build with the dP/dz code, "
                          "on top of the helpers already compiled")]

_PROBE = """
import json, time
t0 = time.perf_counter()
from filippov.fastmap import compile_kernel, compute_returns
t1 = time.perf_counter()
loaded = compile_kernel()
t2 = time.perf_counter()
import numpy as np
from filippov.models import hopf
cm = hopf.compiled(1e-2, -0.5, 1.0 + 1e-2)
t3 = time.perf_counter()
starts = np.column_stack([np.zeros(8), np.linspace(0.9, 1.1, 8), np.zeros(8)])
out = compute_returns(cm, starts, 5.0)
t4 = time.perf_counter()
from filippov.kernel import derivative
# helpers of the dP/dz code compiled so far (none: the returns did not ask for dP/dz)
dpdz = sum(len(f.signatures) for f in vars(derivative).values()
           if getattr(getattr(f, "py_func", None), "__module__", None) == derivative.__name__)
compile_kernel(derivatives=True)
t5 = time.perf_counter()
print(json.dumps({"import": t1 - t0, "kernel": t2 - t1, "model": t3 - t2,
                  "first_call": t4 - t3, "kernel_dpdz": t5 - t4, "loaded": loaded,
                  "dpdz_before": dpdz, "ok": int((out.status == 0).sum())}))
"""


def _process(cache: str) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=os.path.join(cache, "numba"),
               FILIPPOV_CACHE_DIR=os.path.join(cache, "generated"))
    run = subprocess.run([sys.executable, "-c", _PROBE], env=env, capture_output=True,
                         text=True, check=False)
    if run.returncode != 0:
        raise RuntimeError(f"compile_cost probe failed:\n{run.stderr[-3000:]}")
    return json.loads(run.stdout.strip().splitlines()[-1])


def measure(repeat: int = 3, log=print) -> dict:
    """{"cold": {stage: Timing}, "warm": {stage: Timing}} over ``repeat`` pairs of
    processes (the first on empty caches, the second on what the first left)."""
    runs = {"cold": [], "warm": []}
    for k in range(repeat):
        with tempfile.TemporaryDirectory(prefix="filippov-compile-cost-") as cache:
            cold, warm = _process(cache), _process(cache)
        if cold["ok"] != 8 or warm["ok"] != 8:
            raise RuntimeError("compile_cost: a first return of the probe failed")
        if cold["dpdz_before"]:
            raise RuntimeError("compile_cost: returns without dP/dz compiled "
                               f"{cold['dpdz_before']} functions of the dP/dz code")
        if cold["loaded"] or not warm["loaded"]:
            raise RuntimeError("compile_cost: the first process loaded a cached kernel or "
                               "the second compiled it again (a cache outside NUMBA_CACHE_DIR?)")
        runs["cold"].append(cold)
        runs["warm"].append(warm)
        log(f"  pair {k + 1}/{repeat}: kernel {cold['kernel']:.1f} s cold, "
            f"{warm['kernel']:.2f} s warm; with dP/dz +{cold['kernel_dpdz']:.1f} s cold",
            flush=True)
    return {kind: {s: timing.of_rounds([r[s] for r in rows]) for s, _ in STAGES}
            for kind, rows in runs.items()}


def run(repeat: int = 3, log=print) -> xr.Dataset:
    load_before = os.getloadavg()
    m = measure(repeat, log)
    load_after = os.getloadavg()
    names = [s for s, _ in STAGES]
    ds = xr.Dataset(
        {**timing.variables("cold", ("stage",), [m["cold"][s] for s in names],
                            "wall time of the stage, empty caches (a fresh process a round)"),
         **timing.variables("warm", ("stage",), [m["warm"][s] for s in names],
                            "wall time of the stage, caches written by an earlier process"),
         "runs": ("stage", timing.rounds([m["cold"][s] for s in names]), {
             "long_name": "pairs of processes timed (a cold one, then a warm one)",
             "units": "1"}),
         "description": ("stage", [d for _, d in STAGES], {"long_name": "what the stage does"})},
        coords={"stage": ("stage", names, {"long_name": "stage of a process's first return"})})
    log(f"{'stage':12s} {'cold [s] (q1..q3)':>24s} {'warm [s] (q1..q3)':>24s}  what")
    for s, d in STAGES:
        log(f"{s:12s} " + " ".join(f"{t.median:9.2f} ({t.q1:5.2f}..{t.q3:5.2f})"
                                   for t in (m["cold"][s], m["warm"][s])) + f"  {d}")
    log(f"{'total':12s} " + " ".join(f"{sum(t.median for t in m[kind].values()):9.2f} {'':14s}"
                                     for kind in ("cold", "warm")) + "  (sum of the medians)")
    return finalize(ds, None, repeat=repeat, cpu_count=os.cpu_count() or 0,
                    **timing.describe(warmup=0, min_rounds=repeat, min_time=0.0,
                                      max_rounds=repeat),
                    timing_order="per round a process on empty caches, then one on the "
                                 "caches it wrote",
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="compile and load times of the compiled engine")


#: part of `make bench` (filippov_paper.product): rule bench_compile_cost runs main(args + ['--out', 'results/bench_compile_cost.nc'])
WORKFLOW = {"args": ["--repeat", "1"]}  # fresh processes: one round is enough for the table


# ============================================================================= report
# What the reproduction report quotes from this benchmark's dataset (filippov_paper.report
# calls `report`, in REPORT's order among the benchmarks). This part -- REPORT, report and
# the _report_* / _REPORT_* names -- is left out of the code hash of the jobs that run the
# benchmark: editing it rebuilds the report only.
REPORT = {"dataset": "bench_compile_cost", "order": 10}  # macros only: quoted in sec_bench

#: the stages the report quotes, with the tag of their macros (rpCompile<tag>Cold/Warm)
_REPORT_QUOTED = (("kernel", "Kernel"), ("kernel_dpdz", "KernelDpdz"), ("model", "Model"))


def report(ds, m: Macros) -> None:
    """The compiled engine's cold and warm compile/load times of the quoted stages: the
    medians, and their spread (first and third quartile) when the benchmark timed more
    than one pair of processes and kept it (``rpHaveCompileSpread``)."""
    if ds is not None and not {s for s, _ in _REPORT_QUOTED} <= set(ds.stage.values):
        ds = None  # measured by an older benchmark: measured again by make bench
    m.flag("rpHaveCompileCost", ds is not None)
    pairs = int(ds.runs.values.min()) if ds is not None and "runs" in ds else 1
    spread = ds is not None and pairs > 1 and all(f"{kind}_{q}" in ds for kind in
                                                  ("cold", "warm") for q in ("q1", "q3"))
    m.flag("rpHaveCompileSpread", spread)
    if ds is None:
        return None
    sid = REPORT["dataset"]
    for stage, tag in _REPORT_QUOTED:
        for kind in ("cold", "warm"):
            name = f"rpCompile{tag}{kind.title()}"
            var(m, name, ds, sid, kind, sig=2, stage=stage)
            if spread:
                var(m, f"{name}FirstQuartile", ds, sid, f"{kind}_q1", sig=2, stage=stage)
                var(m, f"{name}ThirdQuartile", ds, sid, f"{kind}_q3", sig=2, stage=stage)
    m.add("rpCompilePairs", None, f"{sid}:runs" if "runs" in ds else
          "derived: one pair (the dataset predates the count)",
          text=count_phrase(pairs, "pair of fresh processes", "pairs of fresh processes"))
    return None


def main(argv=None) -> None:
    command_line(__doc__, run, argv, repeat=3)


if __name__ == "__main__":
    main()
