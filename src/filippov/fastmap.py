"""A compiled (numba) fast path for first returns of a piecewise system to a section.

:func:`filippov.poincare.first_returns` runs the event-driven driver of
:mod:`filippov.simulate` once per start point, in Python. This module runs the
same algorithm for a whole batch of start points inside one compiled call:

* regions ``+`` (``h >= 0``) and ``-`` are followed with the model's exact
  flows in the reference driver's windows: ``16 sample_step`` from each mode entry
  (``16 slow_sample_step`` once ``transient_time`` has passed since the entry; the
  next return of an iterated run carries its time in the region on, a section hit
  being no entry), the flow taken from the state at the stay's start (the mode entry,
  or the start point). Each window is cut into
  16 intervals: one sample per sample step, the spacing the model declares to
  resolve its events (the reference driver samples ``samples_per_step`` times
  denser, since its samples are also the stored trajectory; the two agree to
  rounding, not bit for bit); a model without exact flows
  (``CompiledModel.exact = False``) has them integrated like sliding, below
  (the reference driver's ``method="integrate"``);
* the samples are scanned for the same events: ``h`` leaving the region, a
  hidden grazing crossing (a sign change of ``dh/dt`` whose extremum of ``h``
  goes through zero; ``|h| <= touch_tol`` there is a touch, not a switch), the
  section (direction and ``where`` condition; a section root at the instant of
  a switch is the return, a start on the section up to rounding is not, as for
  :class:`filippov.simulate.Section`); roots are refined with a port of scipy's
  ``brentq`` (same tolerances) and then stepped to the far side of the crossing;
* at ``h = 0`` the Filippov decision uses ``a = grad h . F_-`` and
  ``b = grad h . F_+`` exactly as the reference driver (:mod:`filippov.loop.event`);
* sliding is integrated with a port of scipy's ``DOP853`` (same coefficients,
  step-size control, initial step and 7th-order dense output) with the Filippov
  field ``(a F_+ - b F_-)/(a - b)``; it ends where ``a`` or ``b`` reaches zero,
  at the samples or between them (a minimum of ``a`` or maximum of ``b`` found
  from their rates along the orbit, as a hidden extremum of ``h``:
  ``rules.speed_graze``; a touch there is no exit). Each integrated step is
  sampled at ``samples_per_step + 1`` points of its dense output.

Failures never raise inside the compiled code and never hang: each start point
gets a status code (:data:`STATUS`) -- event or step bound hit, accumulation of
switches (Zeno), non-finite state, an exact flow that does not follow its field
(``rules.flow_consistent``, as the reference driver), no return within ``t_max``,
...; the front door :func:`filippov.first_returns` (``engine="compiled"``) turns a failure into the same
exception types as the reference driver.

The kernel itself lives in :mod:`filippov.kernel`, split along its seams (shared
codes and rules, DOP853, segments, root finding, event scan, dP/dz, driver loop);
this module is its Python side: the batch call, its options and its errors.

A model enters as a :class:`CompiledModel`: numba-compiled pieces with the
signatures below (passed to the kernel as their compiled addresses, so the kernel
is compiled once -- about 13 s on 2 cores, 10 s more for its build with the dP/dz code
-- cached on disk by numba, and serves every model), plus a parameter vector ``params`` handed to every piece. See
:func:`filippov.models.hopf.compiled`.

A start point that begins in sliding has that first sliding stretch counted in
``sliding_time``, as the reference's :func:`filippov.poincare.sliding_time` does. Touches are not recorded (they change nothing in a return).
Every difference between the engines, with its reason and its test:
:mod:`filippov.engines`.
"""
from __future__ import annotations

import functools
import inspect
import os
import weakref
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from . import frozen, options, rules, views
from . import scale as scale_mod
from .scale import UNIT
# what a model hands the engine (its pieces' signatures, CompiledModel), re-exported here
from .abi import (FIELD_SIG, FLOW_SIG, PIECES, SCALAR_SIG, WHERE_SIG,  # noqa: F401
                  CompiledModel, no_flow, no_jacobian)
# the kernel (filippov.kernel) and its status codes, re-exported here
from .kernel.base import (BAD_START, EVENT_LIMIT, FLOW_OFF_FIELD, NO_RETURN,  # noqa: F401
                          NO_SLIDING, NON_FINITE, OK, ROOT_FAILED, SECTION_SLIDING, STATUS, STEP_FAILED,
                          STEP_LIMIT, ZENO)
from .kernel.driver import KERNEL_SOURCES, compile_kernel, kernel  # noqa: F401
from .kernel.state import Outputs, Settings
from .checks import check_compiled
from .errors import accumulation_detail, run_error
from .system import MINUS, MODE_NAMES, PLUS
from .section import Returns
from .progress import Progress
from .simulate import (EXACT_BLOCK, EventLimitError, SimulationError,  # noqa: F401
                       SlidingNotBuiltError, ZenoError, slow_window)

@dataclass(frozen=True)
class BatchReturns:
    """Raw kernel output: ``status[i] == OK`` where start ``i`` returned; elsewhere
    ``state``/``time`` are where the run stopped (see :data:`STATUS`)."""

    state: np.ndarray
    time: np.ndarray
    n_switches: np.ndarray
    sliding_time: np.ndarray
    status: np.ndarray
    first_switch: np.ndarray  # time of the first change of mode (NaN: none)
    sliding_displacement: np.ndarray = None  # (m, dim): state change summed over sliding
    orbit: np.ndarray = None  # (m, keep, dim): the last ``keep`` of ``iterations`` returns
    returns_done: np.ndarray = None  # (m,): returns completed (== iterations: all made)
    #: (m, dim, dim): dP/dz of the last return made (``jacobian=True``; NaN: failed, or
    #: not differentiable -- a tangential switch or hit, a touch of H, a start that slides)
    jacobian: np.ndarray = None
    #: (m, keep, dim, dim): dP/dz of the return that produced each ``orbit`` row
    orbit_jacobian: np.ndarray = None
    #: (m,): time the orbit had spent in the region of its last return point when it
    #: returned (0 if sliding there); ``start_age`` of the next return continues the
    #: orbit as an iterated run does, bit for bit
    age: np.ndarray = None
    #: (m,): the mode at the return, or the one the run stopped in (MINUS, SLIDING, PLUS)
    mode: np.ndarray = None
    #: (m, 2): where a run stopped ZENO because its switches shrink geometrically, their
    #: ratio per loop (two switches) and the accumulation time the series sums to
    #: (:func:`filippov.rules.geometric_accumulation`); NaN elsewhere
    accumulation: np.ndarray = None


def _section_pred(direction: int) -> int:
    return rules.section_pred(direction)


def _checked_starts(cmodel: CompiledModel, starts, start_age):
    """(starts (m, n), ages (m,)) as the kernel takes them, or the error naming them."""
    starts = np.ascontiguousarray(np.atleast_2d(np.asarray(starts, dtype=float)))
    if starts.ndim != 2 or starts.shape[1] != cmodel.dim:
        raise ValueError(f"start points must have shape (m, {cmodel.dim}) "
                         f"({', '.join(cmodel.names)}), got {starts.shape}")
    if not np.all(np.isfinite(starts)):
        raise ValueError("start points must be finite")
    try:
        ages = np.array(np.broadcast_to(np.asarray(start_age, dtype=float),
                                        (starts.shape[0],)))  # a writable copy
    except ValueError:
        ages = np.array([np.nan])
    if not np.all(np.isfinite(ages) & (ages >= 0)):
        raise ValueError(f"start_age must be finite and >= 0, a scalar or one per start "
                         f"point ({starts.shape[0]}), got {np.asarray(start_age).tolist()}")
    return starts, ages


#: each piece's compiled address, looked up once per piece (the entry goes with the piece)
_ADDRESSES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def _address(piece, name: str, sig) -> int:
    """The address of ``piece``'s compiled code for ``sig`` (numba's own lookup when it
    hands a compiled function to another as a first-class function), memoized: the
    kernel is handed addresses (kernel.base._PIECE_ADDRS), so that a call costs no
    lookup. The memo holds the compiled code it points into (alive while ``piece``
    lives) and is looked up again if that code is no longer one of the piece's (a
    recompile)."""
    known = _ADDRESSES.setdefault(piece, {})
    cres, addr = known.get(name, (None, 0))
    # dict's own view of numba's OrderedDict: the ordered view looks each key up again,
    # and hashing numba's types cost most of a one-return call (fig12's periodic orbits
    # make 72,000 such calls); membership tests identity first
    if cres is not None and cres in dict.values(piece.overloads):
        return addr
    if not (hasattr(piece, "py_func") and tuple(sig.args) in getattr(piece, "signatures", ())):
        raise TypeError(
            f"CompiledModel.{name}: expected a numba njit function compiled with the "
            f"signature {sig} (filippov.abi; compile_system and SymbolicSystem build "
            f"them), got {piece!r}")
    cres = piece.get_compile_result(sig)
    addr = cres.library.get_pointer_to_function(cres.fndesc.llvm_func_name)
    if not (isinstance(addr, int) and addr > 0):
        raise RuntimeError(f"no compiled address for {piece!r} with {sig}")
    known[name] = (cres, addr)
    return addr


def _pieces(cmodel: CompiledModel) -> tuple:
    """The compiled addresses of the model's pieces in the kernel's order
    (filippov.abi.PIECES), each piece a numba-compiled function with its signature: the
    kernel calls them at their address (kernel.base._piece), which anything else lacks.
    A model without Jacobians hands :func:`no_jacobian`, one without flow Jacobians
    :func:`no_flow` (neither is called)."""
    pieces = []
    for name, sig in PIECES:
        piece = getattr(cmodel, name)
        if name == "jacobian" and piece is None:
            piece = no_jacobian
        elif name.startswith("flow_jacobian_") and piece is None:
            piece = no_flow
        pieces.append(_address(piece, name, sig))
    return tuple(pieces)


def _check_options(cmodel, t_max, iterations, keep, min_time) -> None:
    """compute_returns' own options (the shared ones: filippov.options), each refused
    with its name where out of range."""
    if not (options.finite(t_max) and t_max >= 0):
        raise ValueError(f"need a finite t_max >= 0, got {t_max!r}")
    if not (isinstance(iterations, (int, np.integer)) and iterations >= 1):
        raise ValueError(f"iterations must be an integer >= 1, got {iterations!r}")
    if not (isinstance(keep, (int, np.integer)) and 0 <= keep <= iterations):
        raise ValueError(f"keep must be an integer in [0, iterations={iterations}], got {keep!r}")
    if not (options.finite(min_time) and min_time >= 0):
        raise ValueError(f"min_time must be a finite number >= 0, got {min_time!r}")
    if (cmodel.flow_jacobian_plus is None) != (cmodel.flow_jacobian_minus is None):
        raise ValueError("flow_jacobian_plus, flow_jacobian_minus: give both flow "
                         "Jacobians or neither")
    if cmodel.exact and not (options.finite(cmodel.sample_step) and cmodel.sample_step > 0):
        raise ValueError(f"the compiled model needs a finite sample_step > 0, "
                         f"got {cmodel.sample_step!r}")


#: the environment variable that caps the default number of workers (the workflow's
#: scripts set it to their rule's ``threads:``, so that jobs side by side do not
#: oversubscribe the cores)
WORKERS_ENV = "FILIPPOV_WORKERS"
#: returns (starts x iterations) a slice of a batch must hold at least: each call of the
#: kernel costs some Python (unboxing its arguments, GIL held; ~0.3 ms when the model's
#: nine pieces were handed over as first-class functions, less since they are addresses)
MIN_RETURNS_PER_SLICE = 256
#: slices per worker: starts differ in cost (a sliding return, a failure), so a large
#: batch is cut finer than one slice per thread and a thread takes the next slice when done
SLICES_PER_WORKER = 4


def default_workers() -> int:
    """Threads a batch may use when ``workers`` is not given: ``FILIPPOV_WORKERS`` if set
    (an integer >= 1), else the cores this process may run on."""
    value = os.environ.get(WORKERS_ENV, "").strip()
    if value:
        try:
            n = int(value)
        except ValueError:
            n = 0
        if n < 1:
            raise ValueError(f"{WORKERS_ENV} must be an integer >= 1, got {value!r}")
        return n
    try:
        return len(os.sched_getaffinity(0))  # what a cgroup, taskset or SLURM allows
    except AttributeError:  # not on every platform
        return os.cpu_count() or 1


def _checked_workers(workers) -> int:
    if workers is None:
        return default_workers()
    if not (isinstance(workers, (int, np.integer)) and not isinstance(workers, bool)
            and workers >= 1):
        raise ValueError(f"workers must be an integer >= 1 or None (the default: "
                         f"{WORKERS_ENV} or the cores available), got {workers!r}")
    return int(workers)


def _slices(m: int, iterations: int, workers: int) -> list:
    """Contiguous [lo, hi) slices of a batch of m starts, iterated ``iterations`` times,
    for ``workers`` threads: up to SLICES_PER_WORKER a worker, each of at least
    MIN_RETURNS_PER_SLICE returns and 2 starts (one slice: the calling thread runs it)."""
    count = min(workers * SLICES_PER_WORKER, m * iterations // MIN_RETURNS_PER_SLICE, m // 2)
    if workers <= 1 or count <= 1:
        return [(0, m)]
    bounds = np.linspace(0, m, count + 1).round().astype(int)
    return [(int(lo), int(hi)) for lo, hi in zip(bounds[:-1], bounds[1:])]


def _run_batch(batch, pieces, params, starts, ages, settings, out, workers: int) -> None:
    """The kernel over the whole batch, cut into contiguous slices run on ``workers``
    threads (the kernel releases the GIL). Each start is computed by the same compiled
    code from its own row whichever slice holds it, so the outputs do not depend on
    ``workers``, bit for bit (tests/test_parallel.py)."""
    slices = _slices(starts.shape[0], settings.iterations, workers)
    if len(slices) == 1:
        batch(pieces, params, starts, ages, settings, out)
        return

    def run(lo_hi):  # views of the rows lo:hi: C-contiguous, as the kernel's signature
        lo, hi = lo_hi
        batch(pieces, params[lo:hi] if params.shape[0] > 1 else params, starts[lo:hi],
              ages[lo:hi], settings, Outputs(*(a[lo:hi] for a in out)))

    with ThreadPoolExecutor(max_workers=min(workers, len(slices))) as pool:
        for _ in pool.map(run, slices):
            pass  # the kernel raises nothing itself; map re-raises what a thread did


@functools.lru_cache(maxsize=32)
def _fractions(n: int) -> np.ndarray:
    """The n + 1 sample points of a step as fractions of it, made once for each n: the
    kernel only reads them (one array for every call; linspace costs 15 us a call)."""
    return np.linspace(0.0, 1.0, n + 1)


def _settings(cmodel: CompiledModel, t_max, *, rtol, atol, max_step, max_events, max_steps,
              samples_per_step, touch_tol, event_xtol, zeno_count, zeno_span, min_time,
              iterations, jacobian, scale=UNIT) -> Settings:
    """The kernel's settings of one :func:`compute_returns` call (its options already
    checked there)."""
    hwin = min(EXACT_BLOCK * cmodel.sample_step, max_step, t_max) if cmodel.exact else np.inf
    hwin_slow = slow_window(cmodel.slow_sample_step, hwin, max_step, t_max)
    # an exact flow: one sample per sample step (the model's declared resolution);
    # samples_per_step is for integration steps, whose length error control sets
    frac_ex = _fractions(EXACT_BLOCK)
    frac_in = _fractions(samples_per_step)
    # dP/dz: 0 none, 1 Jacobian-vector products by differences, 2 the model's Jacobians
    jac_mode = (2 if cmodel.jacobian is not None else 1) if jacobian else 0
    # an exact stay's dP/dz: the model's flow Jacobians, else Richardson (kernel.derivative)
    flow_jac = bool(jacobian and cmodel.exact and cmodel.flow_jacobian_plus is not None)
    # the kernel's ABI (abi.PIECES; kernel.state: Settings, Outputs, declared there with
    # their numba types, from which the kernel's one signature is built: Python floats,
    # ints and bools as such)
    return Settings(
        t_max=float(t_max), exact=bool(cmodel.exact), hwin=float(hwin),
        hwin_slow=float(hwin_slow), transient=float(cmodel.transient_time),
        sec_pred=int(_section_pred(cmodel.section_direction)), sliding=bool(cmodel.sliding),
        frac_ex=frac_ex, frac_in=frac_in, rtol=float(rtol),
        # atol per component (filippov.scale: each component's scale), one number or n
        atol=np.array(np.broadcast_to(np.asarray(atol, dtype=float), (len(cmodel.names),))),
        touch_tol=float(touch_tol), xtol=float(event_xtol), zeno_span=float(zeno_span),
        max_step=float(max_step), min_time=float(min_time), max_events=int(max_events),
        max_steps=int(max_steps), zeno_count=int(zeno_count), jac=jac_mode, flow_jac=flow_jac,
        iterations=int(iterations), state_scale=float(scale.state),
        time_scale=float(scale.time), scales=scale.of_components(len(cmodel.names)))


def _outputs(starts, keep: int, jacobian: bool) -> Outputs:
    """The kernel's output arrays for the batch ``starts`` (orbit rows NaN until filled)."""
    m, n = starts.shape
    return Outputs(state=np.empty_like(starts), time=np.empty(m),
                     n_switches=np.empty(m, dtype=np.int64), sliding_time=np.empty(m),
                     status=np.empty(m, dtype=np.int64), first_switch=np.empty(m),
                     sliding_displacement=np.empty_like(starts),
                     orbit=np.full((m, keep, n), np.nan),
                     returns_done=np.empty(m, dtype=np.int64), jacobian=np.empty((m, n, n)),
                     orbit_jacobian=np.full((m, keep if jacobian else 0, n, n), np.nan),
                     age=np.empty(m), mode=np.empty(m, dtype=np.int64),
                     accumulation=np.empty((m, 2)))


def compute_returns(cmodel: CompiledModel, starts, t_max: float, *, rtol: float = 1e-12,
                    atol: float = 1e-14, max_step: float = np.inf, max_events: int = 100_000,
                    max_steps: int = 5_000_000, samples_per_step: int = 4,
                    touch_tol: float = 1e-15, event_xtol: float = 1e-15, zeno_count: int = 64,
                    zeno_span: float = 1e-10, min_time: float = 0.0, iterations: int = 1,
                    keep: int = 0, jacobian: bool = False, start_age=0.0,
                    workers: int | None = None, scale=None) -> BatchReturns:
    """First returns of ``starts`` (``(m, dim)``) to the model's section, one compiled call.

    Options mean what they mean for :func:`filippov.simulate.simulate`, except that
    ``samples_per_step`` counts samples per integration step only: exact flows are
    scanned once per ``cmodel.sample_step`` (``slow_sample_step`` after the
    transient), the resolution the model declares; ``min_time``
    that of :class:`filippov.simulate.Section` (hits before it are ignored; a start
    on the section up to rounding is not a hit either way). Nothing is raised for a
    start point that fails: see ``status``.

    ``iterations`` > 1 iterates the return map: each return starts from the state
    of the one before (``t_max`` and the limits hold per return); the outputs then
    describe the last return made, or the one that failed, ``returns_done[i]``
    counts the returns completed and ``orbit[i]`` holds the last ``keep`` of them
    (rows of a start that stopped early stay NaN).

    A section hit is no mode entry: the next return of an iterated run goes on in the
    exact-flow windows of the time already spent in its region (its fast transient has
    decayed; ``rules.carried_age``). ``start_age`` (scalar or (m,)) says the same of the
    start points -- the ``age`` a previous return reported; the default 0 treats each
    start as just entered (windows on the fast time scale first).

    ``jacobian=True`` also returns the derivative dP/dz of each return
    (``BatchReturns.jacobian``, and ``orbit_jacobian`` for the kept returns), carried
    along the orbit: closed-form flows differentiated by central differences,
    integrated stays (sliding) by the variational equation through the same steps,
    each switch by its saltation matrix, the hit by the projection onto the section.
    It agrees with :func:`filippov.variational.return_jacobian` and with finite
    differences of P (tests/test_return_jacobian.py). It costs little on exact flows
    and about 7 field evaluations per one on integrated stays (benchmark:
    ``filippov_paper.benchmarks.attractor_cost``). NaN where P is not
    differentiable: a switch or section met tangentially, an orbit that touches H
    (``touch_tol``: the kink of P at grazing), a start that slides.

    ``workers`` threads share the start points (contiguous slices of the batch; each
    start's return, iterations included, is computed on one thread): the results are
    the same bit for bit for any number. None: :func:`default_workers` (the
    environment variable ``FILIPPOV_WORKERS``, else the cores available). A batch of
    few returns (starts x iterations, :data:`MIN_RETURNS_PER_SLICE` a slice) uses
    fewer threads, down to the calling thread alone.

    Units as :func:`filippov.simulate.simulate`'s (:mod:`filippov.scale`): ``scale``
    (None: the model's, declared or measured) holds for the whole batch, its open parts
    measured at the smallest and the largest start (the smaller of the two:
    :func:`filippov.scale.of_batch`). Explicit ``atol``, ``touch_tol`` and
    ``event_xtol`` are in units of that scale's S, G and T.
    """
    starts, ages = _checked_starts(cmodel, starts, start_age)
    frozen.check(cmodel.frozen_reads)   # no piece run with a value changed since compiled
    # the pieces checked before anything calls them: check_compiled's Python call would
    # compile a lazy njit piece (one the kernel cannot call at an address) on the spot
    pieces = _pieces(cmodel)
    scale = batch_scale(cmodel, starts, scale)
    if starts.shape[0]:   # the reference driver's start check, once a model
        check_compiled(cmodel, starts[0], floor=scale.state,
                       scales=scale.of_components(starts.shape[1]))
    params = np.ascontiguousarray(np.atleast_2d(np.asarray(cmodel.params, dtype=float)))
    return _returns(cmodel, pieces, params, starts, ages, t_max, rtol=rtol, atol=atol,
                    max_step=max_step, max_events=max_events, max_steps=max_steps,
                    samples_per_step=samples_per_step, touch_tol=touch_tol,
                    event_xtol=event_xtol, zeno_count=zeno_count, zeno_span=zeno_span,
                    min_time=min_time, iterations=iterations, keep=keep, jacobian=jacobian,
                    workers=workers, scale=scale)


#: what the models of one sweep must share (all but their parameter values): the pieces
#: (the same compiled functions), the section's direction and the settings they set
SWEEP_SHARED = ("names", "flow_plus", "flow_minus", "field_plus", "field_minus", "switch",
                "switch_grad", "section", "section_where", "jacobian", "section_direction",
                "sample_step", "sliding", "exact", "slow_sample_step", "transient_time",
                "scale")


def _same(a, b) -> bool:
    if callable(a) or callable(b) or a is None or b is None:
        return a is b  # a piece: the same compiled function
    if isinstance(a, float) and isinstance(b, float) and np.isnan(a) and np.isnan(b):
        return True
    return a == b


def _sweep_params(cmodels) -> np.ndarray:
    """The models' parameters, one row a model, once every model was checked to differ
    from the first in its parameter values only (else the error naming the field)."""
    cmodels = list(cmodels)
    if not cmodels or not all(isinstance(c, CompiledModel) for c in cmodels):
        raise TypeError("cmodels must be a non-empty sequence of CompiledModel, one per "
                        "start point")
    first = cmodels[0]
    k = np.asarray(first.params).size
    for i, c in enumerate(cmodels[1:], start=1):
        for name in SWEEP_SHARED:
            if not _same(getattr(c, name), getattr(first, name)):
                raise ValueError(
                    f"cmodels[{i}].{name} = {getattr(c, name)!r} differs from cmodels[0]."
                    f"{name} = {getattr(first, name)!r}: the models of one sweep may differ "
                    "in their parameter values only (group the points by what else they "
                    "change and sweep each group)")
        if np.asarray(c.params).size != k:
            raise ValueError(f"cmodels[{i}].params has {np.asarray(c.params).size} values, "
                             f"cmodels[0].params {k}")
    params = np.array([np.asarray(c.params, dtype=float).reshape(-1) for c in cmodels])
    if k == 0:  # a model without parameters: the kernel still takes a (1, 0) row
        params = np.zeros((1, 0))
    return np.ascontiguousarray(params)


def sweep_returns(cmodels, starts, t_max: float, *, start_age=0.0, workers=None,
                  **options) -> BatchReturns:
    """:func:`compute_returns` of start i under model ``cmodels[i]``: a parameter sweep in
    one compiled call. The models must be one model at different parameter values (the
    same pieces, section and sampling: :data:`SWEEP_SHARED`), as a model's constructor
    builds them (its checks of the parameters apply); each start's returns are those of
    :func:`compute_returns` with its own model, bit for bit, whatever ``workers`` (where
    the scale is measured, filippov.scale, once for the sweep, at its smallest and its
    largest start, each with its own model: give ``scale=`` to both to compare them).
    ``options`` as there."""
    params = _sweep_params(cmodels)
    cmodels = list(cmodels)
    first = cmodels[0]
    starts, ages = _checked_starts(first, starts, start_age)
    if starts.shape[0] != len(cmodels):
        raise ValueError(f"starts: one start point per model, got {starts.shape[0]} starts "
                         f"for {len(cmodels)} cmodels")
    frozen.check(first.frozen_reads)   # the models share their pieces (_sweep_params)
    pieces = _pieces(first)  # before check_compiled calls them (see compute_returns)
    scale = batch_scale(cmodels, starts, options.pop("scale", None))
    for i, c in enumerate(cmodels):  # once a model object (checks.check_compiled)
        check_compiled(c, starts[i], floor=scale.state,
                       scales=scale.of_components(starts.shape[1]))
    defaults = {name: par.default for name, par in
                inspect.signature(compute_returns).parameters.items()
                if par.kind is par.KEYWORD_ONLY and name not in ("start_age", "workers")}
    unknown = set(options) - set(defaults)
    if unknown:
        raise TypeError(f"sweep_returns() got unexpected options {sorted(unknown)}")
    return _returns(first, pieces, params, starts, ages, t_max, workers=workers,
                    **{**defaults, **options, "scale": scale})


def _returns(cmodel: CompiledModel, pieces, params, starts, ages, t_max, *, rtol, atol,
             max_step, max_events, max_steps, samples_per_step, touch_tol, event_xtol,
             zeno_count, zeno_span, min_time, iterations, keep, jacobian,
             workers, scale) -> BatchReturns:
    """compute_returns and sweep_returns after their own checks of the starts: the
    options checked, one kernel call over the batch (``pieces``: the model's addresses,
    :func:`_pieces`; ``params``: one row for all the starts, or one row a start;
    ``scale``: the batch's, resolved by the caller, :func:`batch_scale`)."""
    workers = _checked_workers(workers)
    options.check(rtol=rtol, atol=atol, max_step=max_step, max_events=max_events,
                  max_steps=max_steps, samples_per_step=samples_per_step, touch_tol=touch_tol,
                  event_xtol=event_xtol, zeno_count=zeno_count, zeno_span=zeno_span,
                  jacobian=jacobian)
    _check_options(cmodel, t_max, iterations, keep, min_time)
    settings = _settings(cmodel, t_max, rtol=rtol,
                         atol=atol * scale.of_components(starts.shape[1]), max_step=max_step,
                         max_events=max_events, max_steps=max_steps,
                         samples_per_step=samples_per_step, touch_tol=touch_tol * scale.switch,
                         event_xtol=event_xtol * scale.time, zeno_count=zeno_count,
                         zeno_span=zeno_span, min_time=min_time, iterations=iterations,
                         jacobian=jacobian, scale=scale)
    out = _outputs(starts, keep, jacobian)
    # the build without the dP/dz code unless it is asked for (kernel.driver)
    _run_batch(kernel(derivatives=bool(jacobian)), pieces, params, starts, ages, settings,
               out, workers)
    return BatchReturns(**dict(out._asdict(), jacobian=out.jacobian if jacobian else None,
                               orbit_jacobian=out.orbit_jacobian if jacobian else None))


def batch_scale(cmodels, starts, value=None):
    """The units of a batch (filippov.scale.of_batch): ``value``, else the model's
    declaration, the parts left open measured at the smallest and the largest start
    (``cmodels``: one model, or one per start -- a sweep -- each start measured with
    its own)."""
    def pieces(i):
        pc = _Pieces(cmodels[i] if isinstance(cmodels, (list, tuple)) else cmodels)
        return pc.field_minus, pc.field_plus, pc.switch_grad
    first = cmodels[0] if isinstance(cmodels, (list, tuple)) else cmodels
    return scale_mod.of_batch(first.scale if value is None else value, starts, pieces)


class _Pieces:
    """A compiled model's fields and gradient as functions of one state (what
    :func:`filippov.checks.non_finite_piece` asks of a system)."""

    def __init__(self, cmodel: CompiledModel):
        self.cm = cmodel

    def _vector(self, piece, z):
        out = np.full(self.cm.dim, np.nan)
        piece(np.ascontiguousarray(z, dtype=float), self.cm.params, out)
        return out

    def field_minus(self, z):
        return self._vector(self.cm.field_minus, z)

    def field_plus(self, z):
        return self._vector(self.cm.field_plus, z)

    def switch_grad(self, z):
        return self._vector(self.cm.switch_grad, z)

    def switch(self, z):
        return self.cm.switch(np.ascontiguousarray(z, dtype=float), self.cm.params)

    def section(self, z):
        return self.cm.section(np.ascontiguousarray(z, dtype=float), self.cm.params)


def failure(cmodel: CompiledModel, out: BatchReturns, i: int) -> str:
    """Why start ``i`` of ``out`` did not return, in words: its status, where (t, state)
    and in which mode; for a non-finite value the piece that gave it (checked by
    evaluating the pieces at that state)."""
    code, z = int(out.status[i]), out.state[i]
    return f"{STATUS[code]} at t={float(out.time[i])!r}, state {z.tolist()}" + _failure_detail(
        cmodel, out, i)


def _failure_detail(cmodel: CompiledModel, out: BatchReturns, i: int) -> str:
    """What :func:`failure` says after the status, time and state: the mode, and the
    evidence for a non-finite value or an exact flow off its field."""
    from .checks import non_finite_piece, piece_not_finite_at

    code, z = int(out.status[i]), out.state[i]
    mode = int(out.mode[i]) if out.mode is not None else None
    where = ""
    if mode is not None:
        where += f", mode {MODE_NAMES.get(mode, mode)}"
    if code == FLOW_OFF_FIELD and mode in (MINUS, PLUS):
        return where + _flow_off_field(cmodel, mode, z)
    if code == ZENO and out.accumulation is not None and np.isfinite(out.accumulation[i, 0]):
        return where + accumulation_detail(*(float(v) for v in out.accumulation[i]))
    if code != NON_FINITE:
        return where
    if not np.all(np.isfinite(z)):
        return where + " (the state itself)"
    pieces = _Pieces(cmodel)
    # a sampled value (h, its rate, the sliding speeds, the section) at the state where
    # the run stopped, or else a field or flow on the way from it
    piece = piece_not_finite_at(pieces, mode, z, (("section", pieces.section),))
    if piece is not None:
        return where + f" ({piece} returned a non-finite value there)"
    if cmodel.exact and mode in (MINUS, PLUS):  # exact flows are sampled, not integrated
        piece = "flow_plus" if mode == PLUS else "flow_minus"
        return where + f" ({piece} returned a non-finite value from there)"
    return where + f" ({non_finite_piece(pieces, mode, z)} returned a non-finite " \
                   f"value there)"


def _flow_off_field(cmodel: CompiledModel, mode: int, z) -> str:
    """Why the exact flow of ``mode`` was refused at ``z`` (the state at the start of the
    window the kernel checked, rules.flow_consistent), with its move over one sample
    step from z next to its field's speed there as evidence."""
    name = MODE_NAMES[mode]
    flow, field = ((cmodel.flow_plus, cmodel.field_plus) if mode == PLUS
                   else (cmodel.flow_minus, cmodel.field_minus))
    z = np.ascontiguousarray(z, dtype=float)
    moved, speed = np.full(cmodel.dim, np.nan), np.full(cmodel.dim, np.nan)
    flow(z, cmodel.sample_step, cmodel.params, moved)
    field(z, cmodel.params, speed)
    return (f" (the exact flow of mode {name}, flow_{name}, does not follow its field "
            f"field_{name} there: over the window from that state it moved the state "
            f"farther than {rules.FLOW_SPEED_FACTOR:g} times the window times the field's "
            f"speed at the window's ends (rules.flow_consistent); over one sample step "
            f"({cmodel.sample_step:g}) from there it moves it by "
            f"{np.linalg.norm(moved - z):.3g}, the field's speed there being "
            f"{np.linalg.norm(speed):.3g}; use integrated flows (method='integrate') or "
            f"check the flow's formula)")


def first_returns_compiled(cmodel: CompiledModel, starts, t_max: float, *,
                           progress: Progress | None = None, **options) -> Returns:
    """Replaced by the front door ``first_returns(cmodel, starts, None, t_max,
    engine="compiled")`` (:func:`filippov.first_returns`); kept for its callers."""
    return _first_returns(cmodel, starts, None, t_max, progress=progress, **options)


def _first_returns(system, starts, section, t_max: float, *, direction: int = 0,
                   where=None, progress: Progress | None = None, **options) -> Returns:
    """:func:`filippov.first_returns` on the compiled engine: one batch call of
    :func:`compute_returns`; ``progress`` is stepped once by the number of start points,
    after the batch. A start point that does not return is an error naming it (the
    first one, with its status), raised as the reference driver raises it: the class and
    the words of its status (:func:`filippov.errors.run_error`, one table for both
    engines), then the failure's detail (:func:`failure`).
    """
    cmodel = views.compiled_model(system, "first_returns", section, direction=direction,
                                    where=where)
    out = compute_returns(cmodel, starts, t_max, **options)
    if progress is not None:
        progress.step(out.status.size)
    bad = np.flatnonzero(out.status != OK)
    if bad.size:
        i = int(bad[0])
        code = int(out.status[i])
        z0 = np.atleast_2d(np.asarray(starts, dtype=float))[i]
        raise run_error(code, out.time[i], out.state[i], _failure_detail(cmodel, out, i)
                        + f": start point {z0.tolist()} did not return to the section of "
                        f"{cmodel.name!r} within t_max={t_max!r} ({bad.size} of "
                        f"{out.status.size} start points failed)")
    return Returns(out.state, out.time, out.n_switches, out.sliding_time, out.first_switch)
