"""fig:dfo: the dry-friction oscillator eq:dfo1 (M = K = 1) over the belt speed v.

(b) the friction law F_c (adopted "stribeck" convention, plus the printed law
read literally for comparison); (c) the bifurcation diagram, measured by the
largest block position x1 along the orbit (x1 where the orbit crosses
{x2 = 0, x1 > x1_eq}, the section of fig:dfo-retmap; x1_eq for the equilibrium):

* equilibrium x = (-F_c(-v), 0), stable iff its damping F_c'(-v) = fv - fc e^{-v} > 0;
  the Hopf point H from that condition and, independently, from the eigenvalues
  of a finite-difference Jacobian at the numerically found equilibrium;
* the unstable periodic orbits born at H, lying in region + (x2 < v), by
  pseudo-arclength continuation of shooting solutions u = (x1, T, v) on the
  section, multipliers from the variational equations; the branch is followed
  until it grazes H_s = {x2 = v} (grazing function v - max x2 along the orbit);
* the stick-slip orbits: they leave the sticking segment at (x1, x2) = (-F_c(0-), v)
  (= (2, v), where b = 0), so there is one per v, found by one simulation; the
  Floquet multipliers come from the monodromy matrix with saltation matrices;
* GS: the v where the orbit through the exit point (2, v) is itself periodic,
  solved directly (forward and backward flows from (2, v) meet on the section)
  and cross-checked against the grazing point of the continued branch.
"""
from __future__ import annotations

from typing import Protocol

import functools

import numpy as np
import xarray as xr
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from filippov import continuation as cont
from filippov.io import finalize
from filippov.progress import Progress
from filippov.simulate import Section, simulate
from filippov_paper.scenes.common import registered_model, require
from filippov_paper.tolerance import Tolerance
from filippov_paper.report import Macros, absent, scalar_table, var

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "description": "Reduced dry-friction oscillator Eq. (C.1) over the belt speed v.",
      "required": ["f0", "fv", "fc", "v_min", "v_max", "n_stick_slip", "gs_closest",
                   "amp_min", "ds", "nu_max"],
      "$ref": "#/$defs/friction_law",
      "propertyNames": {"enum": [
        "f0", "fv", "fc", "convention", "v_min", "v_max", "n_stick_slip", "gs_closest", "amp_min",
        "ds", "nu_max"
      ]},
      "properties": {
        "v_min": {"$ref": "#/$defs/positive"},
        "v_max": {"$ref": "#/$defs/positive"},
        "n_stick_slip": {"type": "integer", "minimum": 8},
        "gs_closest": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 0.01},
        "amp_min": {"$ref": "#/$defs/positive"},
        "ds": {"$ref": "#/$defs/positive"},
        "nu_max": {"$ref": "#/$defs/positive"}
      }
    }
  }
}

#: cross-machine tolerances (filippov_paper.tolerance)
TOLERANCES = {
    "ss_stick_length": Tolerance(1e-9, 1e-8, "DOP853 at rtol 1e-12 over a period of ~7 with "
                                             "|f| ~ 10: a last-bit change alters the step "
                                             "sequence, so the state moves within the global "
                                             "error ~1e-10; x100 for the stick end"),
    "ss_stick_time": Tolerance(1e-9, 1e-8, "as ss_stick_length"),
    "ss_closure": Tolerance(1e-9, 1e-11, "a residual at the shooting's noise floor "
                                         "(~1e-13): compared absolutely"),
    "v_hopf_numeric": Tolerance(1e-8, 1e-12, "finite-difference Jacobian, step ~sqrt(u): "
                                             "rounding enters as u/h ~ 1e-8"),
}

#: the scalars' meanings typeset for the report (attribute long_name_tex)
LATEX_NAMES = {
    "v_hopf": r"Hopf point: belt speed $v$ with $F_c'(-v)=0$, i.e.\ $v=\ln(f_c/f_v)$",
    "v_hopf_numeric": r"Hopf point from the eigenvalues of a finite-difference Jacobian",
    "v_gs": r"grazing-sliding point GS (the orbit through the sticking exit point closes)",
    "v_gs_branch": r"grazing point of the continued branch of unstable cycles",
    "x1_gs": r"largest $x_1$ of the grazing orbit",
    "period_gs": r"period of the grazing orbit",
    "x1_exit": r"$x_1$ where sticking ends, $-F_c(0^-)$",
    "n_folds_hopf_branch": r"folds on the unstable branch",
    "F_c_static": r"$F_c(0^+)$, the static friction level",
}



class FrictionOscillator(Protocol):
    """What this scene uses of its model (``model:``), all functions of a friction law
    (f0, fv, fc, convention): the friction branches and F_c itself, the Hopf speed, the
    equilibrium, the reduced region-+ field with its derivatives, the reference model
    at (eps, v) and the reduced system's Jacobians."""
    def friction_branches(self, f0, fv, fc, convention): ...
    def friction(self, nu, *, f0, fv, fc, convention): ...
    def hopf_speed(self, fv, fc, convention): ...
    def equilibrium(self, v, *, f0, fv, fc, convention): ...
    def plus_field_reduced(self, v, *, f0, fv, fc, convention): ...
    def model(self, eps, v0, *, f0, fv, fc, convention): ...
    def reduced_jacobian(self, v, *, f0, fv, fc, convention): ...


MODEL = FrictionOscillator

RTOL, ATOL = 1e-12, 1e-14
N_MAX = 400  # continuation steps per direction


def _law(p: dict) -> dict:
    return {"f0": float(p["f0"]), "fv": float(p["fv"]), "fc": float(p["fc"]),
            "convention": str(p.get("convention", "stribeck"))}


def section_event(x1_min: float):
    """x2 = 0 crossed downward right of the equilibrium: the largest x1 of a turn."""
    def ev(t, z):
        return z[1] if z[0] > x1_min else 1.0
    ev.direction = -1
    return ev


def _to_section(model, v, z0, law, backward=False, rtol=RTOL, atol=ATOL):
    """From z0 follow the region-+ field (forward or backward) to the section;
    returns (x1 there, time)."""
    f = model.plus_field_reduced(v, **law)[0]
    sign = -1.0 if backward else 1.0
    x_eq = float(model.equilibrium(v, **law)[0])
    ev = section_event(x_eq)
    ev.terminal = True
    ev.direction = -1 if not backward else 1
    sol = solve_ivp(lambda t, z: sign * f(z), (0.0, 50.0), np.asarray(z0, float),
                    method="DOP853", rtol=rtol, atol=atol, events=ev)
    if not sol.t_events[0].size:
        raise RuntimeError(f"no section crossing from {list(z0)} at v={v!r}")
    return float(sol.y_events[0][0][0]), float(sol.t_events[0][0])


def exit_point(model, law) -> float:
    """x1 where sticking ends: b = x1 + F_c(0-) = 0 (eq:atSl with h = v - x2)."""
    branches = model.friction_branches(law["f0"], law["fv"], law["fc"], law["convention"])
    return float(-branches[0](0.0))


def gs_mismatch(model, v, law, rtol=RTOL, atol=ATOL):
    """Forward minus backward section hit of the orbit through the exit point (x_e, v):
    zero iff that orbit is a closed orbit in region + touching x2 = v (grazing)."""
    xe = exit_point(model, law)
    fwd = _to_section(model, v, [xe, v], law, rtol=rtol, atol=atol)[0]
    bwd = _to_section(model, v, [xe, v], law, backward=True, rtol=rtol, atol=atol)[0]
    return fwd - bwd


def grazing_speed(model, law, bracket, rtol=RTOL, atol=ATOL) -> float:
    return brentq(lambda v: gs_mismatch(model, v, law, rtol, atol), *bracket, xtol=1e-15,
                  rtol=1e-15)


def hopf_numeric(model, law, bracket) -> float:
    """v where the largest real part of the Jacobian eigenvalues at the numerically
    found equilibrium crosses zero (Jacobian by central differences)."""
    def re(v):
        f = model.plus_field_reduced(v, **law)[0]
        x = np.array([0.5, 0.0])
        for _ in range(50):  # Newton on f(x) = 0
            J = cont.fd_jacobian(f, x, 1e-6)
            dx = np.linalg.solve(J, -f(x))
            x += dx
            if np.max(np.abs(dx)) < 1e-15:
                break
        return float(np.max(np.linalg.eigvals(cont.fd_jacobian(f, x, 1e-6)).real))
    return brentq(re, *bracket, xtol=1e-13)


# --------------------------------------------------------------------------- branches
def hopf_problem(model, law):
    """Shooting (G, J, unpack) with u = (x1, T, v), start point (x1, 0)."""
    return cont.shooting_residual(lambda v: model.plus_field_reduced(v, **law), 1, 0.0, 2)


def max_x2(model, u, law):
    """Largest x2 along the orbit of u = (x1, T, v): where x2' = 0 with x2 > 0."""
    x1, T, v = u
    f = model.plus_field_reduced(v, **law)[0]
    sol = solve_ivp(lambda t, z: f(z), (0.0, T), [x1, 0.0], method="DOP853", rtol=RTOL,
                    atol=ATOL, dense_output=True)
    ev = lambda t, z: f(z)[1]
    ts = np.linspace(0.0, T, 400)
    d = np.array([ev(t, sol.sol(t)) for t in ts])
    best = -np.inf
    for i in np.flatnonzero((d[:-1] > 0) & (d[1:] <= 0)):
        tm = brentq(lambda t: ev(t, sol.sol(t)), ts[i], ts[i + 1], xtol=1e-15)
        best = max(best, float(sol.sol(tm)[1]))
    return best


def start_cycle(model, v, law, amp=0.2):
    """An unstable cycle of region + at v, reached by flowing backward in time
    (it attracts in reverse time) from near the equilibrium, then Newton."""
    f = model.plus_field_reduced(v, **law)[0]
    x_eq = float(model.equilibrium(v, **law)[0])
    sol = solve_ivp(lambda t, z: -f(z), (0.0, 400.0), [x_eq + amp, 0.0], method="DOP853",
                    rtol=1e-10, atol=1e-12)
    z = sol.y[:, -1]
    x1, _ = _to_section(model, v, z, law)
    _, T = _to_section(model, v, [x1, -1e-9], law)  # just past the section: one turn
    G, J, _ = hopf_problem(model, law)
    u, _ = cont.newton(G, J, np.array([x1, T, v]),
                       extra=lambda w: (w[2] - v, np.array([0.0, 0.0, 1.0])))
    return u


def _branch_amplitude(model, u, law) -> float:
    return u[0] - float(model.equilibrium(u[2], **law)[0])


def branch_start(model, law, v_hopf, v_gs):
    """The cycle both continuation directions start from: at v midway between H and GS."""
    return start_cycle(model, 0.5 * (v_hopf + v_gs), law)


def branch_to_hopf(model, law, u0, amp_min, ds, progress=None):
    """From u0 towards H (v decreasing) until the amplitude drops below amp_min.
    Returns the rows u = (x1, T, v) ordered by increasing v (u0 last) and the
    number of folds between kept rows."""
    G, J, _ = hopf_problem(model, law)
    to_h = cont.pseudo_arclength(G, u0, [0, 0, -1], J=J, ds=ds, ds_max=2 * ds, n_max=N_MAX,
                                 stop=lambda u: "amplitude"
                                 if _branch_amplitude(model, u, law) < amp_min else "",
                                 progress=progress)
    # past H the shooting solutions continue onto the same small cycles seen from
    # the other side of the equilibrium (x1 < x1_eq): keep the physical half
    keep = np.array([_branch_amplitude(model, u, law) > 0 for u in to_h.u])
    folds = [i for i in to_h.folds if keep[i] and keep[i + 1]]
    return to_h.u[keep][::-1], len(folds)


def branch_to_grazing(model, law, u0, ds, progress=None):
    """From u0 towards GS (v increasing) until the cycle touches x2 = v; the grazing
    cycle is refined on the branch (v - max x2 = 0 with G = 0). Returns the rows
    after u0 ending with the grazing cycle, the number of folds, and that cycle."""
    G, J, _ = hopf_problem(model, law)
    to_gs = cont.pseudo_arclength(G, u0, [0, 0, 1], J=J, ds=ds, ds_max=4 * ds, n_max=N_MAX,
                                  stop=lambda u: "grazing" if max_x2(model, u, law) > u[2]
                                  else "",
                                  progress=progress)
    if to_gs.stopped != "grazing":
        raise RuntimeError(f"Hopf branch did not reach grazing ({to_gs.stopped})")
    # grazing on the branch: Newton from the secant guess of the last two points
    gfun = lambda u: u[2] - max_x2(model, u, law)
    ua, ub = to_gs.u[-2], to_gs.u[-1]
    ga, gb = gfun(ua), gfun(ub)
    guess = ua + ga / (ga - gb) * (ub - ua)
    u_gs, _ = cont.newton(G, J, guess, extra=lambda u: (gfun(u), cont.fd_jacobian(
        lambda w: np.array([gfun(w)]), u, 1e-6)[0]), tol=1e-12)
    return np.vstack([to_gs.u[1:-1], u_gs[None]]), len(to_gs.folds), u_gs


def hopf_branch(model, law, v_start, v_hopf, amp_min, ds, progress=None):
    """Unstable periodic orbits from the Hopf point to grazing, as rows u = (x1, T, v)
    ordered by v, with the grazing point refined on the branch (both directions
    from the cycle at v_start; the workflow runs them as separate jobs)."""
    u0 = start_cycle(model, v_start, law)
    low, n_low = branch_to_hopf(model, law, u0, amp_min, ds, progress)
    high, n_high, u_gs = branch_to_grazing(model, law, u0, ds, progress)
    return np.vstack([low, high]), u_gs, n_low + n_high


def multipliers_smooth(model, u, law):
    """Floquet multipliers of a region-+ cycle u = (x1, T, v) (no switching)."""
    x1, T, v = u
    f, dfdx, dfdv = model.plus_field_reduced(v, **law)
    _, Phi, _, _ = cont.flow_with_sensitivities(f, dfdx, dfdv, [x1, 0.0], T)
    m = np.linalg.eigvals(Phi)
    return m[np.argsort(-np.abs(m))]


def stick_slip_orbit(model, v, law, *, rtol=RTOL, atol=ATOL):
    """The stick-slip orbit at v: leave sticking at (x_e, v), go to the section, then
    one full period back to it with the event-driven solver. Returns a dict."""
    system = model.model(0.0, v, **law).reduced()
    xe = exit_point(model, law)
    x_start, _ = _to_section(model, v, [xe, v], law, rtol=rtol, atol=atol)
    sec = Section("x2=0", lambda z: z[1], direction=-1,
                  where=lambda z: z[0] > float(model.equilibrium(v, **law)[0]), terminal=1)
    traj = simulate(system, [x_start, 0.0], 100.0, method="integrate", rtol=rtol, atol=atol,
                    sections=[sec], dense=False)
    if traj.status != "section:x2=0":
        raise RuntimeError(f"stick-slip orbit at v={v!r} did not return ({traj.status})")
    kinds = [e.kind for e in traj.events]
    starts = [e for e in traj.events if e.kind == "slide_start"]
    ends = [e for e in traj.events if e.kind == "slide_end"]
    if len(starts) != 1 or len(ends) != 1:
        raise RuntimeError(f"v={v!r}: expected one sticking phase, got events {kinds}")
    _, mult = cont.monodromy(system, traj, jacobian=model.reduced_jacobian(v, **law))
    return {"x1": x_start, "x1_return": float(traj.z[0]), "period": traj.t,
            "stick_time": ends[0].t - starts[0].t,
            "stick_length": float(ends[0].state[0] - starts[0].state[0]),
            "x1_stick": float(starts[0].state[0]), "multipliers": mult, "trajectory": traj}


# --------------------------------------------------------------------------- scene
# Chunking (filippov_paper.scenes.chunking). The work is a list of independent tasks:
# task 0 continues the unstable cycles from the start cycle towards H, the last
# task continues them towards GS (each direction is sequential in itself), and
# every task in between is one stick-slip orbit (one belt speed v). `sweep` runs
# any subset of the tasks; `assemble` builds the dataset from all of them, so a
# merge of chunks is the unsplit compute bit for bit.
CHUNK_AXIS = "task"
TO_HOPF, STICK_SLIP, TO_GRAZING = 0, 1, 2


def _checked(scene: dict) -> dict:
    require(scene, "system", {"reduced"})
    require(scene, "flow", {"integrate"})
    if not scene["ingredients"]["sliding"]:
        raise ValueError(f"{scene['id']}: ingredients.sliding must be true: stick-slip "
                         "orbits stick (slide on x2 = v)")
    return scene["parameters"]


def _special_speeds(model, scene: dict):
    """(law, v_hopf, v_gs): the friction law, the Hopf point and the GS point of the
    scene's model module ``model``."""
    p = _checked(scene)
    law = _law(p)
    v_hopf = model.hopf_speed(law["fv"], law["fc"], law["convention"])
    if not np.isfinite(v_hopf):
        raise ValueError(f"{scene['id']}: parameters: this friction law has no Hopf point")
    return law, v_hopf, _grazing_speed_cached(model, tuple(sorted(law.items())), v_hopf,
                                              float(p["v_max"]))


@functools.lru_cache(maxsize=8)
def _grazing_speed_cached(model, law_items, v_hopf, v_max):
    # chunk_grid, sweep and assemble each need GS; one root search per process
    return grazing_speed(model, dict(law_items), (v_hopf + 1e-3, v_max))


def stick_slip_speeds(p: dict, v_gs: float) -> np.ndarray:
    """Belt speeds of the stick-slip orbits: uniform up to GS plus points accumulating at GS."""
    n, v_min = int(p["n_stick_slip"]), float(p["v_min"])
    near = np.geomspace(float(p["gs_closest"]), 0.1 * (v_gs - v_min), n // 4)
    return np.unique(np.concatenate([np.linspace(v_min, v_gs, n - n // 4, endpoint=False),
                                     v_gs - near]))


def chunk_grid(scene: dict) -> np.ndarray:
    """Task numbers 0 .. n_stick_slip + 1 (see the comment above)."""
    _, _, v_gs = _special_speeds(registered_model(scene), scene)
    return np.arange(stick_slip_speeds(scene["parameters"], v_gs).size + 2, dtype=np.int32)


def _task_kind(task: int, n_tasks: int) -> int:
    return TO_HOPF if task == 0 else TO_GRAZING if task == n_tasks - 1 else STICK_SLIP


def sweep(scene: dict, tasks, progress: bool = False) -> xr.Dataset:
    """Raw results of the given tasks: stick-slip scalars per task, and the branch
    rows of the two continuation tasks padded with NaN to N_MAX + 1 rows."""
    p = _checked(scene)
    model = registered_model(scene)
    law, v_hopf, v_gs = _special_speeds(model, scene)
    vs = stick_slip_speeds(p, v_gs)
    n_tasks = vs.size + 2
    tasks = np.asarray(tasks, dtype=np.int32)
    kinds = np.array([_task_kind(int(t), n_tasks) for t in tasks], dtype=np.int8)
    n_branch = int(np.sum(kinds != STICK_SLIP))
    bar = Progress(scene["id"], int(np.sum(kinds == STICK_SLIP)) + 30 * n_branch, progress)
    k, rows = tasks.size, N_MAX + 1
    nan = lambda *shape: np.full(shape, np.nan)
    ss = {name: nan(k) for name in ("v", "x1", "period", "stick_time", "stick_length",
                                    "trivial_multiplier", "multiplier", "closure")}
    br_u, br_mult = nan(k, rows, 3), nan(k, rows)
    br_rows, br_folds = np.zeros(k, np.int32), np.zeros(k, np.int32)
    u_gs = nan(k, 3)
    u0 = branch_start(model, law, v_hopf, v_gs) if n_branch else None
    for j, (task, kind) in enumerate(zip(tasks, kinds)):
        if kind == STICK_SLIP:
            v = vs[task - 1]
            r = stick_slip_orbit(model, v, law)
            m = np.abs(r["multipliers"])
            for name, value in (("v", v), ("x1", r["x1"]), ("period", r["period"]),
                                ("stick_time", r["stick_time"]),
                                ("stick_length", r["stick_length"]),
                                ("trivial_multiplier", m[0]), ("multiplier", m[1]),
                                ("closure", abs(r["x1_return"] - r["x1"]))):
                ss[name][j] = value
            bar.step()
            continue
        if kind == TO_HOPF:
            u, n_folds = branch_to_hopf(model, law, u0, float(p["amp_min"]), float(p["ds"]), bar)
        else:
            u, n_folds, u_gs[j] = branch_to_grazing(model, law, u0, float(p["ds"]), bar)
        br_u[j, :len(u)] = u
        br_mult[j, :len(u)] = [np.abs(multipliers_smooth(model, row, law)[0]) for row in u]
        br_rows[j], br_folds[j] = len(u), n_folds
    raw = {f"ss_{name}": (CHUNK_AXIS, value) for name, value in ss.items()}
    raw.update(kind=(CHUNK_AXIS, kinds), br_u=((CHUNK_AXIS, "row", "u"), br_u),
               br_multiplier=((CHUNK_AXIS, "row"), br_mult), br_rows=(CHUNK_AXIS, br_rows),
               br_folds=(CHUNK_AXIS, br_folds), u_gs=((CHUNK_AXIS, "u"), u_gs))
    return xr.Dataset(raw, coords={CHUNK_AXIS: tasks})


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = _checked(scene)
    model = registered_model(scene)
    law, v_hopf, v_gs = _special_speeds(model, scene)
    v_hopf_num = hopf_numeric(model, law, (0.5 * v_hopf, 1.5 * v_hopf))
    br, po_mult, u_gs, n_folds = unstable_cycles(raw)
    ds = xr.Dataset(
        # one dict in the dataset's variable order
        {**_point_vars(model, law, v_hopf, v_hopf_num, v_gs, u_gs, n_folds),
         **_equilibrium_vars(model, law, p, v_hopf),
         **_cycle_vars(br, po_mult),
         **_stick_slip_vars(_stick_slip_rows(raw)),
         **_friction_vars(model, law, p)},
    )
    return finalize(ds, scene, method="integrate", friction_convention=law["convention"],
                    title="dry-friction oscillator Eq. (C.1): friction law and bifurcation "
                          "diagram (Fig. C.1)")


def unstable_cycles(raw: xr.Dataset):
    """The unstable cycles born at H from the two continuation tasks: towards H
    (ordered by v), then towards GS; their multipliers, the grazing cycle (x1, period,
    v) and the number of folds."""
    kind = raw["kind"].values

    def rows(which):
        j = int(np.flatnonzero(kind == which)[0])
        n = int(raw["br_rows"].values[j])
        return raw["br_u"].values[j, :n], raw["br_multiplier"].values[j, :n], j
    low, m_low, j_low = rows(TO_HOPF)
    high, m_high, j_high = rows(TO_GRAZING)
    br, po_mult = np.vstack([low, high]), np.concatenate([m_low, m_high])
    u_gs = raw["u_gs"].values[j_high]
    n_folds = int(raw["br_folds"].values[j_low] + raw["br_folds"].values[j_high])
    return br, po_mult, u_gs, n_folds


def _stick_slip_rows(raw: xr.Dataset) -> dict:
    """The stick-slip tasks' scalars, by name without the ss_ prefix."""
    sel = raw["kind"].values == STICK_SLIP
    return {name[3:]: raw[name].values[sel] for name in raw.data_vars if name.startswith("ss_")}


def _point_vars(model, law, v_hopf, v_hopf_num, v_gs, u_gs, n_folds) -> dict:
    """The special points: Hopf, grazing-sliding, the exit of sticking."""
    return {
        "v_hopf": ((), v_hopf, {"long_name": "Hopf point: belt speed with F_c'(-v) = 0, ln(fc/fv)",
                                "units": "1"}),
        "v_hopf_numeric": ((), v_hopf_num, {"long_name": "Hopf point from the eigenvalues of a "
                                            "finite-difference Jacobian", "units": "1"}),
        "v_gs": ((), v_gs, {"long_name": "grazing-sliding point GS (orbit through the sticking "
                            "exit point closes)", "units": "1"}),
        "v_gs_branch": ((), float(u_gs[2]), {"long_name": "grazing point of the continued branch "
                                          "of unstable cycles", "units": "1"}),
        "x1_gs": ((), float(u_gs[0]), {"long_name": "max x1 of the grazing orbit", "units": "1"}),
        "period_gs": ((), float(u_gs[1]), {"long_name": "period of the grazing orbit", "units": "1"}),
        "x1_exit": ((), exit_point(model, law), {"long_name": "x1 where sticking ends (-F_c(0-))",
                                          "units": "1"}),
        "n_folds_hopf_branch": ((), n_folds, {"long_name": "folds on the unstable branch",
                                                  "units": "1"}),
    }


def _equilibrium_vars(model, law, p: dict, v_hopf: float) -> dict:
    """The equilibrium over [v_min, v_max] with the Hopf point on the grid."""
    ve = np.linspace(float(p["v_min"]), float(p["v_max"]), 401)
    veq = np.unique(np.concatenate([ve, [v_hopf]]))
    x_eq = model.equilibrium(veq, **law)[0]
    return {
        "eq_v": ("eq", veq, {"long_name": "belt speed v", "units": "1"}),
        "eq_x1": ("eq", x_eq, {"long_name": "x1 of the equilibrium, -F_c(-v)", "units": "1"}),
        "eq_stable": ("eq", (veq > v_hopf).astype(np.int8),
                      {"long_name": "1 if the equilibrium is asymptotically stable", "units": "1"}),
    }


def _cycle_vars(br, po_mult) -> dict:
    """The unstable cycles in region + (rows of :func:`unstable_cycles`)."""
    return {
        "po_v": ("po", br[:, 2], {"long_name": "belt speed v", "units": "1"}),
        "po_x1": ("po", br[:, 0], {"long_name": "max x1 along the cycle", "units": "1"}),
        "po_period": ("po", br[:, 1], {"long_name": "period", "units": "1"}),
        "po_multiplier": ("po", po_mult,
                          {"long_name": "nontrivial Floquet multiplier (modulus)", "units": "1"}),
        "po_stable": ("po", (po_mult < 1).astype(np.int8),
                      {"long_name": "1 if the cycle is stable", "units": "1"}),
    }


def _stick_slip_vars(ss: dict) -> dict:
    """The stick-slip orbits, one per belt speed of the sweep."""
    return {
        "ss_v": ("ss", ss["v"], {"long_name": "belt speed v", "units": "1"}),
        "ss_x1": ("ss", ss["x1"], {"long_name": "max x1 along the orbit",
                                   "units": "1"}),
        "ss_period": ("ss", ss["period"], {"long_name": "period", "units": "1"}),
        "ss_stick_time": ("ss", ss["stick_time"],
                          {"long_name": "time spent sticking (sliding on x2 = v)", "units": "1"}),
        "ss_stick_length": ("ss", ss["stick_length"],
                            {"long_name": "x1 distance travelled while sticking", "units": "1"}),
        "ss_multiplier": ("ss", ss["multiplier"],
                          {"long_name": "nontrivial Floquet multiplier (modulus), with saltation",
                           "units": "1"}),
        "ss_trivial_multiplier": ("ss", ss["trivial_multiplier"],
                                  {"long_name": "trivial Floquet multiplier (should be 1)",
                                   "units": "1"}),
        "ss_closure": ("ss", ss["closure"],
                       {"long_name": "|x1 after one period - x1 at start|", "units": "1"}),
        "ss_stable": ("ss", (ss["multiplier"] < 1).astype(np.int8),
                      {"long_name": "1 if the orbit is stable (multipliers)", "units": "1"}),
    }


def _friction_vars(model, law, p: dict) -> dict:
    """The friction law over the relative velocity, as adopted and as printed."""
    nu = np.linspace(-float(p["nu_max"]), float(p["nu_max"]), 801)
    # both sides of the jump at 0, not 0 itself (F_c is set-valued there)
    nu = np.unique(np.concatenate([nu, [-1e-12, 1e-12]]))
    nu = nu[nu != 0]
    F = model.friction(nu, **law)
    F_lit = model.friction(nu, **dict(law, convention="literal"))
    _, _, Fm, _ = model.friction_branches(**law)
    return {
        "nu": ("nu", nu, {"long_name": "relative velocity x2 - v", "units": "1"}),
        "F_c": ("nu", F, {"long_name": "friction force F_c (adopted convention)", "units": "1"}),
        "F_c_literal": ("nu", F_lit, {"long_name": "friction force, printed law read literally",
                                      "units": "1"}),
        "F_c_static": ((), float(Fm(0.0)), {"long_name": "F_c(0+), the static friction level",
                                            "units": "1"}),
    }


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
#: the report does without this scene (its section says "not yet computed")
REPORT_OPTIONAL = True


def report(ds, m: Macros) -> str:
    """Macros for the bifurcation diagram's findings (Hopf and grazing-sliding points,
    multipliers), each when its variable is present, and a table of the scalars."""
    missing = absent(m, "rpHaveTen", ds, "fig10", "results/fig10_dfo.nc")
    if missing:
        return missing
    for name_var, name, sig in (("v_hopf", "rpTenVHopf", 10), ("v_hopf_numeric", "rpTenVHopfNum", 10),
                                ("v_gs", "rpTenVGS", 9), ("v_gs_branch", "rpTenVGSBranch", 9),
                                ("x1_gs", "rpTenXGS", 5), ("period_gs", "rpTenPeriodGS", 5),
                                ("F_c_static", "rpTenStatic", 3)):
        if name_var in ds:
            var(m, name, ds, "fig10_dfo", name_var, sig)
        else:
            m.add(name, None, f"fig10_dfo:{name_var} (missing)",
                  text=r"\emph{(" + name_var + " missing)}")
    if "ss_multiplier" in ds:
        m.add("rpTenSSMultMax", float(np.nanmax(ds.ss_multiplier.values)),
              "derived:max(fig10_dfo:ss_multiplier)", 2)
    if "po_multiplier" in ds:
        m.add("rpTenPOMultMin", float(np.nanmin(ds.po_multiplier.values)),
              "derived:min(fig10_dfo:po_multiplier)", 5)
    return scalar_table(ds)


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "fv"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"n_stick_slip": 8, "ds": 0.2}
