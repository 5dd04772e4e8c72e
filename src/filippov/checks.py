"""Checks of a :class:`~filippov.system.PiecewiseSystem` against its contract.

A system is built by whoever writes the model, and a piece that breaks the
contract of the class (see its docstring) otherwise fails far from the cause:
a numpy broadcast error deep in the event scan, a wrong answer when the number
of samples happens to equal the dimension, a Zeno error for a gradient of the
wrong sign. :func:`check_system` runs once at the start of
:func:`filippov.simulate.simulate` and names the piece instead.

The checks only evaluate the pieces (a few dozen calls on states next to the
start state); they compute nothing the solver uses, so a valid system gives
the same trajectory bit for bit. They cost about as much as a short run of an
exact flow (~0.3 ms), so a system object that passed is not checked again: a
return map calls simulate once per start point on the same system.
"""
from __future__ import annotations

import math
import weakref

import numpy as np

from .system import MINUS, MODE_NAMES, ONE_SURFACE, PLUS, SLIDING, PiecewiseSystem
from .errors import SystemContractError  # noqa: F401  (re-exported)

FLOW_NAMES = {MINUS: "flows[MINUS]", PLUS: "flows[PLUS]", SLIDING: "flows[SLIDING]"}
FIELD_NAMES = {MINUS: "field_minus", PLUS: "field_plus"}

#: batch probe: relative spread of the probe states around the start state, and
#: the agreement asked of a batch evaluation with the column-by-column one. Both
#: evaluate the same elementwise arithmetic (bit-identical); only a library
#: routine that picks another kernel for a batch (matmul: gemv vs gemm, SIMD
#: transcendental functions) may differ, by a few ulps of the terms, far below
#: 1e-8 of a row's size; a piece that mixes samples is off by the spread, 1e-3.
PROBE_SPREAD = 1e-3
PROBE_RTOL = 1e-8

#: switch_grad check: relative tolerance of the directional derivative. The
#: central difference (H(z + h d) - H(z - h d)) / 2h has truncation error
#: ``h^2/6 |D^3 H|`` and rounding error ``~ eps |H| / h``; with h = eps^(1/3) s (s the
#: size of the state) both are ~1e-11 relative when H varies on the scale s, so
#: 1e-3 leaves eight orders of margin, while a gradient of the wrong sign is off
#: by 2 along ``d = grad/|grad|`` (and one of another function by O(1)). A switch
#: that varies on a scale far below s is met by the smaller steps
#: GRAD_STEPS: the check fails only if no step agrees.
GRAD_RTOL = 1e-3
GRAD_STEPS = (1.0, 1e-2, 1e-4)


# (id(system), exact flows checked) -> weak reference to a system that passed; the
# entry goes with the system, so a new object at a recycled id is checked afresh
_PASSED: dict = {}


# what each kind of piece must do (the batch contract of PiecewiseSystem), and how
_CONTRACT = {
    "vector": "must map a state z of shape (n,) to (n,) and a batch (n, m) of m "
              "samples to (n, m), sample by sample",
    "scalar": "must map a state z of shape (n,) to a scalar and a batch (n, m) of m "
              "samples to (m,), sample by sample",
    "flow": "(an exact flow) must map z0 of shape (n,) and a scalar time tau to (n,), "
            "and times tau of shape (m,) to (n, m), time by time",
}
_HINT = {
    "vector": "components are z[i] (not z[..., i]), sums run over axis=0, and a constant "
              "vector B of shape (n,) must broadcast along the samples: B[:, None] for a "
              "batch, B.reshape((-1,) + (1,) * (z.ndim - 1)) for both shapes",
    "flow": "a constant vector v of shape (n,) times tau: np.multiply.outer(v, tau) "
            "serves both shapes; components of z0 are z0[i]",
}
_HINT["scalar"] = _HINT["vector"]


def _how(name, kind):
    return f"{name} {_CONTRACT[kind]} (see PiecewiseSystem); {_HINT[kind]}"


def check_system(system: PiecewiseSystem, z0: np.ndarray, *, method: str,
                 floor: float = 1.0, scales=None) -> None:
    """Raise :class:`SystemContractError` if ``system`` breaks its contract near ``z0``.

    Checked: a finite positive ``sample_step`` when exact flows will be used
    (``method="exact"``); that every piece (and every exact flow that will be
    used) evaluates a batch of states as it does each state alone, with the
    right shape; that ``switch_grad`` is the gradient of ``switch`` at ``z0``.
    A system object that passed is not checked again (for the same use of its
    flows), whatever ``z0``. ``floor``: the run's state scale (filippov.scale), the
    smallest size the gradient's differences step from; ``scales``: each component's
    (None: ``floor`` for all), the least size of a flow's rounding (:func:`flow_check`).
    """
    exact = method == "exact" and len(system.flows) > 0
    key = (id(system), exact)
    ref = _PASSED.get(key)
    if ref is not None and ref() is system:
        return
    _check(system, z0, exact, floor, floor if scales is None else scales)
    try:
        _PASSED[key] = weakref.ref(system, lambda _, key=key: _PASSED.pop(key, None))
    except TypeError:  # an object without weak references is checked every time
        pass


def _check(system, z0, exact, floor, scales):
    if exact:
        check_sample_step(system)
    n = system.dim
    m = n + 2  # neither 1 nor n: a broadcast along the wrong axis cannot pass unseen
    Z = probe_states(z0, m, floor)
    for name, fn, kind in (("field_minus", system.field_minus, "vector"),
                           ("field_plus", system.field_plus, "vector"),
                           ("switch", system.switch, "scalar"),
                           ("switch_grad", system.switch_grad, "vector")):
        _probe_piece(name, fn, Z, [Z[:, j] for j in range(m)], n, kind)
    if exact:
        taus = system.sample_step * np.arange(m) / (m - 1)
        for mode, flow in system.flows.items():
            name = FLOW_NAMES.get(mode, f"flows[{mode!r}]")
            _probe_piece(name, lambda tau, f=flow: f(z0, tau), taus,
                         [np.float64(t) for t in taus], n, "flow")
        for mode, field_name in ((MINUS, "field_minus"), (PLUS, "field_plus")):
            if mode in system.flows:
                flow_check(lambda z, tau, f=system.flows[mode]: f(z, tau),
                           getattr(system, field_name), z0, system.sample_step,
                           FLOW_NAMES.get(mode, repr(mode)), field_name, scales=scales)
    check_switch_grad(system, z0, floor)


def sliding_flow_check(system, z, t: float, scales=None) -> None:
    """The exact sliding flow against the sliding field (:func:`flow_check`) at ``z``,
    where a run of the reference engine first slides (the compiled engine integrates
    every slide): a sliding flow at twice its speed returned (cos 2, sin 2) for (cos 1,
    sin 1) with no word before (a review). One wrong only elsewhere on H is not seen."""
    flow_check(lambda zz, tau: system.flows[SLIDING](zz, tau), system.sliding_field, z,
               system.sample_step, FLOW_NAMES[SLIDING], "the sliding field",
               f"the run's first slide (t={float(t)!r})", scales)


#: the share of each component's speed by which the derivative of an exact flow at time
#: 0 may differ from its field (beside the differences' rounding, and FLOW_FIELD_SHARE of
#: that share of the fastest component's, in the component's own scale)
FLOW_FIELD_SHARE = 1e-4
#: the rounding errors (ulps of a component's size, at least its scale) a flow's value
#: may carry: the extrapolated difference's rounding is about 5 of them over tau
FLOW_ROUNDING_ULPS = 1e3
#: the first time over which the flow is differentiated (a share of the shorter of a
#: sample step and the field's own time), each next one FLOW_STEP_RATIO shorter, at most
#: FLOW_TRIES of them: until it agrees, or its derivative settles elsewhere
FLOW_FIRST_STEP = 0.1
FLOW_STEP_RATIO = 10.0
FLOW_TRIES = 16
#: a derivative settled: it changed from the last step by less than this share of its
#: disagreement with the field and of its own size (a right flow's truncation shrinks as
#: tau^2, a flow faster than tau changes as 1 / tau, a wrong flow's disagreement stays)
FLOW_SETTLED = 0.1


def flow_check(flow, field, z0, sample_step: float, piece: str, of: str,
               where: str = "the start state", scales=None) -> None:
    """Raise :class:`SystemContractError` unless the exact flow ``flow(z, tau)`` leaves
    ``z0`` along its ``field``: Richardson's extrapolation of two forward differences,
    2 D(tau/2) - D(tau), agrees with F in every component within FLOW_FIELD_SHARE of its
    speed and FLOW_ROUNDING_ULPS of its size over tau, at FLOW_FIRST_STEP of the shorter
    of a sample step and the field's own time or at a tau FLOW_STEP_RATIO, 100, ...
    times shorter, tried until the derivative settles (FLOW_SETTLED) away from F: a
    right flow's truncation shrinks as tau^2 and a flow faster than tau changes as 1 /
    tau, where a wrong flow's disagreement stays (and a shorter tau only loosens the
    rounding allowance, which before passed a flow at twice its speed). ``scales``: each component's (filippov.scale), or one for all, the least
    size its rounding is measured from. A flow of the other region, or in other units
    of time, ran before with the speed check of the run (FLOW_OFF_FIELD) only, which
    allows a factor of 100: a review found returns at t = 1.416 and 3.590 for 1.795 with
    no word. Checked at a run's first start, where the parameters are the run's (a
    system may be built with placeholders and given its parameters later). No verdict
    where a value is not finite or a piece raises: the run meets it."""
    z0 = np.asarray(z0, dtype=float).reshape(-1)
    try:
        with np.errstate(all="ignore"):
            F = np.asarray(field(z0), dtype=float).reshape(-1)
            s = np.broadcast_to(np.asarray(1.0 if scales is None else scales, dtype=float),
                                z0.shape)
            size = np.maximum(np.abs(z0), s)
            found = _flow_disagreement(flow, field, z0, F, s, size, sample_step)
    except Exception:   # noqa: BLE001 -- a piece that fails here: the run names it
        return
    if found is None:
        return
    d, tau = found
    raise SystemContractError(
        f"{piece} does not follow {of} at {where} z={z0.tolist()}: the flow's "
        f"derivative at time 0 is {d.tolist()} (over tau = {tau:.3g}), the field there "
        f"{F.tolist()}. An exact flow must be the solution of its own field ({of}), in "
        f"the system's time (a swapped or rescaled flow gives wrong events with no other "
        f"word); a right flow can only fail this where sample_step = {sample_step!r} is "
        f"far too coarse for the fastest time scale (it must resolve it)")


def _fastest_time(field, z0, F, s, size) -> float:
    """1 / the largest rate of the field near z0 (the largest entry of its Jacobian in
    the metric of the scales ``s``, by a forward difference along each component): a
    fast mode barely excited at the start (an amplitude 1e-7 of a mode at rate 1e6) hides
    from the field's own time there, and over a longer tau its flow seemed wrong; inf
    where no probe tells (a value not finite)."""
    rate = 0.0
    for k in range(z0.size):
        step = math.sqrt(np.finfo(float).eps) * size[k]
        z = z0.copy()
        z[k] += step
        step = z[k] - z0[k]   # as represented
        dF = np.asarray(field(z), dtype=float).reshape(-1) - F
        r = float(np.max(np.abs(dF) / s)) * s[k] / step if step > 0.0 else 0.0
        if math.isfinite(r):
            rate = max(rate, r)
    return 1.0 / rate if rate > 0.0 else math.inf


def _flow_disagreement(flow, field, z0, F, s, size, sample_step):
    """(the flow's derivative, tau) where it settles away from F beyond the tolerances of
    :func:`flow_check`, else None (it agrees, or a value is not finite)."""
    if not np.all(np.isfinite(F)):
        return None
    moving = np.abs(F) > 0.0
    own = float(np.min(size[moving] / np.abs(F[moving]))) if np.any(moving) else np.inf
    tau = FLOW_FIRST_STEP * min(sample_step, own, _fastest_time(field, z0, F, s, size))
    fastest = float(np.max(np.abs(F) / s))   # in the metric of the scales
    share = FLOW_FIELD_SHARE * (np.abs(F) + FLOW_FIELD_SHARE * fastest * s)
    last = None
    for _ in range(FLOW_TRIES):
        zt = np.asarray(flow(z0, tau), dtype=float).reshape(-1)
        zh = np.asarray(flow(z0, 0.5 * tau), dtype=float).reshape(-1)
        d = (4.0 * (zh - z0) - (zt - z0)) / tau   # 2 D(tau/2) - D(tau)
        if not np.all(np.isfinite(d)):
            return None
        reach = np.maximum(size, np.maximum(np.abs(zt), np.abs(zh)))
        rounding = FLOW_ROUNDING_ULPS * np.finfo(float).eps * reach / tau
        if np.all(np.abs(d - F) <= share + rounding):
            return None
        # a derivative within its rounding is 0: a flow that stands still where its field
        # moves (its sin terms forgotten) settles there, not on noise growing as 1 / tau
        # until the rounding allowance passes it (a review)
        d = np.where(np.abs(d) <= rounding, 0.0, d)
        change = np.max(np.abs(d - last) / s) if last is not None else np.inf
        if change <= FLOW_SETTLED * min(np.max(np.abs(d - F) / s), np.max(np.abs(d) / s)):
            return d, tau   # settled away from the field: a wrong flow, not a coarse step
        last, tau = d, tau / FLOW_STEP_RATIO
    return d, tau * FLOW_STEP_RATIO   # never agreed nor settled: no verdict can be trusted


def check_sample_step(system: PiecewiseSystem) -> None:
    """Exact flows are scanned for events every ``sample_step``: it must be finite > 0."""
    step = system.sample_step
    modes = ", ".join(MODE_NAMES.get(k, repr(k)) for k in system.flows)
    if not _positive(step):
        raise SystemContractError(
            f"the system has exact flows (modes {modes}) but sample_step={step!r}: an exact "
            "flow is scanned for events every sample_step, so sample_step must be a finite "
            "number > 0 that resolves the fastest time scale of the system (build the "
            "PiecewiseSystem with, e.g., sample_step=period/64 or eps/4; or simulate "
            "with method='integrate')")
    slow = system.slow_sample_step
    if not (np.isnan(slow) or _positive(slow)):
        raise SystemContractError(
            f"slow_sample_step must be NaN (none) or a finite number > 0, got {slow!r}")


def _positive(v) -> bool:
    try:
        return bool(np.isfinite(v) and v > 0)
    except TypeError:
        return False


def probe_states(z0: np.ndarray, m: int, floor: float = 1.0) -> np.ndarray:
    """``m`` distinct states next to ``z0`` (the first is ``z0`` itself), shape (n, m),
    a spread of each component's size (at least ``floor``, the run's state scale) away."""
    n = z0.size
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    pattern = np.where(j == 0, 0.0, np.cos(1.0 + 1.7 * i + 2.3 * j))
    scale = PROBE_SPREAD * np.maximum(np.abs(z0), floor)
    return z0[:, None] + scale[:, None] * pattern


def _probe_piece(name, fn, batch, columns, n, kind):
    """Evaluate ``fn`` on ``batch`` and on each of ``columns``; compare."""
    m = len(columns)
    try:
        singles = [np.asarray(fn(c), dtype=float) for c in columns]
    except Exception:
        # the piece fails on a single state: not a matter of batches; the solver
        # meets (and reports) that itself where it happens
        return
    single_shape = () if kind == "scalar" else (n,)
    what = "time" if kind == "flow" else "state"
    for s in singles:
        if kind == "scalar" and name == "switch" and s.size > 1:
            raise SystemContractError(f"switch returned {s.size} values for a single state: "
                                      f"{ONE_SURFACE}")
        if s.shape != single_shape and not (kind == "scalar" and s.size == 1):
            raise SystemContractError(
                f"{name} returned shape {s.shape} for a single {what} "
                f"({'a scalar tau' if kind == 'flow' else f'z of shape ({n},)'}); expected "
                f"{single_shape}: {_how(name, kind)}")
    want = (m,) if kind == "scalar" else (n, m)
    arg = f"tau of shape ({m},)" if kind == "flow" else f"z of shape ({n}, {m})"
    try:
        out = np.asarray(fn(batch), dtype=float)
    except Exception as exc:
        raise SystemContractError(
            f"{name} fails on a batch ({arg}) but not on each sample alone "
            f"({type(exc).__name__}: {str(exc).strip()}); expected shape {want}: "
            f"{_how(name, kind)}") from exc
    if out.shape != want:
        raise SystemContractError(
            f"{name} returned shape {out.shape} for {arg}; expected {want}: "
            f"{_how(name, kind)}")
    cols = np.stack([s.reshape(()) if kind == "scalar" else s for s in singles], axis=-1)
    rows = np.atleast_2d(cols)
    outs = np.atleast_2d(out)
    with np.errstate(invalid="ignore", over="ignore"):
        finite = np.where(np.isfinite(rows), np.abs(rows), 0.0)
        tol = PROBE_RTOL * (finite.max(axis=1, keepdims=True) + 1e-6 * finite.max(initial=0.0))
        same = (np.abs(outs - rows) <= tol) | (outs == rows) | (np.isnan(outs) & np.isnan(rows))
    if not np.all(same):
        r, c = (int(k[0]) for k in np.nonzero(~same))
        raise SystemContractError(
            f"{name} on a batch ({arg}) differs from its evaluation {what} by {what}: "
            f"{what} {c} gives {float(outs[r, c])!r} in the batch but "
            f"{float(rows[r, c])!r} alone (component {r}), so the piece mixes samples: "
            f"{_how(name, kind)}")


def check_switch_grad(system: PiecewiseSystem, z0: np.ndarray, floor: float = 1.0) -> None:
    """``switch_grad(z0)`` against central differences of ``switch`` along two
    directions: the gradient's own and a fixed one (see :data:`GRAD_RTOL`)."""
    g = np.asarray(system.switch_grad(z0), dtype=float).reshape(-1)
    gradient_check(lambda Z: np.asarray(system.switch(Z), dtype=float), g, z0, floor=floor)


def gradient_check(switch_at, g: np.ndarray, z0: np.ndarray, *, piece: str = "switch_grad",
                   of: str = "switch", floor: float = 1.0) -> None:
    """Raise :class:`SystemContractError` unless ``g`` is the gradient at ``z0`` of the
    function ``switch_at`` (states (n, k) -> values (k,)) -- the check of both engines
    (:func:`check_switch_grad`, :func:`check_compiled`); ``piece``/``of`` name them.
    The differences step from ``floor`` (the run's state scale, filippov.scale) or the
    start's size, whichever is larger."""
    if not np.all(np.isfinite(g)):
        return
    n = z0.size
    fixed = np.cos(0.7 + 2.1 * np.arange(n))
    dirs = [fixed / np.linalg.norm(fixed)]
    gnorm = float(np.linalg.norm(g))
    if gnorm > 0:
        dirs.insert(0, g / gnorm)
    size = max(floor, float(np.max(np.abs(z0))))
    h0 = np.cbrt(np.finfo(float).eps) * size
    steps = [h0 * f for f in GRAD_STEPS]
    pts = [z0 + sign * h * d for h in steps for d in dirs for sign in (1.0, -1.0)]
    try:
        H = np.asarray(switch_at(np.stack(pts, axis=1)), dtype=float)
        H = H.reshape(len(steps), len(dirs), 2)
        H0 = abs(float(np.asarray(switch_at(z0[:, None]), dtype=float).reshape(())))
    except Exception:  # switch fails next to z0: no verdict here, the solver meets it
        return
    # rounding of H at the sample points: eps times the size of H's terms
    terms = H0 + gnorm * float(np.linalg.norm(z0))
    worst = None
    for k, h in enumerate(steps):
        agree = True
        with np.errstate(invalid="ignore", over="ignore"):
            for i, d in enumerate(dirs):
                fd = (H[k, i, 0] - H[k, i, 1]) / (2 * h)
                gd = float(g @ d)
                noise = 8 * np.finfo(float).eps * (terms + np.max(np.abs(H[k, i]))) / h
                scale = max(abs(gd), abs(fd), gnorm)
                if abs(fd - gd) > GRAD_RTOL * scale + noise:  # False for NaN: no verdict
                    agree = False
                    if worst is None:
                        worst = (d, gd, fd, h)
        if agree:
            return
    d, gd, fd, h = worst
    raise SystemContractError(
        f"{piece} does not match a finite difference of {of} at the start state "
        f"z={z0.tolist()}: along d={d.tolist()}, {piece}(z).d = {gd!r} but "
        f"({of}(z + h d) - {of}(z - h d)) / 2h = {float(fd)!r} (h = {h:.3g}; smaller steps "
        f"disagree too). {piece} must return the gradient dH/dz of {of}; one of "
        f"the wrong sign makes attracting sliding look repelling (and crossings look "
        f"like sliding)")


# id(compiled model) -> weak reference to one that passed check_compiled
_PASSED_COMPILED: dict = {}


def check_compiled(cmodel, z0: np.ndarray, floor: float = 1.0, scales=None) -> None:
    """The compiled engine's start check (:func:`filippov.fastmap.compute_returns`), the
    same as the reference driver's :func:`check_switch_grad`: ``grad_h`` is the gradient
    of ``h`` at the first start point, and exact flows follow their fields there
    (:func:`flow_check`); once per model object. (The pieces' output sizes
    are checked where a model is built: ``compile_system``, ``FilippovSystem``.)"""
    key = id(cmodel)
    ref = _PASSED_COMPILED.get(key)
    if ref is not None and ref() is cmodel:
        return
    z0 = np.ascontiguousarray(z0, dtype=float)
    p = cmodel.params
    g = np.full(z0.size, np.nan)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        cmodel.switch_grad(z0, p, g)

        def switch_at(Z):
            return np.array([cmodel.switch(np.ascontiguousarray(Z[:, j]), p)
                             for j in range(Z.shape[1])])

        gradient_check(switch_at, g, z0, floor=floor)  # the user's names
    if cmodel.exact:
        n = z0.size
        for k in ("minus", "plus"):
            flow, field = getattr(cmodel, f"flow_{k}"), getattr(cmodel, f"field_{k}")

            def flow_at(z, tau, flow=flow):
                out = np.empty(n)
                flow(np.ascontiguousarray(z), float(tau), p, out)
                return out

            def field_at(z, field=field):
                out = np.empty(n)
                field(np.ascontiguousarray(z), p, out)
                return out
            flow_check(flow_at, field_at, z0, cmodel.sample_step, f"flow_{k}", f"field_{k}",
                       scales=floor if scales is None else scales)
    try:
        _PASSED_COMPILED[key] = weakref.ref(cmodel,
                                            lambda _, key=key: _PASSED_COMPILED.pop(key, None))
    except TypeError:
        pass


def piece_not_finite_at(system, mode: int, z: np.ndarray, sections=()) -> str | None:
    """The first piece a run in ``mode`` evaluates that is not finite at ``z`` -- the
    mode's field (both fields while sliding), switch, switch_grad, then each of
    ``sections`` (pairs of the words naming it and its function of the state) -- or
    None if all are.
    ``system`` need only have the methods it asks for (field_minus, field_plus, switch,
    switch_grad): both engines blame a non-finite sample with it."""
    fields = (("field_minus", system.field_minus), ("field_plus", system.field_plus))
    if mode in FIELD_NAMES:
        fields = tuple(f for f in fields if f[0] == FIELD_NAMES[mode])
    asked = fields + (("switch", system.switch), ("switch_grad", system.switch_grad))
    asked += tuple(sections)
    z = np.asarray(z, dtype=float)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for name, fn in asked:
            try:
                if not np.all(np.isfinite(np.asarray(fn(z), dtype=float))):
                    return blamed(name, fn, z)
            except Exception:
                return blamed(name, fn, z)
    return None


def blamed(name: str, fn, z) -> str:
    """How a piece is named to its user: ``name``, or what the piece says it is
    (``piece_name``: words, or a function of the state giving them -- a view of several
    surfaces names the region whose field it is, filippov.surfaces)."""
    label = getattr(fn, "piece_name", None)
    if label is None:
        return name
    try:
        return label(z) if callable(label) else str(label)
    except Exception:   # noqa: BLE001 -- naming must not fail where a piece did
        return name


def non_finite_piece(system: PiecewiseSystem, mode: int, z: np.ndarray) -> str:
    """The piece to blame for a non-finite field value of ``mode`` at ``z``."""
    if mode in FIELD_NAMES:
        name = FIELD_NAMES[mode]
        return blamed(name, getattr(system, name, None), z)
    with np.errstate(invalid="ignore", over="ignore", divide="ignore"):
        for name, fn in (("field_minus", system.field_minus), ("field_plus", system.field_plus),
                         ("switch_grad", system.switch_grad)):
            try:
                if not np.all(np.isfinite(np.asarray(fn(z), dtype=float))):
                    return blamed(name, fn, z)
            except Exception:
                return blamed(name, fn, z)
    return ("the sliding field (a F_+ - b F_-)/(a - b), a = dH.F_-, b = dH.F_+ "
            "(built from field_minus, field_plus and switch_grad)")
