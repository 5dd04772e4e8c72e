"""fig:retmaps: the return map P to L1 = {x1 = y = 0, x2 > 0} of the slow-fast
Hopf example (eq:exslow2, eq:exfast2) at the grazing parameter mu = 1.

Start points lie on L1 (so on M_+); P(x2) is x2 at the first return to the
section x1 = 0 with x1 decreasing and x2 > 0. The grid is uniform plus points
approaching the grazing value x2 = 1 geometrically from both sides, so the
jump (theta < 0) and the one-sided slope (theta > 0) are resolved.

Alongside the map the dataset stores, per theta, the quantity of eq:chiminus
that decides case 1 / case 2 of lemma thm:gen, computed by the solver as the
rate of change of h along the region-minus field at the grazing point p_g.
"""
from __future__ import annotations

from typing import Protocol
import numpy as np
import xarray as xr

from filippov.io import finalize
from filippov import models
from filippov.poincare import first_returns, fixed_points
from filippov.progress import Progress
from filippov.simulate import Section
from filippov_paper.scenes.common import engine, registered_model, require, solver_options
from filippov_paper.tolerance import Tolerance, sqrt_law
import math
from filippov_paper.report import Macros, source, value, var


class HopfFamily(Protocol):
    """What this scene uses of its model (``model:``): the model at (eps, theta, mu, omega)
    for the reference driver and its compiled form (with its section) for the kernel."""
    def model(self, eps, theta, mu, omega): ...
    def compiled(self, eps, theta, mu, omega, *, sliding, exact): ...


MODEL = HopfFamily

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "required": ["eps", "mu", "omega", "theta", "x2_min", "x2_max", "n_uniform",
                   "n_geometric", "closest"],
      "additionalProperties": False,
      "properties": {
        "eps": {"$ref": "#/$defs/positive"},
        "mu": True,
        "omega": True,
        "theta": {"type": "array"},
        "x2_min": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
        "x2_max": {"type": "number", "exclusiveMinimum": 1},
        "n_uniform": {"type": "integer", "minimum": 3},
        "n_geometric": {"type": "integer", "minimum": 1},
        "closest": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 0.01}
      }
    }
  }
}


def tolerances(scene: dict) -> dict:
    """Cross-machine tolerances (filippov_paper.tolerance): the grid reaches ``closest``
    above grazing, where times of flight follow a square-root law."""
    closest = float(scene["parameters"]["closest"])
    why = (f"start points down to {closest:g} above grazing: times vary as sqrt(x2 - 1), "
           f"a last-bit change moves them by ulp/(2 sqrt(closest)); x20 (two contacts)")
    tol = Tolerance(1e-9, sqrt_law(closest, 20.0), why)
    return {"return_time": tol, "sliding_time": tol}


def section_L1() -> Section:
    return Section("L1", lambda z: z[0], direction=-1, where=lambda z: z[1] > 0, terminal=1)


def x2_grid(p: dict) -> np.ndarray:
    lo, hi, n = float(p["x2_min"]), float(p["x2_max"]), int(p["n_uniform"])
    near = np.geomspace(float(p["closest"]), min(1.0 - lo, hi - 1.0), int(p["n_geometric"]))
    grid = np.concatenate([np.linspace(lo, hi, n), 1.0 - near, 1.0 + near, [1.0]])
    return np.unique(grid)


def return_map(model, x2, method: str, options: dict, progress=None, sliding=True,
               engine: str = "reference"):
    """P on L1 for the start values ``x2``: (returned x2, residual |y - x1|, Returns).

    ``engine="compiled"`` runs the numba kernel of :mod:`filippov.fastmap` (exact
    flows, or DOP853 in the kernel for ``method="integrate"``); it follows the
    reference driver's algorithm step for step.
    """
    starts = np.stack([np.zeros_like(x2), x2, np.zeros_like(x2)], axis=1)
    t_max = 4.0 * 2 * np.pi / abs(model.parameters["omega"])
    # the model's view for each engine (the compiled model carries the section L1; method
    # "integrate": regions + and - integrated, by the kernel's DOP853 on the compiled
    # engine); one front door runs either (filippov.engines)
    system, section, options = _on_engine(model, method, options, sliding, engine)
    ret = first_returns(system, starts, section, t_max, engine=engine, progress=progress,
                        **options)
    return ret.state[:, 1], np.abs(ret.state[:, 2] - ret.state[:, 0]), ret


def _on_engine(model, method: str, options: dict, sliding: bool, engine: str):
    """(system, section, options) of the Hopf model for ``engine``: the compiled model
    with its section L1, or the reference driver's system, section_L1() and method."""
    exact = method == "exact"
    if engine == "compiled":
        par = model.parameters
        return (models.get(model.name).compiled(par["eps"], par["theta"], par["mu"],
                                                par["omega"], sliding=sliding, exact=exact),
                None, options)
    return model.full(sliding=sliding, exact=exact), section_L1(), dict(options, method=method)


def sigma_minus(model) -> tuple[float, float]:
    """eq:eminus at the grazing point p_g = (-1, 0, -1) of the slow-fast system,
    from the solver's normal speeds, and eq:chiminus (dh/dx f_- - dh/dx f_+)."""
    system = model.full()
    pg = np.array([-1.0, 0.0, -1.0])
    a, _ = system.normal_speeds(pg)
    x, y = pg[:2], pg[2:]
    hx, _ = model.switch_grad(x, y)
    chi = float(hx @ model.f_minus(x, y) - hx @ model.f_plus(x, y))
    return float(a), chi


# Chunking (filippov_paper.scenes.chunking): the x2 grid is split into contiguous
# pieces, each piece's returns are computed by `sweep` (every start point is
# independent of the others), and `assemble` builds the dataset from the whole
# grid -- the fixed points and everything else derived from the whole map are
# computed there, so compute() and a merge of chunks give identical datasets.
CHUNK_AXIS = "x2"
ENGINES = ("reference", "compiled")
VARIABLE_ATTRS = {"theta": ("theta, weight of the fast variable in the switching function",
                            "1")}


def chunk_grid(scene: dict) -> np.ndarray:
    return x2_grid(scene["parameters"])


def sweep(scene: dict, x2: np.ndarray, *, progress: bool = False) -> xr.Dataset:
    """The solver's raw returns for the start values ``x2`` (any part of the grid), per
    theta: P, residual, return_time, n_switches, first_switch_time, sliding_time."""
    require(scene, "system", {"slow_fast"})
    p = scene["parameters"]
    opts = solver_options(scene)
    method = opts.pop("method")
    kernel = engine(scene)
    eps, mu, omega = float(p["eps"]), float(p["mu"]), float(p["omega"])
    thetas = [float(v) for v in p["theta"]]
    x2 = np.asarray(x2, dtype=float)
    bar = Progress(scene["id"], len(thetas) * x2.size, progress)
    P, res, tof, nsw, slide, first = [], [], [], [], [], []
    for theta in thetas:
        model = registered_model(scene).model(eps, theta, mu, omega)
        px2, r, ret = return_map(model, x2, method, opts, bar, scene["ingredients"]["sliding"],
                                 kernel)
        P.append(px2), res.append(r), tof.append(ret.time)
        nsw.append(ret.n_switches), slide.append(ret.sliding_time), first.append(ret.first_switch)
    dims = ("theta", "x2")
    return xr.Dataset(
        {"P": (dims, np.array(P)), "residual": (dims, np.array(res)),
         "return_time": (dims, np.array(tof)), "n_switches": (dims, np.array(nsw, dtype=np.int32)),
         "first_switch_time": (dims, np.array(first)), "sliding_time": (dims, np.array(slide))},
        coords={"theta": ("theta", thetas), "x2": ("x2", x2)})


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    """The figure's dataset from the raw returns on the whole grid (see `sweep`)."""
    p = scene["parameters"]
    method = solver_options(scene)["method"]
    kernel = engine(scene)
    eps, mu, omega = float(p["eps"]), float(p["mu"]), float(p["omega"])
    thetas = [float(v) for v in p["theta"]]
    x2 = x2_grid(p)
    if not (np.array_equal(raw["x2"].values, x2) and raw["theta"].values.tolist() == thetas):
        raise ValueError(f"{scene['id']}: the raw returns are not on the scene's (theta, x2) grid")
    P = [raw["P"].values[i] for i in range(len(thetas))]
    res, tof, nsw = raw["residual"].values, raw["return_time"].values, raw["n_switches"].values
    slide, first = raw["sliding_time"].values, raw["first_switch_time"].values
    sig, chi, fps = [], [], []
    for theta, px2 in zip(thetas, P):
        model = registered_model(scene).model(eps, theta, mu, omega)
        s, c = sigma_minus(model)
        sig.append(s), chi.append(c)
        fps.append(fixed_points(x2, px2))
    n_fp = max(len(f) for f in fps)
    fp = np.full((len(thetas), max(n_fp, 1)), np.nan)
    for i, f in enumerate(fps):
        fp[i, :len(f)] = f
    dims = ("theta", "x2")
    ds = xr.Dataset(
        {"P": (dims, np.array(P), {"long_name": "x2 at the first return to L1", "units": "1"}),
         "residual": (dims, np.array(res), {"long_name": "|y - x1| at the return (distance to M_+)",
                                            "units": "1"}),
         "return_time": (dims, np.array(tof), {"long_name": "time of flight to L1", "units": "1"}),
         "n_switches": (dims, np.array(nsw, dtype=np.int32),
                        {"long_name": "mode changes on the way", "units": "1"}),
         "first_switch_time": (dims, np.array(first), {
             "long_name": "time of the first change of mode after leaving L1 (NaN: none)",
             "units": "1"}),
         "sliding_time": (dims, np.array(slide), {"long_name": "time spent sliding", "units": "1"}),
         "fixed_point": (("theta", "fixed"), fp,
                         {"long_name": "fixed points of P on the grid (NaN: none)", "units": "1"}),
         "sigma_minus": ("theta", np.array(sig), {
             "long_name": "dh/dt along (f_-, g/eps) at p_g (Eq. (A.3)); > 0: case 1 of Lemma 2",
             "units": "1"}),
         "chi_minus": ("theta", np.array(chi), {
             "long_name": "dh/dx f_- - dh/dx f_+ at p_g (Eq. (A.5))", "units": "1"}),
         "slope_smooth": ((), float(np.exp(-4 * np.pi * mu / omega)), {
             "long_name": "slope of the smooth return map at x2=1, exp(-4 pi mu/omega)",
             "units": "1"})},
        coords={"theta": ("theta", thetas, {"units": "1"}),
                "x2": ("x2", x2, {"long_name": "x2 of the start point on L1", "units": "1"})})
    return finalize(ds, scene, method=method, engine=kernel,
                    title="return map P to L1 of the slow-fast Hopf example (Fig. 4)")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
def _report_first_above(x, d0):
    d = x - 1.0
    idx = np.where(d >= d0)[0]
    return int(idx[0])


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig04_retmaps"
    eps, mu, omega = (float(ds.attrs[k]) for k in ("eps", "mu", "omega"))
    m.add("rpFourEps", eps, f"{sid}:attrs.eps")
    m.add("rpFourMu", mu, f"{sid}:attrs.mu")
    m.add("rpFourOmegaOverPi", omega / math.pi, "derived: omega/pi", 4)
    m.add("rpFourNPoints", ds.sizes["x2"], f"{sid}:x2 (size)")
    m.add("rpFourXMin", float(ds.attrs["x2_min"]), f"{sid}:attrs.x2_min")
    m.add("rpFourXMax", float(ds.attrs["x2_max"]), f"{sid}:attrs.x2_max")
    var(m, "rpFourSlopeSmooth", ds, sid, "slope_smooth", sig=4)
    x2 = ds.x2.values
    below = np.where((x2 < 1) & (1 - x2 >= 1e-6))[0][-1]
    Pm, Pp = ds.P.sel(theta=-0.5).values, ds.P.sel(theta=0.5).values
    m.add("rpFourSlopeBelow", (1 - Pm[below]) / (1 - x2[below]),
          "derived: (1 - P(x2))/(1 - x2) at theta=-0.5, 1 - x2 ~ 1e-6", 4)
    m.add("rpFourFixed", value(ds, "fixed_point", theta=-0.5, fixed=0),
          source(sid, "fixed_point", theta=-0.5, fixed=0), 6)
    j = _report_first_above(x2, 0.0 + 1e-300)
    jump = 1.0 - Pm[j]
    m.add("rpFourJump", jump, "derived: 1 - P(theta=-0.5, smallest x2 > 1)", 4)
    m.add("rpFourJumpOverEps", jump / eps, "derived: jump/eps", 3)
    m.add("rpFourClosest", x2[j] - 1.0, "derived: smallest x2 - 1 > 0 on the grid", 2)
    from filippov.analytic.s0 import s0_lambert
    pred = float(s0_lambert(np.array([-0.5]))[0]) * math.exp(-3 * math.pi * mu / omega)
    m.add("rpFourJumpPredOverEps", pred, "derived: s0(-0.5) exp(-3 pi mu/omega)", 3)
    k = _report_first_above(x2, 1e-8)
    m.add("rpFourSlopeAbovePos", (Pp[k] - 1.0) / (x2[k] - 1.0),
          "derived: (P - 1)/(x2 - 1) at theta=0.5, first x2 - 1 >= 1e-8", 3)
    m.add("rpFourSlopeAboveProbe", x2[k] - 1.0, "derived: x2 - 1 used for the slope", 2)
    m.add("rpFourSlopeCarried", -1.0 * value(ds, "slope_smooth"),
          "derived: (theta-1)/theta * slope_smooth at theta=0.5", 3)
    # one-sided slope next to the jump (theta < 0): difference quotients near 1+
    d = x2 - 1.0
    i1, i2 = _report_first_above(x2, 1e-10), _report_first_above(x2, 1e-6)
    s1 = abs((Pm[i1 + 1] - Pm[i1]) / (x2[i1 + 1] - x2[i1]))
    s2 = abs((Pm[i2 + 1] - Pm[i2]) / (x2[i2 + 1] - x2[i2]))
    m.add("rpFourNegSlopeNear", s1, "derived: |dP/dx2| at theta=-0.5, x2 - 1 ~ 1e-10", 2)
    m.add("rpFourNegSlopeFar", s2, "derived: |dP/dx2| at theta=-0.5, x2 - 1 ~ 1e-6", 2)
    m.add("rpFourNegProbeNear", d[i1], "derived: x2 - 1 for rpFourNegSlopeNear", 2)
    m.add("rpFourNegProbeFar", d[i2], "derived: x2 - 1 for rpFourNegSlopeFar", 2)
    res = ds.residual.sel(theta=-0.5).values[(x2 - 1) > 1e-3]
    m.add("rpFourResMin", float(res.min()), "derived: min residual, theta=-0.5, x2 > 1.001", 2)
    m.add("rpFourResMax", float(res.max()), "derived: max residual, theta=-0.5, x2 > 1.001", 2)
    for th, word in ((-0.5, "Neg"), (0.5, "Pos")):
        var(m, f"rpFourSigma{word}", ds, sid, "sigma_minus", sig=3, theta=th)
    return None


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "eps"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"n_uniform": 21, "n_geometric": 6}
