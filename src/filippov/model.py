"""Slow-fast Filippov models (Eqs. (3), (4)) and their reduced systems.

A model is written once, in the paper's terms: slow fields ``f_-(x, y)`` and
``f_+(x, y)``, a switching function ``h(x, y)`` that may depend on the fast
state, fast fields ``g_-(x, y)``, ``g_+(x, y)`` and ``eps``. The same model then
gives either

* :meth:`SlowFastModel.full` -- the slow-fast system in ``z = (x, y)`` with
  fields ``(f, g/eps)``, or
* :meth:`SlowFastModel.reduced` -- the quasi-static system (Eq. (6)) in
  ``z = x`` with ``y = y0(x)`` the root of ``g = 0`` at ``eps = 0``,

so that a scene asks for exactly the system it needs.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from .spelling import one_spelling
from .system import PiecewiseSystem

Fn = Callable[..., np.ndarray]


#: fast relaxation times (eps) after which an exp(-t/eps) transient is below
#: double resolution (exp(-40) = 4e-18): the models' ``transient_time`` in units of eps
TRANSIENT = 40.0


@one_spelling
@dataclass(frozen=True)
class SlowFastModel:
    """Components take ``x`` with shape ``(nx, ...)`` and ``y`` with ``(ny, ...)``.

    ``switch(x, y)`` is the switching function h, ``switch_grad(x, y)`` returns
    ``(dh/dx, dh/dy)``; ``y0_jac(x)`` returns
    ``dy0/dx`` with shape ``(ny, nx, ...)``. Exact flows are optional, per
    system kind ("full", "reduced") and per mode.
    """

    name: str
    slow_names: tuple[str, ...]
    fast_names: tuple[str, ...]
    f_minus: Fn
    f_plus: Fn
    switch: Fn
    switch_grad: Fn
    g_minus: Fn
    g_plus: Fn
    eps: float
    y0: Fn
    y0_jac: Fn
    exact_flows: Mapping[str, Mapping[int, Callable]] = field(default_factory=dict)
    sample_step_full: float = np.inf
    sample_step_reduced: float = np.inf
    # see PiecewiseSystem: the slow-fast system's slow sample step, used once the
    # fast relaxation after a mode entry has decayed (after transient_time_full)
    slow_sample_step_full: float = np.nan
    transient_time_full: float = np.inf
    units: Mapping[str, str] = field(default_factory=dict)
    parameters: Mapping[str, float] = field(default_factory=dict)

    def __post_init__(self):
        if not (np.isfinite(self.eps) and self.eps >= 0):
            raise ValueError(f"eps must be a finite number >= 0, got {self.eps!r}")

    @property
    def nx(self) -> int:
        return len(self.slow_names)

    def split(self, z: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        return z[: self.nx], z[self.nx:]

    def full(self, *, sliding: bool = True, exact: bool = True) -> PiecewiseSystem:
        """The slow-fast system; needs eps > 0."""
        if self.eps <= 0:
            raise ValueError("eps must be > 0 for the slow-fast system; "
                             "use the reduced system for eps = 0")
        eps, split = self.eps, self.split

        def fm(z):
            x, y = split(z)
            return np.concatenate([self.f_minus(x, y), self.g_minus(x, y) / eps])

        def fp(z):
            x, y = split(z)
            return np.concatenate([self.f_plus(x, y), self.g_plus(x, y) / eps])

        def H(z):
            x, y = split(z)
            return self.switch(x, y)

        def dH(z):
            x, y = split(z)
            hx, hy = self.switch_grad(x, y)
            return np.concatenate([hx, hy])

        flows = dict(self.exact_flows.get("full", {})) if exact else {}
        return PiecewiseSystem(
            names=self.slow_names + self.fast_names, field_minus=fm, field_plus=fp,
            switch=H, switch_grad=dH, flows=flows, sliding=sliding,
            sample_step=self.sample_step_full, slow_sample_step=self.slow_sample_step_full,
            transient_time=self.transient_time_full, units=self.units,
            description=f"{self.name}: slow-fast system, eps={eps!r}")

    def reduced(self, *, sliding: bool = True, exact: bool = True) -> PiecewiseSystem:
        """The quasi-static system in x alone, y replaced by y0(x)."""

        def fm(x):
            return self.f_minus(x, self.y0(x))

        def fp(x):
            return self.f_plus(x, self.y0(x))

        def H(x):
            return self.switch(x, self.y0(x))

        def dH(x):
            y = self.y0(x)
            hx, hy = self.switch_grad(x, y)
            # chain rule: dh/dx + (dy0/dx)^T dh/dy
            return hx + np.einsum("j...,ji...->i...", hy, self.y0_jac(x))

        flows = dict(self.exact_flows.get("reduced", {})) if exact else {}
        return PiecewiseSystem(
            names=self.slow_names, field_minus=fm, field_plus=fp, switch=H,
            switch_grad=dH, flows=flows, sliding=sliding,
            sample_step=self.sample_step_reduced, units=self.units,
            description=f"{self.name}: reduced system (eps=0)")

    def system(self, kind: str, *, sliding: bool = True, exact: bool = True) -> PiecewiseSystem:
        """``kind`` is "slow_fast" (alias "full") or "reduced"."""
        if kind in ("slow_fast", "full"):
            return self.full(sliding=sliding, exact=exact)
        if kind == "reduced":
            return self.reduced(sliding=sliding, exact=exact)
        raise ValueError(f"unknown system kind {kind!r}: expected 'slow_fast' or 'reduced'")
