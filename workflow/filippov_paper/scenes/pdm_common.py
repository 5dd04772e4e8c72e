"""Shared part of the two discontinuity-map scenes (fig:pdmthlt0, fig:pdmthgt0):
the xi1 grid, the numerical P_DM for every eps, and convergence measures."""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr

from filippov_paper.config import SceneError
from filippov.pdm import discontinuity_map, scale_for
from filippov.progress import Progress
from filippov_paper.scenes.common import registered_model, require, solver_options


class HopfFamily(Protocol):
    """What the discontinuity-map scenes use of their model (``model:``): the slow-fast
    model at (eps, theta, mu, omega) (:func:`filippov.pdm.discontinuity_map` takes it)."""
    def model(self, eps, theta, mu, omega): ...


def xi1_grid(p: dict) -> np.ndarray:
    """Uniform on [xi1_min, xi1_max] plus points approaching 0 from below
    geometrically (down to -closest), where P_DM has its singular behaviour, and
    optionally ``n_core`` uniform points on [-core, 0]."""
    lo, hi = float(p["xi1_min"]), float(p["xi1_max"])
    if not lo < 0 < hi:
        raise ValueError(f"xi1_min < 0 < xi1_max required, got {lo!r}, {hi!r}")
    near = -np.geomspace(float(p["closest"]), -lo, int(p["n_geometric"]))
    parts = [np.linspace(lo, hi, int(p["n_uniform"])), near, [0.0]]
    if "n_core" in p:
        parts.append(np.linspace(-float(p["core"]), 0.0, int(p["n_core"])))
    return np.unique(np.concatenate(parts))


def eps_list(p: dict) -> np.ndarray:
    eps = np.atleast_1d(np.asarray(p["eps"], dtype=float))
    if np.any(eps <= 0):
        raise ValueError("every eps must be > 0 for the slow-fast system")
    return np.sort(eps)[::-1]  # largest first: the order a reader follows the limit


def pdm_fields(scene: dict, theta: float, xi: np.ndarray,
               progress: bool) -> tuple[np.ndarray, np.ndarray, dict]:
    """(eps, xi1, fields): every PDMResult field stacked to shape (eps, xi1), on the
    points ``xi`` (any part of the xi1 grid: every point is computed on its own, so
    parts of the grid give parts of the fields)."""
    require(scene, "system", {"slow_fast"})
    p = scene["parameters"]
    opts = solver_options(scene)
    method = opts.pop("method")
    mu, omega = float(p["mu"]), float(p["omega"])
    eps, xi = eps_list(p), np.asarray(xi, dtype=float)
    bar = Progress(scene["id"], eps.size * xi.size, progress)
    rows = []
    for e in eps:
        model = registered_model(scene).model(float(e), theta, mu, omega)
        rows.append(discontinuity_map(model, xi, scale=scale_for(float(e), theta),
                                      sliding=scene["ingredients"]["sliding"], method=method,
                                      progress=bar, **opts))
    fields = {k: np.stack([getattr(r, k) for r in rows]) for k in (
        "xi1", "P", "P_flow", "n_switches", "xi2_entry", "excursion_time", "xi1_exit",
        "xi2_exit", "sliding_time")}
    fields["scale"] = np.array([r.scale for r in rows])
    return eps, xi, fields


# Chunking (filippov_paper.scenes.chunking) splits the xi1 grid: `sweep` computes the
# solver's fields on part of it, the scene module's `assemble` builds the
# dataset (errors, rates, limits: all from the whole grid) from the merged fields.
CHUNK_AXIS = "xi1"
FIELDS = ("xi1", "P", "P_flow", "n_switches", "xi2_entry", "excursion_time", "xi1_exit",
          "xi2_exit", "sliding_time")
_RAW_NAME = {"xi1": "xi1_start"}  # the field xi1 would clash with the coordinate


#: the smallest distance of a start point from x1 = -1: 16 ulps of 1
RESOLUTION = 16 * float(np.finfo(float).eps)


def chunk_grid(scene: dict) -> np.ndarray:
    return xi1_grid(scene["parameters"])


def checked_theta(scene: dict, ok, requirement: str) -> float:
    """parameters.theta if ``ok(theta)`` (the case the scene's asymptotics are for),
    with mu = 1 (q = 0), else an error naming the field."""
    p = scene["parameters"]
    theta, mu = float(p["theta"]), float(p["mu"])
    if not ok(theta):
        raise SceneError(f"{scene['id']}: parameters.theta must {requirement}, got {theta!r}")
    if mu != 1.0:
        raise SceneError(f"{scene['id']}: parameters.mu: the stored asymptotics are for "
                         f"q = 0 (mu = 1), got {mu!r}")
    # the grid point nearest grazing, x1 = -1 + scale * closest, must be resolved in
    # floating point near x1 = -1 (16 ulps), or its start point cannot be placed
    closest = float(p["closest"])
    for e in p["eps"]:
        offset = scale_for(float(e), theta) * closest
        if offset < RESOLUTION:
            raise SceneError(
                f"{scene['id']}: parameters.eps: {e!r} puts the grid point xi1 = -closest at "
                f"x1 = -1 + {offset:.3g}, below the resolution of x1 near -1 (need "
                f"{'eps' if theta < 0 else 'eps^2'} * closest >= {RESOLUTION:.2g})")
    return theta


def sweep_dataset(scene: dict, theta: float, xi: np.ndarray, progress: bool) -> xr.Dataset:
    """The fields of :func:`pdm_fields` as a Dataset on (eps, xi1) (raw, no attributes)."""
    eps, xi, f = pdm_fields(scene, theta, xi, progress)
    d2 = ("eps", "xi1")
    data = {_RAW_NAME.get(k, k): (d2, f[k].astype(np.int32) if k == "n_switches" else f[k])
            for k in FIELDS}
    data["scale"] = ("eps", f["scale"])
    return xr.Dataset(data, coords={"eps": ("eps", eps), "xi1": ("xi1", xi)})


def fields_from_dataset(scene: dict, raw: xr.Dataset) -> tuple[np.ndarray, np.ndarray, dict]:
    """(eps, xi1, fields) back from :func:`sweep_dataset` on the whole grid."""
    p = scene["parameters"]
    eps, xi = eps_list(p), xi1_grid(p)
    if not (np.array_equal(raw["eps"].values, eps) and np.array_equal(raw["xi1"].values, xi)):
        raise ValueError(f"{scene['id']}: the raw fields are not on the scene's (eps, xi1) grid")
    return eps, xi, {k: raw[_RAW_NAME.get(k, k)].values for k in FIELDS + ("scale",)}


def max_error(values, reference, mask) -> np.ndarray:
    """max over the masked xi1 of |values - reference|, per eps."""
    d = np.where(mask, np.abs(values - reference), np.nan)
    return np.nanmax(d, axis=-1)


def rates(eps: np.ndarray, err: np.ndarray) -> tuple[np.ndarray, float]:
    """Local slopes d log(err)/d log(eps) between neighbours (NaN for the first)
    and the least-squares slope over the three smallest eps."""
    le, lr = np.log(eps), np.log(err)
    local = np.concatenate([[np.nan], np.diff(lr) / np.diff(le)])
    k = min(3, eps.size)
    fit = float(np.polyfit(le[-k:], lr[-k:], 1)[0]) if k >= 2 else float("nan")
    return local, fit


def base_dataset(eps, xi, f, theta: float) -> xr.Dataset:
    """Variables common to both cases (the solver's raw results)."""
    d2 = ("eps", "xi1")
    u = {"units": "1"}
    ds = xr.Dataset(
        {"P_DM": (d2, f["P"], {"long_name": "P_DM(xi1), numerical: Pi_3 o P_3 o Pi_2 o Pi_1 "
                                            "by the solver (Eq. (B.1))", **u}),
         "P_flow": (d2, f["P_flow"], {"long_name": "xi1 where the true trajectory first reaches "
                                                   "L2 (differs from P_DM where it re-crosses H_s)",
                                      **u}),
         "xi1_start": (d2, f["xi1"], {"long_name": "xi1 of the start point as represented in "
                                                   "floating point", **u}),
         "n_switches": (d2, f["n_switches"].astype(np.int32),
                        {"long_name": "mode changes of the true trajectory up to L2", **u}),
         "xi2_entry": (d2, f["xi2_entry"], {"long_name": "xi2 where the orbit meets H_s "
                                                         "(image of Pi_1), NaN: no contact", **u}),
         "excursion_time": (d2, f["excursion_time"], {
             "long_name": "duration of the first stay in region - or sliding, in units of eps",
             **u}),
         "xi1_exit": (d2, f["xi1_exit"], {"long_name": "xi1 at the end of the first excursion "
                                                       "(point p2)", **u}),
         "xi2_exit": (d2, f["xi2_exit"], {"long_name": "xi2 at p2", **u}),
         "pi3_drop": (d2, f["xi1_exit"] - f["P"], {
             "long_name": "xi1(p2) - P_DM: the decrease of xi1 under Pi_3 o P_3", **u}),
         "sliding_time": (d2, f["sliding_time"], {"long_name": "sliding time of the true "
                                                                "trajectory, in units of eps", **u}),
         "scale": ("eps", f["scale"], {"long_name": "x1 = -1 + scale xi1 (scale = eps for "
                                                    "theta < 0, eps^2 for theta > 0)", **u})},
        coords={"eps": ("eps", eps, {"long_name": "singular perturbation parameter eps", **u}),
                "xi1": ("xi1", xi, {"long_name": "rescaled x1 of a point of L2 (nominal grid)",
                                    **u})})
    pos = xi >= 0
    ds["identity_error"] = ("eps", np.nanmax(np.abs(f["P"] - f["xi1"])[:, pos], axis=1), {
        "long_name": "max |P_DM(xi1) - xi1| over xi1 >= 0", **u})
    ds["identity_error_x1"] = ("eps", ds["identity_error"].values * f["scale"], {
        "long_name": "the same in original x1 units", **u})
    ds["theta"] = ((), theta, {"long_name": "theta", **u})
    return ds
