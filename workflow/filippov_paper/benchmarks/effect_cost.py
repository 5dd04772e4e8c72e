"""What each model ingredient costs: every scene timed as declared and with one
ingredient switched (reduced <-> slow-fast, exact <-> integrated flows, sliding
on <-> off, compiled <-> reference engine).

Run ``python -m filippov_paper.benchmarks.effect_cost [scene ...]``. Each variant runs
in a Python process of its own (:class:`VariantProcess`: a variant pays its own
compilation, generated pieces and caches, and one that hangs is stopped after
``--time-cap`` seconds without the others), timing only the scene's compute call by the
benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`). The processes of a
scene's variants are kept for all their calls, so their rounds can be interleaved
(:func:`~filippov_paper.benchmarks.timing.measure_interleaved`, ``--repeat`` passes): the
parent asks each process in turn for its share of the rounds of a pass, and a spell of
load falls on all variants of the scene alike. Per variant one untimed call first
(compilation, generated pieces, caches), then at least ``--repeat`` timed calls, more
until ``--min-time`` seconds were timed; a round is the compute call as its own
process timed it (the pipes and the process's start are on no round). The dataset
keeps the median (``seconds``) with its spread (``seconds_q1`` to ``seconds_q3``), the
fastest and slowest call (``_min``, ``_max``), the ratio to the scene as declared as
the ratio of the medians (``relative``) and as a range from the quartiles
(``relative_low``, ``relative_high``), and the machine with its load average before and
after. A variant the scene does not support, or one that fails because the scene
needs the switched-off effect, is listed with its message. The point of the table: a
scene pays for the effects it declares and no others.
"""
from __future__ import annotations

import argparse
import copy
import json
import os
import select
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import xarray as xr

from filippov_paper.config import load_scene
from filippov.io import finalize, write_dataset
from filippov_paper.benchmarks import timing
from filippov_paper.report import FIT_BEGIN, FIT_END, Macros, num, num_range, tex_escape

ROOT = Path(__file__).resolve().parents[3]
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"
DEFAULT_SCENES = ["fig02_cases", "fig03_grazingsketch", "fig04_retmaps", "fig05_thetalt0mfs"]
FLIP = {"system": {"slow_fast": "reduced", "reduced": "slow_fast"},
        "flow": {"exact": "integrate", "integrate": "exact"},
        "sliding": {True: False, False: True}}

# A variant's process: reads the scene (one JSON line), then computes it once for each
# further line it reads and answers with the seconds it took (or the error), one JSON
# line each. What the scene prints goes to stderr: stdout carries the answers only.
_CHILD = r"""
import json, os, sys, time
answers = os.fdopen(os.dup(1), "w")
os.dup2(2, 1)
sys.stdout = sys.stderr
import filippov_paper.scenes
scene = json.loads(sys.stdin.readline())
while sys.stdin.readline():
    try:
        t0 = time.perf_counter()
        filippov_paper.scenes.compute(scene)
        out = {"seconds": time.perf_counter() - t0}
    except Exception as exc:
        out = {"error": f"{type(exc).__name__}: {exc}"[:300]}
    answers.write(json.dumps(out) + "\n")
    answers.flush()
"""


class VariantFailed(RuntimeError):
    """A variant's call failed; the message is its status (the error the scene raised,
    ``time cap (...)`` or ``crashed: ...``)."""


class VariantProcess:
    """One variant of a scene in a process of its own (:data:`_CHILD`), started at its
    first call and kept for the others: a call has the process compute the scene once
    and returns the seconds that took there. ``cap``: the seconds the process may take
    over all its calls (its start and import, the warm-up and the rounds; the time the
    other variants take in between does not count); past them it is stopped and the
    call raises :class:`VariantFailed`, as it does for a scene's error or a crash."""

    def __init__(self, scene: dict, cap: float):
        self.scene, self.cap, self.spent = scene, cap, 0.0
        self.proc, self.stderr = None, None

    def __call__(self) -> float:
        if self.proc is None:
            self.stderr = tempfile.TemporaryFile(mode="w+")
            self.proc = subprocess.Popen([sys.executable, "-c", _CHILD], stdin=subprocess.PIPE,
                                         stdout=subprocess.PIPE, stderr=self.stderr, text=True)
            self._send(json.dumps(self.scene))
        t0 = time.monotonic()
        self._send("")
        ready = select.select([self.proc.stdout], [], [], max(self.cap - self.spent, 0.0))[0]
        line = self.proc.stdout.readline() if ready else None
        self.spent += time.monotonic() - t0
        if line is None:
            self.close()
            raise VariantFailed(f"time cap ({self.cap:g} s)")
        if not line:
            raise VariantFailed(f"crashed: {self._last_error()}")
        answer = json.loads(line)
        if "error" in answer:
            raise VariantFailed(answer["error"])
        return float(answer["seconds"])

    def _send(self, line: str) -> None:
        try:
            self.proc.stdin.write(line + "\n")
            self.proc.stdin.flush()
        except OSError:  # the process has ended: the next read says how
            pass

    def _last_error(self) -> list:
        self.proc.wait()
        self.stderr.seek(0)
        return self.stderr.read().strip().splitlines()[-1:]

    def close(self) -> None:
        """Stop the process (it waits for its next line: nothing is cut short)."""
        if self.proc is not None:
            self.proc.kill()
            self.proc.wait()
            for f in (self.proc.stdin, self.proc.stdout, self.stderr):
                f.close()
            self.proc = None


def variants(scene: dict) -> list[tuple[str, dict]]:
    """(label, scene) pairs: as declared, then one ingredient switched at a time."""
    out = [("as declared", scene)]
    for key, flip in FLIP.items():
        value = scene["ingredients"][key]
        if value in flip:
            v = copy.deepcopy(scene)
            v["ingredients"][key] = flip[value]  # same engine: the ingredient's own cost
            out.append((f"{key}: {value} -> {flip[value]}", v))
    engine = scene.get("solver", {}).get("engine")
    if engine == "compiled":
        v = copy.deepcopy(scene)
        v["solver"]["engine"] = "reference"
        out.append(("engine: compiled -> reference", v))
    return out


class _ProcessClock:
    """The clock :func:`timing.measure_interleaved` reads around each call: the seconds
    the variants' processes measured for their compute calls, added up as the calls
    return them, so that a round is the compute call alone."""

    def __init__(self):
        self.now = 0.0

    def __call__(self) -> float:
        return self.now

    def timed(self, process: VariantProcess):
        def call():
            self.now += process()
        return call


def time_variants(scenes: list, cap: float, repeat: int = timing.MIN_ROUNDS,
                  min_time: float = timing.MIN_TIME) -> list:
    """Each of ``scenes`` (the variants of one scene) computed in a process of its own
    (:class:`VariantProcess`, ``cap`` seconds each), their rounds interleaved in
    ``repeat`` passes; per variant its :class:`timing.Timing` or the
    :class:`VariantFailed` it ended with. The processes are stopped at the end."""
    clock = _ProcessClock()
    processes = [VariantProcess(scene, cap) for scene in scenes]
    try:
        return timing.measure_interleaved([clock.timed(p) for p in processes],
                                          min_rounds=repeat, min_time=min_time,
                                          passes=repeat, clock=clock)
    finally:
        for p in processes:
            p.close()


def measure(scene_ids, cap: float, log=print, repeat: int = timing.MIN_ROUNDS,
            min_time: float = timing.MIN_TIME) -> xr.Dataset:
    """Every variant of every scene of ``scene_ids`` timed (:func:`time_variants`, a scene's
    variants interleaved), the ratio of each to its scene as declared from the medians and
    as a range from the quartiles; the machine and its load before and after."""
    labels, timings, relative = [], [], []
    load_before = os.getloadavg()
    for sid in scene_ids:
        scene = load_scene(ROOT / "config" / "scenes" / f"{sid}.yaml", SCHEMA)
        pairs = variants(scene)
        got = time_variants([v for _, v in pairs], cap, repeat, min_time)
        for (label, _), t in zip(pairs, got):
            ok = isinstance(t, timing.Timing) and isinstance(got[0], timing.Timing)
            labels.append((sid, label))
            timings.append(t)
            relative.append(timing.ratio_range(t, got[0]) if ok else (np.nan,) * 3)
            log(f"{sid:22s} {label:32s} {_line(t, relative[-1])}")
    load_after = os.getloadavg()
    status = ["ok" if isinstance(t, timing.Timing) else str(t) for t in timings]
    rel, low, high = (np.array(c, dtype=float) for c in zip(*relative))
    ds = xr.Dataset(
        {**timing.variables("seconds", ("variant",), timings, "compute time of the scene"),
         "runs": ("variant", timing.rounds(timings), {
             "long_name": "timed calls (after a warm-up call)", "units": "1"}),
         "relative": ("variant", rel, {
             "long_name": "time / time as declared, medians", "units": "1"}),
         "relative_low": ("variant", low, {
             "long_name": "low end of the ratio's range: the variant's first quartile over "
                          "the declared one's third", "units": "1"}),
         "relative_high": ("variant", high, {
             "long_name": "high end of the ratio's range: the variant's third quartile over "
                          "the declared one's first", "units": "1"}),
         "status": ("variant", np.array(status, dtype=str),
                    {"long_name": "ok or the error raised"})},
        coords={"scene": ("variant", np.array([s for s, _ in labels], dtype=str)),
                "change": ("variant", np.array([c for _, c in labels], dtype=str))})
    return finalize(ds, None, time_cap=cap,
                    **timing.describe(min_rounds=repeat, min_time=min_time, passes=repeat),
                    **{**timing.machine_attrs(), **timing.load_attrs(load_before, load_after)},
                    title="cost of each model ingredient per scene")


def _line(t, relative) -> str:
    """A variant's time (median, q1..q3) and ratio range to the declared, or its status."""
    if not isinstance(t, timing.Timing):
        return f"{'':>34s}  {t}"
    return (f"{t.median:9.3f} s ({t.q1:9.3f}..{t.q3:9.3f})  x{relative[1]:7.2f}.."
            f"{relative[2]:7.2f}")


#: part of `make bench` (filippov_paper.product): rule bench_effect_cost runs main(args + ['--out', 'results/bench_effect_cost.nc'])
WORKFLOW = {"args": []}


# ============================================================================= report
# What the reproduction report quotes from this benchmark's dataset (filippov_paper.report
# calls `report`, in REPORT's order among the benchmarks). This part -- REPORT, report and
# the _report_* / _REPORT_* names -- is left out of the code hash of the jobs that run the
# benchmark: editing it rebuilds the report only.
REPORT = {"dataset": "bench_effect_cost", "table": "tab_bench.tex", "order": 30}


def report(ds, m: Macros) -> str | None:
    """The cost of each model ingredient: a block of Table tab:bench, below the
    work-precision sweep's (None when not measured, or measured before the benchmark
    kept the spread of its times). A time is the stored median with its spread (first to
    third quartile of the calls); the ratio to the scene as declared is its range
    (``relative_low`` to ``relative_high``), never one number."""
    kept = ("seconds_q1", "seconds_q3", "relative_low", "relative_high")
    if ds is not None and not all(name in ds for name in kept):
        ds = None  # measured by an older benchmark: measured again by make bench
    m.flag("rpHaveEffects", ds is not None)
    if ds is None:
        return None
    lines = [r"\medskip", "", FIT_BEGIN, r"\begin{tabular}{llrrrl}", r"\toprule",
             r"scene & ingredient switched & time [s] & $Q_1$--$Q_3$ & $\times$ declared & "
             r"outcome \\", r"\midrule"]
    for k in range(ds.sizes["variant"]):
        status = str(ds.status.values[k])
        outcome = "ok" if status == "ok" else status.split(":")[0]
        lines.append(" & ".join([
            r"\texttt{" + tex_escape(str(ds.scene.values[k])) + "}",
            tex_escape(str(ds.change.values[k])).replace("->", r"$\to$"),
            f"${num(float(ds.seconds.values[k]), 3)}$",
            num_range(float(ds.seconds_q1.values[k]), float(ds.seconds_q3.values[k]), 3),
            num_range(float(ds.relative_low.values[k]), float(ds.relative_high.values[k]), 3),
            r"\emph{" + tex_escape(outcome) + "}"]) + r" \\")
    return "\n".join(lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=DEFAULT_SCENES)
    ap.add_argument("--time-cap", type=float, default=120.0,
                    help="seconds per variant (its process's start, warm-up call and timed "
                         "calls together)")
    ap.add_argument("--repeat", type=int, default=timing.MIN_ROUNDS,
                    help="timed calls per variant at least (median), after one untimed call; "
                         "also the passes they are interleaved in")
    ap.add_argument("--min-time", type=float, default=timing.MIN_TIME,
                    help="time more calls of a variant until this many seconds")
    ap.add_argument("--out", default=str(ROOT / "results" / "bench_effect_cost.nc"))
    args = ap.parse_args(argv)
    ds = measure(args.scenes, args.time_cap, log=lambda s: print(s, file=sys.stderr, flush=True),
                 repeat=args.repeat, min_time=args.min_time)
    write_dataset(ds, args.out)
    print(f"machine: {ds.attrs['machine_cpu']}, {ds.attrs['cpus']} cores; load average "
          f"{ds.attrs['load_average_before']:.2f} before, {ds.attrs['load_average_after']:.2f} "
          f"after")
    print(f"{'scene':22s} {'change':32s} {'median [s]':>10s} {'q1..q3 [s]':>20s} "
          f"{'x declared (q1..q3)':>20s}  status")
    for i in range(ds.sizes["variant"]):
        print(f"{str(ds.scene.values[i]):22s} {str(ds.change.values[i]):32s} "
              f"{float(ds.seconds[i]):10.3f} {float(ds.seconds_q1[i]):9.3f}.."
              f"{float(ds.seconds_q3[i]):9.3f} {float(ds.relative_low[i]):9.2f}.."
              f"{float(ds.relative_high[i]):9.2f}  {ds.status.values[i]}")
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
