"""Period-adding cascade (theta < 0): the attractor of the return map to L1 of the
slow-fast Hopf example across mu = 1, for several eps, beside the limit map.

Orbit diagram in s = (mu - 1)/eps, u = (x2 - 1)/eps (attractor_common). On top of
the shared sweep this scene locates the windows of the cascade: for each period n of
``window_periods`` the first window of period n on the grid (scanning s upwards); its
periodic orbit is followed in s from the window's middle, down and up (Newton on
P^n(z) - z with the engine's dP/dz; branches.follow), and the ends of its stability --
a period doubling, a border collision at grazing, a fold -- are located by bisection to
``edge_tol`` in s: bifurcation points, not basin boundaries, so where two windows'
orbits are stable at once (hysteresis) both edges are seen. The same on the order-1
limit map for the same eps and on the order-0 limit map (eps -> 0). The edges at
eps <= ``fit_eps_max`` are then fitted by edge = A + B eps^(1/2) (the order-1 term of
P_DM is of order sqrt(eps) relative to the order-0 jump) and by edge = A + B eps; the
intercepts are compared with the order-0 edges.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov import attractors
from filippov.analytic import limit_map
from filippov import branches
from filippov.fastmap import OK, compute_returns
from filippov.io import finalize
from filippov.periodic import periodic_orbit
from filippov_paper.scenes.attractor_common import (CHUNK_AXIS, ENGINES, HopfReturns as MODEL, chunk_grid, PERIOD_TOL, T_RETURN,  # noqa: F401
                               VARIABLE_ATTRS as _COMMON_ATTRS, _settle, chaos_tolerances,
                               common_dataset, eps_list, s_grid, sweep, thetas, validate)
from filippov_paper.scenes.common import registered_model, solver_options
from filippov_paper import tolerance
from filippov_paper.tolerance import Tolerance
from filippov_paper.report import Macros, eps_tex, head, num, source, tabular, value

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "required": ["eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_transient", "n_keep",
                   "max_period", "window", "lyapunov", "window_periods", "edge_tol", "fit_eps_max"],
      "$ref": "#/$defs/attractor_sweep",
      "propertyNames": {"enum": [
        "eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_transient", "n_keep", "max_period",
        "window", "lyapunov", "window_periods", "edge_tol", "fit_eps_max"
      ]},
      "properties": {
        "eps": {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1}},
        "theta": {"type": "number", "exclusiveMaximum": 0, "minimum": -5},
        "s_max": {"type": "number"},
        "window_periods": {"type": "array", "minItems": 1, "items": {"type": "integer", "minimum": 1}},
        "edge_tol": {"type": "number", "exclusiveMinimum": 0},
        "fit_eps_max": {"type": "number", "exclusiveMinimum": 0}
      }
    }
  }
}

VARIABLE_ATTRS = dict(_COMMON_ATTRS)
VARIABLE_ATTRS.update({
    "n": ("period of the window", "1"),
    "side": ("0: left edge (smaller s), 1: right edge", "1"),
    "edge": ("edge in s of the first window of period n, slow-fast system: where its "
             "orbit, followed from inside the window, stops being stable (NaN: stable to "
             "the end of the grid or no window)", "1"),
    "edge_kind": ("how the window's orbit ends there: -1 period doubling, 0 border "
                  "collision (an orbit point reaches grazing), 1 fold, 2 stable to the end "
                  "of the grid, 3 torus, -9 no window on the grid", "1"),
    "edge_multiplier": ("multiplier of the window's orbit at its last stable point", "1"),
    "edge_limit": ("edge in s of the first window of period n, limit map order 1 "
                   "(followed orbit)", "1"),
    "edge_limit_kind": ("as edge_kind, limit map order 1", "1"),
    "edge_limit0": ("edge in s of the first window of period n, limit map order 0 "
                    "(eps -> 0, followed orbit)", "1"),
    "edge_limit0_kind": ("as edge_kind, limit map order 0", "1"),
    "coexistence": ("right edge of the window of n + 1 minus left edge of the window of "
                    "n: > 0 both orbits stable there (hysteresis), < 0 a gap", "1"),
    "fit_sqrt_A": ("intercept A of edge = A + B eps^(1/2) over eps <= fit_eps_max", "1"),
    "fit_sqrt_B": ("slope B of edge = A + B eps^(1/2)", "1"),
    "fit_sqrt_rms": ("rms residual of edge = A + B eps^(1/2)", "1"),
    "fit_lin_A": ("intercept A of edge = A + B eps", "1"),
    "fit_lin_B": ("slope B of edge = A + B eps", "1"),
    "fit_lin_rms": ("rms residual of edge = A + B eps", "1"),
    "edge_gap": ("largest |edge - edge_limit| over the windows: slow-fast against the "
                 "order-1 limit map", "1"),
})


def _fit_weights(x: np.ndarray) -> np.ndarray:
    """sum |c_i| of the least-squares intercept and slope, A = sum c_i y_i (rows): how
    far a change of each edge by one unit can move them."""
    M = np.stack([np.ones_like(x), x], axis=1)
    return np.abs(np.linalg.pinv(M)).sum(axis=1)


def tolerances(scene: dict) -> dict:
    """Cross-machine tolerances (filippov_paper.tolerance). Away from the jump the map
    contracts (slope lambda < 1), but next to it, on the side where the orbit crosses
    H, the sqrt(eps) term of P_DM makes its slope unbounded: at the larger eps orbits
    that pass close to the jump separate, and where no period is found (between the
    windows) the attractor is chaotic. Points, widths and periods are therefore
    compared as in attractor_common.chaos_tolerances.

    The window edges are bifurcation points of the followed orbits (branches.follow),
    not basin edges, so they do not depend on which attractor a start falls into.
    Bisected to edge_tol; a last-bit change moves a border collision by the rounding of
    the grazing point in u (EVENT_STATE/eps) over du/ds of the orbit point (>= 0.1 on
    every window, fig12 data): 10 EVENT_STATE/eps_min; a flip by the rounding of the
    multiplier over its slope in s (steep near grazing: less). The fits carry the
    edges' tolerance through their least-squares weights."""
    p = scene["parameters"]
    eps = np.array(eps_list(p))
    tol_e = float(p["edge_tol"])
    e_atol = 2 * tol_e + 10 * tolerance.EVENT_STATE / float(eps.min())
    edge = Tolerance(0.0, e_atol, "bisection to edge_tol (twice: one midpoint's verdict "
                     "may flip) plus the rounding of the grazing point in s, "
                     "10 EVENT_STATE/eps_min")
    lim = Tolerance(0.0, 2 * tol_e, "limit map (numpy, closed-form slopes): bisection to "
                    "edge_tol, one midpoint's verdict may flip")
    out = chaos_tolerances(scene)
    del out["lyapunov_limit"]  # not computed here
    kind = Tolerance(0.0, 0.0, "the kind of a bifurcation: discrete, decided by the sign "
                     "and size of a multiplier away from its threshold")
    out.update({"edge": edge, "edge_limit": lim, "edge_limit0": lim,
                "edge_kind": kind, "edge_limit_kind": kind, "edge_limit0_kind": kind,
                "edge_multiplier": Tolerance(0.0, 1e-2, "the multiplier at the last stable "
                                             "point, within edge_tol of the edge: at a flip "
                                             "near grazing it changes fast with s"),
                "coexistence": Tolerance(0.0, 2 * e_atol, "difference of two edges"),
                "edge_gap": Tolerance(0.0, e_atol + 2 * tol_e, "slow-fast and limit-map "
                                      "edges"),
                "fit_sqrt_rms": Tolerance(0.0, e_atol, "residual of edges known to that"),
                "fit_lin_rms": Tolerance(0.0, e_atol, "residual of edges known to that")})
    fitted = eps[eps <= float(p["fit_eps_max"])]
    if fitted.size >= 2:
        for name, x in (("sqrt", np.sqrt(fitted)), ("lin", fitted)):
            # three digits: the weights come through LAPACK, whose last bits vary
            wa, wb = (float(f"{w:.3g}") for w in _fit_weights(x))
            out[f"fit_{name}_A"] = Tolerance(0.0, wa * e_atol, "intercept: its least-squares "
                                             "weights times the edges' tolerance")
            out[f"fit_{name}_B"] = Tolerance(0.0, wb * e_atol, "slope: its least-squares "
                                             "weights times the edges' tolerance")
    return out


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def _fit(x: np.ndarray, y: np.ndarray):
    """Least squares y = A + B x over the finite points: (A, B, rms); NaN with < 3."""
    ok = np.isfinite(y)
    if ok.sum() < 3:
        return np.nan, np.nan, np.nan
    M = np.stack([np.ones(ok.sum()), x[ok]], axis=1)
    (a, b), *_ = np.linalg.lstsq(M, y[ok], rcond=None)
    return float(a), float(b), float(np.sqrt(np.mean((M @ [a, b] - y[ok]) ** 2)))


def _slow_fast_orbit_at(model, p: dict, theta: float, eps: float, n: int, options: dict):
    """orbit_at(s, guess) for branches.follow: the period-n orbit of the slow-fast return
    map to L1 at mu = 1 + s eps (Newton with the engine's dP/dz), its largest nontrivial
    multiplier and its itinerary: the number of switches on each of its n returns
    (``model``: the scene's model module, :class:`HopfReturns`)."""
    omega = float(p["omega"])

    def at(s, guess):
        mu = 1.0 + s * eps
        system = model.system(eps, theta, mu, omega, sliding=False)
        orbit = periodic_orbit(system, guess, model.L1["section"], returns=n,
                               direction=model.L1["direction"], where=model.L1["where"],
                               engine="compiled", t_max=T_RETURN, **options)
        cm = system.compiled(**model.L1)
        run = attractors.iterate(cm, orbit.point, transient=0, keep=n, t_max=T_RETURN,
                                 **options)
        points = np.concatenate([orbit.point[None], run.orbit[0, :-1]])
        _distinct(points[:, 1] / eps, n, s)
        points = points[_phase(points[:, 1], guess[1]):]  # Newton may land on another
        points = np.concatenate([points, run.orbit[0, :n - len(points)]])  # of its points
        one = compute_returns(cm, points, T_RETURN, **options)
        if np.any(one.status != OK):
            raise RuntimeError(f"a return of the period-{n} orbit at s = {s!r} failed")
        return branches.Orbit(points[0], float((points[0, 1] - 1.0) / eps),
                              complex(orbit.multipliers[1]),
                              tuple(int(k) for k in one.n_switches))
    return at


def _limit_orbit_at(theta: float, eps: float, omega: float, n: int, order: int):
    """orbit_at(s, guess) for branches.follow on the limit map (limit_map.cycle)."""
    def at(s, guess):
        u = float(np.asarray(guess).reshape(-1)[0])
        points, mult = limit_map.cycle(u, s, n, eps=eps, theta=theta, omega=omega,
                                       order=order)
        _distinct(points, n, s)
        points = np.roll(points, -_phase(points, u))
        return branches.Orbit(points[:1].copy(), float(points[0]), complex(mult),
                              limit_map.itinerary(points, s, eps=eps, theta=theta,
                                                  omega=omega, order=order))
    return at


def _phase(values: np.ndarray, guess: float) -> int:
    """Index of the orbit point nearest the guess: Newton from the last orbit's point may
    converge to the same orbit at another of its points, and the follower compares
    itineraries point by point from the one it started with."""
    return int(np.argmin(np.abs(np.asarray(values) - guess)))


def _distinct(u: np.ndarray, n: int, s: float) -> None:
    """Refuse an 'orbit of period n' whose points repeat with a shorter period (Newton on
    P^n - z also converges to the fixed points of P^d, d | n)."""
    for d in range(1, n):
        if n % d == 0 and np.all(np.abs(u[d:] - u[:-d]) <= PERIOD_TOL):
            raise ValueError(f"the period-{n} orbit at s = {s!r} has period {d}")


def window_edges(orbit_at, grid, periods, n: int, start_state, xtol: float):
    """The first window of period n on the grid, its orbit followed from the window's
    middle grid point down and up in s (branches.follow): ((left, right), (kind_l,
    kind_r), (multiplier at the left end, at the right end)); NaN / BEYOND where the
    orbit stays stable to the end of the grid, NOT_FOUND where the grid has no window."""
    w = attractors.first_window(periods, n)
    if w is None:
        return (np.nan, np.nan), (NOT_FOUND, NOT_FOUND), (np.nan, np.nan)
    mid = (w[0] + w[1]) // 2
    s0 = float(grid[mid])
    step = float(grid[1] - grid[0])
    ends = [branches.follow(orbit_at, s0, start_state(s0), lim, step=step, xtol=xtol,
                            near=NEAR) for lim in (float(grid[0]), float(grid[-1]))]
    return (tuple(e.parameter for e in ends), tuple(e.kind for e in ends),
            tuple(float(np.real(e.inside.multiplier)) for e in ends))


#: edge_kind where the grid shows no window of that period
NOT_FOUND = -9
#: a followed orbit whose point moves by more than this in u between two parameters is
#: another orbit (Newton across a border): the windows' orbits move by ~0.3 in u per unit
#: of s (fig12 data), the continuation steps are one grid step (0.025) or less
NEAR = 0.5


def _coexistence(ns: list, edge: np.ndarray) -> np.ndarray:
    """Per eps and n: right edge of the window of n + 1 minus left edge of the window of
    n (the cascade falls with s: window n + 1 lies left of window n). Positive: both
    orbits are stable on that interval (hysteresis); negative: neither is, and other
    attractors fill the gap; NaN where n + 1 is not followed or an edge is missing."""
    out = np.full(edge.shape[:2], np.nan)
    for m, n in enumerate(ns):
        if n + 1 in ns:
            out[:, m] = edge[:, ns.index(n + 1), 1] - edge[:, m, 0]
    return out


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = scene["parameters"]
    ds = common_dataset(scene, raw)
    (theta,) = thetas(p)
    eps, s = eps_list(p), s_grid(p)
    ns = [int(n) for n in p["window_periods"]]
    tol = float(p["edge_tol"])
    omega, n_tr = float(p["omega"]), int(p["n_transient"])
    opts = solver_options(scene)
    opts.pop("method")
    model = registered_model(scene)

    def limit_start(e, order):
        return lambda x: limit_map.orbit([x], eps=e, theta=theta, omega=omega,
                                         transient=n_tr, keep=1, order=order)[0]

    shape = (len(eps), len(ns), 2)
    edge, kind, mult = np.full(shape, np.nan), np.full(shape, NOT_FOUND, np.int32), \
        np.full(shape, np.nan)
    edge_lim, kind_lim = np.full(shape, np.nan), np.full(shape, NOT_FOUND, np.int32)
    for j, e in enumerate(eps):
        def sf_start(x, e=e):
            return _settle(model, p, theta, e, x, opts, False).states[-1]
        for m, n in enumerate(ns):
            edge[j, m], kind[j, m], mult[j, m] = window_edges(
                _slow_fast_orbit_at(model, p, theta, e, n, opts), s, ds.period.values[0, j], n,
                sf_start, tol)
            edge_lim[j, m], kind_lim[j, m], _ = window_edges(
                _limit_orbit_at(theta, e, omega, n, 1), s, ds.period_limit.values[0, j], n,
                limit_start(e, 1), tol)
    edge0, kind0 = np.full((len(ns), 2), np.nan), np.full((len(ns), 2), NOT_FOUND, np.int32)
    for m, n in enumerate(ns):
        edge0[m], kind0[m], _ = window_edges(
            _limit_orbit_at(theta, eps[-1], omega, n, 0), s, ds.period_limit0.values[0], n,
            limit_start(eps[-1], 0), tol)
    fits = {k: np.full((len(ns), 2), np.nan) for k in (
        "fit_sqrt_A", "fit_sqrt_B", "fit_sqrt_rms", "fit_lin_A", "fit_lin_B", "fit_lin_rms")}
    ea = np.array(eps)
    fitted = ea <= float(p["fit_eps_max"])
    for m in range(len(ns)):
        for side in (0, 1):
            y = np.where(fitted, edge[:, m, side], np.nan)
            fits["fit_sqrt_A"][m, side], fits["fit_sqrt_B"][m, side], \
                fits["fit_sqrt_rms"][m, side] = _fit(np.sqrt(ea), y)
            fits["fit_lin_A"][m, side], fits["fit_lin_B"][m, side], \
                fits["fit_lin_rms"][m, side] = _fit(ea, y)
    ds = ds.assign_coords(n=("n", np.array(ns, dtype=np.int32)),
                          side=("side", np.array([0, 1], dtype=np.int32)))
    ds["edge"] = (("eps", "n", "side"), edge)
    ds["edge_limit"] = (("eps", "n", "side"), edge_lim)
    ds["edge_limit0"] = (("n", "side"), edge0)
    ds["edge_kind"] = (("eps", "n", "side"), kind)
    ds["edge_multiplier"] = (("eps", "n", "side"), mult)
    ds["edge_limit_kind"] = (("eps", "n", "side"), kind_lim)
    ds["edge_limit0_kind"] = (("n", "side"), kind0)
    ds["coexistence"] = (("eps", "n"), _coexistence(ns, edge))
    for k, v in fits.items():
        ds[k] = (("n", "side"), v)
    gap = np.abs(edge - edge_lim).reshape(len(eps), -1)
    ds["edge_gap"] = ("eps", np.array([np.nanmax(g) if np.isfinite(g).any() else np.nan
                                       for g in gap]))
    return finalize(ds, scene, engine="compiled", method="exact",
                    title="period-adding cascade of the slow-fast Hopf example, theta < 0")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
_REPORT_WORD = {2: "Two", 3: "Three", 4: "Four", 5: "Five", 6: "Six"}


#: superscripts of the table's edges: how the window's orbit ends (branches kinds)
_REPORT_KIND = {-1: r"^{\mathrm{d}}", 0: r"^{\mathrm{b}}", 1: r"^{\mathrm{f}}",
                3: r"^{\mathrm{t}}"}


def _report_edge_cell(pair, kinds=(None, None)) -> str:
    return " & ".join("--" if not np.isfinite(v) else
                      f"${num(float(v), 3)}{_REPORT_KIND.get(k, '') if k is not None else ''}$"
                      for v, k in zip(pair, kinds))


def _report_table(ds) -> str:
    """Window edges in s per eps (slow-fast), the eps -> 0 limit map and the fits
    (left edges: A of A + B eps; right edges: A of A + B sqrt(eps))."""
    ns = [int(n) for n in ds.n.values]
    rows = []
    for j, e in enumerate(ds.eps.values):
        rows.append(" & ".join([f"${eps_tex(float(e))}$",
                                *(_report_edge_cell(ds.edge.values[j, m],
                                                    ds.edge_kind.values[j, m])
                                  for m in range(len(ns)))])
                    + r" \\")
    rows.append(r"\midrule")
    rows.append(" & ".join([r"$\to 0$", *(_report_edge_cell(ds.edge_limit0.values[m],
                                                             ds.edge_limit0_kind.values[m])
                                          for m in range(len(ns)))]) + r" \\")
    fit = [(ds.fit_lin_A.values[m, 0], ds.fit_sqrt_A.values[m, 1]) for m in range(len(ns))]
    rows.append(" & ".join(["fit", *(_report_edge_cell(f) for f in fit)]) + r" \\")
    top = " & ".join(["", *(rf"\multicolumn{{2}}{{c}}{{$n={n}$}}" for n in ns)]) + r" \\"
    return tabular("r" + "rr" * len(ns), [top, head(r"$\epsilon$", *(["left", "right"] * len(ns)))],
                   rows)


def report(ds, m: Macros) -> str | None:
    sid = "fig12_period_adding"
    eps = [float(e) for e in ds.eps.values]
    theta = float(ds.theta.values[0])
    m.add("rpTwelveTheta", theta, source(sid, "theta", theta=theta))
    m.add("rpTwelveEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpTwelveEpsMin", eps[-1], f"{sid}:eps[-1]")
    m.add("rpTwelveNEps", len(eps), f"{sid}:eps (size)")
    m.add("rpTwelveSMin", float(ds.attrs["s_min"]), f"{sid}:attrs.s_min")
    m.add("rpTwelveSMax", float(ds.attrs["s_max"]), f"{sid}:attrs.s_max")
    m.add("rpTwelveNMu", ds.sizes["s"], f"{sid}:s (size)")
    m.add("rpTwelveNTransient", float(ds.attrs["n_transient"]), f"{sid}:attrs.n_transient")
    m.add("rpTwelveNKeep", float(ds.attrs["n_keep"]), f"{sid}:attrs.n_keep")
    m.add("rpTwelveEdgeTol", float(ds.attrs["edge_tol"]), f"{sid}:attrs.edge_tol", 1)
    m.add("rpTwelveFitEpsMax", float(ds.attrs["fit_eps_max"]), f"{sid}:attrs.fit_eps_max", 1)
    m.add("rpTwelveMultiplier", value(ds, "multiplier"), source(sid, "multiplier"), 4)
    # below grazing the attractor is the cycle's point, u = (sqrt(mu) - 1)/eps
    s = ds.s.values
    below = s < 0
    per = ds.period.values[0]
    m.add("rpTwelveBelowEvery", None, "derived: period == 1 for every s < 0 and eps",
          text=r"\text{every}" if np.all(per[:, below] == 1) else r"\text{\emph{not} every}")
    onset = [float(s[np.flatnonzero((s > 0) & (per[j] != 1))[0]]) for j in range(len(eps))]
    m.add("rpTwelveOnsetMax", max(onset), "derived: largest first s > 0 with period != 1", 2)
    _report_sequence(ds, m, s, per, eps)
    lin_l = float(np.nanmax(ds.fit_lin_rms.values[:, 0]))
    sq_r = float(np.nanmax(ds.fit_sqrt_rms.values[:, 1]))
    # each window's two fits compared with each other (residuals differ by decades across n)
    ratio = ds.fit_sqrt_rms.values / ds.fit_lin_rms.values
    m.add("rpTwelveLeftLinRms", lin_l, "derived: max fit_lin_rms over n, left edges", 2)
    m.add("rpTwelveRightSqrtRms", sq_r, "derived: max fit_sqrt_rms over n, right edges", 2)
    m.add("rpTwelveLeftRatioMin", float(np.nanmin(ratio[:, 0])), "derived: min over n of "
          "fit_sqrt_rms / fit_lin_rms, left edges", 2)
    m.add("rpTwelveRightRatioMax", float(np.nanmax(ratio[:, 1])), "derived: max over n of "
          "fit_sqrt_rms / fit_lin_rms, right edges", 2)
    e0 = ds.edge_limit0.values
    m.add("rpTwelveLeftAErr", float(np.nanmax(np.abs(ds.fit_lin_A.values[:, 0] - e0[:, 0]))),
          "derived: max |fit_lin_A - edge_limit0|, left edges", 2)
    m.add("rpTwelveRightAErr", float(np.nanmax(np.abs(ds.fit_sqrt_A.values[:, 1] - e0[:, 1]))),
          "derived: max |fit_sqrt_A - edge_limit0|, right edges", 2)
    m.add("rpTwelveRightBMax", float(np.nanmax(ds.fit_sqrt_B.values[:, 1])),
          "derived: max fit_sqrt_B, right edges", 3)
    m.add("rpTwelveRightBMin", float(np.nanmin(ds.fit_sqrt_B.values[:, 1])),
          "derived: min fit_sqrt_B, right edges", 3)
    m.add("rpTwelveGapFirst", float(ds.edge_gap.values[0]), source(sid, "edge_gap", eps=eps[0]), 2)
    m.add("rpTwelveGapLast", float(ds.edge_gap.values[-1]), source(sid, "edge_gap", eps=eps[-1]), 2)
    g = ds.edge_gap.values
    ok = np.isfinite(g) & (np.array(eps) <= float(ds.attrs["fit_eps_max"]))
    rate = np.polyfit(np.log(np.array(eps)[ok]), np.log(g[ok]), 1)[0]
    m.add("rpTwelveGapRate", float(rate), "derived: slope of log edge_gap vs log eps, "
          "eps <= fit_eps_max", 2)
    for k, n in enumerate(ds.n.values):
        w = _REPORT_WORD.get(int(n))
        if w:
            m.add(f"rpTwelveLeftZero{w}", float(e0[k, 0]), source(sid, "edge_limit0", n=int(n), side=0), 4)
            m.add(f"rpTwelveRightZero{w}", float(e0[k, 1]), source(sid, "edge_limit0", n=int(n), side=1), 4)
    _report_bifurcations(ds, m, sid)
    return _report_table(ds)


def _report_list(items: list) -> str:
    """'a', 'a and b', 'a, b and c' in math mode; none: the word."""
    if not items:
        return r"\text{none}"
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + r"\text{ and }" + items[-1]


def _report_pairs(ds) -> list:
    """Per eps (dataset order): [(n + 1, n, coexistence)] for every n whose coexistence
    is known (right edge of the window of n + 1 minus left edge of the window of n;
    > 0: both orbits stable there, < 0: a gap), in the order of n."""
    c, ns = ds.coexistence.values, [int(n) for n in ds.n.values]
    return [[(n + 1, n, float(c[j, m])) for m, n in enumerate(ns) if np.isfinite(c[j, m])]
            for j in range(ds.eps.size)]


def _report_coexist_sentence(ds) -> str:
    """For each eps: which neighbouring windows overlap (both orbits stable) and by how
    much, which are separated by a gap and how wide, generated from ``coexistence``."""
    from filippov_paper.report import count_word
    eps = [float(e) for e in ds.eps.values]
    ns = [int(n) for n in ds.n.values]

    def say(group, lead, verb):
        # overlap: 'a and b overlap by x, c and d by y'; gap: 'a and b are x apart, c and d y'
        def one(k, a, b, v):
            x, names = f"${num(abs(v), 2)}$", f"{count_word(a)} and {count_word(b)}"
            if verb == "overlap":
                return names + (" overlap" if k == 0 else "") + f" by {x}"
            return names + (f" are {x} apart" if k == 0 else f" {x}")
        items = [one(k, a, b, v) for k, (a, b, v) in enumerate(group)]
        joined = items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]
        return f"{lead} {joined}"
    clauses = []
    for j, pairs in enumerate(_report_pairs(ds)):
        over = [(a, b, v) for a, b, v in pairs if v > 0]
        gap = [(a, b, v) for a, b, v in pairs if v <= 0]
        parts = []
        if over:
            parts.append(say(over, "the windows of periods", "overlap"))
        if gap:
            parts.append(say(gap, "those of periods" if over else "the windows of periods",
                             "apart"))
        text = rf"at $\epsilon={eps_tex(eps[j])}$ " + (", ".join(parts) if parts else
                                                       "no pair of windows has both edges")
        absent = [n for m, n in enumerate(ns) if n + 1 in ns
                  and not np.isfinite(ds.coexistence.values[j, m])]
        if absent:
            why = []
            for n in absent:
                for k, side in ((n + 1, 1), (n, 0)):
                    kind = int(ds.edge_kind.values[j, ns.index(k), side])
                    if kind == -9:
                        why.append(f"no window of period {count_word(k)} on the grid")
                    elif not np.isfinite(ds.edge.values[j, ns.index(k), side]):
                        why.append(f"the window of period {count_word(k)} reaches the end "
                                   "of the grid")
            text += " (" + "; ".join(dict.fromkeys(why)) + ")"
        clauses.append(text)
    return "; ".join(clauses)


def _report_back(s, per) -> float:
    """First s > 0 from which the period is one up to the end of the grid (NaN: none)."""
    for k in range(s.size):
        if s[k] > 0 and np.all(per[k:] == 1):
            return float(s[k])
    return np.nan


def _report_sequence(ds, m: Macros, s, per, eps) -> None:
    """Past the window of period two: the periods rise again until the period-one orbit
    is back; where (per eps) and how high the periods go at the smallest eps."""
    back = [_report_back(s, per[j]) for j in range(len(eps))]
    found = [j for j in range(len(eps)) if np.isfinite(back[j])]
    m.add("rpTwelveBackEps", None, "derived: eps at which period one is back on the grid",
          text=_report_list([eps_tex(eps[j]) for j in found]))
    m.add("rpTwelveNotBackEps", None, "derived: eps at which period one is not back",
          text=_report_list([eps_tex(eps[j]) for j in range(len(eps)) if j not in found]))
    m.add("rpTwelveBackSmall", back[-1], "derived: first s from which period == 1 to s_max, "
          "smallest eps", 3)
    if found:
        m.add("rpTwelveBackMax", float(np.nanmax(back)), "derived: max over eps of that s", 3)
    j = len(eps) - 1
    right2 = float(ds.edge.values[j, list(ds.n.values).index(2), 1]) \
        if 2 in ds.n.values else np.nan
    rise = per[j][(s > right2) & (s < back[j])] if np.isfinite(right2 + back[j]) else []
    m.add("rpTwelveRiseMax", float(np.max(rise)) if len(rise) else np.nan,
          "derived: largest period between the right edge of the window of two and the "
          "return of period one, smallest eps", 3)
    m.add("rpTwelveBackZero", _report_back(s, ds.period_limit0.values[0]),
          "derived: first s from which period_limit0 == 1 to s_max", 3)


def _report_bifurcations(ds, m: Macros, sid: str) -> None:
    """How the windows end, and where neighbouring windows overlap or leave a gap."""
    from filippov.branches import BORDER, FLIP

    def every(kinds, kind):   # over the edges that lie on the grid (not BEYOND/no window)
        k = np.asarray(kinds).ravel()
        k = k[np.isin(k, [-1, 0, 1, 3])]
        return bool(k.size) and bool(np.all(k == kind))

    left, right = ds.edge_kind.values[..., 0], ds.edge_kind.values[..., 1]
    m.add("rpTwelveLeftKind", None, "derived: edge_kind == -1 at every left edge on the grid",
          text=r"\text{every}" if every(left, FLIP) else r"\text{\emph{not} every}")
    m.add("rpTwelveRightKind", None, "derived: edge_kind == 0 at every right edge on the grid",
          text=r"\text{every}" if every(right, BORDER) else r"\text{\emph{not} every}")
    m.add("rpTwelveZeroKind", None, "derived: edge_limit0_kind == 0 at every edge",
          text=r"\text{every}" if every(ds.edge_limit0_kind.values, BORDER)
          else r"\text{\emph{not} every}")
    mult = np.abs(ds.edge_multiplier.values[..., 0][left == FLIP] + 1.0)
    m.add("rpTwelveFlipMultErr", float(mult.max()), "derived: max |edge_multiplier + 1| "
          "over the left edges", 1)
    border = np.abs(ds.edge_multiplier.values[..., 1][right == BORDER])
    m.add("rpTwelveBorderMultMax", float(border.max()), "derived: max |edge_multiplier| "
          "over the right edges", 2)
    m.add("rpTwelveCoexistSentence", None, "derived: coexistence per eps and n, its sign "
          "and size", text=_report_coexist_sentence(ds))


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "theta"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"eps": [0.01, 0.001], "n_mu": 7, "n_transient": 40, "n_keep": 20,
              "max_period": 10}
