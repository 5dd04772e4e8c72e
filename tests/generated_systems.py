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
def _exp_blocks(y, tau, p, ore, oim):
    """exp(B tau) y for the block-diagonal B of the parameters at ore (real parts) and
    oim (imaginary parts): a 2x2 block [[re, -im], [im, re]] (marked by im > 0 on its
    first index) maps to e^(re tau) [[cos, -sin], [sin, cos]](im tau)."""
    n = y.size
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
    return w


@njit(cache=True)
def _flow(z0, tau, p, base):
    """z* + V exp(B tau) V^-1 (z0 - z*), B block diagonal (_exp_blocks)."""
    n = z0.size
    oV, oW = base + n * n + n, base + 2 * n * n + n
    ore, oim, ozs = base + 3 * n * n + n, base + 3 * n * n + 2 * n, base + 3 * n * n + 3 * n
    y = np.empty(n)
    for i in range(n):
        acc = 0.0
        for j in range(n):
            acc += p[oW + i * n + j] * (z0[j] - p[ozs + j])
        y[i] = acc
    w = _exp_blocks(y, tau, p, ore, oim)
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
def _flow_jacobian(tau, p, base, n):
    """d flow / d z0 = V exp(B tau) V^-1, column by column as _flow maps z0 - z* (its
    own closed form, not differences)."""
    oV, oW = base + n * n + n, base + 2 * n * n + n
    ore, oim = base + 3 * n * n + n, base + 3 * n * n + 2 * n
    out = np.empty((n, n))
    for k in range(n):
        y = np.empty(n)
        for i in range(n):
            y[i] = p[oW + i * n + k]
        w = _exp_blocks(y, tau, p, ore, oim)
        for i in range(n):
            acc = 0.0
            for j in range(n):
                acc += p[oV + i * n + j] * w[j]
            out[i, k] = acc
    return out


@njit(cache=True)
def flow_jacobian_minus(z0, tau, p):
    return _flow_jacobian(tau, p, 0, z0.size)


@njit(cache=True)
def flow_jacobian_plus(z0, tau, p):
    return _flow_jacobian(tau, p, _offsets(z0.size)[0], z0.size)


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


def system(n: int, exact: bool, time_unit: float = 1.0,
           flow_jacobians: bool = False) -> FilippovSystem:
    """The structure of dimension ``n``, with (``exact``) or without exact flows; built
    once per process. Give it numbers with :func:`load`. ``time_unit``: the system's
    time is measured in units that many times as large (:func:`rescaled`), and so is
    its sample step. ``flow_jacobians``: with the exact flows' Jacobians too."""
    key = (n, exact, time_unit, flow_jacobians)
    if key not in _SYSTEMS:
        p = np.zeros(layout(n)["size"])
        flows = dict(flow_minus=flow_minus, flow_plus=flow_plus,
                     sample_step=SAMPLE_STEP / time_unit) if exact else {}
        if flow_jacobians:
            flows["flow_jacobians"] = {"minus": flow_jacobian_minus,
                                       "plus": flow_jacobian_plus}
        _SYSTEMS[key] = _Cached(tuple(f"x{i + 1}" for i in range(n)), field_minus, field_plus,
                                switch, switch_grad, params=p, name=f"generated{n}",
                                jacobians={"minus": jac_minus, "plus": jac_plus}, **flows)
    return _SYSTEMS[key]


def rescaled(p: np.ndarray, n: int, state: float = 1.0, time: float = 1.0) -> np.ndarray:
    """The parameters of the same system in other units: a state u = z / ``state`` and a
    time s = t / ``time`` (units ``state`` and ``time`` times as large; run it with
    ``system(n, exact, time)``). In closed form, for each side: A -> A time, b -> b time /
    state, the eigenvalues (re, im) -> times ``time``, the rest point z* -> z* / state, the
    eigenvectors V as they are; h(z) = c.z - d + k (e.z)^2 -> c state, d, k state^2, e
    (h keeps its values); the section's level sigma as it is."""
    lay, q = layout(n), np.array(p, dtype=float)
    for base in (lay["minus"], lay["plus"]):
        A, b = base, base + n * n
        q[A:A + n * n] *= time
        q[b:b + n] *= time / state
        ore = base + 3 * n * n + n
        q[ore:ore + 2 * n] *= time                     # re, im
        q[ore + 2 * n:ore + 3 * n] /= state            # z*
    q[lay["c"]:lay["c"] + n] *= state
    q[lay["k"]] *= state * state
    return q


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
def matrix(draw, n, rotations=True, rotate_first=False):
    """(A, V, re, im): A = V B V^-1 with B real-block-diagonal, |re| in [0.15, 1.2] for a
    real eigenvalue (A invertible: an equilibrium z* for the flow's formula), im in
    [0.3, 1.2] for a rotation block (``rotate_first``: the first block is one); V = I + a
    perturbation with cond(V) <= 20."""
    re = np.array(draw(st.lists(st.floats(0.15, 1.2), min_size=n, max_size=n)))
    re *= np.array(draw(st.lists(st.sampled_from([-1.0, 1.0]), min_size=n, max_size=n)))
    im = np.zeros(n)
    B = np.diag(re)
    i = 0
    while i + 1 < n and rotations:
        if (rotate_first and i == 0) or draw(st.booleans(), label="rotation block"):
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


def surface(draw, dims):
    """The dimension and the shape of a switching surface h(z) = c.z - d + k (e.z)^2 (c a
    unit normal, e orthogonal to it; flat, e = 0 and k = 0, unless a curved one is
    drawn): (n, c, e, k)."""
    n = draw(st.sampled_from(dims), label="n")
    c = unit(draw, n, "c")
    curved = draw(st.booleans(), label="curved H")
    e = orthogonal_unit(draw, n, c) if curved else np.zeros(n)
    k = draw(st.floats(-0.4, 0.4), label="k") if curved else 0.0
    return n, c, e, k


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
    n, c, e, k = surface(draw, dims)
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


# ----------------------------------------------------------------------------- folds, starts
# Issue 28's remaining classes: orbits that pass a fold of F_+ or F_- close to H without
# touching it (and ones that dip across it between samples), starts at a fold (a normal
# speed 0 on H: a tangency, visible or invisible), starts on the section itself, and
# sliding on a curved H (a nonlinear sliding field: an integrated reference).
def _dh(g: Generated, side: Affine):
    """dh/dt along the flow of ``side`` (the normal speed, at any state)."""
    return lambda z: float(g.grad_h(z) @ side.f(z))


def _section_side(g: Generated, sigma: float) -> Generated:
    """g with the section h = sigma (the dynamics do not depend on it)."""
    p = g.p.copy()
    p[layout(g.n)["sigma"]] = sigma
    return dataclasses.replace(g, sigma=float(sigma), p=p)


def _leave_to_section(g: Generated, side: Affine, z, direction: int, t_start=0.0):
    """The flow of ``side`` from z to the section h = sigma met in ``direction``: (tau, P),
    or None unless h stays on the region's side of H (by >= 0 on a grid of 201 points past
    t_start) and the section is crossed at a rate >= RATE."""
    tau = root_along(side, z, g.s, t_start=t_start)
    if tau is None:
        return None
    P = side.flow(z, tau)
    if direction * _dh(g, side)(P) < RATE:
        return None
    hs = np.array([g.h(w) for w in side.grid(z, tau, 201)[1][1:]])
    if (direction > 0 and hs.min() <= 0) or (direction < 0 and hs.max() >= 0):
        return None
    return tau, P


@dataclasses.dataclass
class Graze:
    """An orbit of one region's field that dips toward H: h has an extremum hm at tm
    (plus: a minimum, hm = gap > 0; minus: a maximum, hm = -gap): it passes the fold of
    that field (visible from its side) at a distance gap, no switch, and goes on to the
    section h = sigma met in ``direction`` (+1 above H, -1 below). ``gap`` < 0 (plus
    only, planar H, a common matrix A): the dip crosses H at t1 where F_- points up --
    attracting sliding, the slide ends at the visible fold of F_+ nearby at t1 + ts, then
    F_+ to the section; the dip lasts ~2 sqrt(2 |gap| / h''), down to a sample step."""

    g: Generated
    z0: np.ndarray
    side: str
    gap: float
    tm: float
    direction: int
    t1: float           # nan without a switch
    ts: float           # 0 without sliding
    time: float
    P: np.ndarray
    dP: np.ndarray
    scale: float


@st.composite
def grazes(draw, dims=DIMS):
    n = draw(st.sampled_from(dims), label="n")
    side = draw(st.sampled_from(["plus", "minus"]), label="side")
    c = unit(draw, n, "c")
    gap = draw(st.sampled_from([1.0, 1e-1, 1e-2, 1e-3]), label="|gap|") \
        * draw(st.floats(1.0, 9.0), label="gap mantissa")
    dips = side == "plus" and draw(st.booleans(), label="dips across H")
    if dips:
        gap = -gap / 10.0
    curved = not dips and draw(st.booleans(), label="curved H")
    e = orthogonal_unit(draw, n, c) if curved else np.zeros(n)
    k = draw(st.floats(-0.4, 0.4), label="k") if curved else 0.0
    A, V, re, im = draw(matrix(n), label="A")
    z0 = vector(draw, n, -1.0, 1.0)
    sgn = 1 if side == "plus" else -1   # the region's side of H
    # b's part along c sets dh/dt at z0 (grad h . c = 1): heading toward H
    b = vector(draw, n)
    grad0 = c + 2 * k * (e @ z0) * e
    b = b + c * (-sgn * draw(st.floats(0.3, 2.0), label="|dh/dt| at z0") - grad0 @ (A @ z0 + b))
    sides = [(A, b, V, re, im), (A, b, V, re, im)]
    if dips:   # F_- = F_+ - D, with a = c.F_- = b_+ + gD: F_- points up near the dip
        gD = draw(st.floats(0.5, 3.0), label="c.D")
        D = vector(draw, n)
        D = D + c * (-gD - c @ D)
        sides[0] = (A, b + D, V, re, im)
    g = build(n, sides, c, 0.0, k, e, 0.0)
    me = g.plus if side == "plus" else g.minus
    dh = _dh(g, me)
    # the first extremum toward H (plus: dh/dt rises through 0; minus: falls through 0)
    assume(sgn * dh(z0) <= -RATE)
    tm = root_along(me, z0, dh)
    assume(tm is not None and tm >= 0.1)
    zm = me.flow(z0, tm)
    # its sharpness |h''| >= RATE: the extremum is well defined
    assume(sgn * float(g.grad_h(zm) @ me.A @ me.f(zm) + 2 * k * (g.e @ me.f(zm)) ** 2) >= RATE)
    # put H where h's extremum lies gap from it (d shifts h and nothing else)
    d = g.h(zm) - sgn * gap
    g = dataclasses.replace(g, d=float(d), p=g.p.copy())
    g.p[layout(n)["d"]] = d
    assume(sgn * g.h(z0) >= 0.1)   # the start clear of H
    if not dips:
        sigma = sgn * (gap + draw(st.floats(0.1, 1.0), label="sigma - gap"))
        g = _section_side(g, sigma)
        left = _leave_to_section(g, me, z0, sgn, t_start=tm)
        assume(left is not None)
        tau, P = left
        # h monotone into the extremum and out of it to the section: no other dip
        ts_, zs = me.grid(z0, tau, 401)
        rates = np.array([dh(z) for z in zs]) * sgn
        before, after = rates[ts_ < tm - 0.02], rates[ts_ > tm + 0.02]
        assume(before.size == 0 or before.max() < 0)
        assume(after.size == 0 or after.min() > 0)
        assume(np.abs(P).max() <= GROWTH)
        factors = [projection(me.f(P), g.grad_h(P)), me.stm(tau)]
        return Graze(g, z0, side, gap, tm, sgn, np.nan, 0.0, tau, P,
                     np.linalg.multi_dot(factors), _scale(factors))
    # the dip across H: F_+ down to H (the first zero of h, before tm)
    t1 = root_along(g.plus, z0, g.h, t_end=tm)
    assume(t1 is not None)
    zc = g.plus.flow(z0, t1)
    a = lambda z: float(c @ g.minus.f(z))  # noqa: E731
    bspeed = lambda z: float(c @ g.plus.f(z))  # noqa: E731
    assume(a(zc) >= RATE and bspeed(zc) < 0)
    ts_, zs = g.plus.grid(z0, t1, 201)
    assume(max(dh(z) for z in zs) < 0)   # h falls all the way to H: one crossing
    D = g.plus.b - g.minus.b
    Pi = np.eye(n) - np.outer(D, c) / (c @ D)
    sl = Affine(Pi @ A, Pi @ g.minus.b)
    ts = root_along(sl, zc, bspeed, t_start=0.0)
    assume(ts is not None and ts > 0)
    zx = sl.flow(zc, ts)
    assume(min(a(z) for z in sl.grid(zc, ts, 201)[1]) >= RATE)
    assume(c @ A @ sl.f(zx) >= RATE)   # the visible fold, b rising through 0
    g = _section_side(g, draw(st.floats(0.1, 1.0), label="sigma"))
    left = _leave_to_section(g, g.plus, zx, +1, t_start=1e-3)
    assume(left is not None)
    tau, P = left
    assume(np.abs(P).max() <= GROWTH)
    factors = [projection(g.plus.f(P), c), g.plus.stm(tau), expm(sl.A * ts),
               saltation(g.plus.f(zc), sl.f(zc), c), g.plus.stm(t1)]
    return Graze(g, z0, side, gap, tm, +1, t1, ts, t1 + ts + tau, P,
                 np.linalg.multi_dot(factors), _scale(factors))


@dataclasses.dataclass
class FoldStart:
    """A start on planar H exactly at a fold of F_+ (b = 0, a >= RATE) or of F_-
    (a = 0, b <= -RATE), up to the rounding of z0 -- a tangency, where the library's
    decision rests on a normal speed that is rounding noise. A common matrix A, so the
    sliding field is affine. Visible fold (the tangent field's orbit curves away from H
    into its own region, |h''| >= RATE): the Filippov solution leaves into that region
    at once -- no sliding; ``exit`` is that region and ts = 0. Invisible (it curves
    across H, into the other field's push): the solution slides, away from the fold,
    until a or b reaches 0 again (a visible fold, at a rate >= RATE) at ts, and leaves
    into ``exit``. Then to the section h = sigma on the exit's side (+1: sigma > 0
    crossed upwards; -1: sigma < 0 crossed downwards)."""

    g: Generated
    z0: np.ndarray
    field: str          # the tangent field: "plus" (b = 0) or "minus" (a = 0)
    visible: bool
    ts: float
    exit: str           # the region the orbit leaves into
    direction: int
    time: float
    P: np.ndarray


def _affine_sliding(g: Generated):
    """Planar H, a common matrix A: Filippov's sliding field, Pi (A z + b_-)."""
    c = g.c
    D = g.plus.b - g.minus.b
    Pi = np.eye(g.n) - np.outer(D, c) / (c @ D)
    return Affine(Pi @ g.minus.A, Pi @ g.minus.b)


def slide_exit(g: Generated, sl: Affine, z, t_start, clear_from=0.0):
    """Where a slide from z (on H, a > 0 > b past t_start) ends: (ts, region) at the first
    zero of a (-> "minus") or of b (-> "plus") after t_start, or None: none by T_SCAN, the
    speed not crossing 0 at a rate >= RATE (no visible fold), or the other speed within
    RATE of 0 before it (from ``clear_from`` on; before it only on its side of 0: a start
    at a fold, moving away from it)."""
    a = lambda w: float(g.grad_h(w) @ g.minus.f(w))  # noqa: E731
    b = lambda w: float(g.grad_h(w) @ g.plus.f(w))   # noqa: E731
    ends = [(t, r) for t, r in ((root_along(sl, z, a, t_start=t_start), "minus"),
                                (root_along(sl, z, b, t_start=t_start), "plus"))
            if t is not None]
    if not ends:
        return None
    ts, region = min(ends)
    zx = sl.flow(z, ts)
    other = b if region == "minus" else a
    tg, grid = sl.grid(z, ts, 201)
    sgn = -1.0 if region == "minus" else 1.0
    vals = sgn * np.array([other(w) for w in grid])
    if vals[tg >= clear_from].min(initial=np.inf) < RATE or vals[1:].min() <= 0:
        return None
    # the rate of the ending speed along F_s (which equals the tangent field there):
    # c.A F_s, A the common matrix (not sl.A, whose rows c.Pi = 0)
    rate = float(g.c @ g.minus.A @ sl.f(zx))
    if (rate >= RATE) if region == "plus" else (rate <= -RATE):
        return ts, region
    return None


@st.composite
def fold_starts(draw, dims=DIMS):
    n = draw(st.sampled_from(dims), label="n")
    field = draw(st.sampled_from(["plus", "minus"]), label="tangent field")
    visible = draw(st.booleans(), label="visible fold")
    c = unit(draw, n, "c")
    A, V, re, im = draw(matrix(n), label="A")
    d = draw(st.floats(-0.5, 0.5), label="d")
    z0 = vector(draw, n, -0.8, 0.8)
    z0 = z0 + c * (d - c @ z0)   # on H
    Az = A @ z0
    # the tangent field T(z0) = A z0 + b_T: c.b_T = -c.A z0 (tangent), and its tangential
    # part set so that h'' = c.A T(z0) = kappa (sign: visible for F_+ is h'' > 0, for F_-
    # h'' < 0)
    u = c @ A
    q = u - (u @ c) * c
    assume(np.linalg.norm(q) >= 0.3)
    kappa = draw(st.floats(0.3, 1.5), label="|h''|")
    kappa *= 1 if visible == (field == "plus") else -1
    bT = vector(draw, n)
    bT = bT + c * (-(c @ Az) - c @ bT)
    bT = bT + q * (kappa - u @ (Az + bT)) / (q @ q)
    # the other field: normal speed >= RATE toward H (a > 0 below, b < 0 above)
    speed = draw(st.floats(0.5, 2.0), label="other normal speed")
    bO = vector(draw, n)
    bO = bO + c * ((speed if field == "plus" else -speed) - c @ Az - c @ bO)
    bm, bp = (bO, bT) if field == "plus" else (bT, bO)
    g = build(n, ((A, bm, V, re, im), (A, bp, V, re, im)), c, d, 0.0, np.zeros(n), 0.0)
    case = fold_answer(g, z0, field, visible, draw(st.floats(0.1, 1.0), label="|sigma|"))
    assume(case is not None)
    return case


def fold_answer(g: Generated, z0, field, visible, sigma_size):
    """The FoldStart of a start z0 at the fold of ``field`` (None where the generator's
    conditions fail); the section h = +-sigma_size on the exit's side."""
    if visible:
        ts, region = 0.0, field
    else:
        sl = _affine_sliding(g)
        tangent = g.plus if field == "plus" else g.minus
        kappa = abs(float(g.c @ tangent.A @ tangent.f(z0)))
        # leave the fold's neighbourhood first: the tangent speed is 0 at t = 0
        end = slide_exit(g, sl, z0, t_start=1e-3, clear_from=2 * RATE / kappa)
        if end is None:
            return None
        ts, region = end
    zx = z0 if ts == 0.0 else _affine_sliding(g).flow(z0, ts)
    direction = 1 if region == "plus" else -1
    g = _section_side(g, direction * sigma_size)
    side = g.plus if region == "plus" else g.minus
    left = _leave_to_section(g, side, zx, direction, t_start=1e-3)
    if left is None:
        return None
    tau, P = left
    if np.abs(P).max() > GROWTH:
        return None
    return FoldStart(g, z0, field, visible, ts, region, direction, ts + tau, P)


def fold_start_from(n, p, z0) -> FoldStart:
    """A fold start kept as numbers (p, z0): the tangent field is the one whose normal
    speed is 0 at z0, the fold's kind the sign of h'' = c.A F(z0) along it."""
    g = from_p(n, p)
    z0 = np.array(z0, dtype=float)
    a, b = g.c @ g.minus.f(z0), g.c @ g.plus.f(z0)
    field = "plus" if abs(b) < abs(a) else "minus"
    T = g.plus if field == "plus" else g.minus
    curv = float(g.c @ T.A @ T.f(z0))
    visible = curv > 0 if field == "plus" else curv < 0
    return fold_answer(g, z0, field, visible, abs(g.sigma))


@dataclasses.dataclass
class SectionStart:
    """A start on the section h = sigma itself (up to ``offset`` roundings of z0 along
    grad h: 0 or +-4), region +, heading up across it: the start is no return (the
    library's contract: a start on the section up to rounding is not a hit). The orbit
    of F_+ rises, falls back through the section (downwards: not counted), stays >=
    margin above H, and returns upwards at ``time``."""

    g: Generated
    z0: np.ndarray
    offset: int
    time: float
    P: np.ndarray


def section_return(g: Generated, z0, level):
    """From z0 on the level set h = level, crossing it upwards under F_+: the next upward
    crossing after the orbit has fallen back through it, (time, P), or None (not by
    T_SCAN, or a crossing at a rate < RATE)."""
    up = _dh(g, g.plus)
    if up(z0) < RATE:
        return None
    rel = lambda z: g.h(z) - level  # noqa: E731
    t_down = root_along(g.plus, z0, rel, t_start=1e-3)
    if t_down is None or up(g.plus.flow(z0, t_down)) > -RATE:
        return None
    t_r = root_along(g.plus, z0, rel, t_start=t_down + 1e-3)
    if t_r is None:
        return None
    P = g.plus.flow(z0, t_r)
    if up(P) < RATE or np.abs(P).max() > GROWTH:
        return None
    return t_r, P


def from_p(n: int, p) -> Generated:
    """The Generated system whose parameter array is p (a regression case kept as
    numbers)."""
    p = np.array(p, dtype=float)
    L = layout(n)

    def side(base):
        return Affine(p[base:base + n * n].reshape(n, n).copy(),
                      p[base + n * n:base + n * n + n].copy())

    return Generated(n, side(L["minus"]), side(L["plus"]), p[L["c"]:L["c"] + n].copy(),
                     float(p[L["d"]]), float(p[L["k"]]), p[L["e"]:L["e"] + n].copy(),
                     float(p[L["sigma"]]), p)


def section_start_from(n, p, z0) -> SectionStart:
    """A start on the section kept as numbers (p, z0), its return by section_return."""
    g = from_p(n, p)
    z0 = np.array(z0, dtype=float)
    time, P = section_return(g, z0, g.sigma)   # the section is the level set h = sigma
    return SectionStart(g, z0, 0, time, P)


@st.composite
def section_starts(draw, dims=DIMS):
    n, c, e, k = surface(draw, dims)
    # the orbit must rise through the section, fall back and rise again: a rotation
    A, V, re, im = draw(matrix(n, rotate_first=True), label="A")
    z0 = vector(draw, n, -1.0, 1.0)
    # b's part along c sets dh/dt at z0 (grad h . c = 1): upwards across the section
    b = vector(draw, n)
    grad0 = c + 2 * k * (e @ z0) * e
    b = b + c * (draw(st.floats(0.3, 2.0), label="dh/dt at z0") - grad0 @ (A @ z0 + b))
    side = (A, b, V, re, im)
    g = build(n, (side, side), c, 0.0, k, e, 0.0)
    level = g.h(z0)
    ret = section_return(g, z0, level)
    assume(ret is not None)
    t_r, P = ret
    # H below the orbit's lowest point by margin (d shifts h, nothing else)
    low = min(g.h(z) for z in g.plus.grid(z0, t_r, 801)[1])
    margin = draw(st.floats(0.05, 0.5), label="margin")
    d = low - margin
    g = dataclasses.replace(g, d=float(d), p=g.p.copy())
    g.p[layout(n)["d"]] = d
    g = _section_side(g, level - d)
    offset = draw(st.sampled_from([0, 4, -4]), label="offset (roundings)")
    gh = g.grad_h(z0)
    z0 = z0 + offset * np.finfo(float).eps * np.abs(z0).max() * gh / np.linalg.norm(gh)
    return SectionStart(g, z0, offset, t_r, P)


# ----------------------------------------------------------------------------- curved sliding
SLIDE_RTOL = 1e-12


def sliding_field(g: Generated):
    """Filippov's convex combination on H: (a F_+ - b F_-) / (a - b), a = grad h . F_-,
    b = grad h . F_+ (nonlinear in z on a curved H)."""
    def f(t, z):
        n = g.grad_h(z)
        fm, fp = g.minus.f(z), g.plus.f(z)
        a, b = n @ fm, n @ fp
        return (a * fp - b * fm) / (a - b)
    return f


def integrated_slide(g: Generated, z):
    """The slide from z on H by scipy's DOP853 at rtol SLIDE_RTOL, atol 1e-14, to its end
    where b rises through 0 (the event, located by brentq on the dense output, xtol
    4 eps): (ts, zx, steps (states along it)), or None (it ends otherwise by T_SCAN:
    a reaches 0, or never)."""
    from scipy.integrate import solve_ivp

    def b_ev(t, w):
        return float(g.grad_h(w) @ g.plus.f(w))

    def a_ev(t, w):
        return float(g.grad_h(w) @ g.minus.f(w))

    b_ev.terminal, b_ev.direction = True, 1.0
    a_ev.terminal, a_ev.direction = True, -1.0
    sol = solve_ivp(sliding_field(g), (0.0, T_SCAN), z, method="DOP853", rtol=SLIDE_RTOL,
                    atol=1e-14, events=[b_ev, a_ev])
    if sol.status != 1 or not sol.t_events[0].size:
        return None
    return float(sol.t_events[0][0]), sol.y_events[0][0], sol.y.T


@dataclasses.dataclass
class CurvedSlide:
    """A parabolic H (k != 0), any two affine fields: from z0 below H (or on it) to H at
    t1 (F_-, closed form), sliding along Filippov's (nonlinear) field -- integrated by
    scipy -- until b rises through 0 at t1 + ts (a visible fold), then F_+ (closed form)
    to the section h = sigma."""

    g: Generated
    z0: np.ndarray
    on_h: bool
    t1: float
    ts: float
    time: float
    P: np.ndarray


def curved_reference(g: Generated, z0, on_h):
    """(t1, ts, time, P) of the slide from z0 (see CurvedSlide), or None where the
    generator's conditions fail (tangencies, no visible exit, no section)."""
    t1, zc = 0.0, z0
    if not on_h:
        t1 = root_along(g.minus, z0, g.h)
        if t1 is None or rates_along(g.minus, z0, g.grad_h, t1) < RATE:
            return None
        zc = g.minus.flow(z0, t1)
    a = lambda z: float(g.grad_h(z) @ g.minus.f(z))  # noqa: E731
    b = lambda z: float(g.grad_h(z) @ g.plus.f(z))   # noqa: E731
    if a(zc) < RATE or b(zc) > -RATE:
        return None
    slide = integrated_slide(g, zc)
    if slide is None:
        return None
    ts, zx, steps = slide
    if min(a(z) for z in steps) < RATE:
        return None
    # b's rate at the exit, along F_s = F_+ there: grad h . A_+ F_+ + F_+ . Hess(h) F_+
    fp = g.plus.f(zx)
    if g.grad_h(zx) @ g.plus.A @ fp + 2 * g.k * (g.e @ fp) ** 2 < RATE:
        return None
    left = _leave_to_section(g, g.plus, zx, +1, t_start=1e-3)
    if left is None:
        return None
    tau, P = left
    return t1, ts, t1 + ts + tau, P


@st.composite
def curved_slides(draw, dims=DIMS):
    n = draw(st.sampled_from(dims), label="n")
    c = unit(draw, n, "c")
    e = orthogonal_unit(draw, n, c)
    assume(np.abs(e).max() > 0)
    k = draw(st.floats(0.15, 0.5), label="|k|") * draw(st.sampled_from([-1.0, 1.0]),
                                                        label="sign k")
    sides = []
    for name, sgn in (("minus", 1.0), ("plus", -1.0)):
        A, V, re, im = draw(matrix(n), label=f"A_{name}")
        b = vector(draw, n)
        speed = draw(st.floats(0.5, 2.0), label=f"|c.b_{name}|")
        sides.append((A, b + c * (sgn * speed - c @ b), V, re, im))
    g = build(n, sides, c, draw(st.floats(-0.5, 0.5), label="d"), k, e,
              draw(st.floats(0.05, 0.5), label="sigma"))
    on_h = draw(st.booleans(), label="start on H")
    z0 = _drift_to_h(g, vector(draw, n, -0.5, 0.5),
                     0.0 if on_h else -draw(st.floats(0.1, 1.0), label="delta"))
    ref = curved_reference(g, z0, on_h)
    assume(ref is not None)
    t1, ts, time, P = ref
    assume(np.abs(P).max() <= GROWTH)
    return CurvedSlide(g, z0, on_h, t1, ts, time, P)


# ----------------------------------------------------------------------------- NaN regions
# Issue 57 (1): a piece that turns non-finite where the orbit goes must stop the run by
# name, at the time it goes there. The same structure with one more term: 0 * sqrt(level -
# m.z), NaN on the far side of the hyperplane m.z = level, added to the one piece ``where``
# names (0: switch, 1: switch_grad (each component), 2: the section). Its numbers follow
# layout(n)'s in p.
NAN_PIECES = ("switch", "switch_grad", "section")


def nan_layout(n: int) -> dict:
    """Offsets of the NaN term's numbers past layout(n): ``m`` (n), ``level``, ``where``;
    ``size``."""
    o = layout(n)["size"]
    return {"m": o, "level": o + n, "where": o + n + 1, "size": o + n + 2}


@njit(cache=True)
def _nan_term(z, p, piece):
    """0 * sqrt(level - m.z) if the term is ``piece``'s, else 0."""
    n = z.size
    o = _offsets(n)[1] + 2 * n + 3
    if p[o + n + 1] != piece:
        return 0.0
    room = p[o + n]
    for i in range(n):
        room -= p[o + i] * z[i]
    return 0.0 * np.sqrt(room)


@njit(cache=True)
def switch_nan(z, p):
    return switch(z, p) + _nan_term(z, p, 0.0)


@njit(cache=True)
def switch_grad_nan(z, p):
    out = switch_grad(z, p)
    term = _nan_term(z, p, 1.0)
    for i in range(z.size):
        out[i] += term
    return out


@njit(cache=True)
def section_nan(z, p):
    return section(z, p) + _nan_term(z, p, 2.0)


def nan_system(n: int, exact: bool) -> FilippovSystem:
    """The structure of :func:`system` with the NaN term (:func:`nan_layout`), built once
    per process with its section (crossed upwards) on both engines while p is all zeros
    (level 0, m 0: the term is finite everywhere, as the construction's probe asks)."""
    key = ("nan", n, exact)
    if key not in _SYSTEMS:
        p = np.zeros(nan_layout(n)["size"])
        flows = dict(flow_minus=flow_minus, flow_plus=flow_plus,
                     sample_step=SAMPLE_STEP) if exact else {}
        fs = _Cached(tuple(f"x{i + 1}" for i in range(n)), field_minus, field_plus,
                     switch_nan, switch_grad_nan, params=p, name=f"generated{n}-nan",
                     jacobians={"minus": jac_minus, "plus": jac_plus}, **flows)
        fs.compiled(section_nan, direction=+1)
        fs.python_section(section_nan, direction=+1)
        fs.python()
        _SYSTEMS[key] = fs
    return _SYSTEMS[key]


@dataclasses.dataclass
class NanRegion:
    """A Crossing (``case``) whose ``piece`` is NaN where m.z > level: the orbit enters
    that half space first at t_nan (transversally, m.z' >= RATE there), before its
    switch (from below H) or its return (from H); ``p`` the parameter array of
    :func:`nan_system`."""

    case: Crossing
    piece: str
    m: np.ndarray
    level: float
    t_nan: float
    p: np.ndarray

    def orbit(self, t):
        """The closed-form state at time t (before the return)."""
        c = self.case
        if c.start == "below" and t < c.t1:
            return c.g.minus.flow(c.z0, t)
        return c.g.plus.flow(c.zc, t - c.t1)

    def field(self, t):
        c = self.case
        return (c.g.minus if c.start == "below" and t < c.t1 else c.g.plus).f(self.orbit(t))

    def stay(self, t):
        """The closed-form state at time t of the stay the orbit enters the NaN region in,
        continued: past t_nan the piece is NaN, so the system has no switch or return
        there, and an engine that meets it one sample later names this state (which is
        the orbit's only up to the NaN-free H's own event, which may come before)."""
        c = self.case
        if c.start == "below":
            return c.g.minus.flow(c.z0, t)
        return c.g.plus.flow(c.zc, t - c.t1)


@st.composite
def nan_regions(draw, dims=DIMS, pieces=NAN_PIECES):
    case = draw(crossings(dims))
    piece = draw(st.sampled_from(pieces), label="NaN piece")
    # where the orbit enters the NaN region: before anything else happens (the switch
    # from below H; the return from H), clear of the start and of it. (After a switch the
    # engines blame samples of the old field's flow continued past H:
    # test_properties.PHANTOM_NAN.)
    first = case.t1 if case.start == "below" else case.time
    t_nan = draw(st.floats(0.1, 0.9), label="t_nan / first event's time") * first
    assume(t_nan >= 0.1 and first - t_nan >= 0.05)
    region = NanRegion(case, piece, np.zeros(case.g.n), 0.0, t_nan, None)
    # its boundary's normal: along the orbit's velocity there, tilted at random
    f = region.field(t_nan)
    m = f / np.linalg.norm(f) + vector(draw, case.g.n, -0.7, 0.7)
    assume(np.linalg.norm(m) >= 0.3)
    m = m / np.linalg.norm(m)
    z_nan = region.orbit(t_nan)
    level = float(m @ z_nan)
    assume(m @ f >= RATE)
    # the first entry: m.z below the level by >= 1e-3 on the way there (up to 0.05 before;
    # all of it on the first stay's flow)
    side, z_first = (case.g.minus, case.z0) if case.start == "below" else (case.g.plus, case.zc)
    ts, zs = side.grid(z_first, t_nan, 201)
    gaps = level - zs[:-1] @ m
    assume(gaps.min() > 0 and gaps[ts[:-1] < t_nan - 0.05].min(initial=1.0) >= 1e-3)
    L = nan_layout(case.g.n)
    p = np.zeros(L["size"])
    p[:case.g.p.size] = case.g.p
    p[L["m"]:L["m"] + case.g.n], p[L["level"]] = m, level
    p[L["where"]] = NAN_PIECES.index(piece)
    return dataclasses.replace(region, m=m, level=level, p=p)


# ----------------------------------------------------------------------------- two-folds
# Issue 57 (3): piecewise-constant fields in (x, y, w), H = {w = 0}: f+ = (p1, p2, x) above
# (its fold line x = 0: w'' = p1 there, visible for p1 > 0, invisible for p1 < 0), f- =
# (q1, q2, y) below (fold line y = 0, w'' = q2: invisible for q2 > 0). The fold lines meet
# at the two-fold, the origin. Every stay is a parabola in closed form, and so is the map
# over a crossing loop. On H, where the fields push toward H from both sides (x < 0 < y),
# Filippov's sliding field is (y f+ - x f-) / (y - x) (a = y, b = x): with ds = dt / (y - x)
# it is the linear z' = K z, K = [[-q1, p1], [-q2, p2]], and L = u y + v x with
# [[p2, p1], [q2, q1]] (u, v) = (-1, -1) falls at the rate 1 exactly along it (t-time).
@njit(cache=True)
def two_fold_minus(z, p):
    return np.array([p[2], p[3], z[1]])


@njit(cache=True)
def two_fold_plus(z, p):
    return np.array([p[0], p[1], z[0]])


@njit(cache=True)
def two_fold_flow_minus(z0, tau, p):
    return np.array([z0[0] + p[2] * tau, z0[1] + p[3] * tau,
                     z0[2] + z0[1] * tau + 0.5 * p[3] * tau * tau])


@njit(cache=True)
def two_fold_flow_plus(z0, tau, p):
    return np.array([z0[0] + p[0] * tau, z0[1] + p[1] * tau,
                     z0[2] + z0[0] * tau + 0.5 * p[0] * tau * tau])


@njit(cache=True)
def two_fold_switch(z, p):
    return z[2]


@njit(cache=True)
def two_fold_grad(z, p):
    return np.array([0.0, 0.0, 1.0])


@njit(cache=True)
def two_fold_section(z, p):
    """w = sigma (p[4])."""
    return z[2] - p[4]


def two_fold_system(exact: bool) -> FilippovSystem:
    """The two-fold structure (p = (p1, p2, q1, q2, sigma)), built once per process."""
    key = ("two-fold", exact)
    if key not in _SYSTEMS:
        flows = dict(flow_minus=two_fold_flow_minus, flow_plus=two_fold_flow_plus,
                     sample_step=SAMPLE_STEP) if exact else {}
        fs = _Cached(("x", "y", "w"), two_fold_minus, two_fold_plus, two_fold_switch,
                     two_fold_grad, params=np.array([-1.0, -1.0, 2.0, 1.0, 100.0]),
                     name="two-fold", **flows)
        fs.compiled(two_fold_section, direction=+1)
        fs.python_section(two_fold_section, direction=+1)
        _SYSTEMS[key] = fs
    return _SYSTEMS[key]


def slide_rate_one(p1, p2, q1, q2):
    """(u, v): L = u y + v x falls at the rate 1 along the sliding field."""
    return np.linalg.solve([[p2, p1], [q2, q1]], [-1.0, -1.0])


def crossing_loop(p1, p2, q1, q2):
    """The map over one crossing loop of an invisible-invisible two-fold (p1 < 0 < q2),
    from (x, y) on H with x, y > 0: the + arc to (-x, y1), y1 = y + alpha x (alpha =
    -2 p2 / p1), the - arc to (-x - beta y1, -y1) (beta = 2 q1 / q2): [[-(1 + alpha beta),
    -beta], [-alpha, -1]], det 1. Returns (M, alpha, beta)."""
    alpha, beta = -2.0 * p2 / p1, 2.0 * q1 / q2
    return np.array([[-(1.0 + alpha * beta), -beta], [-alpha, -1.0]]), alpha, beta


@dataclasses.dataclass
class TwoFold:
    """A start near an invisible-invisible two-fold (p1 < 0 < q2) and what its Filippov
    solution does. ``kind``: "zeno" (on the loop map's contracting eigenvector: crossing
    loops each ``ratio`` times the one before, accumulating at the two-fold at t_star);
    "leaves" (off it by a relative ``offset``: ``crossings`` crossings of H, arc by arc
    by the map, then into attracting sliding x < 0 < y at t_slide, z_slide, and along it
    into the two-fold at t_star); "slide" (on H in the sliding region: into the two-fold at t_star =
    L(z0))."""

    p: np.ndarray
    z0: np.ndarray
    kind: str
    ratio: float
    t_star: float
    crossings: int = 0
    t_slide: float = 0.0
    z_slide: np.ndarray = None


def loop_q1(p1, p2, q2, ratio):
    """q1 such that the loop map's eigenvalues are ratio, 1 / ratio (its trace
    -(2 + alpha beta) = ratio + 1 / ratio)."""
    alpha = -2.0 * p2 / p1
    beta = -(ratio + 1.0 / ratio + 2.0) / alpha
    return beta * q2 / 2.0


def _on_plus_arc(p1, p2, x, y, s):
    """The state s into the + arc from (x, y, 0)."""
    return np.array([x + p1 * s, y + p2 * s, x * s + 0.5 * p1 * s * s])


def invisible_two_fold_from(p1, p2, q2, ratio, kind, x0=1.0, s_frac=0.5, offset=0.0):
    """The TwoFold with f+ = (p1, p2, x), f- = (q1, q2, y), q1 = loop_q1 (p1, p2 < 0 <
    q2): ``kind`` "zeno" from x0 on the contracting eigenvector, "leaves" from it off by
    the relative ``offset`` in y (both a fraction s_frac into the first + arc), "slide"
    from (-x0, offset) on H. None where the generator's conditions fail."""
    q1 = loop_q1(p1, p2, q2, ratio)
    if not 0.2 <= q1 <= 10.0:
        return None
    M, alpha, beta = crossing_loop(p1, p2, q1, q2)
    vy = -alpha / (1.0 + ratio)           # the eigenvector (1, vy) of ratio
    p = np.array([p1, p2, q1, q2, 100.0])
    u, v = slide_rate_one(p1, p2, q1, q2)
    if kind == "slide":
        x, y = -x0, offset
        return TwoFold(p, np.array([x, y, 0.0]), kind, np.nan, float(u * y + v * x),
                       z_slide=np.array([x, y, 0.0]))
    # start a fraction of the first + arc in (clear of the start-on-H rules)
    s = s_frac * 2.0 * x0 / -p1
    if kind == "zeno":
        y0 = vy * x0
        loop = 2.0 * x0 / -p1 + 2.0 * -alpha * x0 * ratio / ((1.0 + ratio) * q2)
        return TwoFold(p, _on_plus_arc(p1, p2, x0, y0, s), kind, ratio,
                       loop / (1.0 - ratio) - s)
    y0 = vy * x0 * (1.0 + offset)
    # the loops by the map, half arc by half arc, until one ends in the sliding region
    x, y, t = x0, y0, 0.0
    for half in range(8):
        if half % 2 == 0:   # + arc from (x, y), x, y > 0
            t += 2.0 * x / -p1
            x, y = -x, y + alpha * x
            if y > 0:
                break
        else:               # - arc from (x, y), x < 0 > y
            t += 2.0 * y / -q2
            x, y = x + q1 * 2.0 * y / -q2, -y
            if x < 0:
                break
    else:
        return None
    # clear of the crossing region's edges (well conditioned: the speeds that decide),
    # after at least one crossing
    if min(abs(x), abs(y)) < 0.05 * max(abs(x), abs(y)) or half < 1:
        return None
    return TwoFold(p, _on_plus_arc(p1, p2, x0, y0, s), kind, ratio,
                   float(t - s + u * y + v * x), half, float(t - s), np.array([x, y, 0.0]))


def _zeno_switches(case, n, perturb=None):
    """The first n switch times of a "zeno" case and the states the arcs start from, arc
    by arc in closed form at mpmath's precision, from its start a way into the first +
    arc. Each arc begins where the last one ended, on H or off it (w != 0) when
    ``perturb`` = (j, what, d) moved switch j: ``what`` "t" finds it d late (the state d
    further along the arc), 0, 1, 2 adds d to that component of the state after it."""
    import mpmath
    p1, p2, q1, q2 = (mpmath.mpf(float(v)) for v in case.p[:4])
    (x, y, w), t, plus, ts, starts = (mpmath.mpf(float(v)) for v in case.z0), 0, True, [], []
    for j in range(n):
        starts.append((x, y, w))
        if plus:   # w + x tau + p1 tau^2 / 2 = 0, w >= 0, p1 < 0
            tau = (x + mpmath.sqrt(x * x - 2 * p1 * w)) / -p1
        else:      # w + y tau + q2 tau^2 / 2 = 0, w <= 0, q2 > 0
            tau = (-y + mpmath.sqrt(y * y - 2 * q2 * w)) / q2
        if perturb is not None and perturb[:2] == (j, "t"):
            tau += perturb[2]
        fx, fy, fw = (p1, p2, x) if plus else (q1, q2, y)
        acc = p1 if plus else q2
        x, y, w = x + fx * tau, y + fy * tau, w + fw * tau + acc * tau * tau / 2
        if perturb is not None and perturb[0] == j and perturb[1] != "t":
            z = [x, y, w]
            z[perturb[1]] += perturb[2]
            x, y, w = z
        t += tau
        ts.append(t)
        plus = not plus
    return ts, starts


def _reported_t_star(ts):
    """The accumulation time rules.geometric_accumulation reports from the switch times
    ts (its newest loop, its ratio to the loop before, the geometric tail)."""
    loop = ts[-1] - ts[-3]
    ratio = loop / (ts[-3] - ts[-5])
    return ts[-1] + loop * ratio / (1 - ratio)


def zeno_rounding_bound(case, t_stop, xtol):
    """How far the t* an engine reports for a "zeno" case may lie from the exact one by
    the errors of its switches alone, for a run stopped at the switch at t_stop. The start
    is on the loop map's contracting eigenvector; an error off it grows by 1 / ratio per
    loop while the loops shrink by ratio, so an error at an early switch reaches the last
    ones amplified ~ (d_0 / d_k) (the first loop's duration over the last one's). Summed
    worst case over the switches, each error times its gain on the reported t* (mpmath's
    difference quotients of :func:`_zeno_switches`, exact to their precision; the map is
    smooth, so these are the first-order gains):

    * its time, located to xtol + 4 eps |t| (brentq's tolerance) and then stepped to its
      far side (at most as much again): 2 (xtol + 4 eps |t|);
    * its state, evaluated by the closed-form flow from the arc's start (each component a
      sum of at most three terms): 2 eps times the sum of the terms' sizes.

    The integrated flows follow the same quadratics (DOP853 is exact on them) to rounding.
    """
    import mpmath
    eps = float(np.finfo(float).eps)
    with mpmath.workdps(60):
        ts, starts = _zeno_switches(case, 80)
        n = 1 + min(range(len(ts)), key=lambda j: abs(float(ts[j]) - t_stop))
        if n < 5:
            return math.inf
        ts = ts[:n]
        base, d = _reported_t_star(ts), mpmath.mpf("1e-30")

        def gain(j, what):
            moved = _zeno_switches(case, n, (j, what, d))[0]
            return float(abs(_reported_t_star(moved) - base) / d)

        p1, p2, q1, q2 = (abs(float(v)) for v in case.p[:4])
        bound = 0.0
        for j in range(n):
            tj, tau = float(ts[j]), float(ts[j] - (ts[j - 1] if j else 0))
            x, y, w = (abs(float(v)) for v in starts[j])
            fx, fy, fw, acc = (p1, p2, x, p1) if j % 2 == 0 else (q1, q2, y, q2)
            terms = (x + fx * tau, y + fy * tau, w + fw * tau + acc * tau * tau / 2)
            bound += gain(j, "t") * 2.0 * (xtol + 4.0 * eps * abs(tj))
            bound += sum(gain(j, c) * 2.0 * eps * terms[c] for c in range(3))
    return bound


@st.composite
def invisible_two_folds(draw):
    p1 = -draw(st.floats(0.5, 2.0), label="-p1")
    p2 = -draw(st.floats(0.5, 2.0), label="-p2")
    q2 = draw(st.floats(0.5, 2.0), label="q2")
    ratio = draw(st.floats(0.1, 0.5), label="ratio per loop")
    kind = draw(st.sampled_from(["zeno", "leaves", "slide"]), label="kind")
    if kind == "slide":
        case = invisible_two_fold_from(p1, p2, q2, ratio, kind,
                                       draw(st.floats(0.05, 1.5), label="-x0"),
                                       offset=draw(st.floats(0.05, 1.5), label="y0"))
    else:
        x0 = draw(st.floats(0.3, 1.5), label="x0")
        s_frac = draw(st.floats(0.1, 0.9), label="s / first arc")
        offset = 0.0 if kind == "zeno" else \
            10.0 ** draw(st.floats(-2.5, -0.3), label="log10 |offset|") \
            * draw(st.sampled_from([-1.0, 1.0]), label="sign of the offset")
        case = invisible_two_fold_from(p1, p2, q2, ratio, kind, x0, s_frac, offset)
    assume(case is not None)
    return case


@dataclasses.dataclass
class VisibleTwoFold:
    """A start near a visible-invisible two-fold (f+ visible at x = 0: p1 > 0; f- invisible
    at y = 0: q2 > 0) and its Filippov solution in closed form. From ``start`` "below"
    (w0 < 0) the - arc reaches H at t_c, (x_c, y_c) with y_c > 0; for x_c > 0 it crosses
    (``crossings`` 1) and rises to the section w = sigma; for x_c < 0 (or a start "on H"
    there, t_c = 0) it slides. The slide is z' = K z in s (ds = dt / (y - x)): it leaves
    at the visible fold x = 0 (y_e > 0) at t_c + ts -- F = f+ there, whose arc from
    (0, y_e, 0) rises as p1 tau^2 / 2 to the section -- or it runs into the two-fold
    (``two_fold``) at t_star = t_c + L(z_c). ``time``, ``P``: the return (nan without)."""

    p: np.ndarray
    z0: np.ndarray
    start: str
    t_c: float
    z_c: np.ndarray
    slides: bool
    ts: float
    two_fold: bool
    t_star: float
    time: float
    P: np.ndarray


def visible_slide(p1, p2, q1, q2, x, y):
    """The slide from (x, y) on H (x < 0 < y) near a visible-invisible two-fold: ("exit",
    ts, y_e), ("two-fold", None, None), or None (neither clearly: it passes within 2 % of
    |z| of the fold line x = 0 on its way into the two-fold, or runs on past 2e4 steps
    of s)."""
    K = np.array([[-q1, p1, 0.0], [-q2, p2, 0.0], [-1.0, 1.0, 0.0]])
    h = 0.02 / np.linalg.norm(K[:2, :2], 2)
    E = expm(K * h)
    Y = np.array([x, y, 0.0])
    size0, closest = np.hypot(x, y), np.inf
    for i in range(20000):
        Yn = E @ Y
        if Yn[0] >= 0.0:   # the exit, crossing x = 0 at the rate p1 y_e in s
            s = brentq(lambda s: (expm(K * s) @ np.array([x, y, 0.0]))[0], i * h, (i + 1) * h,
                       xtol=1e-15, rtol=4 * np.finfo(float).eps)
            Ye = expm(K * s) @ np.array([x, y, 0.0])
            return ("exit", float(Ye[2]), float(Ye[1])) if Ye[1] >= 0.05 * size0 else None
        closest = min(closest, -Yn[0] / np.hypot(Yn[0], Yn[1]))
        if np.hypot(Yn[0], Yn[1]) <= 1e-9 * size0:
            return ("two-fold", None, None) if closest >= 0.02 else None
        Y = Yn
    return None


def visible_two_fold_from(p1, p2, q1, q2, sigma, start, x, y, tc_frac=0.5):
    """The VisibleTwoFold of f+ = (p1, p2, x), f- = (q1, q2, y), the section w = sigma,
    first on H at (x, y): ``start`` "on H" there, or "below" on the - arc that reaches it
    at t_c = tc_frac 2 y / q2 (w = y (t - t_c) + q2 (t - t_c)^2 / 2 < 0 on [0, t_c): its
    other zero is before 0). None where the generator's conditions fail."""
    if abs(p2 * q1 - p1 * q2) < 0.1:   # L exists
        return None
    p = np.array([p1, p2, q1, q2, sigma])
    if start == "on H":
        z0, t_c = np.array([x, y, 0.0]), 0.0
    else:
        t_c = tc_frac * 2.0 * y / q2
        z0 = np.array([x - q1 * t_c, y - q2 * t_c, -(y * t_c - 0.5 * q2 * t_c * t_c)])
    z_c = np.array([x, y, 0.0])
    if x > 0:   # crossing: x tau + p1 tau^2 / 2 = sigma
        tau = (-x + np.sqrt(x * x + 2.0 * p1 * sigma)) / p1
        P = np.array([x + p1 * tau, y + p2 * tau, sigma])
        return VisibleTwoFold(p, z0, start, t_c, z_c, False, 0.0, False, np.nan, t_c + tau, P)
    end = visible_slide(p1, p2, q1, q2, x, y)
    if end is None:
        return None
    kind, ts, y_e = end
    if kind == "two-fold":
        u, v = slide_rate_one(p1, p2, q1, q2)
        t_star = float(t_c + u * y + v * x)
        return VisibleTwoFold(p, z0, start, t_c, z_c, True, np.nan, True, t_star, np.nan,
                              None) if t_star <= T_MAX else None
    tau = np.sqrt(2.0 * sigma / p1)
    P = np.array([p1 * tau, y_e + p2 * tau, sigma])
    if t_c + ts + tau > T_MAX or np.abs(P).max() > GROWTH:   # O(1) times and states
        return None
    return VisibleTwoFold(p, z0, start, t_c, z_c, True, ts, False, np.nan, t_c + ts + tau, P)


@st.composite
def visible_two_folds(draw):
    p1 = draw(st.floats(0.5, 2.0), label="p1")
    p2 = draw(st.floats(-2.0, 2.0), label="p2")
    q1 = draw(st.floats(-2.0, 2.0), label="q1")
    q2 = draw(st.floats(0.5, 2.0), label="q2")
    sigma = draw(st.floats(0.1, 1.0), label="sigma")
    start = draw(st.sampled_from(["below", "on H"]), label="start")
    # where the orbit is on H first: in the sliding region x < 0 < y, or (from below) in
    # the crossing region x, y > 0 -- clear of the fold lines (well conditioned)
    x = draw(st.floats(0.05, 1.5), label="|x_c|") \
        * (-1.0 if start == "on H" or draw(st.booleans(), label="slides") else 1.0)
    y = draw(st.floats(0.2 if start == "below" else 0.05, 1.5), label="y_c")
    tc_frac = draw(st.floats(0.1, 0.9), label="t_c q2 / 2 y_c") if start == "below" else 0.0
    case = visible_two_fold_from(p1, p2, q1, q2, sigma, start, x, y, tc_frac)
    assume(case is not None)
    return case


# ----------------------------------------------------------------------------- a NaN past a switch
# test_properties.PHANTOM_NAN: x' = 0 below H = {y = 0}, 1 above, y' = 1; the piece named
# is NaN where y - x > 1/4, which only the flow of region - continued past H reaches.
@njit(cache=True)
def _phantom_term(z):
    return 0.0 * np.sqrt(0.25 - z[1] + z[0])


@njit(cache=True)
def phantom_minus(z, p):
    return np.array([0.0, 1.0])


@njit(cache=True)
def phantom_plus(z, p):
    return np.array([1.0, 1.0])


@njit(cache=True)
def phantom_flow_minus(z0, tau, p):
    return np.array([z0[0], z0[1] + tau])


@njit(cache=True)
def phantom_flow_plus(z0, tau, p):
    return np.array([z0[0] + tau, z0[1] + tau])


@njit(cache=True)
def phantom_switch(z, p):
    return z[1] + (_phantom_term(z) if p[0] == 0.0 else 0.0)


@njit(cache=True)
def phantom_grad(z, p):
    return np.array([_phantom_term(z) if p[0] == 1.0 else 0.0, 1.0])


@njit(cache=True)
def phantom_section(z, p):
    """x = 2."""
    return z[0] - 2.0 + (_phantom_term(z) if p[0] == 2.0 else 0.0)


def phantom_system(piece: str, exact: bool) -> FilippovSystem:
    """The system of test_properties.PHANTOM_NAN with ``piece`` NaN where y - x > 1/4
    (p[0]: its index in NAN_PIECES), built once per process (with p[0] = 3, no NaN, for
    the construction's probe)."""
    key = ("phantom", exact)
    if key not in _SYSTEMS:
        flows = dict(flow_minus=phantom_flow_minus, flow_plus=phantom_flow_plus,
                     sample_step=0.1) if exact else {}
        fs = _Cached(("x", "y"), phantom_minus, phantom_plus, phantom_switch, phantom_grad,
                     params=np.array([3.0]), name="phantom", **flows)
        fs.compiled(phantom_section)
        fs.python_section(phantom_section)
        fs.python()
        _SYSTEMS[key] = fs
    fs = _SYSTEMS[key]
    fs.params[0] = NAN_PIECES.index(piece)
    return fs
