"""What numba freezes into a compiled piece, and the check that it has not changed since.

numba compiles a function with the values of the globals and closure cells it reads as
constants: a later ``K = 2.0`` in the user's module (or ``A[0, 0] = 5.0`` on a global
array) is not seen by the compiled piece, which goes on with the old value while Python
code reading the same name sees the new one. A system is compiled once and reused, so
such a change would give a silent wrong answer. :func:`record` notes the values a
piece's code reads (its globals and cells that hold numbers, numpy arrays or tuples of
them, followed into the numba-compiled functions it calls) when the pieces are first
compiled; :func:`check` refuses, naming the piece and the value, once one has changed.
Parameters that change belong in ``p``.

Not seen: a piece handed over already compiled (an ``@njit`` function run before with
other values), and Python objects other than numbers and arrays (numba refuses most).
"""
from __future__ import annotations

import dis
import numbers
import types
from typing import Callable

import numpy as np

from .checks import SystemContractError

_DATA = (numbers.Number, np.ndarray, np.generic)   # bool is a Number


def _is_data(v) -> bool:
    return isinstance(v, _DATA) or (isinstance(v, tuple) and all(_is_data(x) for x in v))


def _copy(v):
    return np.array(v, copy=True) if isinstance(v, np.ndarray) else \
        tuple(_copy(x) for x in v) if isinstance(v, tuple) else v


def _same(a, b) -> bool:
    if type(a) is not type(b):
        return False
    if isinstance(a, np.ndarray):
        return (a.shape == b.shape and a.dtype == b.dtype
                and bool(np.array_equal(a, b, equal_nan=a.dtype.kind in "fc")))
    if isinstance(a, tuple):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b))
    return bool(a == b) or bool(a != a and b != b)   # NaN stays NaN


def _global_names(code: types.CodeType) -> set[str]:
    """The names ``code`` and the functions defined in it load as globals."""
    names, stack = set(), [code]
    while stack:
        c = stack.pop()
        names.update(ins.argval for ins in dis.get_instructions(c)
                     if ins.opname == "LOAD_GLOBAL")
        stack.extend(k for k in c.co_consts if isinstance(k, types.CodeType))
    return names


class _Read:
    """One value a compiled function reads: where it lives, and its value when noted."""

    def __init__(self, piece: str, fn, name: str, cell=None):
        self.piece, self.fn, self.name, self.cell = piece, fn, name, cell
        self.value = _copy(self.current())

    def current(self):
        if self.cell is None:
            return self.fn.__globals__.get(self.name, _GONE)
        try:
            return self.cell.cell_contents
        except ValueError:   # the cell emptied (del): changed
            return _GONE


_GONE = object()   # a global deleted since: changed


def _reads(piece: str, fn, seen: set) -> list[_Read]:
    fn = getattr(fn, "py_func", fn)   # a numba dispatcher: its Python function
    if id(fn) in seen or not isinstance(fn, types.FunctionType):
        return []
    seen.add(id(fn))
    found = []
    candidates = [(name, fn.__globals__[name], None)
                  for name in sorted(_global_names(fn.__code__)) if name in fn.__globals__]
    for name, cell in zip(fn.__code__.co_freevars, fn.__closure__ or ()):
        try:
            candidates.append((name, cell.cell_contents, cell))
        except ValueError:   # an empty cell (a name bound later)
            continue
    for name, value, cell in candidates:
        if _is_data(value):
            found.append(_Read(piece, fn, name, cell))
        elif hasattr(value, "py_func"):   # a compiled function it calls: frozen too
            found += _reads(piece, value, seen)
    return found


def record(pieces: dict[str, Callable]) -> list[_Read]:
    """The values numba freezes into the functions ``pieces`` ({piece name: function or
    numba dispatcher}), noted now: call it when they are first compiled."""
    out = []
    for piece, fn in pieces.items():
        out += _reads(piece, fn, set())
    return out


def check(reads: list[_Read]) -> None:
    """Raises SystemContractError if a value in ``reads`` (:func:`record`) has changed."""
    for r in reads:
        now = r.current()
        if now is _GONE or not _same(r.value, now):
            kind = "closes over" if r.cell is not None else "reads the global"
            was = np.array2string(r.value, threshold=6) if isinstance(r.value, np.ndarray) \
                else repr(r.value)
            raise SystemContractError(
                f"{r.piece}: {kind} {r.name!r} ({r.fn.__qualname__}), which numba compiled "
                f"in as {was} and which has changed since; the compiled piece would go on "
                f"with the old value. Pass values that change in the parameters p "
                f"(params=), or build the system again")
