"""The state on the current segment of the orbit (an exact flow from the mode entry, or
the dense output of an integration step: state.Orbit, w.seg's positions in kernel.state)
and the event functions evaluated on it."""
from __future__ import annotations


from ..system import PLUS, SLIDING
from .base import (_S_A, _S_B, _S_DA, _S_DB, _S_H, _flow_minus, _flow_plus, _jit, _scalar, _speeds)
from .dop853 import _dense_eval
from .state import SEG_ENTRY, SEG_INTEGRATED, SEG_RATE_STEP, SEG_SHIFT, SEG_STEP_H, SEG_STEP_T


@_jit
def _zat(t, mode, o, out):
    """The state at t on the segment of the orbit o (state.Orbit) in out."""
    sg = o.seg
    if mode == SLIDING or sg[SEG_INTEGRATED] != 0.0:
        _dense_eval(t, sg[SEG_STEP_T], sg[SEG_STEP_H], o.y_old, o.F, out)
    elif mode == PLUS:
        _flow_plus(o.fns, o.za, t - sg[SEG_ENTRY], o.p, out)
    else:
        _flow_minus(o.fns, o.za, t - sg[SEG_ENTRY], o.p, out)


@_jit
def _fval(sel, t, mode, o, sc):
    """The event function ``sel`` (base._S_*) at t on the segment (sc: state.Scratch)."""
    if sel == _S_DA or sel == _S_DB:  # the rate of a or b (as _rates)
        d = o.seg[SEG_RATE_STEP]
        base = _S_A if sel == _S_DA else _S_B
        _zat(t + d, mode, o, sc.wz)
        v1 = _scalar(base, sc.wz, o.fns, o.p, sc.wg, sc.wf)
        _zat(t, mode, o, sc.wz)
        v0 = _scalar(base, sc.wz, o.fns, o.p, sc.wg, sc.wf)
        return (v1 - v0) / d
    _zat(t, mode, o, sc.wz)
    v = _scalar(sel, sc.wz, o.fns, o.p, sc.wg, sc.wf)
    return v - o.seg[SEG_SHIFT] if sel == _S_H else v  # the stay's rules.exit_shift


@_jit
def _rates(t, a0, b0, mode, o, sc):
    """(da/dt, db/dt) on the segment at t, where a and b are a0 and b0: forward
    differences of step SEG_RATE_STEP (rules.rate_step), the values _fval(_S_DA / _S_DB, t)
    gives one at a time."""
    d = o.seg[SEG_RATE_STEP]
    _zat(t + d, mode, o, sc.wz)
    a1, b1 = _speeds(sc.wz, o.fns, o.p, sc.wg, sc.wf, sc.wp)
    return (a1 - a0) / d, (b1 - b0) / d
