"""fig:thetalt0mfs: the invariant manifolds near the grazing point p_g = (-1, 0, -1)
of the slow-fast Hopf example (eq:exslow2, eq:exfast2) for theta < 0, mu = 1.

What is computed, and how:

* the grazing periodic orbit: the solver run from (0, 1, 0) on L1 for one
  period; it lies in M_+ = {y = x1} (eq:ymp) and only touches H_s at p_g;
* M_-, the slow manifold of the region-minus flow E_-, computed numerically
  without the closed form: trajectories of E_- (x1' = 1, x2' = 0,
  eps y' = g(x, y)) are integrated with DOP853 for ``settle`` * eps time units
  into each grid point, from y = x1 (on M_+). Off-manifold parts decay like
  exp(-t/eps), so what arrives is M_- to ~exp(-settle). The result is stored
  next to the exact cubic (the model's slow_manifold_minus), the O(eps) expansion
  eq:ymm and the differences, plus the invariance residual of the exact cubic;
* one switching trajectory from L1 slightly outside the grazing orbit, run by
  the solver with the exact flows until it returns to L1: it crosses H_s into
  region - (E_+ -> E_-), crosses back (E_- -> E_+) and relaxes onto M_+; the
  rate of that relaxation is measured from the samples.
"""
from __future__ import annotations

from typing import Protocol

import numpy as np
import xarray as xr
from scipy.integrate import solve_ivp

from filippov import models, simulate
from filippov.io import finalize
from filippov.simulate import Section
from filippov.system import MINUS, PLUS
from filippov_paper.scenes.common import registered_model, require, solver_options
from filippov_paper.report import Macros, var


class HopfManifolds(Protocol):
    """What this scene uses of its model (``model:``): the model at (eps, theta, mu,
    omega), the exact slow manifold M_- and its O(eps) expansion, the fast field g, H_s
    solved for y and the gap between M_+ and M_- at the grazing point, each derived from
    the model's definition."""
    def model(self, eps, theta, mu, omega): ...
    def slow_manifold_minus(self, x1, x2, eps, mu, omega): ...
    def slow_manifold_minus_first_order(self, x1, x2, eps, mu, omega): ...
    def fast_field(self, x1, x2, y, eps, mu, omega): ...
    def switching_surface_y(self, x1, theta): ...
    def grazing_gap(self, eps): ...


MODEL = HopfManifolds

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "required": ["eps", "mu", "omega", "theta", "start_x2", "x1_range", "x2_range",
                   "n_grid", "settle", "rate_window", "n_samples"],
      "additionalProperties": False,
      "properties": {
        "eps": {"$ref": "#/$defs/positive"},
        "mu": {"const": 1.0},
        "omega": True,
        "theta": {"type": "number", "exclusiveMaximum": 0},
        "start_x2": {"type": "number", "exclusiveMinimum": 1},
        "x1_range": {"$ref": "#/$defs/point2"},
        "x2_range": {"$ref": "#/$defs/point2"},
        "n_grid": {"type": "integer", "minimum": 2},
        "settle": {"type": "number", "minimum": 10},
        "rate_window": {"$ref": "#/$defs/positive"},
        "n_samples": {"$ref": "#/$defs/n_samples"}
      }
    }
  }
}

#: names and units of the variables without them below (checked by filippov_paper.scenes)
VARIABLE_ATTRS = {
    "mode": ("field followed: -1 region -, 0 sliding, 1 region +", "1"),
    "switch_from": ("mode before the switch: -1 region -, 0 sliding, 1 region +", "1"),
    "switch_to": ("mode after the switch: -1 region -, 0 sliding, 1 region +", "1"),
    "switch": ("switch index along the switching trajectory", "1"),
}

P_G = np.array([-1.0, 0.0, -1.0])  # grazing point at mu = 1


def section_L1() -> Section:
    return Section("L1", lambda z: z[0], direction=-1, where=lambda z: z[1] > 0, terminal=1)


def numeric_slow_manifold_minus(model, x1, x2, settle: float = 40.0,
                                rtol: float = 1e-12, atol: float = 1e-14):
    """M_- at the points (x1, x2) from integrated E_- trajectories (no closed form).

    Each trajectory starts ``settle * eps`` time units upstream, at
    (x1 - settle eps, x2, y = x1 - settle eps), i.e. on M_+, and is integrated
    with the model's own f_- and g_- fields. Returns (y, t, dev) with ``dev``
    the largest distance to the final surface along the way, sampled at ``t``
    (for showing the convergence; it is measured against the exact cubic of the model's
    module, ``slow_manifold_minus``).
    """
    eps = model.eps
    x1 = np.asarray(x1, dtype=float)
    x2 = np.asarray(x2, dtype=float)
    shape = x1.shape
    a1, a2 = x1.ravel(), x2.ravel()
    T = settle * eps
    mu, omega = model.parameters["mu"], model.parameters["omega"]

    def rhs(s, y):
        x = np.stack([a1 - T + s, a2])
        # slow part of E_- is f_- (x1' = 1, x2' = 0): checked, not assumed
        return model.g_minus(x, y[None])[0] / eps

    f = model.f_minus(np.stack([a1, a2]), a1[None])
    if not (np.all(f[0] == 1.0) and np.all(f[1] == 0.0)):
        raise ValueError("numeric_slow_manifold_minus expects f_- = (1, 0)")
    t_eval = np.linspace(0.0, T, 41)
    sol = solve_ivp(rhs, (0.0, T), a1 - T, method="DOP853", rtol=rtol, atol=atol,
                    t_eval=t_eval)
    if not sol.success:
        raise RuntimeError(f"E_- integration failed: {sol.message}")
    xs = a1[:, None] - T + sol.t[None, :]
    exact = models.get(model.name).slow_manifold_minus(xs, a2[:, None], eps, mu, omega)
    dev = np.max(np.abs(sol.y - exact), axis=0)
    return sol.y[:, -1].reshape(shape), sol.t - T, dev


def invariance_residual(family, x1, x2, eps, mu, omega, step: float = 1e-20):
    """eps * D y_m- . f_- - g_-(x, y_m-) for the exact cubic of the model module
    ``family``, by complex-step differentiation along f_- = (1, 0): zero on an
    invariant graph."""
    d = family.slow_manifold_minus(x1 + 1j * step, x2, eps, mu, omega).imag / step
    y = family.slow_manifold_minus(x1, x2, eps, mu, omega)
    return eps * d - family.fast_field(x1, x2, y, eps, mu, omega)


def relaxation_rate(t, z, t_from: float, t_to: float, floor: float = 1e-9):
    """Least-squares rate lambda of |y - x1| ~ exp(-lambda t) on [t_from, t_to]."""
    dev = np.abs(z[2] - z[0])
    sel = (t > t_from) & (t <= t_to) & (dev > floor)
    if sel.sum() < 3:
        raise RuntimeError("too few samples to measure the relaxation rate")
    slope = np.polyfit(t[sel] - t_from, np.log(dev[sel]), 1)[0]
    return -slope


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    model, system, opts = _model_and_system(scene)
    p = scene["parameters"]
    n, omega, eps = int(p["n_samples"]), float(p["omega"]), float(p["eps"])
    t_orb, z_orb, touches = grazing_orbit(system, omega, n, opts)
    traj, sw = switching_trajectory(system, omega, float(p["start_x2"]), opts, scene["id"])
    t, z, mode = traj.sample(np.linspace(0.0, traj.t, n))
    rate = relaxation_after_return(traj, sw, float(p["rate_window"]) * eps)
    family = registered_model(scene)
    s = surfaces(family, model, p, opts)
    ds = xr.Dataset(
        # one dict in the dataset's variable order: trajectories, surfaces, numbers
        {**_trajectory_vars(z, mode, z_orb, sw), **_surface_vars(s),
         **_number_vars(family, eps, rate, s, touches, z_orb)},
        coords={
            "t": ("t", t, {"long_name": "time", "units": "1"}),
            "t_orbit": ("t_orbit", t_orb, {"long_name": "time on the grazing orbit",
                                           "units": "1"}),
            "switch": ("switch", np.arange(len(sw))),
            "x1_grid": ("x1_grid", s["g1"], {"long_name": "x1", "units": "1"}),
            "x2_grid": ("x2_grid", s["g2"], {"long_name": "x2", "units": "1"}),
            "t_settle": ("t_settle", s["t_conv"], {"long_name": "time before reaching the grid",
                                                   "units": "1"}),
        })
    return finalize(ds, scene, title="manifolds near the grazing point, theta < 0 "
                    "(Eq. (15)/Eq. (16))", p_g=P_G.tolist(),
                    t_return=float(traj.t), x2_return=float(traj.z[1]))


def _model_and_system(scene: dict):
    """The scene's Hopf model, its system and the solver options; theta < 0 and mu = 1
    are required (case 2, grazing at p_g)."""
    kind = require(scene, "system", {"slow_fast"})
    p = scene["parameters"]
    opts = solver_options(scene)
    eps, theta = float(p["eps"]), float(p["theta"])
    mu, omega = float(p["mu"]), float(p["omega"])
    if not theta < 0:
        raise ValueError(f"{scene['id']}: parameters.theta must be < 0 (case 2), got {theta}")
    if mu != 1.0:
        raise ValueError(f"{scene['id']}: parameters.mu must be 1 (grazing at p_g), got {mu}")
    model = registered_model(scene).model(eps, theta, mu, omega)
    system = model.system(kind, sliding=scene["ingredients"]["sliding"],
                          exact=opts["method"] == "exact")
    return model, system, opts


def grazing_orbit(system, omega: float, n: int, opts: dict):
    """The grazing periodic orbit from the solver, one period from L1 (it may only
    touch H_s): ``n`` sample times, the states there and the touch events."""
    orbit = simulate(system, [0.0, 1.0, 0.0], 2.0 * 2 * np.pi / abs(omega),
                     sections=[section_L1()], **opts)
    if orbit.switches():
        raise RuntimeError("the grazing orbit switched: it should only touch H_s")
    touches = [e for e in orbit.events if e.kind == "touch"]
    t_orb, z_orb, _ = orbit.sample(np.linspace(0.0, orbit.t, n), include_events=False)
    return t_orb, z_orb, touches


def switching_trajectory(system, omega: float, start_x2: float, opts: dict, scene_id: str):
    """The run from (0, start_x2, 0) on L1 back to L1 and its switches, which must be
    two crossings E+ -> E- -> E+."""
    traj = simulate(system, [0.0, start_x2, 0.0], 4.0 * 2 * np.pi / abs(omega),
                    sections=[section_L1()], **opts)
    sw = traj.switches()
    if any(e.kind != "crossing" for e in sw):
        raise RuntimeError(f"{scene_id}: expected crossings only, got "
                           f"{[e.kind for e in sw]}")
    if [(e.mode_before, e.mode_after) for e in sw] != [(PLUS, MINUS), (MINUS, PLUS)]:
        raise RuntimeError(f"{scene_id}: expected E+ -> E- -> E+, got "
                           f"{[(e.mode_before, e.mode_after) for e in sw]}")
    return traj, sw


def relaxation_after_return(traj, sw, span: float) -> float:
    """The rate of the relaxation onto M_+ over ``span`` after the crossing back into
    region + (the second switch)."""
    t_back = sw[1].t
    t_fit = np.linspace(t_back, min(t_back + span, traj.t), 401)
    tf, zf, mf = traj.sample(t_fit, include_events=False)
    if np.any(mf[1:] != PLUS):  # the sample at t_back itself closes the E_- segment
        raise RuntimeError("relaxation window left region +")
    return relaxation_rate(tf, zf, t_back, tf[-1])


def surfaces(family, model, p: dict, opts: dict) -> dict:
    """M_- (numerical, exact, expanded), M_+'s gap to it at p_g, H_s and the invariance
    residual on the zoom window's grid (``family``: the model module, ``model``: its
    slow-fast model at the scene's parameters)."""
    eps, theta = float(p["eps"]), float(p["theta"])
    mu, omega = float(p["mu"]), float(p["omega"])
    g1 = np.linspace(*map(float, p["x1_range"]), int(p["n_grid"]))
    g2 = np.linspace(*map(float, p["x2_range"]), int(p["n_grid"]))
    X1, X2 = np.meshgrid(g1, g2, indexing="ij")
    settle = float(p["settle"])
    tol = {k: opts[k] for k in ("rtol", "atol")}
    y_num, t_conv, dev_conv = numeric_slow_manifold_minus(model, X1, X2, settle, **tol)
    y_exact = family.slow_manifold_minus(X1, X2, eps, mu, omega)
    y_exp = family.slow_manifold_minus_first_order(X1, X2, eps, mu, omega)
    y_hs = family.switching_surface_y(X1, theta)
    resid = invariance_residual(family, X1, X2, eps, mu, omega)
    y_pg_num, _, _ = numeric_slow_manifold_minus(model, P_G[:1], P_G[1:2], settle, **tol)
    gap_pg = float(P_G[0] - y_pg_num[0])  # y_m+ - y_m- at x = (-1, 0)
    return dict(g1=g1, g2=g2, X1=X1, settle=settle, y_num=y_num, t_conv=t_conv,
                dev_conv=dev_conv, y_exact=y_exact, y_exp=y_exp, y_hs=y_hs, resid=resid,
                gap_pg=gap_pg)


def _trajectory_vars(z, mode, z_orb, sw) -> dict:
    """The switching trajectory, the grazing orbit and the switches."""
    ev = lambda k: np.array([e.state[k] for e in sw])
    return {
        "x1": ("t", z[0], {"long_name": "switching trajectory x1", "units": "1"}),
        "x2": ("t", z[1], {"long_name": "switching trajectory x2", "units": "1"}),
        "y": ("t", z[2], {"long_name": "switching trajectory y (fast)", "units": "1"}),
        "mode": ("t", mode.astype(np.int8),
                 {"long_name": "flow followed", "flag_values": np.array([-1, 0, 1], np.int8),
                  "flag_meanings": "minus sliding plus"}),
        "orbit_x1": ("t_orbit", z_orb[0], {"long_name": "grazing periodic orbit x1",
                                           "units": "1"}),
        "orbit_x2": ("t_orbit", z_orb[1], {"long_name": "grazing periodic orbit x2",
                                           "units": "1"}),
        "orbit_y": ("t_orbit", z_orb[2], {"long_name": "grazing periodic orbit y",
                                          "units": "1"}),
        "switch_t": ("switch", [e.t for e in sw], {"long_name": "switch time", "units": "1"}),
        "switch_x1": ("switch", ev(0), {"long_name": "x1 at the switch", "units": "1"}),
        "switch_x2": ("switch", ev(1), {"long_name": "x2 at the switch", "units": "1"}),
        "switch_y": ("switch", ev(2), {"long_name": "y at the switch", "units": "1"}),
        "switch_from": ("switch", np.array([e.mode_before for e in sw], np.int8),
                        {"long_name": "mode before the switch"}),
        "switch_to": ("switch", np.array([e.mode_after for e in sw], np.int8),
                      {"long_name": "mode after the switch"}),
    }


def _surface_vars(s: dict) -> dict:
    """The surfaces of :func:`surfaces` on the grid and the convergence of M_-."""
    grid = ("x1_grid", "x2_grid")
    return {
        "y_M_plus": (grid, s["X1"].copy(), {"long_name": "M_+ (Eq. (17)): y = x1", "units": "1"}),
        "y_M_minus": (grid, s["y_num"], {
            "long_name": "M_-: y from E_- trajectories integrated (DOP853) onto the grid",
            "units": "1", "settle_over_eps": s["settle"]}),
        "y_M_minus_exact": (grid, s["y_exact"], {
            "long_name": "M_-: exact cubic (hopf.slow_manifold_minus)", "units": "1"}),
        "y_M_minus_expansion": (grid, s["y_exp"], {
            "long_name": "M_-: O(eps) expansion Eq. (18)", "units": "1"}),
        "M_minus_error": (grid, s["y_num"] - s["y_exact"], {
            "long_name": "numerical M_- minus exact cubic", "units": "1"}),
        "M_minus_expansion_error": (grid, s["y_exact"] - s["y_exp"], {
            "long_name": "exact M_- minus expansion Eq. (18) (O(eps^2))", "units": "1"}),
        "M_minus_invariance_residual": (grid, s["resid"], {
            "long_name": "eps dy/dx . f_- - g_- on the exact cubic (complex step)",
            "units": "1"}),
        "y_H_s": (grid, s["y_hs"], {"long_name": "H_s: theta x1 + (1 - theta) y = -1",
                                    "units": "1"}),
        "convergence": ("t_settle", s["dev_conv"], {
            "long_name": "max over the grid of |y - y_m-| along the E_- trajectories",
            "units": "1"}),
    }


def _number_vars(family, eps: float, rate: float, s: dict, touches, z_orb) -> dict:
    """The scalars the report quotes: decay rate, gap at p_g, surface errors, orbit."""
    one = lambda v, ln, **kw: ((), float(v), {"long_name": ln, "units": "1", **kw})
    return {
        "decay_rate": one(rate, "measured rate of |y - x1| ~ exp(-rate t) after the "
                                "return to region +", expected=1.0 / eps),
        "decay_rate_rel_error": one(rate * eps - 1.0, "decay_rate * eps - 1"),
        "gap_pg": one(s["gap_pg"], "y_m+ - y_m- at x = (-1, 0) from the numerical M_-"),
        "gap_pg_exact": one(family.grazing_gap(eps),
                            "y_m+ - y_m- at x = (-1, 0) from the exact cubic"),
        "M_minus_max_error": one(np.max(np.abs(s["y_num"] - s["y_exact"])),
                                 "max |numerical M_- - exact cubic| on the grid"),
        "M_minus_max_expansion_error": one(np.max(np.abs(s["y_exact"] - s["y_exp"])),
                                           "max |exact M_- - Eq. (18)| on the grid"),
        "orbit_touch_t": one(touches[0].t if touches else np.nan,
                             "time of the grazing orbit's touch of H_s"),
        "orbit_min_x1": one(z_orb[0].min(), "min x1 on the grazing orbit"),
    }


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig05_thetalt0mfs"
    m.add("rpFiveEps", float(ds.attrs["eps"]), f"{sid}:attrs.eps")
    m.add("rpFiveTheta", float(ds.attrs["theta"]), f"{sid}:attrs.theta")
    m.add("rpFiveStart", float(ds.attrs["start_x2"]), f"{sid}:attrs.start_x2", 6)
    m.add("rpFiveSettle", float(ds.attrs["settle"]), f"{sid}:attrs.settle")
    m.add("rpFiveReturn", float(ds.attrs["x2_return"]), f"{sid}:attrs.x2_return", 6)
    var(m, "rpFiveGap", ds, sid, "gap_pg", sig=6)
    var(m, "rpFiveDecay", ds, sid, "decay_rate", sig=8)
    var(m, "rpFiveDecayErr", ds, sid, "decay_rate_rel_error", sig=2)
    var(m, "rpFiveMminusErr", ds, sid, "M_minus_max_error", sig=2)
    var(m, "rpFiveExpansionErr", ds, sid, "M_minus_max_expansion_error", sig=3)
    var(m, "rpFiveSwitchTwoXone", ds, sid, "switch_x1", sig=5, switch=1)
    var(m, "rpFiveSwitchTwoY", ds, sid, "switch_y", sig=5, switch=1)
    var(m, "rpFiveSwitchXtwo", ds, sid, "switch_x2", sig=4, switch=0)
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "eps"
