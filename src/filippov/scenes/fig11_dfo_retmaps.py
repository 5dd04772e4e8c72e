"""fig:dfo-retmap: return maps of the slow-fast dry-friction oscillator eq:dfo-sf
to the half-line L = {x2 = 0, x1 > 0, w = w_+(x)}, (a) eps = 0.1, v0 = 3.32 and
(b) eps = 0.01, v0 = 3.1.

Start points lie on the slow manifold M_+ of region + (where L is), computed by
relaxation (:func:`filippov.models.dry_friction.slow_manifold_plus`); the map
P(x1) is x1 at the first return to {x2 = 0} crossed downward with x1 > 0, by
the event-driven solver (DOP853 on every mode, Filippov sliding). Stored with
it: the distance of the start and return points to M_+, the time and x1
distance spent sliding (sticking), the fixed points.

For each eps the stick-slip orbits (fixed points of P with a sliding segment)
are continued in v0 by pseudo-arclength on G(x1, v0) = P(x1; v0) - x1; the
saddle-node (fold in v0) is located as the extremum of v0 along that branch,
and its sliding length is measured. The grazing fixed point (sliding length
zero) is found as well, so the dataset says whether the fold comes first.

Finally the quantity of eq:chiminus, dh/dx f_- - dh/dx f_+ at the grazing point
of the reduced model, decides case 1 (> 0) or case 2 (< 0) of lemma thm:gen; it
is computed for the adopted friction convention and for the printed law read
literally, together with the solver's normal speeds at a point of H_s.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar

from .. import continuation as cont
from ..io import finalize
from ..models import dry_friction as df
from ..poincare import _sliding_time, fixed_points
from ..progress import Progress
from ..simulate import Section, simulate
from ..system import SLIDING
from .common import require, solver_options


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


def return_map(x1, eps, v0, law, *, rtol=1e-12, atol=1e-14, progress=None,
               with_residual=True):
    """P(x1) on L for start points on M_+. Returns a dict of arrays."""
    x1 = np.atleast_1d(np.asarray(x1, dtype=float))
    ml = {k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")}
    w0, res0 = df.slow_manifold_plus(x1, 0.0, eps, v0, **ml, rtol=rtol, atol=atol)
    system = df.full_system(eps, v0, **ml)
    out = {k: np.empty(x1.size) for k in ("P", "w", "time", "slide_time", "slide_length")}
    out["n_switches"] = np.empty(x1.size, dtype=np.int32)
    sec = section_L()
    for i, (a, w) in enumerate(zip(x1, w0)):
        traj = simulate(system, [a, 0.0, w], 200.0, method="integrate", rtol=rtol, atol=atol,
                        sections=[sec], dense=False, samples_per_step=1)
        if traj.status != "section:L":
            raise RuntimeError(f"start x1={a!r} (eps={eps}, v0={v0}) did not return to L "
                               f"({traj.status})")
        out["P"][i], out["w"][i], out["time"][i] = traj.z[0], traj.z[2], traj.t
        out["slide_time"][i] = _sliding_time(traj.events)
        out["slide_length"][i] = _slide_length(traj.events)
        out["n_switches"][i] = len(traj.switches())
        if progress is not None:
            progress.step()
    out["start_residual"] = res0
    if with_residual:
        # distance of the returned point to M_+ (relaxation since the last switch)
        wr, _ = df.slow_manifold_plus(out["P"], 0.0, eps, v0, **ml, rtol=rtol, atol=atol)
        out["return_residual"] = np.abs(out["w"] - wr)
    return out


def near_manifold_start(x1, eps, v0, law, t_pull=0.5):
    """A start point that is on M_+ up to about exp(-T/eps) by the time it
    reaches L: (x1, 0) pulled back along the slow flow on the second-order
    expansion w2 for T = min(30 eps, t_pull) (short enough to stay below H_s)."""
    ml = {k: law[k] for k in ("f0", "fv", "fc", "convention")}
    gamma = law["gamma"]
    Fp, dFp = df.friction_branches(**ml)[:2]
    g1 = 1.0 + gamma

    def w2(a, b):
        F = Fp(b - v0)
        return v0 + gamma * b + eps * gamma * F + eps ** 2 * gamma * dFp(b - v0) * (a + (1 - gamma) * F)

    back = lambda t, z: -np.array([z[1], -z[0] - Fp(g1 * z[1] - w2(z[0], z[1]))])
    T = min(30 * eps, t_pull)
    zs = solve_ivp(back, (0.0, T), [x1, 0.0], method="DOP853", rtol=1e-12, atol=1e-14).y[:, -1]
    return np.array([zs[0], zs[1], w2(zs[0], zs[1])])


def P_pair(x1, v0, eps, law, rtol, atol):
    """(x1 at the first hit of L, x1 at the next): a return of a point that
    reaches L on M_+ (to about exp(-30) for eps = 0.01; for eps = 0.1 the
    deviation decays by exp(-t/eps) long before the orbit reaches H_s)."""
    system = df.full_system(eps, v0, **{k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")})
    sec = Section("L", lambda z: z[1], direction=-1, where=lambda z: z[0] > 0, terminal=2)
    traj = simulate(system, near_manifold_start(x1, eps, v0, law), 200.0, method="integrate",
                    rtol=rtol, atol=atol, sections=[sec], dense=False, samples_per_step=1)
    hits = traj.section_hits("L")
    if len(hits) != 2:
        raise RuntimeError(f"x1={x1!r}, v0={v0!r}, eps={eps!r}: no return ({traj.status})")
    return float(hits[0].state[0]), float(hits[1].state[0])


def P_scalar(x1, v0, eps, law, rtol, atol):
    """P(x1) - x1 measured on the pair of hits of :func:`P_pair` (so the start
    abscissa is the actual first hit, a hair away from x1)."""
    a, b = P_pair(x1, v0, eps, law, rtol, atol)
    return b - a + x1


def fixed_point_near(x1_guess, v0, eps, law, rtol, atol, width=0.05):
    """A fixed point of P by the secant method from ``x1_guess``."""
    g = lambda x: P_scalar(x, v0, eps, law, rtol, atol) - x
    a, b = x1_guess - width, x1_guess + width
    ga, gb = g(a), g(b)
    if ga * gb > 0:
        raise RuntimeError(f"no sign change of P - x1 in [{a}, {b}] at v0={v0}")
    return brentq(g, a, b, xtol=1e-13)


def saddle_node(eps, law, x1_lo, x1_hi, v0_guess, *, rtol=1e-12, atol=1e-14,
                progress=None):
    """The fold of the stick-slip fixed points of P in v0. M(v0) = max over x1 in
    [x1_lo, x1_hi] of P(x1; v0) - x1 (bounded Brent) is positive while the stable
    and unstable fixed points coexist and negative after they annihilate; the
    saddle-node is the root of M (Brent). The maximum value is insensitive to
    the error in its location (quadratic), so v0 comes out to about the
    accuracy of P. Returns (x1, v0 at the fold, samples (v0, M, argmax))."""
    samples = []

    def M(v):
        res = minimize_scalar(lambda x: -(P_scalar(x, v, eps, law, rtol, atol) - x),
                              bounds=(x1_lo, x1_hi), method="bounded",
                              options={"xatol": 1e-4})
        samples.append((v, -res.fun, res.x))
        if progress is not None:
            progress.step()
        return -res.fun

    # M is nearly linear in v0 near its root: the secant method needs few of
    # these costly evaluations (each one a maximisation over x1)
    v_sn = secant(M, v0_guess, v0_guess + 0.01, tol=1e-12)
    v, m, x = min(samples, key=lambda s: abs(s[0] - v_sn))
    return float(x), float(v_sn), np.array(sorted(samples))


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


def lemma_quantity(law, v, x0=None):
    """eq:chiminus, dh/dx f_- - dh/dx f_+ at the reduced grazing point
    (x0, y0(x0)) with x0 = (x_exit, v), plus the reduced system's normal speeds
    (a, b) at a sticking point (0, v) (eq:atSl: a > 0 > b is attracting)."""
    m = df.model(0.0, v, **law)
    xe = -df.friction_branches(law["f0"], law["fv"], law["fc"], law["convention"])[0](0.0)
    x = np.array([xe, v]) if x0 is None else np.asarray(x0, float)
    y = m.y0(x)
    hx, _ = m.h_grad(x, y)
    chi = float(hx @ m.f_minus(x, y) - hx @ m.f_plus(x, y))
    a, b = m.reduced().normal_speeds(np.array([0.0, v]))
    return chi, float(a), float(b)


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    require(scene, "system", {"slow_fast"})
    require(scene, "flow", {"integrate"})
    if not scene["ingredients"]["sliding"]:
        raise ValueError(f"{scene['id']}: ingredients.sliding must be true (sticking is sliding)")
    p = scene["parameters"]
    opts = solver_options(scene)
    rtol, atol = float(opts["rtol"]), float(opts["atol"])
    law = _law(p)
    eps_list = [float(e) for e in p["eps"]]
    v0_list = [float(v) for v in p["v0"]]
    if len(eps_list) != len(v0_list):
        raise ValueError(f"{scene['id']}: parameters.v0: need one v0 per eps "
                         f"({len(v0_list)} != {len(eps_list)})")
    lo, hi, n = float(p["x1_min"]), float(p["x1_max"]), int(p["n_x1"])
    x1 = np.linspace(lo, hi, n)
    bar = Progress(scene["id"], len(eps_list) * (n + 40), progress)

    maps, fps, sns = [], [], []
    for eps, v0 in zip(eps_list, v0_list):
        r = return_map(x1, eps, v0, law, rtol=rtol, atol=atol, progress=bar)
        maps.append(r)
        fp = fixed_points(x1, r["P"], refine=lambda x, e=eps, v=v0: P_scalar(x, v, e, law, rtol, atol))
        fp = np.array([P_pair(x, v0, eps, law, rtol, atol)[0] for x in fp])
        fps.append(fp)
        # saddle-node of the stick-slip orbits, from the panel's sliding fixed point
        xs, vs, br = saddle_node(eps, law, float(p["sn_x1_range"][0]),
                                 float(p["sn_x1_range"][1]), v0, rtol=rtol, atol=atol,
                                 progress=bar)
        at = return_map([xs], eps, vs, law, rtol=rtol, atol=atol)
        sns.append({"x1": xs, "v0": vs,
                    "slide_length": float(at["slide_length"][0]),
                    "slide_time": float(at["slide_time"][0]), "branch": br})

    n_fp = max(max(len(f) for f in fps), 1)
    fp_arr = np.full((len(eps_list), n_fp), np.nan)
    fp_slide = np.full((len(eps_list), n_fp), np.nan)
    for i, f in enumerate(fps):
        fp_arr[i, :len(f)] = f
        fp_slide[i, :len(f)] = np.interp(f, x1, maps[i]["slide_length"]) if len(f) else []
    nb = max(len(s["branch"]) for s in sns)
    br_x1 = np.full((len(eps_list), nb), np.nan)
    br_v0 = np.full((len(eps_list), nb), np.nan)
    for i, s in enumerate(sns):
        br_x1[i, :len(s["branch"])] = s["branch"][:, 0]
        br_v0[i, :len(s["branch"])] = s["branch"][:, 1]

    chi, a, b = lemma_quantity({k: law[k] for k in ("gamma", "f0", "fv", "fc", "convention")},
                               float(np.mean(v0_list)))
    lit = dict(law, convention="literal")
    chi_l, a_l, b_l = lemma_quantity(lit, float(np.mean(v0_list)))

    d2 = ("panel", "x1")
    st = lambda key: np.array([m[key] for m in maps])
    one = "1"
    ds = xr.Dataset(
        {"P": (d2, st("P"), {"long_name": "x1 at the first return to L", "units": one}),
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
         "eps": ("panel", eps_list, {"long_name": "singular perturbation parameter", "units": one}),
         "v0": ("panel", v0_list, {"long_name": "target belt speed v0", "units": one}),
         "v0_sn": ("panel", [s["v0"] for s in sns], {
             "long_name": "saddle-node of stick-slip orbits: v0 at the fold", "units": one}),
         "x1_sn": ("panel", [s["x1"] for s in sns], {
             "long_name": "fixed point x1 at the saddle-node", "units": one}),
         "sliding_length_sn": ("panel", [s["slide_length"] for s in sns], {
             "long_name": "x1 distance slid by the orbit at the saddle-node", "units": one}),
         "sliding_time_sn": ("panel", [s["slide_time"] for s in sns], {
             "long_name": "time spent sliding by the orbit at the saddle-node", "units": one}),
         "sn_branch_x1": (("panel", "branch"), br_x1, {
             "long_name": "continued stick-slip fixed points: x1", "units": one}),
         "sn_branch_v0": (("panel", "branch"), br_v0, {
             "long_name": "continued stick-slip fixed points: v0", "units": one}),
         "chi_minus": ((), chi, {"long_name": "dh/dx f_- - dh/dx f_+ at the grazing point "
                                 "(eq:chiminus); > 0: case 1 of thm:gen", "units": one}),
         "chi_minus_literal": ((), chi_l, {"long_name": "eq:chiminus for the printed law "
                                           "read literally", "units": one}),
         "sticking_a": ((), a, {"long_name": "dh/dt along f_- at (0, v0), reduced", "units": one}),
         "sticking_b": ((), b, {"long_name": "dh/dt along f_+ at (0, v0), reduced", "units": one}),
         "sticking_a_literal": ((), a_l, {"long_name": "as sticking_a, literal law", "units": one}),
         "sticking_b_literal": ((), b_l, {"long_name": "as sticking_b, literal law", "units": one})},
        coords={"panel": ("panel", np.arange(len(eps_list)), {"long_name": "0: (a), 1: (b)",
                                                               "units": one}),
                "x1": ("x1", x1, {"long_name": "x1 of the start point on L", "units": one})})
    return finalize(ds, scene, method="integrate", friction_convention=law["convention"],
                    title="return maps of the slow-fast dry-friction oscillator (fig:dfo-retmap)")
