"""What each model ingredient costs: every scene timed as declared and with one
ingredient switched (reduced <-> slow-fast, exact <-> integrated flows, sliding
on <-> off, compiled <-> reference engine).

Run ``python -m filippov_paper.benchmarks.effect_cost [scene ...]``. Each variant runs
in its own process (with a time cap over all its calls), timing only the scene's
compute call by the benchmarks' convention (:mod:`filippov_paper.benchmarks.timing`): one
untimed call (compilation, generated pieces, caches), then at least ``--repeat``
timed calls, more until ``--min-time`` seconds were timed; the table shows their
median (the min is stored too). A variant the scene does not support, or one that
fails because the scene needs the switched-off effect, is listed with its message.
The point of the table: a scene pays for the effects it declares and no others.
"""
from __future__ import annotations

import argparse
import copy
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from filippov_paper.config import load_scene
from filippov.io import finalize, write_dataset
from filippov_paper.benchmarks import timing
from filippov_paper.report import FIT_BEGIN, FIT_END, Macros, num, tex_escape

ROOT = Path(__file__).resolve().parents[3]
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"
DEFAULT_SCENES = ["fig02_cases", "fig03_grazingsketch", "fig04_retmaps", "fig05_thetalt0mfs"]
FLIP = {"system": {"slow_fast": "reduced", "reduced": "slow_fast"},
        "flow": {"exact": "integrate", "integrate": "exact"},
        "sliding": {True: False, False: True}}

_CHILD = r"""
import json, sys
import filippov_paper.scenes
from filippov_paper.benchmarks.timing import measure
job = json.loads(sys.stdin.read())
try:
    t = measure(lambda: filippov_paper.scenes.compute(job["scene"]), min_rounds=job["min_rounds"],
                min_time=job["min_time"])
    out = {"status": "ok", "seconds": t.median, "seconds_min": t.min, "runs": t.rounds}
except Exception as exc:
    out = {"status": f"{type(exc).__name__}: {exc}"[:300], "seconds": float("nan"),
           "seconds_min": float("nan"), "runs": 0}
print(json.dumps(out))
"""


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


def time_variant(scene: dict, cap: float, repeat: int = timing.MIN_ROUNDS,
                 min_time: float = timing.MIN_TIME) -> dict:
    """The scene's compute call timed in a fresh process (:data:`_CHILD`): ``seconds``
    (median), ``seconds_min``, ``runs`` and ``status``; the process is stopped after
    ``cap`` seconds (warm-up and rounds together)."""
    failed = {"seconds": np.nan, "seconds_min": np.nan, "runs": 0}
    job = {"scene": scene, "min_rounds": repeat, "min_time": min_time}
    try:
        run = subprocess.run([sys.executable, "-c", _CHILD], input=json.dumps(job),
                             capture_output=True, text=True, timeout=cap)
    except subprocess.TimeoutExpired:
        return {**failed, "status": f"time cap ({cap:g} s)"}
    if run.returncode != 0:
        return {**failed, "status": f"crashed: {run.stderr.strip().splitlines()[-1:]}"}
    return json.loads(run.stdout.strip().splitlines()[-1])


def measure(scene_ids, cap: float, log=print, repeat: int = timing.MIN_ROUNDS,
            min_time: float = timing.MIN_TIME) -> xr.Dataset:
    rows = []
    for sid in scene_ids:
        scene = load_scene(ROOT / "config" / "scenes" / f"{sid}.yaml", SCHEMA)
        base = None
        for label, v in variants(scene):
            r = time_variant(v, cap, repeat, min_time)
            sec = float(r["seconds"])
            base = sec if base is None else base
            rows.append((sid, label, sec, float(r["seconds_min"]), int(r["runs"]), r["status"],
                         sec / base if base else np.nan))
            log(f"{sid:22s} {label:32s} {sec:9.3f} s  x{rows[-1][-1]:7.2f}  {r['status']}")
    sid, label, sec, sec_min, runs, status, rel = (np.array(c) for c in zip(*rows))
    ds = xr.Dataset(
        {"seconds": ("variant", sec.astype(float), {
            "long_name": "compute time (median of the timed calls)", "units": "s"}),
         "seconds_min": ("variant", sec_min.astype(float), {
             "long_name": "compute time (the fastest timed call)", "units": "s"}),
         "runs": ("variant", runs.astype(np.int32), {
             "long_name": "timed calls (after a warm-up call)", "units": "1"}),
         "relative": ("variant", rel.astype(float), {
             "long_name": "time / time as declared", "units": "1"}),
         "status": ("variant", status.astype(str), {"long_name": "ok or the error raised"})},
        coords={"scene": ("variant", sid.astype(str)), "change": ("variant", label.astype(str))})
    return finalize(ds, None, time_cap=cap, **timing.describe(min_rounds=repeat, min_time=min_time),
                    title="cost of each model ingredient per scene")


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
    work-precision sweep's (None when not measured)."""
    m.flag("rpHaveEffects", ds is not None)
    if ds is None:
        return None
    lines = [r"\medskip", "", FIT_BEGIN, r"\begin{tabular}{llrrl}", r"\toprule",
             r"scene & ingredient switched & time [s] & $\times$ declared & outcome \\",
             r"\midrule"]
    for k in range(ds.sizes["variant"]):
        status = str(ds.status.values[k])
        outcome = "ok" if status == "ok" else status.split(":")[0]
        lines.append(" & ".join([
            r"\texttt{" + tex_escape(str(ds.scene.values[k])) + "}",
            tex_escape(str(ds.change.values[k])).replace("->", r"$\to$"),
            f"${num(float(ds.seconds.values[k]), 3)}$",
            f"${num(float(ds.relative.values[k]), 3)}$",
            r"\emph{" + tex_escape(outcome) + "}"]) + r" \\")
    return "\n".join(lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=DEFAULT_SCENES)
    ap.add_argument("--time-cap", type=float, default=120.0,
                    help="seconds per variant (its warm-up call and timed calls together)")
    ap.add_argument("--repeat", type=int, default=timing.MIN_ROUNDS,
                    help="timed calls per variant at least (median), after one untimed call")
    ap.add_argument("--min-time", type=float, default=timing.MIN_TIME,
                    help="time more calls of a variant until this many seconds")
    ap.add_argument("--out", default=str(ROOT / "results" / "bench_effect_cost.nc"))
    args = ap.parse_args(argv)
    ds = measure(args.scenes, args.time_cap, log=lambda s: print(s, file=sys.stderr, flush=True),
                 repeat=args.repeat, min_time=args.min_time)
    write_dataset(ds, args.out)
    print(f"{'scene':22s} {'change':32s} {'time [s]':>9s} {'x declared':>10s}  status")
    for i in range(ds.sizes["variant"]):
        print(f"{str(ds.scene.values[i]):22s} {str(ds.change.values[i]):32s} "
              f"{float(ds.seconds[i]):9.3f} {float(ds.relative[i]):10.2f}  {ds.status.values[i]}")
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
