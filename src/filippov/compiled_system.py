"""A user's Filippov system on the compiled engine, from plain scalar functions.

The compiled kernel (:mod:`filippov.fastmap`) calls its pieces through numba
first-class functions with out-parameters (``field(z, p, out)``). A researcher
should not have to write that ABI: :func:`compile_system` takes functions of one
state ``z`` (a 1-D float array) and the parameter array ``p`` that *return* their
values, compiles each with numba and wraps it in the kernel's signature. The
section is the caller's, not the model's: :func:`with_section` puts another one on
the same compiled system.
"""
from __future__ import annotations

import dataclasses
import warnings
from typing import Callable, Optional

import numpy as np
from numba import njit
from numba.core.errors import NumbaError

from . import frozen, options
from . import scale as scale_mod
from .checks import SystemContractError
from .differences import richardson_jacobian
from .spelling import one_spelling
from .batches import cannot_compile as _cannot_compile
from .batches import flow as _batch_flow, jit as _jit, scalar as _batch_scalar
from .batches import states as _states, vector as _batch_vector
from .surfaces import check_intersection, view_at
from .surfaces_defined import grad_derivative, sliding_jacobian
from .abi import FIELD_SIG, FLOW_SIG, SCALAR_SIG, WHERE_SIG, CompiledModel, always, no_flow

def _params_in_range(pieces: dict, n: int, params, probe) -> None:
    """Refuse a piece that reads ``p`` beyond ``params`` (params= forgotten, or one value
    too few), run once as Python at the probe state: compiled, numba does not check the
    index and reads whatever lies past the array, a silent other system (a review). Only
    an IndexError is judged here; any other failure is left to the engines' checks."""
    z = np.full(n, 0.5) if probe is None else np.asarray(probe, dtype=float).reshape(-1)
    p = np.asarray(params, dtype=float)
    for name, fn in pieces.items():
        if not callable(fn) or name.startswith("flow_jacobian"):
            continue
        args = (z, 0.0, p) if name.startswith("flow") else (z, p)
        try:
            with np.errstate(all="ignore"):
                getattr(fn, "py_func", fn)(*args)
        except IndexError as exc:
            raise SystemContractError(
                f"{name}: IndexError at z={z.tolist()} with params of {p.size} value(s) "
                f"({exc}): it reads p (or z) beyond its size; give every parameter a piece "
                "reads in params=") from None
        except Exception:   # noqa: BLE001 -- not this check's to judge
            continue


def _one_surface(switch, n: int, params, probe) -> None:
    """Refuse a ``switch`` that gives several values at a state (several switching
    surfaces) by name, before numba's error about a vector where a scalar goes; a switch
    that fails at the probe state (zeros, or ``probe``) is left to the engines' checks."""
    if not callable(switch):
        return
    z = np.zeros(n) if probe is None else np.asarray(probe, dtype=float).reshape(-1)
    try:
        with np.errstate(all="ignore"):
            size = np.asarray(getattr(switch, "py_func", switch)(z, params)).size
    except Exception:   # noqa: BLE001 -- not this check's to judge
        return
    if size > 1:
        from .system import ONE_SURFACE

        raise ValueError(f"switch: returned {size} values at z={z.tolist()}: {ONE_SURFACE}")


def _compile(adapter_src: Callable, sig, piece: str):
    """``adapter_src`` compiled with ``sig``; a numba failure becomes one readable line."""
    try:
        with warnings.catch_warnings():  # numba's casts of a broken piece: the error says it
            warnings.simplefilter("ignore")
            return njit(sig)(adapter_src)
    except NumbaError as exc:
        raise _cannot_compile(exc, piece) from None


def _vector_piece(fn, piece: str, n: int):
    user = _jit(fn, piece)

    def adapter(z, p, out):
        v = user(z, p)
        if len(v) != n:
            raise ValueError("a vector piece returned the wrong number of values")
        for i in range(n):
            out[i] = v[i]

    return _compile(adapter, FIELD_SIG, piece)


def _flow_piece(fn, piece: str, n: int):
    user = _jit(fn, piece)

    def adapter(z0, tau, p, out):
        v = user(z0, tau, p)
        if len(v) != n:
            raise ValueError("a flow returned the wrong number of values")
        for i in range(n):
            out[i] = v[i]

    return _compile(adapter, FLOW_SIG, piece)


def _flow_matrix_piece(fn, piece: str, n: int):
    """A flow's Jacobian ``J(z0, tau, p) -> (n, n)`` as the ABI's ``flow_jacobian``
    piece (row by row into ``out``)."""
    user = _jit(fn, piece)

    def adapter(z0, tau, p, out):
        v = user(z0, tau, p)
        if v.shape[0] != n or v.shape[1] != n:
            raise ValueError("a flow's Jacobian returned the wrong shape")
        for i in range(n):
            for k in range(n):
                out[i * n + k] = v[i, k]

    return _compile(adapter, FLOW_SIG, piece)


def _flow_of(flow, tau, p, n):
    """A compiled flow piece as the function z0 -> flow(z0, tau) of differences."""
    def fun(z0):
        out = np.empty(n)
        flow(z0, tau, p, out)
        return out
    return fun


def _check_flow_jacobians(cm: CompiledModel, probe: np.ndarray) -> None:
    """The flow Jacobians a user gave, against Richardson differences of their flows at
    the probe state over one sample step: a wrong one would give wrong dP/dz and
    multipliers with every return right. Refused where an entry is off by 1e-6 of the
    scale (that of J), or where one is not finite."""
    n, p, tau = cm.dim, cm.params, float(cm.sample_step)
    floor = max(1.0, float(np.abs(probe).max()))
    for mode in ("minus", "plus"):
        got = np.full(n * n, np.nan)
        getattr(cm, f"flow_jacobian_{mode}")(probe, tau, p, got)
        J = got.reshape(n, n)
        want = richardson_jacobian(_flow_of(getattr(cm, f"flow_{mode}"), tau, p, n),
                                   probe, floor)
        scale = max(float(np.abs(want).max()), 1e-300)
        bad = ~np.isfinite(J) | (np.abs(J - want) > 1e-6 * scale)
        if bad.any():
            i, k = np.argwhere(bad)[0]
            raise SystemContractError(
                f"flow_jacobian_{mode}: at z0={probe.tolist()}, tau={tau!r} its entry "
                f"[{i}, {k}] is {float(J[i, k])!r}, differences of flow_{mode} give "
                f"{float(want[i, k])!r}: a wrong flow Jacobian gives wrong dP/dz and "
                f"multipliers")


def _scalar_piece(fn, piece: str):
    user = _jit(fn, piece)

    def adapter(z, p):
        return float(user(z, p))

    return _compile(adapter, SCALAR_SIG, piece)


def _where_piece(fn, piece: str):
    if fn is None:
        return always  # compiled once (and cached), not per call
    user = _jit(fn, piece)

    def adapter(z, p):
        return bool(user(z, p))

    return _compile(adapter, WHERE_SIG, piece)


def _check_shapes(cm: CompiledModel, probe: np.ndarray) -> None:
    """Run every piece once at ``probe``: wrong output sizes and non-finite values
    are named here, not deep in the kernel."""
    n, p = cm.dim, cm.params

    def vector(fn):
        def value(z):
            out = np.full(n, np.nan)
            fn(z, p, out)
            return out
        return value

    pieces = {k: vector(getattr(cm, k)) for k in ("field_minus", "field_plus", "switch_grad")}
    pieces.update({k: (lambda z, fn=getattr(cm, k): fn(z, p)) for k in ("switch", "section")})
    _probe(pieces, cm.names, probe)


def _probe(pieces: dict, names, probe: np.ndarray) -> None:
    """Each of ``pieces`` ({user's name: z -> value}) once at ``probe``: a failure (the
    wrong number of values, ...) or a non-finite value is an error naming the piece --
    the construction check of both engines (compile_system, FilippovSystem.python)."""
    n = len(names)
    for piece, value in pieces.items():
        try:
            with np.errstate(all="ignore"):
                v = np.asarray(value(probe), dtype=float)
        except NumbaError as exc:
            raise _cannot_compile(exc, piece) from None
        except Exception as exc:  # the wrong number of values, ...
            want = "one value" if piece in _SCALARS else \
                f"{n} values, one per component of {', '.join(names)}"
            raise SystemContractError(f"{piece} failed at z={probe.tolist()}: {exc} (expected "
                                      f"{want})") from None
        if not np.all(np.isfinite(v)):
            what = "a finite value" if piece in _SCALARS else f"{n} finite values"
            raise SystemContractError(f"{piece} must return {what} at z={probe.tolist()}, "
                                      f"got {v.tolist()}")


def _probe_batches(batches: dict, names, params, probe) -> None:
    """The reference driver's pieces (compiled loops over samples) probed like the
    compiled engine's (:func:`_check_shapes`): compiled here, so that a piece numba
    cannot compile is named now, and run once at the probe state."""
    n = len(names)
    probe = _probe_state(probe, n)
    col = np.ascontiguousarray(probe.reshape(n, 1))
    pieces = {k: (lambda z, b=batches[k]: b(col, params)[:, 0])
              for k in ("field_minus", "field_plus", "switch_grad")}
    pieces["switch"] = lambda z: batches["switch"](col, params)[0]
    for k in ("flow_minus", "flow_plus"):
        if batches.get(k) is not None:
            pieces[k] = lambda z, b=batches[k]: b(probe, np.zeros(1), params)[:, 0]
    _probe(pieces, names, probe)


def _probe_state(probe, n: int) -> np.ndarray:
    probe = np.full(n, 0.5) if probe is None else np.ascontiguousarray(probe, dtype=float)
    if probe.shape != (n,):
        raise ValueError(f"probe: expected shape ({n},), got {probe.shape}")
    return probe


_SCALARS = ("switch", "section")


def _check_options(n, section_direction, flow_minus, flow_plus, flow_jacobian_minus,
                   flow_jacobian_plus, sample_step) -> tuple[bool, bool]:
    """compile_system's options, each refused by name where out of range: (exact flows,
    flow Jacobians)."""
    if n < 1:
        raise ValueError("names: at least one state component")
    if section_direction not in (-1, 0, 1):
        raise ValueError(f"section_direction must be -1, 0 or +1, got {section_direction!r}")
    if (flow_minus is None) != (flow_plus is None):
        raise ValueError("flow_minus and flow_plus: give both exact flows or neither")
    exact = flow_plus is not None
    if (flow_jacobian_minus is None) != (flow_jacobian_plus is None):
        raise ValueError("flow_jacobian_minus and flow_jacobian_plus: give both flow "
                         "Jacobians or neither")
    flow_jac = flow_jacobian_plus is not None
    if flow_jac and not exact:
        raise ValueError("flow_jacobian_minus, flow_jacobian_plus: flow Jacobians need "
                         "the exact flows (flow_minus, flow_plus)")
    if exact and not (np.isfinite(sample_step) and sample_step > 0):
        raise ValueError(f"sample_step: exact flows need a finite sample_step > 0 (the "
                         f"longest time between samples), got {sample_step!r}")
    return exact, flow_jac


@one_spelling
def compile_system(names, field_minus, field_plus, switch, switch_grad, *, section,
                   section_direction: int = 0, section_where: Optional[Callable] = None,
                   params=(), flow_minus: Optional[Callable] = None,
                   flow_plus: Optional[Callable] = None, sample_step: float = np.inf,
                   sliding: bool = True, name: str = "user", probe=None,
                   flow_jacobian_minus: Optional[Callable] = None,
                   flow_jacobian_plus: Optional[Callable] = None) -> CompiledModel:
    """A piecewise system (region + is ``switch(z, p) >= 0``) for the compiled engine.

    Parameters
    ----------
    names : sequence of str
        The state components; their number n is the dimension.
    field_minus, field_plus : callable
        ``f(z, p) -> array (n,)``: the fields of the regions ``switch < 0`` and ``>= 0``.
    switch : callable
        ``switch(z, p) -> float``, the switching function.
    switch_grad : callable
        ``switch_grad(z, p) -> array (n,)``, its gradient.
    section : callable
        ``s(z, p) -> float``: returns are hits of ``s = 0``.
    section_direction : int
        -1 decreasing crossings of ``s`` only, +1 increasing, 0 both.
    section_where : callable, optional
        ``w(z, p) -> bool`` that must hold at a hit (default: always).
    params : sequence of float
        The array ``p`` every piece receives.
    flow_minus, flow_plus : callable, optional
        Exact flows ``phi(z0, tau, p) -> array (n,)`` of the two regions (both or
        neither); without them both regions are integrated with DOP853 inside the
        kernel, like sliding.
    sample_step : float
        With exact flows: the longest time between samples (it must resolve the
        fastest time scale of the flows).
    sliding : bool
        Follow attracting sliding (Filippov's convex combination) where it occurs.
    probe : array (n,), optional
        A state at which every piece is run once to check its output (default: 0.5).
    flow_jacobian_minus, flow_jacobian_plus : callable, optional
        d flow / d z0 of the exact flows, ``J(z0, tau, p) -> array (n, n)`` (both or
        neither; a wrong one is refused): dP/dz without differences of the flows.

    Returns
    -------
    CompiledModel
        For :func:`filippov.fastmap.compute_returns` / ``first_returns_compiled``.

    Each piece is a plain function of one state, compiled with numba (``njit``); it
    must use numpy and math only. The first call compiles the pieces (a second or
    two each) and, once per machine, the kernel (about 13 s on 2 cores, cached).
    """
    names = tuple(str(x) for x in names)
    n = len(names)
    exact, flow_jac = _check_options(n, section_direction, flow_minus, flow_plus,
                                     flow_jacobian_minus, flow_jacobian_plus, sample_step)
    p = np.ascontiguousarray(np.asarray(params, dtype=float).reshape(-1))
    user = dict(field_minus=field_minus, field_plus=field_plus, switch=switch,
                switch_grad=switch_grad, flow_minus=flow_minus, flow_plus=flow_plus,
                flow_jacobian_minus=flow_jacobian_minus,
                flow_jacobian_plus=flow_jacobian_plus)
    reads = tuple(frozen.record({k: f for k, f in user.items() if f is not None}))
    cm = CompiledModel(
        name=name, names=names, params=p,
        flow_plus=_flow_piece(flow_plus, "flow_plus", n) if exact else no_flow,
        flow_minus=_flow_piece(flow_minus, "flow_minus", n) if exact else no_flow,
        field_plus=_vector_piece(field_plus, "field_plus", n),
        field_minus=_vector_piece(field_minus, "field_minus", n),
        switch=_scalar_piece(switch, "switch"),
        switch_grad=_vector_piece(switch_grad, "switch_grad", n),
        section=_scalar_piece(section, "section"),
        section_where=_where_piece(section_where, "section_where"),
        section_direction=int(section_direction), sample_step=float(sample_step),
        sliding=options.flag("sliding", sliding), exact=exact, parameters={},
        frozen_reads=reads,
        **{k: _flow_matrix_piece(user[k], k, n) if flow_jac else None
           for k in ("flow_jacobian_minus", "flow_jacobian_plus")})
    _check_shapes(cm, _probe_state(probe, n))
    if flow_jac:
        _check_flow_jacobians(cm, _probe_state(probe, n))
    return cm


def with_section(cm: CompiledModel, section: Callable, *, direction: int = 0,
                 where: Optional[Callable] = None) -> CompiledModel:
    """The same compiled system with another section (``section(z, p) -> float``)."""
    if direction not in (-1, 0, 1):
        raise ValueError(f"direction must be -1, 0 or +1, got {direction!r}")
    return dataclasses.replace(cm, section=_scalar_piece(section, "section"),
                               section_where=_where_piece(where, "section_where"),
                               section_direction=int(direction))


# ----------------------------------------------------------------------------- one definition
def _surface_functions(user: dict) -> dict:
    """The user's functions of several surfaces by piece name (what numba compiles in:
    filippov.frozen)."""
    out = {}
    for piece in ("fields", "switch", "switch_grad", "jacobians"):
        value = user[piece]
        if isinstance(value, dict):
            out.update({f"{piece}[{k!r}]": f for k, f in value.items()})
        elif isinstance(value, (tuple, list)):
            out.update({f"{piece}[{k}]": f for k, f in enumerate(value)})
        elif value is not None:
            out[piece] = value
    return out


_JAC_MODES = ("minus", "sliding", "plus")   # filippov.system.MODE_NAMES


@one_spelling
class FilippovSystem:
    """One definition of a Filippov system, run by both engines.

    Written once as plain scalar functions of one state ``z`` (1-D float array)
    and the parameter array ``p`` (see :func:`compile_system` for the pieces);
    :meth:`python` gives the :class:`~filippov.system.PiecewiseSystem` the
    reference driver (:func:`filippov.simulate`) runs, its pieces evaluated by
    numba-compiled loops over the samples; :meth:`compiled` gives the compiled
    engine's :class:`~filippov.abi.CompiledModel` with a section of the
    caller's choosing. Sections belong to the caller, not to the system. One
    switching function: a ``switch`` that gives several values at a state (several
    switching surfaces) is refused by name.
    ``jacobians`` (optional, ``{"minus"|"sliding"|"plus": J(z, p) -> (n, n)}``)
    gives :meth:`jacobian` (that of sliding derived from the two fields' where it is
    not given), used for Floquet multipliers and dP/dz on the
    reference driver instead of central differences (each compared with central
    differences of its field at the first state it is asked at: a wrong one is refused);
    :mod:`filippov.symbolic` generates all three from the expressions.
    ``flow_jacobians`` (optional, with exact flows: ``{"minus", "plus": J(z0, tau, p) ->
    (n, n)}``, d flow / d z0) give the compiled engine's dP/dz through an exact stay in
    one evaluation instead of Richardson's differences of the flow (compared with those
    differences when the compiled model is built: a wrong one is refused); a
    ``SymbolicSystem`` generates them from its flows.
    ``scale`` gives the units the engines measure their tolerances in
    (:mod:`filippov.scale`: a number is the state's size, a mapping or a
    :class:`~filippov.scale.Scale` also the time's and H's); None (the default)
    measures them at each run's start, so that the same system in other units gives the
    same results.
    """

    def __init__(self, names, field_minus=None, field_plus=None, switch=None,
                 switch_grad=None, *, params=(), flow_minus=None, flow_plus=None,
                 sample_step: float = np.inf, sliding: bool = True, name: str = "user",
                 jacobians=None, slow_sample_step: float = np.nan,
                 transient_time: float = np.inf, probe=None, scale=None, flow_jacobians=None,
                 fields=None, intersection=None):
        self.names = tuple(str(x) for x in names)
        # the run's units (filippov.scale): checked here, measured at each run's start
        # where not declared (docs/decisions.md#units)
        scale_mod.declared(scale)
        self.scale = scale
        self._probe = probe   # where both engines' pieces are run once when built
        self.slow_sample_step, self.transient_time = float(slow_sample_step), float(transient_time)
        self.params = np.ascontiguousarray(np.asarray(params, dtype=float).reshape(-1))
        self.name, self.sliding, self.sample_step = (name, options.flag("sliding", sliding),
                                                     float(sample_step))
        self.m, self._surfaces, self.intersection = 1, None, intersection
        self._user_surfaces = None   # several surfaces' pieces as the user gave them
        self._frozen = None     # what numba compiles into the pieces (filippov.frozen)
        if fields is not None:   # several switching surfaces (filippov.surfaces_defined)
            field_minus, field_plus, switch, switch_grad, jacobians = self._define_surfaces(
                fields, field_minus, field_plus, switch, switch_grad, jacobians,
                flow_minus is not None or flow_plus is not None)
        elif intersection is not None:
            raise ValueError("intersection: the sliding field on an intersection of "
                             "surfaces goes with several surfaces (fields=)")
        if self._surfaces is None:
            self._require(field_minus=field_minus, field_plus=field_plus, switch=switch,
                          switch_grad=switch_grad)
        flow_jacobians = dict(flow_jacobians or {})
        if flow_jacobians and set(flow_jacobians) != {"minus", "plus"}:
            raise ValueError(f"flow_jacobians: give those of both regions ('minus' and "
                             f"'plus'), got {sorted(flow_jacobians)}")
        if flow_jacobians and (flow_minus is None or flow_plus is None):
            raise ValueError("flow_jacobians: flow Jacobians need the exact flows "
                             "(flow_minus, flow_plus)")
        self._pieces = dict(field_minus=field_minus, field_plus=field_plus, switch=switch,
                            switch_grad=switch_grad, flow_minus=flow_minus, flow_plus=flow_plus,
                            flow_jacobian_minus=flow_jacobians.get("minus"),
                            flow_jacobian_plus=flow_jacobians.get("plus"))
        if self._surfaces is None:
            _one_surface(switch, len(self.names), self.params, probe)
        _params_in_range(self._pieces, len(self.names), self.params, probe)
        jacobians = dict(jacobians or {} if self._surfaces is None else {})
        unknown = set(jacobians) - set(_JAC_MODES)
        if unknown:
            raise ValueError(f"jacobians: unknown mode(s) {sorted(unknown)}; expected "
                             f"{', '.join(_JAC_MODES)}")
        self._jacobians = {m: _jit(f, f"jacobians[{m!r}]") for m, f in jacobians.items()}
        self._python = None
        self._compiled = None   # the fields compiled once; each call only adds a section
        self._user = None       # the pieces as numba dispatchers, shared by both engines
        self._jacobians_checked = set()   # the given Jacobians compared with their fields

    def _require(self, **pieces) -> None:
        """The pieces of one surface, each named where missing (a generated system has
        its own: it overrides this)."""
        missing = [k for k, v in pieces.items() if v is None]
        if missing:
            raise TypeError(f"{missing[0]}: missing; one switching surface takes "
                            f"field_minus, field_plus, switch and switch_grad, several "
                            f"take fields=, switch and switch_grad")

    def _define_surfaces(self, fields, field_minus, field_plus, switch, switch_grad,
                         jacobians, exact: bool):
        """Several switching surfaces (filippov.surfaces_defined): checked and compiled
        for the reference engine; m = 1 becomes today's one-surface pieces."""
        from . import surfaces_defined as defined

        if field_minus is not None or field_plus is not None:
            raise TypeError("fields: give either field_minus and field_plus (one switching "
                            "surface) or fields (a field per sign vector), not both")
        if exact:
            raise ValueError("flow_minus, flow_plus: exact flows take one switching surface; "
                             "with fields= the fields are integrated")
        if switch is None or switch_grad is None:
            raise TypeError(f"{'switch' if switch is None else 'switch_grad'}: missing; "
                            f"several surfaces take fields=, switch and switch_grad")
        n = len(self.names)
        # what numba compiles in, noted before anything is compiled (the pieces are run
        # once below; for one surface, at the first use of an engine)
        self._user_surfaces = dict(fields=fields, switch=switch, switch_grad=switch_grad,
                                   jacobians=dict(jacobians or {}))
        self._frozen = frozen.record(_surface_functions(self._user_surfaces))
        probe = _probe_state(self._probe, n)
        m = defined.count(fields, switch, n, self.params, probe)
        regions = defined.region_functions(fields, m)
        if m == 1:
            jac = {("minus" if k[0] < 0 else "plus"): f for k, f in (
                (defined.sign_vector(k, 1, "jacobians"), f)
                for k, f in dict(jacobians or {}).items())}
            check_intersection(self.intersection, m)
            one = defined.one_surface(regions, switch, switch_grad, probe, self.params)
            return one["field_minus"], one["field_plus"], one["switch"], one["switch_grad"], jac
        check_intersection(self.intersection, m)
        self.m = m
        self._surfaces = defined.compile_pieces(self.names, regions, switch, switch_grad,
                                                jacobians, m)
        defined.probe(self._surfaces, self.names, self.params, _probe_state(self._probe, n))
        return None, None, switch, switch_grad, None

    def _frozen_unchanged(self) -> None:
        """The values the pieces read from globals and closures (numba compiles them in):
        noted at the first use of an engine, checked at every later one."""
        if self._frozen is None:
            pieces = {k: f for k, f in self._pieces.items() if f is not None}
            pieces.update({f"jacobians[{m!r}]": f for m, f in self._jacobians.items()})
            self._frozen = frozen.record(pieces)
        else:
            frozen.check(self._frozen)

    # -- hooks: how the pieces become the engines' (a generated system overrides them)
    def _user_pieces(self) -> dict:
        if self._user is None:
            self._user = {k: (None if f is None else _jit(f, k)) for k, f in self._pieces.items()}
        return self._user

    def _batch_pieces(self) -> dict:
        """The pieces as compiled loops over the columns of ``(n, m)`` states (flows:
        over the times), for the reference driver."""
        n, pc = len(self.names), self._user_pieces()
        out = {k: _batch_vector(pc[k], n, k) for k in ("field_minus", "field_plus", "switch_grad")}
        out["switch"] = _batch_scalar(pc["switch"], n)
        for k in ("flow_minus", "flow_plus"):
            out[k] = None if pc[k] is None else _batch_flow(pc[k], n, k)
        _probe_batches(out, self.names, self.params, self._probe)
        return out

    def _section_batch(self, section):
        return _batch_scalar(_jit(section, "section"), len(self.names))

    def _jacobian_value(self, key: str, z: np.ndarray) -> np.ndarray:
        return np.asarray(self._jacobians[key](z, self.params), dtype=float)

    def _jacobian_modes(self) -> set:
        return set(self._jacobians)

    # -- the engines
    def compiled(self, section, *, direction: int = 0, where=None, probe=None) -> CompiledModel:
        """The compiled engine's model with the section ``section(z, p) = 0``."""
        self._one_surface_only("the compiled engine")
        self._frozen_unchanged()
        if self._compiled is None:
            self._compiled = dataclasses.replace(compile_system(
                self.names, section=section, section_direction=direction, section_where=where,
                params=self.params, sample_step=self.sample_step, sliding=self.sliding,
                name=self.name, probe=self._probe if probe is None else probe,
                **self._user_pieces()),
                slow_sample_step=self.slow_sample_step, transient_time=self.transient_time,
                scale=self.scale)
            return self._compiled
        return with_section(self._compiled, section, direction=direction, where=where)

    def python_section(self, section, *, direction: int = 0, where=None, name: str = "section",
                       min_time: float = 0.0):
        """The section ``section(z, p) = 0`` for the reference driver: a terminal
        :class:`~filippov.simulate.Section` whose function is compiled like the pieces
        and evaluated on one state or a batch of samples."""
        from .section import Section

        n, p = len(self.names), self.params
        batch = self._section_batch(section)

        def func(z):
            zs, tail = _states(z, n)
            out = batch(zs, p)
            return out.reshape(tail) if tail else float(out[0])

        cond = None
        if where is not None:
            w = _jit(where, "section_where")
            cond = lambda z: bool(w(np.ascontiguousarray(z, dtype=float), p))  # noqa: E731
        return Section(name, func, direction=direction, where=cond, terminal=1,
                       min_time=min_time)

    def _one_surface_only(self, what: str) -> None:
        if self._surfaces is not None:
            raise TypeError(f"system: {what} takes one switching surface; this "
                            f"{type(self).__name__} has m = {self.m} (run it with "
                            f"engine='reference')")

    @property
    def has_jacobians(self) -> bool:
        """Whether :meth:`jacobian` has the Jacobians of both regions' fields (that of
        sliding may be absent where the system cannot slide); with several surfaces, of
        every region's."""
        if self._surfaces is not None:
            return set(self._surfaces.jacobians) == set(self.python().field)
        return {"minus", "plus"} <= self._jacobian_modes()

    def jacobian(self, mode: int, z, *, floor: float | None = None) -> np.ndarray:
        """``dF/dz`` (n, n) of the field of ``mode`` (MINUS, SLIDING, PLUS) at one state,
        from the ``jacobians`` pieces: the ``jacobian=`` of :func:`filippov.monodromy`,
        :func:`filippov.variational.return_jacobian` and friends. ``floor``: the run's
        state scale, from which the sliding field's differences step (None: measured at
        z, filippov.scale)."""
        from .system import MODE_NAMES

        self._frozen_unchanged()
        if self._surfaces is not None:
            return self._surfaces_jacobian(mode, z, floor)
        key = MODE_NAMES.get(mode)
        if key == "sliding" and key not in self._jacobian_modes() and self.has_jacobians:
            return self._sliding_jacobian(np.ascontiguousarray(z, dtype=float), floor)
        if key not in self._jacobian_modes():
            raise ValueError(f"jacobian: no Jacobian of mode {mode!r} was given "
                             f"(have {sorted(self._jacobian_modes())})")
        n = len(self.names)
        z = np.ascontiguousarray(z, dtype=float)
        if z.shape != (n,):
            raise ValueError(f"jacobian: expected one state of shape ({n},), got {z.shape}")
        J = self._jacobian_value(key, z).reshape(n, n)
        if key in self._jacobians and key not in self._jacobians_checked:
            self._check_jacobian(key, z, J)
            self._jacobians_checked.add(key)
        return J

    def _surfaces_jacobian(self, mode: int, z, floor) -> np.ndarray:
        """dF/dz of a mode of several surfaces (filippov.surfaces_defined.mode_jacobian),
        each region's Jacobian compared with differences of its field when first used."""
        from .surfaces_defined import mode_jacobian

        n, system = len(self.names), self.python()
        z = np.ascontiguousarray(z, dtype=float)
        if z.shape != (n,):
            raise ValueError(f"jacobian: expected one state of shape ({n},), got {z.shape}")

        def region(sigma, zz):
            if sigma not in self._surfaces.jacobians:
                raise ValueError(f"jacobian: no Jacobian of region {sigma} was given (have "
                                 f"{sorted(self._surfaces.jacobians)})")
            J = np.asarray(self._surfaces.jacobians[sigma](zz, self.params), float)
            if J.size != n * n:
                raise SystemContractError(f"jacobians[{sigma}]: returned shape {J.shape} at "
                                          f"z={zz.tolist()}, expected ({n}, {n})")
            if sigma not in self._jacobians_checked:
                self._compare_jacobian(f"jacobians[{sigma}]", f"fields[{sigma}]",
                                       lambda x: system.region_field(sigma, x), zz,
                                       J.reshape(n, n))
                self._jacobians_checked.add(sigma)
            return J.reshape(n, n)

        floor = self._state_scale(z) if floor is None else floor
        return mode_jacobian(system, region, int(mode), z, floor)

    def _check_jacobian(self, key: str, z: np.ndarray, J: np.ndarray) -> None:
        """A Jacobian the user gave, against central differences of its field at the first
        state it is asked at (step eps^(1/3) times the state's size: errors ~1e-10 of the
        scale for a smooth field); a wrong one would give wrong multipliers and dP/dz with
        the flow's multiplier still 1. Refused where an entry is off by 1e-6 of the scale
        (that of J, and of F over the state's size)."""
        if key == "sliding":
            return   # Filippov's field off H is the caller's extension: not compared
        self._compare_jacobian(f"jacobians[{key!r}]", f"field_{key}",
                               getattr(self.python(), f"field_{key}"), z, J)

    def _compare_jacobian(self, piece: str, field_name: str, field, z, J) -> None:
        """:meth:`_check_jacobian` of the Jacobian ``piece`` of the field ``field``."""
        from .differences import fd_jacobian

        floor = self._state_scale(z)
        size = max(floor, float(np.abs(z).max()))
        fd = fd_jacobian(field, z, np.cbrt(np.finfo(float).eps), floor).astype(float)
        scale = max(np.abs(fd).max(), float(np.abs(field(z)).max()) / size, 1e-300)
        bad = np.abs(J - fd) > 1e-6 * scale
        if not np.all(np.isfinite(J)) or bad.any():
            i, k = np.argwhere(bad | ~np.isfinite(J))[0]
            raise SystemContractError(
                f"{piece}: at z={z.tolist()} its entry [{i}, {k}] is "
                f"{float(J[i, k])!r}, central differences of {field_name} give "
                f"{float(fd[i, k])!r}: a wrong Jacobian gives wrong multipliers and dP/dz "
                f"(the flow's multiplier stays 1)")

    def _state_scale(self, z: np.ndarray) -> float:
        """The state scale (filippov.scale): declared, or measured at z (about 24n
        evaluations: a run passes its own to :meth:`jacobian` as ``floor``)."""
        return scale_mod.of_system(view_at(self.python(), z), z).state

    def _sliding_jacobian(self, z: np.ndarray, floor: float | None = None) -> np.ndarray:
        """dF_s/dz of Filippov's sliding field F_s = (a F_+ - b F_-)/(a - b), a = g.F_-,
        b = g.F_+ (g = switch_grad), from the Jacobians of the two fields; the Hessian
        of the switching function (it moves g) by central differences of switch_grad
        (step eps^(1/3) times the state's size; exact for a planar switching surface)."""
        n = len(self.names)
        if z.shape != (n,):
            raise ValueError(f"jacobian: expected one state of shape ({n},), got {z.shape}")
        sysp = self.python()
        Fm, Fp = (np.asarray(sysp.field_minus(z), float), np.asarray(sysp.field_plus(z), float))
        Jm, Jp = (self._jacobian_value(k, z).reshape(n, n) for k in ("minus", "plus"))
        floor = self._state_scale(z) if floor is None else floor
        Hh = grad_derivative(sysp.switch_grad, z, floor)
        return sliding_jacobian(Fm, Fp, np.asarray(sysp.switch_grad(z), dtype=float), Jm, Jp,
                                Hh, z)

    def python(self):
        """The reference driver's PiecewiseSystem (built once, then reused)."""
        self._frozen_unchanged()
        if self._python is None:
            self._python = self._build_python()
        return self._python

    def _build_python(self):
        from .system import MINUS, PLUS, PiecewiseSystem

        if self._surfaces is not None:   # several surfaces: the reference engine's view
            from .surfaces_defined import reference_system

            return reference_system(self._surfaces, self.names, self.params,
                                    sliding=self.sliding, scale=self.scale,
                                    intersection=self.intersection,
                                    description=f"{self.name} (one definition, m = "
                                                f"{self.m} surfaces, compiled pieces)")

        n, p = len(self.names), self.params
        bp = self._batch_pieces()

        def vector(batch):
            def piece(z):
                zs, tail = _states(z, n)
                return batch(zs, p).reshape((n,) + tail)
            return piece

        def scalar(z):
            zs, tail = _states(z, n)
            out = bp["switch"](zs, p)
            return out.reshape(tail) if tail else float(out[0])

        flows = {}
        if bp["flow_plus"] is not None and bp["flow_minus"] is not None:
            for mode, key in ((PLUS, "flow_plus"), (MINUS, "flow_minus")):
                def flow(z0, tau, batch=bp[key]):
                    tau = np.asarray(tau, dtype=float)
                    out = batch(np.ascontiguousarray(z0, dtype=float),
                                np.ascontiguousarray(tau.reshape(-1)), p)
                    return out.reshape((n,) + tau.shape)
                flows[mode] = flow
        return PiecewiseSystem(names=self.names, field_minus=vector(bp["field_minus"]),
                               field_plus=vector(bp["field_plus"]), switch=scalar,
                               switch_grad=vector(bp["switch_grad"]), flows=flows,
                               sliding=self.sliding, sample_step=self.sample_step,
                               slow_sample_step=self.slow_sample_step,
                               transient_time=self.transient_time, scale=self.scale,
                               description=f"{self.name} (one definition, compiled pieces)")
