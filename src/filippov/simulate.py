"""The event-driven driver: smooth segments, switching decisions, sliding, sections.

The loop is the textbook one for Filippov systems:

1. follow the field of the current mode (``+``, ``-`` or sliding) in segments,
   each with a dense evaluator ``Z(t)`` -- an exact flow if the system has one
   and ``method="exact"``, else a DOP853 step with its 7th-order dense output;
2. scan each segment for the earliest event: ``H`` leaving the region, a hidden
   grazing crossing (a sign change of ``dH/dt`` whose minimum of ``H`` goes
   through zero), the end of sliding (``dH.F_-`` or ``dH.F_+`` reaching zero, at
   a sample or between samples: an extremum of theirs toward zero, from their
   rates along the orbit, :func:`filippov.rules.speed_graze`), or a user
   :class:`Section`; refine it with Brent's method;
3. at a hit of ``H = 0`` decide from ``a = dH.F_-`` and ``b = dH.F_+`` (Eqs. (9),
   (A.3)) whether the trajectory crosses or starts sliding, log it, restart.

Guards stop a run with a clear error instead of hanging or handing on NaN: a
bound on events and steps, and an accumulation (Zeno) detector.
"""
from __future__ import annotations

import contextlib
import functools
import math
from collections import namedtuple
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
from scipy.integrate import DOP853
from scipy.optimize import brentq

from . import checks, options, rules, several, variational, views
from . import scale as scale_mod
from .scale import UNIT
from .loop import interval
from .radau_iia import RadauIIA
from .system import MINUS, MODE_NAMES, PLUS, SLIDING, PiecewiseSystem
from .errors import SimulationError, EventLimitError, ZenoError, SlidingNotBuiltError  # noqa: F401  (re-exported)
from .errors import ValueNotFinite, accumulation_detail, run_error
from .loop.event import SECTION, Pieces, RunOps, make_run, make_sliding_section, make_start
from .loop.run_state import RING, SWITCHES, Limits, new_run_state
from .section import Section, hit_within, names_hit_within, one_instant, tied_hits  # noqa: F401  (.Section)
from .surfaces import SurfacesSystem
from .loop.stay import UNRESOLVED
from .loop.status import (CUT, EVENT_LIMIT, FLOW_OFF_FIELD, GO_ON, NON_FINITE, NO_RETURN,
                          TWO_FOLD, NO_SLIDING, OK,
                          ROOT_FAILED, SECTION_SLIDING, STEP_FAILED, STEP_LIMIT, ZENO)


@dataclass(frozen=True)
class Event:
    t: float
    kind: str  # crossing | slide_start | slide_end | touch | section | start | repelling_start
    state: np.ndarray
    mode_before: int
    mode_after: int
    name: str = ""


@dataclass
class Trajectory:
    system: PiecewiseSystem
    t0: float
    z0: np.ndarray
    t: float = 0.0
    z: np.ndarray = None
    mode: int = PLUS
    events: list = field(default_factory=list)
    segments: list = field(default_factory=list)  # (ta, tb, mode, Z)
    status: str = "running"
    n_steps: int = 0
    # windows of integration steps searched for events (a step's samples that do not
    # resolve what they sample are searched in shorter windows: rules.resolves)
    n_windows: int = 0
    integrated_modes: set = field(default_factory=set)
    # modes whose integration switched from DOP853 to the implicit Radau IIA method
    # because the field proved stiff there (see STIFF_AFTER)
    stiff_modes: set = field(default_factory=set)
    # mode name -> largest absolute tolerance Radau IIA was given there, where the field's
    # rounding noise (see NOISE_STEPS) lifted it above atol: the local accuracy the
    # field's conditioning allowed
    atol_raised: dict = field(default_factory=dict)
    # the units the run's tolerances were measured in (filippov.scale.Scale)
    scale: object = UNIT

    def section_hits(self, name: str) -> list:
        return [e for e in self.events if e.kind == "section" and e.name == name]

    def switches(self) -> list:
        return [e for e in self.events if e.mode_before != e.mode_after]

    def sample(self, times: np.ndarray, *, include_events: bool = True):
        """States on ``times`` (plus event times if asked): ``(t, z[n, m], mode[m])``."""
        if not self.segments:
            raise SimulationError("trajectory was run with dense=False: no samples stored")
        times = np.asarray(times, dtype=float)
        if include_events:
            times = np.union1d(times, [e.t for e in self.events])
        times = times[(times >= self.t0) & (times <= self.t)]
        ends = np.array([s[1] for s in self.segments])
        idx = np.minimum(np.searchsorted(ends, times, side="left"), len(ends) - 1)
        z = np.empty((self.system.dim, times.size))
        modes = np.empty(times.size, dtype=np.int8)
        for k in np.unique(idx):
            sel = idx == k
            ta, tb, mode, Z = self.segments[k]
            z[:, sel] = Z(times[sel])
            modes[sel] = mode
        return times, z, modes


# --------------------------------------------------------------------------- steppers
class _ExactStepper:
    """Walks an exact flow in the windows of :func:`filippov.rules.exact_window` (``h``
    growing with the time since the mode entry, ``h_slow`` once ``transient`` has
    passed); the evaluator is the flow itself."""

    method = None  # not integrated

    def __init__(self, flow, z, t, t_end, h, h_slow=None, transient=np.inf):
        self.flow, self.za, self.ta, self.t, self.t_end, self.h = flow, z.copy(), t, t, t_end, h
        self.h_slow, self.transient = (h if h_slow is None else h_slow), transient
        self.n_taken, self.t_start = 0, t  # steps taken by this stepper, since t_start

    def step(self):
        ta = self.t
        h = rules.exact_window(ta - self.ta, self.h, self.h_slow, self.transient)
        tb = min(ta + h, self.t_end)
        if tb == ta:  # h below the spacing of floats at t
            tb = np.nextafter(ta, np.inf)
        self.t = tb
        flow, za, t0 = self.flow, self.za, self.ta
        return ta, tb, lambda tt: flow(za, np.asarray(tt, dtype=float) - t0)


@functools.lru_cache(maxsize=1)
def _blas_controller():
    from threadpoolctl import ThreadpoolController
    return ThreadpoolController()


def _one_blas_thread():
    """Radau IIA factorises its Newton matrices with LAPACK. OpenBLAS takes another code
    path with more than one thread, and the result moves in the last bits (the
    eps = 1e-4 sliding return differed between OPENBLAS_NUM_THREADS=1, as in a
    Snakemake job, and the default): one thread makes it the same everywhere."""
    return _blas_controller().limit(limits=1, user_api="blas")


#: how much shorter a step that met the non-finite guard is tried again: scipy's least
#: factor for a rejected step (its MIN_FACTOR)
_SHRINK = 0.2


def _first_not_finite(tt, zz, v):
    """(time, state) of the first stage whose field value v is not finite: of a scalar
    call, or of Radau IIA's vectorized one (times and states in columns)."""
    zz = np.array(zz, dtype=float)
    if zz.ndim == 1:
        return float(np.asarray(tt).reshape(-1)[0]), zz
    j = int(np.argmax(~np.all(np.isfinite(np.asarray(v).reshape(zz.shape)), axis=0)))
    return float(tt if np.ndim(tt) == 0 else np.asarray(tt).reshape(-1)[j]), zz[:, j].copy()


class _IntegratingStepper:
    """DOP853 (explicit), or Radau IIA (implicit, for a stiff field), with dense output.
    Events are located on the dense output, and the state at an event is the dense
    output's: a crossing's state is then on the far side of H by construction (a
    more accurate state from a separate step to the event time would not be: it
    differs by up to the tolerance, H = 7e-13 at a stick of the dry-friction model)."""

    def __init__(self, fun, z, t, t_end, rtol, atol, max_step, method=DOP853,
                 piece=lambda zz: "the field", noise=None):
        calls = [0]
        self.atol, self.noise, self.atol_used = atol, noise, float(np.max(atol))
        self.fun, self.piece, self.non_finite = fun, piece, None
        # the earliest time a trial stage met the non-finite guard at that the orbit has
        # not yet passed (_passed_suspect); where the orbit found runs through a field not
        # finite, that time and state (the next step raises there)
        self.suspect, self.not_finite_at = np.inf, None
        self.n_taken, self.t_start = 0, t  # steps taken by this stepper, since t_start

        def checked(tt, zz):
            # scipy's step control loops forever on a NaN error norm. A non-finite
            # field at the start state is an error; on a trial stage (an overlong
            # step into overflow) a huge finite value makes DOP853 reject the step,
            # and if the step size collapses on it, step() names the piece.
            # This runs once per stage, so it is kept cheap: the sum is finite when
            # every component is (the full test runs only when it is not), and the
            # floating-point warnings are silenced once, by simulate().
            v = fun(tt, zz)
            calls[0] += 1
            if not math.isfinite(v.sum()) and not np.all(np.isfinite(v)):
                if calls[0] == 1:
                    raise self._non_finite(tt, zz)
                if self.non_finite is None:  # the first in this step: near the orbit
                    self.non_finite = _first_not_finite(tt, zz, v)
                v = np.full(np.shape(v), rules.NON_FINITE_STAGE)
            return v

        self.method = method
        self.solver = method(checked, t, z, t_end, rtol=rtol, atol=atol,
                             max_step=max_step if np.isfinite(max_step) else np.inf,
                             **({} if method is DOP853 else
                                {"vectorized": True, "stages": STIFF_STAGES}))

    def _non_finite(self, tt, zz, more=""):
        zz = np.asarray(zz, dtype=float)
        return run_error(NON_FINITE, tt, zz, f" ({self.piece(zz)} returned a non-finite "
                                             f"value there{more})")

    def _guarded_step(self, s):
        """One step of the solver s and its dense output: (scipy's message, the dense
        output; None once failed). A DOP853 step whose stages met the non-finite guard
        (rules.NON_FINITE_STAGE) is never accepted: where several stages take its
        constant, the error estimate (zero for a constant field) passes it; nor one whose
        interpolant's extra stages (taken by dense_output()) met it, which made the dense
        output ~1e300. Taken back and tried again shorter, as scipy rejects a step, until
        none meets it or the step size collapses (then failed, named by step())."""
        msg = s.step()
        while s.status != "failed":
            dense = s.dense_output()
            if self.non_finite is None or not np.any(
                    getattr(s, "K_extended", s.K)[:, 0] == rules.NON_FINITE_STAGE):
                return msg, dense
            h = abs(s.h_previous) * _SHRINK
            s.t, s.y, s.f = s.t_old, s.y_old, self.f_before
            s.status, s.h_abs = "running", h
            if not h >= 10 * np.abs(np.nextafter(s.t, np.inf) - s.t):
                s.status = "failed"
                return "the step size collapsed on a non-finite field value", None
            msg = s.step()
        return msg, None

    def step(self):
        s = self.solver
        ta = s.t
        if self.not_finite_at is not None:  # no event before it: the run stops there
            raise self._non_finite(*self.not_finite_at, more="; the orbit found runs "
                                                             "through it")
        self.non_finite = None
        self.f_before = getattr(s, "f", None)   # the field at ta (_guarded_step)
        if self.noise is not None and s.step_size is not None:
            # RadauIIA reads its atol afresh in every step
            s.atol = np.maximum(self.atol, NOISE_STEPS * s.step_size * self.noise)
            self.atol_used = max(self.atol_used, float(np.max(s.atol)))
        if self.method is RadauIIA:  # no guard stages: its collocation is solved
            try:
                with _one_blas_thread():
                    msg = s.step()
            except ValueError:  # LAPACK refuses a Newton matrix the guard's values filled
                if self.non_finite is None:
                    raise
                raise self._non_finite(*self.non_finite, more=f"; RadauIIA could not step "
                                       f"past it from t={float(ta)!r}") from None
            dense = None if s.status == "failed" else s.dense_output()
        else:
            msg, dense = self._guarded_step(s)
        if s.status == "failed":
            if self.non_finite is not None:  # the step size collapsed on a NaN or inf
                raise self._non_finite(*self.non_finite, more=f"; {self.method.__name__} "
                                       f"could not step past it from t={float(ta)!r}")
            raise run_error(STEP_FAILED, ta, s.y, f": {self.method.__name__} failed: {msg}")
        if self.non_finite is not None:
            self.suspect = min(self.suspect, self.non_finite[0])
        if self.suspect <= s.t:
            return ta, self._passed_suspect(dense, s.t), dense
        return ta, s.t, dense

    def _passed_suspect(self, dense, tb):
        """The step passed a time a trial stage met the non-finite guard at: the field on
        the orbit found, there, is finite (the suspect cleared), or the orbit runs through a
        non-finite field -- a band of NaN a shorter step may have stepped over
        (docs/decisions.md#named-edges, (5)). The end of the step the run searches: tb, or
        that time, where the next step raises unless an event before it ends the stay."""
        t, self.suspect = self.suspect, np.inf
        z = np.asarray(dense(t), dtype=float)
        if np.all(np.isfinite(np.asarray(self.fun(t, z), dtype=float))):
            return tb
        self.not_finite_at = (t, z)
        return t


# --------------------------------------------------------------------------- crossings
EXACT_BLOCK = 16
PROJECT_AFTER = 1000  # steps before the step budget is projected from the mean step
#: every STIFF_AFTER DOP853 steps in one stay in a mode, the step is compared with
#: the field's stiffness: when h * rho(J) > 1 the step is bounded by stability, not
#: accuracy (a fast variable slaved to a slow manifold, e.g. sliding of a slow-fast
#: system at small eps), and the rest of the stay is integrated by the implicit
#: Radau IIA method (:mod:`filippov.radau_iia`, STIFF_STAGES stages; listed in
#: Trajectory.stiff_modes). Why 25: docs/decisions.md#stiff-switch
STIFF_AFTER = 25

#: stages of the Radau IIA method that takes over a stiff stay (order 2 s - 1; why 5:
#: docs/decisions.md#stiff-switch)
STIFF_STAGES = 5

#: A stiff field amplifies the rounding of the state, and the implicit method cannot
#: settle below h times that noise: its absolute tolerance is kept at least
#: NOISE_STEPS * h * field_noise (per component, h the last step;
#: docs/decisions.md#stiff-noise-floor)
NOISE_STEPS = 10.0


def field_noise(fun, t, z, floor: float = 1.0) -> np.ndarray:
    """Per component, how far the field moves when the state is rounded: |J| (u |z|)
    plus the rounding of the field itself (u = unit roundoff; J by differences stepping
    from ``floor``, the state scale, up)."""
    z = np.asarray(z, dtype=float)
    f = np.asarray(fun(t, z), dtype=float)
    jac = variational.fd_jacobian(lambda zz: fun(t, zz), z, floor=floor)
    u = np.finfo(float).eps
    return np.abs(jac) @ (u * np.abs(z)) + u * np.abs(f)


def spectral_radius(fun, t, z, iterations: int = 6, floor: float = 1.0) -> float:
    """Largest |eigenvalue| of the field's Jacobian at ``z``, by power iteration on
    finite differences (iterations + 1 field evaluations; steps from ``floor``, the
    state scale, up)."""
    z = np.asarray(z, dtype=float)
    f0 = np.asarray(fun(t, z), dtype=float)
    v = np.ones_like(z) / np.sqrt(z.size)
    delta = 1e-7 * (floor + np.linalg.norm(z))
    rho = 0.0
    for _ in range(iterations):
        w = (np.asarray(fun(t, z + delta * v), dtype=float) - f0) / delta
        rho = float(np.linalg.norm(w))
        if not (np.isfinite(rho) and rho > 0):
            return 0.0
        v = w / rho
    return rho


def _brent(fun, ta, tb, fa, fb, xtol):
    """Brent's root of ``fun`` in [ta, tb], whose sampled values ``fa``, ``fb`` differ in
    sign. The samples come from array evaluations and ``fun`` from scalar ones, which
    may round differently (numpy's SIMD loops, another CPU): where ``fun`` at the ends
    has lost the sign change the samples saw, the bracket keeps the sampled end values
    (the interior is ``fun``'s), so a change the scan decided on is never dropped."""
    try:
        return brentq(fun, ta, tb, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=rules.BRENT_MAXITER)
    except ValueError:
        if not (fa * fb <= 0 and (fa != 0 or fb != 0)):
            raise
    pinned = lambda t: fa if t == ta else fb if t == tb else fun(t)  # noqa: E731
    return brentq(pinned, ta, tb, xtol=xtol, rtol=4 * np.finfo(float).eps, maxiter=rules.BRENT_MAXITER)


# the refinement of a crossing (filippov.loop.refine, written once for both engines,
# asked by the event search) on this engine's root finder: f a callable of time, scipy's
# brentq to the tolerance xtol

def _bracket_root(xtol, fun, ta, tb):
    try:
        r = brentq(fun, ta, tb, xtol=xtol, rtol=4 * np.finfo(float).eps,
                   maxiter=rules.BRENT_MAXITER)
    except ValueError:  # no sign change between fun(ta) and fun(tb)
        return False, ta, fun(ta)
    return True, r, fun(r)


def _root(xtol, fun, lo, hi, vlo, vhi):
    """The reference's root finder (loop.interval.WindowOps' ``root``): scipy's brentq on
    ``fun`` in [lo, hi]; with the samples' values vlo, vhi handed (not NaN), the bracket
    pinned to them where ``fun`` at the ends lost their sign change (_brent). Not ok, at
    the time and with NaN, where ``fun`` was not finite (loop.refine: CUT)."""
    try:
        if math.isnan(vlo):
            return _bracket_root(xtol, fun, lo, hi)
        r = _brent(fun, lo, hi, vlo, vhi, xtol)
        return True, r, fun(r)
    except ValueNotFinite as cut:
        return False, cut.t, math.nan


def _pieces(run):
    """The pieces at the run's state (loop.event.Pieces): a and b as
    PiecewiseSystem.normal_speeds sums them."""
    z = np.asarray(run.z, dtype=float)
    system = run.system
    grad = np.asarray(system.switch_grad(z), float)
    fm, fp = np.asarray(system.field_minus(z), float), np.asarray(system.field_plus(z), float)
    return Pieces(z, grad, fm, fp, float(np.sum(grad * fm, axis=0)),
                  float(np.sum(grad * fp, axis=0)), float(system.switch(z)),
                  getattr(run, "state_scale", 1.0), getattr(run, "scales", np.ones(z.size)))


def _section_along(k, mode, d, run):
    """Section k at z + d times the field of ``mode`` at z (d = 0: at z itself)."""
    z, func = np.asarray(run.z, dtype=float), run.sections[k].func
    if d == 0.0:
        return float(func(z))
    system = run.system
    f = (system.field_minus(z) if mode == MINUS else system.field_plus(z) if mode == PLUS
         else system.sliding_field(z))
    return float(func(z + d * np.asarray(f, float)))


#: where a start is asked about, for the run's operations (they read these fields of a
#: _Run): the start's mode outside a run (initial_mode), the refusal's message
_At = namedtuple("_At", ["system", "sections", "z"])


def _sliding_section(at):
    """The index of the first section the sliding flow at the state of ``at`` (an _At or a
    _Run) stays in, or -1 (none): the loop's test (loop.event.make_sliding_section)."""
    return _SLIDING_SECTION(len(at.sections), at)


def _start(at, touch_tol):
    """(status, mode, what the start event is called) of a start at ``at`` (an _At or
    a _Run)."""
    # a start continues no orbit here (age 0: filippov.engines, the carried age)
    status, mode, repelling, _ = _START(float(at.system.switch(at.z)), touch_tol,
                                        at.system.sliding, len(at.sections), 0.0, at)
    return status, mode, ("repelling_start" if repelling else "start")


def _refuse_sliding_in_sections(system, sections, z, t) -> None:
    k = _sliding_section(_At(system, sections, z))
    if k >= 0:
        raise run_error(
            SECTION_SLIDING, t, z, f": it slides from there inside section "
            f"{sections[k].name!r} (the section lies on H there). Stop at the arrival on H (a "
            "terminal hit there ends the run first) or use a section transverse to "
            "the sliding flow")


# --------------------------------------------------------------------------- driver
def initial_mode(system: PiecewiseSystem, z: np.ndarray, touch_tol: float) -> tuple[int, str]:
    """Region to start in; on H = 0 (to ``touch_tol``) the field directions decide
    (:func:`filippov.rules.start_on_switch`), so a start point that rounding puts a
    hair on the wrong side is not a switch."""
    _, mode, kind = _start(_At(system, (), z), touch_tol)
    return mode, kind


def _quiet_floating_point(fn):
    """Run ``fn`` with overflow/invalid warnings off: the driver tests every field
    value and state for finiteness itself (an overlong trial step may overflow)."""
    @functools.wraps(fn)
    def wrapper(*args, **kwargs):
        with np.errstate(over="ignore", invalid="ignore"):
            return fn(*args, **kwargs)
    return wrapper


def slow_window(slow_sample_step, h, max_step, span):
    """The window of an exact flow after the fast transient: EXACT_BLOCK slow
    sample steps, within the same caps as the fast window and never shorter."""
    if not np.isfinite(slow_sample_step):
        return h
    return max(h, min(EXACT_BLOCK * slow_sample_step, max_step, span))


@_quiet_floating_point
def simulate(system, z0, t_end: float, *, engine: str = "reference", t0: float = 0.0,
             method: str = "exact", rtol: float = 1e-12, atol: float = 1e-14,
             max_step: float = np.inf, sections: Sequence[Section] = (),
             max_events: int = 100_000, max_steps: int = 5_000_000,
             dense: bool = True, samples_per_step: int = 4, touch_tol: float = 1e-15,
             event_xtol: float = 1e-15, zeno_count: int = 64,
             zeno_span: float = 1e-10, stiff: bool = True, scale=None) -> Trajectory:
    """Integrate ``system`` from ``z0`` at ``t0`` to ``t_end`` (or a terminal section).

    ``system`` is a :class:`~filippov.system.PiecewiseSystem` or a system defined once
    (:class:`~filippov.FilippovSystem`, :class:`~filippov.SymbolicSystem`: its
    ``python()`` view). ``engine``: "reference" (this driver; the only engine with a
    trajectory output -- "compiled" is refused, see :mod:`filippov.engines`).

    ``method="exact"`` uses the system's exact flows where it has them (modes
    without one are integrated, listed in ``Trajectory.integrated_modes``);
    ``method="integrate"`` integrates every mode with DOP853 at ``rtol``/``atol``.
    Contacts with ``|H| <= touch_tol`` at a tangency count as touching, not
    crossing (region + is ``H >= 0``). With ``stiff`` (default), an integrated
    mode whose DOP853 steps turn out bounded by stability (step x spectral radius
    of the Jacobian > 1, checked every ``STIFF_AFTER`` steps) continues with the
    implicit Radau IIA method of order 9 (:class:`filippov.radau_iia.RadauIIA`;
    listed in ``Trajectory.stiff_modes``), whose absolute
    tolerance is kept above the field's rounding noise (``NOISE_STEPS``; where that
    lifted it above ``atol``, ``Trajectory.atol_raised`` says by how much).

    Units (:mod:`filippov.scale`): ``atol`` is in units of the state scale S,
    ``touch_tol`` of H's scale, ``event_xtol`` (and the time below which ``zeno_span`` is
    absolute) of the time scale T; ``scale`` (None: the system's, declared or measured
    at ``z0``) sets them, and ``Trajectory.scale`` says which were used.
    """
    run = views.pick(RUNS, "simulate", engine)
    opts = dict(t0=t0, t_end=t_end, method=method, rtol=rtol, atol=atol, max_step=max_step,
                max_events=max_events, max_steps=max_steps, dense=dense,
                samples_per_step=samples_per_step, touch_tol=touch_tol, event_xtol=event_xtol,
                zeno_count=zeno_count, zeno_span=zeno_span, stiff=stiff, scale=scale)
    return run(views.reference_system(system, "simulate", several=True), z0, sections, opts)


def _simulate(system: PiecewiseSystem, z0, sections: Sequence[Section], opts: dict) -> Trajectory:
    """The reference driver's run of :func:`simulate` (``opts``: its options by name)."""
    method, t0, t_end = opts["method"], opts["t0"], opts["t_end"]
    if method not in ("exact", "integrate"):
        raise ValueError(f"method must be 'exact' or 'integrate', got {method!r}")
    z = np.array(z0, dtype=float).reshape(-1)
    if z.size != system.dim:
        raise ValueError(f"initial state has {z.size} components, system has {system.dim} "
                         f"({', '.join(system.names)})")
    if not np.all(np.isfinite(z)):
        raise ValueError(f"initial state must be finite, got {z.tolist()}")
    if not (np.isfinite(t0) and np.isfinite(t_end) and t_end >= t0):
        raise ValueError(f"need finite t0 <= t_end, got t0={t0!r}, t_end={t_end!r}")
    options.check(**{k: v for k, v in opts.items() if k not in ("t0", "t_end", "method",
                                                                   "scale")})
    for k, sec in enumerate(sections):
        if not isinstance(sec, Section):
            raise TypeError(f"sections[{k}]: expected a filippov.simulate.Section, got "
                            f"{type(sec).__name__}")
    if isinstance(system, SurfacesSystem):  # several surfaces: stay by stay
        return several.run(system, z, list(sections), opts, one_stay, initial_mode)
    sc = scale_mod.of_system(system, z, opts.get("scale"))   # never raises: checked next
    checks.check_system(system, z, method=method, floor=sc.state,   # the class's contract
                        scales=sc.of_components(z.size))
    return _Run(system, z, list(sections), scale_mod.tolerances(opts, sc, z.size),
                sc).go()


#: what runs :func:`simulate` on each engine (the compiled one has no trajectory
#: output: :data:`filippov.views.LACKS`)
RUNS = {views.REFERENCE: _simulate, views.COMPILED: None}


class _Run:
    """One call of :func:`simulate`: its options, the trajectory and the counters.
    :meth:`go` runs the shared loop (:data:`_RUN`), :meth:`stay` follows one mode until
    its next event; the functions under "one event" are what the loop does there."""

    def __init__(self, system, z, sections, opts, scale=UNIT, begun=None):
        self.system, self.sections = system, sections
        self.state_scale = self.time_scale = 1.0
        self.__dict__.update(opts)
        # each component's scale (filippov.scale): the metric of the two-fold's cosines
        self.scales = scale.of_components(np.asarray(z).size)
        self.slide_checked = False   # an exact sliding flow: checked where first used
        self.traj = Trajectory(system=system, t0=self.t0, z0=z.copy(), t=self.t0, z=z.copy(),
                               scale=scale)
        self.t, self.z = self.t0, z
        if begun is None:
            status, self.mode, kind = _start(self, self.touch_tol)
            self.traj.events.append(Event(self.t0, kind, z.copy(), self.mode, self.mode))
            if status != GO_ON:
                raise self._event_error(status)
        else:  # a stay that goes on from a switch the run before it decided (_one_stay)
            self.mode = begun[0]
        self.traj.mode = self.mode
        self.preds = [rules.section_pred(sec.direction) for sec in sections]
        self.hits = [0] * len(sections)
        # what the loop keeps: limits, switches, the Zeno ring (filippov.loop.run_state)
        self.rs = new_run_state(Limits(self.t_end, system.sliding, self.max_events,
                                       self.zeno_count, self.zeno_span, self.touch_tol,
                                       self.state_scale, self.time_scale, True,
                                       len(sections), self.max_steps, self.rtol))
        self.hit_section = None
        self.failed = None  # a slide's failed step (_step), raised unless at a two-fold
        self._flow_field = None  # (mode, f, z) at the end of the last exact window
        # subtracted from H in this stay (rules.exit_shift); ... while inside the exit's
        # band (rules.banded_shift); the rounding band of the exit the stay began at
        # (rules.exit_band)
        self.shift, self.banded, self.band = (0.0, 0.0, 0.0) if begun is None else begun[1:]
        self.handed_on = False  # the run ended at its first switch (_one_stay)
        # the sections a start on which is no hit, the instant they were hit at, and the
        # time and state of the stay's start: all of them at a run's start; at a stay that
        # goes on from a switch (one_stay) those its caller names (hit at that switch); at
        # a stay that begins at the instant of a section hit (one_instant: also after a
        # switch refined a few ulps past it), the sections hit then (_section_hit)
        self.start_sections, self.start_instant = None, self.t0
        self.start_t, self.start_z = self.t0, z.copy()
        self.frac_integrated = np.linspace(0.0, 1.0, self.samples_per_step + 1)
        # An exact flow is evaluated EXACT_BLOCK windows at a time: the same sample
        # spacing, a sixteenth of the Python overhead.
        self.frac_exact = np.linspace(0.0, 1.0, EXACT_BLOCK * self.samples_per_step + 1)

    def stop(self, status):
        traj = self.traj
        traj.status, traj.t, traj.z, traj.mode = status, self.t, self.z.copy(), self.mode
        return traj

    def go(self) -> Trajectory:
        """The run from the start, in the shared order of :mod:`filippov.loop.event`; a
        status that ends it becomes the trajectory's end or its exception."""
        status, _, _ = _RUN(self.z, 0.0, self, self.rs)
        if status == NO_RETURN:
            return self.stop("t_end")
        if status == OK:
            return self.stop(f"section:{self.sections[self.hit_section].name}")
        if status == STEP_FAILED:  # a slide's failed step, not at a two-fold: as raised
            raise self.failed
        raise self._event_error(status)

    # ------------------------------------------------------------------ one stay
    def flows_exactly(self, mode):
        return self.method == "exact" and self.system.has_flow(mode)

    def _stepper(self, mode):
        system, t, z = self.system, self.t, self.z
        if self.flows_exactly(mode):
            if mode == SLIDING and not self.slide_checked:   # where a slide first begins
                checks.sliding_flow_check(system, z, t, self.scales)
                self.slide_checked = True
            h = min(EXACT_BLOCK * system.sample_step, self.max_step, self.t_end - self.t0)
            return _ExactStepper(system.flows[mode], z, t, self.t_end, h,
                                 slow_window(system.slow_sample_step, h, self.max_step,
                                             self.t_end - self.t0),
                                 system.transient_time)
        self.traj.integrated_modes.add(MODE_NAMES[mode])
        return _IntegratingStepper(lambda _t, zz: system.field(mode, zz), z, t, self.t_end,
                                   self.rtol, self.atol, self.max_step,
                                   piece=lambda zz: checks.non_finite_piece(system, mode, zz))

    def _leave(self, mode, banded=True):
        """The functions whose sign change ends this mode (rules.leave_pred: H, measured
        from the exit's rounding band while the stay is inside it unless not ``banded``;
        while sliding a and b)."""
        system = self.system
        if mode != SLIDING:
            shift = self.banded if banded and self.band > 0.0 else self.shift
            switch = (system.switch if shift == 0.0
                      else (lambda zz, c=shift: system.switch(zz) - c))
            return [switch]
        return [lambda zz: system.normal_speeds(zz)[0], lambda zz: system.normal_speeds(zz)[1]]

    # A stay, in the shared order of filippov.loop.event: per step next_step (the first
    # begins the stay: start_stay), its windows (window, walked by
    # loop.stay.make_step_windows), end_step.
    def start_stay(self):
        """The stay in the current mode begins: its stepper and leave functions."""
        if not one_instant(self.start_instant, self.t, self.event_xtol):
            self.start_instant, self.start_sections = self.t, set()   # on no section
        self.start_t, self.start_z = self.t, self.z.copy()
        self.stepper = self._stepper(self.mode)
        self.leave_now = self._leave(self.mode)
        self.steps_in_mode = 0
        return GO_ON

    def next_step(self, first):
        """The stay's next step (its dense output in self.step_Z): (GO_ON, its end);
        ``first``: the stay begins (:meth:`start_stay`)."""
        if first:
            self.start_stay()
        step = self._step(self.stepper)
        if step is None:  # a slide's step failed: the loop asks whether at a two-fold
            return STEP_FAILED, self.t
        ta, tb, self.step_Z = step
        if self.dense:
            self.traj.segments.append((ta, tb, self.mode, self.step_Z))
        return GO_ON, tb

    def end_step(self, ta, tb, status):
        """After a step's windows: GO_ON to the next step (NO_RETURN once it passed
        t_end), or the event found (OK: the state at it, the section hit in hit_section)."""
        stepper = self.stepper
        if status == GO_ON:
            if tb >= self.t_end:
                self._note_tolerance(stepper)
                return NO_RETURN
            self.steps_in_mode += 1
            self.stepper = self._stiff_switch(stepper, self.steps_in_mode, tb - ta)
            return GO_ON
        te, ze, what, idx = self.found
        if self.dense:  # the segment ends at the event
            self.traj.segments[-1] = (ta, te, self.mode, self.step_Z)
        self.t, self.z = te, ze
        self._note_tolerance(stepper)
        self.hit_section = idx
        return OK

    def window(self, ta, tb, first, may_split):
        """The window [ta, tb] of the current step: sampled, then searched for its
        earliest event (OK, its time, what; kept in self.found) or none (GO_ON: the state
        at tb); UNRESOLVED when ``may_split`` and its samples do not resolve what they
        sample (loop.stay.make_step_windows; an exact flow's window is the model's own,
        its sample_step resolves it: never split)."""
        stepper, Z = self.stepper, self.step_Z
        ts, zs = self._samples(stepper, Z, ta, tb)
        self.traj.n_windows += stepper.method is not None
        scan = _Scan(self.system, self.mode, Z, ts, zs, self.leave_now, self.sections,
                     self.preds, first, self.touch_tol, self.event_xtol, self.traj,
                     self.band, self._leave(self.mode, banded=False) if self.band > 0.0
                     else None)
        scan.start_sections, scan.start = self.start_sections, (self.start_t, self.start_z)
        if may_split and stepper.method is not None and not scan.resolved():
            # a window cut at a sample not finite: its shorter windows end there
            # (loop.stay.make_step_windows)
            return UNRESOLVED, (ta if scan.not_finite is None else scan.cut_time), None
        band = self.band
        found = self._scan(scan, ta, tb)
        if found is None:
            self.t, self.z = tb, zs[:, -1].copy()
            if self.band != band:  # the scan ended the exit's band: H unbiased on
                self.leave_now = self._leave(self.mode)
            return GO_ON, tb, None
        self.found = found
        return OK, found[0], found[2]

    def _note_tolerance(self, stepper):
        """At the end of a stay: how far the noise floor lifted Radau IIA's atol (the
        stepper keeps the largest; a stay ends with the stepper that lifted it)."""
        if stepper.method is RadauIIA and stepper.atol_used > np.max(self.atol):
            raised, name = self.traj.atol_raised, MODE_NAMES[self.mode]
            raised[name] = max(raised.get(name, 0.0), stepper.atol_used)

    def _step(self, stepper):
        """One step (the run asked the step budget before it: filippov.loop.event); a run
        that cannot reach t_end within the budget stops now, not after minutes (the steps
        left projected from the mean step). None where a slide's step failed (kept in
        self.failed, raised unless the loop finds the slide at a two-fold)."""
        traj, mode = self.traj, self.mode
        traj.n_steps += 1
        try:
            ta, tb, Z = stepper.step()
        except SimulationError as err:
            if mode != SLIDING:
                raise
            self.failed = err
            return None
        stepper.n_taken += 1
        mean = (tb - stepper.t_start) / stepper.n_taken
        left = ((self.t_end - tb) / mean if stepper.n_taken > PROJECT_AFTER and mean > 0
                else 0.0)
        if traj.n_steps + left > self.max_steps:
            raise run_error(
                STEP_LIMIT, ta, self.z, f", mode {MODE_NAMES[mode]}: steps of {tb - ta:.3g} "
                f"(mean {mean:.3g}): ~{left:.3g} more steps to "
                f"t_end={self.t_end!r} exceed max_steps={self.max_steps}"
                + ("; the integrated field is stiff here (a fast time scale, e.g. a "
                   "small eps): use exact flows or a shorter t_end"
                   if stepper.method is not None else ""))
        return ta, tb, Z

    def _samples(self, stepper, Z, ta, tb):
        frac = self.frac_exact if stepper.method is None else self.frac_integrated
        ts = ta + frac * (tb - ta)
        ts[-1] = tb
        zs = Z(ts)
        if not np.all(np.isfinite(zs[:, 0])):
            raise run_error(NON_FINITE, ta, self.z, f", mode {MODE_NAMES[self.mode]}: the "
                            f"state turns non-finite before t={tb!r} (the state given: the "
                            "last finite one)")
        # a state not finite further on cuts the samples there (_Scan: an event before
        # it stands), as a piece's value does; the flow is checked on a finite window
        if stepper.method is None and np.all(np.isfinite(zs[:, -1])):
            self._check_flow(ta, tb, zs[:, -1])
        return ts, zs

    def _check_flow(self, ta, tb, zb):
        """An exact flow must move the state as its field does (rules.flow_consistent):
        a closed form that loses its accuracy (cancellation at extreme parameters) is
        refused here, not followed to a wrong answer."""
        za = self.z
        # the field at the window's start is the last window's end value: kept, not redone
        last = self._flow_field
        fa = (last[1] if last is not None and last[0] == self.mode
              and np.array_equal(last[2], za)
              else np.asarray(self.system.field(self.mode, za), dtype=float))
        fb = np.asarray(self.system.field(self.mode, zb), dtype=float)
        self._flow_field = (self.mode, fb, zb.copy())
        dz = float(np.linalg.norm(zb - za))
        if not rules.flow_consistent(dz, tb - ta, float(np.linalg.norm(fa)),
                                     float(np.linalg.norm(fb)),
                                     float(max(np.abs(za).max(), np.abs(zb).max())),
                                     self.state_scale):
            raise run_error(
                FLOW_OFF_FIELD, ta, za, f": the exact flow of mode {MODE_NAMES[self.mode]} "
                f"moved the state by {dz:.3g} to t={tb!r} (state {zb.tolist()}), but its "
                f"field's speed is {np.linalg.norm(fa):.3g} .. {np.linalg.norm(fb):.3g}: the "
                f"closed form does not follow the field there; use integrated flows "
                "(method='integrate') or check the flow's formula")

    def _scan(self, scan, ta, tb):
        try:
            found, band = scan.earliest()
        except ValueError as exc:  # scipy's root finders: no context of their own
            raise run_error(
                ROOT_FAILED, ta, self.z, f", mode {MODE_NAMES[self.mode]}: between t={ta!r} "
                f"and t={tb!r}: {exc}; the sampled sign change did not survive refinement "
                f"(time scale of the system: sample_step {self.system.sample_step!r})"
            ) from exc
        self.band = band
        return found

    def _stiff_switch(self, stepper, steps_in_mode, h):
        """Radau IIA for the rest of the stay when DOP853's steps are bounded by stability
        (checked every STIFF_AFTER steps; see there)."""
        if not (self.stiff and stepper.method is DOP853 and steps_in_mode % STIFF_AFTER == 0):
            return stepper
        field = stepper.fun
        if h * spectral_radius(field, self.t, self.z, floor=self.state_scale) <= 1.0:
            return stepper
        self.traj.stiff_modes.add(MODE_NAMES[self.mode])
        stiff = _IntegratingStepper(field, self.z, self.t, self.t_end, self.rtol, self.atol,
                                    self.max_step, method=RadauIIA, piece=stepper.piece,
                                    noise=field_noise(field, self.t, self.z,
                                                      self.state_scale))
        stiff.suspect = stepper.suspect   # a time not yet passed goes with the stay
        return stiff

    # ------------------------------------------------------------------ one event
    def _event_error(self, status):
        """The exception of a status :func:`_RUN` ended the run with, at (t, z)."""
        te, ze = self.t, self.z
        if status == NO_SLIDING:
            return _no_sliding(te, ze)
        if status == SECTION_SLIDING:
            _refuse_sliding_in_sections(self.system, self.sections, ze, te)
        if not hasattr(self, "rs"):   # at the start, before the run's record exists
            return run_error(status, te, ze)
        ring, entries = self.rs.ring, self.rs.count[RING]
        if status == ZENO:
            ratio, t_star = rules.geometric_accumulation(ring, entries, self.zeno_count)
            if ratio == ratio:
                return run_error(ZENO, te, ze, accumulation_detail(ratio, t_star))
            oldest = ring[entries % self.zeno_count]
            return run_error(ZENO, te, ze, f": {self.zeno_count} switches within "
                                           f"{te - oldest:.3e} time units (Zeno point or "
                                           "chattering below the time resolution)")
        if status == TWO_FOLD and getattr(self, "failed", None) is not None:  # a failed step
            return run_error(TWO_FOLD, te, ze, ": the sliding field's steps collapsed where "
                             "both fields are tangent to H")
        if status == STEP_LIMIT:
            return run_error(STEP_LIMIT, te, ze, f", mode {MODE_NAMES[self.mode]}: step "
                             f"limit {self.max_steps} hit: the run is too long or the step "
                             "size collapsed")
        if status == EVENT_LIMIT and self.rs.count[SWITCHES] > self.max_events:
            return run_error(EVENT_LIMIT, te, ze, f": event limit {self.max_events} hit "
                                                  "(rapid switching)")
        if status == EVENT_LIMIT:  # projected (rules.budget_runs_out) at the switch recorded
            every, ahead = rules.budget_projection(ring, entries, te, self.zeno_count,
                                                   self.t_end)
            new_mode = self.traj.events[-1].mode_after
            return run_error(
                EVENT_LIMIT, te, ze, f", mode {MODE_NAMES[new_mode]}: switching every "
                f"{every:.3g} time units: ~{ahead:.3g} more switches to t_end={self.t_end!r} "
                f"exceed max_events={self.max_events} (raise max_events if this rate does "
                "not last)")
        return run_error(status, te, ze)

    def _flow_at_zero(self, mode, z):
        """The state the next stay in ``mode`` starts from as its stepper evaluates it:
        the exact flow of z over time 0 (its rounding, rules.exit_band), or z itself for
        an integrated stay."""
        if self.method == "exact" and self.system.has_flow(mode):
            zf = self.system.flows[mode](z, np.zeros(1))
            return np.asarray(zf, dtype=float).reshape(-1)
        return z


def _no_sliding(t, z) -> SlidingNotBuiltError:
    return run_error(NO_SLIDING, t, z, ": the system was built with sliding=False; build "
                                       "it with sliding=True to follow sliding")


#: how many hits of one section within one instant (rules.same_instant) a run may log
#: before it is refused as not advancing (_section_hit)
REHITS_AT_INSTANT = 8


def _section_hit(mode, t, run):
    """Logs the hit, and those of the sections crossed at its instant
    (:func:`filippov.section.tied_hits`, on the step's dense output), in order; GO_ON, or
    OK when a terminal one is hit often enough (``hit_section``: the first such)."""
    name = run.sections[run.hit_section].name
    if names_hit_within(run.traj.events, t, run.event_xtol).count(name) >= REHITS_AT_INSTANT:
        # section hits count against no budget: a run that finds one crossing again and
        # again at one instant would not advance (an orbit may cross a section twice
        # within rounding, at a corner: not refused)
        raise run_error(EVENT_LIMIT, t, run.z, f"; section {name!r} hit "
                        f"{REHITS_AT_INSTANT + 1} times within one instant: the run does "
                        "not advance past it")
    ties = [] if len(run.sections) < 2 else tied_hits(
        run.sections, run.hit_section, t, run.z, run.step_Z, run.traj.t0, run.event_xtol,
        skip=hit_within(run.sections, run.traj.events, t, run.event_xtol))
    ended, hit = None, sorted([run.hit_section] + ties)   # one instant: in the order given
    for idx in hit:
        sec = run.sections[idx]
        run.hits[idx] += 1
        run.traj.events.append(Event(t, "section", run.z.copy(), mode, mode, sec.name))
        if ended is None and sec.terminal is not None and run.hits[idx] >= sec.terminal:
            ended = idx
    if ended is None:
        # the run goes on from the hit's state, on these sections: an exact flow that
        # rounds it back a hair is no second crossing (rules.starts_on_section)
        if not one_instant(run.start_instant, t, run.event_xtol):
            run.start_instant, run.start_sections = t, set()
        if run.start_sections is not None:
            run.start_sections = set(run.start_sections) | set(hit)
        return GO_ON
    run.hit_section = ended
    return OK


def _exit_state(new_mode, run):
    """The event's state, a copy of its own (the event may move it onto H), grad H and H
    there, and the state the next stay in new_mode starts from as it evaluates it."""
    run.z = run.z.copy()
    return (run.z, run.system.switch_grad(run.z[:, None])[:, 0],
            float(run.system.switch(run.z)), run._flow_at_zero(new_mode, run.z))


def _record(mode, new_mode, what, t, shift, banded, band, run):
    """A section hit (:func:`_section_hit`: OK, or GO_ON) or a switch, logged, after which
    the run goes on in new_mode with the next stay's shifts and band (dP/dz across a
    crossing: filippov.variational, from the trajectory): GO_ON."""
    if what == SECTION:
        return _section_hit(mode, t, run)
    kind = ("slide_end" if what != rules.SWITCH
            else "crossing" if new_mode != SLIDING else "slide_start")
    run.traj.events.append(Event(t, kind, run.z.copy(), mode, new_mode))
    run.shift, run.banded, run.band = shift, banded, band
    run.mode = run.traj.mode = new_mode
    return GO_ON


#: the reference driver's side of the seam (filippov.contracts.RunOperations) and its
#: run (filippov.loop.event) on them; ctx: the _Run, which made its start when it was
#: built (begin: the state it made)
RUN_OPERATIONS = RunOps(
    begin=lambda z0, age0, run: (GO_ON, run.t, run.mode),
    next_step=lambda mode, ta, first, run: run.next_step(first),
    window=lambda mode, t0, t1, first, may_split, run: run.window(t0, t1, first, may_split),
    end_step=lambda mode, ta, tb, status, t, run: run.end_step(ta, tb, status),
    record=_record,
    pieces=_pieces,
    section_along=_section_along,
    exit_state=_exit_state)
_RUN = make_run(RUN_OPERATIONS)


def _record_and_hand_on(mode, new_mode, what, t, shift, banded, band, run):
    """:func:`_record`, and a switch ends the run there (OK, ``run.handed_on``)."""
    status = _record(mode, new_mode, what, t, shift, banded, band, run)
    if what == SECTION or status != GO_ON:
        return status
    run.handed_on = True
    return OK


#: the shared loop up to its first switch: one stay of a several-surface run
_RUN_TO_SWITCH = make_run(RUN_OPERATIONS._replace(record=_record_and_hand_on))


def one_stay(system, z, sections, opts, scale, begun=None, start_sections=None):
    """One stay of a run on ``system`` (a one-surface view: filippov.several), to its
    first switch ("switch", the switch recorded and its next mode in ``run.mode``), a
    terminal section ("section") or the end time ("t_end"): ``(how, run)``; anything
    else raises as :func:`simulate` does. ``begun``: (mode, shift, banded, band) of a
    stay that goes on from a switch (else the start decides, as a run's start does);
    ``opts``: the run's options in its units (filippov.scale.tolerances);
    ``start_sections``: the indices of the sections a start on which (up to rounding) is
    no hit (None: all, as at a run's start) -- a stay that goes on from a switch counts a
    crossing just after it, unless the stay before already counted it there."""
    run = _Run(system, z, list(sections), opts, scale, begun)
    run.start_sections = start_sections
    status, _, _ = _RUN_TO_SWITCH(run.z, 0.0, run, run.rs)
    if status == OK:
        return ("switch" if run.handed_on else "section"), run
    if status == NO_RETURN:
        return "t_end", run
    if status == STEP_FAILED:
        raise run.failed
    raise run._event_error(status)


#: the start's mode and its refusal to slide in a section, and that test alone, on the
#: operations above (filippov.loop.event)
_START = make_start(RUN_OPERATIONS)
_SLIDING_SECTION = make_sliding_section(RUN_OPERATIONS)


def _speed_rates(system, Z, z0, floor=1.0):
    """While sliding: ``rates(t) -> (da/dt, db/dt)`` on the segment ``Z`` (forward
    differences on the orbit, of the step rules.rate_step gives at its first sample z0),
    or None where that step is 0."""
    fm = np.asarray(system.field_minus(z0), dtype=float)
    fp = np.asarray(system.field_plus(z0), dtype=float)
    a, b = (float(v) for v in system.normal_speeds(z0))
    d = rules.rate_step(z0, fm, fp, a, b, floor)
    if d == 0.0:
        return None

    def rates(tt):
        tt = np.asarray(tt, dtype=float)
        a1, b1 = system.normal_speeds(Z(tt + d))
        a0, b0 = system.normal_speeds(Z(tt))
        return (a1 - a0) / d, (b1 - b0) / d
    rates.step = d
    return rates


def _rounding(func, zs) -> float:
    """The rounding of ``func`` (vectorized over states in columns) at the sampled states
    zs (one a column): at each, its changes when each component moves by
    rules.RESOLVE_PROBE_ULPS ulps, summed and scaled to rules.RESOLVE_NOISE_ULPS (the
    state's rounding carried through the function, e.g. times 1/eps by a and b of a
    stiff slide); the smallest over the samples, so that no run of five is judged above
    another's rounding. 0 where not finite."""
    zs = np.asarray(zs, dtype=float)
    dim, n = zs.shape
    probes = np.repeat(zs[:, None, :], dim + 1, axis=1)   # (dim, dim + 1, n)
    idx = np.arange(dim)
    probes[idx, idx + 1, :] += rules.RESOLVE_PROBE_ULPS * np.finfo(float).eps * np.abs(zs)
    v = np.asarray(func(probes.reshape(dim, -1)), dtype=float).reshape(dim + 1, n)
    floor = (rules.RESOLVE_NOISE_ULPS / rules.RESOLVE_PROBE_ULPS) * float(
        np.abs(v[1:] - v[0]).sum(axis=0).min())
    return floor if np.isfinite(floor) else 0.0


def _in_section_rounding(func, s0, z0, zr) -> bool:
    """rules.on_section_by_value: the start's section value s0 within the section's own
    rounding, measured at the probes rules.section_probe places about z0 toward the
    crossing zr (no probes beyond its reach: False)."""
    probe = np.empty_like(z0)
    noise, s_2, s_1 = 0.0, 0.0, 0.0
    for j in range(-rules.SECTION_PROBES, rules.SECTION_PROBES + 1):
        if not rules.section_probe(z0, zr, j, probe):
            return False
        s = float(func(probe.copy()))
        if j >= 2 - rules.SECTION_PROBES:
            noise = rules.section_noise(noise, s_2, s_1, s)
        s_2, s_1 = s_1, s
    return rules.on_section_by_value(s0, noise)


def _finite_at(t, v):
    """v, a function's value at t, or ValueNotFinite where it is not finite."""
    if not math.isfinite(v):
        raise ValueNotFinite(t)
    return v


class _Scan:
    """One segment as :meth:`earliest` examines it: the values at the samples of the
    functions whose sign change leaves the mode (``leave``), of dH/dt (in a region) or
    of the rates of the sliding speeds a and b (sliding), and of the sections; the
    exit's band while in force. ``band``: the rounding band of the sliding exit the stay
    began at, while the orbit is inside it (rules.exit_band, rules.graze; ``leave`` then
    measures H from the band's edge, ``unbanded`` from the exit shift alone): it ends at
    the first sample interval examined whose start is out of the band (rules.clears_band),
    or at the last sample of a segment with no event."""

    def __init__(self, system, mode, Z, ts, zs, leave, sections, preds, first, touch_tol,
                 xtol, traj, band, unbanded):
        # the pieces never see a state that is not finite: the samples end before the
        # first such (the kernel's scan._sample tests the state first), and the window
        # is cut there (_cut; sample 0 is finite: _Run._samples)
        self.ts_all, finite = ts, np.all(np.isfinite(zs), axis=0)
        k_state = ts.size if finite.all() else int(np.argmin(finite))
        state_cut = None if k_state == ts.size else (k_state, ts[k_state], zs[:, k_state])
        ts, zs = ts[:k_state], zs[:, :k_state]
        self.system, self.mode, self.Z, self.ts, self.zs = system, mode, Z, ts, zs
        self.leave, self.sections, self.preds, self.first = leave, sections, preds, first
        self.touch_tol, self.xtol, self.traj = touch_tol, xtol, traj
        self.band, self.unbanded = band, unbanded
        self.order = None  # the candidate intervals still to ask (earliest, _unband)
        # the sections a start on which, up to rounding, is no hit, and the instant and
        # state of that start (_Run.start_sections)
        self.start_sections, self.start = None, (traj.t0, traj.z0)
        # the leave functions as sampled (raw) and as the search reads them (vals: h
        # sampled again unbiased once the band ends, _unband)
        self.raw = [np.asarray(func(zs), dtype=float) for func in leave]
        self.vals = list(self.raw)
        self.D = None
        if mode != SLIDING:  # dH/dt along the mode's field: extrema of H are its roots
            self.D = np.asarray(system.speed_of_switch(mode, zs), dtype=float)
        self.svals = [np.asarray(s.func(zs), dtype=float) for s in sections]
        self.rates = self.R = None
        if mode == SLIDING:  # the rates of a and b along the orbit: their extrema are roots (rules)
            self.rates = _speed_rates(system, Z, np.asarray(zs[:, 0], dtype=float),
                                      traj.scale.state)
            if self.rates is not None:
                self.R = self.rates(ts)
        self.not_finite = self._first_not_finite() or state_cut
        if self.not_finite is not None:
            self._cut(self.not_finite[0])

    def _first_not_finite(self):
        """(k, t, z): the first sample k where a sampled value is not finite, with the time
        and state where the piece gave it (the rates of a and b evaluate them a step
        ahead), or None. A NaN sample shows no sign change: a switch or a section hit
        there would be missed, not found (the kernel: scan._sample)."""
        sampled = self.raw + self.svals + ([self.D] if self.D is not None else [])
        ahead = len(sampled)
        sampled += list(self.R) if self.R is not None else []
        first = None
        for j, v in enumerate(sampled):
            if not math.isfinite(float(np.sum(v))) and not np.all(np.isfinite(v)):
                k = int(np.flatnonzero(~np.isfinite(v))[0])
                if first is None or k < first[0] or (k == first[0] and j < ahead):
                    t = self.ts[k] if j < ahead else self.ts[k] + self.rates.step
                    first = (k, t, self.zs[:, k] if j < ahead else self.Z(t))
        return first

    def _cut(self, k):
        """The samples before k only: an event among them stands (past an event the
        samples follow this mode's field, not the orbit); with none, :meth:`earliest`
        stops the run at sample k."""
        self.ts, self.zs = self.ts[:k], self.zs[:, :k]
        self.vals, self.raw = [v[:k] for v in self.vals], [v[:k] for v in self.raw]
        self.svals = [v[:k] for v in self.svals]
        self.D = None if self.D is None else self.D[:k]
        self.R = None if self.R is None else tuple(r[:k] for r in self.R)

    @property
    def cut_time(self):
        """The time of the sample the window is cut at (not finite)."""
        return self.ts_all[self.not_finite[0]]

    def _non_finite(self, t, z):
        z = np.asarray(z, dtype=float).reshape(-1)
        piece = checks.piece_not_finite_at(
            self.system, self.mode, z, [(f"section {s.name!r}", s.func) for s in self.sections])
        return run_error(NON_FINITE, t, z, f", mode {MODE_NAMES[self.mode]} "
                                           f"({piece or 'a piece'} returned a non-finite "
                                           "value there)")

    def resolved(self):
        """The samples resolve the leave functions and the sections (rules.resolves; the
        values as sampled, before the first one is clamped; h with its slopes dH/dt),
        above their rounding where 64 ulps of the samples fall short of it (measured at
        the samples only then: :func:`_rounding`; engines.py asymmetry 12)."""
        ts, n = self.ts, self.ts.size
        # cut at a sample not finite: with too few kept to judge, shorter windows up to it
        if self.not_finite is not None and not rules.cut_resolves(n, self.ts_all.size):
            return False
        if self.mode == SLIDING:
            judged = [(v, v, False, func) for v, func in zip(self.raw, self.leave)]
        else:
            judged = [(self.raw[0], self.D, True, self.leave[0])]
        judged += [(v, v, False, s.func) for v, s in zip(self.svals, self.sections)]
        for v, d, slopes, func in judged:
            if (not rules.resolves(v, d, ts, n, slopes, 0.0)
                    and not rules.resolves(v, d, ts, n, slopes, _rounding(func, self.zs))):
                return False
        return True

    def _along(self, func):
        """``func`` of the state as a function of time on the segment; a value not finite
        raises ValueNotFinite, which the search's operations turn into NaN (the loop then
        searches up to it as past a sample not finite: :meth:`earliest`)."""
        Z = self.Z

        def along(tt):
            return _finite_at(tt, float(func(Z(tt))))
        return along

    @functools.cached_property
    def _dH(self):
        """dH/dt along the segment, a function of time (built once: Brent calls it)."""
        return self._along(lambda z: self.system.speed_of_switch(self.mode, z))

    def candidates(self):
        """Sample intervals that may hold an event (loop.interval.candidate_mask, array
        operations); only those are examined one by one (a scan of many samples costs a
        few numpy calls)."""
        rates = [self.D] if self.mode != SLIDING else self.R
        return interval.candidate_mask(self.mode, self.vals, rates,
                                       list(zip(self.preds, self.svals)), self.first)

    def earliest(self):
        """(t, z, what, section index) of the earliest event in the segment, or None; and
        the band still in force after it. Past a sample that is not finite, the interval
        up to it is searched in sub-windows (:meth:`_past_cut`)."""
        if self.not_finite is not None and self.ts.size < 1:
            raise self._stop(*self.not_finite[1:], None)
        (found, cut), scan = self._search(), self
        if cut is not None:  # a value between samples i and i + 1 not finite, at t
            i, t = cut
            found, scan = self._past_cut(self.ts[i], t, (i, t, self.Z(t)),
                                         self.first and i == 0)
        elif found is None and self.not_finite is not None:
            found, scan = self._past_cut(self.ts[-1], self.cut_time, self.not_finite,
                                         self.first and self.ts.size == 1)
        if found is None:
            return None, scan.band
        r, what, k = found
        return (r, np.asarray(self.Z(r), dtype=float).reshape(-1).copy(), what, k), scan.band

    def _search(self):
        """((t, what, section index) of the earliest event on the samples, or None;
        None, or (i, t) where a value asked between samples i and i + 1 was not finite
        at t: the search ends there, loop.interval's CUT)."""
        if self.ts.size < 2:
            return None, None
        self.cand = self.candidates()
        st, r, what, k = _window_event(self, self.mode)
        if st == CUT:
            return None, (k, r)
        if st != OK:  # (its root finder raises instead: _Run._scan names the failure)
            raise ValueError(f"the event search ended with status {st}")
        return (None if what == interval.NONE else (r, what, k)), None

    def _past_cut(self, lo, hi, not_finite, first):
        """The interval [lo, hi] before the first sample, or value between samples, that
        was not finite (``not_finite``: (k, t, z) as :meth:`_first_not_finite`'s), with
        no event up to lo: sub-windows [lo, mid] sampled as this window was, the bracket
        halved (rules.cut_midpoint) to the field's edge; an event before it stands, else
        the run stops at the last one found not finite
        (docs/decisions.md#past-a-non-finite-sample; the kernel's driver._past_cut).
        ``first``: lo is the stay's first sample. (event or None, the last scan: its
        band)."""
        scan = self
        frac = np.linspace(0.0, 1.0, self.ts_all.size)   # as _Run sampled the window
        # the stay's first sample, while lo stays there: clamped as it is there
        t_first = lo if first else -np.inf
        mid = rules.cut_midpoint(lo, hi, self.xtol)
        while mid == mid:
            ts = lo + frac * (mid - lo)
            ts[-1] = mid
            scan = _Scan(self.system, self.mode, self.Z, ts, self.Z(ts), scan.leave,
                         self.sections, self.preds, lo == t_first, self.touch_tol,
                         self.xtol, self.traj, scan.band, self.unbanded)
            scan.start_sections, scan.start = self.start_sections, self.start
            if scan.not_finite is not None and scan.not_finite[0] == 0:
                not_finite = scan.not_finite   # lo's own sample: the edge is there
                break
            found, cut = scan._search()
            if cut is not None:  # a value between the sub-window's samples, not finite
                i, t = cut
                not_finite, lo, hi = (i, t, self.Z(t)), scan.ts[i], t
            elif found is not None:
                return found, scan
            elif scan.not_finite is None:
                lo = mid
            else:
                not_finite = scan.not_finite
                lo, hi = scan.ts[-1], scan.cut_time
            mid = rules.cut_midpoint(lo, hi, self.xtol)
        raise self._stop(*not_finite[1:], lo)

    def _stop(self, t, z, lo):
        """The run's end past the last finite sample lo (None: none): where a piece's
        value was not finite (t, z), or at lo where the state itself was not."""
        if np.all(np.isfinite(z)) or lo is None:
            return self._non_finite(t, z)
        return run_error(NON_FINITE, lo, self.Z(lo), f", mode {MODE_NAMES[self.mode]}: the "
                         f"state turns non-finite after t={float(lo)!r}, within the event tolerance "
                         "(the state given: the last finite one)")

    # -------------------------------------------- the event search's operations on it
    # The walk over the window's intervals, the questions of each and every decision
    # among them are the one event search (filippov.loop.interval, _window_event below);
    # these methods report this engine's samples and the values of its functions on its
    # dense output Z, each function by the loop's code (F_*). Its failures raise, so each
    # returns the status OK.

    def _window(self):
        t0 = self.traj.t0
        return interval.Window(self.ts.size - 1, self.first, self.band, self.rates is not None,
                               self.touch_tol, self.xtol, self.preds,
                               tuple(t0 + sec.min_time for sec in self.sections), self.cand)

    def _sampled(self, f, i):
        if f == interval.F_TIME:
            return self.ts[i]
        if f >= interval.F_SECTION:
            return self.svals[f - interval.F_SECTION][i]
        if f >= interval.F_RATE:
            if self.mode != SLIDING:
                return self.D[i]
            return math.nan if self.R is None else self.R[f - interval.F_RATE][i]
        return self.vals[f][i]

    def _function(self, f):
        """Function f (the loop's code) of time on the segment."""
        if f >= interval.F_SECTION:
            return self._along(self.sections[f - interval.F_SECTION].func)
        if f == interval.F_UNBANDED:
            return self._along(self.unbanded[0])
        if f >= interval.F_RATE:
            if self.mode != SLIDING:
                return self._dH
            q = f - interval.F_RATE
            return lambda tt: _finite_at(tt, float(self.rates(tt)[q]))
        return self._along(self.leave[f])

    def _value(self, f, t, mode):
        try:
            return self._function(f)(t)
        except ValueNotFinite:
            return math.nan

    def _root(self, f, lo, hi, vlo, vhi, mode):
        return _root(self.xtol, self._function(f), lo, hi, vlo, vhi)

    def _counts(self, k, i, r, mode):
        """The crossing of section k at r is a hit: ``where`` holds there, and it is not
        a start on the section up to rounding (the run's, or a stay's that goes on from
        a hit of k)."""
        sec, zr = self.sections[k], self.Z(r)
        if sec.where is not None and not sec.where(zr):
            return False
        starts = self.start_sections  # None: every section (the run's own start)
        return not (i == 0 and self.ts[i] == self.start[0] and (starts is None or k in starts)
                    and self._starts_on(sec, self.svals[k], zr))

    def _touch(self, tm, mode):
        """A touch of H at tm: no event for the orbit, a kink of P (recorded)."""
        self.traj.events.append(Event(tm, "touch", self.Z(tm).copy(), mode, mode))

    def _unband(self, i, mode):
        """Out of the exit's rounding band at ts[i] (at the last sample when i is
        ts.size: no interval left): H unbiased from there on, so a return across H is
        refined at H = 0 (as in the compiled engine). The candidate intervals from i on,
        again."""
        self.band, self.leave = 0.0, self.unbanded
        self.vals[0] = np.asarray(self.leave[0](self.zs), dtype=float)
        self.cand = self.candidates()  # a band is in force in a region only: h, dH/dt,
        self.cand[:i] = False          # sections

    def _starts_on(self, sec, sv, zr) -> bool:
        """The start on the section, up to its rounding (rules.starts_on_section,
        rules.on_section_by_value): no hit."""
        z_first = np.asarray(self.zs[:, 0], dtype=float)
        z_root = np.asarray(zr, dtype=float).reshape(-1)
        return (rules.starts_on_section(float(sv[0]), z_first, float(sec.func(zr)), z_root,
                                        np.asarray(self.start[1], dtype=float).reshape(-1),
                                        self.traj.scale.state)
                or _in_section_rounding(sec.func, float(sv[0]), z_first, z_root))


#: what this engine reports of a window to the event search (the window seam:
#: filippov.contracts.WindowOperations), and that one search (filippov.loop.interval)
WINDOW_OPERATIONS = interval.WindowOps(
    _Scan._window, _Scan._sampled, _Scan._value, _Scan._root, _Scan._counts, _Scan._touch,
    _Scan._unband)
_window_event = interval.make_window_event(WINDOW_OPERATIONS)

# the event search and what is done at an event speak the same codes
assert interval.SECTION == SECTION and interval.OK == OK
