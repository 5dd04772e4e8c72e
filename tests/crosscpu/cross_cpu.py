"""`make cross-cpu`: emulate another CPU's arithmetic and check every scene against
the committed manifest.

Other machines round transcendental functions differently in the last bit
(numpy's AVX-512 loops, another libm). This check makes such a machine out of
the one it runs on, then builds every figure there:

* ``lastbit.c`` (beside this file), preloaded into every process, moves half the
  exp, log, sin, atan2, ... results by 1..N ulps up or down (``--ulps N``: real
  libms differ by up to a few ulps), deterministically per input and per seed
  (``LASTBIT_SEED``; N = 1 is the draw this check always made): Python's math
  module, numba-compiled code and numpy's scalar loops all call those symbols.
  Besides the seeds, one build moves every result (by -N..-1, 1..N ulps: no
  unmoved fraction, ``LASTBIT_ALL``);
* numpy's SIMD dispatch is switched down to its baseline
  (``NPY_DISABLE_CPU_FEATURES``), so numpy's own vector loops give way to the
  perturbed libm wherever the machine had something to switch;
* ``NUMBA_CPU_NAME=generic`` with a numba cache of its own: kernels compiled for
  no particular CPU. The emulated builds share that cache (the first compiles, the
  others load): the compiled code is the same in each, and the shim moves results
  when it calls libm, at run time. Only a libm call LLVM folds at compile time
  (a constant argument) keeps the first build's draw, as one machine would;
* ``OPENBLAS_CORETYPE=Prescott``: OpenBLAS (numpy's and scipy's, built for every
  x86 CPU and picking its kernels at load) runs its SSE3 kernels, as on a CPU
  without AVX and FMA; LAPACK's LU in Radau's Newton steps then rounds differently
  (the eps = 1e-4 sliding return of the hard-case sweep moves by 4e-16).

Each emulated build must pass the manifest check (data within each variable's
declared tolerance, figures by image). The work-precision sweep (its wall
times are measured, never compared; its errors are) runs in the last emulated
build only: the others take the native build's file, as ``make verify``'s
second build does. The emulated data are also compared with a native build of
the same tree, full arrays: every dataset whose numbers pass through a
transcendental function must change (an emulation that changes nothing
emulates nothing), and the spread per variable over the seeds is set against
its tolerance (margin = tolerance / spread; >= 10 is healthy; a count allowed
to jump by one crossing pair has margin 1 when it does). A margin below 1 is a
problem: the tolerance declared for that variable does not hold between two
machines (a manifest check can still pass then, if the manifest was written on
a machine whose values happen to lie between the two).
``--record`` writes the measured spreads into the manifest next to each
tolerance. ``--scenes`` rebuilds only some datasets (scene ids, ``hard_cases``,
``work_precision``) and checks only those: for iterating on one tolerance.

    python tests/crosscpu/cross_cpu.py [--ulps 2] [--seeds [1 2 3]] [--no-all-moved]
                                       [--scenes ID ...] [--native DIR] [--record] [--keep]
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path[:0] = [str(ROOT / "src"), str(ROOT / "workflow")]
sys.path.insert(0, str(ROOT / "workflow" / "scripts"))

from verify import copy_project, reuse_measured, run_snakemake  # noqa: E402

from filippov_paper import manifest  # noqa: E402
from filippov.io import read_dataset  # noqa: E402
from filippov_paper.tolerance import spread  # noqa: E402

#: datasets whose numbers never pass through a transcendental function: the
#: emulation cannot move them, and they are not required to move
ALGEBRAIC = {
    "fig01_slidesketch": "a sketch of linear fields: arrows, straight trajectories and "
                         "their sliding segment, all polynomial",
}


def build_shim(dest: Path) -> Path:
    cc = shutil.which(os.environ.get("CC", "cc")) or shutil.which("gcc")
    if cc is None:
        raise SystemExit("cross-cpu: no C compiler (cc/gcc) to build tests/crosscpu/lastbit.c")
    out = dest / "lastbit.so"
    subprocess.run([cc, "-O2", "-fno-builtin", "-shared", "-fPIC", "-o", str(out), str(HERE / "lastbit.c"),
                    "-ldl", "-lm"], check=True)
    return out


def emulation_env(shim: Path, seed: int, cache: Path, ulps: int = 1,
                  all_moved: bool = False) -> dict:
    """The environment of an emulated build: results moved by up to ``ulps`` ulps
    (every one of them when ``all_moved``), numpy at its SIMD baseline, numba for a
    generic CPU with the cache ``cache``, OpenBLAS's SSE3 kernels."""
    if ulps < 1:
        raise ValueError(f"ulps: at least 1, got {ulps}")
    env = {"LD_PRELOAD": str(shim), "LASTBIT_SEED": str(seed), "LASTBIT_ULPS": str(ulps),
           "LASTBIT_ALL": "1" if all_moved else "0", "NUMBA_CPU_NAME": "generic",
           "NUMBA_CACHE_DIR": str(cache), "PYTHONDONTWRITEBYTECODE": "1",
           "OPENBLAS_CORETYPE": "Prescott"}
    disable = manifest.numpy_simd()   # switched down to numpy's baseline
    if disable:
        env["NPY_DISABLE_CPU_FEATURES"] = " ".join(disable)
    return env


#: datasets of the build that are not scenes (no figure in the manifest)
SWEEPS = ("hard_cases", "work_precision")


def targets(only: list[str] | None = None) -> list[str]:
    """What the workflow builds (every scene file's figures, unless config.yaml picks
    some, and the sweeps); ``only``: just these scene ids and sweeps."""
    from filippov_paper.config import load_workflow_config

    scenes = load_workflow_config(ROOT / "config" / "config.yaml",
                                  ROOT / "config" / "schema" / "config.schema.json")["scenes"]
    if only is not None:
        unknown = sorted(set(only) - set(scenes) - set(SWEEPS))
        if unknown:
            raise SystemExit(f"cross-cpu: --scenes: not a scene or sweep: {', '.join(unknown)}")
    keep = (lambda name: True) if only is None else (lambda name: name in only)
    return [f"figures/{s}.{ext}" for s in scenes if keep(s) for ext in ("pdf", "png")] + \
        [f"results/{d}.nc" for d in SWEEPS if keep(d)]


def restrict(man: dict, only: list[str] | None) -> dict:
    """The manifest of the datasets and figures ``only`` names (all: None)."""
    if only is None:
        return man
    return dict(man, data={k: v for k, v in man["data"].items() if k in only},
                figures={k: v for k, v in man["figures"].items() if k in only})


def build(work: Path, env: dict | None, label: str, only: list[str] | None = None) -> float:
    """Build ``work`` (a project copy); the wall time in seconds."""
    t0 = time.perf_counter()
    print(f"== {label}: building in {work}", flush=True)
    run = run_snakemake(work, *targets(only), cores="all", env=env)
    if run.returncode != 0:
        sys.stdout.write(run.stdout[-4000:] + run.stderr[-4000:])
        raise SystemExit(f"cross-cpu: {label} build failed (exit {run.returncode})")
    elapsed = time.perf_counter() - t0
    print(f"== {label}: {elapsed:.0f} s", flush=True)
    return elapsed


def compare_builds(native: Path, emulated: Path, only: list[str] | None = None) -> dict:
    """{dataset: {variable: spread dict}} over full arrays (see
    filippov_paper.tolerance.spread); ``only``: just these datasets (``--scenes``)."""
    out = {}
    for nc in manifest.data_files(native / "results"):
        if only is not None and nc.stem not in only:
            continue
        a, b = read_dataset(nc), read_dataset(emulated / "results" / nc.name)
        out[nc.stem] = {name: spread(a[name], b[name]) for name in sorted(a.variables)
                        if a[name].dtype.kind in "fiub"}
    return out


def merge_spreads(runs: list[dict]) -> dict:
    """The worst of the seeds, per variable."""
    merged: dict = {}
    for run in runs:
        for sid, variables in run.items():
            for name, s in variables.items():
                m = merged.setdefault(sid, {}).setdefault(name, dict(s, seeds=0))
                m["seeds"] += 1
                for key in ("max_abs", "max_rel", "changed"):
                    m[key] = max(m[key], s[key])
                if s["margin"] < m["margin"]:   # the values at the worst entry of the worst seed
                    m["margin"], m["worst"] = s["margin"], s.get("worst")
                m["ok"] = m["ok"] and s["ok"]
    return merged


def report(merged: dict, lowest: int = 15) -> list[str]:
    """Table lines; and the list of problems (datasets that did not move, variables
    whose native and emulated values differ beyond their declared tolerance)."""
    problems = []
    print(f"\n{'dataset':24s} {'variables moved':>16s}  smallest margin (variable)")
    for sid, variables in sorted(merged.items()):
        moved = sum(1 for s in variables.values() if s["changed"])
        finite = [(s["margin"], n) for n, s in variables.items() if s["changed"]]
        worst = min(finite) if finite else None
        text = f"{worst[0]:.3g} ({worst[1]})" if worst else "-"
        print(f"{sid:24s} {moved:>7d} of {len(variables):<6d}  {text}")
        if moved == 0 and sid not in ALGEBRAIC:
            problems.append(f"results/{sid}.nc: the emulation changed nothing (emulates nothing)")
        if moved and sid in ALGEBRAIC:
            problems.append(f"results/{sid}.nc: listed as algebraic but moved: update ALGEBRAIC")
    rows = sorted((s["margin"], sid, n, s) for sid, v in merged.items() for n, s in v.items()
                  if s["changed"])
    n = max((s["seeds"] for v in merged.values() for s in v.values()), default=0)
    print(f"\nsmallest margins (tolerance / spread over {n} emulated builds):")
    print(f"{'margin':>9s}  {'max abs':>9s}  {'max rel':>9s}  variable  "
          f"(native -> emulated at the entry that sets the margin)")
    for margin, sid, name, s in rows[:lowest]:
        at = s.get("worst")
        where = f"  ({at[0]:.4g} -> {at[1]:.4g})" if at else ""
        print(f"{margin:9.3g}  {s['max_abs']:9.2e}  {s['max_rel']:9.2e}  {sid}:{name}{where}")
    for margin, sid, name, s in rows:
        if not s["ok"]:
            problems.append(f"results/{sid}.nc: {name}: native and emulated builds differ "
                            f"beyond its declared tolerance (rule {s['rule']}, margin "
                            f"{margin:.3g}): the tolerance does not hold across CPUs")
    return problems


def record(merged: dict, ulps: int, path: Path = manifest.MANIFEST) -> None:
    """The spreads into the manifest, next to each tolerance (with the emulation's
    size: ``ulps``; ``seeds`` counts the emulated builds, the all-moved one included)."""
    man = json.loads(path.read_text())
    for sid, variables in merged.items():
        for name, s in variables.items():
            entry = man["data"].get(sid, {}).get("variables", {}).get(name)
            if entry is not None:
                entry["spread"] = {k: (None if k == "margin" and not np.isfinite(v) else v)
                                   for k, v in s.items() if k != "ok"}
                entry["spread"]["ulps"] = ulps
    path.write_text(json.dumps(man, indent=1, sort_keys=True) + "\n")
    print(f"recorded the spreads in {path}")


def runs_of(seeds: list[int], all_moved: bool) -> list[tuple[int, bool, str]]:
    """(seed, every result moved, label) of each emulated build: the seeds, then one
    build where every result moves (its seed the next after the largest)."""
    runs = [(seed, False, f"seed {seed}") for seed in seeds]
    if all_moved:
        seed = max(seeds, default=0) + 1
        runs.append((seed, True, f"seed {seed}, every result moved"))
    return runs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ulps", type=int, default=2,
                    help="results move by up to N ulps (half of them, per input and seed; "
                         "all in one more build; default 2)")
    ap.add_argument("--seeds", type=int, nargs="*", default=[1, 2, 3],
                    help="the seeds of the builds where half the results move (default 1 2 "
                         "3; none: only the build where every result moves)")
    ap.add_argument("--all-moved", action=argparse.BooleanOptionalAction, default=True,
                    help="one more build in which every result moves (default: yes)")
    ap.add_argument("--scenes", nargs="+", metavar="ID",
                    help="build and check only these scenes/sweeps (iteration; not a full check)")
    ap.add_argument("--native", type=Path, help="a finished native build (project copy) to reuse")
    ap.add_argument("--record", action="store_true", help="write the spreads into the manifest")
    ap.add_argument("--keep", action="store_true", help="keep the build directories")
    args = ap.parse_args(argv)
    if args.ulps < 1:
        ap.error(f"--ulps: at least 1, got {args.ulps}")
    if not args.seeds and not args.all_moved:
        ap.error("--seeds none and --no-all-moved: no emulated build to make")
    if args.record and args.scenes:
        ap.error("--record needs the full build (no --scenes)")
    only = args.scenes
    man = restrict(json.loads(manifest.MANIFEST.read_text()), only)
    runs_planned = runs_of(args.seeds, args.all_moved)
    tmp = Path(tempfile.mkdtemp(prefix="filippov-cross-cpu-"))
    problems, runs, times = [], [], {}
    try:
        shim = build_shim(tmp)
        native = args.native
        if native is None:
            native = copy_project(tmp / "native")
            times["native"] = build(native, None, "native", only)
        problems += [f"native: {p}"
                     for p in manifest.check(native / "results", native / "figures", man,
                                             only=only)]
        for k, (seed, every, label) in enumerate(runs_planned):
            work = copy_project(tmp / f"seed{seed}")
            if k < len(runs_planned) - 1:  # the sweep's errors once, in the last build
                reuse_measured(native, work, only)  # its wall times are never compared
            # one cache for every emulated build: the kernels compile once (module doc)
            env = emulation_env(shim, seed, tmp / "numba-cache-generic", args.ulps, every)
            times[label] = build(work, env, f"emulated CPU (+-{args.ulps} ulps), {label}", only)
            problems += [f"{label}: {p}"
                         for p in manifest.check(work / "results", work / "figures", man,
                                                 only=only)]
            runs.append(compare_builds(native, work, only))
        merged = merge_spreads(runs)
        problems += report(merged)
        if args.record:
            record(merged, args.ulps)
    finally:
        if args.keep:
            print(f"builds kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)
    for p in problems:
        print(f"MISMATCH {p}")
    print("build times: " + ", ".join(f"{k} {v:.0f} s" for k, v in times.items()))
    print(f"cross-cpu: {len(runs_planned)} emulated builds (results moved by up to "
          f"{args.ulps} ulps{'; one with every result moved' if args.all_moved else ''}"
          f"{'; only ' + ' '.join(only) if only else ''}): "
          f"{'OK' if not problems else f'{len(problems)} problems'}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
