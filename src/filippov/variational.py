"""Derivatives of a nonsmooth flow with respect to its start state.

An event-driven trajectory of :mod:`filippov.simulate` is smooth between its
events, so its derivative dz(t)/dz0 is a product: on every segment the
variational equation of that mode's field (the Filippov field while sliding),
and at every event the saltation matrix that carries perturbations across the
switching surface (Filippov's correction for the change of arrival time):

* a crossing from mode a to b, or the start of sliding, at a point with normal
  n = grad H: S = I + (f_b - f_a) n^T / (n . f_a); entering sliding it projects
  onto the tangent space of H_s;
* the end of sliding: identity (one normal speed is zero there, so the sliding
  field equals the field it leaves into).

On several switching surfaces (:class:`~filippov.surfaces.SurfacesSystem`, modes by
their codes) the same, with the gradient of the one surface a switch changes; a switch
that changes two at once (a corner) has no derivative (neighbouring orbits cross them
in either order) and is refused.

:func:`transition_matrix` is that product over a whole trajectory;
:func:`return_jacobian` adds the correction for the arrival time at a Poincare
section, giving the derivative dP/dz0 of a return map (tested against finite
differences of P, tests/test_variational.py); :func:`filippov.continuation.monodromy`
closes a period with it.
"""
from __future__ import annotations

from typing import Callable, Optional

import numpy as np
from scipy.integrate import solve_ivp

from .system import PLUS, SLIDING
from .errors import VariationalError  # noqa: F401  (re-exported)
from .differences import fd_jacobian  # noqa: F401  (re-exported)


def field_jacobian(system, mode: int, z: np.ndarray, step: float = 1e-6,
                   floor: float = 1.0) -> np.ndarray:
    """Jacobian of the field of ``mode`` by central differences. The step is well
    above the noise level: the variational equation must see a smooth matrix, or
    DOP853's step control chases rounding noise. ``floor`` as :func:`fd_jacobian`'s."""
    return fd_jacobian(lambda zz: system.field(mode, zz), z, step, floor)


def saltation(f_before, f_after, grad):
    """I + (f_after - f_before) grad^T / (grad . f_before): maps perturbations
    across a switching surface with normal ``grad`` reached along f_before."""
    speed = grad @ f_before
    if speed == 0:
        raise VariationalError("the switching surface is reached tangentially (grad H . f = 0): "
                               "the flow is not differentiable there")
    return np.eye(f_before.size) + np.outer(f_after - f_before, grad) / speed


def reference_view(system, jacobian, capability: str, floor: float | None = None):
    """The :class:`~filippov.system.PiecewiseSystem` the reference driver ran for
    ``system`` (any system the front doors take: :func:`filippov.views.reference_system`)
    and the Jacobian to use: the caller's ``jacobian``, else the system's own (a
    FilippovSystem or SymbolicSystem that has its fields' Jacobians; told the run's
    state scale ``floor`` where it takes one, so that it need not measure it at every
    sliding state), else None (central differences)."""
    import functools
    import inspect

    from . import views
    from .contracts import WithJacobians, provides

    if jacobian is None and provides(system, WithJacobians) and system.has_jacobians:
        jacobian = system.jacobian
        if floor is not None and "floor" in inspect.signature(jacobian).parameters:
            jacobian = functools.partial(jacobian, floor=floor)
    return views.reference_system(system, capability, several=True), jacobian


def _modes(system):
    """(field(mode, z), switch_matrix(before, after, z), the projection of a start that
    slides(mode, z) or None) of the system a trajectory ran: one surface's, or a
    :class:`~filippov.surfaces.SurfacesSystem`'s by its mode codes."""
    from .surfaces import SurfacesSystem

    if isinstance(system, SurfacesSystem):
        return (system.mode_field, lambda b, a, z: _surfaces_switch_matrix(system, b, a, z),
                lambda mode, z: _surfaces_start(system, mode, z))

    def start(mode, z):
        # a start that slides: a perturbation off H comes back onto it along F_+ or F_-
        # and slides on late, the projection of an arrival from either side
        # (I + (F_+ - F_-) n^T / (a - b), the same from both)
        if mode != SLIDING:
            return None
        return saltation(system.field(PLUS, z), system.field(SLIDING, z),
                         system.switch_grad(z))
    return system.field, lambda b, a, z: switch_matrix(system, b, a, z), start


def _surfaces_switch_matrix(system, before: int, after: int, z):
    """The saltation matrix of a switch of a several-surface run (modes by their codes,
    filippov.surfaces): across a surface, or onto it to slide (onto an intersection from
    one of its surfaces too), that surface's; None where there is none (no change, the
    end of a slide on a surface); through a corner the flow is not differentiable
    (VariationalError)."""
    from .surfaces import digits, mode_name

    m = system.m
    if before == after:
        return None
    changed = [k for k, (a, b) in enumerate(zip(digits(before, m), digits(after, m)))
               if a != b]
    if len(changed) == 1 and digits(before, m)[changed[0]] == 0:
        return None   # the end of a slide on that surface: the identity
    if len(changed) != 1:
        raise VariationalError(
            f"a switch from {mode_name(before, m)} to {mode_name(after, m)} changes "
            f"{len(changed)} surfaces at once (a corner): the flow is not differentiable "
            "there")
    grad = np.asarray(system.grads(np.asarray(z, dtype=float)), dtype=float)[changed[0]]
    return saltation(np.asarray(system.mode_field(before, z), dtype=float),
                     np.asarray(system.mode_field(after, z), dtype=float), grad)


def _surfaces_start(system, mode: int, z):
    """A several-surface run that starts sliding: the projection of an arrival on its
    surface (as for one surface), or None in a region."""
    if system.slid_on(mode) < 0:
        return None
    k, plus, _ = system.beside(mode)
    grad = np.asarray(system.grads(np.asarray(z, dtype=float)), dtype=float)[k]
    return saltation(np.asarray(system.region_field(plus, z), dtype=float),
                     np.asarray(system.mode_field(mode, z), dtype=float), grad)


#: the relative step of the central differences of a section's gradient: eps^(1/3), where
#: rounding (eps / step) and truncation (step^2) balance, ~4e-11 of the gradient (a step
#: of 1e-7 left its rounding, ~2e-9, in dP/dz)
SECTION_STEP = float(np.cbrt(np.finfo(float).eps))


def switch_matrix(system, before: int, after: int, z: np.ndarray):
    """Saltation matrix of a switch from mode ``before`` to ``after`` at ``z``; None
    when there is none: no switch, or the end of sliding (identity)."""
    if before == after or before == SLIDING:
        return None
    return saltation(system.field(before, z), system.field(after, z), system.switch_grad(z))


def _state_scale(traj) -> float:
    """The state scale the run of ``traj`` measured its tolerances in (filippov.scale)."""
    scale = getattr(traj, "scale", None)
    return 1.0 if scale is None else float(scale.state)


def _component_scales(traj, n: int) -> np.ndarray:
    """Each component's scale in the run of ``traj`` (filippov.scale): the steps of the
    differences along a component and its absolute tolerance grow from it."""
    scale = getattr(traj, "scale", None)
    return np.ones(n) if scale is None else scale.of_components(n)


def transition_matrix(system, traj, *, rtol: float = 1e-10, atol: float = 1e-12,
                      jacobian: Optional[Callable] = None) -> np.ndarray:
    """dz(t_end)/dz0 along ``traj`` (a Trajectory of :func:`filippov.simulate`):
    the variational equations of every segment between its events, from the event
    states, composed with the saltation matrix of every switch.

    Parameters
    ----------
    system : FilippovSystem, SymbolicSystem or PiecewiseSystem
        The system ``traj`` was computed with.
    traj : Trajectory
        Its events (``traj.events``) and end (``traj.t``, ``traj.z``) are used.
    rtol, atol : float
        Tolerances of the variational integration (DOP853); ``atol`` of the state in
        units of the run's state scale (``traj.scale``, filippov.scale). With the default
        finite-difference Jacobians keep rtol >= ~1e-10: tighter, DOP853 chases
        their rounding noise (a stiff sliding segment of the Hopf example took 94 s
        at rtol 1e-12 and 0.2 s at 1e-10).
    jacobian : callable, optional
        ``jacobian(mode, z)`` -> (n, n) Jacobian of the field of ``mode``;
        default: the system's own Jacobians where it has them, else central
        differences (:func:`field_jacobian`).

    Returns
    -------
    ndarray, shape (n, n)
    """
    system, jacobian = reference_view(system, jacobian, "transition_matrix",
                                      _state_scale(traj))
    n = system.dim
    field, salt, start = _modes(system)
    floors = _component_scales(traj, n)
    jac = jacobian or (lambda mode, z: fd_jacobian(lambda zz: field(mode, zz), z, 1e-6,
                                                   floors))
    # the state's error in its own units, the derivative's (dimensionless) as it is
    atols = np.concatenate([atol * floors, np.full(n * n, atol)])
    M = np.eye(n)
    ev = traj.events
    for k, e in enumerate(ev):
        S = salt(e.mode_before, e.mode_after, e.state)
        if k == 0 and start(e.mode_after, e.state) is not None:
            S = start(e.mode_after, e.state)
        if S is not None:
            M = S @ M
        t_next = ev[k + 1].t if k + 1 < len(ev) else traj.t
        dt = t_next - e.t
        if dt <= 0:
            continue
        mode = e.mode_after

        def rhs(t, z, mode=mode):
            x, Phi = z[:n], z[n:].reshape(n, n)
            return np.concatenate([field(mode, x), (jac(mode, x) @ Phi).ravel()])

        sol = solve_ivp(rhs, (0.0, dt), np.concatenate([e.state, np.eye(n).ravel()]),
                        method="DOP853", rtol=rtol, atol=atols)
        if not sol.success:
            raise VariationalError(f"variational integration failed: {sol.message}")
        M = sol.y[n:, -1].reshape(n, n) @ M
    return M


def return_jacobian(system, traj, section, *, rtol: float = 1e-10, atol: float = 1e-12,
                    jacobian: Optional[Callable] = None,
                    section_grad: Optional[Callable] = None) -> np.ndarray:
    """dP/dz0 of the return map to ``section`` at the start of ``traj``, a run of
    :func:`filippov.simulate` that stopped at a hit of that (terminal) section.

    P(z0) lies on the section, so dP/dz0 = (I - f n^T / (n . f)) dz(T)/dz0 with
    f the field and n the section's gradient at the hit: a perturbation moves the
    arrival time, along f, until the orbit is back on the section. Columns along
    the flow direction at z0 give zero when z0 itself lies on the section.

    Parameters
    ----------
    system, traj, rtol, atol, jacobian
        As for :func:`transition_matrix`.
    section : Section
        The section ``traj`` stopped at (``traj.status == "section:<name>"``).
    section_grad : callable, optional
        ``section_grad(z)`` -> (n,) gradient of ``section.func``; default: central
        differences.

    Returns
    -------
    ndarray, shape (n, n)
        Maps perturbations of z0 to perturbations of P(z0) (within the section's
        tangent space).
    """
    if traj.status != f"section:{section.name}":
        raise VariationalError(f"the trajectory ended with status {traj.status!r}, not at a "
                               f"hit of section {section.name!r}")
    system, jacobian = reference_view(system, jacobian, "return_jacobian", _state_scale(traj))
    Phi = transition_matrix(system, traj, rtol=rtol, atol=atol, jacobian=jacobian)
    z = np.asarray(traj.z, dtype=float)
    grad = (np.asarray(section_grad(z), dtype=float) if section_grad is not None else
            fd_jacobian(lambda zz: np.atleast_1d(section.func(zz)), z, SECTION_STEP,
                        floor=_component_scales(traj, z.size))[0])
    f = np.asarray(_modes(system)[0](traj.mode, z), dtype=float)
    speed = grad @ f
    if speed == 0:
        raise VariationalError(f"section {section.name!r} is hit tangentially at t={traj.t!r}: "
                               "the return map is not differentiable there")
    return (np.eye(z.size) - np.outer(f, grad) / speed) @ Phi
