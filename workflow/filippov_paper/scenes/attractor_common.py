"""Shared part of the small-scale instability scenes (orbit diagrams of the Hopf
example's return map to L1 across mu = 1, on the compiled engine with exact flows).

Coordinates are the paper's scales: sigma = eps (theta < 0), eps^2 (theta > 0);
s = (mu - 1)/sigma along the parameter, u = (x2 - 1)/sigma on L1. Every (theta, eps, s)
is computed on its own (one compiled call iterating the return map from the cycle's
point (0, sqrt(mu), 0)), so the s grid splits into chunks bit for bit. Beside each
slow-fast diagram the limit map of :mod:`filippov.analytic.limit_map` is iterated
on the same grid, at order 1 for each eps and at order 0 (eps -> 0).
"""
from __future__ import annotations

from typing import Protocol

import numpy as np
import xarray as xr

from filippov import attractors
from filippov_paper import tolerance
from filippov.analytic import limit_map
from filippov_paper.config import SceneError
from filippov.progress import Progress
from filippov_paper.tolerance import Tolerance
from filippov_paper.scenes.common import registered_model, require, solver_options



class HopfReturns(Protocol):
    """What the orbit-diagram scenes use of their model (``model:``): the compiled return
    map to L1 at (eps, theta, mu, omega), and the system with its section L1 (fig12's
    and fig14's periodic orbits)."""
    L1: dict

    def compiled(self, eps, theta, mu, omega, *, sliding): ...
    def system(self, eps, theta, mu, omega, *, sliding): ...


CHUNK_AXIS = "s"
ENGINES = ("compiled",)
T_RETURN = 1.0  # t_max of one return: four rotations (one return takes one)


def s_grid(p: dict) -> np.ndarray:
    """n_mu points on [s_min, s_max], and with ``n_geo`` the points of a geometric grid
    from s_max to s_geo_max beyond it (how the attractor ends away from grazing)."""
    lo, hi, n = float(p["s_min"]), float(p["s_max"]), int(p["n_mu"])
    if not lo < hi:
        raise SceneError(f"parameters.s_min < s_max required, got {lo!r}, {hi!r}")
    grid = np.linspace(lo, hi, n)
    if int(p.get("n_geo", 0)) > 0:
        top = float(p["s_geo_max"])
        if not (hi > 0 and top > hi):
            raise SceneError(f"parameters.s_geo_max: need s_geo_max > s_max > 0, got "
                             f"{top!r} and {hi!r}")
        grid = np.concatenate([grid, np.geomspace(hi, top, int(p["n_geo"]) + 1)[1:]])
    return grid


def chunk_grid(scene: dict) -> np.ndarray:
    return s_grid(scene["parameters"])


def thetas(p: dict) -> list[float]:
    return [float(t) for t in np.atleast_1d(p["theta"])]


def eps_list(p: dict) -> list[float]:
    return sorted((float(e) for e in np.atleast_1d(p["eps"])), reverse=True)


def validate(scene: dict) -> None:
    p = scene["parameters"]
    for t in thetas(p):
        for e in eps_list(p):
            try:
                attractors.check_resolvable(limit_map.scale(e, t))
            except ValueError as exc:
                raise SceneError(f"{scene['id']}: parameters.eps: {e:g} at theta = {t:g}: "
                                 f"{exc}") from None
    if int(p["n_keep"]) < 2 * int(p["max_period"]):
        raise SceneError(f"{scene['id']}: parameters.n_keep: need at least 2 max_period = "
                         f"{2 * int(p['max_period'])} kept returns to tell periods up to "
                         f"max_period, got {p['n_keep']}")
    if any(t == 0 for t in thetas(p)):
        raise SceneError(f"{scene['id']}: parameters.theta: theta = 0 is the boundary "
                         "between the two cases (no scale)")


def _model(model, p, theta, eps, s):
    """The compiled model at the sweep point s of (theta, eps) and the start there
    (``model``: the scene's model module)."""
    mu = 1.0 + s * limit_map.scale(eps, theta)
    cm = model.compiled(eps, theta, mu, float(p["omega"]), sliding=theta > 0)
    return cm, [0.0, np.sqrt(mu), 0.0]


def _settle(model, p, theta, eps, s, options, lyapunov, point=None, first=None):
    """The attractor at the sweep point s (``point``, ``first``: its model and start, and
    its first returns, already made by :func:`_first_returns`)."""
    cm, start = point if point is not None else _model(model, p, theta, eps, s)
    w = float(p["window"])
    return attractors.settle(
        cm, start, coordinate=1, transient=int(p["n_transient"]), keep=int(p["n_keep"]),
        t_max=T_RETURN, scale=limit_map.scale(eps, theta), max_period=int(p["max_period"]),
        window=(1.0 - w, 1.0 + w), lyapunov=lyapunov, first=first, **options)


def _first_returns(model, p, theta, eps, s, options, lyapunov):
    """The models and starts of every point s of (theta, eps), and their first
    n_transient + n_keep returns in one compiled call (one model at different mu, the start points spread over the cores);
    row k is what attractors.settle would make for s[k] itself, bit for bit."""
    attractors.check_resolvable(limit_map.scale(eps, theta))  # settle's refusal, first
    points = [_model(model, p, theta, eps, float(sk)) for sk in s]
    return points, attractors.iterate_sweep(
        [cm for cm, _ in points], [z for _, z in points], transient=int(p["n_transient"]),
        keep=int(p["n_keep"]), t_max=T_RETURN, jacobian=lyapunov, **options)


def sweep(scene: dict, s: np.ndarray, *, progress: bool = False) -> xr.Dataset:
    """Raw attractors on the points ``s`` (any part of the grid), per theta and eps."""
    require(scene, "system", {"slow_fast"})
    require(scene, "flow", {"exact"})
    p = scene["parameters"]
    opts = solver_options(scene)
    opts.pop("method")
    lyapunov = bool(p.get("lyapunov", False))
    model = registered_model(scene)
    th, ep, s = thetas(p), eps_list(p), np.asarray(s, dtype=float)
    keep = int(p["n_keep"])
    shape = (len(th), len(ep), s.size)
    u = np.full(shape + (keep,), np.nan)
    period, status = np.zeros(shape, dtype=np.int32), np.zeros(shape, dtype=np.int32)
    width, lyap, lyap_err = np.full(shape, np.nan), np.full(shape, np.nan), np.full(shape, np.nan)
    bar = Progress(scene["id"], int(np.prod(shape)), progress)
    for i, theta in enumerate(th):
        for j, eps in enumerate(ep):
            sigma = limit_map.scale(eps, theta)
            points, first = _first_returns(model, p, theta, eps, s, opts, lyapunov)
            for k, sk in enumerate(s):
                at = _settle(model, p, theta, eps, float(sk), opts, lyapunov, point=points[k],
                             first=attractors.row(first, k))
                u[i, j, k] = (at.values - 1.0) / sigma
                period[i, j, k] = at.period
                width[i, j, k] = at.width / sigma
                lyap[i, j, k] = at.lyapunov
                lyap_err[i, j, k] = at.lyapunov_err
                status[i, j, k] = at.status
                bar.step()
    dims = ("theta", "eps", "s")
    return xr.Dataset(
        {"u": (dims + ("k",), u), "period": (dims, period), "width": (dims, width),
         "lyapunov": (dims, lyap), "lyapunov_err": (dims, lyap_err), "status": (dims, status)},
        coords={"theta": ("theta", th), "eps": ("eps", ep), "s": ("s", s),
                "k": ("k", np.arange(keep, dtype=np.int32))})


def limit_diagrams(scene: dict, s: np.ndarray) -> dict:
    """The limit map on the same grid: order 1 per (theta, eps) and order 0 per theta
    (for theta > 0 the two coincide: no eps is left at leading order)."""
    p = scene["parameters"]
    th, ep = thetas(p), eps_list(p)
    n_tr, keep, omega = int(p["n_transient"]), int(p["n_keep"]), float(p["omega"])
    u1 = limit_map.orbits(s, th, ep, omega=omega, transient=n_tr, keep=keep, order=1)
    u0 = limit_map.orbits(s, th, ep[-1:], omega=omega, transient=n_tr, keep=keep,
                          order=0)[:, 0]
    return {"u_limit": u1, "u_limit0": u0}


def periods_of(u: np.ndarray, scale_tol: float, max_period: int) -> np.ndarray:
    """Period of each row of kept scaled values (last axis), as attractors.period_of."""
    flat = u.reshape(-1, u.shape[-1])
    out = np.array([attractors.period_of(r, scale_tol, max_period) if np.all(np.isfinite(r))
                    else 0 for r in flat], dtype=np.int32)
    return out.reshape(u.shape[:-1])


#: tolerance of a period in scaled units (u is already divided by the scale)
PERIOD_TOL = attractors.period_tolerance(1.0)

VARIABLE_ATTRS = {
    "u": ("(x2 - 1)/sigma at the kept returns to L1 (sigma = eps for theta < 0, eps^2 for "
          "theta > 0)", "1"),
    "period": ("period of the attractor: a periodic orbit found by Newton from the kept "
               "returns, stable, and approached by them (0: none up to max_period)", "1"),
    "lyapunov_err": ("standard error of lyapunov (batch means over twenty consecutive blocks "
                     "of the returns it is the mean over, filippov.attractors.LYAPUNOV_BLOCKS; "
                     "0 for a confirmed periodic orbit, whose exponent is "
                     "log of its spectral radius over its period)", "1"),
    "width": ("width of the attractor in u (max - min of the kept returns)", "1"),
    "lyapunov": ("largest Lyapunov exponent of the return map along the attractor (mean "
                 "log growth of a tangent vector under the engine's dP/dz; for a confirmed "
                 "periodic orbit log of its spectral radius over its period; NaN: not "
                 "computed or escaped)", "1"),
    "status": ("0: settled; 100: left the window; else the engine's status code of the "
               "failed return", "1"),
    "u_limit": ("u of the limit map (paper's asymptotics, order 1 in sqrt(eps))", "1"),
    "u_limit0": ("u of the limit map at order 0 (eps -> 0)", "1"),
    "period_limit": ("period of the limit map's attractor (order 1)", "1"),
    "period_limit0": ("period of the limit map's attractor (order 0)", "1"),
    "theta": ("theta, weight of the fast variable in the switching function", "1"),
    "eps": ("eps, time-scale ratio", "1"),
    "s": ("s = (mu - 1)/sigma, the scaled parameter", "1"),
    "k": ("index of the kept return", "1"),
}


def common_dataset(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    """Raw sweep plus the limit maps and their periods."""
    p = scene["parameters"]
    s = s_grid(p)
    if not np.array_equal(raw["s"].values, s):
        raise ValueError(f"{scene['id']}: the raw attractors are not on the scene's s grid")
    lim = limit_diagrams(scene, s)
    mp = int(p["max_period"])
    ds = raw.copy()
    ds["u_limit"] = (("theta", "eps", "s", "k"), lim["u_limit"])
    ds["u_limit0"] = (("theta", "s", "k"), lim["u_limit0"])
    ds["period_limit"] = (("theta", "eps", "s"), periods_of(lim["u_limit"], PERIOD_TOL, mp))
    ds["period_limit0"] = (("theta", "s"), periods_of(lim["u_limit0"], PERIOD_TOL, mp))
    ds["multiplier"] = ((), limit_map.multiplier(1.0, float(p["omega"])), {
        "long_name": "lambda = exp(-4 pi/omega), the Hopf cycle's multiplier per turn at mu = 1",
        "units": "1"})
    return ds


def lyapunov_limit(ds: xr.Dataset, omega: float) -> np.ndarray:
    """Lyapunov exponent of the limit map along its kept points, per (theta, eps, s): the
    mean log-slope by central differences of the map."""
    out = np.full(ds.period_limit.shape, np.nan)
    s = ds.s.values
    for i, theta in enumerate(ds.theta.values):
        for j, eps in enumerate(ds.eps.values):
            sl = limit_map.slopes(ds.u_limit.values[i, j], s[:, None], eps=float(eps),
                                  theta=float(theta), omega=omega)
            with np.errstate(divide="ignore"):
                out[i, j] = np.mean(np.log(np.abs(sl)), axis=1)
    return out


#: how far an end of a chaotic row's extent may move, in units of the row's width. The
#: kept points are a sample of the attractor (another machine: another orbit), and an
#: end of their extent is a sample extreme: how far it falls short of the band's edge
#: depends on the invariant density there and on how often the orbit visits it (rare
#: excursions near band mergings), not on the numerics, and not predictably on n_keep
#: (at +-2 ulps an end moved by up to 0.20 of the width at n_keep = 60 (fig12), 0.26 at
#: 40 (fig14), 0.25 at 100 (fig13): no 1/sqrt(n) law). No numerics-based bound exists;
#: the one the sampling gives: both extents lie in the same band, which the reference's
#: extent spans, so an end moves by at most about that width
EXTENT_JUMP = 1.0


def lyapunov_atol(n_keep: int) -> float:
    """Tolerance of a Lyapunov exponent, a mean of ``n_keep`` correlated log-slopes
    (standard error ~2/sqrt(n_keep)): two builds compute two independent estimates
    (two orbits), whose difference has sqrt(2) times that standard error; three of
    them."""
    return 3.0 * np.sqrt(2.0) * 2.0 / np.sqrt(n_keep)


def chaos_tolerances(scene: dict) -> dict:
    """Cross-machine tolerances where the attractor may be chaotic (filippov_paper.tolerance).
    There a last-bit change is amplified by e^(lambda n) over the n returns of the run
    (lambda up to ~0.6: e^180 after 300): the kept points belong to another orbit on the
    same attractor. Points are therefore compared by each row's extent (rule attractor,
    an end within the row's width, EXTENT_JUMP: a sampled statistic); the exponent,
    a mean of log-slopes whose logs spread by about one (slopes lambda and lambda s), by
    three standard errors of the difference of two such means (lyapunov_atol); the
    width (max - min) to the sum of its two ends' tolerances (width_tolerance). Periodic
    rows (width 0) keep the close tolerance of their points, 10 x EVENT_STATE / sigma_min in u. The
    classifications (period) may change at a few points near a boundary between types
    (at most one in fifty)."""
    p = scene["parameters"]
    sigma = min(limit_map.scale(e, t) for e in eps_list(p) for t in thetas(p))
    u_atol = 10 * tolerance.EVENT_STATE / sigma
    stat = "a sampled statistic of a chaotic orbit (another orbit on another machine)"
    keep = int(p["n_keep"])
    pts = Tolerance(0.0, u_atol, f"{stat}: a chaotic orbit's points are not reproducible, "
                                 "only where they lie: each row's extent, an end being a "
                                 "sample extreme (set by the density at the band's edge and "
                                 "the orbit's visits there, not by the numerics): within the "
                                 "width of the band both samples lie in", rule="attractor",
                    jump=EXTENT_JUMP)
    lim = Tolerance(0.0, 1e-9, "limit map (numpy): chaotic where lambda s < -1; each row's "
                               "extent, to half its width", rule="attractor", jump=0.5)
    mean = Tolerance(0.0, lyapunov_atol(keep),
                     f"{stat}: mean of n_keep correlated log-slopes, standard error "
                     f"~2/sqrt(n_keep) (per-return spread ~1, correlated over a few "
                     f"returns); two builds' means are independent estimates, their "
                     f"difference sqrt(2) times that; three of those: 6 sqrt(2)/sqrt(n_keep)")
    n_pts = len(thetas(p)) * len(eps_list(p)) * len(s_grid(p))
    kind = Tolerance(0.0, 0.0, "a classification: points at a boundary of types (or with "
                               "an exponent within sampling error of 0) may change",
                     rule="tangency", changed=max(1, n_pts // 50), jump=100.0)
    return {"period": kind, "period_limit": kind, "period_limit0": kind,
            "u": pts, "u_limit": lim, "u_limit0": lim, "lyapunov": mean,
            "lyapunov_limit": mean,
            "lyapunov_err": Tolerance(1.0, lyapunov_atol(keep),
                                      f"{stat}: spread of block means, itself sampled"),
            "width": width_tolerance(pts, stat)}


def width_tolerance(points: Tolerance, stat: str, atol: float | None = None) -> Tolerance:
    """The tolerance of a row's width, max - min of its kept points, implied by the
    ``points``' rule ``attractor``: each end may move by ``points.atol`` plus
    ``points.jump`` times the width, and the two ends independently (another orbit
    samples each edge of the band anew), so the width by twice that: rtol 2 jump,
    atol 2 points.atol (``atol``: instead, in other units, e.g. x2 = u eps^2)."""
    if points.rule != "attractor":
        raise ValueError(f"width_tolerance: points compared by rule 'attractor', got "
                         f"{points.rule!r}")
    atol = 2 * points.atol if atol is None else atol
    return Tolerance(2 * points.jump, atol,
                     f"{stat}: max - min of the kept points, each end within its sampling "
                     f"error (the points' rule attractor: jump times the width each): "
                     f"2 jump of the width")
