"""fig:s0theta: s0(theta) for theta < 0, by Lambert W and by root finding."""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr

from filippov.io import finalize
from filippov_paper.scenes.common import registered_model, require
from filippov_paper.report import Macros


class S0ClosedForm(Protocol):
    """What this scene uses of its model (``model:``): s0(theta) two ways, and eq:s0def."""
    def s0_lambert(self, theta): ...
    def s0_root(self, theta): ...
    def residual(self, s, theta): ...


MODEL = S0ClosedForm

VARIABLE_ATTRS = {"residual": ("left side of Eq. (B.15) at the closed-form s0", "1")}
from filippov_paper.tolerance import U, Tolerance


def tolerances(scene: dict) -> dict:
    """s0 = 1 - theta + W0(-(1 - theta) e^(theta - 1)) cancels near the branch
    point of W0 (theta -> 0): its absolute spread is ~u/|theta|."""
    theta_max = abs(float(scene["parameters"]["theta_max"]))
    return {"s0": Tolerance(1e-9, 50 * U / theta_max,
                            f"cancellation near W0's branch point: ~u/|theta| at |theta| >= "
                            f"{theta_max:g}; x50")}


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    require(scene, "system", {"none"})
    require(scene, "flow", {"closed_form"})
    s0 = registered_model(scene)   # the closed form and root finding of filippov.analytic.s0
    p = scene["parameters"]
    lo, hi, n = p["theta_min"], p["theta_max"], p["n_theta"]
    if not lo < hi < 0:
        raise ValueError(f"{scene['id']}: parameters.theta_min < parameters.theta_max < 0 "
                         f"required, got {lo!r}, {hi!r}")
    # geometric in -theta: resolves the square-root-like start of s0 at theta -> 0-
    theta = np.sort(-np.geomspace(-hi, -lo, n))
    closed, root = s0.s0_lambert(theta), s0.s0_root(theta)
    diff = np.abs(closed - root)
    ds = xr.Dataset(
        {"s0": ("theta", closed, {"long_name": "s0(theta), closed form via Lambert W_0",
                                  "units": "1", "equation": "Eq. (B.15)"}),
         "s0_root": ("theta", root, {"long_name": "s0(theta) by Brent root finding on Eq. (B.15)",
                                     "units": "1"}),
         "residual": ("theta", s0.residual(closed, theta),
                      {"long_name": "left side of Eq. (B.15) at the closed-form s0"})},
        coords={"theta": ("theta", theta, {"long_name": "theta", "units": "1",
                                            "spacing": "geometric in -theta"})})
    return finalize(ds, scene, max_abs_difference=float(diff.max()),
                    title="s0(theta), the positive root of Eq. (B.15)")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig08_s0theta"
    th = ds.theta.values
    m.add("rpEightThetaMin", float(th[0]), f"{sid}:theta[0]")
    m.add("rpEightThetaMax", float(th[-1]), f"{sid}:theta[-1]")
    m.add("rpEightN", th.size, f"{sid}:theta (size)")
    m.add("rpEightLambertRoot", float(np.max(np.abs(ds.s0.values - ds.s0_root.values))),
          "derived: max |s0 - s0_root|", 2)
    m.add("rpEightResidual", float(np.max(np.abs(ds.residual.values))), "derived: max |residual|", 2)
    m.add("rpEightMargin", float(np.min(ds.s0.values + th)), "derived: min (s0 + theta) > 0", 3)
    m.add("rpEightSmallRatio", float(ds.s0.values[-1] / (-2 * th[-1] / (1 - th[-1]))),
          "derived: s0 / (-2 theta/(1-theta)) at theta[-1]", 5)
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "theta_min"
