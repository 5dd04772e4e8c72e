"""A Filippov system with several switching surfaces: its definition, its modes, and
the one-surface views a run is made of (the problem's definition, engine-free).

m switching functions ``h_k(z)`` split the state space into up to 2**m regions, each
named by its *sign vector* ``sigma`` (``sigma_k = +1`` where ``h_k >= 0``, the convention
of one surface), each with its own field ``F_sigma``. A run's *mode* is one integer, the
balanced-ternary number of its digits: digit k is ``sigma_k`` in a region, and 0 while
the orbit slides on surface k (:func:`mode_of`, :func:`digits`). For m = 1 the code is
today's MINUS (-1), SLIDING (0), PLUS (+1).

What a run does next depends, at any time, on one surface only, or it is refused by
name: in region sigma the orbit leaves through the nearest surface it reaches, so the
region's boundary is the zero set of ``min_k sigma_k h_k`` (:func:`region_view`); while
sliding on surface k only h_k and the two fields beside it matter (:func:`slide_view`),
until the slide reaches another surface (an intersection: :mod:`filippov.several`). Each
view is a :class:`~filippov.system.PiecewiseSystem`, which the one-surface engine runs
as it is, with every rule of the book (docs/decisions.md#several-surfaces-as-stays).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, Mapping

import numpy as np

from .scale import UNIT
from .system import PiecewiseSystem

__all__ = ["MAX_SURFACES", "SurfacesSystem", "digits", "flip", "mode_name", "mode_of",
           "region_view", "regions", "slide_view", "view_at"]

#: the most surfaces a system may have here: a mode's code (3**m values) then fits the
#: int8 a trajectory samples its modes in (Trajectory.sample)
MAX_SURFACES = 5


def mode_of(digits) -> int:
    """The mode code of the digits (each -1, 0 or +1; digit k at 3**k)."""
    return int(sum(int(d) * 3 ** k for k, d in enumerate(digits)))


def digits(mode: int, m: int) -> tuple:
    """The m digits of a mode code (inverse of :func:`mode_of`)."""
    out, rest = [], int(mode)
    for _ in range(m):
        d = (rest + 1) % 3 - 1
        out.append(d)
        rest = (rest - d) // 3
    return tuple(out)


def mode_name(mode: int, m: int) -> str:
    """A mode as its digits, surface 1 first: ``+-`` a region, ``+0`` sliding on h2."""
    return "".join("-0+"[d + 1] for d in digits(mode, m))


def flip(sigma: tuple, k: int) -> tuple:
    """The region across surface k from region ``sigma``."""
    return sigma[:k] + (-sigma[k],) + sigma[k + 1:]


def _column(v: np.ndarray, z: np.ndarray) -> np.ndarray:
    """``v`` of shape (m,) shaped to broadcast against values of shape (m,) or (m, b)."""
    return v.reshape((-1,) + (1,) * (z.ndim - 1))


@dataclass(frozen=True)
class SurfacesSystem:
    """``dz/dt = F_sigma(z)`` in the region whose sign vector is ``sigma``.

    * ``switches(z)``: the m values ``h_k(z)``, shape ``(m,)`` for a state ``(n,)`` and
      ``(m, b)`` for a batch ``(n, b)``; each smooth across its zero set;
    * ``switch_grads(z)``: their gradients, ``(m, n)`` or ``(m, n, b)``;
    * ``field``: ``field(sigma, z)`` for a sign vector ``sigma`` (a tuple of m values
      +-1), or a mapping from sign vectors to functions ``f(z)``; shape as ``z``.

    The batch contract is that of :class:`~filippov.system.PiecewiseSystem`. ``sliding``
    says whether Filippov sliding on a surface is part of the model; ``scale`` as there.
    """

    names: tuple
    switches: Callable[[np.ndarray], np.ndarray]
    switch_grads: Callable[[np.ndarray], np.ndarray]
    field: object
    m: int
    sliding: bool = True
    units: Mapping[str, str] = field(default_factory=dict)
    description: str = ""
    scale: object = UNIT
    #: the sliding field on an intersection of two surfaces where the system does not
    #: settle it (filippov.intersection): None (refused there), or "bilinear" (Dieci and
    #: Lopez's bilinear interpolation)
    intersection: str | None = None

    def __post_init__(self):
        m = self.m
        if isinstance(m, bool) or not isinstance(m, (int, np.integer)) or not (
                1 <= m <= MAX_SURFACES):
            raise ValueError(f"m: the number of switching surfaces must be an integer from 1 "
                             f"to {MAX_SURFACES}, got {m!r}")
        if self.intersection not in INTERSECTIONS:
            check_intersection(self.intersection, m)
        for name in ("switches", "switch_grads"):
            if not callable(getattr(self, name)):
                raise TypeError(f"{name}: expected a function of the state")
        f = self.field
        if isinstance(f, Mapping):
            want = set(regions(m))
            keys = {tuple(int(s) for s in k) if np.ndim(k) == 1 else k for k in f}
            if not keys <= want:
                bad = sorted(map(str, keys - want))[0]
                raise ValueError(f"field: {bad} is not a sign vector of {m} values +-1")
            if keys != want:
                missing = sorted(want - keys)[0]
                raise ValueError(f"field: no field for region {missing} (one per sign "
                                 f"vector: {2 ** m} regions)")
            if not all(callable(v) for v in f.values()):
                raise TypeError("field: every region's field must be a function f(z)")
        elif not callable(f):
            raise TypeError("field: expected field(sigma, z) or a mapping from sign vectors "
                            "to functions f(z)")
        # the views a run asks for, built once: the engine's contract check of a system
        # is then made once per view (checks.check_system keeps the systems it passed)
        object.__setattr__(self, "_views", {})
        # asked at every evaluation of a field: isinstance on a typing ABC is slow
        object.__setattr__(self, "_by_region", isinstance(f, Mapping))

    @property
    def dim(self) -> int:
        return len(self.names)

    def region_field(self, sigma: tuple, z: np.ndarray) -> np.ndarray:
        """``F_sigma(z)``."""
        if self._by_region:
            return self.field[sigma](z)
        return self.field(sigma, z)

    def values(self, z: np.ndarray) -> np.ndarray:
        """The m switching values at z, checked for their shape."""
        h = np.asarray(self.switches(z), dtype=float)
        want = (self.m,) + np.shape(z)[1:]
        if h.shape != want:
            raise ValueError(f"switches: returned shape {h.shape} for a state of shape "
                             f"{np.shape(z)}, expected {want} (m = {self.m} values per state)")
        return h

    def grads(self, z: np.ndarray) -> np.ndarray:
        """The m gradients at z, checked for their shape."""
        g = np.asarray(self.switch_grads(z), dtype=float)
        want = (self.m, self.dim) + np.shape(z)[1:]
        if g.shape != want:
            raise ValueError(f"switch_grads: returned shape {g.shape} for a state of shape "
                             f"{np.shape(z)}, expected {want}")
        return g

    def region(self, z: np.ndarray) -> tuple:
        """The sign vector of a state (+1 where h_k >= 0)."""
        return tuple(1 if v >= 0 else -1 for v in self.values(np.asarray(z, float)))

    # ------------------------------------------------ the modes of a run, by their codes
    def slid_on(self, mode: int) -> int:
        """The surface a mode slides on (its 0 digit), or -1 in a region."""
        d = digits(mode, self.m)
        return d.index(0) if 0 in d else -1

    def beside(self, mode: int):
        """(k, the region on the + side of surface k, the one on its - side) of a slide."""
        d = digits(mode, self.m)
        k = d.index(0)
        return k, d[:k] + (1,) + d[k + 1:], d[:k] + (-1,) + d[k + 1:]

    def mode_field(self, mode: int, z: np.ndarray) -> np.ndarray:
        """The field of a mode: its region's, or Filippov's sliding field on the surface
        it slides on (the convex combination of the fields on either side)."""
        if self.slid_on(mode) < 0:
            return self.region_field(digits(mode, self.m), z)
        d = digits(mode, self.m)
        if d.count(0) == 2:
            from .intersection import bilinear_field

            j, k = (i for i, v in enumerate(d) if v == 0)
            return bilinear_field(self, d, j, k, z)
        k, plus, _ = self.beside(mode)
        return self.view(plus, 1, k).sliding_field(z)

    def intersection_view(self, sigma: tuple, j: int, k: int) -> PiecewiseSystem:
        """A slide on the intersection of h_j and h_k (beside region ``sigma``'s other
        digits) as a one-surface system with no surface: both fields the bilinear
        sliding field (filippov.intersection), H = 1 (never reached), built once."""
        from .intersection import bilinear_field

        key = ("both", tuple(sigma), j, k)
        if key not in self._views:
            def f(z):
                return bilinear_field(self, sigma, j, k, z)
            f.piece_name = (f"the sliding field on the intersection of h{j + 1} and "
                            f"h{k + 1} (region {tuple(sigma)}'s fields around it)")
            self._views[key] = PiecewiseSystem(
                tuple(self.names), f, f, lambda z: np.ones(np.shape(z)[1:]),
                lambda z: np.zeros(np.shape(z)), sliding=self.sliding,
                units=dict(self.units), description=self.description, scale=self.scale)
        return self._views[key]

    def view(self, sigma: tuple, s: int, only: int | None = None) -> PiecewiseSystem:
        """:func:`region_view` (``only``: :func:`slide_view` on surface ``only``), built
        once per system."""
        key = (tuple(sigma), s, only)
        if key not in self._views:
            self._views[key] = region_view(self, key[0], s, only)
        return self._views[key]

    def one_surface(self) -> PiecewiseSystem:
        """The system of m = 1 as today's :class:`~filippov.system.PiecewiseSystem`: its
        pieces the definition's own, h and its gradient the first (only) row."""
        if self.m != 1:
            raise ValueError(f"one_surface: the system has m = {self.m} surfaces")
        if "one" not in self._views:
            self._views["one"] = PiecewiseSystem(
                tuple(self.names), lambda z: self.region_field((-1,), z),
                lambda z: self.region_field((1,), z), lambda z: self.values(z)[0],
                lambda z: self.grads(z)[0], sliding=self.sliding, units=dict(self.units),
                description=self.description, scale=self.scale)
        return self._views["one"]


def view_at(system, z) -> PiecewiseSystem:
    """The one-surface system whose pieces say what holds at a state z (its units, its
    field there): ``system`` itself, or a several-surface system's view of the region
    of z."""
    if isinstance(system, SurfacesSystem):
        return system.view(system.region(np.asarray(z, dtype=float)), 1)
    return system


def regions(m: int) -> list:
    """Every sign vector of m surfaces."""
    out = [()]
    for _ in range(m):
        out = [r + (s,) for r in out for s in (-1, 1)]
    return out


#: the sliding fields on an intersection a system may name (SurfacesSystem.intersection)
INTERSECTIONS = (None, "bilinear")


def check_intersection(choice, m: int) -> None:
    """``intersection`` as every definition of several surfaces takes it: one of
    INTERSECTIONS, and None for one surface (which has no intersection); ValueError."""
    if choice not in INTERSECTIONS:
        raise ValueError(f"intersection: expected None or 'bilinear', got {choice!r}")
    if m == 1 and choice is not None:
        raise ValueError("intersection: one switching surface has no intersection")


def check_regions(keys, m: int) -> None:
    """A field for every region of m surfaces among the sign vectors ``keys``."""
    given = set(keys)
    missing = [s for s in regions(m) if s not in given]
    if missing:
        raise ValueError(f"fields: no field for region {missing[0]} (one per sign vector: "
                         f"{2 ** m} regions)")


def region_view(system: SurfacesSystem, sigma: tuple, s: int,
                only: int | None = None) -> PiecewiseSystem:
    """Region ``sigma`` as one side of a one-surface system: H = s min_k sigma_k h_k (the
    region's boundary; ``only``: surface ``only`` alone, a slide's view), the region's
    field on side s (H >= 0 for s = +1), and beyond H the field of the region across the
    nearest surface (the argmin; ties: the lowest index). ``s`` keeps H the same function
    near a surface from one view to the next (:mod:`filippov.several`)."""
    sig, sigma = np.asarray(sigma, dtype=float), tuple(sigma)

    def oriented(z):
        g = _column(sig, np.asarray(z)) * system.values(z)
        return g if only is None else g[only:only + 1]

    def nearest(z):
        if only is not None:   # a slide's view: its surface, the others not evaluated
            return np.full(np.shape(z)[1:], only, dtype=np.intp)
        return np.argmin(oriented(z), axis=0)

    def switch(z):
        return s * np.min(oriented(z), axis=0)

    def switch_grad(z):
        z = np.asarray(z)
        k, G = nearest(z), system.grads(z)   # (m, n) or (m, n, b)
        if z.ndim == 1:
            return s * sig[k] * G[k]
        return s * sig[k] * G[k, :, np.arange(z.shape[1])].T

    def inside(z):
        return system.region_field(sigma, z)

    def beyond(z):
        k = nearest(z)
        if np.ndim(k) == 0:
            return system.region_field(flip(tuple(sigma), int(k)), z)
        out = np.empty(np.shape(z))
        for j in np.unique(k):
            sel = k == j
            out[:, sel] = system.region_field(flip(tuple(sigma), int(j)), z[:, sel])
        return out

    # what a non-finite value is blamed on (filippov.checks.blamed): the region, not the
    # view's side
    inside.piece_name = f"the field of region {sigma}"
    beyond.piece_name = lambda z: (f"the field of region "
                                   f"{flip(sigma, int(np.ravel(nearest(z))[0]))}")
    switch.piece_name, switch_grad.piece_name = ("a switching function h_k",
                                                 "a switching function's gradient")
    plus, minus = (inside, beyond) if s > 0 else (beyond, inside)
    return PiecewiseSystem(tuple(system.names), minus, plus, switch, switch_grad,
                           sliding=system.sliding, units=dict(system.units),
                           description=system.description, scale=system.scale)


def slide_view(system: SurfacesSystem, sigma: tuple, k: int, s: int) -> PiecewiseSystem:
    """A slide on surface k beside region ``sigma``: H = s sigma_k h_k, the fields of
    sigma and of the region across k (:func:`region_view` on surface k alone)."""
    return region_view(system, sigma, s, only=k)
