"""fig:p:xi12: the graph s(theta, omega, xi1, 0) xi1 against xi1 (eq:xi1r),
parametrised by the sliding time t_s, from the closed forms in analytic.sgraph."""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr

from filippov.io import finalize
from filippov_paper.scenes.common import registered_model, require
from filippov_paper.report import Macros, source, var


class SGraphClosedForm(Protocol):
    """What this scene uses of its model (``model:``): the closed forms of the s graph."""
    def xi1(self, t, theta, omega): ...
    def image(self, t, theta, omega): ...
    def slope(self, t, theta, omega): ...
    def slope_at_zero(self, theta): ...
    def image_limit(self, theta, omega): ...


MODEL = SGraphClosedForm


def t_grid(p: dict) -> np.ndarray:
    """Geometric in t_s from t_min (resolves xi1 ~ t_s^2 near 0) joined to a uniform grid."""
    lo, hi = float(p["t_min"]), float(p["t_max"])
    geo = np.geomspace(lo, hi, int(p["n_geometric"]))
    lin = np.linspace(0.0, hi, int(p["n_linear"]))[1:]
    return np.unique(np.concatenate([geo, lin[lin > lo]]))


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    require(scene, "system", {"none"})
    require(scene, "flow", {"closed_form"})
    p = scene["parameters"]
    if not 0 < p["t_min"] < p["t_max"]:
        raise ValueError(f"{scene['id']}: 0 < parameters.t_min < parameters.t_max required, "
                         f"got {p['t_min']!r}, {p['t_max']!r}")
    theta, omega = float(p["theta"]), float(p["omega"])
    sgraph = registered_model(scene)   # the closed forms of filippov.analytic.sgraph
    t = t_grid(p)
    xi1 = sgraph.xi1(t, theta, omega)
    img = sgraph.image(t, theta, omega)
    s_direct = sgraph.slope(t, theta, omega)
    s = img / xi1
    ds = xr.Dataset(
        {"xi1": ("t_s", xi1, {"long_name": "xi1, rescaled x1 before sliding (Eq. (23))",
                              "units": "1", "equation": "Eq. (23)"}),
         "image": ("t_s", img, {"long_name": "s(theta, omega, xi1, 0) xi1 = P_DM(xi1) (Eq. (23))",
                                "units": "1", "equation": "Eq. (23)"}),
         "s": ("t_s", s, {"long_name": "slope s(theta, omega, xi1, 0) = image / xi1",
                          "units": "1"}),
         "slope_at_zero": ((), sgraph.slope_at_zero(theta), {
             "long_name": "limit of s as t_s -> 0 (xi1 -> 0-): (theta - 1)/theta", "units": "1"}),
         "image_limit": ((), sgraph.image_limit(theta, omega), {
             "long_name": "limit of s xi1 as t_s -> infinity: omega^2 (1 - theta)", "units": "1"})},
        coords={"t_s": ("t_s", t, {"long_name": "sliding time t_s", "units": "1",
                                   "spacing": "geometric from t_min joined to uniform"})})
    return finalize(ds, scene, title="graph of s(theta, omega, ., 0) from Eq. (23) (Fig. 6)",
                    max_abs_difference_s=float(np.max(np.abs(s - s_direct))))


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig06_sgraph"
    m.add("rpSixTheta", float(ds.attrs["theta"]), f"{sid}:attrs.theta")
    var(m, "rpSixSlopeZero", ds, sid, "slope_at_zero")
    var(m, "rpSixImageLimit", ds, sid, "image_limit", sig=5)
    m.add("rpSixSFirst", float(ds.s.values[0]), source(sid, "s") + "[0]", 6)
    m.add("rpSixTsMin", float(ds.t_s.values[0]), "fig06_sgraph:t_s[0]", 2)
    m.add("rpSixTsMax", float(ds.t_s.values[-1]), "fig06_sgraph:t_s[-1]", 2)
    m.add("rpSixXiMin", float(ds.xi1.values[-1]), "fig06_sgraph:xi1[-1]", 4)
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "omega"
