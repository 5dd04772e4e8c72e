"""A Filippov system written once as SymPy expressions; its derivatives generated.

The hand-written route (:class:`~filippov.compiled_system.FilippovSystem`) asks for
the switching gradient as a separate piece, and Jacobians (for Floquet
multipliers, saltation matrices, dP/dz by variational equations) come from
central differences. Here the system is its expressions: the switching gradient,
the Jacobian of each field and of Filippov's sliding field are differentiated by
SymPy, and every piece is printed as Python source (common subexpressions
shared, :func:`sympy.cse`), compiled by numba and handed to
:class:`~filippov.compiled_system.FilippovSystem` -- so both engines run from
one definition, and the derivatives come from the same one.

A slow-fast system (:class:`SymbolicSlowFast`) is declared by its slow and fast
variables, ``f_-``, ``f_+``, ``g_-``, ``g_+``, ``h`` and the symbol ``eps``; the
slow-fast system ``(f, g/eps)`` and the reduced one (``y = y0(x)`` solved from
``g = 0`` at ``eps = 0``) both follow from it.

Why SymPy: the pieces of a Filippov model are short closed-form expressions;
symbolic differentiation gives the exact Jacobians at no run-time cost, the
generated source can be read (:meth:`SymbolicSystem.source`), and numba
compiles it like a hand-written piece. Automatic differentiation of numba code
has no well-kept library; complex-step breaks on ``abs``/comparisons.
"""
from __future__ import annotations

import copy
from typing import Mapping, Optional, Sequence

import numpy as np
import sympy as sp

from . import codegen
from . import scale as scale_mod
from .abi import CompiledModel, no_flow
from .compiled_system import FilippovSystem, _scalar_piece, _where_piece
from .errors import SymbolicError  # noqa: F401  (re-exported)
from .spelling import one_spelling

MODES = ("minus", "plus")


def _symbols(seq, what: str) -> tuple:
    out = tuple(seq)
    for s in out:
        if not isinstance(s, sp.Symbol):
            raise SymbolicError(f"{what}: expected SymPy symbols, got {s!r} "
                                f"({type(s).__name__})")
        try:
            codegen.check_name(s.name, what)
        except ValueError as exc:
            raise SymbolicError(str(exc)) from None
    if len(set(out)) != len(out):
        raise SymbolicError(f"{what}: a symbol appears twice in {list(out)}")
    return out


def _vector(exprs, n: int, piece: str) -> tuple:
    try:
        out = tuple(sp.sympify(e) for e in exprs)
    except (TypeError, sp.SympifyError) as exc:
        raise SymbolicError(f"{piece}: expected {n} SymPy expressions ({exc})") from None
    if len(out) != n:
        raise SymbolicError(f"{piece}: expected {n} expressions, one per state, got {len(out)}")
    return out


def _check_free(exprs, allowed: set, piece: str) -> None:
    for e in exprs:
        if e.has(sp.zoo, sp.nan, sp.oo, -sp.oo):
            raise SymbolicError(f"{piece}: the expression {e} is not finite")
        unknown = e.free_symbols - allowed
        if unknown:
            names = ", ".join(sorted(str(s) for s in unknown))
            raise SymbolicError(f"{piece}: unknown symbol(s) {names} (neither a state "
                                f"nor a parameter)")


#: functions that jump: inside a region's field or in the switch, a discontinuity the
#: engines neither locate nor slide along (a review: sign and Heaviside in a field ended
#: in the printer's raw error about their derivatives)
JUMPS = (sp.sign, sp.Heaviside, sp.DiracDelta, sp.floor, sp.ceiling, sp.frac)


def _check_smooth(exprs, piece: str) -> None:
    """Refuse a piece that jumps inside a region (:data:`JUMPS`), naming it."""
    for e in exprs:
        jumps = sorted({str(a) for a in sp.sympify(e).atoms(*JUMPS)})
        if jumps:
            raise SymbolicError(
                f"{piece}: {jumps[0]} jumps inside a region, where the engines neither "
                f"locate the jump nor slide along it: write it as a switching surface "
                f"(switch=..., or several surfaces with fields=...)")


_OPTIONS = {"sample_step": float, "slow_sample_step": float, "transient_time": float,
            "sliding": bool, "scale": lambda v: v}


@one_spelling
class SymbolicSystem:
    """A Filippov system ``z' = F_-(z)`` if ``h(z) < 0`` else ``F_+(z)``, in SymPy.

    Parameters
    ----------
    states : sequence of sympy.Symbol
        The state components, in order; their names name the system's components.
    field_minus, field_plus : sequence of sympy expressions
        ``F_-``, ``F_+`` (one expression per state).
    switch : sympy expression
        The switching function ``h``; region + is ``h >= 0``. One only: a list of
        several (several switching surfaces) is refused by name.
    params : mapping sympy.Symbol -> float, optional
        The parameters and their values (the generated pieces read them from the
        parameter array, in this order: :meth:`with_params` changes values without
        generating or compiling again).
    time : sympy.Symbol, optional
        The elapsed time in ``flows``.
    flows : mapping {"minus", "plus"} -> sequence of sympy expressions, optional
        Exact flows of both regions: each component at elapsed time ``time`` from
        the start state, written with the state symbols standing for the start.
    sample_step : float
        With exact flows: the longest time between samples (resolving the fastest
        time scale of the flows).
    slow_sample_step, transient_time : float
        A fast relaxation after each mode entry that is over after
        ``transient_time``, and the sample step of the slow dynamics from then on
        (see :class:`filippov.system.PiecewiseSystem`).
    sliding : bool
        Follow attracting sliding (Filippov's convex combination).
    scale : None, number, mapping or filippov.scale.Scale
        The units the engines measure tolerances in (:mod:`filippov.scale`): None
        measures them at each run's start; a number is the state's scale.
    name : str

    Attributes
    ----------
    switch_grad : tuple of sympy expressions
        ``dh/dz``, differentiated from ``switch``.
    sliding_field : tuple of sympy expressions or None
        Filippov's convex combination ``(a F_+ - b F_-) / (a - b)``, ``a = dh.F_-``,
        ``b = dh.F_+``; None when ``a - b`` vanishes identically (no sliding).
    jacobians : dict mode -> sympy.Matrix
        ``dF/dz`` of "minus", "plus" and (with a sliding field) "sliding".
    """

    def __init__(self, states: Sequence, field_minus=None, field_plus=None, switch=None, *,
                 params: Optional[Mapping] = None, time=None, flows: Optional[Mapping] = None,
                 sample_step: float = np.inf, slow_sample_step: float = np.nan,
                 transient_time: float = np.inf, sliding: bool = True, name: str = "user",
                 scale=None, fields=None, intersection=None):
        self.states = _symbols(states, "states")
        scale_mod.declared(scale)
        self.scale = scale   # the run's units (filippov.scale; None: measured)
        n = len(self.states)
        if n < 1:
            raise SymbolicError("states: at least one state")
        params = dict(params or {})
        self.param_symbols = _symbols(params, "params")
        values = np.array([float(v) for v in params.values()], dtype=float)
        if not np.all(np.isfinite(values)):
            bad = [str(s) for s, v in zip(self.param_symbols, values) if not np.isfinite(v)]
            raise SymbolicError(f"params: values of {', '.join(bad)} must be finite")
        clash = set(self.states) & set(self.param_symbols)
        if clash:
            raise SymbolicError(f"params: {sorted(map(str, clash))} are also states")
        self.param_values = values
        allowed = set(self.states) | set(self.param_symbols)
        self.sample_step, self.sliding, self.name = float(sample_step), bool(sliding), name
        self.slow_sample_step, self.transient_time = float(slow_sample_step), float(transient_time)
        self._system = None
        self._generated: dict = {}   # sources, shared by with_params/with_options copies
        self.m, self.intersection, self.fields = 1, intersection, None
        if fields is not None:
            field_minus, field_plus, switch = self._define_surfaces(
                fields, field_minus, field_plus, switch, allowed, bool(flows))
            if self.m > 1:
                return
        elif intersection is not None:
            raise SymbolicError("intersection: the sliding field on an intersection of "
                                "surfaces goes with several surfaces (fields=)")
        if field_minus is None or field_plus is None or switch is None:
            raise SymbolicError("field_minus, field_plus, switch: one switching surface "
                                "takes all three; several take switch=[...] and fields=")
        self.field_minus = _vector(field_minus, n, "field_minus")
        self.field_plus = _vector(field_plus, n, "field_plus")
        if isinstance(switch, (list, tuple, sp.MatrixBase)) and len(switch) != 1:
            from .system import ONE_SURFACE

            raise SymbolicError(f"switch: {len(switch)} expressions: {ONE_SURFACE}")
        self.switch = sp.sympify(switch[0] if isinstance(switch, (list, tuple, sp.MatrixBase))
                                 else switch)
        for piece, exprs in (("field_minus", self.field_minus),
                             ("field_plus", self.field_plus), ("switch", (self.switch,))):
            _check_free(exprs, allowed, piece)
            _check_smooth(exprs, piece)
        self.time = None
        self.flows = {}
        if flows:
            if time is None or not isinstance(time, sp.Symbol) or time in allowed:
                raise SymbolicError("time: exact flows need a time symbol that is neither a "
                                    "state nor a parameter")
            if set(flows) != set(MODES):
                raise SymbolicError(f"flows: give the flows of both regions "
                                    f"('minus' and 'plus'), got {sorted(flows)}")
            _symbols([time], "time")
            self.time = time
            for mode in MODES:
                self.flows[mode] = _vector(flows[mode], n, f"flows[{mode!r}]")
                _check_free(self.flows[mode], allowed | {time}, f"flows[{mode!r}]")
        z = sp.Matrix(self.states)
        self.switch_grad = tuple(sp.diff(self.switch, s) for s in self.states)
        grad = sp.Matrix(self.switch_grad)
        Fm, Fp = sp.Matrix(self.field_minus), sp.Matrix(self.field_plus)
        a, b = (grad.T * Fm)[0], (grad.T * Fp)[0]
        self.jacobians = {"minus": Fm.jacobian(z), "plus": Fp.jacobian(z)}
        # a - b = dh.(F_- - F_+) identically 0: the fields never point to opposite sides,
        # no sliding anywhere, and Filippov's field has no formula (it stays None)
        self.sliding_field = None
        if sp.expand(a - b) != 0:
            self.sliding_field = tuple((a * Fp - b * Fm) / (a - b))
            self.jacobians["sliding"] = sp.Matrix(self.sliding_field).jacobian(z)

    def _define_surfaces(self, fields, field_minus, field_plus, switch, allowed, flows):
        """Several switching surfaces: ``switch`` a list of m expressions, ``fields`` a
        mapping from sign vectors to expressions (or a function of the sign vector giving
        them); each region's Jacobian differentiated. m = 1 gives today's pieces
        (field_minus, field_plus, switch)."""
        from .surfaces import MAX_SURFACES, check_intersection, check_regions, regions
        from .surfaces_defined import sign_vector

        if field_minus is not None or field_plus is not None:
            raise SymbolicError("fields: give either field_minus and field_plus (one "
                                "switching surface) or fields (a field per sign vector)")
        if switch is None:
            raise SymbolicError("switch: missing; several surfaces take switch=[h1, h2, ...]")
        if flows:
            raise SymbolicError("flows: exact flows take one switching surface; with "
                                "fields= the fields are integrated")
        hs = list(switch) if isinstance(switch, (list, tuple, sp.MatrixBase)) else [switch]
        m = len(hs)
        if not 1 <= m <= MAX_SURFACES:
            raise SymbolicError(f"switch: {m} expressions; from 1 to {MAX_SURFACES} are taken")
        given = dict(fields) if isinstance(fields, Mapping) else {s: fields(s) for s in
                                                                   regions(m)}
        out = {}
        for key, exprs in given.items():
            try:
                sigma = sign_vector(key, m)
            except ValueError as exc:
                raise SymbolicError(str(exc)) from None
            out[sigma] = _vector(exprs, len(self.states), f"fields[{sigma}]")
            _check_free(out[sigma], allowed, f"fields[{sigma}]")
            _check_smooth(out[sigma], f"fields[{sigma}]")
        try:
            check_regions(out, m)
            check_intersection(self.intersection, m)
        except ValueError as exc:
            raise SymbolicError(str(exc)) from None
        if m == 1:
            return out[(-1,)], out[(1,)], hs[0]
        self.m, self.fields = m, out
        self.switch = tuple(sp.sympify(h) for h in hs)
        _check_free(self.switch, allowed, "switch")
        _check_smooth(self.switch, "switch")
        self.field_minus = self.field_plus = self.sliding_field = None
        self.time, self.flows = None, {}
        self.switch_grad = tuple(tuple(sp.diff(h, v) for v in self.states)
                                 for h in self.switch)
        z = sp.Matrix(self.states)
        self.jacobians = {s: sp.Matrix(f).jacobian(z) for s, f in out.items()}
        return None, None, None

    # ------------------------------------------------------------------ code
    def _pieces(self) -> dict:
        n = len(self.states)
        if self.m > 1:   # several surfaces: by region index (filippov.surfaces.regions)
            return self._surfaces_pieces()
        pieces = {"field_minus": ("vector", self.field_minus),
                  "field_plus": ("vector", self.field_plus),
                  "switch": ("scalar", (self.switch,)),
                  "switch_grad": ("vector", self.switch_grad)}
        for mode, J in self.jacobians.items():
            pieces[f"jacobian_{mode}"] = ("matrix", [J[k // n, k % n] for k in range(n * n)])
        z = list(self.states)
        for mode, exprs in self.flows.items():
            pieces[f"flow_{mode}"] = ("flow", exprs)
            # d flow / d z0, differentiated here: dP/dz through an exact stay without
            # differences (the compiled engine's flow_jacobian pieces)
            J = sp.Matrix(exprs).jacobian(z)
            pieces[f"flow_jacobian_{mode}"] = ("flow_matrix", [J[k // n, k % n]
                                                               for k in range(n * n)])
        return pieces

    def _surfaces_pieces(self) -> dict:
        from .surfaces import regions

        n, pieces = len(self.states), {}
        for i, sigma in enumerate(regions(self.m)):
            J = self.jacobians[sigma]
            pieces[f"field_r{i}"] = ("vector", self.fields[sigma])
            pieces[f"jacobian_r{i}"] = ("matrix", [J[k // n, k % n] for k in range(n * n)])
        for k, h in enumerate(self.switch):
            pieces[f"switch_{k}"] = ("scalar", (h,))
            pieces[f"switch_grad_{k}"] = ("vector", self.switch_grad[k])
        return pieces

    def source(self) -> str:
        """The generated Python source of every piece (what numba compiles)."""
        if "system" not in self._generated:
            self._generated["system"] = codegen.source(
                f"the system {self.name!r}", self.states, self.param_symbols, self._pieces(),
                time=self.time) + ("" if self.m > 1 else codegen.jacobian_dispatch(
                    "sliding" in self.jacobians))
        return self._generated["system"]

    def section_source(self, section, where=None) -> str:
        """The generated source of a section ``section = 0`` (an expression of the
        states and parameters) with the condition ``where`` (a SymPy relation) a hit
        must satisfy."""
        key = ("section", section, where)
        if key not in self._generated:
            self._generated[key] = self._section_source(section, where)
        return self._generated[key]

    def _section_source(self, section, where) -> str:
        allowed = set(self.states) | set(self.param_symbols)
        section = sp.sympify(section)
        _check_free([section], allowed, "section")
        pieces = {"section": ("scalar", (section,))}
        if where is not None:
            where = sp.sympify(where)
            if not isinstance(where, (sp.core.relational.Relational, sp.logic.boolalg.Boolean)):
                raise SymbolicError(f"where: expected a SymPy condition (e.g. x2 > 0), "
                                    f"got {where}")
            _check_free([where], allowed, "where")
            pieces["section_where"] = ("where", (where,))
        return codegen.source(f"a section of {self.name!r}", self.states, self.param_symbols,
                              pieces)

    def module(self):
        """The generated, compiled module (cached on disk; see :mod:`filippov.codegen`)."""
        return codegen.load(self.source())

    # ------------------------------------------------------------------ systems
    def system(self) -> "GeneratedSystem":
        """The :class:`~filippov.compiled_system.FilippovSystem` both engines run, its
        pieces the generated ones, with :meth:`~FilippovSystem.jacobian` exact."""
        if self._system is None:
            self._system = GeneratedSystem(self)
        return self._system

    # the views of a system defined once (filippov.contracts.DefinedOnce,
    # WithJacobians), those of :meth:`system`: the front doors take a SymbolicSystem as
    # they take the FilippovSystem it generates
    @property
    def names(self) -> tuple:
        return self.system().names

    def python(self):
        return self.system().python()

    def python_section(self, section, *, direction: int = 0, where=None,
                       name: str = "section", min_time: float = 0.0):
        return self.system().python_section(section, direction=direction, where=where,
                                            name=name, min_time=min_time)

    def compiled(self, section, *, direction: int = 0, where=None, probe=None):
        return self.system().compiled(section, direction=direction, where=where, probe=probe)

    @property
    def has_jacobians(self) -> bool:
        return self.system().has_jacobians

    def jacobian(self, mode: int, z, *, floor: float | None = None):
        return self.system().jacobian(mode, z, floor=floor)

    def with_params(self, **values) -> "SymbolicSystem":
        """The same expressions with other parameter values (by parameter name): a copy
        sharing the derivatives and the generated pieces (nothing is generated or
        compiled again)."""
        names = [str(s) for s in self.param_symbols]
        unknown = set(values) - set(names)
        if unknown:
            raise SymbolicError(f"with_params: unknown parameter(s) {sorted(unknown)}; "
                                f"the system has {sorted(names)}")
        new = np.array([float(values.get(k, v)) for k, v in zip(names, self.param_values)])
        if not np.all(np.isfinite(new)):
            raise SymbolicError(f"with_params: values must be finite, got {values}")
        other = copy.copy(self)
        other.param_values, other._system = new, None
        return other

    def with_options(self, **options) -> "SymbolicSystem":
        """A copy with other scan options (``sample_step``, ``slow_sample_step``,
        ``transient_time``, ``sliding``), sharing everything generated."""
        unknown = set(options) - set(_OPTIONS)
        if unknown:
            raise SymbolicError(f"with_options: unknown option(s) {sorted(unknown)}; "
                                f"expected {', '.join(_OPTIONS)}")
        other = copy.copy(self)
        for k, v in options.items():
            setattr(other, k, _OPTIONS[k](v))
        other._system = None
        return other

    @staticmethod
    def slow_fast(slow, fast, f_minus, f_plus, g_minus, g_plus, switch, *, eps, params,
                  time=None, flows=None, name: str = "user") -> "SymbolicSlowFast":
        """A slow-fast model ``x' = f(x, y)``, ``eps y' = g(x, y)`` in SymPy: its
        ``full()`` and ``reduced()`` systems are SymbolicSystems (see
        :class:`SymbolicSlowFast` for the arguments)."""
        return SymbolicSlowFast(slow, fast, f_minus, f_plus, g_minus, g_plus, switch,
                                eps=eps, params=params, time=time, flows=flows, name=name)


class GeneratedSystem(FilippovSystem):
    """A :class:`FilippovSystem` whose pieces are generated from a :class:`SymbolicSystem`:
    the compiled engine gets the generated pieces as they are (no adapters, cached on
    disk), and a section given as a SymPy expression is generated too."""

    def __init__(self, symbolic: SymbolicSystem):
        self.symbolic = symbolic
        self.mod = symbolic.module()
        super().__init__(tuple(str(s) for s in symbolic.states), None, None, None, None,
                         params=symbolic.param_values, sample_step=symbolic.sample_step,
                         slow_sample_step=symbolic.slow_sample_step,
                         transient_time=symbolic.transient_time,
                         sliding=symbolic.sliding, name=symbolic.name,
                         scale=symbolic.scale,
                         fields=symbolic.fields if symbolic.m > 1 else None,
                         intersection=symbolic.intersection)

    def _require(self, **pieces) -> None:
        pass   # the generated module has every piece

    def _define_surfaces(self, fields, *given):
        """Several surfaces: the generated pieces by region index (SymbolicSystem
        ._surfaces_pieces) as filippov.surfaces_defined's Pieces."""
        from .surfaces import regions
        from .surfaces_defined import Pieces, stacked

        mod, m, n = self.mod, self.symbolic.m, len(self.names)

        def jacobian(i):
            def J(z, p):
                out = np.empty(n * n)
                getattr(mod, f"jacobian_r{i}")(np.ascontiguousarray(z, dtype=float), p, out)
                return out.reshape(n, n)
            return J
        sigmas = regions(m)
        self.m, self._user_surfaces = m, dict(fields=None, switch=None, switch_grad=None,
                                             jacobians=None)
        self._surfaces = Pieces(
            m, {s: getattr(mod, f"field_r{i}_batch") for i, s in enumerate(sigmas)},
            stacked([getattr(mod, f"switch_{k}_batch") for k in range(m)]),
            stacked([getattr(mod, f"switch_grad_{k}_batch") for k in range(m)]),
            {s: jacobian(i) for i, s in enumerate(sigmas)})
        return None, None, None, None, None

    def _user_pieces(self) -> dict:
        raise AssertionError("a generated system has no user pieces")  # never called

    def _batch_pieces(self) -> dict:
        out = {k: getattr(self.mod, f"{k}_batch")
               for k in ("field_minus", "field_plus", "switch", "switch_grad")}
        for k in ("flow_minus", "flow_plus"):
            out[k] = getattr(self.mod, f"{k}_batch", None)
        return out

    def _jacobian_modes(self) -> set:
        return set(self.symbolic.jacobians)

    def _jacobian_value(self, key: str, z: np.ndarray) -> np.ndarray:
        out = np.empty(z.size * z.size)
        getattr(self.mod, f"jacobian_{key}")(z, self.params, out)
        return out

    def _section_pieces(self, section, where):
        """(section, section_where) in the ABI: generated from expressions, or the
        caller's functions of (z, p) compiled."""
        if isinstance(section, sp.Basic):
            mod = codegen.load(self.symbolic.section_source(section, where))
            return mod.section, getattr(mod, "section_where", None)
        if isinstance(where, sp.Basic):
            raise SymbolicError("where: a SymPy condition goes with a SymPy section")
        return _scalar_piece(section, "section"), (None if where is None else
                                                   _where_piece(where, "section_where"))

    def compiled(self, section, *, direction: int = 0, where=None, probe=None) -> CompiledModel:
        """The compiled engine's model with the section ``section = 0``: a SymPy
        expression of the states and parameters (``where`` a SymPy condition), or a
        function ``section(z, p)`` (``where(z, p)``) like :class:`FilippovSystem`'s."""
        from .abi import always

        self._one_surface_only("the compiled engine")
        if direction not in (-1, 0, 1):
            raise ValueError(f"direction must be -1, 0 or +1, got {direction!r}")
        sec, wh = self._section_pieces(section, where)
        m, exact = self.mod, bool(self.symbolic.flows)
        return CompiledModel(
            name=self.name, names=self.names, params=self.params,
            flow_plus=m.flow_plus if exact else no_flow,
            flow_minus=m.flow_minus if exact else no_flow,
            field_plus=m.field_plus, field_minus=m.field_minus, switch=m.switch,
            switch_grad=m.switch_grad, section=sec, section_where=wh or always, scale=self.scale,
            section_direction=int(direction), sample_step=self.sample_step,
            slow_sample_step=self.slow_sample_step, transient_time=self.transient_time,
            sliding=self.sliding, exact=exact, jacobian=m.jacobian,
            flow_jacobian_plus=m.flow_jacobian_plus if exact else None,
            flow_jacobian_minus=m.flow_jacobian_minus if exact else None,
            parameters={str(k): float(v) for k, v in zip(self.symbolic.param_symbols,
                                                         self.params)})

    def python_section(self, section, *, direction: int = 0, where=None, name: str = "section",
                       min_time: float = 0.0):
        """The reference driver's section; ``section``/``where`` as for :meth:`compiled`."""
        if isinstance(where, sp.Basic):
            if not isinstance(section, sp.Basic):
                raise SymbolicError("where: a SymPy condition goes with a SymPy section")
            where = codegen.load(self.symbolic.section_source(section, where)).section_where
        return super().python_section(section, direction=direction, where=where, name=name,
                                      min_time=min_time)

    def _section_batch(self, section):
        if isinstance(section, sp.Basic):
            return codegen.load(self.symbolic.section_source(section)).section_batch
        return super()._section_batch(section)


def _regions(flows):
    """The flows of regions - and +: the compiled engine integrates sliding (a sliding
    flow serves the reference driver's model only)."""
    return None if not flows else {m: flows[m] for m in MODES}


@one_spelling
class SymbolicSlowFast:
    """A slow-fast Filippov model (the paper's Eqs. (3), (4)) in SymPy.

    ``x' = f_+(x, y)``, ``eps y' = g_+(x, y)`` where ``h(x, y) >= 0``, else with
    ``f_-``, ``g_-``. :meth:`full` is the slow-fast system in ``z = (x, y)``;
    :meth:`reduced` the quasi-static one in ``x`` with ``y = y0(x)`` solved by SymPy
    from ``g = 0`` at ``eps = 0`` (the same root on both sides of the switch);
    :meth:`model` the :class:`~filippov.model.SlowFastModel` of the reference
    driver, its pieces generated as NumPy code.

    Parameters
    ----------
    slow, fast : sequence of sympy.Symbol
    f_minus, f_plus : sequence of sympy expressions (one per slow variable)
    g_minus, g_plus : sequence of sympy expressions (one per fast variable)
    switch : sympy expression, ``h(x, y)``
    eps : sympy.Symbol
        The small parameter (a key of ``params``).
    params : mapping sympy.Symbol -> float
        Parameters and their default values (in this order in the parameter array).
    time : sympy.Symbol, optional
        The elapsed time in ``flows``.
    flows : mapping, optional
        Exact flows: ``{"full": {"minus": [...], "plus": [...]}, "reduced": {...}}``,
        each component a function of the start state (the state symbols) and ``time``;
        either kind may be missing (that system is then integrated). A ``"sliding"``
        flow (on the switching surface) serves :meth:`model` (the reference driver);
        the compiled engine integrates sliding.
    """

    def __init__(self, slow, fast, f_minus, f_plus, g_minus, g_plus, switch, *, eps,
                 params: Mapping, time=None, flows: Optional[Mapping] = None,
                 name: str = "user"):
        self.slow, self.fast = _symbols(slow, "slow"), _symbols(fast, "fast")
        self.f_minus = _vector(f_minus, len(self.slow), "f_minus")
        self.f_plus = _vector(f_plus, len(self.slow), "f_plus")
        self.g_minus = _vector(g_minus, len(self.fast), "g_minus")
        self.g_plus = _vector(g_plus, len(self.fast), "g_plus")
        if isinstance(switch, (list, tuple, sp.MatrixBase)) and len(switch) != 1:
            from .system import ONE_SURFACE

            raise SymbolicError(f"switch: {len(switch)} expressions: {ONE_SURFACE}")
        self.switch = sp.sympify(switch[0] if isinstance(switch, (list, tuple, sp.MatrixBase))
                                 else switch)
        if not isinstance(eps, sp.Symbol) or eps not in params:
            raise SymbolicError("eps: the small parameter must be a symbol among params")
        self.eps, self.params, self.name = eps, dict(params), name
        self.time, self.flows = time, dict(flows or {})
        self._generated: dict = {}   # y0 and the NumPy source, derived once
        unknown = set(self.flows) - {"full", "reduced"}
        if unknown:
            raise SymbolicError(f"flows: unknown system kind(s) {sorted(unknown)}; expected "
                                f"'full' and/or 'reduced'")
        for kind, modes in self.flows.items():
            bad = set(modes) - {"minus", "plus", "sliding"}
            if bad or not {"minus", "plus"} <= set(modes):
                raise SymbolicError(f"flows[{kind!r}]: expected the flows of 'minus' and "
                                    f"'plus' (and optionally 'sliding'), got {sorted(modes)}")

    def _params(self, values: Mapping, *, reduced: bool = False) -> dict:
        names = {str(s): s for s in self.params}
        unknown = set(values) - set(names)
        if unknown:
            raise SymbolicError(f"unknown parameter(s) {sorted(unknown)}; the model has "
                                f"{sorted(names)}")
        out = {s: float(values.get(str(s), v)) for s, v in self.params.items()}
        if reduced:
            out.pop(self.eps)
        return out

    def full(self, *, exact: bool = True, values: Optional[Mapping] = None,
             **options) -> SymbolicSystem:
        """The slow-fast system ``z = (x, y)``, fields ``(f, g/eps)``; needs eps > 0.
        ``exact``: with the declared exact flows (else integrated); ``values``:
        parameter values by name; ``options``: of :class:`SymbolicSystem`."""
        params = self._params(values or {})
        if not params[self.eps] > 0:
            raise SymbolicError(f"eps: the slow-fast system needs eps > 0, got "
                                f"{params[self.eps]!r} (use reduced() for eps = 0)")
        e = self.eps
        flows = _regions(self.flows.get("full")) if exact else None
        return SymbolicSystem(self.slow + self.fast,
                              self.f_minus + tuple(g / e for g in self.g_minus),
                              self.f_plus + tuple(g / e for g in self.g_plus), self.switch,
                              params=params, time=self.time if flows else None, flows=flows,
                              name=f"{self.name} (slow-fast)", **options)

    def quasi_static(self) -> dict:
        """``{y_i: y0_i(x)}``: the root of ``g(x, y) = 0`` at ``eps = 0``, the same for
        ``g_-`` and ``g_+``; refused when SymPy finds no unique root."""
        if "y0" not in self._generated:
            self._generated["y0"] = self._quasi_static()
        return dict(self._generated["y0"])

    def _quasi_static(self) -> dict:
        roots = []
        for side, g in (("g_minus", self.g_minus), ("g_plus", self.g_plus)):
            eqs = [gi.subs(self.eps, 0) for gi in g]
            sol = sp.solve(eqs, self.fast, dict=True)
            if len(sol) != 1 or set(sol[0]) != set(self.fast):
                raise SymbolicError(f"{side}: g = 0 at eps = 0 has {len(sol)} solution(s) for "
                                    f"{list(map(str, self.fast))}; the reduced system needs "
                                    f"exactly one")
            roots.append(sol[0])
        if any(sp.simplify(roots[0][y] - roots[1][y]) != 0 for y in self.fast):
            raise SymbolicError("g_minus, g_plus: their quasi-static roots y0(x) differ; "
                                "the reduced system needs one slow manifold across the switch")
        return roots[0]

    def reduced(self, *, exact: bool = True, values: Optional[Mapping] = None,
                **options) -> SymbolicSystem:
        """The quasi-static system in ``x`` (``y = y0(x)``, eps = 0)."""
        y0 = self.quasi_static()
        sub = lambda e: e.subs(y0).subs(self.eps, 0)  # noqa: E731
        flows = _regions(self.flows.get("reduced")) if exact else None
        return SymbolicSystem(self.slow, [sub(f) for f in self.f_minus],
                              [sub(f) for f in self.f_plus], sub(self.switch),
                              params=self._params(values or {}, reduced=True),
                              time=self.time if flows else None, flows=flows,
                              name=f"{self.name} (reduced)", **options)

    def numpy_source(self) -> str:
        """Generated NumPy source of the :class:`~filippov.model.SlowFastModel` pieces:
        ``f(x, y, p)``, ``g(x, y, p)``, ``h``, ``h_grad`` (its x and y parts),
        ``y0(x, p)``, its Jacobian, and the exact flows ``(z0, tau, p)``."""
        if "numpy" not in self._generated:     # printed once (SymPy takes ~40 ms)
            self._generated["numpy"] = self._numpy_source()
        return self._generated["numpy"]

    def _numpy_source(self) -> str:
        x, y, ps = list(self.slow), list(self.fast), list(self.params)
        nx, ny = len(x), len(y)
        xy = [("_x", x), ("_y", y), ("_p", ps)]
        y0 = self.quasi_static()
        fns = [(k, xy, exprs, (len(exprs),), "_x[0]") for k, exprs in (
            ("f_minus", self.f_minus), ("f_plus", self.f_plus),
            ("g_minus", self.g_minus), ("g_plus", self.g_plus))]
        fns += [("h", xy, [self.switch], (), "_x[0]"),
                ("h_grad_x", xy, [sp.diff(self.switch, v) for v in x], (nx,), "_x[0]"),
                ("h_grad_y", xy, [sp.diff(self.switch, v) for v in y], (ny,), "_x[0]"),
                ("y0", [("_x", x), ("_p", ps)], [y0[v] for v in y], (ny,), "_x[0]"),
                ("y0_jac", [("_x", x), ("_p", ps)], [sp.diff(y0[v], u) for v in y for u in x],
                 (ny, nx), "_x[0]")]
        for kind, states in (("full", x + y), ("reduced", x)):
            for mode, exprs in self.flows.get(kind, {}).items():
                fns.append((f"flow_{kind}_{mode}", [("_z0", states), ("_tau", self.time),
                                                     ("_p", ps)], exprs, (len(states),), "_tau"))
        return codegen.numpy_source(f"the slow-fast model {self.name!r}", fns)

    def model(self, values: Optional[Mapping] = None, **options):
        """The reference driver's :class:`~filippov.model.SlowFastModel` at the parameter
        ``values`` (by name; defaults from ``params``); ``options`` are its sampling
        fields (``sample_step_full``, ``transient_time_full``, ``units``, ...)."""
        from .model import SlowFastModel
        from .system import MINUS, PLUS, SLIDING

        params = self._params(values or {})
        p = tuple(params.values())
        mod = codegen.load_numpy(self.numpy_source())
        bind = lambda fn: (lambda *args: fn(*args, p))  # noqa: E731

        def h_grad(x, y):
            return mod.h_grad_x(x, y, p), mod.h_grad_y(x, y, p)

        def flow(fn):
            return lambda z0, tau: fn(z0, np.asarray(tau, dtype=float), p)

        codes = {"minus": MINUS, "plus": PLUS, "sliding": SLIDING}
        flows = {kind: {codes[m]: flow(getattr(mod, f"flow_{kind}_{m}")) for m in modes}
                 for kind, modes in self.flows.items()
                 if kind == "reduced" or params[self.eps] > 0}
        return SlowFastModel(
            name=self.name, slow_names=tuple(map(str, self.slow)),
            fast_names=tuple(map(str, self.fast)), f_minus=bind(mod.f_minus),
            f_plus=bind(mod.f_plus), switch=bind(mod.h), switch_grad=h_grad, g_minus=bind(mod.g_minus),
            g_plus=bind(mod.g_plus), eps=params[self.eps], y0=bind(mod.y0),
            y0_jac=bind(mod.y0_jac), exact_flows=flows,
            parameters={str(k): v for k, v in params.items()}, **options)
