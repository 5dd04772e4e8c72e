"""Compact numerical continuation for the paper's bifurcation diagrams.

No maintained Python package continues periodic orbits of Filippov systems
(PyPI's ``pacopy`` continues solutions of F(u, p) = 0 only, without shooting,
Floquet multipliers or saltation matrices), so this module keeps the few pieces
needed, each tested in tests/test_continuation.py:

* :func:`pseudo_arclength` -- a branch of solutions of G(u) = 0, G: R^(n+1) -> R^n,
  by predictor (tangent) and Newton corrector on the arclength constraint, with
  detection of folds (the parameter component of the tangent changes sign);
* :func:`locate_fold` -- a fold (saddle-node) refined as the extremum of the
  parameter along the branch;
* :func:`flow_with_sensitivities` -- a smooth flow with its Jacobians with respect
  to the start state and a parameter (variational equations, DOP853);
* :func:`shooting_residual` -- periodic orbits of a smooth field by single
  shooting with the phase fixed by a coordinate section (unknowns: the other
  start coordinates, the period and the parameter);
* :func:`monodromy` -- the monodromy matrix of a (nonsmooth) periodic orbit from
  an event-driven trajectory of :mod:`filippov.simulate`: variational equations on
  each smooth or sliding segment and saltation matrices at the switches;
* :func:`floquet_multipliers` -- its eigenvalues, checked for the multiplier 1
  every periodic orbit of an autonomous system has.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Optional

import numpy as np
import scipy.linalg
from scipy.integrate import solve_ivp
from scipy.optimize import minimize_scalar

from .progress import Progress
# the derivatives live in filippov.variational; fd_jacobian and saltation stay
# importable from here, where the continuation code and its users reach for them
from .variational import (VariationalError, _modes, _state_scale, fd_jacobian,  # noqa: F401
                          reference_view, saltation, switch_matrix, transition_matrix)
from .errors import ContinuationError  # noqa: F401  (re-exported)


def _null_vector(J: np.ndarray) -> np.ndarray:
    """Unit vector spanning the kernel of an n x (n+1) matrix."""
    _, _, vt = np.linalg.svd(J)
    return vt[-1]


# --------------------------------------------------------------------------- continuation
@dataclass
class Branch:
    """Points ``u`` (rows) of a branch, their unit tangents, and the indices i
    where a fold lies between points i and i+1."""

    u: np.ndarray
    tangent: np.ndarray
    folds: list = field(default_factory=list)
    stopped: str = ""


def newton(G, J, u, *, tol=1e-12, max_iter=12, extra=None, floor=1.0):
    """Newton for the square system [G(u); extra(u)] = 0 (``extra`` returns a
    (value, gradient) pair for one more scalar equation). Converged when a step is below
    ``tol max(floor, |u|)``; ``floor``: the unknowns' scale, 1 unless given -- the
    guess's size alone cannot tell it (a small guess near a root at 0 of a residual with
    terms of order one never meets a test at its own size): give it for unknowns in
    other units (filippov.scale)."""
    u = np.asarray(u, dtype=float).copy()
    for it in range(max_iter):
        r = np.atleast_1d(G(u))
        A = np.atleast_2d(J(u))
        if extra is not None:
            e, de = extra(u)
            r = np.append(r, e)
            A = np.vstack([A, de])
        du = np.linalg.solve(A, -r)
        u += du
        if np.max(np.abs(du)) <= tol * max(floor, np.max(np.abs(u))):
            return u, it + 1
    raise ContinuationError(f"Newton did not converge in {max_iter} iterations "
                            f"(last step {np.max(np.abs(du)):.3e}) at u={u.tolist()}")


def pseudo_arclength(G, u0, direction, *, J=None, ds=0.05, ds_min=1e-6, ds_max=0.2,
                     n_max=200, param_index=-1, stop: Optional[Callable] = None,
                     tol=1e-11, progress: Progress | None = None) -> Branch:
    """Continue G(u) = 0 from the solution ``u0`` with initial tangent sign given by
    ``direction`` (a vector; the tangent is oriented to have a positive dot
    product with it). ``stop(u)`` returning a non-empty string ends the branch
    after accepting u. Folds: sign changes of the tangent's ``param_index``
    component."""
    Jf = J if J is not None else (lambda u: fd_jacobian(G, u))
    u = np.asarray(u0, dtype=float)
    t = _null_vector(np.atleast_2d(Jf(u)))
    if t @ np.asarray(direction, dtype=float) < 0:
        t = -t
    us, ts, folds = [u.copy()], [t.copy()], []
    reason = "n_max"
    for _ in range(n_max):
        while True:
            pred = u + ds * t
            try:
                unew, its = newton(G, Jf, pred, tol=tol,
                                   extra=lambda w, u=u, t=t, ds=ds: ((w - u) @ t - ds, t))
            except (ContinuationError, np.linalg.LinAlgError, RuntimeError):
                its = None
            if its is not None:
                break
            ds /= 2
            if ds < ds_min:
                raise ContinuationError(f"step size below {ds_min} at u={u.tolist()}")
        tnew = _null_vector(np.atleast_2d(Jf(unew)))
        if tnew @ t < 0:
            tnew = -tnew
        if np.sign(tnew[param_index]) != np.sign(t[param_index]) and t[param_index] != 0:
            folds.append(len(us) - 1)
        u, t = unew, tnew
        us.append(u.copy())
        ts.append(t.copy())
        if progress is not None:
            progress.step()
        if its <= 3:
            ds = min(1.5 * ds, ds_max)
        if stop is not None:
            why = stop(u)
            if why:
                reason = why
                break
    return Branch(np.array(us), np.array(ts), folds, reason)


def locate_fold(G, u_a, u_b, *, param_index=-1, state_index=None, tol=1e-12):
    """The fold between branch points ``u_a`` and ``u_b``: the extremum of the
    parameter along the branch, the branch parametrised by one state coordinate
    (the one changing most between the two points, monotone through a fold).

    Returns (u at the fold, 'max' or 'min'). The extremal parameter value is
    insensitive to the error in the state coordinate (quadratic), so it comes
    out to about the accuracy of G.
    """
    u_a, u_b = np.asarray(u_a, float), np.asarray(u_b, float)
    n1 = u_a.size
    p = param_index % n1
    if state_index is None:
        d = np.abs(u_b - u_a)
        d[p] = -1.0
        state_index = int(np.argmax(d))
    free = [i for i in range(n1) if i != state_index]
    cache = {}

    def solve(s):
        # solve for everything but coordinate state_index, from the interpolated guess
        # (or the nearest point solved before)
        frac = (s - u_a[state_index]) / (u_b[state_index] - u_a[state_index])
        guess = u_a + frac * (u_b - u_a)
        if cache:
            k = min(cache, key=lambda c: abs(c - s))
            guess = cache[k].copy()
        guess[state_index] = s

        def Gr(w):
            full = guess.copy()
            full[free] = w
            return G(full)

        w, _ = newton(Gr, lambda w: fd_jacobian(Gr, w), guess[free], tol=tol)
        full = guess.copy()
        full[free] = w
        cache[s] = full
        return full

    mid = solve(0.5 * (u_a[state_index] + u_b[state_index]))
    pa, pb, pm = u_a[p], u_b[p], mid[p]
    lo, hi = sorted([u_a[state_index], u_b[state_index]])
    # the midpoint's guess of the kind is wrong where the fold lies in an outer quarter of
    # the bracket: each kind's extremum must be beyond both ends' parameter to count
    # (found by an independent review: p = 1 - x^2 bracketed by x = -0.05, 0.5 gave the
    # end p = 0.75 as a 'min')
    first = "max" if pm > max(pa, pb) else "min"
    for kind in (first, "min" if first == "max" else "max"):
        sign = -1.0 if kind == "max" else 1.0
        res = minimize_scalar(lambda s: sign * solve(s)[p], bounds=(lo, hi),
                              method="bounded", options={"xatol": 1e-9 * max(1.0, abs(hi))})
        u = solve(res.x)
        if sign * u[p] < sign * (max(pa, pb) if kind == "max" else min(pa, pb)):
            return u, kind
    raise ContinuationError(f"locate_fold: no fold between the branch points {u_a.tolist()} "
                            f"and {u_b.tolist()}: the parameter along the branch has no "
                            "extremum inside the bracket")


# --------------------------------------------------------------------------- smooth flows
def flow_with_sensitivities(f, dfdx, dfdp, x0, T, *, rtol=1e-12, atol=1e-14,
                            events=None, dense_output=False):
    """x(T), dx(T)/dx0 and dx(T)/dp of x' = f(x) (parameter fixed inside f,
    dfdp its derivative) by the variational equations.

    Returns (x_T, Phi, S, sol)."""
    x0 = np.asarray(x0, dtype=float)
    n = x0.size

    def rhs(t, z):
        x, Phi, S = z[:n], z[n:n + n * n].reshape(n, n), z[n + n * n:]
        A = dfdx(x)
        return np.concatenate([f(x), (A @ Phi).ravel(), A @ S + dfdp(x)])

    z0 = np.concatenate([x0, np.eye(n).ravel(), np.zeros(n)])
    sol = solve_ivp(rhs, (0.0, T), z0, method="DOP853", rtol=rtol, atol=atol,
                    events=events, dense_output=dense_output)
    if not sol.success:
        raise ContinuationError(f"variational integration failed: {sol.message}")
    z = sol.y[:, -1]
    return z[:n], z[n:n + n * n].reshape(n, n), z[n + n * n:], sol


def shooting_residual(make_field, fixed_index: int, fixed_value: float, n: int, *,
                      rtol=1e-12, atol=1e-14):
    """(G, J) for periodic orbits of x' = f(x; p): unknowns u = (free start
    coordinates, T, p), the start point having x[fixed_index] = fixed_value
    (the phase condition). ``make_field(p)`` returns (f, dfdx, dfdp)."""
    free = [i for i in range(n) if i != fixed_index]

    def unpack(u):
        x0 = np.empty(n)
        x0[fixed_index] = fixed_value
        x0[free] = u[:n - 1]
        return x0, u[n - 1], u[n]

    def both(u):
        x0, T, p = unpack(u)
        f, dfdx, dfdp = make_field(p)
        xT, Phi, S, _ = flow_with_sensitivities(f, dfdx, dfdp, x0, T, rtol=rtol, atol=atol)
        r = xT - x0
        Jx = (Phi - np.eye(n))[:, free]
        return r, np.column_stack([Jx, f(xT), S])

    cache = {}

    def cached(u):
        key = tuple(np.asarray(u, float))
        if key not in cache:
            cache.clear()
            cache[key] = both(np.asarray(u, float))
        return cache[key]

    return (lambda u: cached(u)[0]), (lambda u: cached(u)[1]), unpack


# --------------------------------------------------------------------------- Floquet
def monodromy(system, traj, *, rtol=1e-10, atol=1e-12, jacobian=None):
    """Monodromy matrix of the periodic orbit traced by ``traj`` (one period,
    from a start point back to it), built from its events:

    * on every segment between events the variational equation of that mode's
      field (the Filippov field while sliding) is integrated from the event
      state (Jacobians by ``jacobian(mode, z)`` or central differences);
    * at a crossing or the start of sliding the saltation matrix with the
      normal grad H applies; it projects onto T H_s when sliding starts;
    * at the end of sliding the field is continuous (a or b is zero there, so
      the sliding field equals the field it leaves into): identity;
    * a period that starts on the switching surface ends in another mode than
      it started in: that switch is applied once, at the end, so the result
      does not depend on where on the orbit the period starts.

    Returns (M, multipliers sorted by modulus, descending). ``system``, ``jacobian`` and
    ``atol`` (in units of the run's state scale, ``traj.scale``) as for
    :func:`filippov.variational.transition_matrix`."""
    system, jacobian = reference_view(system, jacobian, "monodromy", _state_scale(traj))
    try:
        M = transition_matrix(system, traj, rtol=rtol, atol=atol, jacobian=jacobian)
        # simulate logs a start on H = 0 as 'start' in the mode it leaves in, and the
        # return to it is logged as a switch only if rounding puts the end state past
        # the surface: close the period with the switch from the end mode to the start
        # mode. Saltations of crossings at one point compose (S_bc S_ab = S_ac,
        # S_ba S_ab = I), so a switch logged at t0 or at the end too is not counted twice.
        # (the system's own switch: one surface's, or that of the surface a
        # several-surface run's modes differ on)
        S = _modes(system)[1](traj.mode, traj.events[0].mode_after, traj.z)
    except VariationalError as exc:
        raise ContinuationError(str(exc)) from exc
    if S is not None:
        M = S @ M
    mult = np.linalg.eigvals(M)
    return M, mult[np.argsort(-np.abs(mult))]


def floquet_multipliers(system, traj, *, rtol=1e-10, atol=1e-12, jacobian=None,
                        check=True):
    """Floquet multipliers of the periodic orbit traced by ``traj`` (see
    :func:`monodromy`), sorted by modulus, descending. With ``check``, a
    ContinuationError is raised when none of them is 1 within the accuracy of the
    computation: the system is autonomous, so the flow direction f(z0) of a
    periodic orbit is an eigenvector with multiplier 1, and its absence means the
    monodromy matrix (or the orbit) is wrong.

    Tolerance, by first-order perturbation theory: an error E in M moves a simple
    eigenvalue lambda_i by at most ``kappa_i |E|`` (``kappa_i = 1 / |w_i^H v_i|``, unit left
    and right eigenvectors; large near a defective eigenvalue, e.g. a second
    multiplier near 1 at a fold, where the check cannot decide and passes).
    ``|E| / max(1, |M|)`` is estimated as the sum of

    * 100 (rtol + atol): the DOP853 global error of the variational equations, seen
      at <= 3 rtol over a period on the orbits of tests/test_continuation.py and the
      stick-slip orbits (rtol 1e-6 .. 1e-12), with a x30 margin;
    * 1e-8 when no ``jacobian`` is given: central differences at step 1e-6 carry a
      rounding error eps/1e-6 ~ 2e-10 relative to the field, seen at <= 3e-9 in M;
    * ``|f(z_T) - f(z0)| / |f(z0)|``: ``traj`` ends at z_T, not exactly at z0, and M
      maps f(z0) to f(z_T), so the trivial multiplier is off by that much.

    A missing saltation matrix shifts it by O(1)."""
    system, jacobian = reference_view(system, jacobian, "floquet_multipliers", _state_scale(traj))
    M, _ = monodromy(system, traj, rtol=rtol, atol=atol, jacobian=jacobian)
    lam, wl, vr = scipy.linalg.eig(M, left=True, right=True)
    order = np.argsort(-np.abs(lam))
    if check:
        mode = traj.events[0].mode_after
        f0 = system.field(mode, traj.z0)
        scale = np.linalg.norm(f0)
        if not scale > 0:
            raise ContinuationError(f"the start point {traj.z0.tolist()} is an equilibrium: "
                                    "no periodic orbit through it")
        err = (100 * (rtol + atol) + (1e-8 if jacobian is None else 0.0)
               + np.linalg.norm(system.field(mode, traj.z) - f0) / scale)
        err *= max(1.0, np.linalg.norm(M, 2))
        with np.errstate(divide="ignore"):
            kappa = 1.0 / np.abs(np.sum(wl.conj() * vr, axis=0))
        if not np.any(np.abs(lam - 1) <= kappa * err):
            i = int(np.argmin(np.abs(lam - 1)))
            raise ContinuationError(
                f"no Floquet multiplier is 1: the nearest is {lam[i]:.6g} (|m - 1| = "
                f"{abs(lam[i] - 1):.2e} > {kappa[i] * err:.2e}, the accuracy of M): the "
                f"monodromy matrix or the orbit is wrong; multipliers {lam[order].tolist()}")
    lam = lam[order]
    return lam.real if np.all(lam.imag == 0) else lam   # as np.linalg.eigvals
