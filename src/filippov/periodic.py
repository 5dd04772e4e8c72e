"""Periodic orbits through a section, on either engine, from one system definition.

A periodic orbit crossing a section is a fixed point of the section's return map P.
:func:`periodic_orbit` finds it by Newton's method on P(z) - z with the derivative
dP/dz of each return -- the compiled engine's (``compute_returns(jacobian=True)``) or
the reference driver's (:func:`filippov.variational.return_jacobian`) -- and returns its
Floquet multipliers: the eigenvalues of dP/dz at the fixed point, with the one that
belongs to the flow direction (dP/dz f = 0 there: a shift along the orbit is no
perturbation of P) replaced by the multiplier 1 of an autonomous orbit. That the flow
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
    """z -> (P(z), return time, dP/dz) on the chosen engine."""
    if engine == "compiled":
        from .fastmap import OK, STATUS, compute_returns

        cm = system.compiled(section, direction=direction)

        def one(z):
            out = compute_returns(cm, [z], t_max, jacobian=True, **options)
            if out.status[0] != OK:
                raise PeriodicOrbitError(f"no return from {np.asarray(z).tolist()}: "
                                         f"{STATUS[int(out.status[0])]}")
            return out.state[0], float(out.time[0]), out.jacobian[0]
        return one

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
    return one


def _field_at(python, z: np.ndarray) -> np.ndarray:
    """The field of the region z lies in (region + where the switching function >= 0)."""
    from .system import MINUS, PLUS

    mode = PLUS if float(python.switch(z)) >= 0 else MINUS
    return np.asarray(python.field(mode, z), dtype=float)


def floquet_from_return(J: np.ndarray, f: np.ndarray, *, tol: float = 1e-6) -> np.ndarray:
    """Floquet multipliers from dP/dz at a fixed point with the field ``f`` there: the
    eigenvalues of dP/dz, the one whose eigenvector is the flow direction (eigenvalue 0)
    replaced by 1, that one first, the others by decreasing modulus. Refused when
    |dP/dz f| > tol |dP/dz| |f| (the derivative does not annihilate the flow)."""
    J, f = np.asarray(J, dtype=float), np.asarray(f, dtype=float)
    scale = max(np.abs(J).max(), 1.0) * np.abs(f).max()
    if not (np.all(np.isfinite(J)) and scale > 0):
        raise PeriodicOrbitError("dP/dz is not finite at the fixed point (a tangential "
                                 "switch, a touch of H or a start that slides)")
    drift = np.abs(J @ f).max()
    if drift > tol * scale:
        raise PeriodicOrbitError(f"dP/dz does not annihilate the flow direction at the fixed "
                                 f"point (|dP/dz f| = {drift:.3g}, scale {scale:.3g}): not a "
                                 f"periodic orbit of an autonomous system, or a wrong derivative")
    lam, vec = np.linalg.eig(J)
    unit = f / np.linalg.norm(f)
    along = np.abs(np.conj(vec).T @ unit) / np.linalg.norm(vec, axis=0)
    k = int(np.argmax(along))
    rest = np.delete(lam, k)
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
    ret = _returns(system, section, direction, engine, t_max, options)
    for it in range(1, max_iter + 1):
        Pz, period, J = ret(z)
        residual = float(np.abs(Pz - z).max())
        if residual <= tol * (1.0 + np.abs(z).max()):
            f = _field_at(system.python(), z)
            return PeriodicOrbit(z, period, floquet_from_return(J, f), J, it - 1, residual)
        A = J - np.eye(z.size)
        try:
            z = z - np.linalg.solve(A, Pz - z)
        except np.linalg.LinAlgError:
            raise PeriodicOrbitError(f"dP/dz - I is singular at {z.tolist()}: a multiplier "
                                     "1 besides the flow's (a bifurcation)") from None
    raise PeriodicOrbitError(f"Newton did not converge in {max_iter} steps (last residual "
                             f"{residual:.3g} at {z.tolist()})")
