"""fig:dfo-retmap: return maps of the slow-fast dry-friction oscillator eq:dfo-sf
to the half-line L = {x2 = 0, x1 > 0, w = w_+(x)}, (a) eps = 0.1, v0 = 3.32 and
(b) eps = 0.01, v0 = 3.1.

Start points lie on the slow manifold M_+ of region + (where L is), computed by
relaxation (:func:`filippov.models.dry_friction.slow_manifold_plus`); the map
P(x1) is x1 at the first return to {x2 = 0} crossed downward with x1 > 0, by
the event-driven solver (DOP853 on every mode, Filippov sliding). Stored with
it: the distance of the start and return points to M_+, the time and x1
distance spent sliding (sticking), the fixed points.

The grid is the uniform base grid (x1_min, x1_max, n_x1) refined where the
map is steep: the onset of sticking of each panel (the root of the first
minimum of h along the smooth region-+ orbit, located to about 1e-11) is a
grid point, and intervals where |Delta P| exceeds refine_dP in some panel are
subdivided (deterministic, both panels share the grid). Start points on M_+
come from one relaxation per panel, interpolated along L
(:func:`filippov.models.dry_friction.slow_manifold_plus_on_L`).

For each eps the saddle-node of the stick-slip orbits (fixed points of P with
a sliding segment) is the root in v0 of M(v0) = max_x1 P(x1; v0) - x1: secant
from the reduced GS point plus O(eps) at a looser search tolerance, then one
Newton correction at the full tolerance (v0_sn_search and v0_sn are both
stored); its sliding length is measured.

Finally the quantity of eq:chiminus, dh/dx f_- - dh/dx f_+ at the grazing point
of the reduced model, decides case 1 (> 0) or case 2 (< 0) of lemma thm:gen; it
is computed for the adopted friction convention and for the printed law read
literally, together with the solver's normal speeds at a point of H_s.
"""
from __future__ import annotations

from typing import Protocol

from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from filippov import fastmap
from filippov.io import finalize
from filippov.poincare import fixed_points, sliding_time
from filippov.progress import Progress
from filippov.simulate import Section, simulate
from filippov.system import SLIDING
from filippov_paper.scenes.common import engine, registered_model, require, solver_options
from filippov_paper.tolerance import Tolerance
from filippov_paper.report import Macros, absent, scalar_table, var

class FrictionReturns(Protocol):
    """What this scene uses of its model (``model:``), all functions of a friction law
    (gamma, f0, fv, fc, convention) at (eps, v0): the slow-fast system for either engine,
    the slow manifold M_+ (by relaxation, and along L), the region-+ pieces printed from
    the definition (REGION_PLUS: the fields and the expansion w2 of M_+), the law's
    coefficients, the friction branches and the reference model."""
    REGION_PLUS: dict

    def compiled(self, eps, v0, *, gamma, f0, fv, fc, convention): ...
    def full_system(self, eps, v0, *, gamma, f0, fv, fc, convention): ...
    def slow_manifold_plus(self, x1, x2, eps, v0, *, gamma, f0, fv, fc, convention,
                           rtol, atol): ...
    def slow_manifold_plus_on_L(self, x1_lo, x1_hi, eps, v0, *, gamma, f0, fv, fc,
                                convention, rtol, atol): ...
    def law_coefficients(self, f0, fv, fc, convention): ...
    def friction_branches(self, f0, fv, fc, convention): ...
    def model(self, eps, v0, *, gamma, f0, fv, fc, convention): ...


MODEL = FrictionReturns

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "description": "Slow-fast dry-friction oscillator Eq. (C.3); one v0 per eps (panels).",
      "required": ["gamma", "f0", "fv", "fc", "eps", "v0", "x1_min", "x1_max", "n_x1",
                   "sn_x1_range"],
      "$ref": "#/$defs/friction_law",
      "propertyNames": {"enum": [
        "f0", "fv", "fc", "convention", "gamma", "eps", "v0", "x1_min", "x1_max", "n_x1",
        "sn_x1_range", "refine_dP", "refine_rounds", "sn_v0_guess", "sn_search_rtol"
      ]},
      "properties": {
        "gamma": {"type": "number", "minimum": 0},
        "eps": {"type": "array", "minItems": 1, "items": {"$ref": "#/$defs/positive"}},
        "v0": {"type": "array", "minItems": 1, "items": {"$ref": "#/$defs/positive"}},
        "x1_min": {"$ref": "#/$defs/positive"},
        "x1_max": {"$ref": "#/$defs/positive"},
        "n_x1": {"type": "integer", "minimum": 3},
        "sn_x1_range": {"$ref": "#/$defs/point2"},
        "refine_dP": {"$ref": "#/$defs/positive"},
        "refine_rounds": {"type": "integer", "minimum": 0},
        "sn_v0_guess": {
          "type": "array",
          "minItems": 2,
          "maxItems": 2,
          "items": {"type": "number"}
        },
        "sn_search_rtol": {"$ref": "#/$defs/positive"}
      }
    }
  }
}

#: the scalars' meanings typeset for the report (attribute long_name_tex)
LATEX_NAMES = {
    "chi_minus": r"$\nabla h\cdot f_- - \nabla h\cdot f_+$ at the grazing point; $>0$: case 1 "
                 r"of the lemma",
    "chi_minus_literal": r"the same for the printed friction law read literally",
    "sticking_a": r"$\mathrm{d}h/\mathrm{d}t$ along $f_-$ at $(0, v_0)$, reduced system",
    "sticking_b": r"$\mathrm{d}h/\mathrm{d}t$ along $f_+$ at $(0, v_0)$, reduced system",
    "sticking_a_literal": r"as \texttt{sticking\_a}, printed law read literally",
    "sticking_b_literal": r"as \texttt{sticking\_b}, printed law read literally",
}

_ONSET = ("the onset of sticking is a grid point of each panel: whether that orbit "
          "slides is decided at a tangency (onset known to a few 1e-11, x1_onset_step)")
_FOLD = "at the fold P(x1) - x1 has a flat maximum: its argmax is square-root conditioned"
#: v0 from the saddle-node search at sn_search_rtol = 1e-8: converged to that rtol; x10
V0_SEARCH_RTOL = 1e-7
#: |dM/dv0| at the fold, M(v0) = max_x1 P - x1: 1.46 and 1.56 (eps 0.1, 0.01: the secant's
#: widest pair of iterates, manifest data), bounded by 2
SN_SLOPE_BOUND = 2.0
#: v0 at the fold: 3.32 and 3.17 (v0_sn), bounded by 3.5
SN_V0_BOUND = 3.5
#: the last sample of the search history is M at v0_sn_search (full rtol): M'(v0) times
#: v0_sn_search's offset from the fold, so it moves as v0_sn_search does, times |M'|
#: (M's own rounding at the full rtol, ~1e-10 as P's, is below that)
SN_M_ATOL = SN_SLOPE_BOUND * V0_SEARCH_RTOL * SN_V0_BOUND
#: cross-machine tolerances (filippov_paper.tolerance)
TOLERANCES = {
    "n_switches": Tolerance(0.0, 0.0, _ONSET + ": one crossing pair more or less",
                            rule="tangency", changed=2, jump=2),
    "sliding_length": Tolerance(3e-8, 1e-9, _ONSET + ": its whole slide, ~10 sqrt(distance "
                                "past the onset) <= 3e-4 for an onset off by up to 1e-9; x3. "
                                "Elsewhere: DOP853 at rtol 1e-12 through a relaxation of "
                                "stiffness 1/eps <= 100 over a period ~7 with |f| ~ 3: ~3e-9, "
                                "x10", rule="tangency", changed=2, jump=1e-3),
    "sliding_time": Tolerance(3e-8, 1e-9, "as sliding_length", rule="tangency", changed=2,
                              jump=1e-3),
    "return_residual": Tolerance(1e-9, 2e-10, "distance to M_+ at the noise floor of the "
                                              "relaxation (rtol 1e-12 / eps): absolute"),
    "x1_onset_step": Tolerance(1e-9, 1e-9, "last correction of an iteration at its noise "
                                           "floor (a few 1e-11): absolute"),
    "x1_sn": Tolerance(1e-9, 1e-6, _FOLD + ": sqrt(2 delta M / |M''|) ~ 1e-6"),
    "sliding_length_sn": Tolerance(1e-9, 1e-4, _FOLD + "; the slide near the fold grows "
                                                       "steeply in x1 (~100 per unit)"),
    "sliding_time_sn": Tolerance(1e-9, 1e-4, "as sliding_length_sn"),
    "v0_sn_search": Tolerance(V0_SEARCH_RTOL, 1e-12, "secant at sn_search_rtol = 1e-8: "
                                                     "converged to that rtol; x10"),
    "sn_branch_v0": Tolerance(V0_SEARCH_RTOL, 1e-12, "secant history: only the last sample "
                                                     "is a result (= v0_sn_search)",
                              rule="trace"),
    "sn_branch_x1": Tolerance(1e-9, 1e-5, "secant history: only the last sample is a "
                                          "result, the argmax of the correction at the full "
                                          "rtol (= x1_sn, 1e-6); x10", rule="trace"),
    "sn_branch_M": Tolerance(1e-9, SN_M_ATOL, "secant history: only the last sample is a "
                                          "result, M at v0_sn_search and the full rtol, "
                                          "M'(v0) (v0_sn_search - v0_sn): |M'| <= "
                                          f"{SN_SLOPE_BOUND:g} times the tolerance of "
                                          f"v0_sn_search ({V0_SEARCH_RTOL:g} of v0 <= "
                                          f"{SN_V0_BOUND:g})", rule="trace"),
}


T_RETURN = 200.0  # time bound of one return to L
ENGINES = ("reference", "compiled")


def section_L() -> Section:
    return Section("L", lambda z: z[1], direction=-1, where=lambda z: z[0] > 0, terminal=1)


def _law(p: dict) -> dict:
    return {"gamma": float(p["gamma"]), "f0": float(p["f0"]), "fv": float(p["fv"]),
            "fc": float(p["fc"]), "convention": str(p.get("convention", "stribeck"))}


def _slide_length(events) -> float:
    """x1 distance covered while sliding (sticking) on the way."""
    total, start = 0.0, None
    for e in events:
        if e.mode_after == SLIDING and e.mode_before != SLIDING:
            start = e.state[0]
        elif e.mode_before == SLIDING and e.mode_after != SLIDING and start is not None:
            total += e.state[0] - start
            start = None
    return total


def compiled_returns(model, z0s, eps, v0, law, rtol, atol):
    """First returns to L of the states ``z0s`` by the compiled kernel (every mode
    integrated with DOP853 there, the algorithm of the reference driver), sampled
    as the scene's reference driver runs it (one sample per step)."""
    ml = {k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")}
    z0s = np.atleast_2d(np.asarray(z0s, dtype=float))
    out = fastmap.compute_returns(model.compiled(eps, v0, **ml), z0s, T_RETURN, rtol=rtol,
                                  atol=atol, samples_per_step=1)
    bad = np.flatnonzero(out.status != fastmap.OK)
    if bad.size:
        i = int(bad[0])
        raise RuntimeError(f"start {z0s[i].tolist()} (eps={eps}, v0={v0}) did not return to "
                           f"L: {fastmap.STATUS[int(out.status[i])]}")
    return out


def return_map(model, x1, eps, v0, law, *, rtol=1e-12, atol=1e-14, progress=None,
               with_residual=True, start=None, engine="reference"):
    """P(x1) on L for start points on M_+. Returns a dict of arrays.
    ``start``: optional ``x1 -> (w, estimate)`` on M_+
    (:func:`filippov.models.dry_friction.slow_manifold_plus_on_L`), else the
    relaxation is run for these points. ``engine``: "reference" (the reference
    driver, one orbit at a time) or "compiled" (:func:`compiled_returns`)."""
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    ml = {k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")}
    if start is None:
        w0, res0 = model.slow_manifold_plus(x1, 0.0, eps, v0, **ml, rtol=rtol, atol=atol)
    else:
        w0, res0 = start(x1)
    if engine == "compiled":
        ret = compiled_returns(model, np.stack([x1, np.zeros_like(x1), w0], axis=1), eps, v0,
                               law, rtol, atol)
        out = {"P": ret.state[:, 0].copy(), "w": ret.state[:, 2].copy(), "time": ret.time,
               "slide_time": ret.sliding_time,
               "slide_length": ret.sliding_displacement[:, 0].copy(),
               "n_switches": ret.n_switches.astype(np.int32)}
        if progress is not None:
            progress.step(x1.size)
    else:
        out = {k: np.empty(x1.size) for k in ("P", "w", "time", "slide_time", "slide_length")}
        out["n_switches"] = np.empty(x1.size, dtype=np.int32)
        system = model.full_system(eps, v0, **ml)
        sec = section_L()
        for i, (a, w) in enumerate(zip(x1, w0)):
            traj = simulate(system, [a, 0.0, w], T_RETURN, method="integrate", rtol=rtol,
                            atol=atol, sections=[sec], dense=False, samples_per_step=1)
            if traj.status != "section:L":
                raise RuntimeError(f"start x1={a!r} (eps={eps}, v0={v0}) did not return to L "
                                   f"({traj.status})")
            out["P"][i], out["w"][i], out["time"][i] = traj.z[0], traj.z[2], traj.t
            out["slide_time"][i] = sliding_time(traj.events)
            out["slide_length"][i] = _slide_length(traj.events)
            out["n_switches"][i] = len(traj.switches())
            if progress is not None:
                progress.step()
    out["start_residual"] = res0
    if with_residual:
        # distance of the returned point to M_+ (relaxation since the last switch)
        wr, _ = model.slow_manifold_plus(out["P"], 0.0, eps, v0, **ml, rtol=rtol, atol=atol)
        out["return_residual"] = np.abs(out["w"] - wr)
    return out


def near_manifold_start(model, x1, eps, v0, law, t_pull=0.5):
    """A start point that is on M_+ up to about exp(-T/eps) by the time it
    reaches L: (x1, 0) pulled back along the slow flow on the second-order
    expansion w2 of the model (:data:`filippov.models.dry_friction.W2_PLUS`, analytic
    branch) for T = min(30 eps, t_pull) (short enough to stay below H_s)."""
    gamma = law["gamma"]
    coef = model.law_coefficients(law["f0"], law["fv"], law["fc"], law["convention"])
    plus = model.REGION_PLUS["analytic"]
    w2 = lambda a, b: plus["w2"](a, b, eps, v0, gamma, *coef)  # noqa: E731
    back = lambda t, z: -np.array([z[1], plus["slow"](z[0], z[1], w2(z[0], z[1]), gamma, *coef)])
    T = min(30 * eps, t_pull)
    zs = solve_ivp(back, (0.0, T), [x1, 0.0], method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
    return np.array([zs[0], zs[1], w2(zs[0], zs[1])])


def P_pair(model, x1, v0, eps, law, rtol, atol, engine="reference"):
    """(x1 at the first hit of L, x1 at the next): a return of a point that
    reaches L on M_+ (to about exp(-30) for eps = 0.01; for eps = 0.1 the
    deviation decays by exp(-t/eps) long before the orbit reaches H_s).
    The compiled engine runs the two returns as two calls (the second from
    the first hit)."""
    if engine == "compiled":
        first = compiled_returns(model, near_manifold_start(model, x1, eps, v0, law), eps, v0,
                                 law, rtol, atol).state
        second = compiled_returns(model, first, eps, v0, law, rtol, atol).state
        return float(first[0, 0]), float(second[0, 0])
    system = model.full_system(eps, v0, **{k: law[k] for k in ("gamma", "f0", "fv", "fc",
                                                               "convention")})
    sec = Section("L", lambda z: z[1], direction=-1, where=lambda z: z[0] > 0, terminal=2)
    traj = simulate(system, near_manifold_start(model, x1, eps, v0, law), T_RETURN,
                    method="integrate", rtol=rtol, atol=atol, sections=[sec], dense=False,
                    samples_per_step=1)
    hits = traj.section_hits("L")
    if len(hits) != 2:
        raise RuntimeError(f"x1={x1!r}, v0={v0!r}, eps={eps!r}: no return ({traj.status})")
    return float(hits[0].state[0]), float(hits[1].state[0])


def P_scalar(model, x1, v0, eps, law, rtol, atol, engine="reference"):
    """P(x1) - x1 measured on the pair of hits of :func:`P_pair` (so the start
    abscissa is the actual first hit, a hair away from x1)."""
    a, b = P_pair(model, x1, v0, eps, law, rtol, atol, engine)
    return b - a + x1


def fixed_point_near(model, x1_guess, v0, eps, law, rtol, atol, width=0.05):
    """A fixed point of P by the secant method from ``x1_guess``."""
    g = lambda x: P_scalar(model, x, v0, eps, law, rtol, atol) - x
    a, b = x1_guess - width, x1_guess + width
    ga, gb = g(a), g(b)
    if ga * gb > 0:
        raise RuntimeError(f"no sign change of P - x1 in [{a}, {b}] at v0={v0}")
    return brentq(g, a, b, xtol=1e-13)


def saddle_node(model, eps, law, x1_lo, x1_hi, v0_guess, *, rtol=1e-12, atol=1e-14,
                search_rtol=1e-10, window=0.02, progress=None, engine="reference"):
    """The fold of the stick-slip fixed points of P in v0.

    M(v0) = max over x1 of P(x1; v0) - x1 is positive while the stable and
    unstable fixed points coexist and negative after they annihilate; the
    saddle-node is the root of M. The maximum value is insensitive to the
    error in its location (quadratic), so v0 comes out to about the accuracy
    of P.

    Cost: M is nearly linear in v0, so the secant method from a good guess
    (the reduced GS point plus O(eps), see the scene config) needs few
    evaluations; the search runs at the looser ``search_rtol`` (P changes by
    about 3e-11 between rtol 1e-10 and 1e-12) and each maximisation after the
    first one is restricted to +-``window`` around the previous argmax. The
    result is then verified and corrected by one evaluation of M at the full
    ``rtol``: v_sn = v_search - M_full(v_search) / M'(v0) (one Newton step;
    M' from the secant iterates).

    Returns (x1 at the fold, v0 at the fold, samples (v0, M, argmax) in the order
    they were taken -- the last is the correction's, at v0 from the search and the
    full rtol --, v0 from the search tolerance alone).
    """
    samples = []
    state = {"x": None}

    def M(v, rt, win=window, xatol=1e-5):
        x0 = state["x"]
        bounds = (x1_lo, x1_hi) if x0 is None else (max(x1_lo, x0 - win),
                                                       min(x1_hi, x0 + win))
        f = lambda x: -(P_scalar(model, x, v, eps, law, rt, rt * atol / rtol, engine) - x)
        res = minimize_scalar(f, bounds=bounds, method="bounded", options={"xatol": xatol})
        if x0 is not None and min(res.x - bounds[0], bounds[1] - res.x) < 0.05 * win:
            # the argmax ran to the window's edge: maximise over the full range
            res = minimize_scalar(f, bounds=(x1_lo, x1_hi), method="bounded",
                                  options={"xatol": xatol})
        state["x"] = float(res.x)
        samples.append((v, -res.fun, res.x))
        if progress is not None:
            progress.step()
        return -res.fun

    # the search stops at a step of about 1e-8 (M carries noise of about 1e-9 at
    # search_rtol 1e-8, so smaller steps only wander); the correction at the full
    # rtol is a Newton step from there: its error is O(step^2)
    v_search = secant(lambda v: M(v, search_rtol), v0_guess, v0_guess + 1e-3, tol=3e-9,
                      max_iter=15)
    # M'(v0) from the widest pair (M is nearly linear; neighbouring iterates are
    # too close for a difference quotient above the noise)
    (va, ma, _), (vb, mb, _) = samples[0], samples[-1]
    slope = (mb - ma) / (vb - va)
    # same v0: the argmax moves by ~1e-6 at most; a finer argmax, since near the
    # onset of sticking P - x1 is sharply curved (error G'' dx^2 / 2 in M)
    m_full = M(v_search, rtol, win=2e-3, xatol=1e-7)
    v_sn = v_search - m_full / slope
    # the samples in the order they were taken: the last one is the correction's
    # evaluation at the full rtol (the converged value; rule trace compares it alone)
    return float(samples[-1][2]), float(v_sn), np.array(samples), float(v_search)


# --------------------------------------------------------------------------- onset of sticking
def grazing_gap(model, x1, eps, v0, law, rtol=1e-12, atol=1e-14, start=None):
    """g(x1): the first local minimum of h = w - (1 + gamma) x2 on the orbit
    from the start point (x1, 0, w_+) on L, following the region-+ field
    F_+ continued smoothly across H_s (the friction branch F_plus is analytic
    for every nu).

    g > 0: the orbit returns without touching H_s (no sticking); g < 0: it
    reaches H_s, where sliding (sticking) is attracting (case 1), so it sticks.
    g is a smooth function of x1 (the grazing of a smooth flow), and its root
    is the onset of sticking. Start points are those of :func:`return_map`
    (M_+ by relaxation), one batch for all x1.
    """
    from filippov.system import PLUS
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    ml = {k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")}
    if start is None:
        w0, _ = model.slow_manifold_plus(x1, 0.0, eps, v0, **ml, rtol=rtol, atol=atol)
    else:
        w0 = start(x1)[0]
    system = model.full_system(eps, v0, **ml)
    grad = np.asarray(system.switch_grad(np.zeros(3)), dtype=float)
    rhs = lambda t, z: system.field(PLUS, z)
    dh = lambda t, z: float(grad @ system.field(PLUS, z))
    dh.terminal, dh.direction = True, 1      # h has a minimum: dh/dt goes - to +
    out = np.empty(x1.size)
    for i, (a, w) in enumerate(zip(x1, w0)):
        sol = solve_ivp(rhs, (0.0, 50.0), [a, 0.0, w], method="DOP853", rtol=rtol,
                        atol=atol, events=dh)
        if sol.status != 1:
            raise RuntimeError(f"x1={a!r}: no minimum of h on the region-+ orbit")
        out[i] = float(system.switch(sol.y_events[0][0]))
    return out


def sticking_onset(model, eps, v0, law, lo, hi, *, rtol=1e-12, atol=1e-14, xtol=1e-10,
                   max_rounds=4, start=None):
    """The x1 on L where sticking begins: the root of :func:`grazing_gap` in
    [lo, hi] (a bracket from the grid). Batched interpolation rounds (each one
    batch of start points on M_+): Chebyshev interpolation of g on 5 nodes of
    the bracket, then quadratic interpolation on 3 points around the estimate
    with the spacing shrinking, until the estimate moves by less than ``xtol``
    (at rtol 1e-12 the noise of g puts a floor of a few 1e-11 under the
    corrections).
    Returns (x1_onset, last correction, |g| at the last nodes' interpolant)."""
    nodes = lo + (hi - lo) * 0.5 * (1 - np.cos(np.pi * np.arange(5) / 4))
    g = grazing_gap(model, nodes, eps, v0, law, rtol, atol, start)
    if not (g[0] > 0 > g[-1]):
        raise RuntimeError(f"eps={eps}, v0={v0}: no onset of sticking in [{lo}, {hi}] "
                           f"(g = {g[0]:.3e} .. {g[-1]:.3e})")
    x = _interp_root(nodes, g, lo, hi)
    d, step = 1e-3 * (hi - lo), np.inf
    for _ in range(max_rounds):
        pts = x + d * np.array([-1.0, 0.0, 1.0])
        gp = grazing_gap(model, pts, eps, v0, law, rtol, atol, start)
        xn = _interp_root(pts, gp, pts[0] - 10 * d, pts[-1] + 10 * d)
        step, x = abs(xn - x), xn
        if step <= xtol:
            break
        d = max(10 * step, 1e-7)
    return float(x), float(step)


def _interp_root(x, g, lo, hi):
    c = np.polynomial.Polynomial.fit(x, g, len(x) - 1)
    r = c.roots()
    r = np.real(r[(np.abs(np.imag(r)) < 1e-12) & (np.real(r) >= lo) & (np.real(r) <= hi)])
    if r.size == 0:
        raise RuntimeError("onset of sticking: the interpolant has no root in the bracket")
    return float(r[np.argmin(np.abs(r - x[np.argmin(np.abs(g))]))])


def _merge(maps, new):
    """Append the point results ``new`` (dict of arrays with key 'x1') to ``maps``, sorted."""
    out = {k: np.concatenate([maps[k], new[k]]) for k in maps}
    order = np.argsort(out["x1"], kind="stable")
    return {k: v[order] for k, v in out.items()}


def refined_return_maps(model, x_base, panels, law, *, rtol, atol, dP_max, max_rounds, bar=None,
                        starts=None, engine="reference"):
    """P on one x1 grid shared by all panels: the uniform ``x_base``, plus the
    onset of sticking of each panel, plus points subdividing every interval
    where |Delta P| > ``dP_max`` in some panel (:func:`_subdivide`, repeated
    until no interval is too steep, at most ``max_rounds`` rounds;
    deterministic). ``starts``: one start-point callable per panel (see
    :func:`return_map`). Returns (maps, onsets)."""
    starts = [None] * len(panels) if starts is None else starts

    def run(x):
        outs = []
        for (eps, v0), st in zip(panels, starts):
            r = return_map(model, x, eps, v0, law, rtol=rtol, atol=atol, progress=bar,
                           with_residual=False, start=st, engine=engine)
            r["x1"] = np.asarray(x, dtype=float).copy()
            outs.append(r)
        return outs

    maps = run(np.asarray(x_base, dtype=float))
    onsets = []
    for (eps, v0), m, st in zip(panels, maps, starts):
        stick = m["slide_length"] > 0
        i = np.flatnonzero(~stick[:-1] & stick[1:])
        if i.size != 1:
            raise RuntimeError(f"eps={eps}: expected one onset of sticking on the grid, "
                               f"found {i.size}")
        onsets.append(sticking_onset(model, eps, v0, law, m["x1"][i[0]], m["x1"][i[0] + 1],
                                     rtol=rtol, atol=atol, start=st))
    new = _subdivide(maps, dP_max, extra=[x for x, _ in onsets])
    for _ in range(max_rounds):
        if new.size == 0:
            break
        maps = [_merge(m, r) for m, r in zip(maps, run(new))]
        new = _subdivide(maps, dP_max)
    return maps, onsets


def _subdivide(maps, dP_max, extra=()):
    """New grid points: ``extra`` (the onsets), and in every interval where
    |Delta P| > dP_max in some panel, ceil(|Delta P| / dP_max) - 1 equally
    spaced points (one round of this does what several rounds of bisection do
    where P is close to linear; the next round checks)."""
    x = maps[0]["x1"]
    k = np.zeros(x.size - 1, dtype=int)
    for m in maps:
        k = np.maximum(k, np.ceil(np.abs(np.diff(m["P"])) / dP_max - 1e-9).astype(int) - 1)
    pts = [x[i] + (x[i + 1] - x[i]) * np.arange(1, k[i] + 1) / (k[i] + 1)
           for i in np.flatnonzero(k > 0)]
    pts = np.concatenate(pts + [np.asarray(extra, dtype=float)])
    pts = np.unique(pts)
    return pts[~np.isin(pts, x)]


def secant(g, a, b, tol=1e-13, max_iter=30):
    ga, gb = g(a), g(b)
    for _ in range(max_iter):
        if gb == ga:
            return b
        c = b - gb * (b - a) / (gb - ga)
        a, ga = b, gb
        b, gb = c, g(c)
        if abs(b - a) <= tol * max(1.0, abs(b)):
            return b
    raise RuntimeError(f"secant did not converge (last step {abs(b - a):.3e})")


def lemma_quantity(model, law, v, x0=None):
    """eq:chiminus, dh/dx f_- - dh/dx f_+ at the reduced grazing point
    (x0, y0(x0)) with x0 = (x_exit, v), plus the reduced system's normal speeds
    (a, b) at a sticking point (0, v) (eq:atSl: a > 0 > b is attracting)."""
    m = model.model(0.0, v, **law)
    branches = model.friction_branches(law["f0"], law["fv"], law["fc"], law["convention"])
    xe = -branches[0](0.0)
    x = np.array([xe, v]) if x0 is None else np.asarray(x0, float)
    y = m.y0(x)
    hx, _ = m.switch_grad(x, y)
    chi = float(hx @ m.f_minus(x, y) - hx @ m.f_plus(x, y))
    a, b = m.reduced().normal_speeds(np.array([0.0, v]))
    return chi, float(a), float(b)


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    c = _settings(scene)
    model = c.model
    bar = Progress(scene["id"], len(c.eps) * (2 * c.n + 60), progress)
    panels = list(zip(c.eps, c.v0))
    # start points on M_+ over the grid and over the returns, one relaxation per panel
    span = (min(c.lo, c.x1_return_min), c.hi)
    starts = [model.slow_manifold_plus_on_L(*span, eps, v0, **c.model_law, rtol=c.rtol,
                                         atol=c.atol)
              for eps, v0 in panels]
    maps, onsets = refined_return_maps(model, np.linspace(c.lo, c.hi, c.n), panels, c.law,
                                       rtol=c.rtol, atol=c.atol, dP_max=c.dP_max,
                                       max_rounds=c.rounds, bar=bar, starts=starts,
                                       engine=c.kernel)
    x1 = maps[0]["x1"]
    fps, sns = [], []
    for (eps, v0), r, st in zip(panels, maps, starts):
        fp, sn = _panel_analysis(c, eps, v0, r, st, x1, bar)
        fps.append(fp)
        sns.append(sn)
    ds = xr.Dataset(
        # one dict in the dataset's variable order: maps, panels, lemma thm:gen
        {**_map_vars(maps, fps, x1), **_panel_vars(c, sns, onsets, maps, x1),
         **_lemma_vars(c)},
        coords={"panel": ("panel", np.arange(len(c.eps)), {"long_name": "0: (a), 1: (b)",
                                                            "units": "1"}),
                "x1": ("x1", x1, {"long_name": "x1 of the start point on L", "units": "1"})})
    return finalize(ds, scene, method="integrate", friction_convention=c.law["convention"],
                    title="return maps of the slow-fast dry-friction oscillator (Fig. C.2)")


@dataclass(frozen=True)
class _Settings:
    """The scene's parameters and solver options as :func:`compute` uses them."""
    rtol: float
    atol: float
    kernel: str                 # the engine
    model: object               # the model module (the scene's ``model:``; FrictionReturns)
    law: dict                   # the friction law (_law)
    model_law: dict             # the law's keys that the model's slow_manifold_plus_on_L takes
    eps: list                   # one per panel
    v0: list                    # one per panel
    lo: float                   # the uniform x1 grid
    hi: float
    n: int
    dP_max: float               # grid refinement
    rounds: int
    search_rtol: float          # saddle-node search
    v_gs: float
    c_gs: float
    sn_lo: float
    sn_hi: float
    x1_return_min: float


def _settings(scene: dict) -> _Settings:
    require(scene, "system", {"slow_fast"})
    require(scene, "flow", {"integrate"})
    if not scene["ingredients"]["sliding"]:
        raise ValueError(f"{scene['id']}: ingredients.sliding must be true (sticking is sliding)")
    p = scene["parameters"]
    opts = solver_options(scene)
    kernel = engine(scene)
    law = _law(p)
    eps_list = [float(e) for e in p["eps"]]
    v0_list = [float(v) for v in p["v0"]]
    if len(eps_list) != len(v0_list):
        raise ValueError(f"{scene['id']}: parameters.v0: need one v0 per eps "
                         f"({len(v0_list)} != {len(eps_list)})")
    vgs, cgs = (float(v) for v in p.get("sn_v0_guess", [3.15625, 1.7]))
    return _Settings(
        rtol=float(opts["rtol"]), atol=float(opts["atol"]), kernel=kernel,
        model=registered_model(scene), law=law,
        model_law={k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")},
        eps=eps_list, v0=v0_list,
        lo=float(p["x1_min"]), hi=float(p["x1_max"]), n=int(p["n_x1"]),
        dP_max=float(p.get("refine_dP", 0.03)), rounds=int(p.get("refine_rounds", 5)),
        search_rtol=float(p.get("sn_search_rtol", 1e-10)), v_gs=vgs, c_gs=cgs,
        sn_lo=float(p["sn_x1_range"][0]), sn_hi=float(p["sn_x1_range"][1]),
        x1_return_min=float(p.get("x1_return_min", 3.3)))


def _panel_analysis(c: _Settings, eps: float, v0: float, r: dict, st, x1, bar):
    """One panel's return residual (into ``r``), the fixed points of its map and the
    saddle-node of its stick-slip orbits."""
    model, law, rtol, atol, kernel = c.model, c.law, c.rtol, c.atol, c.kernel
    # distance of the returned points to M_+ (relaxation since the last switch)
    r["return_residual"] = np.abs(r["w"] - st(r["P"])[0])
    # fixed points of the same map (same start points), Brent in each sign change
    Pm = lambda x, e=eps, v=v0, s_=st: float(return_map(
        model, [x], e, v, law, rtol=rtol, atol=atol, with_residual=False, start=s_,
        engine=kernel)["P"][0])
    fp = np.asarray(fixed_points(x1, r["P"], refine=Pm, xtol=1e-12))
    # saddle-node of the stick-slip orbits; first guess: reduced GS + c eps
    xs, vs, br, v_search = saddle_node(model, eps, law, c.sn_lo, c.sn_hi,
                                       c.v_gs + c.c_gs * eps, rtol=rtol, atol=atol,
                                       search_rtol=c.search_rtol,
                                       progress=bar, engine=kernel)
    at = return_map(model, [xs], eps, vs, law, rtol=rtol, atol=atol, with_residual=False,
                    engine=kernel)
    return fp, {"x1": xs, "v0": vs, "v0_search": v_search,
                "slide_length": float(at["slide_length"][0]),
                "slide_time": float(at["slide_time"][0]), "branch": br}


def _padded(rows, width: int) -> np.ndarray:
    """Rows of different lengths as one array, NaN after each row's end."""
    out = np.full((len(rows), width), np.nan)
    for i, row in enumerate(rows):
        out[i, :len(row)] = row
    return out


def _map_vars(maps, fps, x1) -> dict:
    """The return maps over the x1 grid and their fixed points."""
    n_fp = max(max(len(f) for f in fps), 1)
    fp_arr = _padded(fps, n_fp)
    fp_slide = _padded([np.interp(f, x1, m["slide_length"]) if len(f) else []
                        for f, m in zip(fps, maps)], n_fp)
    d2 = ("panel", "x1")
    st = lambda key: np.array([m[key] for m in maps])
    one = "1"
    return {
        "P": (d2, st("P"), {"long_name": "x1 at the first return to L", "units": one}),
        "w_return": (d2, st("w"), {"long_name": "w at the return", "units": one}),
        "start_residual": (d2, st("start_residual"), {
            "long_name": "distance of the start point to M_+ (change of w when the "
                         "relaxation is lengthened by half)", "units": one}),
        "return_residual": (d2, st("return_residual"), {
            "long_name": "|w - w_+(x)| at the return (distance to M_+)", "units": one}),
        "return_time": (d2, st("time"), {"long_name": "time of flight to L", "units": one}),
        "sliding_time": (d2, st("slide_time"), {"long_name": "time spent sliding (sticking)",
                                                 "units": one}),
        "sliding_length": (d2, st("slide_length"), {
            "long_name": "x1 distance travelled while sliding (sticking)", "units": one}),
        "n_switches": (d2, st("n_switches"), {"long_name": "mode changes on the way",
                                              "units": one}),
        "fixed_point": (("panel", "fixed"), fp_arr, {
            "long_name": "fixed points of P (NaN: none)", "units": one}),
        "fixed_point_sliding_length": (("panel", "fixed"), fp_slide, {
            "long_name": "sliding length at the fixed point (interpolated)", "units": one}),
    }


def _panel_vars(c: _Settings, sns, onsets, maps, x1) -> dict:
    """Per panel: its parameters, the saddle-node and its search, the onset of sticking."""
    nb = max(len(s["branch"]) for s in sns)
    # the search samples' columns: (v0, M, x1)
    branch = lambda col: _padded([s["branch"][:, col] for s in sns], nb)
    one = "1"
    return {
        "eps": ("panel", c.eps, {"long_name": "singular perturbation parameter", "units": one}),
        "v0": ("panel", c.v0, {"long_name": "target belt speed v0", "units": one}),
        "v0_sn": ("panel", [s["v0"] for s in sns], {
            "long_name": "saddle-node of stick-slip orbits: v0 at the fold", "units": one}),
        "x1_sn": ("panel", [s["x1"] for s in sns], {
            "long_name": "fixed point x1 at the saddle-node", "units": one}),
        "sliding_length_sn": ("panel", [s["slide_length"] for s in sns], {
            "long_name": "x1 distance slid by the orbit at the saddle-node", "units": one}),
        "sliding_time_sn": ("panel", [s["slide_time"] for s in sns], {
            "long_name": "time spent sliding by the orbit at the saddle-node", "units": one}),
        "v0_sn_search": ("panel", [s["v0_search"] for s in sns], {
            "long_name": "v0 at the fold from the search at rtol sn_search_rtol alone "
                         "(v0_sn: corrected by one evaluation at the full rtol)",
            "units": one}),
        "x1_onset": ("panel", [o[0] for o in onsets], {
            "long_name": "x1 on L where sticking begins (root of the minimum of h along "
                         "the region-+ orbit)", "units": one}),
        "x1_onset_step": ("panel", [o[1] for o in onsets], {
            "long_name": "last correction of the onset iteration (noise floor at "
                         "rtol 1e-12: a few 1e-11)", "units": one}),
        "P_onset": ("panel", [float(np.interp(o[0], x1, m["P"])) for o, m in zip(onsets, maps)], {
            "long_name": "P at the onset of sticking (a grid point)", "units": one}),
        "sn_branch_x1": (("panel", "branch"), branch(2), {
            "long_name": "saddle-node search samples in the order taken (the last: the "
                         "correction at the full rtol): argmax over x1 of P(x1) - x1",
            "units": one}),
        "sn_branch_v0": (("panel", "branch"), branch(0), {
            "long_name": "saddle-node search samples (as sn_branch_x1): v0", "units": one}),
        "sn_branch_M": (("panel", "branch"), branch(1), {
            "long_name": "saddle-node search samples (as sn_branch_x1): max over x1 of "
                         "P(x1) - x1",
            "units": one}),
    }


def _lemma_vars(c: _Settings) -> dict:
    """The case of lemma thm:gen (eq:chiminus) and the reduced sticking speeds, for the
    law as used and as printed (literal), at the panels' mean v0."""
    model = c.model
    chi, a, b = lemma_quantity(model, c.model_law, float(np.mean(c.v0)))
    lit = dict(c.law, convention="literal")
    chi_l, a_l, b_l = lemma_quantity(model, lit, float(np.mean(c.v0)))
    one = "1"
    return {
        "chi_minus": ((), chi, {"long_name": "dh/dx f_- - dh/dx f_+ at the grazing point "
                                "(Eq. (A.5)); > 0: case 1 of Lemma 2", "units": one}),
        "chi_minus_literal": ((), chi_l, {"long_name": "Eq. (A.5) for the printed law "
                                          "read literally", "units": one}),
        "sticking_a": ((), a, {"long_name": "dh/dt along f_- at (0, v0), reduced", "units": one}),
        "sticking_b": ((), b, {"long_name": "dh/dt along f_+ at (0, v0), reduced", "units": one}),
        "sticking_a_literal": ((), a_l, {"long_name": "as sticking_a, literal law", "units": one}),
        "sticking_b_literal": ((), b_l, {"long_name": "as sticking_b, literal law", "units": one}),
    }


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
#: the report does without this scene (its section says "not yet computed")
REPORT_OPTIONAL = True


def report(ds, m: Macros) -> str:
    """Macros for the return maps' findings (chi_-, the sticking interval, the
    saddle-node of each panel), each when present, and a table of the scalars."""
    missing = absent(m, "rpHaveEleven", ds, "fig11", "results/fig11_dfo_retmaps.nc")
    if missing:
        return missing
    for name_var, name in (("chi_minus", "rpElevenChi"), ("chi_minus_literal", "rpElevenChiLit"),
                           ("sticking_a", "rpElevenA"), ("sticking_b", "rpElevenB"),
                           ("sticking_a_literal", "rpElevenALit"),
                           ("sticking_b_literal", "rpElevenBLit")):
        if name_var in ds:
            var(m, name, ds, "fig11_dfo_retmaps", name_var, 3)
    for k, key in ((0, "A"), (1, "B")):
        if "panel" not in ds.dims or ds.sizes["panel"] <= k:
            continue
        for name_var, name, sig in (("eps", "Eps", 3), ("v0_sn", "VSN", 8), ("x1_sn", "XSN", 6),
                                    ("sliding_length_sn", "SlideSN", 3),
                                    ("sliding_time_sn", "SlideTimeSN", 3)):
            if name_var in ds:
                var(m, f"rpEleven{name}{key}", ds, "fig11_dfo_retmaps", name_var, sig, panel=k)
        # the saddle-node's distance above the reduced model's grazing-sliding point
        # (fig10's report, made before this one), in units of eps
        gs = m.values().get("rpTenVGS", (None,))[0]
        if gs is not None and {"v0_sn", "eps"} <= set(ds.variables):
            shift = (float(ds.v0_sn[k]) - gs) / float(ds.eps[k])
            m.add(f"rpElevenSNShift{key}", shift,
                  f"derived:(fig11_dfo_retmaps:v0_sn[panel={k}] - fig10_dfo:v_gs)"
                  f" / fig11_dfo_retmaps:eps[panel={k}]", 3)
    return scalar_table(ds)


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "fv"
