"""fig:cases: the pseudo-equilibrium example for theta > 0 (sliding) and theta < 0 (chatter)."""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr

from filippov import simulate
from filippov.analytic import chatter
from filippov.io import finalize
from filippov.progress import Progress
from filippov.sliding import attracting_intervals
from filippov.system import PLUS
from filippov_paper.scenes.common import registered_model, require, solver_options
import math
from filippov_paper.report import Macros, value, var


class SlowFastFamily(Protocol):
    """What this scene uses of its model (``model:``): the slow-fast model at (eps, theta)."""
    def model(self, eps, theta): ...


MODEL = SlowFastFamily

#: names and units of the variables without them below (checked by filippov_paper.scenes)
VARIABLE_ATTRS = {
    "mode": ("field followed: -1 region -, 0 sliding, 1 region +", "1"),
    "x_cycle": ("x along one period of the chatter orbit (solver)", "1"),
    "y_cycle": ("y along one period of the chatter orbit (solver)", "1"),
    "t_cycle": ("time along one period of the chatter orbit, from a switch to +", "1"),
    "theta": ("theta, weight of the fast variable in the switching function", "1"),
    "t": ("time", "1"),
}

SETTLE_PERIODS = 40  # the orbit contracts by ~0.03 a period (theta=-0.5): ample


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    kind = require(scene, "system", {"slow_fast"})
    scene_model = registered_model(scene)
    p = scene["parameters"]
    eps, thetas = float(p["eps"]), [float(v) for v in p["theta"]]
    if sorted(np.sign(thetas)) != [-1.0, 1.0] or len(thetas) != 2:
        raise ValueError(f"{scene['id']}: parameters.theta needs one value > 0 and one < 0")
    opts = solver_options(scene)
    t = np.linspace(0.0, p["t_end"], p["n_samples"])
    bar = Progress(scene["id"], len(thetas), progress)
    tracks, scalars, extra = {}, {}, {}
    for theta in thetas:
        model = scene_model.model(eps, theta)
        system = model.system(kind, sliding=scene["ingredients"]["sliding"],
                              exact=opts["method"] == "exact")
        traj = simulate(system, p["start"], p["t_end"], **opts)
        _, z, mode = traj.sample(t, include_events=False)
        tracks[theta] = (z[0], z[1], mode)
        if theta > 0:
            # the solver's own sliding decision along H_s = {y = -theta x / (1 - theta)}
            line = lambda s: np.stack([s, -theta / (1 - theta) * s])
            ivals = attracting_intervals(system, line, np.linspace(-5 * eps, 5 * eps, 201))
            (lo, hi), = ivals
            scalars["sliding_x_min"], scalars["sliding_x_max"] = lo, hi
            start = next(e for e in traj.events if e.kind == "slide_start")
            scalars["slide_start_x"], scalars["slide_start_y"] = start.state
            scalars["x_final"] = traj.z[0]
        else:
            scalars.update(_chatter(system, traj, opts, eps, theta, extra))
        bar.step(note=f"theta={theta}")
    order = sorted(thetas, reverse=True)
    stack = lambda i: np.array([tracks[th][i] for th in order])
    ds = xr.Dataset(
        {"x": (("theta", "t"), stack(0), {"long_name": "slow variable x", "units": "1"}),
         "y": (("theta", "t"), stack(1), {"long_name": "fast variable y", "units": "1"}),
         "mode": (("theta", "t"), stack(2).astype(np.int8),
                  {"flag_values": np.array([-1, 0, 1], dtype=np.int8),
                   "flag_meanings": "minus sliding plus"}),
         "x_cycle": ("cycle", extra["x_cycle"]), "y_cycle": ("cycle", extra["y_cycle"]),
         "t_cycle": ("cycle", extra["t_cycle"])},
        coords={"theta": ("theta", order, {"units": "1"}), "t": ("t", t, {"units": "1"})})
    theta_neg = min(thetas)
    descr = {
        "period": "full period of the chatter orbit (solver)",
        "x_switch": "x at the switch from f_- to f_+ on the chatter orbit (solver)",
        "y_switch": "y at the switch from f_- to f_+ on the chatter orbit (solver)",
        "period_formula": "2 eps T from the corrected parametrisation (analytic.chatter)",
        "x_switch_formula": "eps T / 2", "y_switch_formula": "eps (T/2 - tanh(T/2))",
        "y_switch_printed": "paper's printed y_switch = eps theta (e^-T - 1)/(e^-T + 1)",
        "theta_printed": "paper's printed theta(T) evaluated at the solver's T",
        "sliding_x_min": "left end of the attracting sliding segment on H_s (solver)",
        "sliding_x_max": "right end of the attracting sliding segment on H_s (solver)",
        "slide_start_x": "x where the theta > 0 trajectory starts sliding",
        "slide_start_y": "y where the theta > 0 trajectory starts sliding",
        "x_final": "x at t_end for theta > 0 (pseudo-equilibrium at 0)",
        "T_half": "solver's half period divided by eps",
    }
    for name, val in scalars.items():
        ds[name] = ((), float(val), {"long_name": descr.get(name, name), "units": "1",
                                     "eps": eps, "theta": theta_neg if name not in (
                                         "sliding_x_min", "sliding_x_max", "slide_start_x",
                                         "slide_start_y", "x_final") else max(thetas)})
    return finalize(ds, scene, eps=eps, theta=theta_neg, theta_sliding=max(thetas),
                    title="pseudo-equilibrium example Eq. (7)/Eq. (8)")


def _chatter(system, traj, opts, eps, theta, extra):
    """Settle onto the chatter orbit, then measure period and switch point.

    The measuring run restarts the clock at the switch point, so the period is
    not a difference of two large event times (which would cost digits).
    """
    ups = [e for e in traj.switches() if e.mode_after == PLUS]
    if len(ups) < 2:
        raise RuntimeError("chatter orbit not reached: fewer than 2 switches on the transient")
    guess = ups[-1].t - ups[-2].t
    settle = simulate(system, ups[-1].state, SETTLE_PERIODS * guess, dense=False, **opts)
    last = [e for e in settle.switches() if e.mode_after == PLUS][-1]
    one = simulate(system, last.state, 1.5 * guess, **opts)
    period = next(e.t for e in one.switches() if e.mode_after == PLUS)
    tc, zc, _ = one.sample(np.linspace(0.0, period, 401))
    keep = tc <= period
    extra.update(x_cycle=zc[0][keep], y_cycle=zc[1][keep], t_cycle=tc[keep])
    formula = chatter.orbit(eps, theta)
    T = period / (2 * eps)
    return {"period": period, "x_switch": last.state[0], "y_switch": last.state[1],
            "period_formula": formula["period"], "x_switch_formula": formula["x_switch"],
            "y_switch_formula": formula["y_switch"], "y_switch_printed": formula["y_switch_printed"],
            "theta_printed": float(chatter.theta_of_T_as_printed(T)), "T_half": T}


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig02_cases"
    eps, th_slide = float(ds.attrs["eps"]), float(ds.attrs["theta_sliding"])
    m.add("rpTwoEps", eps, f"{sid}:attrs.eps")
    m.add("rpTwoThetaSlide", th_slide, f"{sid}:attrs.theta_sliding")
    m.add("rpTwoThetaChatter", float(ds.attrs["theta"]), f"{sid}:attrs.theta")
    m.add("rpTwoEpsTheta", eps * th_slide, "derived: eps*theta_sliding")
    start = [float(v) for v in np.atleast_1d(ds.attrs["start"])]
    m.add("rpTwoStartX", start[0], "fig02_cases:attrs.start[0]")
    m.add("rpTwoStartY", start[1], "fig02_cases:attrs.start[1]")
    var(m, "rpTwoSlideMin", ds, sid, "sliding_x_min", sig=6)
    var(m, "rpTwoSlideMax", ds, sid, "sliding_x_max", sig=6)
    m.add("rpTwoSlideErr", max(abs(value(ds, "sliding_x_min") + eps * th_slide),
                               abs(value(ds, "sliding_x_max") - eps * th_slide)),
          "derived: max |sliding_x_min + eps theta|, |sliding_x_max - eps theta|", 2)
    var(m, "rpTwoXFinal", ds, sid, "x_final", sig=2)
    for name_var, name in (("period", "Period"), ("x_switch", "XSwitch"), ("y_switch", "YSwitch"),
                      ("period_formula", "PeriodFormula"), ("T_half", "THalf"),
                      ("y_switch_printed", "YSwitchPrinted"), ("theta_printed", "ThetaPrinted")):
        var(m, f"rpTwo{name}", ds, sid, name_var, sig=6 if name_var != "theta_printed" else 4)
    m.add("rpTwoPeriodOverEps", value(ds, "period") / eps, "derived: period/eps")
    m.add("rpTwoPeriodErr", abs(value(ds, "period") - value(ds, "period_formula")),
          "derived: |period - period_formula|", 2)
    m.add("rpTwoYSwitchErr", abs(value(ds, "y_switch") - value(ds, "y_switch_printed")),
          "derived: |y_switch - y_switch_printed|", 2)
    T = value(ds, "T_half")
    m.add("rpTwoMinusThetaTanh", -float(ds.attrs["theta"]) * math.tanh(T / 2),
          "derived: -theta tanh(T_half/2)", 4)
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "eps"
