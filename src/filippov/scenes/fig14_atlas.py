"""Atlas of the attractor near grazing: its type over (theta, s) at one eps.

The sweep of attractor_common over a grid of theta on both sides of 0 (s = (mu - 1)/eps
for theta < 0, (mu - 1)/eps^2 for theta > 0), classified per point as periodic (its
period), chaotic (no period up to max_period and a positive Lyapunov exponent),
aperiodic without a positive exponent, or escaped; the limit map is classified the same
way (its exponent by central differences of the map). Drawn with the paper's condition
s(theta, 0, 0) = (theta - 1)/theta = -1 (theta = 1/2) and the threshold of the whole
return, lambda s(theta, 0, 0) = -1.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from ..analytic import limit_map
from ..io import finalize
from .attractor_common import (CHUNK_AXIS, ENGINES, chunk_grid, T_RETURN,  # noqa: F401
                               VARIABLE_ATTRS as _COMMON_ATTRS, chaos_tolerances,
                               common_dataset, lyapunov_limit, s_grid, sweep, validate)
from ..report import Macros, source, value

#: this scene's block of the scene schema: filippov.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "required": ["eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_transient", "n_keep",
                   "max_period", "window", "lyapunov"],
      "$ref": "#/$defs/attractor_sweep",
      "propertyNames": {"enum": [
        "eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_transient", "n_keep", "max_period",
        "window", "lyapunov"
      ]},
      "properties": {
        "eps": {"type": "array", "minItems": 1, "maxItems": 1, "items": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1}},
        "theta": {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": -5, "exclusiveMaximum": 1}},
        "s_max": {"type": "number"}
      }
    }
  }
}

#: attractor types besides a period n >= 1
CHAOTIC, APERIODIC, ESCAPED = 0, -1, -2

VARIABLE_ATTRS = dict(_COMMON_ATTRS)
VARIABLE_ATTRS.update({
    "attractor_type": ("n >= 1: period n; 0: chaotic (no period, Lyapunov exponent > 0); "
                       "-1: no period, exponent <= 0; -2: escaped", "1"),
    "attractor_type_limit": ("attractor_type of the limit map (order 1 at the scene's eps)",
                             "1"),
    "lyapunov_limit": ("Lyapunov exponent of the limit map along its attractor", "1"),
    "theta_critical": ("theta where lambda s(theta,0,0) = -1: lambda/(1 + lambda)", "1"),
})


def tolerances(scene: dict) -> dict:
    """attractor_common.chaos_tolerances; the type of a point is a classification, as
    the period there."""
    out = chaos_tolerances(scene)
    out.update({name: out["period"] for name in ("attractor_type", "attractor_type_limit")})
    return out


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def classify(period, lyapunov, escaped) -> np.ndarray:
    period, lyapunov = np.asarray(period), np.asarray(lyapunov)
    out = np.where(period > 0, period, np.where(lyapunov > 0, CHAOTIC, APERIODIC))
    return np.where(escaped, ESCAPED, out).astype(np.int32)


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = scene["parameters"]
    ds = common_dataset(scene, raw)
    ds["lyapunov_limit"] = (("theta", "eps", "s"), lyapunov_limit(ds, float(p["omega"])))
    ds["attractor_type"] = (("theta", "eps", "s"),
                            classify(ds.period.values, ds.lyapunov.values, ds.status.values != 0))
    ds["attractor_type_limit"] = (("theta", "eps", "s"), classify(
        ds.period_limit.values, ds.lyapunov_limit.values, ~np.isfinite(ds.u_limit.values).all(-1)))
    lam = limit_map.multiplier(1.0, float(p["omega"]))
    ds["theta_critical"] = ((), lam / (1.0 + lam))
    return finalize(ds, scene, engine="compiled", method="exact",
                    title="atlas of the attractor near grazing, slow-fast Hopf example")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def report(ds, m: Macros) -> str | None:
    sid = "fig14_atlas"
    th, s = ds.theta.values, ds.s.values
    kind, lim = ds.attractor_type.values[:, 0, :], ds.attractor_type_limit.values[:, 0, :]
    m.add("rpFourteenEps", float(ds.eps.values[0]), f"{sid}:eps[0]")
    m.add("rpFourteenNTheta", th.size, f"{sid}:theta (size)")
    m.add("rpFourteenNMu", s.size, f"{sid}:s (size)")
    m.add("rpFourteenThetaCrit", value(ds, "theta_critical"), source(sid, "theta_critical"), 3)
    above = s > 0
    pos = th > 0
    chaotic = np.array([np.any(kind[i, above] == 0) for i in range(th.size)])
    one = np.array([np.all(kind[i, above] == 1) for i in range(th.size)])
    m.add("rpFourteenChaosThetaMax", float(th[pos & chaotic].max()),
          "derived: largest theta > 0 with a chaotic point above grazing", 3)
    m.add("rpFourteenPeriodOneThetaMin", float(th[pos & one].min()),
          "derived: smallest theta > 0 with period one everywhere above grazing", 3)
    m.add("rpFourteenBelowAllOne", None, "derived: period one at every s < 0",
          text=r"\text{every}" if np.all(kind[:, s < 0] == 1) else r"\text{\emph{not} every}")
    m.add("rpFourteenAgree", 100.0 * float(np.mean(kind == lim)),
          "derived: percent of points where slow-fast and limit-map types agree", 3)
    neg = th < 0
    m.add("rpFourteenNegChaos", float(np.sum(kind[neg][:, above] == 0)),
          "derived: chaotic points at theta < 0", 1)
    return None
