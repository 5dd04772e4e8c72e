"""What each model ingredient costs: every scene timed as declared and with one
ingredient switched (reduced <-> slow-fast, exact <-> integrated flows, sliding
on <-> off, compiled <-> python engine).

Run ``python -m filippov.benchmarks.effect_cost [scene ...]``. Each variant runs
in its own process (with a time cap), timing only the scene's compute call; a
variant the scene does not support, or one that fails because the scene needs
the switched-off effect, is listed with its message. The point of the table: a
scene pays for the effects it declares and no others.
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

from ..config import load_scene
from ..io import finalize, write_dataset

ROOT = Path(__file__).resolve().parents[3]
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"
DEFAULT_SCENES = ["fig02_cases", "fig03_grazingsketch", "fig04_retmaps", "fig05_thetalt0mfs"]
FLIP = {"system": {"slow_fast": "reduced", "reduced": "slow_fast"},
        "flow": {"exact": "integrate", "integrate": "exact"},
        "sliding": {True: False, False: True}}

_CHILD = r"""
import json, sys, time
import filippov.scenes
scene = json.loads(sys.stdin.read())
t0 = time.perf_counter()
try:
    filippov.scenes.compute(scene)
    out = {"status": "ok"}
except Exception as exc:
    out = {"status": f"{type(exc).__name__}: {exc}"[:300]}
out["seconds"] = time.perf_counter() - t0
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
        v["solver"]["engine"] = "python"
        out.append(("engine: compiled -> python", v))
    return out


def time_variant(scene: dict, cap: float) -> tuple[float, str]:
    try:
        run = subprocess.run([sys.executable, "-c", _CHILD], input=json.dumps(scene),
                             capture_output=True, text=True, timeout=cap)
    except subprocess.TimeoutExpired:
        return np.nan, f"time cap ({cap:g} s)"
    if run.returncode != 0:
        return np.nan, f"crashed: {run.stderr.strip().splitlines()[-1:]}"
    res = json.loads(run.stdout.strip().splitlines()[-1])
    return float(res["seconds"]), res["status"]


def measure(scene_ids, cap: float, log=print) -> xr.Dataset:
    rows = []
    for sid in scene_ids:
        scene = load_scene(ROOT / "config" / "scenes" / f"{sid}.yaml", SCHEMA)
        # one untimed run first, so that numba's cache and the imports are warm
        time_variant(scene, cap)
        base = None
        for label, v in variants(scene):
            sec, status = time_variant(v, cap)
            base = sec if base is None else base
            rows.append((sid, label, sec, status, sec / base if base else np.nan))
            log(f"{sid:22s} {label:32s} {sec:9.3f} s  x{rows[-1][4]:7.2f}  {status}")
    sid, label, sec, status, rel = (np.array(c) for c in zip(*rows))
    ds = xr.Dataset(
        {"seconds": ("variant", sec.astype(float), {"long_name": "compute time", "units": "s"}),
         "relative": ("variant", rel.astype(float), {
             "long_name": "time / time as declared", "units": "1"}),
         "status": ("variant", status.astype(str), {"long_name": "ok or the error raised"})},
        coords={"scene": ("variant", sid.astype(str)), "change": ("variant", label.astype(str))})
    return finalize(ds, None, time_cap=cap, title="cost of each model ingredient per scene")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scenes", nargs="*", default=DEFAULT_SCENES)
    ap.add_argument("--time-cap", type=float, default=120.0, help="seconds per variant")
    ap.add_argument("--out", default=str(ROOT / "results" / "bench_effect_cost.nc"))
    args = ap.parse_args(argv)
    ds = measure(args.scenes, args.time_cap, log=lambda s: print(s, file=sys.stderr, flush=True))
    write_dataset(ds, args.out)
    print(f"{'scene':22s} {'change':32s} {'time [s]':>9s} {'x declared':>10s}  status")
    for i in range(ds.sizes["variant"]):
        print(f"{str(ds.scene.values[i]):22s} {str(ds.change.values[i]):32s} "
              f"{float(ds.seconds[i]):9.3f} {float(ds.relative[i]):10.2f}  {ds.status.values[i]}")
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
