"""The event scan of one window: its samples, and the earliest event among them (as
filippov.simulate._scan)."""
from __future__ import annotations

import numpy as np

from .. import rules
from ..system import MINUS, PLUS, SLIDING
from .base import (OK, ROOT_FAILED, _EPS, _MAXITER_EXTREMUM, _S_A, _S_B, _S_H, _S_SEC, _TO_NEG, _TO_NONNEG,
                   _TO_NONPOS, _W_EXIT_MINUS, _W_EXIT_PLUS, _W_NONE, _W_SECTION, _W_SWITCH,
                   _after, _band_probe, _clamp, _clears_band, _crosses, _dips_and_returns, _dot, _extremum_between,
                   _graze, _jit, _same_instant, _speeds, _starts_on_section, _field_minus,
                   _field_plus, _grad_h, _h, _section, _where)
from .segment import (_fval, _zat)
from .roots import (_brentq, _refine)


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
            vals[0, k] = _h(fns, wz, p) - sg[4]
            _grad_h(fns, wz, p, wg)
            if mode == PLUS:
                _field_plus(fns, wz, p, wf)
            else:
                _field_minus(fns, wz, p, wf)
            dvals[k] = _dot(wg, wf)
        svals[k] = _section(fns, wz, p)
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
        if sg[5] > 0.0 and _clears_band(mode, vals[0, i], sg[5]):
            # the orbit is out of its exit's rounding band at ts[i]: from there H is
            # unbiased (rules.clears_band), so a return across H is refined at H = 0
            sg[4] = sg[6]
            sg[5] = 0.0
            for k in range(i, ns):
                vals[0, k] = _fval(_S_H, ts[k], mode, sg, za, F, y_old, fns, p, wz, wg, wf)
            c0 = _crosses(pred0, vals[0, i], vals[0, i + 1])
            if not (c0 or c1 or cd or cs):
                continue
        ta, tb = ts[i], ts[i + 1]
        best_t, best_w = np.inf, _W_NONE
        if c0:
            lo, vlo = ta, vals[0, i]
            if first and i == 0 and mode != SLIDING and _dips_and_returns(mode, dvals[0], dvals[1]):
                tm, ok = _brentq(sel_d, ta, tb, xtol, 4.0 * _EPS, _MAXITER_EXTREMUM, mode, sg, za, F, y_old,
                                 fns, p, wz, wg, wf)
                hm = _fval(_S_H, tm, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
                if ok and not _after(pred0, hm):  # refine beyond the dip (rules)
                    lo, vlo = tm, hm
            r, ok = _refine(sel0, pred0, lo, tb, vlo, xtol, mode, sg, za, F, y_old,
                            fns, p, wz, wg, wf)
            if not ok:
                return ROOT_FAILED, r, _W_NONE
            if sg[5] > 0.0:  # found beyond the exit's band: again on H itself (rules.band_probe)
                tq, step, done, clear = r, 0.0, False, False
                while not done:
                    clear = _clears_band(mode, _fval(_S_H, tq, mode, sg, za, F, y_old, fns, p,
                                                     wz, wg, wf), sg[5])
                    done, tq, step = _band_probe(tq, step, lo, clear)
                if clear:
                    banded = sg[4]
                    sg[4] = sg[6]
                    r2, ok = _refine(sel0, pred0, tq, r, _fval(_S_H, tq, mode, sg, za, F, y_old,
                                                               fns, p, wz, wg, wf),
                                     xtol, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
                    sg[4] = banded
                    if ok:
                        r = r2
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
            tm, ok = _brentq(sel_d, ta, tb, xtol, 4.0 * _EPS, _MAXITER_EXTREMUM, mode, sg, za, F, y_old,
                             fns, p, wz, wg, wf)
            if not ok:
                return ROOT_FAILED, tm, _W_NONE
            hm = _fval(_S_H, tm, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
            kind = _graze(mode, hm, touch_tol, sg[5])  # sg[5]: the exit's band (rules)
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
                if _where(fns, wz, p):
                    at_start = False
                    if ts[i] == 0.0:
                        _zat(ts[i], mode, sg, za, F, y_old, fns, p, wg)
                        at_start = _starts_on_section(svals[i], wg, _section(fns, wz, p), wz)
                    if not at_start:
                        best_t, best_w = r, _W_SECTION
        if best_w != _W_NONE:
            return OK, best_t, best_w
    return OK, np.inf, _W_NONE
