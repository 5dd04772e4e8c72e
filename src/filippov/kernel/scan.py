"""The event scan of one window: its samples, and the earliest event among them (as
filippov.simulate._scan)."""
from __future__ import annotations

import numpy as np

from .. import rules
from ..system import MINUS, PLUS, SLIDING
from .base import (OK, ROOT_FAILED, _EPS, _MAXITER_EXTREMUM, _S_A, _S_B, _S_DA, _S_DB, _S_H, _S_SEC, _TO_NEG, _TO_NONNEG,
                   _TO_NONPOS, _W_EXIT_MINUS, _W_EXIT_PLUS, _W_NONE, _W_SECTION, _W_SWITCH,
                   _after, _band_probe, _clamp, _clears_band, _crosses, _dips_and_returns, _dot, _extremum_between,
                   _flow_consistent, _graze, _jit, _rate_step, _same_instant, _speed_extremum_between, _speed_graze,
                   _speeds, _starts_on_section, _field_minus, _section_probe, _section_noise,
                   _on_section_by_value,
                   _field_plus, _grad_h, _h, _section, _where)
from .segment import (_fval, _rates, _zat)
from .roots import (_brentq, _refine)


@_jit
def _sample(mode, ta, tb, frac, ns, k0, sg, za, F, y_old, fns, p, ts, vals, dvals, svals,
            wz, wg, wf, wp, zlast):
    """Samples of one window: times ts, the leave functions (h, or a and b when
    sliding), their rates (dh/dt; the rates of a and b along the orbit while sliding,
    rules.rate_step: sg[7]) and the section; the last state in zlast. (False: non-finite,
    |f|^2 at the first sample outside sliding -- the state at ta -- for _flow_follows).
    Samples from k0 on: k0 = 1 when the caller carried sample 0 over (_carry_sample);
    outside sliding the last sample's h and |f|^2 are kept in sg[8], sg[9] for that."""
    speed2_a = sg[9] if k0 == 1 else 0.0
    for k in range(k0, ns):
        tk = ta + frac[k] * (tb - ta) if k < ns - 1 else tb
        ts[k] = tk
        _zat(tk, mode, sg, za, F, y_old, fns, p, wz)
        for c in range(wz.size):
            if not np.isfinite(wz[c]):
                return False, speed2_a
        svals[k] = _section(fns, wz, p)
        if k == ns - 1:
            for c in range(wz.size):
                zlast[c] = wz[c]
        if mode == SLIDING:
            a, b = _speeds(wz, fns, p, wg, wf, wp)
            vals[0, k] = a
            vals[1, k] = b
            if k == 0:  # one difference step for the window (wf, wp: F_-, F_+ at wz)
                sg[7] = _rate_step(wz, wf, wp, a, b)
            if sg[7] > 0.0:  # (overwrites wz)
                da, db = _rates(tk, a, b, mode, sg, za, F, y_old, fns, p, wz, wg, wf, wp)
                dvals[0, k] = da
                dvals[1, k] = db
        else:
            hk = _h(fns, wz, p)
            vals[0, k] = hk - sg[4]
            _grad_h(fns, wz, p, wg)
            if mode == PLUS:
                _field_plus(fns, wz, p, wf)
            else:
                _field_minus(fns, wz, p, wf)
            dvals[0, k] = _dot(wg, wf)
            if k == 0:
                speed2_a = _dot(wf, wf)
            if k == ns - 1:  # for the next window's sample 0 (_carry_sample)
                sg[8] = hk
                sg[9] = _dot(wf, wf)
    return True, speed2_a


@_jit
def _carry_sample(ns, sg, ts, vals, dvals, svals):
    """Sample 0 of an exact flow's window that goes on from the window before in the
    same stay: the state at its start is that window's last sample (the same flow from
    the same entry over the same time, bit for bit), so its values are taken over
    instead of evaluated again (h less the current sg[4], which may have changed)."""
    ts[0] = ts[ns - 1]
    vals[0, 0] = sg[8] - sg[4]
    dvals[0, 0] = dvals[0, ns - 1]
    svals[0] = svals[ns - 1]


@_jit
def _flow_follows(za, zb, dt, speed2_a, fb):
    """rules.flow_consistent for an exact flow's window of length dt from za to zb, the
    field's |f|^2 at ta and f at zb given (the values _sample evaluated for dh/dt): as
    simulate._Run._check_flow, from the same field values, no evaluation of its own."""
    d2, size = 0.0, 0.0
    for c in range(za.size):
        d2 += (zb[c] - za[c]) * (zb[c] - za[c])
        size = max(size, abs(za[c]), abs(zb[c]))
    return _flow_consistent(np.sqrt(d2), dt, np.sqrt(speed2_a), np.sqrt(_dot(fb, fb)), size)


@_jit
def _in_section_rounding(fns, p, s0, z0, zr, probe):
    """simulate._in_section_rounding: the start's section value s0 within the section's
    rounding measured at the probes about z0 toward zr (``probe``: scratch)."""
    noise, s_2, s_1 = 0.0, 0.0, 0.0
    for j in range(-rules.SECTION_PROBES, rules.SECTION_PROBES + 1):
        if not _section_probe(z0, zr, j, probe):
            return False
        s = _section(fns, probe, p)
        if j >= 2 - rules.SECTION_PROBES:
            noise = _section_noise(noise, s_2, s_1, s)
        s_2, s_1 = s_1, s
    return _on_section_by_value(s0, noise)


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
        cd = mode != SLIDING and _extremum_between(mode, dvals[0, i], dvals[0, i + 1])
        cs = _crosses(sec_pred, svals[i], svals[i + 1])
        # while sliding: a minimum of a, a maximum of b between the samples (rules)
        ha = nleave == 2 and sg[7] > 0.0 and _speed_extremum_between(
            _TO_NONPOS, dvals[0, i], dvals[0, i + 1])
        hb = nleave == 2 and sg[7] > 0.0 and _speed_extremum_between(
            _TO_NONNEG, dvals[1, i], dvals[1, i + 1])
        if not (c0 or c1 or cd or cs or ha or hb):
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
            if first and i == 0 and mode != SLIDING and _dips_and_returns(mode, dvals[0, 0], dvals[0, 1]):
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
        if best_w == _W_NONE and (ha or hb):
            # the end of sliding hidden between the samples (rules.speed_graze): refined
            # at the extremum of a or b, an exit at the speed's root before it
            touch_t = np.inf
            for q in range(2):
                if not (ha if q == 0 else hb):
                    continue
                sel_v, sel_r = (_S_A, _S_DA) if q == 0 else (_S_B, _S_DB)
                pred = _TO_NONPOS if q == 0 else _TO_NONNEG
                tm, ok = _brentq(sel_r, ta, tb, xtol, 4.0 * _EPS, _MAXITER_EXTREMUM, mode, sg,
                                 za, F, y_old, fns, p, wz, wg, wf)
                if not ok:
                    return ROOT_FAILED, tm, _W_NONE
                vm = _fval(sel_v, tm, mode, sg, za, F, y_old, fns, p, wz, wg, wf)
                kind = _speed_graze(pred, vm, dvals[q, i], dvals[q, i + 1], tb - ta, touch_tol)
                if kind == rules.GRAZE_CROSSES:
                    r, ok = _refine(sel_v, pred, ta, tm, vals[q, i], xtol, mode, sg, za, F,
                                    y_old, fns, p, wz, wg, wf)
                    if not ok:
                        return ROOT_FAILED, r, _W_NONE
                    if best_w == _W_NONE or r < best_t:
                        best_t, best_w = r, (_W_EXIT_MINUS if q == 0 else _W_EXIT_PLUS)
                elif kind == rules.GRAZE_TOUCHES:
                    touch_t = min(touch_t, tm)
            if touch_t < best_t:
                touched[0] = True  # a touch before any exit: P has a kink here
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
            # simulate._scan: min_time; a tie with a switch (rules.same_instant)
            # goes to the section; a start on the section up to rounding is no hit
            if r >= min_time and (best_w == _W_NONE
                                  or r <= best_t + _same_instant(xtol, best_t)):
                _zat(r, mode, sg, za, F, y_old, fns, p, wz)
                if _where(fns, wz, p):
                    at_start = False
                    if ts[i] == 0.0:
                        _zat(ts[i], mode, sg, za, F, y_old, fns, p, wg)
                        # the closed form's start za counts for an exact flow only; a
                        # dense output (integrated, sliding) starts at wg itself and za is
                        # stale there (it took crossings within 64 x 1e-10 for the start)
                        exact = mode != SLIDING and sg[3] == 0.0
                        at_start = (_starts_on_section(svals[i], wg, _section(fns, wz, p), wz,
                                                       za if exact else wg)
                                    or _in_section_rounding(fns, p, svals[i], wg, wz, wf))
                    if not at_start:
                        best_t, best_w = r, _W_SECTION
        if best_w != _W_NONE:
            return OK, best_t, best_w
    return OK, np.inf, _W_NONE
