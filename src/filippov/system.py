"""The object the solver integrates: two smooth fields split by a switching function.

A :class:`PiecewiseSystem` is all the solver ever sees. Whether it came from a
slow-fast model (state ``z = (x, y)``, fields ``(f, g/eps)``) or from its reduced
system (state ``x``, ``y = y0(x)``) is decided by whoever built it; the solver
never knows which physics it runs.

Conventions (the paper's Eq. (1)): region ``+`` is ``H(z) >= 0``, region ``-`` is
``H(z) < 0``. All callables take a state with the components along axis 0, so
``z`` may be a vector ``(n,)`` or a batch ``(n, m)``; exact flows take a start
state ``(n,)`` and elapsed times ``tau`` (scalar or ``(m,)``). The full contract
is in :class:`PiecewiseSystem`; :func:`filippov.checks.check_system` tests it at
the start of every simulation.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from .scale import UNIT
from .spelling import one_spelling

MINUS, SLIDING, PLUS = -1, 0, 1

#: what a system with several switching functions is told (a FilippovSystem, a
#: SymbolicSystem or a PiecewiseSystem whose switch gives more than one value per state)
ONE_SURFACE = ("a system has one switching function h(z), one value per state (region + "
               "is h >= 0); several switching surfaces take a field per sign vector: "
               "FilippovSystem(names, fields=..., switch=..., switch_grad=...), "
               "SymbolicSystem(states, switch=[...], fields=...) or "
               "filippov.surfaces.SurfacesSystem (engine='reference')")
MODE_NAMES = {MINUS: "minus", SLIDING: "sliding", PLUS: "plus"}

Field = Callable[[np.ndarray], np.ndarray]
Flow = Callable[[np.ndarray, np.ndarray], np.ndarray]


@one_spelling
@dataclass(frozen=True)
class PiecewiseSystem:
    """A Filippov system ``dz/dt = F_-(z)`` if ``H(z) < 0`` else ``F_+(z)``.

    The pieces, for a system of ``n = len(names)`` components:

    * ``field_minus(z)``, ``field_plus(z)``: ``F_-``, ``F_+``;
    * ``switch(z)``: ``H``, smooth across ``H = 0``;
    * ``switch_grad(z)``: its gradient ``dH/dz`` (not a multiple, not of another
      function: its sign decides between crossing and sliding);
    * ``flows[mode](z0, tau)``: the exact flow of a mode from ``z0`` over the
      elapsed times ``tau``.

    Batch contract: the solver evaluates the pieces both on one state ``z`` of
    shape ``(n,)`` and on a batch ``z`` of shape ``(n, m)`` (m samples along a
    segment, any m >= 1, also m == n), components along axis 0. A piece must
    treat the samples independently and return the same trailing shape: fields
    and ``switch_grad`` ``(n,)`` or ``(n, m)``, ``switch`` a scalar or ``(m,)``.
    An exact flow takes ``z0`` of shape ``(n,)`` and ``tau`` a scalar or
    ``(m,)``, and returns ``(n,)`` or ``(n, m)``. Write pieces with ``z[i]`` for
    component i, reductions over ``axis=0``, and constant vectors that
    broadcast along the samples: ``A @ z - B`` with ``B`` of shape ``(n,)`` is
    wrong for a batch (``(n, m) - (n,)`` fails, or for m == n silently subtracts
    ``B[j]`` from sample j); write ``A @ z - B.reshape((-1,) + (1,) * (z.ndim - 1))``
    (``B[:, None]`` when z is a batch). :func:`filippov.simulate.simulate`
    checks this contract at its start (:mod:`filippov.checks`) and names the
    piece that breaks it.

    ``flows`` maps a mode (MINUS, PLUS, SLIDING) to an exact flow
    ``flow(z0, tau)``; a missing entry means that mode is integrated.
    ``sliding`` says whether the model includes Filippov sliding: when False and
    a trajectory reaches an attracting sliding region, the solver stops with an
    error instead of silently computing an effect the system was not built for.
    ``sample_step`` is the longest time between samples when an exact flow is
    scanned for events; it must resolve the fastest time scale (eps), and a
    system with exact flows needs one (finite, > 0) to be simulated with
    ``method="exact"``; the default (inf) suits a system without flows. A model
    whose fast time scale lives only in a relaxation after each mode entry
    declares how long that lasts (``transient_time``: after it the relaxation
    is below roundoff) and the sample step of its slow dynamics
    (``slow_sample_step``): an exact flow that stays longer than
    ``transient_time`` in one mode is scanned at the slow step from then on,
    so tiny eps does not cost O(1/eps) samples per unit time.
    """

    names: tuple[str, ...]
    field_minus: Field
    field_plus: Field
    switch: Callable[[np.ndarray], np.ndarray]
    switch_grad: Callable[[np.ndarray], np.ndarray]
    flows: Mapping[int, Flow] = field(default_factory=dict)
    sliding: bool = True
    sample_step: float = np.inf
    slow_sample_step: float = np.nan   # NaN: none (sample_step throughout)
    transient_time: float = np.inf
    units: Mapping[str, str] = field(default_factory=dict)
    description: str = ""
    #: the run's units (filippov.scale): a Scale, a number or a mapping as
    #: filippov.scale.declared reads them, or None (measured at each run's start); a
    #: system written here by hand is taken in units of its own size
    scale: object = UNIT

    @property
    def dim(self) -> int:
        return len(self.names)

    def field(self, mode: int, z: np.ndarray) -> np.ndarray:
        if mode == PLUS:
            return self.field_plus(z)
        if mode == MINUS:
            return self.field_minus(z)
        return self.sliding_field(z)

    def normal_speeds(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """``(a, b) = (dH.F_-, dH.F_+)``: the rates of change of H along each field.

        Attracting sliding needs a > 0 > b (Eq. (9)); a < 0 < b is repelling.
        """
        grad = self.switch_grad(z)
        a = np.sum(grad * self.field_minus(z), axis=0)
        b = np.sum(grad * self.field_plus(z), axis=0)
        return a, b

    def sliding_field(self, z: np.ndarray) -> np.ndarray:
        """Filippov's convex combination (Eq. (2)): tangent to H = 0."""
        grad, fm, fp = self.switch_grad(z), self.field_minus(z), self.field_plus(z)
        a, b = np.sum(grad * fm, axis=0), np.sum(grad * fp, axis=0)
        return (a * fp - b * fm) / (a - b)

    def speed_of_switch(self, mode: int, z: np.ndarray) -> np.ndarray:
        """dH/dt along the field of ``mode`` (zero in sliding, by construction)."""
        return np.sum(self.switch_grad(z) * self.field(mode, z), axis=0)

    def has_flow(self, mode: int) -> bool:
        return mode in self.flows
