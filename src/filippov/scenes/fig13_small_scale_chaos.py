"""Small-scale chaos (theta > 0): the attractor of the return map to L1 of the slow-fast
Hopf example across mu = 1 for several theta and eps, with its largest Lyapunov
exponent and width, beside the limit map.

Orbit diagrams in s = (mu - 1)/eps^2, u = (x2 - 1)/eps^2 (attractor_common), on a
uniform grid around grazing and a geometric one beyond it (where the attractor ends).
On top of the shared sweep:

* the one-sided slope of P_DM at grazing, s(theta, 0, 0) = (theta - 1)/theta (the
  paper's chaos condition is s < -1), and the slope of the whole return there,
  lambda s (lambda the cycle's multiplier per turn): the fixed point on the sliding
  branch loses stability where lambda s < -1;
* the Lyapunov exponent of the limit map along its attractor (central differences of
  the map), beside the slow-fast one;
* the width in x2 (width u times eps^2) and its scaling exponent k per (theta, s):
  the least-squares slope of log width against log eps over eps <= ``fit_eps_max``,
  where the attractor is not a point at any of them.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from .. import tolerance
from ..analytic import limit_map
from ..io import finalize
from ..tolerance import Tolerance
from .attractor_common import (CHUNK_AXIS, ENGINES, chunk_grid, T_RETURN,  # noqa: F401
                               VARIABLE_ATTRS as _COMMON_ATTRS, chaos_tolerances,
                               common_dataset, eps_list, lyapunov_limit, s_grid, sweep, thetas)
from .attractor_common import validate as _validate_common
from ..config import SceneError

VARIABLE_ATTRS = dict(_COMMON_ATTRS)
VARIABLE_ATTRS.update({
    "slope_pdm": ("one-sided slope s(theta,0,0) = (theta - 1)/theta of P_DM at grazing", "1"),
    "slope_return": ("lambda s(theta,0,0): slope of the return map on the sliding side", "1"),
    "lyapunov_limit": ("Lyapunov exponent of the limit map along its attractor", "1"),
    "width_x2": ("width of the attractor in x2 (width times eps^2)", "1"),
    "width_exponent": ("k of width_x2 ~ eps^k: least-squares slope over eps <= fit_eps_max "
                       "(NaN: the attractor is a point at one of them)", "1"),
})


def tolerances(scene: dict) -> dict:
    """attractor_common.chaos_tolerances, and for the derived widths: width_x2 to its
    sampling error (50%), the width exponent, a log10 ratio of two widths a decade of
    eps apart, to log10(1.5/0.5) ~ 0.5."""
    out = chaos_tolerances(scene)
    stat = "a sampled statistic of a chaotic orbit (another orbit on another machine)"
    out["width_x2"] = Tolerance(0.5, tolerance.EVENT_STATE, f"{stat}: extent of the points")
    out["width_exponent"] = Tolerance(0.0, 0.5, f"{stat}: log10 of a width ratio")
    return out


def validate(scene: dict) -> None:
    _validate_common(scene)
    if any(not 0 < t < 1 for t in thetas(scene["parameters"])):
        raise SceneError(f"{scene['id']}: parameters.theta: each theta must lie in (0, 1) "
                         "(the sliding case)")


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = scene["parameters"]
    ds = common_dataset(scene, raw)
    th, eps = np.array(thetas(p)), np.array(eps_list(p))
    lam = limit_map.multiplier(1.0, float(p["omega"]))
    ds["slope_pdm"] = ("theta", (th - 1.0) / th)
    ds["slope_return"] = ("theta", lam * (th - 1.0) / th)
    ds["lyapunov_limit"] = (("theta", "eps", "s"), lyapunov_limit(ds, float(p["omega"])))
    wx = ds.width.values * (eps ** 2)[None, :, None]
    ds["width_x2"] = (("theta", "eps", "s"), wx)
    k = np.full((th.size, ds.sizes["s"]), np.nan)
    fitted = eps <= float(p["fit_eps_max"])
    le = np.log(eps[fitted])
    for i in range(th.size):
        for m in range(ds.sizes["s"]):
            w = wx[i, fitted, m]
            # a period-one attractor has width zero up to rounding: no exponent
            if le.size >= 2 and np.all(np.isfinite(w) &
                                       (ds.period.values[i, fitted, m] != 1)):
                k[i, m] = np.polyfit(le, np.log(w), 1)[0]
    ds["width_exponent"] = (("theta", "s"), k)
    return finalize(ds, scene, engine="compiled", method="exact",
                    title="small-scale chaos of the slow-fast Hopf example, theta > 0")
