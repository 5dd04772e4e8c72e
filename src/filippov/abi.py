"""The compiled ABI: what a model hands the compiled engine (:mod:`filippov.fastmap`).

A model for the compiled engine is a :class:`CompiledModel`: numba-compiled pieces with
the signatures below, its parameters and its sampling scales. Models and user systems
import this module, never the engine: the engine can change its insides (stepper, scan,
driver) without any model noticing.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Mapping

import numpy as np
from numba import njit, types

from .scale import UNIT
from .spelling import one_spelling

_vec = types.float64[::1]
#: ``flow(z0, tau, params, out)``: the exact flow of a region from ``z0`` over ``tau``.
FLOW_SIG = types.void(_vec, types.float64, _vec, _vec)
#: ``field(z, params, out)`` (also ``grad_h``).
FIELD_SIG = types.void(_vec, _vec, _vec)
#: ``switch(z, params)`` and ``section(z, params)``.
SCALAR_SIG = types.float64(_vec, _vec)
#: ``where(z, params)``: the condition a section hit must satisfy.
WHERE_SIG = types.boolean(_vec, _vec)
#: ``flow_jacobian(z0, tau, params, out)`` (a flow's signature, ``out`` n*n): the
#: derivative of a region's exact flow from ``z0`` over ``tau`` with respect to ``z0``, row
#: by row.
#: ``jacobian(mode, z, params, out)``: dF/dz of the field of ``mode`` (-1 region -,
#: 0 Filippov's sliding field, +1 region +) at z, row by row into ``out`` (n*n).
JAC_SIG = types.void(types.int64, _vec, _vec, _vec)


#: the pieces of a :class:`CompiledModel` with their signatures, in the order the
#: compiled engine takes them (its kernel's arguments, and the index it calls each by)
PIECES = (("flow_plus", FLOW_SIG), ("flow_minus", FLOW_SIG), ("field_plus", FIELD_SIG),
          ("field_minus", FIELD_SIG), ("switch", SCALAR_SIG), ("switch_grad", FIELD_SIG),
          ("section", SCALAR_SIG), ("section_where", WHERE_SIG), ("jacobian", JAC_SIG),
          ("flow_jacobian_plus", FLOW_SIG), ("flow_jacobian_minus", FLOW_SIG))


@njit(FLOW_SIG, cache=True)
def no_flow(z0, tau, p, out):
    """Stands in for the flows of a model without them (never called: exact=False)."""
    for k in range(out.size):
        out[k] = np.nan


@njit(JAC_SIG, cache=True)
def no_jacobian(mode, z, p, out):
    """Stands in for the Jacobian of a model without one (never called: the engine
    takes Jacobian-vector products by central differences of the field instead)."""
    for k in range(out.size):
        out[k] = np.nan


@njit(WHERE_SIG, cache=True)
def always(z, p):
    """The ``section_where`` of a section without a condition: every hit counts."""
    return True


@one_spelling
@dataclass(frozen=True)
class CompiledModel:
    """A piecewise system (region + is ``switch >= 0``) and a section, as numba-compiled
    functions with the module's signatures; with exact flows in both regions
    (``exact=True``), or integrated there with DOP853 like sliding (``exact=False``,
    the flows are then :func:`no_flow`).

    ``flow_plus``/``flow_minus``: :data:`FLOW_SIG`; ``field_plus``/``field_minus``/
    ``switch_grad``: :data:`FIELD_SIG`; ``switch``/``section``: :data:`SCALAR_SIG`;
    ``section_where``: :data:`WHERE_SIG`. Every piece receives ``params``.
    ``section_direction`` -1 counts decreasing crossings of ``section(z) = 0``,
    +1 increasing, 0 both. ``sample_step`` is the longest time between samples
    of an exact flow (it must resolve the fastest time scale; unused when
    ``exact`` is False); ``slow_sample_step`` and ``transient_time`` as for
    :class:`filippov.system.PiecewiseSystem` (the slow step once the fast
    relaxation after a mode entry has decayed).
    """

    name: str
    names: tuple
    params: np.ndarray
    flow_plus: Any
    flow_minus: Any
    field_plus: Any
    field_minus: Any
    switch: Any
    switch_grad: Any
    section: Any
    section_where: Any
    section_direction: int
    sample_step: float
    sliding: bool = True
    parameters: Mapping[str, float] = field(default_factory=dict)
    exact: bool = True
    slow_sample_step: float = np.nan   # see filippov.system.PiecewiseSystem
    transient_time: float = np.inf
    #: optional :data:`JAC_SIG` piece: exact Jacobians for dP/dz through integrated stays
    #: (None: Jacobian-vector products by central differences of the field)
    jacobian: Any = None
    #: optional :data:`FLOW_SIG` pieces, both or neither (with exact flows): the exact
    #: flows' derivatives d flow / d z0, n*n row by row, for dP/dz through exact stays
    #: (None: Richardson's extrapolation of central differences of the flows)
    flow_jacobian_plus: Any = None
    flow_jacobian_minus: Any = None
    #: what numba compiled into the user's pieces from globals and closures, checked by
    #: the compiled engine's front doors before every call (:mod:`filippov.frozen`)
    frozen_reads: tuple = field(default=(), compare=False, repr=False)
    #: the run's units (filippov.scale; None: measured at the starts); a model written
    #: here by hand is taken in units of its own size
    scale: Any = UNIT

    @property
    def dim(self) -> int:
        return len(self.names)
