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

import dataclasses
from dataclasses import dataclass

import numpy as np
from . import views
from .contracts import DefinedOnce, provides
from .scale import of_system
from .section import Section
from .surfaces import SurfacesSystem, view_at
from .errors import PeriodicOrbitError  # noqa: F401  (re-exported)


@dataclass(frozen=True)
class PeriodicOrbit:
    """A fixed point of the return map to a section and what it says of the orbit."""

    point: np.ndarray          # (n,) the orbit's point on the section
    period: float              # the return time there
    multipliers: np.ndarray    # (n,) Floquet multipliers, the flow's 1 first, then by |.|
    jacobian: np.ndarray       # (n, n) dP/dz at the fixed point
    iterations: int            # Newton steps taken
    residual: float            # max |P(z) - z| at the point


def _compiled_return(system, section, direction: int, where, t_max: float, options: dict):
    """(z, age -> (P(z), its time, dP/dz, age at the return), z -> section value) on the
    compiled engine, dP/dz carried along the return; the time spent in the region is
    carried across a hit, as an iterated run does."""
    from .fastmap import OK, compute_returns, failure

    cm = views.compiled_model(system, "periodic_orbit", section, direction=direction,
                                where=where)

    def single(z, age):
        out = compute_returns(cm, [z], t_max, jacobian=True, start_age=age, **options)
        if out.status[0] != OK:
            raise PeriodicOrbitError(f"no return from {np.asarray(z).tolist()}: "
                                     f"{failure(cm, out, 0)}")
        return out.state[0], float(out.time[0]), out.jacobian[0], float(out.age[0])
    value = lambda z: float(cm.section(np.ascontiguousarray(z, dtype=float), cm.params))  # noqa: E731
    return single, value


def _reference_return(system, section, direction: int, where, t_max: float, options: dict):
    """As :func:`_compiled_return` on the reference driver, dP/dz from the variational
    equations afterwards (each return starts afresh: age 0)."""
    from .simulate import simulate
    from .variational import reference_view, return_jacobian

    # exact field Jacobians where the system has them (filippov.symbolic), else differences
    scale = options.get("scale")   # the orbit's, fixed at the guess (_orbit_scale)
    python, jac = reference_view(system, None, "periodic_orbit",
                                 floor=getattr(scale, "state", None))
    if isinstance(section, Section):   # several surfaces: the reference engine's Section
        sec = section if section.terminal == 1 else dataclasses.replace(section, terminal=1)
    elif not provides(system, DefinedOnce):
        raise TypeError(f"section: periodic_orbit of a {type(system).__name__} expected a "
                        f"filippov.Section, got {type(section).__name__}")
    else:
        sec = system.python_section(section, direction=direction, where=where)

    def single(z, age):
        traj = simulate(python, z, t_max, sections=[sec], dense=False, **options)
        if traj.status != f"section:{sec.name}":
            raise PeriodicOrbitError(f"no return from {np.asarray(z).tolist()} within "
                                     f"t_max={t_max!r} (status {traj.status})")
        J = return_jacobian(python, traj, sec, jacobian=jac)
        return np.asarray(traj.z, dtype=float), float(traj.t - traj.t0), J, 0.0
    value = lambda z: float(np.asarray(sec.func(z)).reshape(()))  # noqa: E731
    return single, value


#: what runs one return of :func:`periodic_orbit`'s Newton iteration on each engine
RUNS = {views.REFERENCE: _reference_return, views.COMPILED: _compiled_return}


def _returns(system, section, direction: int, where, engine: str, t_max: float, returns: int,
             options: dict):
    """(z -> (P^returns(z), its time, its dP/dz), z -> section value) on the chosen engine
    (:func:`filippov.views.pick` from :data:`RUNS`): ``returns`` single returns, each
    from the last one's state, their derivatives multiplied."""
    single, value = views.pick(RUNS, "periodic_orbit", engine)(system, section, direction,
                                                              where, t_max, options)

    def one(z):
        total, D, age = 0.0, np.eye(z.size), 0.0
        for _ in range(returns):
            z, t, J, age = single(z, age)
            total += t
            D = J @ D
        return z, total, D
    return one, value


def _finite_derivative(J: np.ndarray, z: np.ndarray) -> None:
    if not np.all(np.isfinite(J)):
        raise PeriodicOrbitError(
            f"dP/dz is not finite at {z.tolist()} (a tangential switch, a touch of H, or a "
            "return that starts sliding in the section: there the compiled engine gives no "
            "dP/dz and the reference derives it along the slide; filippov.engines, item 11)")


def _section_normal(value, z: np.ndarray, floor: float = 1.0, r=None) -> np.ndarray:
    """The gradient of the section function at z by central differences (step eps^(1/3)
    times the state's size, at least ``floor``, the state scale: ~1e-11 relative for a
    section that varies on that size; along component k times ``r[k]``, its scale over
    the state scale, filippov.scale: 1 for all in a run of one scale)."""
    r = _ratios(r, z.size)
    h = np.cbrt(np.finfo(float).eps) * max(floor, float(np.abs(z / r).max())) * r
    g = np.empty(z.size)
    for k in range(z.size):
        e = np.zeros(z.size)
        e[k] = h[k]
        g[k] = (value(z + e) - value(z - e)) / (2 * h[k])
    return g


def _ratios(r, n: int) -> np.ndarray:
    """Each component's scale over the state scale (powers of two, at most 1; ones where
    the run has one scale): the metric in which periodic_orbit measures distances."""
    return np.ones(n) if r is None else np.asarray(r, dtype=float)


def _onto_section(value, z: np.ndarray, floor: float = 1.0, r=None) -> np.ndarray:
    """z moved along the section's gradient onto it (one Newton step on the section
    function: exact for a planar section, O(offset^2) off for a curved one), the gradient
    in the metric of the components' scales (``r``, :func:`_ratios`)."""
    s = value(z)
    if s == 0.0 or not np.isfinite(s):
        return z
    r = _ratios(r, z.size)
    g = _section_normal(value, z, floor, r) * r
    gg = float(g @ g)
    return z - (s / gg) * g * r if gg > 0 else z


def _field_at(python, z: np.ndarray, touch_tol: float = 1e-15) -> np.ndarray:
    """The field the orbit from z starts with: that of its region, and on H (|h| <=
    touch_tol, e.g. a section on the switching surface) the one both engines start
    with, decided by the normal speeds (simulate.initial_mode) -- not by the sign of a
    rounded h: a fixed point at h = -1e-17 starts in region + like one at h = 0, and dP/dz
    annihilates F_+ there, not F_-."""
    from .simulate import initial_mode

    python = view_at(python, z)
    mode, _ = initial_mode(python, np.asarray(z, dtype=float), touch_tol)
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
                        tol: float = 1e-6, r=None) -> np.ndarray:
    """Floquet multipliers from dP/dz at a fixed point with the field ``f`` there: the
    flow's 1 first, then the multipliers of the section's chart by decreasing modulus.
    Refused when ``|dP/dz f| > tol |dP/dz| |f|`` (the derivative does not annihilate the
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
    off by ``O(|dP/dz f|)`` otherwise. ``r``: each component's scale over the state
    scale (filippov.scale; None: one scale): the tests and the chart in their metric
    (dP/dz similar to diag(1/r) J diag(r), f as f / r, the normal as normal r), so that
    components in units far apart neither pass a drift nor refuse a crossing."""
    J, f = np.asarray(J, dtype=float), np.asarray(f, dtype=float)
    n = f.size
    r = _ratios(r, n)
    J, f = J * r[None, :] / r[:, None], f / r
    if normal is not None:
        normal = np.asarray(normal, dtype=float) * r
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


#: a "return" whose path (return time times the speed ``|f|`` at z) is shorter than this,
#: relative to the state's size, is the start itself: z lies on the section up to the
#: rounding of the flow and the section, and a sign change of that rounding was taken
#: for a crossing. A genuine orbit travels a length the sampling resolves.
SHORTEST_PATH = 1e-9


def _refuse_the_start_itself(z, period, f, floor: float = 1.0, r=None) -> None:
    r = _ratios(r, np.size(z))
    path = period * float(np.abs(f / r).max())
    if not path > SHORTEST_PATH * (floor + float(np.abs(z / r).max())):
        raise PeriodicOrbitError(
            f"the return from {z.tolist()} came back after t = {period:.3g} (a path of "
            f"length {path:.3g}): the start itself, a hair before the section by the "
            "rounding of the flow or the section, not a periodic orbit. Start Newton from "
            "a guess off the section, or make the exact flow's rounding smaller")


#: Newton has run away when an iterate is this many times farther from the guess than
#: the guess's size (or the state scale): the guess is not near an orbit, or dP/dz is
#: wrong there -- said as such, not as the failure of a return from far away
RUNAWAY = 1e3


def _orbit_scale(python, z, value):
    """The units of every return of one Newton iteration (filippov.scale): ``value``, else
    the system's, the parts left open measured at the guess -- once, so that the
    tolerances, and with them P, stay the same map at every iterate. (What the runs take,
    the whole Scale): several surfaces' runs take its state and time scales and measure
    each surface's switch scale on its own (filippov.several)."""
    sc = of_system(view_at(python, z), z, value)
    if isinstance(python, SurfacesSystem) and sc.how != "declared":
        return {"state": sc.state, "time": sc.time}, sc
    return sc, sc


def _newton_step(z, Pz, J, guess, floor: float) -> np.ndarray:
    """The Newton iterate after z for P(z) - z = 0 (dP/dz = J), refused where J is not
    finite or J - I singular, or where it ran away from the guess (RUNAWAY)."""
    _finite_derivative(J, z)   # a Newton step from a NaN would leave the state
    try:
        new = z - np.linalg.solve(J - np.eye(z.size), Pz - z)
    except np.linalg.LinAlgError:
        raise PeriodicOrbitError(f"dP/dz - I is singular at {z.tolist()}: a multiplier "
                                 "1 besides the flow's (a bifurcation)") from None
    # in the state's own size, not each component's: a component small at the guess
    # may be large on the orbit (a review: c = 1e-7 at the guess, 1.38 on the orbit)
    g = np.asarray(guess, dtype=float).reshape(-1)
    size = max(floor, float(np.abs(g).max()))
    away = float(np.abs(new - g).max()) / size
    if not away <= RUNAWAY:
        raise PeriodicOrbitError(
            f"Newton ran away from the guess: the iterate {new.tolist()} lies {away:.3g} "
            f"times the guess's size {size:.3g} from it (from {z.tolist()}, residual "
            f"{float(np.abs(Pz - z).max()):.3g}); the guess is not near a periodic orbit "
            "through the section, or dP/dz is wrong there")
    return new


def _checked_start(system, guess, returns, engine) -> np.ndarray:
    """periodic_orbit's arguments checked (each refused naming it); the guess as a vector."""
    views.checked(engine)
    if not (isinstance(system, SurfacesSystem)   # several surfaces: the reference engine
            or provides(system, DefinedOnce)):   # filippov.contracts
        raise TypeError(f"system: periodic_orbit expected a FilippovSystem or a "
                        f"SymbolicSystem (a system defined once: both engines' views), "
                        f"got {type(system).__name__}")
    z = np.array(guess, dtype=float).reshape(-1)
    if z.size != len(system.names) or not np.all(np.isfinite(z)):
        raise ValueError(f"guess: expected {len(system.names)} finite values "
                         f"({', '.join(system.names)}), got {np.asarray(guess).tolist()}")
    if not (isinstance(returns, (int, np.integer)) and returns >= 1):
        raise ValueError(f"returns must be an integer >= 1, got {returns!r}")
    return z


#: options of the engines' return calls that periodic_orbit sets itself (P is one return
#: of the section, with its derivative): given, they would make P another map
OWN_OPTIONS = ("iterations", "keep", "jacobian", "sections", "dense", "start_age")


def _check_newton(tol, max_iter, options=()) -> None:
    """Newton's options, each named where out of range (a review: tol 10 returned the
    guess as the orbit, max_iter 0 an UnboundLocalError, iterations=2 went to the engine
    and broke Newton's map)."""
    own = sorted(set(options) & set(OWN_OPTIONS))
    if own:
        raise ValueError(f"{own[0]}: periodic_orbit sets it itself (one return of the "
                         f"section a time, with its derivative); give returns= for an "
                         f"orbit that meets the section more than once")
    if not (isinstance(tol, (int, float)) and 0.0 < tol <= 1e-3):
        raise ValueError(f"tol: the relative residual Newton stops at, in (0, 1e-3]; got "
                         f"{tol!r}")
    if isinstance(max_iter, bool) or not isinstance(max_iter, (int, np.integer)) \
            or max_iter < 1:
        raise ValueError(f"max_iter: a positive integer, got {max_iter!r}")


def periodic_orbit(system, guess, section, *, direction: int = 0, where=None,
                   returns: int = 1, engine: str = "compiled", t_max: float,
                   tol: float = 1e-12, max_iter: int = 20, **options) -> PeriodicOrbit:
    """The periodic orbit through ``section`` near ``guess``, by Newton on P^n(z) - z
    (n = ``returns``, the times the orbit meets the section in one period).

    Parameters
    ----------
    system : FilippovSystem
        The system, defined once (:class:`filippov.FilippovSystem` or
        :class:`filippov.SymbolicSystem`): both engines' views and the field at the
        fixed point.
    guess : array (n,)
        A start near the orbit (on the section or not).
    section : callable
        ``s(z, p) -> float``: the section ``s = 0`` (the caller's, not the system's).
    direction : int
        -1 decreasing crossings of ``s`` only, +1 increasing, 0 both.
    where : callable, optional
        ``w(z, p) -> bool`` that must hold at a hit (a SymPy condition with a SymPy
        section of a symbolic system).
    returns : int
        n: the orbit's period is n returns to the section (its point is a fixed point
        of P^n; ``period`` is the time of all n, ``jacobian`` d(P^n)/dz).
    engine : {"compiled", "reference"}
        The compiled engine (numba, dP/dz carried along the return) or the reference
        driver (dP/dz from the variational equations afterwards); chosen by
        :func:`filippov.views.pick` from :data:`RUNS`.
    t_max : float
        Longest time a return may take.
    tol : float
        In (0, 1e-3]: converged when ``max |P(z) - z| <= tol (S + max |z|)``, S the state scale
        (:mod:`filippov.scale`: the system's, or measured at the guess, and kept for
        every return of the iteration, so that P is one map).
    max_iter : int
        Newton steps at most (a positive integer).
    **options
        For the engine (``rtol``, ``atol``, ``min_time``, ...); ``atol``, ``touch_tol``
        and ``event_xtol`` in units of the scale's S, G and T, and ``scale=``
        (:mod:`filippov.scale`) declares it.

    Returns
    -------
    PeriodicOrbit
        Point, period, Floquet multipliers (1 first), dP/dz, steps and residual.

    Raises
    ------
    PeriodicOrbitError
        No convergence within ``max_iter``, a failed return, a derivative that does
        not annihilate the flow direction at the fixed point, a "fixed point" whose
        return is the start itself (a path shorter than ``SHORTEST_PATH`` of the state's
        size: the start a hair before the section by rounding), or an iterate that ran
        away from the guess (``RUNAWAY`` times its size).
    ValueError
        A ``tol``, ``max_iter`` or option out of range (``OWN_OPTIONS``), named.
    """
    _check_newton(tol, max_iter, options)
    z = _checked_start(system, guess, returns, engine)
    python = views.reference_system(system, "periodic_orbit", several=True)
    runs, sc = _orbit_scale(python, z, options.get("scale"))   # what the runs take; all
    options = {**options, "scale": runs}
    ret, section_value = _returns(system, section, direction, where, engine, t_max,
                                  int(returns), options)
    r = sc.of_components(z.size) / sc.state   # powers of two: the metric of the scales
    for it in range(1, max_iter + 1):
        Pz, period, J = ret(z)
        residual = float(np.abs((Pz - z) / r).max())
        if residual <= tol * (sc.state + np.abs(z / r).max()):
            f = _field_at(python, z, options.get("touch_tol", 1e-15) * sc.switch)
            _refuse_the_start_itself(z, period, f, sc.state, r)
            mult = floquet_from_return(J, f, normal=_section_normal(section_value, z,
                                                                    sc.state, r), r=r)
            return PeriodicOrbit(z, period, mult, J, it - 1, float(np.abs(Pz - z).max()))
        z = _newton_step(z, Pz, J, guess, sc.state)
        # onto the section (off it by dP/dz's error times the step), or an iterate a hair
        # before it "returns" at once and Newton converges there (test_properties.py)
        z = _onto_section(section_value, z, sc.state, r)
    raise PeriodicOrbitError(f"Newton did not converge in {max_iter} steps (last residual "
                             f"{residual:.3g} at {z.tolist()})")
