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

from filippov import attractors
from filippov.analytic import limit_map
from filippov.io import finalize
from filippov.periodic import PeriodicOrbitError, periodic_orbit
from filippov_paper.tolerance import Tolerance
from filippov_paper.scenes.attractor_common import (CHUNK_AXIS, ENGINES, HopfReturns as MODEL, chunk_grid, T_RETURN,  # noqa: F401
                               VARIABLE_ATTRS as _COMMON_ATTRS, chaos_tolerances,
                               common_dataset, lyapunov_limit, s_grid, sweep, validate)
from filippov_paper.scenes.common import registered_model
from filippov_paper.report import Macros, source, value

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "required": ["eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_transient", "n_keep",
                   "max_period", "window", "lyapunov", "boundary_eps", "boundary_s"],
      "$ref": "#/$defs/attractor_sweep",
      "propertyNames": {"enum": [
        "eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_transient", "n_keep", "max_period",
        "window", "lyapunov", "boundary_eps", "boundary_s"
      ]},
      "properties": {
        "eps": {"type": "array", "minItems": 1, "maxItems": 1, "items": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1}},
        "theta": {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": -5, "exclusiveMaximum": 1}},
        "s_max": {"type": "number"},
        "boundary_eps": {"type": "array", "minItems": 1, "items": {"type": "number", "minimum": 1e-5, "maximum": 0.01}},
        "boundary_s": {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0, "maximum": 10}}
      }
    }
  }
}

#: attractor types besides a period n >= 1
CHAOTIC, APERIODIC, ESCAPED = 0, -1, -2

VARIABLE_ATTRS = dict(_COMMON_ATTRS)
VARIABLE_ATTRS.update({
    "attractor_type": ("n >= 1: period n (a confirmed, stable periodic orbit); 0: chaotic "
                       "(no period, Lyapunov exponent above three standard errors); -1: no "
                       "period, exponent not positive beyond its error; -2: escaped", "1"),
    "attractor_type_limit": ("attractor_type of the limit map (order 1 at the scene's eps)",
                             "1"),
    "lyapunov_limit": ("Lyapunov exponent of the limit map along its attractor", "1"),
    "theta_critical": ("theta where lambda s(theta,0,0) = -1: lambda/(1 + lambda)", "1"),
    "theta_chaos": ("theta where lambda^2 s(theta,0,0) = -1: lambda^2/(1 + lambda^2), the "
                    "normal form's end of the period-two orbit", "1"),
    "theta_flip_limit": ("theta where the limit map's period-one orbit has the multiplier "
                         "-1 (order 1 at the scene's eps)", "1"),
    "theta_chaos_limit": ("theta where the limit map's period-two orbit has the multiplier "
                          "-1 (order 1 at the scene's eps)", "1"),
    "theta_flip": ("theta where the slow-fast period-one orbit has the multiplier -1 "
                   "(Newton on P(z) - z with the engine's dP/dz)", "1"),
    "theta_chaos_flip": ("theta where the slow-fast period-two orbit has the multiplier -1 "
                         "(Newton on P^2(z) - z with the engine's dP/dz)", "1"),
    "s_boundary": ("s of the boundaries' points", "1"),
    "eps_boundary": ("eps of the slow-fast boundaries", "1"),
})

#: the flips past grazing are bracketed in theta: period one from FLIP_ONE (inside, where it
#: is stable) towards the second value; period two from just past that flip (by
#: FLIP_STEP: the orbit born there is stable) towards FLIP_TWO_OUTSIDE. The normal form's
#: thresholds are 0.378 and 0.269 at omega = 8 pi; the limit map's move down with s (to
#: 0.355 and 0.236 at s = 4), the slow-fast ones up at larger eps (0.43 at eps = 1e-2)
FLIP_ONE = (0.48, 0.25)
FLIP_STEP = 0.01
FLIP_TWO_OUTSIDE = 0.15
#: theta of a flip to this accuracy: far below the grid's spacing and above what the
#: multipliers resolve (the engine's dP/dz to ~1e-9, its slope in theta ~1)
FLIP_XTOL = 1e-9


def tolerances(scene: dict) -> dict:
    """attractor_common.chaos_tolerances; the type of a point is a classification, as
    the period there."""
    out = chaos_tolerances(scene)
    out.update({name: out["period"] for name in ("attractor_type", "attractor_type_limit")})
    flip = Tolerance(0.0, 1e-7, "a bisection to 1e-9 in theta on a multiplier + 1 whose "
                                "rounding (the engine's dP/dz to ~1e-9, central slopes of the "
                                "limit map to ~1e-10) moves the root by ~1e-9: 100 x that")
    out.update({name: flip for name in ("theta_flip_limit", "theta_chaos_limit", "theta_flip",
                                        "theta_chaos_flip")})
    return out


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def classify(period, lyapunov, escaped, lyapunov_err=None) -> np.ndarray:
    """Type per point: the confirmed period, else chaotic where the exponent is positive
    beyond attractors.LYAPUNOV_SIGMAS standard errors (``lyapunov_err``; without it, where it is
    positive: the limit map's, a mean over its kept points), else aperiodic."""
    period, lyapunov = np.asarray(period), np.asarray(lyapunov)
    positive = lyapunov > 0
    if lyapunov_err is not None:
        err = np.asarray(lyapunov_err)
        positive = np.isfinite(err) & (lyapunov > attractors.LYAPUNOV_SIGMAS * err)
    out = np.where(period > 0, period, np.where(positive, CHAOTIC, APERIODIC))
    return np.where(escaped, ESCAPED, out).astype(np.int32)


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = scene["parameters"]
    ds = common_dataset(scene, raw)
    ds["lyapunov_limit"] = (("theta", "eps", "s"), lyapunov_limit(ds, float(p["omega"])))
    ds["attractor_type"] = (("theta", "eps", "s"),
                            classify(ds.period.values, ds.lyapunov.values, ds.status.values != 0,
                                     ds.lyapunov_err.values))
    ds["attractor_type_limit"] = (("theta", "eps", "s"), classify(
        ds.period_limit.values, ds.lyapunov_limit.values, ~np.isfinite(ds.u_limit.values).all(-1)))
    lam = limit_map.multiplier(1.0, float(p["omega"]))
    ds["theta_critical"] = ((), limit_map.flip_threshold(lam))
    ds["theta_chaos"] = ((), limit_map.chaos_threshold(lam))
    ds = ds.assign(boundaries(registered_model(scene), p))
    return finalize(ds, scene, engine="compiled", method="exact",
                    title="atlas of the attractor near grazing, slow-fast Hopf example")


def boundaries(model, p: dict) -> dict:
    """Where period one gives way to period two and period two to chaos, past grazing:
    on the limit map at the scene's eps (over boundary_s) and on the slow-fast system of
    ``model`` (the scene's model module) at each boundary_eps (the multiplier of the
    followed orbit crossing -1, located by bisection in theta: bifurcation points, not
    edges of a basin on a grid)."""
    omega, eps = float(p["omega"]), float(p["eps"][0])
    s_b = np.asarray(p["boundary_s"], dtype=float)
    e_b = np.asarray(sorted(p["boundary_eps"], reverse=True), dtype=float)

    def limit(s, n, inside, outside):
        return limit_map.flip_point(s, n, inside, outside, eps=eps, omega=omega,
                                    xtol=FLIP_XTOL)

    lim1 = np.array([limit(s, 1, *FLIP_ONE) for s in s_b])
    lim2 = np.array([limit(s, 2, t - FLIP_STEP, FLIP_TWO_OUTSIDE) for s, t in zip(s_b, lim1)])
    sf1 = np.array([[slow_fast_flip(model, e, s, 1, omega, *FLIP_ONE) for s in s_b]
                    for e in e_b])
    sf2 = np.array([[slow_fast_flip(model, e, s, 2, omega, t - FLIP_STEP, FLIP_TWO_OUTSIDE)
                     for s, t in zip(s_b, row)] for e, row in zip(e_b, sf1)])
    return {"theta_flip_limit": (("s_boundary",), lim1),
            "theta_chaos_limit": (("s_boundary",), lim2),
            "theta_flip": (("eps_boundary", "s_boundary"), sf1),
            "theta_chaos_flip": (("eps_boundary", "s_boundary"), sf2),
            "s_boundary": (("s_boundary",), s_b), "eps_boundary": (("eps_boundary",), e_b)}


def slow_fast_flip(model, eps: float, s: float, n: int, omega: float, inside: float,
                   outside: float) -> float:
    """theta where the period-n orbit of the slow-fast return map to L1 at (eps, s) of
    ``model`` (the scene's model module, :class:`HopfReturns`) has the multiplier -1
    (periodic_orbit with returns=n on the compiled engine, followed from the attractor
    at ``inside`` towards ``outside``)."""
    sigma = eps * eps
    mu = 1.0 + s * sigma
    at = _attractor_point(model, eps, inside, mu, omega)
    last = {"z": at}

    def excess(theta):
        system = model.system(eps, theta, mu, omega, sliding=True)
        try:
            orbit = periodic_orbit(system, last["z"], model.L1["section"],
                                   direction=model.L1["direction"], where=model.L1["where"],
                                   returns=n, engine="compiled", t_max=T_RETURN)
        except PeriodicOrbitError as exc:
            raise PeriodicOrbitError(f"eps={eps}, s={s}, theta={theta}: {exc}") from None
        last["z"] = orbit.point
        return float(np.real(orbit.multipliers[1])) + 1.0

    return limit_map.bisect_crossing(excess, inside, outside, FLIP_XTOL,
                                     what=f"slow-fast period-{n} orbit")


def _attractor_point(model, eps, theta, mu, omega):
    """The state after 400 returns from the cycle's point (Newton's start)."""
    cm = model.compiled(eps, theta, mu, omega, sliding=True)
    run = attractors.iterate(cm, [0.0, np.sqrt(mu), 0.0], transient=399, keep=1,
                             t_max=T_RETURN)
    return run.orbit[0, -1]


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
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
    n_neg = int(np.sum(kind[neg][:, above] == 0))
    m.add("rpFourteenNegChaos", None, "derived: chaotic points at theta < 0 (count)",
          text=r"\text{no chaotic point}" if n_neg == 0 else
          (r"\text{one chaotic point}" if n_neg == 1 else rf"{n_neg}\text{{ chaotic points}}"))
    _report_flips(ds, m, sid)
    return None


def _report_flips(ds, m: Macros, sid: str) -> None:
    """The flips past grazing: normal form, limit map over boundary_s, slow-fast per eps,
    and the exponent of the slow-fast distance to the limit map over the eps computed."""
    m.add("rpFourteenThetaChaos", value(ds, "theta_chaos"), source(sid, "theta_chaos"), 3)
    sb, eb = ds.s_boundary.values, ds.eps_boundary.values
    m.add("rpFourteenBoundarySMin", float(sb.min()), f"{sid}:s_boundary (min)")
    m.add("rpFourteenBoundarySMax", float(sb.max()), f"{sid}:s_boundary (max)")
    m.add("rpFourteenBoundaryEpsMax", float(eb.max()), f"{sid}:eps_boundary (max)")
    m.add("rpFourteenBoundaryEpsMin", float(eb.min()), f"{sid}:eps_boundary (min)")
    for name, tag in (("theta_flip_limit", "FlipLimit"), ("theta_chaos_limit", "ChaosLimit")):
        v = ds[name].values
        m.add(f"rpFourteen{tag}Min", float(v.min()), f"{sid}:{name} (min over s)", 3)
        m.add(f"rpFourteen{tag}Max", float(v.max()), f"{sid}:{name} (max over s)", 3)
    i = int(np.argmin(eb))
    for name, tag in (("theta_flip", "FlipSF"), ("theta_chaos_flip", "ChaosSF")):
        v = ds[name].values[i]
        m.add(f"rpFourteen{tag}Min", float(v.min()), f"{sid}:{name}[eps min] (min over s)", 3)
        m.add(f"rpFourteen{tag}Max", float(v.max()), f"{sid}:{name}[eps min] (max over s)", 3)
    k = _report_flip_exponents(ds)
    m.add("rpFourteenFlipExpMin", float(k.min()), "derived: least-squares exponent of "
          "theta_flip - theta_flip_limit (and of the chaos flips) over eps_boundary, min "
          "over s and both flips", 2)
    m.add("rpFourteenFlipExpMax", float(k.max()), "derived: the same, max", 2)


def _report_flip_exponents(ds) -> np.ndarray:
    """k of |theta(eps) - theta_limit| ~ eps^k, fitted over eps_boundary, per s and flip
    (the limit map's flip at the scene's eps: it carries no eps at leading order)."""
    le = np.log(ds.eps_boundary.values)
    out = []
    for sf, lim in (("theta_flip", "theta_flip_limit"), ("theta_chaos_flip", "theta_chaos_limit")):
        gap = np.abs(ds[sf].values - ds[lim].values[None, :])
        out += [np.polyfit(le, np.log(gap[:, j]), 1)[0] for j in range(gap.shape[1])]
    return np.array(out)


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "theta"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"theta": [-1.0, 0.6, 0.8], "n_mu": 7, "n_transient": 40, "n_keep": 20,
              "max_period": 10, "boundary_eps": [0.001], "boundary_s": [1.0]}
