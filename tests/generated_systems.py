"""Generated Filippov systems with answers in closed form, for tests/test_properties.py.

One structure serves every generated system: two affine fields z' = A_- z + b_- (region
h < 0) and z' = A_+ z + b_+ (h >= 0) in n = 2, 3 or 4 dimensions, the switching function
h = c.z - d + k (e.z)^2 (e orthogonal to c: a planar surface for k = 0, a parabolic
cylinder otherwise) and the section s = h - sigma (a level set of h; sigma = 0 is H
itself). Everything a system is made of travels in the parameter array p (layout:
:func:`layout`), so the pieces below are numba-compiled once per process and each engine
builds its model once per dimension (:func:`system`): a hypothesis example only writes
new numbers into p. The exact flows come from a real block decomposition A = V B V^-1
(B: real eigenvalues and 2x2 rotation-scaling blocks [[re, -im], [im, re]]), written out
in closed form; the tests' reference answers never use it -- they use scipy.linalg.expm
of A and root finding (:class:`Affine`).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np
from hypothesis import assume
from hypothesis import strategies as st
from numba import njit
from scipy.linalg import expm
from scipy.optimize import brentq

from filippov import FilippovSystem

DIMS = (2, 3, 4)
#: the exact flows are scanned once per sample step: generated spectra have |re|, |im| <= 1.2,
#: so one step is at most a tenth of the fastest time scale (1/1.2)
SAMPLE_STEP = 0.08


# ----------------------------------------------------------------------------- p's layout
def side_size(n: int) -> int:
    return 3 * n * n + 4 * n   # A, b, V, V^-1, re, im, z*


def layout(n: int) -> dict:
    """Offsets into p: ``minus`` and ``plus`` (each: A n*n, b n, V n*n, V^-1 n*n, re n,
    im n, z* n), ``c`` (n), ``d``, ``k``, ``e`` (n), ``sigma``; ``size``."""
    s = side_size(n)
    h = 2 * s
    return {"minus": 0, "plus": s, "c": h, "d": h + n, "k": h + n + 1, "e": h + n + 2,
            "sigma": h + 2 * n + 2, "size": h + 2 * n + 3}


@njit(cache=True)
def _offsets(n):
    s = 3 * n * n + 4 * n
    return s, 2 * s   # plus, c


@njit(cache=True)
def _affine(z, p, base):
    n = z.size
    out = np.empty(n)
    for i in range(n):
        acc = p[base + n * n + i]
        for j in range(n):
            acc += p[base + i * n + j] * z[j]
        out[i] = acc
    return out


@njit(cache=True)
def _flow(z0, tau, p, base):
    """z* + V exp(B tau) V^-1 (z0 - z*), B block diagonal: exp of a 2x2 block
    [[re, -im], [im, re]] (marked by im > 0 on its first index) is
    e^(re tau) [[cos, -sin], [sin, cos]](im tau)."""
    n = z0.size
    oV, oW = base + n * n + n, base + 2 * n * n + n
    ore, oim, ozs = base + 3 * n * n + n, base + 3 * n * n + 2 * n, base + 3 * n * n + 3 * n
    y = np.empty(n)
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += p[oW + i * n + j] * (z0[j] - p[ozs + j])
        y[i] = acc
    w = np.empty(n)
    i = 0
    while i < n:
        g = math.exp(p[ore + i] * tau)
        if p[oim + i] > 0.0 and i + 1 < n:
            co, si = math.cos(p[oim + i] * tau), math.sin(p[oim + i] * tau)
            w[i] = g * (co * y[i] - si * y[i + 1])
            w[i + 1] = g * (si * y[i] + co * y[i + 1])
            i += 2
        else:
            w[i] = g * y[i]
            i += 1
    out = np.empty(n)
    for i in range(n):
        acc = p[ozs + i]
        for j in range(n):
            acc += p[oV + i * n + j] * w[j]
        out[i] = acc
    return out


@njit(cache=True)
def field_minus(z, p):
    return _affine(z, p, 0)


@njit(cache=True)
def field_plus(z, p):
    return _affine(z, p, _offsets(z.size)[0])


@njit(cache=True)
def flow_minus(z0, tau, p):
    return _flow(z0, tau, p, 0)


@njit(cache=True)
def flow_plus(z0, tau, p):
    return _flow(z0, tau, p, _offsets(z0.size)[0])


@njit(cache=True)
def switch(z, p):
    n = z.size
    oc = _offsets(n)[1]
    lin, ez = -p[oc + n], 0.0
    for i in range(n):
        lin += p[oc + i] * z[i]
        ez += p[oc + n + 2 + i] * z[i]
    return lin + p[oc + n + 1] * ez * ez


@njit(cache=True)
def switch_grad(z, p):
    n = z.size
    oc = _offsets(n)[1]
    ez = 0.0
    for i in range(n):
        ez += p[oc + n + 2 + i] * z[i]
    out = np.empty(n)
    for i in range(n):
        out[i] = p[oc + i] + 2.0 * p[oc + n + 1] * ez * p[oc + n + 2 + i]
    return out


@njit(cache=True)
def section(z, p):
    n = z.size
    return switch(z, p) - p[_offsets(n)[1] + 2 * n + 2]


@njit(cache=True)
def _matrix(p, base, n):
    out = np.empty((n, n))
    for i in range(n):
        for j in range(n):
            out[i, j] = p[base + i * n + j]
    return out


@njit(cache=True)
def jac_minus(z, p):
    return _matrix(p, 0, z.size)


@njit(cache=True)
def jac_plus(z, p):
    return _matrix(p, _offsets(z.size)[0], z.size)


# ----------------------------------------------------------------------------- the engines
class _Cached(FilippovSystem):
    """A FilippovSystem whose section models are built once per (section, direction):
    the generated tests ask for the same section thousands of times with new numbers in
    p, and each new section would otherwise compile its adapter again (~0.5 s)."""

    def __init__(self, *args, **kw):
        super().__init__(*args, **kw)
        self._sections = {}

    def compiled(self, section, *, direction=0, where=None, probe=None):
        key = ("compiled", section, direction, where)
        if key not in self._sections:
            self._sections[key] = super().compiled(section, direction=direction, where=where,
                                                   probe=probe)
        return self._sections[key]

    def python_section(self, section, *, direction=0, where=None, name="section",
                       min_time=0.0):
        key = ("python", section, direction, where, name, min_time)
        if key not in self._sections:
            self._sections[key] = super().python_section(section, direction=direction,
                                                         where=where, name=name,
                                                         min_time=min_time)
        return self._sections[key]


_SYSTEMS: dict = {}


def system(n: int, exact: bool) -> FilippovSystem:
    """The structure of dimension ``n``, with (``exact``) or without exact flows; built
    once per process. Give it numbers with :func:`load`."""
    key = (n, exact)
    if key not in _SYSTEMS:
        p = np.zeros(layout(n)["size"])
        flows = dict(flow_minus=flow_minus, flow_plus=flow_plus,
                     sample_step=SAMPLE_STEP) if exact else {}
        _SYSTEMS[key] = _Cached(tuple(f"x{i + 1}" for i in range(n)), field_minus, field_plus,
                                switch, switch_grad, params=p, name=f"generated{n}",
                                jacobians={"minus": jac_minus, "plus": jac_plus}, **flows)
    return _SYSTEMS[key]


def load(fs: FilippovSystem, p: np.ndarray) -> None:
    """Write ``p`` into the system's parameter array, which both engines' models read
    (the compiled models share its buffer: checked, not assumed)."""
    fs.params[:] = p
    for cm in [m for m in fs._sections.values() if hasattr(m, "params")]:
        assert np.shares_memory(cm.params, fs.params) and np.array_equal(cm.params, p)


# ----------------------------------------------------------------------------- closed forms
@dataclasses.dataclass
class Affine:
    """z' = A z + b, its exact flow by scipy.linalg.expm (not the pieces' formula)."""

    A: np.ndarray
    b: np.ndarray

    def f(self, z):
        return self.A @ z + self.b

    def flow(self, z0, t):
        # the augmented matrix [[A, b], [0, 0]]: exp gives e^{At} and int_0^t e^{As} ds b
        n = self.b.size
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = self.A * t, self.b * t
        E = expm(M)
        return E[:n, :n] @ z0 + E[:n, n]

    def stm(self, t):
        return expm(self.A * t)

    def grid(self, z0, t_end, num):
        """The flow from z0 on num equally spaced times of [0, t_end]: (times, states
        (num, n)), stepped with one exponential of the step (rounding grows ~ num eps:
        for scanning; roots are refined with :meth:`flow`)."""
        ts = np.linspace(0.0, t_end, num)
        n = self.b.size
        M = np.zeros((n + 1, n + 1))
        M[:n, :n], M[:n, n] = self.A * ts[1], self.b * ts[1]
        E = expm(M)
        out = np.empty((num, n))
        out[0] = z0
        for i in range(1, num):
            out[i] = E[:n, :n] @ out[i - 1] + E[:n, n]
        return ts, out


@dataclasses.dataclass
class Generated:
    """One generated system: its fields, switching function and section, as numbers."""

    n: int
    minus: Affine
    plus: Affine
    c: np.ndarray
    d: float
    k: float
    e: np.ndarray
    sigma: float
    p: np.ndarray   # the parameter array (layout(n))

    def h(self, z):
        return self.c @ z - self.d + self.k * (self.e @ z) ** 2

    def grad_h(self, z):
        return self.c + 2 * self.k * (self.e @ z) * self.e

    def s(self, z):
        return self.h(z) - self.sigma


def _side(A, b, V, re, im):
    n = b.size
    zs = -np.linalg.solve(A, b)
    return np.concatenate([A.ravel(), b, V.ravel(), np.linalg.inv(V).ravel(), re, im, zs])


def build(n, sides, c, d, k, e, sigma) -> Generated:
    """``sides``: ((A, b, V, re, im) of region -, same of region +)."""
    L = layout(n)
    p = np.zeros(L["size"])
    p[L["minus"]:L["plus"]] = _side(*sides[0])
    p[L["plus"]:L["c"]] = _side(*sides[1])
    p[L["c"]:L["c"] + n], p[L["d"]], p[L["k"]] = c, d, k
    p[L["e"]:L["e"] + n], p[L["sigma"]] = e, sigma
    return Generated(n, Affine(sides[0][0], sides[0][1]), Affine(sides[1][0], sides[1][1]),
                     np.asarray(c, float), float(d), float(k), np.asarray(e, float),
                     float(sigma), p)


# ----------------------------------------------------------------------------- strategies
def unit(draw, n, name="unit"):
    v = np.array(draw(st.lists(st.floats(-1, 1), min_size=n, max_size=n), label=name))
    v[0] += 1.0 if v[0] >= 0 else -1.0    # |v| >= 1: no direction is lost to rounding
    return v / np.linalg.norm(v)


@st.composite
def matrix(draw, n, rotations=True):
    """(A, V, re, im): A = V B V^-1 with B real-block-diagonal, |re| in [0.15, 1.2] for a
    real eigenvalue (A invertible: an equilibrium z* for the flow's formula), im in
    [0.3, 1.2] for a rotation block; V = I + a perturbation with cond(V) <= 20."""
    re = np.array(draw(st.lists(st.floats(0.15, 1.2), min_size=n, max_size=n)))
    re *= np.array(draw(st.lists(st.sampled_from([-1.0, 1.0]), min_size=n, max_size=n)))
    im = np.zeros(n)
    B = np.diag(re)
    i = 0
    while i + 1 < n and rotations:
        if draw(st.booleans(), label="rotation block"):
            w = draw(st.floats(0.3, 1.2))
            re[i + 1] = re[i]
            im[i], im[i + 1] = w, -w
            B[i:i + 2, i:i + 2] = [[re[i], -w], [w, re[i]]]
            i += 2
        else:
            i += 1
    V = np.eye(n) + np.array(draw(st.lists(st.floats(-0.6, 0.6), min_size=n * n,
                                           max_size=n * n))).reshape(n, n)
    assume(np.linalg.cond(V) <= 20)
    return V @ B @ np.linalg.inv(V), V, re, im


def vector(draw, n, lo=-1.0, hi=1.0):
    return np.array(draw(st.lists(st.floats(lo, hi), min_size=n, max_size=n)))


def orthogonal_unit(draw, n, c):
    e = vector(draw, n)
    e = e - (e @ c) * c
    if np.linalg.norm(e) < 0.2:
        return np.zeros(n)
    return e / np.linalg.norm(e)


# ----------------------------------------------------------------------------- scanning
def first_root(g, t0, t1, num=801, scan=None):
    """The first sign change of the scalar g(t) on [t0, t1], by a grid and brentq (xtol
    1e-15 absolute + 4 eps relative); None without one. ``scan``: g's values on the
    grid (ts, values), when a cheaper way to get them is at hand."""
    ts, vals = scan if scan is not None else (np.linspace(t0, t1, num), None)
    if vals is None:
        vals = np.array([g(t) for t in ts])
    idx = np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) <= 0)
    if idx.size == 0:
        return None
    i = int(idx[0])
    lo, hi = ts[i], ts[i + 1]
    glo, ghi = g(lo), g(hi)
    if glo == 0.0:
        return lo
    if glo * ghi > 0:   # the scan's rounding put a root at a grid point: widen
        lo, hi = ts[max(i - 1, 0)], ts[min(i + 2, ts.size - 1)]
    return brentq(g, lo, hi, xtol=1e-15, rtol=4 * np.finfo(float).eps, maxiter=200)


def rates_along(side: Affine, z0, grad, t_end, num=401):
    """min over a grid of [0, t_end] of grad(z).f(z) along the flow from z0 (the rate of a
    function along the orbit) -- a coarse monotonicity check."""
    _, zs = side.grid(z0, t_end, num)
    return min(float(grad(z) @ side.f(z)) for z in zs)


def root_along(side: Affine, z0, fun, t_end=None, t_start=0.0, num=801):
    """The first zero of fun(z) along the flow from z0 after t_start (None: none by
    t_end): scanned on a grid, refined with brentq on the flow's exponential."""
    t_end = T_SCAN if t_end is None else t_end
    ts, zs = side.grid(z0, t_end, num)
    vals = np.array([fun(z) for z in zs])
    keep = ts >= t_start
    return first_root(lambda t: fun(side.flow(z0, t)), t_start, t_end,
                      scan=(ts[keep], vals[keep]))


# ----------------------------------------------------------------------------- the cases
T_SCAN = 8.0      # longest stay the references look for
RATE = 0.2        # |dh/dt| at least this along a stay that ends at a crossing (no near-tangency)
T_MAX = 3 * T_SCAN
#: returns beyond this size are filtered out: the tolerances are stated for O(1) states
GROWTH = 10.0


def _drift_to_h(g: Generated, z, level):
    """z moved along c until h(z) = level (c is a unit vector orthogonal to e: h changes
    by the shift itself)."""
    return z + g.c * (level - g.h(z))


@dataclasses.dataclass
class Crossing:
    """From z0 (below H, or on it) under F_- to H at t1 (a transversal crossing), then
    under F_+ to the section h = sigma at t1 + tau2."""

    g: Generated
    z0: np.ndarray
    start: str          # "below", "on H" (a, b > 0) or "repelling" (a < 0 < b on H)
    t1: float           # the switch (0 for a start on H: no switch)
    zc: np.ndarray      # the state at the switch
    time: float         # the return time
    P: np.ndarray       # the return
    dP: np.ndarray      # dP/dz0 (None at a start on H: P has a kink there)
    scale: float        # product of the norms of dP/dz's factors (errors multiply by it)


def projection(f, normal):
    """dP/dz's last factor: a perturbation moves the hit along f back onto the section."""
    return np.eye(f.size) - np.outer(f, normal) / (normal @ f)


def saltation(f_before, f_after, grad):
    return np.eye(f_before.size) + np.outer(f_after - f_before, grad) / (grad @ f_before)


@st.composite
def crossings(draw, dims=DIMS):
    n = draw(st.sampled_from(dims), label="n")
    c = unit(draw, n, "c")
    curved = draw(st.booleans(), label="curved H")
    e = orthogonal_unit(draw, n, c) if curved else np.zeros(n)
    k = draw(st.floats(-0.4, 0.4), label="k") if curved else 0.0
    d = draw(st.floats(-0.5, 0.5), label="d")
    start = draw(st.sampled_from(["below", "on H", "repelling"]), label="start")
    sides = []
    for name in ("minus", "plus"):
        A, V, re, im = draw(matrix(n), label=f"A_{name}")
        b = vector(draw, n)
        # the normal speed c.b: F_- points up (down for a repelling start), F_+ up
        speed = draw(st.floats(1.0, 3.0), label=f"c.b_{name}")
        if name == "minus" and start == "repelling":
            speed = -speed
        sides.append((A, b + c * (speed - c @ b), V, re, im))
    g = build(n, sides, c, d, k, e, draw(st.floats(0.2, 1.0), label="sigma"))
    delta = draw(st.floats(0.1, 1.0), label="delta") if start == "below" else 0.0
    z0 = _drift_to_h(g, vector(draw, n, -0.5, 0.5), -delta)
    if start == "below":
        t1 = root_along(g.minus, z0, g.h)
        assume(t1 is not None)
        # h increases at a rate >= RATE all the way: no earlier (hidden) crossing, and the
        # crossing time is well conditioned (an error dh in h moves it by dh / RATE)
        assume(rates_along(g.minus, z0, g.grad_h, t1) >= RATE)
        zc = g.minus.flow(z0, t1)
    else:
        t1, zc = 0.0, z0
        a, b = g.grad_h(z0) @ g.minus.f(z0), g.grad_h(z0) @ g.plus.f(z0)
        # clear of the boundaries of the crossing / repelling region (a or b = 0)
        assume(b >= RATE and (a >= RATE if start == "on H" else a <= -RATE))
    tau = root_along(g.plus, zc, g.s)
    assume(tau is not None)
    assume(rates_along(g.plus, zc, g.grad_h, tau) >= RATE)
    P = g.plus.flow(zc, tau)
    assume(np.abs(P).max() <= GROWTH)
    factors = [projection(g.plus.f(P), g.grad_h(P)), g.plus.stm(tau)]
    if start == "below":
        factors += [saltation(g.minus.f(zc), g.plus.f(zc), g.grad_h(zc)), g.minus.stm(t1)]
    dP = np.linalg.multi_dot(factors) if start == "below" else None
    return Crossing(g, z0, start, t1, zc, t1 + tau, P, dP, _scale(factors))


def _scale(factors):
    return float(np.prod([np.linalg.norm(F, 2) for F in factors]))


@dataclasses.dataclass
class Slide:
    """Planar H, a common matrix A: the sliding field F_s = (a F_+ - b F_-)/(a - b)
    (a = c.F_-, b = c.F_+) is then the affine Pi (A z + b_-), Pi = I - D c^T/(c.D),
    D = b_+ - b_- (a - b = -c.D is constant). From z0 below H (or on it) to H at t1,
    sliding until F_+ turns tangent (b = 0, a visible fold: b rises through 0) at t1 + ts,
    then under F_+ to the section h = sigma."""

    g: Generated
    z0: np.ndarray
    on_h: bool
    t1: float
    ts: float
    time: float
    P: np.ndarray
    dP: np.ndarray
    scale: float        # product of the norms of dP/dz's factors


@st.composite
def slides(draw, dims=DIMS):
    n = draw(st.sampled_from(dims), label="n")
    c = unit(draw, n, "c")
    A, V, re, im = draw(matrix(n), label="A")
    # a = c.F_- = ga + c.A z > 0 and b = c.F_+ = -gb + c.A z < 0 where c.A z ~ 0
    ga, gb = draw(st.floats(0.5, 2.0), label="c.b_-"), draw(st.floats(0.3, 1.5), label="-c.b_+")
    bm = vector(draw, n)
    bm = bm + c * (ga - c @ bm)
    D = vector(draw, n)
    D = D + c * (-(ga + gb) - c @ D)
    g = build(n, ((A, bm, V, re, im), (A, bm + D, V, re, im)), c,
              draw(st.floats(-0.5, 0.5), label="d"), 0.0, np.zeros(n),
              draw(st.floats(0.05, 0.5), label="sigma"))
    on_h = draw(st.booleans(), label="start on H")
    z0 = _drift_to_h(g, vector(draw, n, -0.5, 0.5),
                     0.0 if on_h else -draw(st.floats(0.1, 1.0), label="delta"))
    t1 = 0.0
    if not on_h:
        t1 = root_along(g.minus, z0, g.h)
        assume(t1 is not None)
        assume(rates_along(g.minus, z0, g.grad_h, t1) >= RATE)
    zc = g.minus.flow(z0, t1) if t1 > 0 else z0
    a = lambda z: c @ g.minus.f(z)  # noqa: E731
    b = lambda z: c @ g.plus.f(z)   # noqa: E731
    assume(a(zc) >= RATE and b(zc) <= -RATE)   # attracting sliding, away from its ends
    Pi = np.eye(n) - np.outer(D, c) / (c @ D)
    sl = Affine(Pi @ A, Pi @ bm)
    ts = root_along(sl, zc, b)
    assume(ts is not None)
    zx = sl.flow(zc, ts)
    # the slide ends where b reaches 0 (a stays clear of 0 until then), b rising through it
    # at a rate >= RATE (a visible fold, well-conditioned exit time)
    assume(min(a(z) for z in sl.grid(zc, ts, 201)[1]) >= RATE)
    assume(c @ A @ sl.f(zx) >= RATE)
    tau = root_along(g.plus, zx, g.s, t_start=1e-3)
    assume(tau is not None)
    # h grows from 0 (b > 0 after the fold): never back to H before the section
    assume(min(b(z) for z in g.plus.grid(zx, tau, 201)[1][4:]) > 0)
    assume(b(g.plus.flow(zx, tau)) >= RATE)
    P = g.plus.flow(zx, tau)
    assume(np.abs(P).max() <= GROWTH)
    # the entry's saltation projects onto H; the exit's is the identity (F_s = F_+ where
    # b = 0)
    factors = [projection(g.plus.f(P), c), g.plus.stm(tau), expm(sl.A * ts)]
    if not on_h:
        factors += [saltation(g.minus.f(zc), sl.f(zc), c), g.minus.stm(t1)]
    dP = None if on_h else np.linalg.multi_dot(factors)
    return Slide(g, z0, on_h, t1, ts, t1 + ts + tau, P, dP, _scale(factors))


@dataclasses.dataclass
class Relay:
    """x' = A x - b_r sign(c.x) with A the companion matrix of prod (s + lam_i) and
    c = (1, gamma, 0, ...): the symmetric orbit from x0 on H (crossed upwards) to -x0
    in the half-period T: (I + e^{AT}) x0 = A^{-1}(e^{AT} - I) b_r and c.x0(T) = 0."""

    g: Generated
    x0: np.ndarray
    period: float
    dP: np.ndarray           # dP/dz at x0 (section H, crossed upwards)
    multipliers: np.ndarray  # of the monodromy matrix, 1 first then by modulus


@st.composite
def relays(draw, dims=(3, 4)):
    n = draw(st.sampled_from(dims), label="n")
    # distinct, spaced by >= 0.15 (V, a Vandermonde matrix, stays well conditioned)
    lam = np.cumsum([draw(st.floats(0.3, 0.6), label="-eigenvalue 1")]
                    + draw(st.lists(st.floats(0.15, 0.5), min_size=n - 1, max_size=n - 1),
                           label="eigenvalue gaps"))
    case = relay_from(lam, draw(st.floats(0.5, 2.0), label="relay amplitude"),
                      draw(st.floats(0.0, 0.6), label="gamma"))
    assume(case is not None)
    return case


def relay_from(lam, amplitude, gamma):
    """The relay around prod 1/(s + lam_i) with c = (1, gamma, 0, ...)/|.|, b_r = amplitude
    e_n, and its symmetric orbit (None if the half-period condition has no root in
    (0.05, 30] whose orbit stays in h > 0 for its half period)."""
    lam = np.asarray(lam, dtype=float)
    n = lam.size
    coef = np.poly(-lam)                    # s^n + a1 s^(n-1) + ... + an
    A = np.zeros((n, n))
    A[:-1, 1:] = np.eye(n - 1)
    A[-1] = -coef[1:][::-1]
    V = np.vander(-lam, n, increasing=True).T   # columns (1, mu, mu^2, ...)
    br = np.zeros(n)
    br[-1] = amplitude
    c = np.zeros(n)
    c[0], c[1] = 1.0, gamma
    cn = c / np.linalg.norm(c)
    g = build(n, ((A, br, V, -lam, np.zeros(n)), (A, -br, V, -lam, np.zeros(n))), cn, 0.0,
              0.0, np.zeros(n), 0.0)

    def x0_of(T):
        E = expm(A * T)
        return np.linalg.solve(np.eye(n) + E, np.linalg.solve(A, (E - np.eye(n)) @ br))

    Ts = np.linspace(0.05, 30.0, 600)
    vals = np.array([cn @ x0_of(T) for T in Ts])
    found = None
    for i in np.flatnonzero(np.sign(vals[:-1]) * np.sign(vals[1:]) < 0):
        T = brentq(lambda T: cn @ x0_of(T), Ts[i], Ts[i + 1], xtol=1e-15,
                   rtol=4 * np.finfo(float).eps)
        x0 = x0_of(T)
        up = cn @ A @ x0           # c.F_-(x0) = c.F_+(x0) (c.b_r = 0 for n >= 3)
        inside = min(cn @ z for z in g.plus.grid(x0, T, 201)[1][2:-2])
        if up >= 0.05 and inside > 0:   # crossed upwards, then in h > 0 until -x0
            found = (T, x0)
            break
    if found is None:
        return None
    T, x0 = found
    E = expm(A * T)
    S_up = saltation(g.minus.f(x0), g.plus.f(x0), cn)
    S_down = saltation(g.plus.f(-x0), g.minus.f(-x0), cn)
    M = S_up @ E @ S_down @ E
    dP = projection(g.minus.f(x0), cn) @ E @ S_down @ E
    mu = np.linalg.eigvals(M)
    one = int(np.argmin(np.abs(mu - 1)))
    rest = np.delete(mu, one)
    rest = rest[np.argsort(-np.abs(rest), kind="stable")]
    return Relay(g, x0, 2 * T, dP, np.concatenate([[mu[one]], rest]))
