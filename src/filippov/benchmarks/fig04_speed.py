"""What the fig04 return maps cost: the project's solver against scipy's solve_ivp.

Run ``python -m filippov.benchmarks.fig04_speed`` (``make bench-fig04``). Every
method computes P on the same grid (the scene's, or every k-th point of it with
``--every k``) for both theta, and is scored by its maximal deviation from a
reference: the project's exact-flow driver, which is itself checked against
DOP853 at rtol 1e-13 on the same grid (the "reference check" row). Times are
the median of ``--repeat`` runs in this process, one core.

The solve_ivp baseline is written the way a user would: integrate the current
region with a terminal event on h and on the section, decide at each hit of h
from the two normal speeds whether to cross or slide, and integrate sliding with
the Filippov field and terminal events where a sliding condition fails.
"""
from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np
import yaml
from scipy.integrate import solve_ivp

from ..models import hopf
from ..scenes.fig04_retmaps import return_map, x2_grid
from ..system import MINUS, PLUS, SLIDING

SCENE = Path(__file__).resolve().parents[3] / "config" / "scenes" / "fig04_retmaps.yaml"


def solve_ivp_map(model, x2, method: str, rtol: float, atol: float, max_events: int = 200):
    """P on L1 with solve_ivp and events, one region (or sliding) at a time."""
    system = model.full()
    period = 2 * np.pi / abs(model.parameters["omega"])
    out = np.empty_like(x2)
    for k, x in enumerate(x2):
        z, t, mode = np.array([0.0, x, 0.0]), 0.0, PLUS
        t_max = 4 * period
        for _ in range(max_events):
            switch = lambda _t, zz: system.switch(zz)
            switch.terminal = True
            switch.direction = -1 if mode == PLUS else 1
            section = lambda _t, zz: zz[0] if zz[1] > 0 else 1.0
            section.terminal, section.direction = True, -1
            if mode == SLIDING:
                exit_a = lambda _t, zz: system.normal_speeds(zz)[0]
                exit_b = lambda _t, zz: system.normal_speeds(zz)[1]
                exit_a.terminal = exit_b.terminal = True
                exit_a.direction, exit_b.direction = -1, 1
                events = [section, exit_a, exit_b]
            else:
                events = [section, switch]
            sol = solve_ivp(lambda _t, zz, m=mode: system.field(m, zz), (t, t_max), z,
                            method=method, rtol=rtol, atol=atol, events=events)
            if sol.status != 1:
                raise RuntimeError(f"{method}: no return to L1 from x2={x!r} ({sol.message})")
            hit = [i for i, te in enumerate(sol.t_events) if te.size]
            i = min(hit, key=lambda j: sol.t_events[j][0])
            t, z = sol.t_events[i][0], sol.y_events[i][0]
            if i == 0 and t > 1e-9:  # the section, not the start point on it
                out[k] = z[1]
                break
            if i == 0:
                z = z + 1e-12 * system.field(mode, z)  # step off the start point
                continue
            a, b = system.normal_speeds(z)
            if mode == SLIDING:
                mode = MINUS if i == 1 else PLUS
            elif mode == PLUS:
                mode = SLIDING if a > 0 else MINUS
            else:
                mode = SLIDING if b < 0 else PLUS
        else:
            raise RuntimeError(f"{method}: event limit from x2={x!r}")
    return out


def timed(fn, repeat: int):
    times, result = [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), result


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--every", type=int, default=1, help="use every k-th grid point")
    ap.add_argument("--repeat", type=int, default=3, help="runs per method (median)")
    args = ap.parse_args(argv)
    p = yaml.safe_load(SCENE.read_text())["parameters"]
    x2 = x2_grid(p)[:: args.every]
    eps, mu, omega = p["eps"], p["mu"], p["omega"]
    models = [hopf.model(eps, th, mu, omega) for th in p["theta"]]
    tight = {"rtol": 1e-12, "atol": 1e-14}

    def ours(method, opts):
        return lambda: np.concatenate([return_map(m, x2, method, opts)[0] for m in models])

    # away from the grazing value the map is well conditioned; at x2 = 1 exactly the
    # exact flow touches H_s while an integrator's own error decides the side
    away = np.concatenate([np.abs(x2 - 1) > 1e-6] * len(models))
    print(f"fig04 grid: {x2.size} points x {len(models)} theta, median of {args.repeat} runs")
    t_ref, ref = timed(ours("exact", tight), args.repeat)
    check = ours("integrate", {"rtol": 1e-13, "atol": 1e-15})()
    rows = [("project exact flows (reference)", t_ref, 0.0),
            ("reference check: project DOP853 rtol 1e-13", np.nan, np.max(np.abs(check - ref)[away]))]
    for rtol in (1e-6, 1e-10, 1e-12):
        t, val = timed(ours("integrate", {"rtol": rtol, "atol": rtol * 1e-2}), args.repeat)
        rows.append((f"project DOP853 rtol {rtol:g}", t, np.max(np.abs(val - ref)[away])))
    for method, rtol in (("RK45", 1e-6), ("RK45", 1e-10), ("DOP853", 1e-10)):
        fn = lambda: np.concatenate([solve_ivp_map(m, x2, method, rtol, rtol * 1e-2) for m in models])
        name = f"solve_ivp {method} rtol {rtol:g}"
        try:
            t, val = timed(fn, 1)
        except RuntimeError as err:  # listed, not dropped
            rows.append((name, np.nan, f"failed: {err}"))
            continue
        rows.append((name, t, np.max(np.abs(val - ref)[away])))
    print(f"{'method':46s} {'time [s]':>10s} {'max error':>11s} {'time / ours':>12s}")
    for name, t, err in rows:
        ratio = t / t_ref if np.isfinite(t) else np.nan
        err = f"{err:11.2e}" if not isinstance(err, str) else err
        print(f"{name:46s} {t:10.3f} {err:>11s} {ratio:12.1f}")


if __name__ == "__main__":
    main()
