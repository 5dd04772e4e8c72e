"""The Poincare discontinuity map P_DM of the slow-fast Hopf example, computed
by the event-driven solver (appendix of the paper, Eq. (B.1)).

P_DM maps the curve L2 = {y = x1, h'_+ = 0} near the grazing point
p_g = (-1, 0, -1) to itself. On M_+ = {y = x1} the condition h'_+ = 0 reads
x1' = f_+,1(x) = 0, so L2 is the set of minima of x1 along the orbits of E_+ on
M_+, and it is parametrised by x1. For a point p0 of L2 with x1 < -1
(Eq. (B.1))

    P_DM = Pi_3 o P_3 o Pi_2 o Pi_1:

* Pi_1 follows E_+ backward from p0 to H_s (within M_+);
* Pi_2 follows the true dynamics forward from there: E_- until H_s is hit
  again (theta < 0), or the sliding flow until h'_+ = 0 (theta > 0);
* P_3 projects along the stable fibres of E_+, (x1, x2, y) -> (x1, x2, x1);
* Pi_3 follows E_+ on M_+ to L2.

Numerically: p0 is moved backward along E_+ on M_+ (its exact flow: M_+ is
invariant and the Hopf flow is known in closed form) to a start point in the
interior of region +, a little before the crossing of H_s. From there the solver
integrates the full piecewise system forward; it finds the crossing of H_s (that
is Pi_1, located by the solver's own event detection), then follows E_- or
slides (Pi_2), and detects the switch back to E_+ at the point p2. P_3 and
Pi_3 are applied by projecting p2 onto M_+ and running the solver on the smooth
flow E_+ alone (no switching) to the section L2. Because f_+ does not depend on
y, the x-part of E_+ from p2 and from P_3(p2) coincide, so this is exactly the
paper's map, with no further asymptotics.

The paper's Pi_3 ignores H_s. Where P_DM(xi1) < 0 the true orbit crosses H_s
again before it reaches L2; :func:`discontinuity_map` therefore also returns
``P_flow``, the x1 at which the true trajectory of the piecewise system first
reaches L2 (after all its excursions): the local map the return map sees.

Coordinates: xi1 = (x1 + 1) / scale with scale = eps for theta < 0 (Eq. (B.2))
and scale = eps^2 for theta > 0 (Eq. (B.24)); in both scalings x2 and time are
scaled by sqrt(scale).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .model import SlowFastModel
from .models.hopf import hopf_rhs, polar_flow
from .poincare import sliding_time
from .progress import Progress
from .simulate import SimulationError, Section, simulate
from .system import MINUS, PLUS, SLIDING, PiecewiseSystem


def scale_for(eps: float, theta: float) -> float:
    """Size of the grazing neighbourhood in x1 and mu: eps (theta < 0), eps^2 (theta > 0)."""
    if theta == 0:
        raise ValueError("theta = 0 is the degenerate boundary between the two cases")
    return eps if theta < 0 else eps * eps


def l2_x2(x1, mu: float, omega: float):
    """x2 of the point of L2 with the given x1: the root near 0 of
    f_+,1 = mu x1 - omega x2 - (x1^2 + x2^2) x1 = 0 (Eq. (B.9)), written without
    cancellation."""
    x1 = np.asarray(x1, dtype=float)
    c = x1 * (mu - x1 * x1)
    return 2.0 * c / (omega + np.sqrt(omega * omega + 4.0 * x1 * c))


def l2_section(mu: float, omega: float) -> Section:
    """L2 projected along the fibres: x1' = 0 with x1' increasing (a minimum of x1)."""
    return Section("L2", lambda z: hopf_rhs(z[0], z[1], mu, omega)[0], direction=+1, terminal=1)


def smooth_plus(system: PiecewiseSystem) -> PiecewiseSystem:
    """The smooth flow E_+ alone: the same field and exact flow, no switching surface."""
    return PiecewiseSystem(
        names=system.names, field_minus=system.field_plus, field_plus=system.field_plus,
        switch=lambda z: np.ones_like(np.asarray(z, dtype=float)[0]),
        switch_grad=lambda z: np.zeros_like(np.asarray(z, dtype=float)),
        flows={PLUS: system.flows[PLUS]} if PLUS in system.flows else {},
        sliding=False, sample_step=system.sample_step, units=system.units,
        description=f"E_+ of {system.description}")


@dataclass(frozen=True)
class PDMResult:
    """P_DM on a grid of xi1 (all arrays have the grid's shape).

    Rescaled quantities use ``scale`` for x1 and ``sqrt(scale)`` for x2 and time;
    times in ``excursion_time`` are in units of eps (the fast time s of Eq. (B.13)
    for theta < 0, the time t of Eq. (B.28) for theta > 0).
    """

    scale: float
    xi1: np.ndarray            # xi1 of the start point on L2, from the double actually used
    P: np.ndarray              # paper's P_DM (Pi_3 ignores H_s)
    P_flow: np.ndarray         # first arrival of the true trajectory at L2
    n_switches: np.ndarray     # mode changes of the true trajectory on its way to L2
    xi2_entry: np.ndarray      # xi2 where the trajectory first meets H_s (Pi_1), NaN if it does not
    excursion_time: np.ndarray  # time in mode - or sliding during the first excursion, / eps
    xi1_exit: np.ndarray       # xi1 where the first excursion ends (point p2)
    xi2_exit: np.ndarray       # xi2 there
    sliding_time: np.ndarray   # total sliding time of the true trajectory / eps


def _first_excursion(events):
    """(entry event, exit event) of the first stay in mode - or sliding, or (None, None)."""
    entry = None
    for e in events:
        if entry is None and e.mode_before == PLUS and e.mode_after in (MINUS, SLIDING):
            entry = e
        elif entry is not None and e.mode_before in (MINUS, SLIDING) and e.mode_after == PLUS:
            return entry, e
    return entry, None


def discontinuity_map(model: SlowFastModel, xi1, *, scale: float | None = None,
                      sliding: bool = True, method: str = "exact",
                      rtol: float = 1e-12, atol: float = 1e-14, back: float = 1.3,
                      progress: Progress | None = None) -> PDMResult:
    """P_DM(xi1) of the slow-fast Hopf ``model`` on the grid ``xi1`` (rescaled).

    ``back`` sets how far before the crossing of H_s the solver starts: the start
    point is p0 moved backward along E_+ by ``back`` times the leading-order
    time to H_s (plus one unit of the scaled time for points with xi1 >= 0).
    """
    p = model.parameters
    eps, theta, mu, omega = (float(p[k]) for k in ("eps", "theta", "mu", "omega"))
    if scale is None:
        scale = scale_for(eps, theta)
    if not back > 1:
        raise ValueError("back must be > 1: the start point must lie before the crossing")
    system = model.full(sliding=sliding, exact=method == "exact")
    smooth = smooth_plus(system)
    section = l2_section(mu, omega)
    t_max = 2 * np.pi / abs(omega)  # one turn: far beyond the local dynamics
    opts = dict(method=method, rtol=rtol, atol=atol, dense=False)

    grid = np.asarray(xi1, dtype=float)
    out = {k: np.full(grid.shape, np.nan) for k in (
        "xi1", "P", "P_flow", "xi2_entry", "excursion_time", "xi1_exit", "xi2_exit",
        "sliding_time")}
    n_sw = np.zeros(grid.shape, dtype=np.int64)
    root = np.sqrt(scale)
    for idx, xi in np.ndenumerate(grid):
        x10 = -1.0 + scale * xi
        out["xi1"][idx] = (x10 + 1.0) / scale  # exact: Sterbenz
        x20 = float(l2_x2(x10, mu, omega))
        # leading order x1(t) = x10 + omega^2 t^2 / 2 about the minimum
        tau = back * np.sqrt(2.0 * scale * (abs(xi) + (1.0 if xi >= 0 else 0.0))) / abs(omega)
        s1, s2 = polar_flow(x10, x20, np.asarray(-tau), mu, omega)
        z0 = np.array([float(s1), float(s2), float(s1)])  # on M_+, inside region +
        if not float(system.switch(z0)) > 0:
            raise SimulationError(
                f"start point for xi1={xi!r} (eps={eps!r}) is not inside region +: x1 = -1 + "
                f"{scale * abs(xi):.3g} is below the resolution of x1 near -1, or the start "
                f"is too close to the crossing (argument back={back!r})")
        traj = simulate(system, z0, t_max, sections=[section], **opts)
        if traj.status != "section:L2" or traj.events[-1].mode_after != PLUS:
            raise RuntimeError(f"xi1={xi!r}: the trajectory did not return to L2 in mode + "
                               f"(status {traj.status})")
        out["P_flow"][idx] = (traj.events[-1].state[0] + 1.0) / scale
        n_sw[idx] = len(traj.switches())
        out["sliding_time"][idx] = sliding_time(traj.events) / eps
        entry, exit_ = _first_excursion(traj.events)
        if entry is None:  # no contact with H_s: P_DM is the identity here
            out["P"][idx] = out["P_flow"][idx]
        else:
            out["xi2_entry"][idx] = entry.state[1] / root
            if exit_ is None:
                raise RuntimeError(f"xi1={xi!r}: reached L2 without leaving H_s or region -")
            out["excursion_time"][idx] = (exit_.t - entry.t) / eps
            p2 = exit_.state
            out["xi1_exit"][idx] = (p2[0] + 1.0) / scale
            out["xi2_exit"][idx] = p2[1] / root
            p3 = np.array([p2[0], p2[1], p2[0]])  # P_3: along the stable fibre onto M_+
            if not hopf_rhs(p3[0], p3[1], mu, omega)[0] < 0:
                raise RuntimeError(f"xi1={xi!r}: p2 lies beyond L2; Pi_3 would run backward")
            arm = simulate(smooth, p3, t_max, sections=[section], **opts)
            if arm.status != "section:L2":
                raise RuntimeError(f"xi1={xi!r}: E_+ from P_3(p2) did not reach L2")
            out["P"][idx] = (arm.events[-1].state[0] + 1.0) / scale
        if progress is not None:
            progress.step()
    return PDMResult(scale=scale, n_switches=n_sw, **out)
