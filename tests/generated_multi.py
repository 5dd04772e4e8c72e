"""Generated piecewise-affine systems with several planar switching surfaces, and their
orbits in closed form: the reference answers the engines will be held to when they take
several surfaces (issue 59), written before the engines so that the property suite is
the safety net of that redesign.

A system: m planar surfaces h_k(z) = c_k . z - d_k (unit normals c_k), so 2^m regions,
each named by its sign vector (+1 where h_k >= 0), each with an affine field
z' = A_s z + b_s (:class:`generated_systems.Affine`: its flow by scipy's expm, not by any
formula of the library). Every field drifts along one unit vector u (its normal speeds
through the surfaces, whose normals lean toward u, are >= RATE along every stay), so an
orbit from a start below every surface crosses them one by one, upward and transversally
(no sliding: the field beyond a surface also crosses it), in an order the numbers decide,
and then hits the section u . z = sigma upward. A draw is kept only where each crossing is
clear of the others (corners: no other surface within CORNER of the crossing point) and
well conditioned (the rates), so that the answer is unique and any correct engine
reproduces it to its tolerances.

The answer (:class:`MultiCrossing`): the surfaces crossed, in order, with their times and
states; the return point and time; dP/dz0, the product of the stays' transition matrices
(expm), one saltation matrix per crossing (that of the surface crossed) and the section's
projection.
"""
from __future__ import annotations

import dataclasses
import itertools

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st

from generated_systems import (GROWTH, RATE, T_SCAN, Affine, matrix, projection,
                               rates_along, root_along, saltation, unit, vector)

#: a crossing closer than this (in h) to another surface is a corner: not drawn
CORNER = 0.05
#: the fields' matrices are scaled by this: the drift along u dominates them
SOFT = 0.3


@dataclasses.dataclass
class Multi:
    """m planar surfaces in n dimensions, a field per region, a section u . z = sigma."""

    n: int
    C: np.ndarray           # (m, n) unit normals
    d: np.ndarray           # (m,) offsets
    fields: dict            # sign vector (tuple of +-1) -> Affine
    u: np.ndarray           # the drift direction, the section's normal
    sigma: float

    @property
    def m(self) -> int:
        return self.C.shape[0]

    def h(self, z) -> np.ndarray:
        return self.C @ z - self.d

    def region(self, z) -> tuple:
        """The sign vector of z (+1 where h_k(z) >= 0, the convention of one surface)."""
        return tuple(1 if v >= 0 else -1 for v in self.h(z))

    def s(self, z) -> float:
        return float(self.u @ z - self.sigma)


@dataclasses.dataclass
class MultiCrossing:
    """The orbit from z0 through its crossings to the section: ``surfaces[j]`` crossed at
    ``times[j]`` in ``states[j]``, the region after it ``regions[j + 1]`` (``regions[0]``
    the start's); the return P at ``time``; dP = dP/dz0 and ``scale``, the product of
    its factors' norms (the errors multiply by it)."""

    g: Multi
    z0: np.ndarray
    surfaces: list
    times: list
    states: list
    regions: list
    time: float
    P: np.ndarray
    dP: np.ndarray
    scale: float


def orbit(g: Multi, z0) -> MultiCrossing | None:
    """The closed-form orbit from z0 to the section, or None where it is not a clean one
    (no return within the scan, a crossing that slides or is not well conditioned, a
    corner, a return that grows past GROWTH)."""
    z, t, sig = np.asarray(z0, dtype=float), 0.0, g.region(z0)
    out = MultiCrossing(g, z.copy(), [], [], [], [sig], np.nan, None, None, np.nan)
    factors = []
    for _ in range(g.m + 1):
        side = g.fields[sig]
        roots = [root_along(side, z, lambda x, k=k: g.h(x)[k]) for k in range(g.m)]
        tau_s = root_along(side, z, g.s)
        taus = [r if r is not None else np.inf for r in roots]
        k = int(np.argmin(taus))
        if tau_s is not None and tau_s < taus[k]:
            # the section: hit upward, the speed well clear of 0
            if not (rates_along(side, z, lambda x: g.u, tau_s) >= RATE
                    and _rising(g, side, z, tau_s)):
                return None
            P = side.flow(z, tau_s)
            if np.abs(P).max() > GROWTH:
                return None
            factors += [side.stm(tau_s), projection(side.f(P), g.u)]
            out.time, out.P = t + tau_s, P
            out.dP = _product(factors)
            out.scale = float(np.prod([np.linalg.norm(F, 2) for F in factors]))
            return out
        if not np.isfinite(taus[k]) or sig[k] > 0:
            return None           # no event, or a surface crossed downward: not drawn
        tau = taus[k]
        c = g.C[k]
        if not _rising(g, side, z, tau):
            return None
        zc = side.flow(z, tau)
        others = np.delete(g.h(zc), k)
        if others.size and np.abs(others).min() < CORNER:
            return None           # a corner: two surfaces at (nearly) one point
        new = tuple(1 if j == k else s for j, s in enumerate(sig))
        after = g.fields[new]
        if not c @ after.f(zc) >= RATE:
            return None           # the field beyond does not carry on across: sliding
        factors += [side.stm(tau), saltation(side.f(zc), after.f(zc), c)]
        t, z, sig = t + tau, zc, new
        out.surfaces.append(k)
        out.times.append(t)
        out.states.append(zc)
        out.regions.append(sig)
    return None


def _rising(g: Multi, side: Affine, z, tau) -> bool:
    """Every h_k rises at RATE at least along the stay: each surface is crossed once at
    most, transversally, and none is touched on the way."""
    return all(rates_along(side, z, lambda x, c=c: c, tau) >= RATE for c in g.C)


def _product(factors):
    """factors in the order they act (the first stay's transition matrix first)."""
    M = np.eye(factors[0].shape[0])
    for F in factors:
        M = F @ M
    return M


@st.composite
def multi_crossings(draw, dims=(2, 3), counts=(2, 3)):
    """A system of :class:`Multi` and a start below every surface whose orbit crosses each
    one it meets cleanly and returns to the section (:func:`orbit`)."""
    n = draw(st.sampled_from(dims), label="n")
    m = draw(st.sampled_from(counts), label="m")
    u = unit(draw, n, "u")
    C = []
    for k in range(m):
        c = unit(draw, n, f"c{k}")
        c = c + u * max(0.0, 0.6 - c @ u)       # every normal leans toward u
        C.append(c / np.linalg.norm(c))
    C = np.array(C)
    d = vector(draw, m, -0.6, 0.6)
    fields = {}
    for sig in itertools.product((-1, 1), repeat=m):
        A, _, _, _ = draw(matrix(n), label=f"A{sig}")
        drift = draw(st.floats(1.0, 3.0), label=f"drift{sig}")
        b = drift * u + 0.3 * vector(draw, n)
        fields[sig] = Affine(SOFT * A, b)
    g = Multi(n, C, d, fields, u, draw(st.floats(1.5, 2.5), label="sigma"))
    w = vector(draw, n, -0.4, 0.4)
    z0 = -2.5 * u + (w - (w @ u) * u)
    assume(max(g.h(z0)) < -CORNER)
    case = orbit(g, z0)
    assume(case is not None and len(case.surfaces) >= 1)
    return case


__all__ = ["CORNER", "Multi", "MultiCrossing", "T_SCAN", "multi_crossings", "orbit"]
