"""fig:pdmthlt0: the discontinuity map P_DM for theta < 0 in the coordinates of
eq:scal (x1 = -1 + eps xi1, mu = 1 + eps q), computed by the solver from the full
slow-fast system for several eps, against the expansions of eq:pdmdisc.

Stored asymptotics (see filippov.analytic.pdm): the corrected expansion
xi1 + s0 + sqrt(eps) s0 sqrt(-2 xi1) [omega/(theta+s0) - 2/omega] (first order)
and xi1 + s0 (zero order), and eq:pdmdisc as printed. Convergence: per eps the
largest difference over the grid points xi1 < 0, and its observed rate in eps.
The pieces Pi_1 (eq:xi2int) and Pi_2 (eq:hittime) are compared separately.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov.analytic import pdm as asym
from filippov.analytic.s0 import s0_lambert
from filippov.io import finalize
from filippov_paper.tolerance import EVENT_STATE, ULP, Tolerance
from filippov_paper.report import Macros, head, num, per_eps_rows, rate_cell, source, tabular, value, var

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "description": "theta < 0: P_DM in xi1 = (x1 + 1)/eps (Eq. (B.2)), one curve per eps.",
      "required": ["eps", "mu", "omega", "theta", "xi1_min", "xi1_max", "n_uniform",
                   "n_geometric", "closest"],
      "$ref": "#/$defs/pdm_sweep",
      "propertyNames": {"enum": [
        "eps", "mu", "omega", "theta", "xi1_min", "xi1_max", "n_uniform", "n_geometric",
        "closest"
      ]},
      "properties": {
        "theta": {"type": "number", "exclusiveMaximum": 0}
      }
    }
  }
}


def tolerances(scene: dict) -> dict:
    """Cross-machine tolerances (filippov_paper.tolerance). xi = (x1 + 1)/eps: an O(1)
    state known to EVENT_STATE becomes EVENT_STATE/eps_min in xi; xi2 near
    xi1 = 0 follows sqrt(-2 xi1), which amplifies the rounding of the start."""
    p = scene["parameters"]
    eps_min, closest = min(map(float, p["eps"])), float(p["closest"])
    xi = EVENT_STATE / eps_min
    in_xi = Tolerance(1e-9, xi, f"xi = (x1 + 1)/eps: event-located state ({EVENT_STATE:g}) "
                                f"/ eps_min ({eps_min:g})")
    xi2 = Tolerance(1e-9, 10 * 2 * ULP / eps_min / np.sqrt(2 * closest),
                    f"xi2 ~ sqrt(-2 xi1) for xi1 >= -{closest:g}: 2 ulps of x1 / eps_min "
                    f"amplified by 1/sqrt(2 closest); x10")
    rate = Tolerance(1e-9, 2 * xi / (1e-3 * np.log(10)),
                     f"log-log slope of errors >= 1e-3 known to {xi:g}: "
                     f"2 delta/(e ln 10)")
    names = ("P_DM", "P_flow", "xi1_exit", "excursion_time", "excursion_time_asym", "pi3_drop",
             "pi3_drop_asym", "sliding_time", "P_left", "identity_error", "left_limit_error",
             "error_first_order", "error_zero_order", "error_printed", "error_excursion_time")
    # error_xi2_entry = max |xi2_entry - closed form|: the closed form is smooth, so the
    # error moves as xi2_entry does (its sqrt-amplified rounding), not as xi
    return {**{n: in_xi for n in names}, "xi2_entry": xi2, "xi2_exit": xi2,
            "error_xi2_entry": xi2,
            "rate_first_order": rate, "rate_zero_order": rate}
from filippov_paper.scenes.pdm_common import (CHUNK_AXIS, HopfFamily as MODEL, base_dataset, checked_theta, chunk_grid,  # noqa: F401
                         fields_from_dataset, max_error, rates, sweep_dataset)
# CHUNK_AXIS, chunk_grid, sweep and assemble make the scene splittable (see .chunking)


def validate(scene: dict) -> None:
    """The checks a schema cannot make (filippov_paper.scenes.check runs them first)."""
    _theta(scene)


def _theta(scene: dict) -> float:
    return checked_theta(scene, lambda t: t < 0, "be < 0")


def sweep(scene: dict, xi: np.ndarray, *, progress: bool = False) -> xr.Dataset:
    """The solver's P_DM fields on the points ``xi`` of the xi1 grid (raw)."""
    return sweep_dataset(scene, _theta(scene), xi, progress)


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    """The figure's dataset from the fields on the whole xi1 grid (see `sweep`)."""
    theta = _theta(scene)
    p = scene["parameters"]
    omega = float(p["omega"])
    eps, xi, f = fields_from_dataset(scene, raw)
    ds = base_dataset(eps, xi, f, theta)
    x = f["xi1"]
    e2 = eps[:, None]
    first = asym.pdm_theta_neg(x, theta, omega, e2, order=1)
    zero = asym.pdm_theta_neg(x, theta, omega, e2, order=0)
    printed = asym.pdm_theta_neg_printed(x, theta, omega, e2, order=1)
    s0 = float(s0_lambert(theta))
    u = {"units": "1"}
    d2 = ("eps", "xi1")
    ds["P_first_order"] = (d2, first, {
        "long_name": "xi1 + s0 + sqrt(eps) s0 sqrt(-2 xi1) (omega/(theta+s0) - 2/omega): "
                     "Eq. (B.20) with Pi_3 corrected", **u})
    ds["P_zero_order"] = (d2, zero, {"long_name": "xi1 + s0(theta) for xi1 < 0 (corrected "
                                                  "zero order)", **u})
    ds["P_printed"] = (d2, printed, {"long_name": "Eq. (B.20) / Eq. (21) as printed", **u})
    ds["xi2_entry_asym"] = (d2, asym.xi2_entry_theta_neg(x, omega, e2), {
        "long_name": "xi2 at H_s from Eq. (B.12)", **u})
    ds["excursion_time_asym"] = (d2, asym.hit_time_theta_neg(f["xi2_entry"], theta, omega, e2), {
        "long_name": "s_* from Eq. (B.14) at the numerical xi2_entry", **u})
    ds["pi3_drop_asym"] = (d2, 0.5 * f["xi2_exit"] ** 2, {
        "long_name": "xi2(p2)^2 / 2: leading-order drop of xi1 under Pi_3 (the printed "
                     "Eq. (B.18) has 0)", **u})

    neg = xi < 0
    err1 = max_error(f["P"], first, neg)
    err0 = max_error(f["P"], zero, neg)
    errp = max_error(f["P"], printed, neg)
    loc1, fit1 = rates(eps, err1)
    loc0, fit0 = rates(eps, err0)
    for name, val, what in [
            ("error_first_order", err1, "first-order corrected expansion"),
            ("error_zero_order", err0, "xi1 + s0"),
            ("error_printed", errp, "Eq. (B.20) as printed")]:
        ds[name] = ("eps", val, {"long_name": f"max over xi1 < 0 of |P_DM - ({what})|", **u})
    ds["rate_first_order"] = ("eps", loc1, {"long_name": "local slope of log error_first_order "
                                                         "against log eps", **u})
    ds["rate_zero_order"] = ("eps", loc0, {"long_name": "local slope of log error_zero_order "
                                                        "against log eps", **u})
    ds["error_xi2_entry"] = ("eps", max_error(f["xi2_entry"], ds["xi2_entry_asym"].values, neg),
                             {"long_name": "max |xi2_entry - Eq. (B.12)|", **u})
    ds["error_excursion_time"] = ("eps", max_error(f["excursion_time"],
                                                   ds["excursion_time_asym"].values, neg),
                                  {"long_name": "max |s_* - Eq. (B.14)|", **u})
    k = int(np.argmax(neg & (xi == xi[neg].max())))  # the grid point closest to 0-
    ds["xi1_left"] = ((), float(xi[k]), {"long_name": "grid point closest to 0 from below", **u})
    ds["P_left"] = ("eps", f["P"][:, k], {"long_name": "numerical P_DM at xi1_left", **u})
    ds["left_limit_error"] = ("eps", np.abs(f["P"][:, k] - s0), {
        "long_name": "|P_DM(xi1_left) - s0(theta)|", **u})
    ds["s0"] = ((), s0, {"long_name": "s0(theta), Eq. (B.15)", **u})
    ds["jump_x1"] = ("eps", eps * s0, {"long_name": "jump of P_DM at 0 in original units, "
                                                    "eps s0", **u})
    return finalize(ds, scene, method=scene["ingredients"]["flow"],
                    rate_first_order_fit=fit1, rate_zero_order_fit=fit0,
                    title="discontinuity map P_DM for theta < 0 (Fig. B.1)")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def _report_table(ds) -> str:
    """Convergence over eps, one row per eps."""
    def cells(d):
        return [f"${num(float(d.P_left), 5)}$", f"${num(float(d.left_limit_error), 2)}$",
                f"${num(float(d.error_printed))}$", f"${num(float(d.error_zero_order))}$",
                f"${num(float(d.error_first_order))}$", rate_cell(float(d.rate_first_order), 2)]
    return tabular("rrrrrrr", [head(
        r"$\epsilon$", r"$P_\mathrm{DM}(0^-)$", r"$|P_\mathrm{DM}(0^-)$//$-s_0|$", "printed",
        r"$\xi_1+s_0$", "corrected//1st order", "rate")], per_eps_rows(ds, cells))


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig07_pdm_theta_neg"
    eps = [float(e) for e in ds.eps.values]
    m.add("rpSevenTheta", value(ds, "theta"), source(sid, "theta"))
    var(m, "rpSevenSzero", ds, sid, "s0", sig=6)
    m.add("rpSevenXiMin", float(ds.attrs["xi1_min"]), f"{sid}:attrs.xi1_min")
    m.add("rpSevenXiMinAbs", abs(float(ds.attrs["xi1_min"])), "derived: |xi1_min|")
    m.add("rpSevenEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpSevenEpsMin", eps[-1], f"{sid}:eps[-1]")
    m.add("rpSevenRateFirst", float(ds.attrs["rate_first_order_fit"]),
          f"{sid}:attrs.rate_first_order_fit", 2)
    m.add("rpSevenRateZero", float(ds.attrs["rate_zero_order_fit"]),
          f"{sid}:attrs.rate_zero_order_fit", 2)
    for name_var, name in (("error_printed", "ErrPrinted"), ("error_first_order", "ErrFirst"),
                      ("error_zero_order", "ErrZero"), ("left_limit_error", "LeftErr"),
                      ("jump_x1", "Jump")):
        var(m, f"rpSeven{name}Max", ds, sid, name_var, eps=eps[0])
        var(m, f"rpSeven{name}Min", ds, sid, name_var, eps=eps[-1])
    m.add("rpSevenIdentityErr", float(ds.identity_error_x1.max()),
          "derived: max identity_error_x1 over eps", 2)
    return _report_table(ds)


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "theta"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"eps": [0.01, 0.001], "n_uniform": 9, "n_geometric": 4}
