"""Periodic orbits through a section, on either engine, from one system definition.

A periodic orbit crossing a section is a fixed point of the section's return map P.
:func:`periodic_orbit` finds it by Newton's method on P(z) - z with the derivative
dP/dz of each return -- the compiled engine's (``compute_returns(jacobian=True)``) or
the reference driver's (:func:`filippov.variational.return_jacobian`) -- and returns its
Floquet multipliers: the multiplier 1 of an autonomous orbit and the eigenvalues of
dP/dz on a complement of the flow direction (dP/dz f = 0 there: a shift along the orbit
is no perturbation of P). That the flow
direction is indeed annihilated is checked, not assumed: a derivative that fails it is
an error, never a silent multiplier.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

ENGINES = ("compiled", "python")


class PeriodicOrbitError(RuntimeError):
    """Newton's method did not converge, a return failed, or the derivative at the
    fixed point does not annihilate the flow direction."""


@dataclass(frozen=True)
class PeriodicOrbit:
    """A fixed point of the return map to a section and what it says of the orbit."""

    point: np.ndarray          # (n,) the orbit's point on the section
    period: float              # the return time there
    multipliers: np.ndarray    # (n,) Floquet multipliers, the flow's 1 first, then by |.|
    jacobian: np.ndarray       # (n, n) dP/dz at the fixed point
    iterations: int            # Newton steps taken
    residual: float            # max |P(z) - z| at the point


def _returns(system, section, direction: int, engine: str, t_max: float, options: dict):
    """(z -> (P(z), return time, dP/dz), z -> section value) on the chosen engine."""
    if engine == "compiled":
        from .fastmap import OK, compute_returns, failure

        cm = system.compiled(section, direction=direction)

        def one(z):
            out = compute_returns(cm, [z], t_max, jacobian=True, **options)
            if out.status[0] != OK:
                raise PeriodicOrbitError(f"no return from {np.asarray(z).tolist()}: "
                                         f"{failure(cm, out, 0)}")
            return out.state[0], float(out.time[0]), out.jacobian[0]
        return one, lambda z: float(cm.section(np.ascontiguousarray(z, dtype=float), cm.params))

    from .simulate import simulate
    from .variational import return_jacobian

    python, sec = system.python(), system.python_section(section, direction=direction)
    # exact field Jacobians where the system has them (filippov.symbolic), else differences
    jac = system.jacobian if getattr(system, "has_jacobians", False) else None

    def one(z):
        traj = simulate(python, z, t_max, sections=[sec], dense=False, **options)
        if traj.status != f"section:{sec.name}":
            raise PeriodicOrbitError(f"no return from {np.asarray(z).tolist()} within "
                                     f"t_max={t_max!r} (status {traj.status})")
        J = return_jacobian(python, traj, sec, jacobian=jac)
        return np.asarray(traj.z, dtype=float), float(traj.t - traj.t0), J
    return one, lambda z: float(np.asarray(sec.func(z)).reshape(()))


def _section_normal(value, z: np.ndarray) -> np.ndarray:
    """The gradient of the section function at z by central differences (step eps^(1/3)
    times the state's size: ~1e-11 relative for a section that varies on that size)."""
    h = np.cbrt(np.finfo(float).eps) * max(1.0, float(np.abs(z).max()))
    g = np.empty(z.size)
    for k in range(z.size):
        e = np.zeros(z.size)
        e[k] = h
        g[k] = (value(z + e) - value(z - e)) / (2 * h)
    return g


def _field_at(python, z: np.ndarray) -> np.ndarray:
    """The field of the region z lies in (region + where the switching function >= 0)."""
    from .system import MINUS, PLUS

    mode = PLUS if float(python.switch(z)) >= 0 else MINUS
    return np.asarray(python.field(mode, z), dtype=float)


def _complement(v: np.ndarray) -> np.ndarray:
    """An orthonormal basis (n, n-1) of the complement of v: a Householder reflection
    that maps v/|v| to the last axis, without its last column."""
    n = v.size
    u = v / np.linalg.norm(v)
    e = np.zeros(n)
    e[-1] = 1.0
    w = u - e if u[-1] <= 0 else u + e
    R = np.eye(n) - 2.0 * np.outer(w, w) / (w @ w)
    return R[:, :-1]


def floquet_from_return(J: np.ndarray, f: np.ndarray, *, normal=None,
                        tol: float = 1e-6) -> np.ndarray:
    """Floquet multipliers from dP/dz at a fixed point with the field ``f`` there: the
    flow's 1 first, then the multipliers of the section's chart by decreasing modulus.
    Refused when |dP/dz f| > tol |dP/dz| |f| (the derivative does not annihilate the
    flow), or when ``f`` is (nearly) tangent to the section.

    The multipliers are the eigenvalues of dP/dz on the section, never chosen among
    eigenvectors: sliding collapses directions, so dP/dz has a repeated, nearly defective
    eigenvalue 0, and picking the flow's eigenvalue by the direction of its eigenvector
    dropped a genuine multiplier ([1, 1e-10, 0] for the truth [1, 1.6e-3, 0]:
    tests/test_periodic.py). With the section's ``normal`` (gradient of its function):
    in a basis [Q, f], Q spanning the section's tangent space T, dP/dz maps Q into T
    (returns lie on the section) and f to ~0, so B^-1 dP/dz B = [[M, d], [0, d']] is block
    triangular and M ((n-1) x (n-1), the derivative of P in the chart Q) has exactly the
    eigenvalues of dP/dz but the flow's, whatever the small residual d of dP/dz f.
    Without it, Q spans the complement of f, which is exact when dP/dz f = 0 and
    off by O(|dP/dz f|) otherwise."""
    J, f = np.asarray(J, dtype=float), np.asarray(f, dtype=float)
    n = f.size
    scale = max(np.abs(J).max(), 1.0) * np.abs(f).max()
    if not (np.all(np.isfinite(J)) and scale > 0):
        raise PeriodicOrbitError("dP/dz is not finite at the fixed point (a tangential "
                                 "switch, a touch of H or a start that slides)")
    drift = np.abs(J @ f).max()
    if drift > tol * scale:
        raise PeriodicOrbitError(f"dP/dz does not annihilate the flow direction at the fixed "
                                 f"point (|dP/dz f| = {drift:.3g}, scale {scale:.3g}): not a "
                                 f"periodic orbit of an autonomous system, or a wrong derivative")
    if n == 1:
        return np.ones(1)
    if normal is None:
        Q = _complement(f)
    else:
        normal = np.asarray(normal, dtype=float)
        cross = abs(normal @ f) / (np.linalg.norm(normal) * np.linalg.norm(f))
        if not cross > 1e-8:
            raise PeriodicOrbitError(f"the flow is tangent to the section at the fixed point "
                                     f"(|n.f|/(|n||f|) = {cross:.3g}): no multipliers there")
        Q = _complement(normal)
    B = np.column_stack([Q, f / np.linalg.norm(f)])
    M = np.linalg.solve(B, J @ Q)[:-1]
    rest = np.linalg.eigvals(M)
    rest = rest[np.argsort(-np.abs(rest), kind="stable")]
    out = np.concatenate([[1.0], rest])
    return out.real if np.all(np.abs(out.imag) <= 1e-12 * np.maximum(1.0, np.abs(out))) else out


def periodic_orbit(system, guess, section, *, direction: int = 0, engine: str = "compiled",
                   t_max: float, tol: float = 1e-12, max_iter: int = 20,
                   **options) -> PeriodicOrbit:
    """The periodic orbit through ``section`` near ``guess``, by Newton on P(z) - z.

    Parameters
    ----------
    system : FilippovSystem
        The system, defined once (:class:`filippov.FilippovSystem`).
    guess : array (n,)
        A start near the orbit (on the section or not).
    section : callable
        ``s(z, p) -> float``: the section ``s = 0`` (the caller's, not the system's).
    direction : int
        -1 decreasing crossings of ``s`` only, +1 increasing, 0 both.
    engine : {"compiled", "python"}
        The compiled engine (numba, dP/dz carried along the return) or the reference
        driver (dP/dz from the variational equations afterwards).
    t_max : float
        Longest time a return may take.
    tol : float
        Converged when max |P(z) - z| <= tol (1 + max |z|).
    max_iter : int
        Newton steps at most.
    **options
        For the engine (``rtol``, ``atol``, ``min_time``, ...).

    Returns
    -------
    PeriodicOrbit
        Point, period, Floquet multipliers (1 first), dP/dz, steps and residual.

    Raises
    ------
    PeriodicOrbitError
        No convergence within ``max_iter``, a failed return, or a derivative that does
        not annihilate the flow direction at the fixed point.
    """
    if engine not in ENGINES:
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    z = np.array(guess, dtype=float).reshape(-1)
    if z.size != len(system.names) or not np.all(np.isfinite(z)):
        raise ValueError(f"guess: expected {len(system.names)} finite values "
                         f"({', '.join(system.names)}), got {np.asarray(guess).tolist()}")
    ret, section_value = _returns(system, section, direction, engine, t_max, options)
    for it in range(1, max_iter + 1):
        Pz, period, J = ret(z)
        residual = float(np.abs(Pz - z).max())
        if residual <= tol * (1.0 + np.abs(z).max()):
            f = _field_at(system.python(), z)
            mult = floquet_from_return(J, f, normal=_section_normal(section_value, z))
            return PeriodicOrbit(z, period, mult, J, it - 1, residual)
        A = J - np.eye(z.size)
        try:
            z = z - np.linalg.solve(A, Pz - z)
        except np.linalg.LinAlgError:
            raise PeriodicOrbitError(f"dP/dz - I is singular at {z.tolist()}: a multiplier "
                                     "1 besides the flow's (a bifurcation)") from None
    raise PeriodicOrbitError(f"Newton did not converge in {max_iter} steps (last residual "
                             f"{residual:.3g} at {z.tolist()})")
