"""The hard-case sweep over eps: what must stay true as eps -> 0, one eps at a time.

Four measurements, each at one value of eps and independent of every other eps
(so a sweep split into chunks gives the same numbers, bit for bit):

* :func:`theta_negative_jump` -- the Hopf example of Fig. 4 at theta < 0:
  the jump 1 - P(x2) of the return map just above grazing (x2 = 1 + 1e-13),
  from the compiled kernel; jump/eps converges as eps -> 0.
* :func:`theta_positive_slope` -- the same map at theta > 0: the one-sided
  slope (P(x2) - P(1))/(x2 - 1), probed inside the kink (width O(eps^2)) but
  not below the spacing of doubles near 1; it stays of order one.
* :func:`chatter_period` -- the pseudo-equilibrium example at theta < 0: the
  period of the chatter orbit from the reference driver's switching times
  against the closed form of :mod:`filippov.analytic.chatter`, and period/eps.
* :func:`slide_in` -- the pseudo-equilibrium example at theta > 0: the orbit
  starts sliding at x = -(1 - theta) eps and slides into the origin, from
  30 eps away (reference driver) and from x = 0.3 (compiled kernel).

:func:`sweep` measures a list of eps values and returns one Dataset (dimension
``eps``). The workflow splits the configured list (``hard_cases:`` in
config/config.yaml, checked by :func:`check_config`) into ``chunks`` contiguous
parts (:func:`compute_part`, the split of :func:`filippov_paper.scenes.chunking.bounds`)
and :func:`merge` puts them back together: the result is the dataset
:func:`sweep` returns for the whole list, byte for byte once written with
:func:`filippov.io.write_dataset`. ``chunks`` says how to run the sweep, not
what it computes: it is not part of the dataset.

No Snakemake here; ``workflow/scripts/hard_cases_*.py`` are the thin callers.
"""
from __future__ import annotations

import json
import math
from collections import Counter

import numpy as np
import xarray as xr

from filippov import fastmap
from filippov.analytic import chatter
from filippov.io import finalize
from filippov_paper.tolerance import ULP, Tolerance, annotate, sqrt_law
from filippov_paper.report import (Macros, count_phrase, head, not_yet, num, per_eps_rows,
                                   share_phrase, tabular, value, var)
from filippov.models import hopf, pseudo_equilibrium
from filippov.progress import Progress
from filippov_paper.scenes.chunking import bounds
from filippov.poincare import sliding_time
from filippov_paper.scenes.fig04_retmaps import section_L1  # the section of the return map P (fig04)
from filippov.simulate import simulate

DATASET_ID = "hard_cases"
CONFIG_KEYS = ("eps", "chunks")
LAYOUT_KEYS = ("chunks",)

# Fixed settings of the four measurements (recorded in every dataset and chunk).
OMEGA, MU = 8 * np.pi, 1.0
PARAMETERS = {
    "omega": float(OMEGA),                 # Hopf example: rotation speed ...
    "mu": MU,                              # ... at the grazing parameter
    "hopf_t_max": float(4 * 2 * np.pi / OMEGA),  # time bound of one return to L1
    "jump_theta": -0.5,
    "jump_x2_offset": 1e-13,               # start x2 = 1 + offset
    "slope_theta": 0.5,
    "slope_probe_factor": 1e-3,            # x2 - 1 = max(factor eps^2, floor)
    "slope_probe_floor": 1e-13,
    "chatter_theta": -0.5,
    "chatter_periods": 20.25,              # simulated time in periods of the orbit
    "chatter_max_events": 100,
    "slide_theta": 0.6,
    "slide_start_over_eps": 30.0,          # reference driver: start at x = 30 eps ...
    "slide_t_end_over_eps": 100.0,         # ... for a time 100 eps
    "slide_max_events": 100,
    "kernel_start": 0.3,                   # compiled kernel: start at x = 0.3 ...
    "kernel_t_max": 0.5,                   # ... for a time 0.5
    "return_theta": 0.5,                   # Hopf example, theta > 0: one return to L1 ...
    "return_x2": 1.2,                      # ... from (0, return_x2, 0), sliding on the way
}

_STATUS_NOTE = "filippov.fastmap status: " + "; ".join(
    f"{code} = {text}" for code, text in fastmap.STATUS.items())

# name -> (dtype, long_name, units[, comment]); every variable has dimension eps
VARIABLES = {
    "jump": ("f8", "jump 1 - P(x2) of the Hopf return map at x2 = 1 + jump_x2_offset, "
                   "theta = jump_theta", "1"),
    "jump_over_eps": ("f8", "jump divided by eps", "1"),
    "jump_status": ("i4", "compiled kernel status of the jump orbit", "1", _STATUS_NOTE),
    "jump_switches": ("i4", "switches of the jump orbit before its return to L1", "1"),
    "jump_finite": ("i4", "1 if the returned state of the jump orbit is finite, else 0", "1"),
    "slope": ("f8", "one-sided slope (P(x2) - P(1))/(x2 - 1) of the Hopf return map, "
                    "theta = slope_theta", "1"),
    "slope_probe": ("f8", "x2 - 1 of the probe (the step 1 + max(slope_probe_factor eps^2, "
                          "slope_probe_floor) rounds to)", "1"),
    "slope_P_grazing": ("f8", "P(1): return of the grazing orbit, theta = slope_theta", "1"),
    "slope_sliding_time": ("f8", "time the probe orbit slides", "1"),
    "slope_status_grazing": ("i4", "compiled kernel status of the grazing orbit", "1",
                             _STATUS_NOTE),
    "slope_status_probe": ("i4", "compiled kernel status of the probe orbit", "1",
                           _STATUS_NOTE),
    "slope_finite": ("i4", "1 if the returned states of both orbits are finite, else 0", "1"),
    "chatter_period": ("f8", "period of the chatter orbit (closed form), "
                             "theta = chatter_theta", "1"),
    "chatter_period_over_eps": ("f8", "chatter period divided by eps", "1"),
    "chatter_period_max_rel_dev": ("f8", "largest relative deviation of the simulated "
                                         "periods (every second switching time) from the "
                                         "closed form", "1"),
    "chatter_switches": ("i4", "switches of the reference driver within chatter_periods "
                               "periods", "1"),
    "chatter_times_finite": ("i4", "1 if every switching time is finite, else 0", "1"),
    "slide_events": ("i4", "events of the reference driver after the start, "
                           "theta = slide_theta", "1"),
    "slide_starts": ("i4", "of these, events where sliding starts", "1"),
    "slide_final_mode": ("i4", "mode at the end of the run (0 sliding, 1 region +, "
                               "-1 region -)", "1"),
    "slide_start_x": ("f8", "x where sliding starts (first event after the start)", "1"),
    "slide_start_offset": ("f8", "x where sliding starts + (1 - theta) eps", "1"),
    "slide_final_abs_x": ("f8", "|x| at the end of the reference driver's run", "1"),
    "slide_finite": ("i4", "1 if the final state of the reference driver is finite, else 0",
                     "1"),
    "kernel_status": ("i4", "compiled kernel status of the run from x = kernel_start", "1",
                      _STATUS_NOTE),
    "kernel_switches": ("i4", "switches of the compiled kernel's run", "1"),
    "kernel_final_abs_x": ("f8", "|x| at the end of the compiled kernel's run", "1"),
    "kernel_finite": ("i4", "1 if the final state of the compiled kernel is finite, else 0",
                      "1"),
    "return_P": ("f8", "x2 at the first return to L1 of the Hopf orbit from (0, return_x2, 0), "
                       "theta = return_theta, reference driver (sliding integrated)", "1"),
    "return_P_reduced": ("f8", "the same return of the reduced system (eps = 0)", "1"),
    "return_sliding_time": ("f8", "time the orbit slides on the way", "1"),
    "return_steps": ("i4", "driver steps of the return (its cost, deterministic)", "1"),
    "return_stiff": ("i4", "1 if the sliding was finished by the implicit Radau IIA method "
                           "(DOP853 bounded by stability), else 0", "1"),
    "return_finite": ("i4", "1 if the returned state is finite, else 0", "1"),
}
_OFFSET = PARAMETERS["jump_x2_offset"]
#: cross-machine tolerances beyond the default (see filippov_paper.tolerance)
TOLERANCES = {
    "jump": Tolerance(1e-6, 1e-12, f"return of a start {_OFFSET:g} above grazing: event "
                                   f"times square-root conditioned (ulp/(2 sqrt(offset)) = "
                                   f"{sqrt_law(_OFFSET):.1e}) in a jump of O(eps)"),
    "jump_over_eps": Tolerance(1e-6, 1e-12, "as jump"),
    "slope": Tolerance(1e-9, 20 * ULP / PARAMETERS["slope_probe_floor"],
                       "difference quotient over a probe >= slope_probe_floor: one ulp of P "
                       "moves it by ulp/probe; x20"),
    "slope_sliding_time": Tolerance(1e-9, sqrt_law(PARAMETERS["slope_probe_floor"], 3.0),
                                    "slide of a probe just past grazing: square-root law; x3"),
    "return_steps": Tolerance(0.5, 10, "a cost counter, not a result: step acceptance and "
                                       "Radau IIA's Newton decisions flip with "
                                       "last bits (a few percent measured); it shows the cost "
                                       "stays bounded"),
}

#: the sliding return's slide end, in u/(theta eps) (see :func:`tolerances`)
SLIDE_END_FLOOR = 10.0


def tolerances(eps_values) -> dict:
    """:data:`TOLERANCES` and those that follow the smallest eps of the sweep.

    ``return_sliding_time``: the slide of the sliding return ends where the Filippov
    field leaves H (dH.F_+ = 0), located on the path of the stiff stay's Radau IIA
    steps, whose absolute tolerance is held at the field's rounding noise: the slide
    relaxes at rate 1/(theta eps), so an ulp of the state moves the field by
    u/(theta eps) (simulate.NOISE_STEPS). A last bit elsewhere flips a Newton count,
    an LU pivot's rounding or a step size, and the path moves within that floor, not
    by ulps. Measured over 60 step sequences per eps (starts moved by +-15 ulps, rtol
    x0.5..2 around 1e-12), the slide end moved by up to 0.01, 0.2, 0.3 and 2.4
    u/(theta eps) at eps = 1e-3, 1e-4, 1e-5, 1e-6 (rms 0.7 at 1e-6), the returned
    state P by a few ulps. x4 room: SLIDE_END_FLOOR u/(theta eps_min)."""
    eps_min = min(float(e) for e in eps_values)
    floor = ULP / (PARAMETERS["return_theta"] * eps_min)
    return {**TOLERANCES, "return_sliding_time": Tolerance(
        1e-9, SLIDE_END_FLOOR * floor,
        f"slide end located on the stiff stay's Radau IIA path, known to its noise floor "
        f"u/(theta eps) ({floor:.1e} at eps_min {eps_min:g}), not to ulps (Newton counts, LU "
        f"rounding, step sizes flip with last bits): <= 2.4 u/(theta eps) over 60 step "
        f"sequences at eps = 1e-6; x4")}


EPS_ATTRS = {"long_name": "singular perturbation parameter eps", "units": "1"}


class ConfigError(ValueError):
    """The ``hard_cases:`` block of config/config.yaml is malformed."""


# ----------------------------------------------------------------------------- measurements
def _hopf_returns(eps: float, theta: float, x2) -> fastmap.BatchReturns:
    x2 = np.asarray(x2, dtype=float)
    starts = np.stack([np.zeros_like(x2), x2, np.zeros_like(x2)], axis=1)
    cm = hopf.compiled(eps, theta, PARAMETERS["mu"], PARAMETERS["omega"])
    return fastmap.compute_returns(cm, starts, PARAMETERS["hopf_t_max"])


def theta_negative_jump(eps: float) -> dict:
    """The jump of P just above grazing at theta = jump_theta (< 0), compiled kernel."""
    x2 = 1.0 + PARAMETERS["jump_x2_offset"]
    out = _hopf_returns(eps, PARAMETERS["jump_theta"], [x2])
    jump = 1.0 - float(out.state[0, 1])
    return {"jump": jump, "jump_over_eps": jump / eps, "jump_status": int(out.status[0]),
            "jump_switches": int(out.n_switches[0]),
            "jump_finite": int(np.all(np.isfinite(out.state)))}


def slope_probe(eps: float) -> float:
    """x2 of the slope probe: inside the kink, whose width in x2 is O(eps^2), but
    not below the spacing of doubles near 1 (the step taken is what 1 + dx rounds to)."""
    return 1.0 + max(PARAMETERS["slope_probe_factor"] * eps * eps, PARAMETERS["slope_probe_floor"])


def theta_positive_slope(eps: float) -> dict:
    """The one-sided slope of P at grazing for theta = slope_theta (> 0), compiled kernel."""
    x2 = slope_probe(eps)
    out = _hopf_returns(eps, PARAMETERS["slope_theta"], [1.0, x2])
    P = out.state[:, 1]
    return {"slope": float((P[1] - P[0]) / (x2 - 1.0)), "slope_probe": x2 - 1.0,
            "slope_P_grazing": float(P[0]), "slope_sliding_time": float(out.sliding_time[1]),
            "slope_status_grazing": int(out.status[0]), "slope_status_probe": int(out.status[1]),
            "slope_finite": int(np.all(np.isfinite(out.state)))}


def chatter_period(eps: float) -> dict:
    """Chatter period at theta = chatter_theta (< 0): reference driver vs closed form."""
    theta = PARAMETERS["chatter_theta"]
    orbit = chatter.orbit(eps, theta)
    system = pseudo_equilibrium.model(eps, theta).full()
    traj = simulate(system, [orbit["x_switch"], orbit["y_switch"]],
                    PARAMETERS["chatter_periods"] * orbit["period"], dense=False,
                    max_events=PARAMETERS["chatter_max_events"])
    t = np.array([e.t for e in traj.switches()], dtype=float)
    periods = np.diff(t[::2])
    dev = float(np.max(np.abs(periods - orbit["period"])) / abs(orbit["period"])) \
        if periods.size else math.nan
    return {"chatter_period": float(orbit["period"]),
            "chatter_period_over_eps": float(orbit["period"] / eps),
            "chatter_period_max_rel_dev": dev, "chatter_switches": int(t.size),
            "chatter_times_finite": int(np.all(np.isfinite(t)))}


def slide_in(eps: float) -> dict:
    """Slide-in to the pseudo-equilibrium at theta = slide_theta (> 0): from
    slide_start_over_eps * eps with the reference driver (the approach within
    the fast transient, sampled on the eps scale) and from kernel_start with the
    compiled kernel (exact flows, sliding by DOP853); the O(1) approach of the
    reference driver is tests/test_hard_cases.py's
    test_reference_driver_travels_order_one_at_tiny_eps_within_a_step_bound."""
    theta = PARAMETERS["slide_theta"]
    system = pseudo_equilibrium.model(eps, theta).full()
    traj = simulate(system, [PARAMETERS["slide_start_over_eps"] * eps, 0.0],
                    PARAMETERS["slide_t_end_over_eps"] * eps, dense=False,
                    max_events=PARAMETERS["slide_max_events"])
    after = traj.events[1:]
    x_start = float(after[0].state[0]) if after else math.nan
    out = fastmap.compute_returns(pseudo_equilibrium.compiled(eps, theta),
                                  [[PARAMETERS["kernel_start"], 0.0]], PARAMETERS["kernel_t_max"])
    return {"slide_events": len(after),
            "slide_starts": sum(e.kind == "slide_start" for e in after),
            "slide_final_mode": int(traj.mode), "slide_start_x": x_start,
            "slide_start_offset": x_start + (1 - theta) * eps,
            "slide_final_abs_x": abs(float(traj.z[0])),
            "slide_finite": int(np.all(np.isfinite(traj.z))),
            "kernel_status": int(out.status[0]), "kernel_switches": int(out.n_switches[0]),
            "kernel_final_abs_x": abs(float(out.state[0, 0])),
            "kernel_finite": int(np.all(np.isfinite(out.state)))}


def sliding_return(eps: float) -> dict:
    """One return to L1 of the Hopf example at theta = return_theta (> 0) with the
    reference driver: the orbit grazes into sliding, whose fast direction
    (x1 + 1 relaxing at rate 1/(theta eps)) makes the sliding field stiff; the
    driver detects it and finishes with Radau IIA. Its steps are the cost."""
    p = PARAMETERS
    model = hopf.model(eps, p["return_theta"], p["mu"], p["omega"])
    start = [0.0, p["return_x2"], 0.0]
    traj = simulate(model.full(), start, p["hopf_t_max"], sections=[section_L1()],
                    dense=False)
    reduced = simulate(model.reduced(), start[:2], p["hopf_t_max"], sections=[section_L1()],
                       dense=False)
    ok = traj.status == "section:L1" and reduced.status == "section:L1"
    return {"return_P": float(traj.z[1]) if ok else math.nan,
            "return_P_reduced": float(reduced.z[1]) if ok else math.nan,
            "return_sliding_time": float(sliding_time(traj.events)),
            "return_steps": int(traj.n_steps), "return_stiff": int("sliding" in traj.stiff_modes),
            "return_finite": int(ok and np.all(np.isfinite(traj.z)))}


MEASUREMENTS = (theta_negative_jump, theta_positive_slope, chatter_period, slide_in,
                sliding_return)


def measure(eps: float) -> dict:
    """Every quantity of the sweep at one eps (nothing depends on other eps values)."""
    values = {}
    for fn in MEASUREMENTS:
        values.update(fn(eps))
    return values


# ----------------------------------------------------------------------------- config
def _eps_list(values, field: str = "eps") -> list[float]:
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise ConfigError(f"{field}: must be a non-empty list of numbers, got {values!r}")
    out = []
    for k, v in enumerate(list(values)):
        where = f"{field}[{k}]"
        if isinstance(v, str):
            raise ConfigError(f"{where}: must be a number, got the string {v!r} (YAML reads "
                              f"1e-3 as text; write 1.0e-3)")
        if isinstance(v, (bool, np.bool_)) or not isinstance(v, (int, float, np.integer,
                                                                  np.floating)):
            raise ConfigError(f"{where}: must be a number, got {v!r}")
        v = float(v)
        if not (math.isfinite(v) and v > 0):
            raise ConfigError(f"{where}: must be a positive finite number, got {v!r}")
        if v in out:
            raise ConfigError(f"{where}: {v!r} is listed twice (already {field}[{out.index(v)}])")
        out.append(v)
    if not out:
        raise ConfigError(f"{field}: must be a non-empty list of numbers, got an empty list")
    return out


def check_config(config) -> dict:
    """The ``hard_cases:`` block, checked: ``{"eps": [floats], "chunks": int}``.

    Errors name the field (``hard_cases.eps[2]``, ``hard_cases.chunks``)."""
    name = DATASET_ID
    if config is None:
        raise ConfigError(f"{name}: missing from config/config.yaml (needs eps: [...] and "
                          f"chunks: N)")
    if not isinstance(config, dict):
        raise ConfigError(f"{name}: must be a mapping with keys {', '.join(CONFIG_KEYS)}, "
                          f"got {config!r}")
    unknown = sorted(str(k) for k in config if k not in CONFIG_KEYS)
    if unknown:
        raise ConfigError(f"{name}.{unknown[0]}: unknown key (allowed: {', '.join(CONFIG_KEYS)})")
    if "eps" not in config:
        raise ConfigError(f"{name}.eps: required (a list of positive numbers)")
    eps = _eps_list(config["eps"], f"{name}.eps")
    n = config.get("chunks", 1)
    if isinstance(n, (bool, np.bool_)) or not isinstance(n, (int, np.integer)) \
            or not 1 <= n <= len(eps):
        raise ConfigError(f"{name}.chunks: must be an integer from 1 to {len(eps)} (the number "
                          f"of eps values), got {n!r}")
    return {"eps": eps, "chunks": int(n)}


# ----------------------------------------------------------------------------- datasets
def _provenance(eps: list[float]) -> dict:
    """What the dataset depends on (as a scene dict for :func:`filippov.io.finalize`):
    the eps grid and the fixed settings; not how the work was split."""
    return {"id": DATASET_ID, "eps": list(eps), "parameters": dict(PARAMETERS)}


def _variables(eps: np.ndarray, columns: dict) -> xr.Dataset:
    data = {}
    for name, (dtype, long_name, units, *comment) in VARIABLES.items():
        attrs = {"long_name": long_name, "units": units}
        if comment:
            attrs["comment"] = comment[0]
        data[name] = (("eps",), np.asarray(columns[name], dtype=dtype), attrs)
    return xr.Dataset(data, coords={"eps": ("eps", np.asarray(eps, dtype="f8"), dict(EPS_ATTRS))})


def _raw(eps: list[float], progress: bool = False, label: str = DATASET_ID) -> xr.Dataset:
    bar = Progress(label, len(eps), enabled=progress)
    rows = []
    for e in eps:
        rows.append(measure(e))
        bar.step(note=f"eps={e:g}")
    return _variables(np.asarray(eps, dtype="f8"),
                      {name: [row[name] for row in rows] for name in VARIABLES})


def _finish(raw: xr.Dataset, eps: list[float]) -> xr.Dataset:
    return finalize(annotate(raw, tolerances(eps)), _provenance(eps),
                    title="hard cases: eps sweep of the jump, slope, chatter period and "
                          "slide-in (filippov_paper.hard_cases)")


def sweep(eps_values, progress: bool = False) -> xr.Dataset:
    """Every measurement at every eps of ``eps_values`` (in that order): dimension ``eps``."""
    eps = _eps_list(eps_values)
    return _finish(_raw(eps, progress), eps)


def compute_part(config, i: int, progress: bool = False) -> xr.Dataset:
    """Chunk ``i`` (0-based) of the configured sweep: the measurements on its
    contiguous part of the eps list, with attributes that :func:`merge` checks."""
    cfg = check_config(config)
    eps, n = cfg["eps"], cfg["chunks"]
    start, stop = bounds(len(eps), i, n)
    raw = _raw(eps[start:stop], progress, label=f"{DATASET_ID} chunk {i + 1}/{n}")
    return finalize(raw, _provenance(eps), chunk_index=i, chunk_count=n, chunk_axis="eps",
                    chunk_start=start, chunk_stop=stop, grid_size=len(eps),
                    title=f"chunk {i + 1} of {n} of the hard-case sweep (see "
                          f"results/{DATASET_ID}.nc)")


def merge(parts, config=None) -> xr.Dataset:
    """The sweep's dataset from its chunks (in any order): identical to
    ``sweep(eps)`` for the whole configured list. With ``config`` (the
    ``hard_cases:`` block) the chunks must have been computed from it; without,
    from the configuration recorded in the chunks, which must all agree."""
    name = DATASET_ID
    parts = list(parts)
    if not parts:
        raise ValueError(f"{name}: no chunks to merge")
    for k, part in enumerate(parts):
        if part.attrs.get("scene_id") != name or "chunk_index" not in part.attrs:
            raise ValueError(f"{name}: input {k} is not a chunk of the hard-case sweep "
                             f"(scene_id {part.attrs.get('scene_id')!r}, "
                             f"title {part.attrs.get('title')!r})")
    if config is not None:
        cfg = check_config(config)
        eps, n = cfg["eps"], cfg["chunks"]
    else:
        recorded = json.loads(parts[0].attrs["scene_config"])
        eps, n = _eps_list(recorded.get("eps"), f"{name}.eps"), int(parts[0].attrs["chunk_count"])
    want = json.dumps(_provenance(eps), sort_keys=True)
    for part in parts:
        i = int(part.attrs["chunk_index"])
        if part.attrs.get("scene_config") != want:
            raise ValueError(f"{name}: chunk {i} was computed for a different configuration "
                             f"or code (eps grid or fixed settings differ); recompute it")
        if int(part.attrs.get("chunk_count", -1)) != n:
            raise ValueError(f"{name}: chunk {i} belongs to a split into "
                             f"{int(part.attrs.get('chunk_count', -1))} chunks, the "
                             f"configuration asks for {n}; recompute it")
    count = Counter(int(p.attrs["chunk_index"]) for p in parts)
    twice = sorted(i for i, c in count.items() if c > 1)
    if twice:
        raise ValueError(f"{name}: chunk {twice[0]} given {count[twice[0]]} times; need chunks "
                         f"0..{n - 1} exactly once")
    extra = sorted(i for i in count if not 0 <= i < n)
    if extra:
        raise ValueError(f"{name}: chunk index {extra[0]} out of range 0..{n - 1}")
    missing = [i for i in range(n) if i not in count]
    if missing:
        raise ValueError(f"{name}: chunk {', '.join(map(str, missing))} of 0..{n - 1} missing; "
                         f"need chunks 0..{n - 1} exactly once")
    parts = sorted(parts, key=lambda p: int(p.attrs["chunk_index"]))
    for part in parts:
        i = int(part.attrs["chunk_index"])
        start, stop = bounds(len(eps), i, n)
        got = np.asarray(part["eps"].values, dtype="f8") if "eps" in part.coords else None
        if got is None or not np.array_equal(got, np.asarray(eps[start:stop], dtype="f8")):
            raise ValueError(f"{name}: chunk {i} does not hold eps[{start}:{stop}] of the "
                             f"configured grid (got {None if got is None else got.tolist()})")
        lacking = sorted(set(VARIABLES) - set(part.data_vars))
        if lacking:
            raise ValueError(f"{name}: chunk {i} lacks {', '.join(lacking)}; recompute it")
    columns = {v: np.concatenate([np.asarray(p[v].values, dtype=VARIABLES[v][0]) for p in parts])
               for v in VARIABLES}
    merged = np.concatenate([p["eps"].values for p in parts])
    if not np.array_equal(merged, np.asarray(eps, dtype="f8")):
        raise ValueError(f"{name}: the chunks do not cover the configured eps grid")
    return _finish(_variables(merged, columns), eps)

# ============================================================================= report
# What the reproduction report quotes from the sweep's dataset (filippov_paper.report calls
# `report`). This part -- REPORT, report and the _report_* names -- is left out of the
# code hash of the sweep's jobs: editing it rebuilds the report only.
#: the files of paper/generated/ its tables go into, in the order report returns them
REPORT = {"tables": ["tab_hard_cases.tex", "tab_hard_return.tex"]}


def report(ds, m: Macros) -> tuple[str, str]:
    """Macros and the per-eps table of the hard-case sweep (results/hard_cases.nc):
    jump/eps (theta < 0), one-sided slope (theta > 0), chatter period, slide-in."""
    m.flag("rpHaveHardCases", ds is not None)
    if ds is None:
        return (not_yet("Hard-case eps sweep", f"results/{DATASET_ID}.nc"),
                not_yet("Sliding return sweep", f"results/{DATASET_ID}.nc"))
    sid = DATASET_ID
    eps = [float(e) for e in ds.eps.values]
    kmax, kmin = int(np.argmax(eps)), int(np.argmin(eps))
    m.add("rpHardN", len(eps), f"{sid}:eps (size)")
    m.add("rpHardNValues", None, f"{sid}:eps (size)", text=count_phrase(len(eps), "value"))
    m.add("rpHardEpsMax", eps[kmax], f"{sid}:eps[{kmax}]")
    m.add("rpHardEpsMin", eps[kmin], f"{sid}:eps[{kmin}]")
    for attr, name, sig in (("jump_theta", "JumpTheta", 3), ("jump_x2_offset", "JumpOffset", 3),
                            ("slope_theta", "SlopeTheta", 3), ("slope_probe_factor", "ProbeFactor", 3),
                            ("slope_probe_floor", "ProbeFloor", 3),
                            ("chatter_theta", "ChatterTheta", 3),
                            ("chatter_periods", "ChatterPeriods", 4),
                            ("slide_theta", "SlideTheta", 3),
                            ("slide_start_over_eps", "SlideStart", 3),
                            ("kernel_start", "KernelStart", 3)):
        m.add(f"rpHard{name}", float(ds.attrs[attr]), f"{sid}:attrs.{attr}", sig)
    var(m, "rpHardJumpFirst", ds, sid, "jump_over_eps", sig=5, eps=eps[kmax])
    var(m, "rpHardJumpLast", ds, sid, "jump_over_eps", sig=5, eps=eps[kmin])
    from filippov.analytic.s0 import s0_lambert
    mu, omega = float(ds.attrs["mu"]), float(ds.attrs["omega"])
    pred = float(s0_lambert(np.array([float(ds.attrs["jump_theta"])]))[0]) \
        * math.exp(-3 * math.pi * mu / omega)
    m.add("rpHardJumpPred", pred, "derived: s0(jump_theta) exp(-3 pi mu/omega)", 5)
    if len(eps) > 1:
        m.add("rpHardJumpDiffLast", abs(value(ds, "jump_over_eps", eps=eps[kmin])
                                        - value(ds, "jump_over_eps", eps=sorted(eps)[1])),
              "derived: |difference of jump_over_eps| between the two smallest eps", 2)
    m.add("rpHardSlopeMin", float(ds.slope.min()), "derived: min slope over eps", 3)
    m.add("rpHardSlopeMax", float(ds.slope.max()), "derived: max slope over eps", 3)
    var(m, "rpHardPeriodOverEps", ds, sid, "chatter_period_over_eps", sig=6, eps=eps[kmin])
    m.add("rpHardPeriodDev", float(ds.chatter_period_max_rel_dev.max()),
          "derived: max chatter_period_max_rel_dev over eps", 2)
    m.add("rpHardSlideOffset", float(np.abs(ds.slide_start_offset).max()),
          "derived: max |slide_start_offset| over eps", 2)
    m.add("rpHardSlideFinal", float(ds.slide_final_abs_x.max()),
          "derived: max slide_final_abs_x over eps", 2)
    m.add("rpHardKernelFinal", float(ds.kernel_final_abs_x.max()),
          "derived: max kernel_final_abs_x over eps", 2)
    maps = per_eps_rows(ds, lambda d: [
        f"${num(float(d.jump_over_eps), 6)}$", f"${num(float(d.slope), 4)}$",
        f"${num(float(d.slope_probe), 2)}$"])
    chatter = per_eps_rows(ds, lambda d: [
        f"${num(float(d.chatter_period_over_eps), 6)}$",
        f"${num(float(d.chatter_period_max_rel_dev), 2)}$",
        f"${num(float(d.slide_start_offset), 2)}$", f"${num(float(d.slide_final_abs_x), 2)}$",
        f"${num(float(d.kernel_final_abs_x), 2)}$"])
    # the return maps, then the pseudo-equilibrium (two tabulars: one would not fit)
    table = tabular("rrrr", [head(r"$\epsilon$", r"jump$/\epsilon$", "slope", "$x_2-1$")],
                     maps) + "\n\\medskip\n\n" + tabular("rrrrrr", [head(
                         r"$\epsilon$", r"period//$/\epsilon$", "period//dev.",
                         r"slide start//$+(1-\theta)\epsilon$", "final//$|x|$",
                         "final $|x|$,//kernel")], chatter)
    return table, _report_return(ds, m, eps)


def _report_return(ds, m: Macros, eps: list) -> str:
    """The theta > 0 sliding return per eps: 1 - P against eps^2, sliding time, cost."""
    sid = DATASET_ID
    m.add("rpHardReturnTheta", float(ds.attrs["return_theta"]), f"{sid}:attrs.return_theta", 3)
    m.add("rpHardReturnXtwo", float(ds.attrs["return_x2"]), f"{sid}:attrs.return_x2", 3)
    gap = np.abs(ds.return_P_reduced.values - ds.return_P.values)
    scaled = gap / ds.eps.values ** 2
    small = [k for k, e in enumerate(eps) if e <= 1e-3] or list(range(len(eps)))
    m.add("rpHardReturnScaledMin", float(scaled[small].min()),
          "derived: min |P_reduced - P|/eps^2 over eps <= 1e-3", 3)
    m.add("rpHardReturnScaledMax", float(scaled[small].max()),
          "derived: max |P_reduced - P|/eps^2 over eps <= 1e-3", 3)
    steps = ds.return_steps.values
    m.add("rpHardReturnStepsMin", int(steps.min()), "derived: min return_steps over eps")
    m.add("rpHardReturnStepsMax", int(steps.max()), "derived: max return_steps over eps")
    m.add("rpHardReturnStiffN", int(ds.return_stiff.values.sum()),
          "derived: eps values whose sliding was finished by Radau IIA")
    m.add("rpHardReturnStiffShare", None,
          "derived: eps values whose sliding was finished by Radau IIA, of all",
          text=share_phrase(ds.return_stiff.values.sum(), len(eps), r"$\epsilon$ value"))
    rows = per_eps_rows(ds.assign(gap=("eps", gap), scaled=("eps", scaled)), lambda d: [
        f"${num(float(d.gap), 3)}$", f"${num(float(d.scaled), 4)}$",
        f"${num(float(d.return_sliding_time), 5)}$", f"${int(d.return_steps)}$",
        "Radau IIA" if int(d.return_stiff) else "DOP853"])
    return tabular("rrrrrl", [
        r"$\epsilon$ & $|P_0-P|$ & $|P_0-P|/\epsilon^2$ & sliding time & steps & "
        r"sliding by \\"], rows)
