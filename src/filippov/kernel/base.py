"""What every part of the compiled kernel shares: the model pieces' function types,
the status codes, event and predicate codes, the compile decorators, the rule book
registered as compilable from its one source (filippov.rules) and the small model-piece
helpers."""
from __future__ import annotations

import functools
import inspect

import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.extending import intrinsic, register_jitable

from .. import rules
from ..abi import PIECES
from ..loop import interval
# the status codes: one set for both engines, declared in filippov.loop.status
from ..loop.status import (BAD_START, EVENT_LIMIT, FLOW_OFF_FIELD, NON_FINITE,  # noqa: F401
                           NO_RETURN, NO_SLIDING, OK, ROOT_FAILED, SECTION_SLIDING, STATUS,
                           STEP_FAILED, STEP_LIMIT, ZENO)


# ----------------------------------------------------------------------------- signatures
_vec = types.float64[::1]
#: the numba types of the model's pieces, in the kernel's order (filippov.abi.PIECES)
_PIECE_TYPES = tuple(types.FunctionType(sig) for _, sig in PIECES)

# crossing predicates (filippov.rules), as numpy integers (docs/decisions.md#kernel-codes-are-numpy-integers)
_TO_NEG, _TO_NONNEG, _TO_NONPOS, _EITHER = (
    np.int64(c) for c in (rules.TO_NEG, rules.TO_NONNEG, rules.TO_NONPOS, rules.EITHER))
# scalar functions of the state whose zeros are events; and the rates of a and b along
# the orbit (forward differences on the segment, step w.seg[SEG_RATE_STEP] of
# kernel.state: rules.rate_step), whose zeros are their extrema while sliding
_S_H, _S_A, _S_B, _S_SEC, _S_DA, _S_DB = (np.int64(c) for c in range(6))
# brentq's iteration bounds, the reference driver's (rules.BRENT_MAXITER): for an event,
# and for the extremum of h or of a normal speed between two samples
_MAXITER_EVENT = _MAXITER_EXTREMUM = np.int64(rules.BRENT_MAXITER)
# what an event is
_W_NONE, _W_SWITCH, _W_EXIT_MINUS, _W_EXIT_PLUS, _W_SECTION = -1, 0, 1, 2, 3

_TINY = np.finfo(float).tiny
_EPS = np.finfo(float).eps


# Every helper works on arrays it is handed and allocates nothing (only _batch allocates)
# and is never called from Python: compiled without reference counting and without
# numba's CPython and C wrappers (docs/decisions.md#kernel-no-refcounting)
_jit = njit(cache=True, _nrt=False, no_cpython_wrapper=True, no_cfunc_wrapper=True)
# the driver's pieces (kernel.driver: the stay's operations, _window, the event's) are
# inlined into _one at the IR level, and so are the pieces of the window walk,
# kernel.scan._window_event (docs/decisions.md#kernel-inlined-driver)
_jit_inline = njit(cache=True, _nrt=False, inline="always")


def rule_book():
    """The rule book: every public function of filippov.rules, by name."""
    return {name: f for name, f in vars(rules).items()
            if inspect.isfunction(f) and f.__module__ == rules.__name__
            and not name.startswith("_")}


# Every rule compiles where compiled code calls it: the loop (filippov.loop), the kernel
# and a rule calling another (section_first: same_instant) all call ``rules.<name>`` as
# the reference driver does, and numba compiles that function into its caller, without
# a wrapper or a cache of its own (its caller's cache holds it; kernel.driver's stamp
# covers rules.py). A new rule needs no entry here.
for _rule in rule_book().values():
    register_jitable(_nrt=False)(_rule)


@functools.cache
def compiled_rule(name):
    """rules.<name> compiled on its own, as the kernel compiles it, with a wrapper so that
    Python calls it: what tests compare with the rule run as Python."""
    return njit(_nrt=False)(rule_book()[name])


# the codes the one event search (filippov.loop.interval) hands back
assert (_W_NONE, _W_SWITCH, _W_EXIT_MINUS, _W_EXIT_PLUS, _W_SECTION) == (
    interval.NONE, rules.SWITCH, rules.EXIT_MINUS, rules.EXIT_PLUS, interval.SECTION)
assert OK == interval.OK


# ============================================================================= model pieces
# The model's pieces reach the kernel as their compiled addresses: a tuple of integers
# (_PIECE_ADDRS, in the order of filippov.abi.PIECES; fastmap.compute_returns takes them
# from numba-compiled pieces only, once per piece: fastmap._address), each called straight
# at its address with its signature from PIECES (docs/decisions.md#kernel-piece-addresses)
_PIECE_ADDRS = types.UniTuple(types.intp, len(PIECES))


def _call_piece_codegen(index):
    def codegen(context, builder, signature, args):
        sig = _PIECE_TYPES[index].signature
        fnptr = builder.inttoptr(builder.extract_value(args[0], index),
                                 context.call_conv.get_function_type(
                                     sig.return_type, sig.args).as_pointer())
        status, res = context.call_conv.call_function(builder, fnptr, sig.return_type,
                                                      sig.args, args[1:])
        with cgutils.if_unlikely(builder, status.is_error):
            context.call_conv.return_status_propagate(builder, status)
        return res
    return codegen


def _piece(name):
    """An intrinsic ``piece(fns, *args)``: calls the piece ``name`` of filippov.abi.PIECES
    at its address fns[its index] (_PIECE_ADDRS) with its signature's arguments (numba's intrinsics take no ``*args``:
    one typing function per arity)."""
    index = [n for n, _ in PIECES].index(name)
    arity = len(PIECES[index][1].args)

    def typed(fns):
        sig = _PIECE_TYPES[index].signature
        return sig.return_type(fns, *sig.args), _call_piece_codegen(index)
    by_arity = {2: lambda typingctx, fns, a, b: typed(fns),
                3: lambda typingctx, fns, a, b, c: typed(fns),
                4: lambda typingctx, fns, a, b, c, d: typed(fns)}
    return intrinsic(by_arity[arity])


# the piece at fns[k] by name: (z0, tau, p, out), (z, p, out), (z, p) -> float or bool, (mode, z, p, out)
(_flow_plus, _flow_minus, _field_plus, _field_minus, _h, _grad_h, _section, _where,
 _jacobian, _flow_jacobian_plus, _flow_jacobian_minus) = (_piece(name) for name, _ in PIECES)


@_jit
def _dot(u, v):
    s = 0.0
    for k in range(u.size):
        s += u[k] * v[k]
    return s


@_jit
def _speeds(z, fns, p, wg, wm, wp):
    """(a, b) = (grad h . F_-, grad h . F_+) at z; fills wg, wm, wp."""
    _grad_h(fns, z, p, wg)
    _field_minus(fns, z, p, wm)
    _field_plus(fns, z, p, wp)
    return _dot(wg, wm), _dot(wg, wp)


@_jit
def _scalar(sel, z, fns, p, wg, wf):
    if sel == _S_H:
        return _h(fns, z, p)
    if sel == _S_SEC:
        return _section(fns, z, p)
    _grad_h(fns, z, p, wg)
    if sel == _S_A:
        _field_minus(fns, z, p, wf)
    else:
        _field_plus(fns, z, p, wf)
    return _dot(wg, wf)
