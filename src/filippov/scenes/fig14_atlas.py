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

from .. import tolerance
from ..analytic import limit_map
from ..io import finalize
from ..tolerance import Tolerance
from .attractor_common import (CHUNK_AXIS, ENGINES, T_RETURN,  # noqa: F401
                               VARIABLE_ATTRS as _COMMON_ATTRS, common_dataset, eps_list,
                               s_grid, sweep, validate)

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
    """As fig13 (filippov.scenes.fig13_small_scale_chaos.tolerances): chaotic points
    compared by each row's extent, sampled statistics to their sampling error. The
    type of a point is a classification: at most a few points near a boundary between
    types, or with an exponent within its sampling error of 0, may change."""
    eps = np.array(eps_list(scene["parameters"]))
    scale = np.array([limit_map.scale(e, t) for e in eps for t in (-1.0, 1.0)]).min()
    u_atol = 10 * tolerance.EVENT_STATE / scale
    n_pts = len(np.atleast_1d(scene["parameters"]["theta"])) * len(s_grid(scene["parameters"]))
    flip = max(1, n_pts // 50)
    pts = Tolerance(0.0, u_atol, "chaotic points: each row's extent, to half its width",
                    rule="attractor", jump=0.5)
    lim = Tolerance(0.0, 1e-9, "limit map: each row's extent, to half its width",
                    rule="attractor", jump=0.5)
    kind = Tolerance(0.0, 0.0, "a classification: points at a boundary of types (or with "
                               "an exponent within sampling error of 0) may change",
                     rule="tangency", changed=flip, jump=100.0)
    stat = "a sampled statistic of a chaotic orbit (another orbit on another machine)"
    return {"u": pts, "u_limit": lim, "u_limit0": lim,
            "lyapunov": Tolerance(0.0, 0.3, f"{stat}: mean log-slope"),
            "lyapunov_limit": Tolerance(0.0, 0.3, f"{stat}: mean log-slope"),
            "width": Tolerance(0.5, u_atol, f"{stat}: extent of the kept points"),
            "period": kind, "period_limit": kind, "period_limit0": kind,
            "attractor_type": kind, "attractor_type_limit": kind}


def chunk_grid(scene: dict) -> np.ndarray:
    return s_grid(scene["parameters"])


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def classify(period, lyapunov, escaped) -> np.ndarray:
    period, lyapunov = np.asarray(period), np.asarray(lyapunov)
    out = np.where(period > 0, period, np.where(lyapunov > 0, CHAOTIC, APERIODIC))
    return np.where(escaped, ESCAPED, out).astype(np.int32)


def _lyapunov_limit(ds, p) -> np.ndarray:
    omega = float(p["omega"])
    out = np.full(ds.period_limit.shape, np.nan)
    s = ds.s.values
    for i, theta in enumerate(ds.theta.values):
        for j, eps in enumerate(ds.eps.values):
            sl = limit_map.slopes(ds.u_limit.values[i, j], s[:, None], eps=float(eps),
                                  theta=float(theta), omega=omega)
            with np.errstate(divide="ignore"):
                out[i, j] = np.mean(np.log(np.abs(sl)), axis=1)
    return out


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = scene["parameters"]
    ds = common_dataset(scene, raw)
    ds["lyapunov_limit"] = (("theta", "eps", "s"), _lyapunov_limit(ds, p))
    ds["attractor_type"] = (("theta", "eps", "s"),
                            classify(ds.period.values, ds.lyapunov.values, ds.status.values != 0))
    ds["attractor_type_limit"] = (("theta", "eps", "s"), classify(
        ds.period_limit.values, ds.lyapunov_limit.values, ~np.isfinite(ds.u_limit.values).all(-1)))
    lam = limit_map.multiplier(1.0, float(p["omega"]))
    ds["theta_critical"] = ((), lam / (1.0 + lam))
    return finalize(ds, scene, engine="compiled", method="exact",
                    title="atlas of the attractor near grazing, slow-fast Hopf example")
