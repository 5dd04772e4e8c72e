"""scipy's DOP853 inside the kernel: its tableau, one accepted step with scipy's step-size
control, its initial step, its 7th-order dense output (used for sliding and for the
regions of a model without exact flows)."""
from __future__ import annotations

import numpy as np

from .. import dop853_tableau as _dop
from .. import rules
from ..system import MINUS, PLUS
from .base import (_field_minus, _field_plus, _jit, _speeds)
from .state import Stages

# ----------------------------------------------------------------------------- DOP853 tableau
# The coefficients of scipy's DOP853, which the reference driver integrates sliding
# with (the sliding field is autonomous: the nodes C are not needed).
_NS = _dop.N_STAGES              # 12
_NSE = _dop.N_STAGES_EXTENDED    # 16
_NI = _dop.INTERPOLATOR_POWER    # 7
# _checked_field's first_call, as numpy booleans: a literal True/False would compile it
# twice (see base: codes handed to helpers)
_FIRST_CALL, _TRIAL = np.bool_(True), np.bool_(False)
# the rows of K _met_guard searches, as numpy integers for the same reason: the stages
# (the field at the step's end among them), then the interpolant's extra stages
_STAGE_1, _EXTRA_1, _EXTRA_END = np.int64(1), np.int64(_NS + 1), np.int64(_NSE)
_A = np.ascontiguousarray(_dop.A, dtype=np.float64)
_B = np.ascontiguousarray(_dop.B, dtype=np.float64)
_E3 = np.ascontiguousarray(_dop.E3, dtype=np.float64)
_E5 = np.ascontiguousarray(_dop.E5, dtype=np.float64)
_D = np.ascontiguousarray(_dop.D, dtype=np.float64)
_C = np.ascontiguousarray(_dop.C, dtype=np.float64)   # the stages' nodes (K[_NS]: 1)
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_ERR_EXP = -1.0 / (7 + 1)  # error estimator order 7


@_jit
def _dense_eval(t, t_old, hs, y_old, F, out):
    """scipy's Dop853DenseOutput at a scalar t."""
    x = (t - t_old) / hs
    # one component at a time: per component scipy's operations in scipy's order, in
    # loops that compile small (docs/decisions.md#kernel-small-loops)
    for k in range(y_old.size):
        acc = 0.0
        for i in range(_NI):
            acc += F[_NI - 1 - i, k]
            acc *= x if i % 2 == 0 else 1.0 - x
        out[k] = acc + y_old[k]


@_jit
def _checked_field(z, mode, first_call, fns, p, fl, out):
    """The field of ``mode`` (the Filippov field when sliding; fl: state.Fill) with the
    non-finite guard both engines keep (rules.NON_FINITE_STAGE): a non-finite value at
    the first call is an error (False), on a trial stage it is replaced."""
    if mode == PLUS:
        _field_plus(fns, z, p, out)
    elif mode == MINUS:
        _field_minus(fns, z, p, out)
    else:
        a, b = _speeds(z, fns, p, fl.wg, fl.wm, fl.wp)
        for k in range(z.size):
            out[k] = (a * fl.wp[k] - b * fl.wm[k]) / (a - b)
    finite = True
    for k in range(z.size):
        if not np.isfinite(out[k]):
            finite = False
            break  # an early exit: not vectorized (docs/decisions.md#kernel-small-loops)
    if not finite:
        if first_call:
            return False
        for k in range(z.size):
            out[k] = rules.NON_FINITE_STAGE
    return True


@_jit
def _stage(s, mode, y0, h, st, fns, p, fl):
    """Stage s of the tableau from y0 over h: K[s] = field(y0 + h sum_j<s A[s, j] K[j])
    (st: state.Stages, K and ytmp, which holds the stage's state)."""
    K, ytmp = st.K, st.ytmp
    for k in range(y0.size):
        acc = 0.0
        for j in range(s):
            acc += K[j, k] * _A[s, j]
        ytmp[k] = y0[k] + acc * h
    _checked_field(ytmp, mode, _TRIAL, fns, p, fl, K[s])


@_jit
def _rms(x, scale):
    s = 0.0
    for k in range(x.size):
        q = x[k] / scale[k]
        s += q * q
    return np.sqrt(s) / np.sqrt(x.size)


@_jit
def _dop_initial_step(mode, t0, ctl, fns, p, fl, d):
    """scipy.integrate._ivp.common.select_initial_step for DOP853 (order 7) from d.y, its
    field d.f (ctl: state.Control; d: state.Dop, d.ynew and d.ytmp scratch)."""
    t_bound, max_step, rtol, atol = ctl.t_bound, ctl.max_step, ctl.rtol, ctl.atol
    y0, f0, y1, f1, scale = d.y, d.f, d.ynew, d.ytmp, d.scale
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    n = y0.size
    for k in range(n):
        scale[k] = atol[k] + abs(y0[k]) * rtol
    d0 = _rms(y0, scale)
    d1 = _rms(f0, scale)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    h0 = min(h0, interval)
    for k in range(n):
        y1[k] = y0[k] + h0 * f0[k]
    _checked_field(y1, mode, _TRIAL, fns, p, fl, f1)
    s = 0.0
    for k in range(n):
        q = (f1[k] - f0[k]) / scale[k]
        s += q * q
    d2 = np.sqrt(s) / np.sqrt(n) / h0
    if d1 <= 1e-15 and d2 <= 1e-15:
        h1 = max(1e-6, h0 * 1e-3)
    else:
        h1 = (0.01 / max(d1, d2)) ** (1.0 / 8.0)
    return min(100.0 * h0, h1, interval, max_step)


@_jit
def _dop_step(mode, t, h_abs, ctl, fns, p, fl, d):
    """One accepted step of scipy's DOP853 (RungeKutta._step_impl) from d.y, its field
    d.f (ctl: state.Control; d: state.Dop).

    Returns (ok, t_new, h, h_abs_next, t_guard); K holds the stages, ynew the new
    state, K[_NS] the field there; t_guard: the time of the first stage of a trial that
    met the non-finite guard (inf: none), where the orbit found is asked again
    (driver._next_step). On failure (the step size collapsed): (False, t, the last step
    tried, h_abs, t_guard), K holding that step's stages (see _non_finite_stage)."""
    t_bound, max_step, rtol, atol = ctl.t_bound, ctl.max_step, ctl.rtol, ctl.atol
    y, f, K, ynew, scale = d.y, d.f, d.K, d.ynew, d.scale
    stages = Stages(K, d.ytmp)
    n = y.size
    h = 0.0
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    if h_abs > max_step:
        h_abs = max_step
    elif h_abs < min_step:
        h_abs = min_step
    rejected = False
    t_guard = np.inf
    while True:
        if not h_abs >= min_step:  # also stops a NaN step size
            return False, t, h, h_abs, t_guard
        h = h_abs
        t_new = t + h
        if t_new - t_bound > 0.0:
            t_new = t_bound
        h = t_new - t
        h_abs = abs(h)
        # rk_step
        for k in range(n):
            K[0, k] = f[k]
        for s in range(1, _NS):
            _stage(s, mode, y, h, stages, fns, p, fl)
        for k in range(n):
            acc = 0.0
            for j in range(_NS):
                acc += K[j, k] * _B[j]
            ynew[k] = y[k] + h * acc
        _checked_field(ynew, mode, _TRIAL, fns, p, fl, K[_NS])
        # error norm (DOP853._estimate_error_norm)
        for k in range(n):
            scale[k] = atol[k] + max(abs(y[k]), abs(ynew[k])) * rtol
        e5, e3 = 0.0, 0.0
        for k in range(n):
            a5, a3 = 0.0, 0.0
            for j in range(_NS + 1):
                a5 += K[j, k] * _E5[j]
                a3 += K[j, k] * _E3[j]
            a5 /= scale[k]
            a3 /= scale[k]
            e5 += a5 * a5
            e3 += a3 * a3
        e5 = np.sqrt(e5) ** 2
        e3 = np.sqrt(e3) ** 2
        if e5 == 0.0 and e3 == 0.0:
            err = 0.0
        else:
            err = abs(h) * e5 / np.sqrt((e5 + 0.01 * e3) * n)
        # a step whose stages met the non-finite guard is never accepted, nor one whose
        # interpolant's extra stages (taken here for _dop_dense) did (_met_guard)
        guard = _met_guard(K, _STAGE_1, _EXTRA_1)
        if err < 1.0 and guard == 0:
            for s in range(_NS + 1, _NSE):
                _stage(s, mode, y, h, stages, fns, p, fl)
            guard = _met_guard(K, _EXTRA_1, _EXTRA_END)
        if guard != 0 and t_guard == np.inf:
            t_guard = t + _C[guard] * h
        if err < 1.0 and guard == 0:
            if err == 0.0:
                factor = _MAX_FACTOR
            else:
                factor = min(_MAX_FACTOR, _SAFETY * err ** _ERR_EXP)
            if rejected:
                factor = min(1.0, factor)
            return True, t_new, h, h_abs * factor, t_guard
        q = _SAFETY * err ** _ERR_EXP
        h_abs *= q if q > _MIN_FACTOR and guard == 0 else _MIN_FACTOR   # NaN q: MIN too
        rejected = True


@_jit
def _met_guard(K, first, stop):
    """A stage of the step among K[first:stop] (K[1:_NS + 1]: the stages, the field at
    its end among them; K[_NS + 1:]: the interpolant's) took the non-finite guard's
    constant (_checked_field fills its row with it): the first such stage, or 0. Where
    several stages take the constant, the error estimate (zero for a constant field)
    passes the step; where the interpolant's do, the dense output, and the events on
    it, are ~1e300 (docs/decisions.md#named-edges (4), (5))."""
    for s in range(first, stop):
        if K[s, 0] == rules.NON_FINITE_STAGE:
            return s
    return 0


@_jit
def _non_finite_stage(y, h, K, out):
    """After a failed step from y over h (stages in K): True if a stage met a non-finite
    field value (_checked_field put rules.NON_FINITE_STAGE in its row), with that
    stage's state in out (the interpolant's stages last: those of an earlier trial of
    the step may be left there)."""
    n = y.size
    found = 0
    for s in range(1, _NSE):
        hit = True
        for k in range(n):
            if K[s, k] != rules.NON_FINITE_STAGE:
                hit = False
                break  # an early exit: not vectorized (docs/decisions.md#kernel-small-loops)
        if hit:
            found = s
            break
    if found == 0:
        return False
    # the stage's state once, after the search (docs/decisions.md#kernel-small-loops)
    for k in range(n):
        acc = 0.0
        for j in range(found):
            acc += K[j, k] * (_B[j] if found == _NS else _A[found, j])
        out[k] = y[k] + acc * h
    return True


@_jit
def _dop_dense(h, d):
    """DOP853._dense_output_impl of the step h from d.y_old to d.y: the interpolant d.F
    (7, n), of the extra stages _dop_step took before it accepted the step."""
    y_old, y, f_old, f, K, F = d.y_old, d.y, d.f_old, d.f, d.K, d.F
    n = y.size
    for k in range(n):
        dy = y[k] - y_old[k]
        F[0, k] = dy
        F[1, k] = h * f_old[k] - dy
        F[2, k] = 2.0 * dy - h * (f[k] + f_old[k])
        for r in range(_NI - 3):
            acc = 0.0
            for j in range(_NSE):
                acc += _D[r, j] * K[j, k]
            F[3 + r, k] = h * acc
