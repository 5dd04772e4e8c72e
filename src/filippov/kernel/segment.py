"""The state on the current segment of the orbit (an exact flow from the mode entry, or
the dense output of an integration step) and the event functions evaluated on it."""
from __future__ import annotations


from ..system import PLUS, SLIDING
from .base import (_S_A, _S_B, _S_DA, _S_DB, _S_H, _flow_minus, _flow_plus, _jit, _scalar, _speeds)
from .dop853 import _dense_eval

# output (F, y_old) of the integration step [sg[1], sg[1] + sg[2]] -- always
# when sliding, and in regions + and - when sg[3] != 0 (a model without flows).
# sg[4]: what the stay subtracts from H (rules.exit_shift; 0 but after a slide), moved by
# sg[5], the rounding band of the exit the stay began at, while the orbit is inside it
# (rules.exit_band, rules.banded_shift; 0 once it is out); sg[6]: the exit_shift alone;
# sg[7]: while sliding, the step of the forward differences that give the rates of a and
# b along the orbit in the current window (rules.rate_step; 0: none).
# sg[8], sg[9]: outside sliding, h and |f|^2 at the last sample of the last window (the
# next window's first sample: scan._carry_sample).
@_jit
def _zat(t, mode, sg, za, F, y_old, fns, p, out):
    if mode == SLIDING or sg[3] != 0.0:
        _dense_eval(t, sg[1], sg[2], y_old, F, out)
    elif mode == PLUS:
        _flow_plus(fns, za, t - sg[0], p, out)
    else:
        _flow_minus(fns, za, t - sg[0], p, out)


@_jit
def _fval(sel, t, mode, sg, za, F, y_old, fns, p, wz, wg, wf):
    if sel == _S_DA or sel == _S_DB:  # the rate of a or b (as _rates)
        d = sg[7]
        base = _S_A if sel == _S_DA else _S_B
        _zat(t + d, mode, sg, za, F, y_old, fns, p, wz)
        v1 = _scalar(base, wz, fns, p, wg, wf)
        _zat(t, mode, sg, za, F, y_old, fns, p, wz)
        v0 = _scalar(base, wz, fns, p, wg, wf)
        return (v1 - v0) / d
    _zat(t, mode, sg, za, F, y_old, fns, p, wz)
    v = _scalar(sel, wz, fns, p, wg, wf)
    return v - sg[4] if sel == _S_H else v  # sg[4]: the stay's rules.exit_shift


@_jit
def _rates(t, a0, b0, mode, sg, za, F, y_old, fns, p, wz, wg, wf, wp):
    """(da/dt, db/dt) on the segment at t, where a and b are a0 and b0: forward
    differences of step sg[7] (rules.rate_step), the values _fval(_S_DA / _S_DB, t)
    gives one at a time."""
    d = sg[7]
    _zat(t + d, mode, sg, za, F, y_old, fns, p, wz)
    a1, b1 = _speeds(wz, fns, p, wg, wf, wp)
    return (a1 - a0) / d, (b1 - b0) / d
