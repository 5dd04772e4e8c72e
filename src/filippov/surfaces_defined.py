"""Several switching surfaces defined once: a :class:`~filippov.FilippovSystem` given
``fields=`` (or a :class:`~filippov.SymbolicSystem` given a list of switching
functions). The user's pieces are checked by name and compiled into numba loops over
samples (:mod:`filippov.batches`); :func:`reference_system` is the
:class:`~filippov.surfaces.SurfacesSystem` the reference engine runs stay by stay
(:mod:`filippov.several`), and :func:`mode_jacobian` the Jacobian of a mode's field
from those of the regions (the ``jacobian=`` of the variational equations).

The definition (docs/decisions.md#several-surfaces-as-stays):

* ``switch``: a tuple of m functions ``h_k(z, p) -> float``, or one function giving the
  m values; ``switch_grad``: a tuple of m gradients ``(n,)``, or one function giving
  the ``(m, n)`` matrix;
* ``fields``: a mapping from each sign vector (a tuple of m values +-1; ``sigma_k = +1``
  where ``h_k >= 0``) to ``f(z, p)``, or one function ``f(sigma, z, p)`` (``sigma`` a
  tuple of m ints);
* ``jacobians`` (optional): a mapping from sign vectors to ``J(z, p) -> (n, n)``.

m = 1 is today's one-surface system (:func:`one_surface`): the same pieces, so the same
numbers on both engines, bit for bit.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Mapping

import numpy as np
from numba import njit
from numba.core.errors import NumbaError

from . import batches
from .differences import fd_jacobian
from .errors import SystemContractError
from .surfaces import MAX_SURFACES, SurfacesSystem, check_regions, digits, regions


@dataclass(frozen=True)
class Pieces:
    """The pieces of m surfaces as loops over samples: ``fields[sigma](zs, p) -> (n, b)``,
    ``switches(zs, p) -> (m, b)``, ``grads(zs, p) -> (m * n, b)``, and the regions'
    Jacobians ``jacobians[sigma](z) -> (n, n)`` that were given."""

    m: int
    fields: dict
    switches: Callable
    grads: Callable
    jacobians: dict


def sign_vector(key, m: int | None, what: str = "fields") -> tuple:
    """``key`` as a sign vector (a tuple of m ints +-1), else refused naming ``what``."""
    try:
        values = [float(s) for s in key]
    except (TypeError, ValueError):
        values = None
    if values is None or any(v not in (-1.0, 1.0) for v in values) or (
            m is not None and len(values) != m):
        size = "values +-1" if m is None else f"{m} values +-1"
        raise ValueError(f"{what}: {key!r} is not a sign vector (a tuple of {size})")
    return tuple(int(v) for v in values)


def count(fields, switch, n: int, params: np.ndarray, probe: np.ndarray) -> int:
    """m: the length of the sign vectors of ``fields``, the number of ``switch``
    functions, or the number of values one ``switch`` gives at the probe state; those
    given must agree, else refused naming the pieces."""
    found = {}
    if isinstance(fields, Mapping):
        if not fields:
            raise ValueError("fields: no region's field given")
        lengths = {len(sign_vector(k, None)) for k in fields}
        if len(lengths) > 1:
            raise ValueError(f"fields: sign vectors of different lengths {sorted(lengths)}")
        found["fields"] = lengths.pop()
    if isinstance(switch, (tuple, list)):
        found["switch"] = len(switch)
    elif callable(switch):
        with np.errstate(all="ignore"):
            try:
                found["switch"] = int(np.asarray(
                    getattr(switch, "py_func", switch)(probe, params)).size)
            except Exception as exc:   # noqa: BLE001 -- named below
                raise SystemContractError(f"switch failed at z={probe.tolist()}: {exc}") \
                    from None
    else:
        raise TypeError("switch: expected a function h(z, p) of the m values, or a tuple "
                        "of m functions")
    if len(set(found.values())) > 1:
        raise ValueError(f"switch: {found['switch']} switching functions, but fields has "
                         f"sign vectors of {found['fields']} values")
    m = found["switch"]
    if not 1 <= m <= MAX_SURFACES:
        raise ValueError(f"switch: {m} switching functions; from 1 to {MAX_SURFACES} are "
                         f"taken")
    return m


def _region_piece(user, sigma: tuple):
    """``f(sigma, z, p)`` as the region's ``f(z, p)`` (sigma compiled in)."""
    sig = tuple(int(s) for s in sigma)

    def region(z, p):
        return user(sig, z, p)
    return njit(region)


def region_functions(fields, m: int) -> dict:
    """Each region's field as a numba dispatcher ``f(z, p)``, by sign vector; every
    region must have one."""
    if isinstance(fields, Mapping):
        out = {sign_vector(k, m): batches.jit(f, f"fields[{k!r}]") for k, f in fields.items()}
        check_regions(out, m)
        return out
    if not callable(fields):
        raise TypeError("fields: expected a mapping from sign vectors to f(z, p), or a "
                        "function f(sigma, z, p)")
    user = batches.jit(fields, "fields")
    return {s: _region_piece(user, s) for s in regions(m)}


def _row_piece(user, k: int):
    def row(z, p):
        return user(z, p)[k]
    return njit(row)


def _first_row(fn, piece: str, ndim: int, z: np.ndarray, params: np.ndarray):
    """A piece of m = 1 as one surface's: itself where it gives one surface's shape at z
    (``ndim`` 0: a value, 1: a gradient), else its first row (an array of one value, a
    (1, n) matrix)."""
    user = batches.jit(fn, piece)
    with np.errstate(all="ignore"):
        try:
            got = np.ndim(getattr(fn, "py_func", fn)(z, params))
        except Exception:   # noqa: BLE001 -- the engines' checks name it when run
            got = ndim + 1
    return user if got == ndim else _row_piece(user, 0)


def one_surface(fields: dict, switch, switch_grad, z: np.ndarray, params: np.ndarray) -> dict:
    """The pieces of m = 1 as today's one-surface system's (field_minus, field_plus,
    switch, switch_grad), numba dispatchers; the switch and its gradient as one surface's
    or as one row of several (asked of them at the probe state z)."""
    h = switch[0] if isinstance(switch, (tuple, list)) else switch
    g = switch_grad[0] if isinstance(switch_grad, (tuple, list)) else switch_grad
    return dict(field_minus=fields[(-1,)], field_plus=fields[(1,)],
                switch=_first_row(h, "switch", 0, z, params),
                switch_grad=_first_row(g, "switch_grad", 1, z, params))


def stacked(parts: list):
    """Loops over samples of one row each (or a block of rows), stacked: (rows, b)."""
    def batch(zs, p):
        return np.concatenate([part(zs, p).reshape(-1, zs.shape[1]) for part in parts])
    return batch


def compile_pieces(names, fields: dict, switch, switch_grad, jacobians, m: int) -> Pieces:
    """:class:`Pieces` from the user's functions (``fields`` from
    :func:`region_functions`)."""
    n = len(names)
    vec = {s: batches.vector(f, n, f"fields[{s}]") for s, f in fields.items()}
    if isinstance(switch, (tuple, list)):
        if len(switch) != m:
            raise ValueError(f"switch: {len(switch)} functions for m = {m} surfaces")
        hs = stacked([batches.scalar(batches.jit(h, f"switch[{k}]"), n)
                      for k, h in enumerate(switch)])
    else:
        hs = batches.rows(batches.jit(switch, "switch"), n, m, "switch")
    if isinstance(switch_grad, (tuple, list)):
        if len(switch_grad) != m:
            raise ValueError(f"switch_grad: {len(switch_grad)} gradients for m = {m} "
                             f"surfaces")
        gs = stacked([batches.vector(batches.jit(g, f"switch_grad[{k}]"), n,
                                     f"switch_grad[{k}]")
                      for k, g in enumerate(switch_grad)])
    elif callable(switch_grad):
        gs = batches.rows(batches.jit(switch_grad, "switch_grad"), n, m * n, "switch_grad")
    else:
        raise TypeError("switch_grad: expected a function of the (m, n) gradients, or a "
                        "tuple of m functions")
    jac = {sign_vector(key, m, "jacobians"): batches.jit(J, f"jacobians[{key!r}]")
           for key, J in dict(jacobians or {}).items()}
    return Pieces(m, vec, hs, gs, jac)


def probe(pc: Pieces, names, params: np.ndarray, z: np.ndarray) -> None:
    """Every piece once at the state ``z``: a failure or a non-finite value is refused
    naming the piece (what the one-surface system's pieces get, filippov.compiled_system)."""
    n, col = len(names), np.ascontiguousarray(z.reshape(-1, 1))
    pieces = {f"fields[{s}]": (b, n) for s, b in pc.fields.items()}
    pieces.update(switch=(pc.switches, pc.m), switch_grad=(pc.grads, pc.m * n))
    for piece, (batch, size) in pieces.items():
        try:
            with np.errstate(all="ignore"):
                v = np.asarray(batch(col, params), dtype=float)
        except NumbaError as exc:
            raise batches.cannot_compile(exc, piece) from None
        except Exception as exc:   # noqa: BLE001 -- the piece's own, named here
            line = next((ln for ln in str(exc).splitlines() if ln.strip()), type(exc).__name__)
            raise SystemContractError(f"{piece} failed at z={z.tolist()}: {line} (expected "
                                      f"{size} values)") from None
        if v.size != size or not np.all(np.isfinite(v)):
            raise SystemContractError(f"{piece} must return {size} finite values at "
                                      f"z={z.tolist()}, got {v.ravel().tolist()}")


def reference_system(pc: Pieces, names, params: np.ndarray, **options) -> SurfacesSystem:
    """The :class:`~filippov.surfaces.SurfacesSystem` of the pieces (``options``: its
    ``sliding``, ``scale``, ``intersection``, ``description``)."""
    n, m = len(names), pc.m

    def vector(batch):
        def piece(z):
            zs, tail = batches.states(z, n)
            return batch(zs, params).reshape((n,) + tail)
        return piece

    def switches(z):
        zs, tail = batches.states(z, n)
        return pc.switches(zs, params).reshape((m,) + tail)

    def switch_grads(z):
        zs, tail = batches.states(z, n)
        return pc.grads(zs, params).reshape((m, n) + tail)

    return SurfacesSystem(tuple(names), switches, switch_grads,
                          {s: vector(b) for s, b in pc.fields.items()}, m, **options)


def sliding_jacobian(Fm, Fp, g, Jm, Jp, Hh, z, mode: int = 0) -> np.ndarray:
    """``dF_s/dz`` of Filippov's sliding field ``F_s = (a F_+ - b F_-) / (a - b)``,
    ``a = g.F_-``, ``b = g.F_+`` (g the surface's gradient), from the fields' Jacobians
    ``Jm``, ``Jp`` and ``Hh[:, k] = d g / d z_k`` (the switching function's Hessian)."""
    a, b = g @ Fm, g @ Fp
    if not abs(a - b) > 0:
        raise ValueError(f"jacobian: no Jacobian of mode {mode} (sliding) at z={z.tolist()}: "
                         f"Filippov's sliding field is not defined where dH.F_- = dH.F_+ "
                         f"(= {a!r})")
    da, db = Hh.T @ Fm + Jm.T @ g, Hh.T @ Fp + Jp.T @ g   # gradients of a and b
    num = a * Fp - b * Fm
    dnum = np.outer(Fp, da) + a * Jp - np.outer(Fm, db) - b * Jm
    return dnum / (a - b) - np.outer(num, da - db) / (a - b) ** 2


def grad_derivative(grad: Callable, z: np.ndarray, floor: float) -> np.ndarray:
    """``Hh[:, k] = d grad / d z_k`` by central differences (step eps^(1/3) times the
    state's size; exact for a planar surface)."""
    n = z.size
    step = np.cbrt(np.finfo(float).eps) * max(floor, float(np.abs(z).max()))
    Hh = np.empty((n, n))
    for k in range(n):
        e = np.zeros(n)
        e[k] = step
        Hh[:, k] = (np.asarray(grad(z + e), float) - np.asarray(grad(z - e), float)) / (
            2 * step)
    return Hh


def mode_jacobian(system: SurfacesSystem, region_jacobian: Callable, mode: int,
                  z: np.ndarray, floor: float) -> np.ndarray:
    """dF/dz of the field of ``mode`` (a code of :mod:`filippov.surfaces`) at z: a
    region's from ``region_jacobian(sigma, z)``; a slide on one surface's from the two
    regions beside it (:func:`sliding_jacobian`); a slide on an intersection's by central
    differences of its bilinear field (no closed form)."""
    d = digits(mode, system.m)
    if d.count(0) == 0:
        return region_jacobian(d, z)
    if d.count(0) == 1:
        k, plus, minus = system.beside(mode)
        Fm, Fp = (np.asarray(system.region_field(s, z), float) for s in (minus, plus))
        Hh = grad_derivative(lambda zz: system.grads(zz)[k], z, floor)
        return sliding_jacobian(Fm, Fp, system.grads(z)[k], region_jacobian(minus, z),
                                region_jacobian(plus, z), Hh, z, mode)
    return fd_jacobian(lambda zz: system.mode_field(mode, zz), z,
                       np.cbrt(np.finfo(float).eps), floor)
