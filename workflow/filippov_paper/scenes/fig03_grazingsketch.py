"""fig:grazingsketch: the attracting periodic orbit of the reduced Hopf example
(eq:red) for mu < 1, mu = 1 (grazing at x_g) and mu > 1 (sliding from x_h to x_l).

Each orbit is computed by the solver: from a start point on the section
L1 = {x1 = 0, x2 > 0} the trajectory is followed one return to L1 at a time
until two consecutive returns agree to ``settle_tol``; the last period is then
sampled densely (the event times of that period are added to the uniform time
grid, so the corner at x_h lies on a sample).

Stored next to the orbits: x_g = (-1, 0) and the orbit's point on {x2 = 0, x1 < 0}
(root of x2 on the solver's dense output); x_h and x_l as the solver's
slide_start and slide_end events; x_l also from the tangency condition
dh0/dx f_+ = 0 on x1 = -1, i.e. x2^2 - omega x2 + 1 - mu = 0, the root of smaller
modulus x2 = 2 (1 - mu) / (omega + sqrt(omega^2 + 4 (mu - 1))) (negative for mu > 1,
zero at mu = 1).

At mu = 1 the orbit is the circle r = 1 and touches x1 = -1 at x_g only. In
floating point its radius is 1 to an ulp, so the solver may report a degenerate
slide there (length ~1e-8 in x2, ~1e-9 in time, around x_g): the answer for
mu = 1 + O(1e-16), present on one machine and absent on another. A period that
slides for less than ``DEGENERATE_SLIDE`` in time is therefore the grazing
orbit: x_h and x_l are NaN and its events are not put on the sample grid (so the
samples of every machine lie at the same times); ``sliding_time`` keeps what
the solver measured.
"""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr
from scipy.optimize import brentq

from filippov import simulate
from filippov.io import finalize
from filippov.progress import Progress
from filippov.simulate import Section
from filippov_paper.tolerance import Tolerance
from filippov_paper.scenes.common import registered_model, require, solver_options
import math
from filippov_paper.report import Macros, source, value, var


class HopfFamily(Protocol):
    """What this scene uses of its model (``model:``): the model at (eps, theta, mu, omega),
    whose reduced system it follows."""
    def model(self, eps, theta, mu, omega): ...


MODEL = HopfFamily

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "description": "Reduced system: eps and theta do not enter (h0 = x1 + 1).",
      "required": ["omega", "mu", "x2_start", "settle_tol", "max_periods", "n_samples"],
      "additionalProperties": False,
      "properties": {
        "omega": True,
        "mu": {"type": "array", "minItems": 1},
        "x2_start": {"$ref": "#/$defs/positive"},
        "settle_tol": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1e-06},
        "max_periods": {"type": "integer", "minimum": 2},
        "n_samples": {"$ref": "#/$defs/n_samples"}
      }
    }
  }
}

COMPONENTS = ["x1", "x2"]
VARIABLE_ATTRS = {"component": ("state component", None),
                  "sample": ("sample index along one period", "1")}
#: a slide shorter than this (in time) is the grazing contact at mu = 1 + O(1e-16):
#: its length is ~sqrt(1e-16) = 1e-8, while the slides of mu >= 1 + 1e-10 last
#: longer than 1e-6 (length ~ sqrt(mu - 1))
DEGENERATE_SLIDE = 1e-6

#: cross-machine tolerances (filippov_paper.tolerance): the grazing orbit at mu = 1 opens
#: or closes a ~1e-9-long slide with the last bit of its radius (square-root law)
_GRAZING = "mu = 1 grazes: a last-bit change of the radius opens or closes a slide of " \
           "~sqrt(u) = 1e-8 in x2 and ~1e-9 in time (measured <= 4e-10)"
TOLERANCES = {
    "t": Tolerance(1e-9, 1e-8, _GRAZING + "; samples are uniform over the period"),
    "period": Tolerance(1e-9, 1e-8, _GRAZING),
    "sliding_time": Tolerance(1e-9, 1e-8, _GRAZING),
    "x1": Tolerance(1e-9, 1e-6, _GRAZING + "; a sample time moved by 1e-8 moves x by |f| = 25 "
                                          "times that"),
    "x2": Tolerance(1e-9, 1e-6, _GRAZING + "; a sample time moved by 1e-8 moves x by |f| = 25 "
                                          "times that"),
    "mode": Tolerance(0.0, 0.0, _GRAZING + "; the sample at a quarter period lies on x_g "
                                           "itself, inside or beside that slide",
                      rule="tangency", changed=1, jump=1),
}


def section_L1() -> Section:
    # x1 decreasing: the flow turns counter-clockwise for omega > 0
    return Section("L1", lambda z: z[0], direction=-1, where=lambda z: z[1] > 0, terminal=1)


def x_l_tangency(mu: float, omega: float) -> float:
    """x2 of the point on x1 = -1 where f_+ is tangent to it, near the origin:
    -mu - omega x2 + (1 + x2^2) = 0, the root of smaller modulus (no cancellation)."""
    return 2.0 * (1.0 - mu) / (omega + np.sign(omega) * np.sqrt(omega ** 2 + 4.0 * (mu - 1.0)))


def settle(system, x2_start: float, tol: float, max_periods: int, opts: dict):
    """Returns to L1 one at a time until consecutive x2 agree to ``tol``; the last run
    (one full period from L1 to L1) is returned with the list of return values."""
    returns = [float(x2_start)]
    z = np.array([0.0, x2_start])
    for _ in range(max_periods):
        traj = simulate(system, z, t_end=1e3, sections=[section_L1()], **opts)
        if not traj.status.startswith("section:L1"):
            raise RuntimeError(f"no return to L1 from x2={z[1]!r} (status {traj.status})")
        z = traj.z.copy()
        z[0] = 0.0  # the hit is at |x1| ~ 1e-14; restart exactly on L1
        returns.append(float(z[1]))
        if len(returns) > 2 and abs(returns[-1] - returns[-2]) <= tol:
            return traj, np.array(returns)
    raise RuntimeError(f"orbit not settled to {tol} after {max_periods} periods "
                       f"(last change {abs(returns[-1] - returns[-2]):.3e})")


def one_period(traj, n: int, grazing: bool = False):
    """n samples of the whole run (one period), uniform in time plus the interior events
    (without the degenerate slide of a grazing orbit)."""
    kinds = ("crossing",) if grazing else ("slide_start", "slide_end", "crossing")
    inner = np.array([e.t for e in traj.events if traj.t0 < e.t < traj.t and e.kind in kinds])
    m = n - inner.size
    while True:
        times = np.union1d(np.linspace(traj.t0, traj.t, m), inner)
        if times.size >= n:
            break
        m += 1
    t, z, mode = traj.sample(times[:n], include_events=False)
    return t - traj.t0, z, mode


def left_crossing(traj, t, z) -> np.ndarray:
    """Point of the orbit on {x2 = 0, x1 < 0}, by Brent's method on the dense output
    (at mu = 1 this is where it grazes x1 = -1: the solver's x_g)."""
    x2 = lambda tt: float(traj.sample([tt], include_events=False)[1][1, 0])
    i = np.flatnonzero((z[1, :-1] > 0) & (z[1, 1:] <= 0) & (z[0, :-1] < 0))
    if i.size != 1:
        return np.array([np.nan, np.nan])
    ta, tb = t[i[0]], t[i[0] + 1]
    tr = tb if z[1, i[0] + 1] == 0 else brentq(x2, ta, tb, xtol=1e-16, rtol=4 * np.finfo(float).eps)
    return traj.sample([tr], include_events=False)[1][:, 0]


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    require(scene, "system", {"reduced"})
    if not scene["ingredients"]["sliding"]:
        raise ValueError(f"{scene['id']}: ingredients.sliding must be true: panel (c) slides")
    p = scene["parameters"]
    opts = solver_options(scene)
    omega = float(p["omega"])
    mus = [float(m) for m in p["mu"]]
    n = int(p["n_samples"])
    nan2 = [np.nan, np.nan]
    out = {k: [] for k in ("t", "x1", "x2", "mode", "period", "fixed_x2", "settle", "n_periods",
                           "x_h", "x_l", "x_l_formula", "left", "sliding_time")}
    bar = Progress(scene["id"], len(mus), progress)
    hopf = registered_model(scene)   # the reduced Hopf example, from the registry
    for mu in mus:
        # theta and eps do not enter the reduced system: h0 = x1 + 1 for every theta
        system = hopf.model(0.0, 0.0, mu, omega).reduced(sliding=True, exact=opts["method"] == "exact")
        traj, returns = settle(system, float(p["x2_start"]), float(p["settle_tol"]),
                               int(p["max_periods"]), opts)
        starts = [e.t for e in traj.events if e.kind == "slide_start"]
        ends = [e.t for e in traj.events if e.kind == "slide_end"]
        slid = sum(b - a for a, b in zip(starts, ends))
        grazing = slid < DEGENERATE_SLIDE
        t, z, mode = one_period(traj, n, grazing)
        ev = {} if grazing else \
            {e.kind: e.state.copy() for e in traj.events if traj.t0 < e.t < traj.t}
        out["t"].append(t), out["x1"].append(z[0]), out["x2"].append(z[1])
        out["mode"].append(mode)
        out["period"].append(traj.t - traj.t0)
        out["fixed_x2"].append(returns[-1])
        out["settle"].append(abs(returns[-1] - returns[-2]))
        out["n_periods"].append(returns.size - 1)
        out["x_h"].append(ev.get("slide_start", nan2))
        out["x_l"].append(ev.get("slide_end", nan2))
        out["sliding_time"].append(slid)
        out["x_l_formula"].append([-1.0, x_l_tangency(mu, omega)] if mu >= 1 else nan2)
        out["left"].append(left_crossing(traj, t + traj.t0, z))
        bar.step(note=f"mu={mu}")

    dims, vec = ("mu", "sample"), ("mu", "component")
    pts = {k: np.array(out[k], dtype=float) for k in ("x_h", "x_l", "x_l_formula", "left")}
    ds = xr.Dataset(
        {"t": (dims, np.array(out["t"]), {"long_name": "time since the orbit left L1", "units": "1"}),
         "x1": (dims, np.array(out["x1"]), {"long_name": "x1 on the periodic orbit", "units": "1"}),
         "x2": (dims, np.array(out["x2"]), {"long_name": "x2 on the periodic orbit", "units": "1"}),
         "mode": (dims, np.array(out["mode"], dtype=np.int8),
                  {"long_name": "field followed", "units": "1",
                   "flag_values": np.array([-1, 0, 1], dtype=np.int8),
                   "flag_meanings": "minus sliding plus"}),
         "period": ("mu", np.array(out["period"]), {"long_name": "period of the orbit", "units": "1"}),
         "fixed_x2": ("mu", np.array(out["fixed_x2"]),
                      {"long_name": "x2 where the orbit crosses L1 (fixed point of M_mu)", "units": "1"}),
         "settle_error": ("mu", np.array(out["settle"]),
                          {"long_name": "|change of the L1 return value| over the last period",
                           "units": "1"}),
         "n_periods": ("mu", np.array(out["n_periods"], dtype=np.int32),
                       {"long_name": "periods followed from x2_start until settled", "units": "1"}),
         "sliding_time": ("mu", np.array(out["sliding_time"]),
                          {"long_name": "time spent sliding per period", "units": "1"}),
         "x_h": (vec, pts["x_h"], {"long_name": "start of sliding x_h (solver event slide_start; "
                                                "NaN: no sliding, or a degenerate slide "
                                                "shorter than degenerate_slide)", "units": "1"}),
         "x_l": (vec, pts["x_l"], {"long_name": "end of sliding x_l (solver event slide_end; "
                                                "NaN: no sliding, or a degenerate slide "
                                                "shorter than degenerate_slide)", "units": "1"}),
         "x_l_formula": (vec, pts["x_l_formula"], {
             "long_name": "x_l from the tangency dh0/dx f_+ = 0 on x1 = -1 (NaN: mu < 1)",
             "units": "1"}),
         "x_left": (vec, pts["left"], {
             "long_name": "orbit point on {x2 = 0, x1 < 0} (solver section); x_g at mu = 1",
             "units": "1"}),
         "x_g": ("component", np.array([-1.0, 0.0]),
                 {"long_name": "grazing point x_g of the orbit at mu = 1", "units": "1"})},
        coords={"mu": ("mu", mus, {"long_name": "mu", "units": "1"}),
                "component": ("component", COMPONENTS),
                "sample": ("sample", np.arange(n), {"long_name": "sample index along one period"})})
    return finalize(ds, scene, method=opts["method"], switching_line="x1 = -1",
                    degenerate_slide=DEGENERATE_SLIDE,
                    section_L1="x1 = 0, x2 > 0",
                    title="grazing-sliding of the reduced Hopf example Eq. (11) (Fig. 3)")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig03_grazingsketch"
    mus = [float(v) for v in ds.mu.values]
    m.add("rpThreeOmega", float(ds.attrs["omega"]), f"{sid}:attrs.omega", 6)
    m.add("rpThreeStart", float(ds.attrs["x2_start"]), f"{sid}:attrs.x2_start")
    m.add("rpThreeSettle", float(ds.attrs["settle_tol"]), f"{sid}:attrs.settle_tol")
    for mu, word in zip(mus, ("Below", "At", "Above")):
        m.add(f"rpThreeMu{word}", mu, source(sid, "mu", mu=mu))
        var(m, f"rpThreeFixed{word}", ds, sid, "fixed_x2", sig=6, mu=mu)
        var(m, f"rpThreePeriod{word}", ds, sid, "period", sig=6, mu=mu)
        var(m, f"rpThreeSlideTime{word}", ds, sid, "sliding_time", sig=3, mu=mu)
    mu = mus[2]
    var(m, "rpThreeXhTwo", ds, sid, "x_h", sig=4, mu=mu, component="x2")
    var(m, "rpThreeXlTwo", ds, sid, "x_l", sig=6, mu=mu, component="x2")
    var(m, "rpThreeXlFormulaTwo", ds, sid, "x_l_formula", sig=6, mu=mu, component="x2")
    m.add("rpThreeXlErr", abs(value(ds, "x_l", mu=mu, component="x2")
                              - value(ds, "x_l_formula", mu=mu, component="x2")),
          "derived: |x_l - x_l_formula| at mu above 1", 2)
    m.add("rpThreeSqrtMuBelow", math.sqrt(mus[0]), "derived: sqrt(mu below 1)", 6)
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "omega"
