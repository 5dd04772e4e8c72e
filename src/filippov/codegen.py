"""SymPy expressions printed as numba pieces with the compiled ABI, cached on disk.

A generated module holds, for each piece, the compiled engine's form
(:mod:`filippov.abi` signatures: ``field(z, p, out)``, ``h(z, p)``,
``flow(z0, tau, p, out)``, ``where(z, p)``; a Jacobian is a field with ``n*n``
outputs, row by row, a flow's Jacobian a flow with ``n*n`` outputs) and, for vectors, scalars and flows, a batch form for the
reference driver (``field_batch(zs, p) -> (n, m)`` over the columns of ``zs``).
States and parameters are read from ``z`` and ``p`` by position; common
subexpressions are shared (:func:`sympy.cse`).

The module is written once per source (its file name is the sha256 of the
source) to a cache directory -- ``$FILIPPOV_CACHE_DIR``, else
``$XDG_CACHE_HOME/filippov`` or ``~/.cache/filippov`` -- and imported, so numba's
on-disk cache (``cache=True``) keeps the compiled pieces between processes: a
second process loads them instead of compiling. Where no cache directory can be
written, the source is compiled in memory (correct, only slower to start).
"""
from __future__ import annotations

import hashlib
import importlib.util
import os
import sys
import tempfile
from pathlib import Path
from typing import Sequence

import sympy as sp
from sympy.printing.numpy import NumPyPrinter
from sympy.printing.pycode import PythonCodePrinter

from .errors import SymbolicError

#: piece kinds -> (signature name in filippov.abi, arguments)
KINDS = {"vector": ("FIELD_SIG", "_z, _p, _out"), "matrix": ("FIELD_SIG", "_z, _p, _out"),
         "scalar": ("SCALAR_SIG", "_z, _p"), "where": ("WHERE_SIG", "_z, _p"),
         "flow": ("FLOW_SIG", "_z0, _tau, _p, _out"),
         "flow_matrix": ("FLOW_SIG", "_z0, _tau, _p, _out")}
#: names the generated code uses itself: no state or parameter may take them
RESERVED = {"math", "numpy", "njit", "FIELD_SIG", "FLOW_SIG", "JAC_SIG", "SCALAR_SIG",
            "WHERE_SIG", "_out"}


def check_name(name: str, what: str) -> None:
    """A symbol name the generated code can use as a variable (else ValueError)."""
    import keyword
    import re

    if not name.isidentifier() or keyword.iskeyword(name) or name.startswith("_") \
            or name in RESERVED or re.fullmatch(r"c_\d+", name):
        raise ValueError(f"{what}: the symbol name {name!r} cannot be a variable of the "
                         f"generated code (use a Python identifier, not starting with '_', "
                         f"not a keyword, not {sorted(RESERVED - {'_out'})} or c_<number>)")


class _Printer(PythonCodePrinter):
    """Python 3 with ``math`` functions; floats printed so that they read back exactly."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "standard": "python3"})

    def _print_Float(self, expr):
        return repr(float(expr))   # sympy's default keeps 15 digits: 8 pi would lose its last bits


class _NumPyPrinter(NumPyPrinter):
    """NumPy, elementwise over any array shape; floats printed so that they read back."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True})

    def _print_Float(self, expr):
        return repr(float(expr))


def _body(exprs: Sequence, head: list[str], printer=_Printer,
          name: str = "a piece") -> tuple[list[str], list[str]]:
    reps, reduced = sp.cse(list(exprs), symbols=sp.numbered_symbols("c_"))
    pr = printer()
    try:
        return (head + [f"{s} = {pr.doprint(e)}" for s, e in reps],
                [pr.doprint(e) for e in reduced])
    except NotImplementedError as exc:   # sympy's PrintMethodNotImplementedError
        # a kink's derivative (|x|: re and im of a complex symbol; Max, Min) has no code:
        # the printer's raw error named neither the piece nor what to write instead
        what = str(exc).splitlines()[0]
        raise SymbolicError(
            f"{name}: cannot be written as code ({what}). A field with a kink (Abs, Max, "
            f"Min) has no Jacobian formula there: write the kink as a switching surface, "
            f"or give the system without it") from None


_BATCH = {
    "vector": """
@njit(cache=True)
def {name}_batch(zs, p):
    m = zs.shape[1]
    out = numpy.empty(({n}, m))
    z = numpy.empty({n})
    o = numpy.empty({n})
    for j in range(m):
        for i in range({n}):
            z[i] = zs[i, j]
        {name}(z, p, o)
        for i in range({n}):
            out[i, j] = o[i]
    return out
""",
    "scalar": """
@njit(cache=True)
def {name}_batch(zs, p):
    m = zs.shape[1]
    out = numpy.empty(m)
    z = numpy.empty({n})
    for j in range(m):
        for i in range({n}):
            z[i] = zs[i, j]
        out[j] = {name}(z, p)
    return out
""",
    "flow": """
@njit(cache=True)
def {name}_batch(z0, taus, p):
    out = numpy.empty(({n}, taus.size))
    o = numpy.empty({n})
    for j in range(taus.size):
        {name}(z0, taus[j], p, o)
        for i in range({n}):
            out[i, j] = o[i]
    return out
"""}


def source(title: str, states: Sequence, params: Sequence, pieces: dict,
           time=None) -> str:
    """The module's source. ``pieces`` maps a name to ``(kind, expressions)``: a
    sequence of n (vector, flow), n*n (matrix, flow_matrix: row-major) or one expression
    (scalar, where). Flows and their Jacobians read the start state from ``z0`` and the
    elapsed time ``time`` from ``tau``."""
    n = len(states)
    out = [f'"""Generated by filippov.codegen: {title}. Do not edit."""', "import math",
           "", "import numpy", "from numba import njit", "",
           "from filippov.abi import FIELD_SIG, FLOW_SIG, JAC_SIG, SCALAR_SIG, WHERE_SIG", ""]
    for name, (kind, exprs) in pieces.items():
        sig, args = KINDS[kind]
        flow = kind in ("flow", "flow_matrix")
        zname = "_z0" if flow else "_z"
        head = [f"{s} = {zname}[{i}]" for i, s in enumerate(states)]
        head += [f"{s} = _p[{i}]" for i, s in enumerate(params)]
        if flow:
            head.append(f"{time} = _tau")
        lines, res = _body(list(exprs), head, name=name)
        out += ["", f"@njit({sig}, cache=True)", f"def {name}({args}):"]
        out += ["    " + ln for ln in lines]
        if kind in ("scalar", "where"):
            out.append(f"    return {res[0]}")
        else:
            out += [f"    _out[{k}] = {r}" for k, r in enumerate(res)]
        if kind in _BATCH:
            out.append(_BATCH[kind].format(name=name, n=n))
    return "\n".join(out) + "\n"


_JAC_DISPATCH = """

@njit(JAC_SIG, cache=True)
def jacobian(_mode, _z, _p, _out):
    if _mode > 0:
        jacobian_plus(_z, _p, _out)
    elif _mode < 0:
        jacobian_minus(_z, _p, _out)
    else:
        {sliding}
"""


def jacobian_dispatch(sliding: bool) -> str:
    """The ABI's ``jacobian(mode, z, p, out)`` over the pieces ``jacobian_minus``,
    ``jacobian_plus`` and (``sliding``) ``jacobian_sliding``; NaN for sliding without one."""
    body = ("jacobian_sliding(_z, _p, _out)" if sliding else
            "for _k in range(_out.size):\n            _out[_k] = math.nan")
    return _JAC_DISPATCH.format(sliding=body)


def _cache_dir() -> Path:
    root = os.environ.get("FILIPPOV_CACHE_DIR")
    if not root:
        base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
        root = os.path.join(base, "filippov")
    return Path(root) / "generated"


_LOADED: dict[str, object] = {}


def load(src: str):
    """The module of ``src``: imported from its cached file (written atomically on first
    use), or compiled in memory where no cache directory can be written."""
    key = hashlib.sha256(src.encode()).hexdigest()[:24]
    if key in _LOADED:
        return _LOADED[key]
    modname = f"filippov_generated_{key}"
    try:
        folder = _cache_dir()
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{modname}.py"
        if not path.is_file() or path.read_text() != src:
            fd, tmp = tempfile.mkstemp(dir=folder, suffix=".tmp")
            with os.fdopen(fd, "w") as fh:
                fh.write(src)
            os.replace(tmp, path)          # other processes see all of it or nothing
        spec = importlib.util.spec_from_file_location(modname, path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[modname] = module
        spec.loader.exec_module(module)
    except OSError:
        module = _in_memory(modname, src)
    _LOADED[key] = module
    return module


def _in_memory(modname: str, src: str):
    import types

    module = types.ModuleType(modname)
    # numba caches only functions defined in a file: compile without the cache here
    exec(compile(src.replace("cache=True", "cache=False"), f"<{modname}>", "exec"),
         module.__dict__)
    return module


# ------------------------------------------------------------------------------- NumPy
_NUMPY_HEAD = '''"""Generated by filippov.codegen: {title}. Do not edit."""
import numpy


def _out(values, shape, like):
    """The values stacked to ``shape + numpy.shape(like)`` (constants broadcast)."""
    tail = numpy.shape(like)
    if not shape:
        v = numpy.asarray(values[0], dtype=float)
        return (numpy.broadcast_to(v, tail).copy() if v.shape != tail else v)[()]
    out = numpy.empty(tuple(shape) + tail)
    flat = out.reshape((-1,) + tail)
    for k, v in enumerate(values):
        flat[k] = v
    return out
'''


def numpy_source(title: str, functions: Sequence) -> str:
    """Source of NumPy functions, elementwise over trailing sample axes: each entry
    ``(name, args, exprs, shape, like)`` with ``args`` a list of ``(argument,
    symbols)`` (component k of the argument is symbols[k]; a bare symbol is the
    argument itself), ``exprs`` the flat outputs, ``shape`` their shape (``()`` for
    one value) and ``like`` the argument expression whose shape the samples take."""
    out = [_NUMPY_HEAD.format(title=title)]
    for name, args, exprs, shape, like in functions:
        head = []
        for arg, syms in args:
            if isinstance(syms, sp.Symbol):
                head.append(f"{syms} = {arg}")
            else:
                head += [f"{s} = {arg}[{i}]" for i, s in enumerate(syms)]
        lines, res = _body(list(exprs), head, _NumPyPrinter, name)
        out += ["", f"def {name}({', '.join(a for a, _ in args)}):"]
        out += ["    " + ln for ln in lines]
        out.append(f"    return _out([{', '.join(res)}], {tuple(shape)!r}, {like})")
        out.append("")
    return "\n".join(out)


def load_numpy(src: str):
    """The NumPy module of ``src`` (built in memory: nothing to compile or cache)."""
    import types

    key = hashlib.sha256(src.encode()).hexdigest()[:24]
    if key not in _LOADED:
        module = types.ModuleType(f"filippov_generated_numpy_{key}")
        exec(compile(src, f"<{module.__name__}>", "exec"), module.__dict__)
        _LOADED[key] = module
    return _LOADED[key]


# ------------------------------------------------------------------ NumPy, as written
class _WrittenOrderPrinter(_NumPyPrinter):
    """NumPy with the terms and factors in the order of the expression's tree (no
    canonical reordering): an expression kept unevaluated (``parse_expr(...,
    evaluate=False)``) is printed with the same operations, in the same order, as
    the text it was parsed from, so it rounds like a hand-written NumPy form of that
    text. Functions SymPy does not know are printed as calls (see :func:`lambdify_written`)."""

    def __init__(self):
        NumPyPrinter.__init__(self, {"fully_qualified_modules": True, "order": "none",
                                     "allow_unknown_functions": True})


def lambdify_written(args: Sequence, expr, functions: dict | None = None):
    """A NumPy function of ``args`` computing ``expr`` (an expression or a list),
    printed in written order (:class:`_WrittenOrderPrinter`), without common
    subexpressions; ``functions`` names the Python callables of the undefined
    functions in ``expr`` (e.g. a friction branch chosen by the caller)."""
    return sp.lambdify(args, expr, modules=[dict(functions or {}), "numpy"],
                       printer=_WrittenOrderPrinter(), cse=False)


def parse_written(text: str, names: dict):
    """``text`` as a SymPy expression kept in its written order (unevaluated: ``a - b +
    c`` stays ``(a - b) + c``), the names read from ``names``; ``.doit()`` gives the
    canonical expression."""
    from sympy.parsing.sympy_parser import parse_expr

    return parse_expr(text, local_dict=dict(names), evaluate=False)
