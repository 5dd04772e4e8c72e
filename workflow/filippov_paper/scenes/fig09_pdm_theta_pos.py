"""fig:pdmthgt0: the discontinuity map P_DM for theta > 0 in the coordinates of
eq:p:scal (x1 = -1 + eps^2 xi1, mu = 1 + eps^2 q), computed by the solver from the
full slow-fast system (with sliding) for several eps, against the zero-order
curve parametrised by the sliding time (eq:p:xi10t2 with eq:p:xi14t2, i.e. the
graph s xi1 of eq:xi1r), its corrected form, and the linear map eq:p:pdm.

The sliding layer where the asymptotics hold has xi2 < theta/((1 - theta) omega eps)
(eq:p:tangency), so it widens like 1/eps^2 in xi1: convergence is measured both
over the whole grid and over a fixed window |xi1| <= core.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov.analytic import pdm as asym
from filippov.io import finalize
from filippov_paper.tolerance import Tolerance
from filippov_paper.report import Macros, head, num, per_eps_rows, rate_cell, source, tabular, value, var

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "description": "0 < theta < 1: P_DM in xi1 = (x1 + 1)/eps^2 (Eq. (B.24)), one curve per eps; core: half-width of the fixed xi1 window for the convergence rate.",
      "required": ["eps", "mu", "omega", "theta", "xi1_min", "xi1_max", "n_uniform",
                   "n_geometric", "closest", "core"],
      "$ref": "#/$defs/pdm_sweep",
      "propertyNames": {"enum": [
        "eps", "mu", "omega", "theta", "xi1_min", "xi1_max", "n_uniform", "n_geometric",
        "closest", "core", "n_core"
      ]},
      "properties": {
        "theta": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
        "core": {"$ref": "#/$defs/positive"},
        "n_core": {"type": "integer", "minimum": 2}
      }
    }
  }
}

#: x1 near -1 after the grazing-sliding passage: the events there move at speed
#: O(eps), so each leaves x1 reproducible to an ulp or two of 1 (2.2e-16); 450
#: ulps for the ~10 events and the sliding segment of one passage
X1_NEAR_GRAZING = 1e-13


def tolerances(scene: dict) -> dict:
    """Cross-machine tolerances (filippov_paper.tolerance). xi = (x1 + 1)/eps^2: x1 known
    to X1_NEAR_GRAZING becomes X1_NEAR_GRAZING/eps_min^2 in xi; xi2 and the
    sliding times follow sqrt(-2 xi1) near xi1 = 0; slopes divide by |xi1|."""
    p = scene["parameters"]
    eps_min, closest = min(map(float, p["eps"])), float(p["closest"])
    xi = X1_NEAR_GRAZING / eps_min ** 2
    in_xi = Tolerance(1e-9, xi, f"xi = (x1 + 1)/eps^2: x1 to {X1_NEAR_GRAZING:g} (450 ulps) / "
                                f"eps_min^2 ({eps_min ** 2:g})")
    sqrt = Tolerance(1e-9, xi / np.sqrt(2 * closest),
                     f"~ sqrt(-2 xi1) for xi1 <= -{closest:g}: {xi:g} / sqrt(2 closest)")
    slope = Tolerance(1e-9, xi / closest, f"P_DM/xi1 at |xi1| >= {closest:g}: {xi:g} / closest")
    rate = Tolerance(1e-9, 2 * xi / (3e-3 * np.log(10)),
                     f"log-log slope of errors >= 3e-3 known to {xi:g}: 2 delta/(e ln 10)")
    names = ("P_DM", "P_flow", "xi1_exit", "pi3_drop", "pi3_drop_asym", "error", "error_core",
             "error_printed", "error_xi1_exit", "identity_error", "P_left")
    return {**{n: in_xi for n in names},
            **{n: sqrt for n in ("xi2_entry", "xi2_exit", "excursion_time", "sliding_time")},
            "error_slope": slope, "slope_left": slope, "rate": rate, "rate_core": rate}
from filippov_paper.scenes.pdm_common import (CHUNK_AXIS, HopfFamily as MODEL, base_dataset, checked_theta, chunk_grid,  # noqa: F401
                         fields_from_dataset, max_error, rates, sweep_dataset)
# CHUNK_AXIS, chunk_grid, sweep and assemble make the scene splittable (see .chunking)


def validate(scene: dict) -> None:
    """The checks a schema cannot make (filippov_paper.scenes.check runs them first)."""
    _theta(scene)


def _theta(scene: dict) -> float:
    return checked_theta(scene, lambda t: 0 < t < 1, "lie in (0, 1)")


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
    corrected = asym.pdm_theta_pos(x, theta, omega)
    printed = asym.pdm_theta_pos(x, theta, omega, printed=True)
    t2 = asym.sliding_time_theta_pos(x, theta, omega)
    _, xi21, xi12 = asym.sliding_curve(np.nan_to_num(t2), theta, omega)
    u = {"units": "1"}
    d2 = ("eps", "xi1")
    ds["P_zero_order"] = (d2, corrected, {
        "long_name": "zero-order P_DM, xi_{1,2} - xi_{1,2}^2/(2 omega^2) along the sliding "
                     "time (Eq. (B.34) with Pi_3 corrected)", **u})
    ds["P_printed"] = (d2, printed, {"long_name": "Eq. (B.34) as printed (= s xi1 of Eq. (23))",
                                     **u})
    ds["P_linear"] = ("xi1", asym.pdm_theta_pos_linear(xi, theta), {
        "long_name": "Eq. (B.23): slope (theta-1)/theta for xi1 < 0", **u})
    ds["P_reduced"] = ("xi1", asym.pdm_reduced(xi), {"long_name": "reduced model (eps = 0)",
                                                     **u})
    ds["excursion_time_asym"] = (d2, t2, {"long_name": "sliding time t2 from Eq. (B.33)", **u})
    ds["xi2_entry_asym"] = (d2, np.where(x < 0, xi21, np.nan),
                            {"long_name": "xi_{2,1} from Eq. (B.30)", **u})
    ds["xi1_exit_asym"] = (d2, np.where(x < 0, xi12, np.nan),
                           {"long_name": "xi_{1,2} from Eq. (B.31)", **u})
    ds["pi3_drop_asym"] = (d2, 0.5 * f["xi2_exit"] ** 2, {
        "long_name": "xi2(p2)^2 / 2: leading-order drop of xi1 under Pi_3 (Eq. (B.34) "
                     "as printed has 0)", **u})

    core = float(p["core"])
    neg = xi < 0
    in_core = neg & (xi >= -core)
    err = max_error(f["P"], corrected, neg)
    err_core = max_error(f["P"], corrected, in_core)
    errp = max_error(f["P"], printed, neg)
    rel = max_error(f["P"] / np.where(neg, xi, 1.0), corrected / np.where(neg, xi, 1.0), neg)
    loc, fit = rates(eps, err)
    loc_c, fit_c = rates(eps, err_core)
    for name, val, what in [
            ("error", err, "max over xi1 < 0 of |P_DM - zero-order corrected|"),
            ("error_core", err_core, f"the same over -{core:g} <= xi1 < 0"),
            ("error_printed", errp, "max over xi1 < 0 of |P_DM - Eq. (B.34) as printed|"),
            ("error_slope", rel, "max over xi1 < 0 of |P_DM/xi1 - zero-order s|")]:
        ds[name] = ("eps", val, {"long_name": what, **u})
    ds["rate"] = ("eps", loc, {"long_name": "local slope of log error against log eps", **u})
    ds["rate_core"] = ("eps", loc_c, {"long_name": "local slope of log error_core against "
                                                   "log eps", **u})
    ds["error_xi1_exit"] = ("eps", max_error(f["xi1_exit"], ds["xi1_exit_asym"].values, in_core),
                            {"long_name": "max over the core |xi1(p2) - Eq. (B.31)|", **u})
    k = int(np.flatnonzero(neg)[-1])  # grid point closest to 0 from below
    slope = f["P"][:, k] / xi[k]
    ds["xi1_left"] = ((), float(xi[k]), {"long_name": "grid point closest to 0 from below", **u})
    ds["P_left"] = ("eps", f["P"][:, k], {"long_name": "numerical P_DM at xi1_left "
                                                       "(continuity: -> 0)", **u})
    ds["slope_left"] = ("eps", slope, {"long_name": "P_DM(xi1_left)/xi1_left", **u})
    ds["slope_theory"] = ((), (theta - 1) / theta, {"long_name": "(theta-1)/theta (Eq. (B.23))",
                                                    **u})
    ds["sliding_limit_xi2"] = ("eps", theta / ((1 - theta) * omega * eps), {
        "long_name": "xi2 above which f_- no longer points to H_s (Eq. (B.27)): end of the "
                     "sliding regime", **u})
    return finalize(ds, scene, method=scene["ingredients"]["flow"], rate_fit=fit,
                    rate_core_fit=fit_c, core=core,
                    title="discontinuity map P_DM for theta > 0 (Fig. B.3)")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def _report_table(ds) -> str:
    """Convergence over eps with the core correction, one row per eps."""
    def cells(d):
        return [f"${num(float(d.slope_left), 4)}$", f"${num(float(d.error_printed))}$",
                f"${num(float(d.error))}$", f"${num(float(d.error_core))}$",
                rate_cell(float(d.rate_core), 3), f"${num(float(d.sliding_limit_xi2))}$"]
    return tabular("rrrrrrr", [head(
        r"$\epsilon$", r"$P_\mathrm{DM}(\xi_1^-)$//$/\xi_1^-$", "printed", "corrected",
        "corrected,//core", "rate//(core)", r"$\xi_2$, sliding//limit")], per_eps_rows(ds, cells))


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig09_pdm_theta_pos"
    eps = [float(e) for e in ds.eps.values]
    m.add("rpNineTheta", value(ds, "theta"), source(sid, "theta"))
    var(m, "rpNineSlopeTheory", ds, sid, "slope_theory")
    m.add("rpNineEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpNineEpsMin", eps[-1], f"{sid}:eps[-1]")
    var(m, "rpNineXiLeft", ds, sid, "xi1_left")
    m.add("rpNineCore", float(ds.attrs["core"]), f"{sid}:attrs.core")
    m.add("rpNineXiMin", float(ds.attrs["xi1_min"]), f"{sid}:attrs.xi1_min")
    m.add("rpNineRateCore", float(ds.attrs["rate_core_fit"]), f"{sid}:attrs.rate_core_fit", 3)
    for name_var, name in (("error_printed", "ErrPrinted"), ("error", "Err"),
                      ("error_core", "ErrCore"), ("slope_left", "SlopeLeft")):
        var(m, f"rpNine{name}Max", ds, sid, name_var, sig=4 if name_var == "slope_left" else 3, eps=eps[0])
        var(m, f"rpNine{name}Min", ds, sid, name_var, sig=4 if name_var == "slope_left" else 3, eps=eps[-1])
    var(m, "rpNineSlideLimitMax", ds, sid, "sliding_limit_xi2", eps=eps[0])
    return _report_table(ds)


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "theta"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"eps": [0.01, 0.001], "n_uniform": 9, "n_geometric": 4, "n_core": 5}
