"""A compiled (numba) fast path for first returns of a piecewise system to a section.

:func:`filippov.poincare.first_returns` runs the event-driven driver of
:mod:`filippov.simulate` once per start point, in Python. This module runs the
same algorithm for a whole batch of start points inside one compiled call:

* regions ``+`` (``h >= 0``) and ``-`` are followed with the model's exact
  flows in the reference driver's windows: ``16 sample_step`` from each mode entry
  (``16 slow_sample_step`` once ``transient_time`` has passed since the entry),
  the flow always taken from the state at the mode entry. Each window is cut into
  16 intervals: one sample per sample step, the spacing the model declares to
  resolve its events (the reference driver samples ``samples_per_step`` times
  denser, since its samples are also the stored trajectory; the two agree to
  rounding, not bit for bit); a model without exact flows
  (``CompiledModel.exact = False``) has them integrated like sliding, below
  (the reference driver's ``method="integrate"``);
* the samples are scanned for the same events: ``h`` leaving the region, a
  hidden grazing crossing (a sign change of ``dh/dt`` whose extremum of ``h``
  goes through zero; ``|h| <= touch_tol`` there is a touch, not a switch), the
  section (direction and ``where`` condition; a section root at the instant of
  a switch is the return, a start on the section up to rounding is not, as for
  :class:`filippov.simulate.Section`); roots are refined with a port of scipy's
  ``brentq`` (same tolerances) and then stepped to the far side of the crossing;
* at ``h = 0`` the Filippov decision uses ``a = grad h . F_-`` and
  ``b = grad h . F_+`` exactly as :func:`filippov.simulate._decide`;
* sliding is integrated with a port of scipy's ``DOP853`` (same coefficients,
  step-size control, initial step and 7th-order dense output) with the Filippov
  field ``(a F_+ - b F_-)/(a - b)``; it ends where ``a`` or ``b`` reaches zero.
  Each integrated step is sampled at ``samples_per_step + 1`` points of its
  dense output.

Failures never raise inside the compiled code and never hang: each start point
gets a status code (:data:`STATUS`) -- event or step bound hit, accumulation of
switches (Zeno), non-finite state, no return within ``t_max``, ...; the wrapper
:func:`first_returns_compiled` turns a failure into the same exception types as
the reference driver.

A model enters as a :class:`CompiledModel`: numba-compiled pieces with the
signatures below (passed to the kernel as first-class functions, so the kernel
is compiled once -- about 12 s -- cached on disk by numba, and serves every
model), plus a parameter vector ``params`` handed to every piece. See
:func:`filippov.models.hopf.compiled`.

One deliberate difference from :func:`filippov.poincare.first_returns`: a start
point that begins in sliding has that first sliding stretch counted in
``sliding_time`` (the reference's event bookkeeping skips it). Touches are not
recorded (they change nothing in a return).
"""
from __future__ import annotations

import hashlib
import warnings
from collections import namedtuple
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numba import njit, types
from numba.core.errors import NumbaExperimentalFeatureWarning

from . import dop853_tableau as _dop
# what a model hands the engine (its pieces' signatures, CompiledModel), re-exported here
from .abi import FIELD_SIG, FLOW_SIG, SCALAR_SIG, WHERE_SIG, CompiledModel, no_flow  # noqa: F401
from .poincare import Returns
from .progress import Progress
from .simulate import (EXACT_BLOCK, EventLimitError, SimulationError,
                       SlidingNotBuiltError, ZenoError, slow_window)
from . import rules
from .system import MINUS, PLUS, SLIDING

# ----------------------------------------------------------------------------- signatures
_vec = types.float64[::1]
_FLOW = types.FunctionType(FLOW_SIG)
_FIELD = types.FunctionType(FIELD_SIG)
_SCALAR = types.FunctionType(SCALAR_SIG)
_WHERE = types.FunctionType(WHERE_SIG)

# ----------------------------------------------------------------------------- status codes
OK = 0
NO_RETURN = 1      # t_max reached before the section
EVENT_LIMIT = 2    # more than max_events switches
STEP_LIMIT = 3     # more than max_steps windows / integration steps
ZENO = 4           # zeno_count switches within zeno_span
NON_FINITE = 5     # non-finite state or field value
NO_SLIDING = 6     # attracting sliding reached, but the model declares no sliding
STEP_FAILED = 7    # the sliding integrator's step size collapsed
ROOT_FAILED = 8    # an event could not be bracketed / refined
BAD_START = 9      # non-finite start point
SECTION_SLIDING = 10  # the orbit slides inside the section (a section on H)

STATUS = {OK: "ok", NO_RETURN: "no return within t_max", EVENT_LIMIT: "event limit",
          STEP_LIMIT: "step limit", ZENO: "accumulation of switches (Zeno)",
          NON_FINITE: "non-finite state or field value",
          NO_SLIDING: "attracting sliding reached, but the model declares no sliding",
          STEP_FAILED: "sliding integrator: step size too small",
          ROOT_FAILED: "event refinement failed (no bracket or no convergence)",
          BAD_START: "non-finite start point",
          SECTION_SLIDING: "the orbit slides along H inside the section (a section on the "
                           "switching surface): its crossings there would be rounding noise"}

# crossing predicates (filippov.rules)
_TO_NEG, _TO_NONNEG, _TO_NONPOS, _EITHER = rules.TO_NEG, rules.TO_NONNEG, rules.TO_NONPOS, rules.EITHER
# scalar functions of the state whose zeros are events
_S_H, _S_A, _S_B, _S_SEC = 0, 1, 2, 3
# what an event is
_W_NONE, _W_SWITCH, _W_EXIT_MINUS, _W_EXIT_PLUS, _W_SECTION = -1, 0, 1, 2, 3

_TINY = np.finfo(float).tiny
_EPS = np.finfo(float).eps

# ----------------------------------------------------------------------------- DOP853 tableau
# The coefficients of scipy's DOP853, which the reference driver integrates sliding
# with (the sliding field is autonomous: the nodes C are not needed).
_NS = _dop.N_STAGES              # 12
_NSE = _dop.N_STAGES_EXTENDED    # 16
_NI = _dop.INTERPOLATOR_POWER    # 7
_A = np.ascontiguousarray(_dop.A, dtype=np.float64)
_B = np.ascontiguousarray(_dop.B, dtype=np.float64)
_E3 = np.ascontiguousarray(_dop.E3, dtype=np.float64)
_E5 = np.ascontiguousarray(_dop.E5, dtype=np.float64)
_D = np.ascontiguousarray(_dop.D, dtype=np.float64)
_SAFETY, _MIN_FACTOR, _MAX_FACTOR = 0.9, 0.2, 10.0
_ERR_EXP = -1.0 / (7 + 1)  # error estimator order 7


# Every helper below works on arrays it is handed and allocates nothing, so it is
# compiled without numba's reference counting (_nrt=False): otherwise each call
# of a helper pays an atomic incref/decref per array argument, which was half the
# run time. Only the kernel _batch allocates (its work arrays, once per call).
_jit = njit(cache=True, _nrt=False)
# the driver's pieces below (_window, _stay_*, _event) are inlined into _one at the
# IR level: as separate calls they were 4-13% slower on the fig04/fig11 maps, each
# call passing the named work arrays by value
_jit_inline = njit(cache=True, _nrt=False, inline="always")


# ============================================================================= rules
# every decision and crossing predicate, compiled from its one source (filippov.rules)
(_after, _crosses, _clamp, _far_side, _extremum_between, _graze, _central_step,
 _slides_in_section, _starts_on_section, _same_instant, _start_side, _start_on_switch,
 _next_mode, _accumulates, _exit_shift, _dips_and_returns, _exact_window, _onto_switch,
 _exit_drift) = (
    _jit(getattr(rules, name)) for name in (
    "after", "crosses", "clamp", "far_side", "extremum_between", "graze", "central_step",
    "slides_in_section", "starts_on_section", "same_instant", "start_side", "start_on_switch",
    "next_mode", "accumulates", "exit_shift", "dips_and_returns", "exact_window",
    "onto_switch", "exit_drift"))
assert (_W_SWITCH, _W_EXIT_MINUS, _W_EXIT_PLUS) == (rules.SWITCH, rules.EXIT_MINUS, rules.EXIT_PLUS)


# ============================================================================= model pieces
@_jit
def _dot(u, v):
    s = 0.0
    for k in range(u.size):
        s += u[k] * v[k]
    return s


@_jit
def _speeds(z, fns, p, wg, wm, wp):
    """(a, b) = (grad h . F_-, grad h . F_+) at z; fills wg, wm, wp."""
    fns[5](z, p, wg)
    fns[3](z, p, wm)
    fns[2](z, p, wp)
    return _dot(wg, wm), _dot(wg, wp)


@_jit
def _scalar(sel, z, fns, p, wg, wf):
    if sel == _S_H:
        return fns[4](z, p)
    if sel == _S_SEC:
        return fns[6](z, p)
    fns[5](z, p, wg)
    if sel == _S_A:
        fns[3](z, p, wf)
    else:
        fns[2](z, p, wf)
    return _dot(wg, wf)


@_jit
def _dense_eval(t, t_old, hs, y_old, F, out):
    """scipy's Dop853DenseOutput at a scalar t."""
    x = (t - t_old) / hs
    n = y_old.size
    for k in range(n):
        out[k] = 0.0
    for i in range(_NI):
        r = _NI - 1 - i
        for k in range(n):
            out[k] += F[r, k]
            if i % 2 == 0:
                out[k] *= x
            else:
                out[k] *= 1.0 - x
    for k in range(n):
        out[k] += y_old[k]


# A segment of the current mode: exact flow from za at time sg[0], or the dense
# output (F, y_old) of the integration step [sg[1], sg[1] + sg[2]] -- always
# when sliding, and in regions + and - when sg[3] != 0 (a model without flows).
# sg[4]: what the stay subtracts from H (rules.exit_shift; 0 but after a slide).
@_jit
def _zat(t, mode, sg, za, F, y_old, fns, p, out):
    if mode == SLIDING or sg[3] != 0.0:
        _dense_eval(t, sg[1], sg[2], y_old, F, out)
    elif mode == PLUS:
        fns[0](za, t - sg[0], p, out)
    else:
        fns[1](za, t - sg[0], p, out)


@_jit
def _fval(sel, t, mode, sg, za, F, y_old, fns, p, wz, wg, wf):
    _zat(t, mode, sg, za, F, y_old, fns, p, wz)
    v = _scalar(sel, wz, fns, p, wg, wf)
    return v - sg[4] if sel == _S_H else v  # sg[4]: the stay's rules.exit_shift


# ============================================================================= root finding
@_jit
def _brentq(sel, xa, xb, xtol, rtol, maxiter, mode, sg, za, F, y_old, fns, p, wz, wg, wf):
    """scipy.optimize.brentq (scipy/optimize/Zeros/brentq.c); returns (root, ok)."""
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _fval(sel, xpre, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
    fcur = _fval(sel, xcur, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
    if np.isnan(fpre) or np.isnan(fcur):
        return xcur, False
    if fpre == 0.0:
        return xpre, True
    if fcur == 0.0:
        return xcur, True
    if (fpre < 0.0) == (fcur < 0.0):
        return xcur, False
    for _ in range(maxiter):
        if fpre != 0.0 and fcur != 0.0 and ((fpre < 0.0) != (fcur < 0.0)):
            xblk = xpre
            fblk = fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = (xtol + rtol * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur, True
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)  # interpolate
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre = scur
                scur = stry
            else:
                spre = sbis
                scur = sbis
        else:
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = _fval(sel, xcur, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
        if np.isnan(fcur):
            return xcur, False
    return xcur, False


@_jit
def _refine(sel, pred, ta, tb, va, xtol, mode, sg, za, F, y_old, fns, p, wz, wg, wf):
    """simulate._refine: root in [ta, tb] on the far side of the crossing; (t, ok)."""
    pred = _far_side(pred, va)
    if va == 0.0:
        r = ta
    else:
        r, ok = _brentq(sel, ta, tb, xtol, 4.0 * _EPS, 200, mode, sg, za, F, y_old, fns, p,
                        wz, wg, wf)
        if not ok:
            # as simulate._refine: no sign change because the start sample of a
            # just-entered mode was clamped inside while the true value is already
            # past the crossing -- the event is at once
            if _after(pred, _fval(sel, ta, mode, sg, za, F, y_old, fns, p, wz, wg, wf)):
                r = ta
            else:
                return r, False
    a = max(abs(r), _TINY)
    step = 2.0 * (np.nextafter(a, np.inf) - a)
    while not _after(pred, _fval(sel, r, mode, sg, za, F, y_old, fns, p, wz, wg, wf)):
        if r >= tb:
            return tb, True
        r = min(r + step, tb)
        step *= 2.0
    return r, True


# ============================================================================= event scan
@_jit
def _sample(mode, ta, tb, frac, ns, sg, za, F, y_old, fns, p, ts, vals, dvals, svals,
            wz, wg, wf, wp, zlast):
    """Samples of one window: times ts, the leave functions (h, or a and b when
    sliding), dh/dt and the section; the last state in zlast. False: non-finite."""
    for k in range(ns):
        tk = ta + frac[k] * (tb - ta) if k < ns - 1 else tb
        ts[k] = tk
        _zat(tk, mode, sg, za, F, y_old, fns, p, wz)
        for c in range(wz.size):
            if not np.isfinite(wz[c]):
                return False
        if mode == SLIDING:
            a, b = _speeds(wz, fns, p, wg, wf, wp)
            vals[0, k] = a
            vals[1, k] = b
        else:
            vals[0, k] = fns[4](wz, p) - sg[4]
            fns[5](wz, p, wg)
            if mode == PLUS:
                fns[2](wz, p, wf)
            else:
                fns[3](wz, p, wf)
            dvals[k] = _dot(wg, wf)
        svals[k] = fns[6](wz, p)
    for c in range(wz.size):
        zlast[c] = wz[c]
    return True


@_jit
def _find(mode, ts, ns, first, sec_pred, touch_tol, xtol, min_time, sg, za, F, y_old, fns,
          p, vals, dvals, svals, wz, wg, wf, touched):
    """simulate._scan on the samples: the earliest event; (status, t, what). A touch of
    H on the way (no event) sets touched[0]."""
    if mode == PLUS:
        nleave, sel0, pred0, what0, sel_d = 1, _S_H, _TO_NEG, _W_SWITCH, _S_B
    elif mode == MINUS:
        nleave, sel0, pred0, what0, sel_d = 1, _S_H, _TO_NONNEG, _W_SWITCH, _S_A
    else:
        nleave, sel0, pred0, what0, sel_d = 2, _S_A, _TO_NONPOS, _W_EXIT_MINUS, _S_A
    if first:  # just entered this mode: its start is inside by construction
        vals[0, 0] = _clamp(pred0, vals[0, 0])
        if nleave == 2:
            vals[1, 0] = _clamp(_TO_NONNEG, vals[1, 0])
    for i in range(ns - 1):
        c0 = _crosses(pred0, vals[0, i], vals[0, i + 1])
        c1 = nleave == 2 and _crosses(_TO_NONNEG, vals[1, i], vals[1, i + 1])
        cd = mode != SLIDING and _extremum_between(mode, dvals[i], dvals[i + 1])
        cs = _crosses(sec_pred, svals[i], svals[i + 1])
        if not (c0 or c1 or cd or cs):
            continue
        ta, tb = ts[i], ts[i + 1]
        best_t, best_w = np.inf, _W_NONE
        if c0:
            lo, vlo = ta, vals[0, i]
            if first and i == 0 and mode != SLIDING and _dips_and_returns(mode, dvals[0], dvals[1]):
                tm, ok = _brentq(sel_d, ta, tb, xtol, 4.0 * _EPS, 100, mode, sg, za, F, y_old,
                                 fns, p, wz, wg, wf)
                hm = _fval(_S_H, tm, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
                if ok and not _after(pred0, hm):  # refine beyond the dip (rules)
                    lo, vlo = tm, hm
            r, ok = _refine(sel0, pred0, lo, tb, vlo, xtol, mode, sg, za, F, y_old,
                            fns, p, wz, wg, wf)
            if not ok:
                return ROOT_FAILED, r, _W_NONE
            best_t, best_w = r, what0
        if c1:
            r, ok = _refine(_S_B, _TO_NONNEG, ta, tb, vals[1, i], xtol, mode, sg, za, F,
                            y_old, fns, p, wz, wg, wf)
            if not ok:
                return ROOT_FAILED, r, _W_NONE
            if best_w == _W_NONE or r < best_t:
                best_t, best_w = r, _W_EXIT_PLUS
        if mode != SLIDING and best_w == _W_NONE and cd:
            # a minimum (in +) or maximum (in -) of h hidden between samples
            tm, ok = _brentq(sel_d, ta, tb, xtol, 4.0 * _EPS, 100, mode, sg, za, F, y_old,
                             fns, p, wz, wg, wf)
            if not ok:
                return ROOT_FAILED, tm, _W_NONE
            hm = _fval(_S_H, tm, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
            kind = _graze(mode, hm, touch_tol)
            if kind == rules.GRAZE_CROSSES:
                r, ok = _refine(_S_H, pred0, ta, tm, vals[0, i], xtol, mode, sg, za, F,
                                y_old, fns, p, wz, wg, wf)
                if not ok:
                    return ROOT_FAILED, r, _W_NONE
                best_t, best_w = r, _W_SWITCH
            elif kind == rules.GRAZE_TOUCHES:
                # |hm| <= touch_tol: a touch, not an event; P has a kink here
                touched[0] = True
        if cs:
            r, ok = _refine(_S_SEC, sec_pred, ta, tb, svals[i], xtol, mode, sg, za, F, y_old,
                            fns, p, wz, wg, wf)
            if not ok:
                return ROOT_FAILED, r, _W_NONE
            # simulate._scan: min_time; a tie with a switch (simulate._same_instant)
            # goes to the section; a start on the section up to rounding is no hit
            if r >= min_time and (best_w == _W_NONE
                                  or r <= best_t + _same_instant(xtol, best_t)):
                _zat(r, mode, sg, za, F, y_old, fns, p, wz)
                if fns[7](wz, p):
                    at_start = False
                    if ts[i] == 0.0:
                        _zat(ts[i], mode, sg, za, F, y_old, fns, p, wg)
                        at_start = _starts_on_section(svals[i], wg, fns[6](wz, p), wz)
                    if not at_start:
                        best_t, best_w = r, _W_SECTION
        if best_w != _W_NONE:
            return OK, best_t, best_w
    return OK, np.inf, _W_NONE


# ============================================================================= DOP853
@_jit
def _checked_field(z, mode, first_call, fns, p, wg, wm, wp, out):
    """The field of ``mode`` (the Filippov field when sliding) with
    simulate._IntegratingStepper's guard: a non-finite value at the first call
    is an error (False), on a trial stage it is 1e300."""
    if mode == PLUS:
        fns[2](z, p, out)
    elif mode == MINUS:
        fns[3](z, p, out)
    else:
        a, b = _speeds(z, fns, p, wg, wm, wp)
        for k in range(z.size):
            out[k] = (a * wp[k] - b * wm[k]) / (a - b)
    finite = True
    for k in range(z.size):
        if not np.isfinite(out[k]):
            finite = False
    if not finite:
        if first_call:
            return False
        for k in range(z.size):
            out[k] = 1e300
    return True


@_jit
def _rms(x, scale):
    s = 0.0
    for k in range(x.size):
        q = x[k] / scale[k]
        s += q * q
    return np.sqrt(s) / np.sqrt(x.size)


@_jit
def _dop_initial_step(mode, t0, y0, f0, t_bound, max_step, rtol, atol, fns, p, wg, wm, wp,
                      y1, f1, scale):
    """scipy.integrate._ivp.common.select_initial_step for DOP853 (order 7)."""
    interval = abs(t_bound - t0)
    if interval == 0.0:
        return 0.0
    n = y0.size
    for k in range(n):
        scale[k] = atol + abs(y0[k]) * rtol
    d0 = _rms(y0, scale)
    d1 = _rms(f0, scale)
    if d0 < 1e-5 or d1 < 1e-5:
        h0 = 1e-6
    else:
        h0 = 0.01 * d0 / d1
    h0 = min(h0, interval)
    for k in range(n):
        y1[k] = y0[k] + h0 * f0[k]
    _checked_field(y1, mode, False, fns, p, wg, wm, wp, f1)
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
def _dop_step(mode, t, y, f, h_abs, t_bound, max_step, rtol, atol, fns, p, wg, wm, wp,
              K, ynew, ytmp, scale):
    """One accepted step of scipy's DOP853 (RungeKutta._step_impl).

    Returns (ok, t_new, h, h_abs_next); K holds the stages, ynew the new state,
    K[_NS] the field there."""
    n = y.size
    min_step = 10.0 * abs(np.nextafter(t, np.inf) - t)
    if h_abs > max_step:
        h_abs = max_step
    elif h_abs < min_step:
        h_abs = min_step
    rejected = False
    while True:
        if not h_abs >= min_step:  # also stops a NaN step size
            return False, t, 0.0, h_abs
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
            for k in range(n):
                acc = 0.0
                for j in range(s):
                    acc += K[j, k] * _A[s, j]
                ytmp[k] = y[k] + acc * h
            _checked_field(ytmp, mode, False, fns, p, wg, wm, wp, K[s])
        for k in range(n):
            acc = 0.0
            for j in range(_NS):
                acc += K[j, k] * _B[j]
            ynew[k] = y[k] + h * acc
        _checked_field(ynew, mode, False, fns, p, wg, wm, wp, K[_NS])
        # error norm (DOP853._estimate_error_norm)
        for k in range(n):
            scale[k] = atol + max(abs(y[k]), abs(ynew[k])) * rtol
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
        if err < 1.0:
            if err == 0.0:
                factor = _MAX_FACTOR
            else:
                factor = min(_MAX_FACTOR, _SAFETY * err ** _ERR_EXP)
            if rejected:
                factor = min(1.0, factor)
            return True, t_new, h, h_abs * factor
        q = _SAFETY * err ** _ERR_EXP
        h_abs *= q if q > _MIN_FACTOR else _MIN_FACTOR  # max(MIN_FACTOR, q), NaN -> MIN_FACTOR
        rejected = True


@_jit
def _dop_dense(mode, h, y_old, y, f_old, f, fns, p, wg, wm, wp, K, ytmp, F):
    """DOP853._dense_output_impl: extra stages and the interpolant F (7, n)."""
    n = y.size
    for s in range(_NS + 1, _NSE):
        for k in range(n):
            acc = 0.0
            for j in range(s):
                acc += K[j, k] * _A[s, j]
            ytmp[k] = y_old[k] + acc * h
        _checked_field(ytmp, mode, False, fns, p, wg, wm, wp, K[s])
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



# ============================================================================= dP/dz
# The derivative of a return, carried in w.M while the orbit runs (Settings.jac), as the
# reference driver's filippov.variational composes it: an exact-flow stay by central
# differences of the closed-form flow from its mode entry; an integrated stay (sliding,
# or a model without flows) by the variational equation taken through the very DOP853
# steps of the state (internal differentiation: the derivative of the computed
# solution, the step sizes held); a switch by its saltation matrix; the end of sliding
# by the identity; the section hit by the projection along the field.
@_jit
def _apply(J, M, T):
    """M <- J M (T: workspace)."""
    n = M.shape[0]
    for i in range(n):
        for j in range(n):
            acc = 0.0
            for k in range(n):
                acc += J[i, k] * M[k, j]
            T[i, j] = acc
    for i in range(n):
        for j in range(n):
            M[i, j] = T[i, j]


@_jit
def _rank_one(M, u, g, speed):
    """M <- M + u (g^T M) / speed: a saltation matrix (u = f_after - f_before, g = grad
    h, speed = g . f_before) or the section's projection (u = f, speed = -g . f). A zero
    speed (a tangential switch or hit: no derivative) makes M NaN."""
    n = M.shape[0]
    for j in range(n):
        r = 0.0
        for k in range(n):
            r += g[k] * M[k, j]
        r = r / speed if speed != 0.0 else np.nan
        for i in range(n):
            M[i, j] += u[i] * r


@_jit
def _flow_jacobian(mode, za, tau, fns, p, J, z1, z2):
    """J = d flow(za, tau) / d za by central differences of the closed-form flow (step
    rules.central_step per component; za is restored bit for bit)."""
    for k in range(za.size):
        orig = za[k]
        d = _central_step(max(1.0, abs(orig)), 1.0)
        za[k] = orig + d
        up = za[k]
        if mode == PLUS:
            fns[0](za, tau, p, z1)
        else:
            fns[1](za, tau, p, z1)
        za[k] = orig - d
        down = za[k]
        if mode == PLUS:
            fns[0](za, tau, p, z2)
        else:
            fns[1](za, tau, p, z2)
        za[k] = orig
        for i in range(za.size):
            J[i, k] = (z1[i] - z2[i]) / (up - down)


@_jit
def _jvp(mode, y, v, out, fns, p, w):
    """out = J(y) v, the field's Jacobian along v, by a central difference
    (rules.central_step along v)."""
    n = y.size
    size, vmax = 1.0, 0.0
    for k in range(n):
        size = max(size, abs(y[k]))
        vmax = max(vmax, abs(v[k]))
    d = _central_step(size, vmax)
    if d == 0.0:
        for k in range(n):
            out[k] = 0.0 if vmax == 0.0 else np.nan
        return
    for k in range(n):
        w.jz1[k] = y[k] + d * v[k]
        w.jz2[k] = y[k] - d * v[k]
    _checked_field(w.jz1, mode, False, fns, p, w.wg, w.wf, w.wp, w.jf1)
    _checked_field(w.jz2, mode, False, fns, p, w.wg, w.wf, w.wp, w.jf2)
    for k in range(n):
        out[k] = (w.jf1[k] - w.jf2[k]) / (2.0 * d)


@_jit
def _var_step(mode, y0, h, fns, p, w):
    """w.M <- the DOP853 step of size h from y0 applied to the variational equation
    M' = J(z(t)) M, with the state's stages recomputed from y0 (the same numbers as the
    step of the state)."""
    n = y0.size
    for s in range(_NS):
        for k in range(n):
            acc = 0.0
            for j in range(s):
                acc += w.KV[j, k] * _A[s, j]
            w.ys[k] = y0[k] + acc * h
        _checked_field(w.ys, mode, False, fns, p, w.wg, w.wf, w.wp, w.KV[s])
        for a in range(n):
            for b in range(n):
                acc = 0.0
                for j in range(s):
                    acc += w.KP[j, a, b] * _A[s, j]
                w.Mt[a, b] = w.M[a, b] + acc * h
        for b in range(n):
            for a in range(n):
                w.jv[a] = w.Mt[a, b]
            _jvp(mode, w.ys, w.jv, w.jo, fns, p, w)
            for a in range(n):
                w.KP[s, a, b] = w.jo[a]
    for a in range(n):
        for b in range(n):
            acc = 0.0
            for j in range(_NS):
                acc += w.KP[j, a, b] * _B[j]
            w.M[a, b] += h * acc


@_jit
def _switch_derivative(mode, new_mode, fns, p, w):
    """w.M <- S w.M, S the saltation matrix of the switch mode -> new_mode at w.z."""
    _checked_field(w.z, mode, False, fns, p, w.wg, w.wf, w.wp, w.jf1)
    _checked_field(w.z, new_mode, False, fns, p, w.wg, w.wf, w.wp, w.jf2)
    fns[5](w.z, p, w.jz1)
    speed = _dot(w.jz1, w.jf1)
    for k in range(w.z.size):
        w.jf2[k] -= w.jf1[k]
    _rank_one(w.M, w.jf2, w.jz1, speed)


@_jit
def _section_derivative(mode, fns, p, w):
    """w.M <- (I - f g^T / (g . f)) w.M at the section hit w.z: f the field there, g the
    section's gradient (central differences; w.z is restored bit for bit)."""
    z = w.z
    _checked_field(z, mode, False, fns, p, w.wg, w.wf, w.wp, w.jf1)
    for k in range(z.size):
        orig = z[k]
        d = _central_step(max(1.0, abs(orig)), 1.0)
        z[k] = orig + d
        up = z[k]
        s1 = fns[6](z, p)
        z[k] = orig - d
        down = z[k]
        s2 = fns[6](z, p)
        z[k] = orig
        w.jz1[k] = (s1 - s2) / (up - down)
    _rank_one(w.M, w.jf1, w.jz1, -_dot(w.jz1, w.jf1))


# ============================================================================= one start point
@_jit
def _section_rate(z, wm, wp, cm, cp, d, fns, p, wz):
    """Central difference of the section along the field cm F_- + cp F_+."""
    for k in range(z.size):
        wz[k] = z[k] + d * (cm * wm[k] + cp * wp[k])
    s1 = fns[6](wz, p)
    for k in range(z.size):
        wz[k] = z[k] - d * (cm * wm[k] + cp * wp[k])
    return (s1 - fns[6](wz, p)) / (2.0 * d)


@_jit
def _slides_in(z, fns, p, wg, wm, wp, wz):
    """simulate._slides_in: the sliding flow at z stays in the section (on H)."""
    a, b = _speeds(z, fns, p, wg, wm, wp)
    speed, size = 0.0, 1.0
    for k in range(z.size):
        speed = max(speed, abs(wm[k]), abs(wp[k]))
        size = max(size, abs(z[k]))
    d = _central_step(size, speed)
    if d == 0.0:
        return False
    return _slides_in_section(fns[6](z, p), d, _section_rate(z, wm, wp, 1.0, 0.0, d, fns, p, wz),
                              _section_rate(z, wm, wp, 0.0, 1.0, d, fns, p, wz),
                              _section_rate(z, wm, wp, -b / (a - b), a / (a - b), d, fns, p, wz))


@_jit
def _initial_mode(z, fns, p, touch_tol, sliding, wg, wm, wp):
    """simulate.initial_mode (rules.start_side, rules.start_on_switch)."""
    H = fns[4](z, p)
    side = _start_side(H, touch_tol)
    if side != SLIDING:
        return side
    a, b = _speeds(z, fns, p, wg, wm, wp)
    mode, _ = _start_on_switch(H, a, b, sliding)
    return mode


#: what a batch runs with (compute_returns fills it; _batch builds it once per call)
Settings = namedtuple("Settings", [
    "t_max", "exact", "hwin", "hwin_slow", "transient", "sec_pred", "sliding",
    "frac_ex", "frac_in", "rtol", "atol", "touch_tol", "xtol", "zeno_span", "max_step",
    "min_time", "max_events", "max_steps", "zeno_count", "jac"])

#: the kernel's named work arrays, allocated once per batch by _batch. count: switches,
#: steps, entries in the Zeno ring; tally: time slid, start of the current slide
Work = namedtuple("Work", [
    "ts", "vals", "dvals", "svals", "recent", "sg", "za", "y", "f", "y_old", "f_old", "K",
    "ynew", "ytmp", "scale", "F", "wz", "wg", "wf", "wp", "z", "first_sw", "slide_dz",
    "slide_z0", "count", "tally",
    # dP/dz (Settings.jac): the derivative so far, workspaces, the variational stages
    "M", "Mt", "KV", "KP", "ys", "jv", "jo", "jz1", "jz2", "jf1", "jf2", "touched"])

_GO_ON = -1  # no event yet / the orbit goes on (never a returned status)


@_jit_inline
def _window(mode, ta, tb, frac, first, fns, p, s, w):
    """Samples the segment [ta, tb] of the current mode and finds its earliest event:
    (_GO_ON, tb, _W_NONE) if there is none (the state at tb in w.z), (OK, te, what)
    at an event (its state in w.z), NO_RETURN at t_max, or an error (status, ta)."""
    ns = frac.size
    if not _sample(mode, ta, tb, frac, ns, w.sg, w.za, w.F, w.y_old, fns, p, w.ts, w.vals,
                   w.dvals, w.svals, w.wz, w.wg, w.wf, w.wp, w.ynew):
        return NON_FINITE, ta, _W_NONE
    st, te, what = _find(mode, w.ts, ns, first, s.sec_pred, s.touch_tol, s.xtol, s.min_time,
                         w.sg, w.za, w.F, w.y_old, fns, p, w.vals, w.dvals, w.svals, w.wz,
                         w.wg, w.wf, w.touched)
    if s.jac and w.touched[0]:  # P is not differentiable where the orbit touches H
        for i in range(w.z.size):
            for j in range(w.z.size):
                w.M[i, j] = np.nan
    if st != OK:
        return st, ta, _W_NONE
    if what == _W_NONE:
        for c in range(w.z.size):
            w.z[c] = w.ynew[c]
        return (NO_RETURN if tb >= s.t_max else _GO_ON), tb, _W_NONE
    _zat(te, mode, w.sg, w.za, w.F, w.y_old, fns, p, w.z)
    return OK, te, what


@_jit_inline
def _stay_exact(mode, t, fns, p, s, w):
    """A stay in region + or - on the exact flow from the mode entry, in the windows of
    rules.exact_window (hwin growing with the time since the entry during the fast
    transient, then hwin_slow); (status, t, what)."""
    for k in range(w.z.size):
        w.za[k] = w.z[k]
    w.sg[0] = t
    w.sg[3] = 0.0
    ta, first = t, True
    while True:
        w.count[1] += 1
        if w.count[1] > s.max_steps:
            return STEP_LIMIT, ta, _W_NONE
        tb = min(ta + _exact_window(ta - w.sg[0], s.hwin, s.hwin_slow, s.transient), s.t_max)
        if tb == ta:
            tb = np.nextafter(ta, np.inf)
        st, t, what = _window(mode, ta, tb, s.frac_ex, first, fns, p, s, w)
        if st != _GO_ON:
            if st == OK and s.jac:
                _flow_jacobian(mode, w.za, t - w.sg[0], fns, p, w.Mt, w.jz1, w.jz2)
                _apply(w.Mt, w.M, w.KP[0])
            return st, t, what
        ta, first = tb, False


@_jit_inline
def _stay_integrated(mode, t, fns, p, s, w):
    """A stay integrated by DOP853 with the mode's field (Filippov's when sliding;
    regions + and - of a model without exact flows); (status, t, what)."""
    n = w.z.size
    w.sg[3] = 1.0
    for k in range(n):
        w.y[k] = w.z[k]
    if not _checked_field(w.y, mode, True, fns, p, w.wg, w.wf, w.wp, w.f):
        return NON_FINITE, t, _W_NONE
    h_abs = _dop_initial_step(mode, t, w.y, w.f, s.t_max, s.max_step, s.rtol, s.atol, fns, p,
                              w.wg, w.wf, w.wp, w.ynew, w.ytmp, w.scale)
    ta, first = t, True
    while True:
        w.count[1] += 1
        if w.count[1] > s.max_steps:
            return STEP_LIMIT, ta, _W_NONE
        ok, tb, hstep, h_abs = _dop_step(mode, ta, w.y, w.f, h_abs, s.t_max, s.max_step, s.rtol,
                                         s.atol, fns, p, w.wg, w.wf, w.wp, w.K, w.ynew, w.ytmp,
                                         w.scale)
        if not ok:
            return STEP_FAILED, ta, _W_NONE
        for k in range(n):
            w.y_old[k] = w.y[k]
            w.f_old[k] = w.f[k]
            w.y[k] = w.ynew[k]
            w.f[k] = w.K[_NS, k]
        _dop_dense(mode, hstep, w.y_old, w.y, w.f_old, w.f, fns, p, w.wg, w.wf, w.wp, w.K,
                   w.ytmp, w.F)
        w.sg[1] = ta
        w.sg[2] = tb - ta
        st, t, what = _window(mode, ta, tb, s.frac_in, first, fns, p, s, w)
        if s.jac and (st == _GO_ON or (st == OK and t > ta)):
            _var_step(mode, w.y_old, (tb if st == _GO_ON else t) - ta, fns, p, w)
        if st != _GO_ON:
            return st, t, what
        ta, first = tb, False


@_jit_inline
def _end_slide(t, w):
    """Counts the slide that ends at t (time, and change of state)."""
    w.tally[0] += t - w.tally[1]
    for k in range(w.z.size):
        w.slide_dz[k] += w.z[k] - w.slide_z0[k]


@_jit_inline
def _event(mode, t, what, fns, p, s, w):
    """The event ``what`` at (t, w.z): a section hit ends the run (OK); a switch is
    decided (rules.next_mode) and counted against the limits and the Zeno ring.
    (status, mode to go on in); status _GO_ON unless the run ends here."""
    if what == _W_SECTION:
        if mode == SLIDING:
            _end_slide(t, w)
        if s.jac:
            _section_derivative(mode, fns, p, w)
        return OK, mode
    a, b = _speeds(w.z, fns, p, w.wg, w.wf, w.wp)
    new_mode = _next_mode(mode, what, a, b)  # what: rules.SWITCH/EXIT_MINUS/EXIT_PLUS
    if new_mode == SLIDING and not s.sliding:
        return NO_SLIDING, mode
    if new_mode == SLIDING and mode != SLIDING and _slides_in(w.z, fns, p, w.wg, w.wf, w.wp,
                                                             w.wz):
        return SECTION_SLIDING, mode
    drift, h0 = False, 0.0
    if mode == SLIDING:
        if new_mode != SLIDING:
            h0 = fns[4](w.z, p)
            drift = _exit_drift(new_mode, h0, w.z, w.wg, s.touch_tol)
            if drift:  # w.wg holds grad h at w.z (from _speeds)
                _onto_switch(w.z, h0, w.wg)
                h0 = fns[4](w.z, p)  # what rounding left
        _end_slide(t, w)
    if new_mode == SLIDING:
        w.tally[1] = t
        for k in range(w.z.size):
            w.slide_z0[k] = w.z[k]
    if new_mode != mode:
        w.count[0] += 1
        if w.count[0] == 1:
            w.first_sw[0] = t
    if w.count[0] > s.max_events:
        return EVENT_LIMIT, mode
    w.recent[w.count[2] % s.zeno_count] = t
    w.count[2] += 1
    if w.count[2] >= s.zeno_count and _accumulates(w.recent[w.count[2] % s.zeno_count], t,
                                                   s.zeno_span):
        return ZENO, mode
    w.sg[4] = 0.0
    if mode == SLIDING and new_mode != SLIDING:
        w.sg[4] = _exit_shift(new_mode, h0, s.touch_tol, drift)
    if s.jac and mode != SLIDING and new_mode != mode:  # the end of sliding: identity
        _switch_derivative(mode, new_mode, fns, p, w)
    return _GO_ON, new_mode


@_jit
def _one(z0, fns, p, s, w):
    """First return of z0 (the state at the return, or where the run stopped, in w.z);
    (status, t, n_switches, sliding_time). w.first_sw[0]: time of the first change of
    mode (left untouched if there is none); w.slide_dz: the change of state summed
    over the sliding stretches (counted like sliding_time)."""
    n = z0.size
    for k in range(n):
        w.slide_dz[k] = 0.0
    for k in range(n):
        w.z[k] = z0[k]
        if not np.isfinite(z0[k]):
            return BAD_START, 0.0, 0, 0.0
    mode = _initial_mode(w.z, fns, p, s.touch_tol, s.sliding, w.wg, w.wf, w.wp)
    if mode == SLIDING and _slides_in(w.z, fns, p, w.wg, w.wf, w.wp, w.wz):
        return SECTION_SLIDING, 0.0, 0, 0.0
    w.touched[0] = False
    if s.jac:
        # a start that slides: the return is not differentiable across H there
        for i in range(n):
            for j in range(n):
                w.M[i, j] = np.nan if mode == SLIDING else (1.0 if i == j else 0.0)
    for k in range(n):
        w.slide_z0[k] = w.z[k]
    for k in range(3):
        w.count[k] = 0
    w.tally[0] = 0.0
    w.tally[1] = 0.0
    w.sg[4] = 0.0
    t = 0.0
    while True:
        if t >= s.t_max:
            return NO_RETURN, t, w.count[0], w.tally[0]
        if mode == SLIDING and not s.sliding:
            return NO_SLIDING, t, w.count[0], w.tally[0]
        if mode != SLIDING and s.exact:
            st, t, what = _stay_exact(mode, t, fns, p, s, w)
        else:
            st, t, what = _stay_integrated(mode, t, fns, p, s, w)
        if st == OK:
            st, mode = _event(mode, t, what, fns, p, s, w)
        if st != _GO_ON:
            return st, t, w.count[0], w.tally[0]


_KERNEL_SIG = types.void(
    _FLOW, _FLOW, _FIELD, _FIELD, _SCALAR, _FIELD, _SCALAR, _WHERE,  # the model
    _vec,                       # params
    types.float64[:, ::1],      # starts (m, n)
    types.float64,              # t_max
    types.boolean,              # exact flows in regions + and - (else DOP853)
    types.float64,              # window length of the exact flows
    types.int64,                # section predicate
    types.boolean,              # sliding declared
    _vec, _vec,                 # sample fractions: exact windows, integration steps
    _vec,                       # rtol, atol, touch_tol, event_xtol, zeno_span, max_step,
                                # slow window, transient time, min_time
    types.int64[::1],           # max_events, max_steps, zeno_count, returns per start,
                                # dP/dz wanted (0/1)
    types.float64[:, ::1], _vec, types.int64[::1], _vec, types.int64[::1], _vec,  # outputs
    types.float64[:, ::1],
    types.float64[:, :, ::1],   # the last returns of each start (m, keep, n)
    types.int64[::1],           # returns completed per start
    types.float64[:, :, ::1],   # dP/dz of the last return (m, n, n)
    types.float64[:, :, :, ::1])  # dP/dz of each kept return (m, keep, n, n) or (m, 0, n, n)


@njit(cache=True)
def _batch(flow_plus, flow_minus, field_plus, field_minus, h, grad_h, section, where, p,
           starts, t_max, exact, hwin, sec_pred, sliding, frac_ex, frac_in, fopts, iopts,
           out_state, out_time, out_nsw, out_slide, out_status, out_first, out_slide_dz,
           out_orbit, out_done, out_jac, out_orbit_jac):
    """Each start is mapped iopts[3] times by the first-return map, each return
    starting from the last one's state; the outputs describe the last return made
    (or where it stopped) and out_orbit[i] holds the last keep returns (with iopts[4]:
    out_jac and out_orbit_jac their derivatives dP/dz, NaN where not made)."""
    fns = (flow_plus, flow_minus, field_plus, field_minus, h, grad_h, section, where)
    m, n = starts.shape
    nsmax = max(frac_ex.size, frac_in.size)
    ts = np.empty(nsmax)
    vals = np.empty((2, nsmax))
    dvals = np.empty(nsmax)
    svals = np.empty(nsmax)
    recent = np.empty(max(iopts[2], 1))
    sg = np.zeros(5)
    za, y, f = np.zeros(n), np.zeros(n), np.zeros(n)
    y_old, f_old, ynew, ytmp, scale = (np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                                       np.zeros(n))
    wz, wg, wf, wp = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    K = np.zeros((_NSE, n))
    F = np.zeros((_NI, n))
    first = np.zeros(1)
    w = Work(ts, vals, dvals, svals, recent, sg, za, y, f, y_old, f_old, K, ynew, ytmp, scale,
             F, wz, wg, wf, wp, np.zeros(n), first, np.zeros(n), np.zeros(n),
             np.zeros(3, dtype=np.int64), np.zeros(2),
             np.zeros((n, n)), np.zeros((n, n)), np.zeros((_NS, n)), np.zeros((_NS, n, n)),
             np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
             np.zeros(n), np.zeros(1, dtype=np.bool_))
    jac = iopts[4] != 0
    s = Settings(t_max, exact, hwin, fopts[6], fopts[7], sec_pred, sliding, frac_ex, frac_in,
                 fopts[0], fopts[1], fopts[2], fopts[3], fopts[4], fopts[5], fopts[8],
                 iopts[0], iopts[1], iopts[2], jac)
    keep_jac = out_orbit_jac.shape[1]
    n_iter, keep = iopts[3], out_orbit.shape[1]
    zin = np.empty(n)
    for i in range(m):
        for c in range(n):
            zin[c] = starts[i, c]
        done = 0
        while True:
            first[0] = np.nan
            st, t, nsw, sl = _one(zin, fns, p, s, w)
            if st != OK:
                break
            done += 1
            j = done - 1 - (n_iter - keep)
            if j >= 0:
                for c in range(n):
                    out_orbit[i, j, c] = w.z[c]
                if keep_jac > 0:
                    out_orbit_jac[i, j] = w.M
            if done >= n_iter:
                break
            for c in range(n):
                zin[c] = w.z[c]
        out_done[i] = done
        out_first[i] = first[0]
        for c in range(n):
            out_state[i, c] = w.z[c]
            out_slide_dz[i, c] = w.slide_dz[c]
        out_status[i] = st
        if jac and st == OK:
            out_jac[i] = w.M
        else:
            out_jac[i] = np.nan
        out_time[i] = t
        out_nsw[i] = nsw
        out_slide[i] = sl


# ============================================================================= Python side
#: the files whose code the kernel contains. numba's on-disk cache checks only the file
#: of each cached function, not those of the functions it calls (a kernel cached before
#: an edit of rules.py would go on running the old rules: seen, and numba's documented
#: limit), so the kernel's cache carries a stamp of all of them (_fresh_cache)
KERNEL_SOURCES = ("fastmap.py", "rules.py", "dop853_tableau.py", "abi.py", "system.py")


def _kernel_stamp() -> str:
    digest = hashlib.sha256()
    for name in KERNEL_SOURCES:
        digest.update((Path(__file__).parent / name).read_bytes())
    return digest.hexdigest()


def _fresh_cache() -> None:
    """Drop every cached compiled function of this module (the rules compiled here
    included) when the kernel's sources changed since the cache was written."""
    stamp_file = Path(_batch._cache.cache_path) / "fastmap-kernel.sha256"
    stamp = _kernel_stamp()
    try:
        if stamp_file.read_text() == stamp:
            return
    except OSError:
        pass  # no stamp yet: a cache of unknown sources
    for obj in list(globals().values()):
        if hasattr(obj, "py_func") and hasattr(obj, "_cache"):
            obj._cache.flush()
    try:
        stamp_file.parent.mkdir(parents=True, exist_ok=True)
        stamp_file.write_text(stamp)
    except OSError:
        pass  # a read-only cache: numba compiles in memory and caches nothing anyway


def compile_kernel() -> bool:
    """Compile the kernel for its one signature (or load it from numba's on-disk
    cache, if that was written from the same sources); done on first use. Returns True
    if it was loaded from the cache."""
    if not _batch.signatures:
        _fresh_cache()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", NumbaExperimentalFeatureWarning)
            _batch.compile(_KERNEL_SIG)
        _batch.disable_compile()  # any other argument types are an error, not a recompile
    return sum(_batch.stats.cache_hits.values()) > 0


@dataclass(frozen=True)
class BatchReturns:
    """Raw kernel output: ``status[i] == OK`` where start ``i`` returned; elsewhere
    ``state``/``time`` are where the run stopped (see :data:`STATUS`)."""

    state: np.ndarray
    time: np.ndarray
    n_switches: np.ndarray
    sliding_time: np.ndarray
    status: np.ndarray
    first_switch: np.ndarray  # time of the first change of mode (NaN: none)
    sliding_displacement: np.ndarray = None  # (m, dim): state change summed over sliding
    orbit: np.ndarray = None  # (m, keep, dim): the last ``keep`` of ``iterations`` returns
    returns_done: np.ndarray = None  # (m,): returns completed (== iterations: all made)
    #: (m, dim, dim): dP/dz of the last return made (``jacobian=True``; NaN: failed, or
    #: not differentiable -- a tangential switch or hit, a touch of H, a start that slides)
    jacobian: np.ndarray = None
    #: (m, keep, dim, dim): dP/dz of the return that produced each ``orbit`` row
    orbit_jacobian: np.ndarray = None


def _section_pred(direction: int) -> int:
    return rules.section_pred(direction)


def _checked_starts(cmodel: CompiledModel, starts) -> np.ndarray:
    starts = np.ascontiguousarray(np.atleast_2d(np.asarray(starts, dtype=float)))
    if starts.ndim != 2 or starts.shape[1] != cmodel.dim:
        raise ValueError(f"start points must have shape (m, {cmodel.dim}) "
                         f"({', '.join(cmodel.names)}), got {starts.shape}")
    if not np.all(np.isfinite(starts)):
        raise ValueError("start points must be finite")
    return starts


def _check_options(cmodel, t_max, samples_per_step, max_step, zeno_count, iterations, keep,
                   min_time) -> None:
    """compute_returns' options, each refused with its name where out of range."""
    if not (np.isfinite(t_max) and t_max >= 0):
        raise ValueError(f"need a finite t_max >= 0, got {t_max!r}")
    if samples_per_step < 1:
        raise ValueError("samples_per_step must be >= 1")
    if not max_step > 0:
        raise ValueError(f"max_step must be > 0, got {max_step!r}")
    if zeno_count < 1:
        raise ValueError("zeno_count must be >= 1")
    if not (isinstance(iterations, (int, np.integer)) and iterations >= 1):
        raise ValueError(f"iterations must be an integer >= 1, got {iterations!r}")
    if not (isinstance(keep, (int, np.integer)) and 0 <= keep <= iterations):
        raise ValueError(f"keep must be an integer in [0, iterations={iterations}], got {keep!r}")
    if not (np.isfinite(min_time) and min_time >= 0):
        raise ValueError(f"min_time must be a finite number >= 0, got {min_time!r}")
    if cmodel.exact and not (np.isfinite(cmodel.sample_step) and cmodel.sample_step > 0):
        raise ValueError(f"the compiled model needs a finite sample_step > 0, "
                         f"got {cmodel.sample_step!r}")


def compute_returns(cmodel: CompiledModel, starts, t_max: float, *, rtol: float = 1e-12,
                    atol: float = 1e-14, max_step: float = np.inf, max_events: int = 100_000,
                    max_steps: int = 5_000_000, samples_per_step: int = 4,
                    touch_tol: float = 1e-15, event_xtol: float = 1e-15, zeno_count: int = 64,
                    zeno_span: float = 1e-10, min_time: float = 0.0, iterations: int = 1,
                    keep: int = 0, jacobian: bool = False) -> BatchReturns:
    """First returns of ``starts`` (``(m, dim)``) to the model's section, one compiled call.

    Options mean what they mean for :func:`filippov.simulate.simulate`, except that
    ``samples_per_step`` counts samples per integration step only: exact flows are
    scanned once per ``cmodel.sample_step`` (``slow_sample_step`` after the
    transient), the resolution the model declares; ``min_time``
    that of :class:`filippov.simulate.Section` (hits before it are ignored; a start
    on the section up to rounding is not a hit either way). Nothing is raised for a
    start point that fails: see ``status``.

    ``iterations`` > 1 iterates the return map: each return starts from the state
    of the one before (``t_max`` and the limits hold per return); the outputs then
    describe the last return made, or the one that failed, ``returns_done[i]``
    counts the returns completed and ``orbit[i]`` holds the last ``keep`` of them
    (rows of a start that stopped early stay NaN).

    ``jacobian=True`` also returns the derivative dP/dz of each return
    (``BatchReturns.jacobian``, and ``orbit_jacobian`` for the kept returns), carried
    along the orbit: closed-form flows differentiated by central differences,
    integrated stays (sliding) by the variational equation through the same steps,
    each switch by its saltation matrix, the hit by the projection onto the section.
    It agrees with :func:`filippov.variational.return_jacobian` and with finite
    differences of P (tests/test_return_jacobian.py). It costs little on exact flows
    and about 7 field evaluations per one on integrated stays (benchmark:
    ``filippov.benchmarks.attractor_cost``). NaN where P is not
    differentiable: a switch or section met tangentially, an orbit that touches H
    (``touch_tol``: the kink of P at grazing), a start that slides.
    """
    starts = _checked_starts(cmodel, starts)
    _check_options(cmodel, t_max, samples_per_step, max_step, zeno_count, iterations, keep,
                   min_time)
    hwin = min(EXACT_BLOCK * cmodel.sample_step, max_step, t_max) if cmodel.exact else np.inf
    hwin_slow = slow_window(cmodel.slow_sample_step, hwin, max_step, t_max)
    # an exact flow: one sample per sample step (the model's declared resolution);
    # samples_per_step is for integration steps, whose length error control sets
    frac_ex = np.linspace(0.0, 1.0, EXACT_BLOCK + 1)
    frac_in = np.linspace(0.0, 1.0, samples_per_step + 1)
    fopts = np.array([rtol, atol, touch_tol, event_xtol, zeno_span, max_step, hwin_slow,
                      cmodel.transient_time, min_time], dtype=float)
    iopts = np.array([max_events, max_steps, zeno_count, iterations, int(bool(jacobian))],
                     dtype=np.int64)
    m = starts.shape[0]
    state = np.empty_like(starts)
    time = np.empty(m)
    nsw = np.empty(m, dtype=np.int64)
    slide = np.empty(m)
    status = np.empty(m, dtype=np.int64)
    first = np.empty(m)
    slide_dz = np.empty_like(starts)
    orbit = np.full((m, keep, starts.shape[1]), np.nan)
    done = np.empty(m, dtype=np.int64)
    n = starts.shape[1]
    jac = np.empty((m, n, n))
    orbit_jac = np.full((m, keep if jacobian else 0, n, n), np.nan)
    params = np.ascontiguousarray(cmodel.params, dtype=float)
    compile_kernel()
    _batch(cmodel.flow_plus, cmodel.flow_minus, cmodel.field_plus, cmodel.field_minus,
           cmodel.h, cmodel.grad_h, cmodel.section, cmodel.section_where, params,
           starts, float(t_max), bool(cmodel.exact), float(hwin), _section_pred(cmodel.section_direction),
           bool(cmodel.sliding), frac_ex, frac_in, fopts, iopts, state, time, nsw, slide, status,
           first, slide_dz, orbit, done, jac, orbit_jac)
    return BatchReturns(state, time, nsw, slide, status, first, slide_dz, orbit, done,
                        jac if jacobian else None, orbit_jac if jacobian else None)


_ERRORS = {EVENT_LIMIT: EventLimitError, STEP_LIMIT: EventLimitError, ZENO: ZenoError,
           NO_SLIDING: SlidingNotBuiltError}


def first_returns_compiled(cmodel: CompiledModel, starts, t_max: float, *,
                           progress: Progress | None = None, **options) -> Returns:
    """:func:`filippov.poincare.first_returns` on the compiled path.

    ``options`` go to :func:`compute_returns`; ``progress`` is stepped once by
    the number of start points, after the batch. A start point that does not return
    is an error naming it (the first one, with its status), raised as the
    reference driver would: :class:`EventLimitError` for the event and step
    bounds, :class:`ZenoError`, :class:`SimulationError` for a numerical
    failure, RuntimeError for no return within ``t_max``.
    """
    out = compute_returns(cmodel, starts, t_max, **options)
    if progress is not None:
        progress.step(out.status.size)
    bad = np.flatnonzero(out.status != OK)
    if bad.size:
        i = int(bad[0])
        code = int(out.status[i])
        z0 = np.atleast_2d(np.asarray(starts, dtype=float))[i]
        msg = (f"start point {z0.tolist()} did not return to the section of "
               f"{cmodel.name!r} within t_max={t_max!r}: {STATUS[code]} at t={out.time[i]!r}, "
               f"state {out.state[i].tolist()} ({bad.size} of {out.status.size} start "
               f"points failed)")
        if code == NO_RETURN:
            raise RuntimeError(msg)
        raise _ERRORS.get(code, SimulationError)(msg)
    return Returns(out.state, out.time, out.n_switches, out.sliding_time, out.first_switch)
