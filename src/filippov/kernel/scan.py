"""The event scan of one window: its samples, and the earliest event among them (the
order of the questions in a sample interval: filippov.loop.interval)."""
from __future__ import annotations

import numpy as np
from numba import types
from numba.extending import overload

from .. import rules
from ..loop.interval import (F_LEAVE, F_RATE, F_SECTION, F_TIME, F_UNBANDED, Window, WindowOps,
                             asks, make_window_event)
from ..system import MINUS, PLUS, SLIDING
from .base import (OK, ROOT_FAILED, _MAXITER_EVENT, _MAXITER_EXTREMUM, _S_A, _S_B, _S_DA, _S_DB, _S_H,
                   _S_SEC, _dot, _jit, _jit_inline, _speeds, _field_minus, _field_plus,
                   _grad_h, _h, _section, _where)
from .segment import (_fval, _rates, _zat)
from .state import (SEG_BAND, SEG_EXIT_SHIFT, SEG_INTEGRATED, SEG_LAST_H, SEG_LAST_SPEED2,
                    SEG_RATE_STEP, SEG_SHIFT, Walk)
from .roots import _brentq_f


@_jit_inline
def _not_finite(a, b, c):
    """One of a, b, c is not finite: their sum asked first (one comparison where each term
    is: the samples' path), the terms only where it is not -- finite terms whose sum
    overflows are finite (the reference tests each array)."""
    if np.isfinite(a + b + c):
        return False
    return not (np.isfinite(a) and np.isfinite(b) and np.isfinite(c))


@_jit
def _sample(mode, ta, tb, frac, k0, o, sm, sc):
    """Samples of one window at the fractions frac of [ta, tb] (sm: state.Samples): times
    ts, the leave functions (h, or a and b when sliding), their rates (dh/dt; the rates of
    a and b along the orbit while sliding, rules.rate_step: SEG_RATE_STEP) and the section;
    the last state in sm.end. Returns (-1, |f|^2 at the first sample outside sliding --
    the state at ta -- for _flow_follows), or (k, .) at the first sample k whose state or
    a value sampled there is not finite (the state then in sc.wz: a NaN sample shows no
    sign change, so a switch or section there would be missed, not found). Samples from
    k0 on: k0 = 1 when the caller carried sample 0 over (_carry_sample); outside sliding
    the last sample's h and |f|^2 are kept in SEG_LAST_H, SEG_LAST_SPEED2 for that."""
    ns = frac.size
    sg, wz, wg, wf, wp = o.seg, sc.wz, sc.wg, sc.wf, sc.wp
    ts, vals, dvals, svals = sm.ts, sm.vals, sm.dvals, sm.svals
    fns, p = o.fns, o.p
    speed2_a = sg[SEG_LAST_SPEED2] if k0 == 1 else 0.0
    for k in range(k0, ns):
        tk = ta + frac[k] * (tb - ta) if k < ns - 1 else tb
        ts[k] = tk
        _zat(tk, mode, o, wz)
        for c in range(wz.size):
            if not np.isfinite(wz[c]):
                return k, speed2_a
        svals[k] = _section(fns, wz, p)
        if k == ns - 1:
            for c in range(wz.size):
                sm.end[c] = wz[c]
        if mode == SLIDING:
            a, b = _speeds(wz, fns, p, wg, wf, wp)
            vals[0, k] = a
            vals[1, k] = b
            if k == 0:  # one difference step for the window (wf, wp: F_-, F_+ at wz)
                sg[SEG_RATE_STEP] = rules.rate_step(wz, wf, wp, a, b, o.floor)
            if _not_finite(svals[k], a, b):
                return k, speed2_a
            if sg[SEG_RATE_STEP] > 0.0:  # (overwrites wz: the state at tk + the step)
                da, db = _rates(tk, a, b, mode, o, sc)
                dvals[0, k] = da
                dvals[1, k] = db
                if _not_finite(da, db, 0.0):  # stopped where the rates evaluated a, b
                    ts[k] = tk + sg[SEG_RATE_STEP]
                    return k, speed2_a
        else:
            hk = _h(fns, wz, p)
            vals[0, k] = hk - sg[SEG_SHIFT]
            _grad_h(fns, wz, p, wg)
            if mode == PLUS:
                _field_plus(fns, wz, p, wf)
            else:
                _field_minus(fns, wz, p, wf)
            dvals[0, k] = _dot(wg, wf)
            if _not_finite(svals[k], hk, dvals[0, k]):
                return k, speed2_a
            if k == 0:
                speed2_a = _dot(wf, wf)
            if k == ns - 1:  # for the next window's sample 0 (_carry_sample)
                sg[SEG_LAST_H] = hk
                sg[SEG_LAST_SPEED2] = _dot(wf, wf)
    return -1, speed2_a


@_jit
def _carry_sample(ns, seg, sm):
    """Sample 0 of an exact flow's window that goes on from the window before in the
    same stay: the state at its start is that window's last sample (the same flow from
    the same entry over the same time, bit for bit), so its values are taken over
    instead of evaluated again (h less the current SEG_SHIFT, which may have changed)."""
    sm.ts[0] = sm.ts[ns - 1]
    sm.vals[0, 0] = seg[SEG_LAST_H] - seg[SEG_SHIFT]
    sm.dvals[0, 0] = sm.dvals[0, ns - 1]
    sm.svals[0] = sm.svals[ns - 1]


@_jit
def _flow_follows(za, zb, dt, speed2_a, fb, floor):
    """rules.flow_consistent for an exact flow's window of length dt from za to zb, the
    field's |f|^2 at ta and f at zb given (the values _sample evaluated for dh/dt): as
    simulate._Run._check_flow, from the same field values, no evaluation of its own."""
    d2, size = 0.0, 0.0
    for c in range(za.size):
        d2 += (zb[c] - za[c]) * (zb[c] - za[c])
        size = max(size, abs(za[c]), abs(zb[c]))
    return rules.flow_consistent(np.sqrt(d2), dt, np.sqrt(speed2_a), np.sqrt(_dot(fb, fb)), size,
                                 floor)


@_jit
def _in_section_rounding(fns, p, s0, z0, zr, probe):
    """simulate._in_section_rounding: the start's section value s0 within the section's
    rounding measured at the probes about z0 toward zr (``probe``: scratch)."""
    noise, s_2, s_1 = 0.0, 0.0, 0.0
    for j in range(-rules.SECTION_PROBES, rules.SECTION_PROBES + 1):
        if not rules.section_probe(z0, zr, j, probe):
            return False
        s = _section(fns, probe, p)
        if j >= 2 - rules.SECTION_PROBES:
            noise = rules.section_noise(noise, s_2, s_1, s)
        s_2, s_1 = s_1, s
    return rules.on_section_by_value(s0, noise)


# ------------------------------------------------------------------ the event search
# The walk over the window's intervals and the questions of each, every decision among
# them, are the one event search (filippov.loop.interval); what follows is how the
# kernel reports its samples (sm) and values on its segment (o), each function by the
# loop's code (F_*) mapped to the kernel's selector (_S_*). The walk's state is a
# state.Walk: the window's records and its number of samples.

@_jit_inline
def _sel(f, mode):
    """The kernel's selector of the window's function f (loop.interval.F_*) in mode."""
    if f == F_LEAVE:
        return _S_H if mode != SLIDING else _S_A
    if f == F_LEAVE + 1:
        return _S_B
    if f == F_RATE:  # dh/dt along F_+ is b, along F_- a; while sliding the rate of a
        return _S_DA if mode == SLIDING else (_S_B if mode == PLUS else _S_A)
    if f == F_RATE + 1:
        return _S_DB
    if f == F_UNBANDED:
        return _S_H
    return _S_SEC


@_jit_inline
def _window_of(ctx):
    """The window as the search sees it: one section, which the run may hit from t = 0 +
    min_time on; every interval asked (cand None: the kernel finds no candidates ahead)."""
    sg = ctx.o.seg
    return Window(ctx.ns - 1, ctx.first, sg[SEG_BAND], sg[SEG_RATE_STEP] > 0.0,
                  ctx.touch_tol, ctx.o.xtol, (ctx.sec_pred,), (ctx.min_time,), None)


@overload(asks, inline="always")
def _asks(cand, i):
    """loop.interval.asks compiled for the window's ``cand``: None (the kernel's) asks
    every interval, a constant the walk's test folds away (docs/decisions.md#window-seam)."""
    if isinstance(cand, types.NoneType):
        return lambda cand, i: True
    return lambda cand, i: cand[i]


@_jit_inline
def _sampled(ctx, f, i):
    sm = ctx.sm
    if f == F_TIME:
        return sm.ts[i]
    if f >= F_SECTION:
        return sm.svals[i]
    if f >= F_RATE:
        return sm.dvals[f - F_RATE, i]
    return sm.vals[f, i]


@_jit_inline
def _unbiased(sg):
    """h measured from the exit's shift alone (F_UNBANDED), not the band's: returns the
    banded shift, for the caller to put back."""
    banded = sg[SEG_SHIFT]
    sg[SEG_SHIFT] = sg[SEG_EXIT_SHIFT]
    return banded


@_jit_inline
def _value(ctx, f, t, mode):
    """f at t; h unbiased (F_UNBANDED): the exit's shift in force of the banded one."""
    o, sc = ctx.o, ctx.sc
    if f != F_UNBANDED:
        return _fval(_sel(f, mode), t, mode, o, sc)
    banded = _unbiased(o.seg)
    v = _fval(_S_H, t, mode, o, sc)
    o.seg[SEG_SHIFT] = banded
    return v


@_jit_inline
def _root(ctx, f, lo, hi, vlo, vhi, mode):
    """brentq's root of f in [lo, hi] and f there (roots._brentq_f; a rate's, an
    extremum, within _MAXITER_EXTREMUM iterations): h unbiased (F_UNBANDED) with the exit's
    shift in force of the banded one. The kernel samples and refines through the same
    compiled scalar functions: a sign change its ends lost is a failure (ROOT_FAILED), not
    pinned to the samples' values (filippov.engines, item 5)."""
    o, sc = ctx.o, ctx.sc
    rate = f >= F_RATE and f < F_UNBANDED
    if not rate and not np.isnan(vlo):
        return False, lo, vlo
    if f != F_UNBANDED:
        r, fr, ok = _brentq_f(_sel(f, mode), lo, hi,
                              _MAXITER_EXTREMUM if rate else _MAXITER_EVENT, mode, o, sc)
        return ok, r, fr
    banded = _unbiased(o.seg)
    r, fr, ok = _brentq_f(_S_H, lo, hi, _MAXITER_EVENT, mode, o, sc)
    o.seg[SEG_SHIFT] = banded
    return ok, r, fr


@_jit_inline
def _counts(ctx, k, i, r, mode):
    """The section's crossing at r is a hit: ``where`` holds there, and it is not the
    start on the section up to rounding."""
    o, sm, sc = ctx.o, ctx.sm, ctx.sc
    wz, wg = sc.wz, sc.wg
    _zat(r, mode, o, wz)
    if not _where(o.fns, wz, o.p):
        return False
    if sm.ts[i] != 0.0:
        return True
    _zat(sm.ts[i], mode, o, wg)
    # the closed form's start za counts for an exact flow only; a dense output
    # (integrated, sliding) starts at wg itself and za is stale there (it took
    # crossings within 64 x 1e-10 for the start)
    exact = mode != SLIDING and o.seg[SEG_INTEGRATED] == 0.0
    return not (rules.starts_on_section(sm.svals[i], wg, _section(o.fns, wz, o.p), wz,
                                   o.za if exact else wg, o.floor)
                or _in_section_rounding(o.fns, o.p, sm.svals[i], wg, wz, sc.wf))


@_jit_inline
def _touch(ctx, t, mode):
    ctx.sm.touched[0] = True  # no event; P has a kink here


@_jit_inline
def _unband(ctx, i, mode):
    """The orbit is out of its exit's rounding band at ts[i] (at the last sample when i
    is ns: none left to sample): from there h is unbiased (rules.clears_band), so a
    return across H is refined at H = 0: the shift dropped and h sampled again from ts[i]
    on."""
    o, sm, sc, ns = ctx.o, ctx.sm, ctx.sc, ctx.ns
    o.seg[SEG_SHIFT] = o.seg[SEG_EXIT_SHIFT]
    o.seg[SEG_BAND] = 0.0
    for k in range(i, ns):
        sm.vals[0, k] = _fval(_S_H, sm.ts[k], mode, o, sc)


#: what the kernel reports of a window to the event search (the window seam:
#: filippov.contracts.WindowOperations)
WINDOW_OPERATIONS = WindowOps(_window_of, _sampled, _value, _root, _counts, _touch, _unband)
#: the one event search (loop.interval) on them: a call, its operations inlined, the root
#: of a leave function a call of its own (docs/decisions.md#kernel-inlined-driver)
_window_event = _jit(make_window_event(WINDOW_OPERATIONS, call=_jit, inline=_jit_inline))


@_jit_inline
def _find(mode, ns, first, s, o, sm, sc):
    """The earliest event on the samples (the one event search of loop.interval); (status,
    t, what, i): i the sample interval a status other than OK arose in (CUT: a value not
    finite at t there). A touch of H on the way (no event) sets sm.touched[0]."""
    st, t, what, i = _window_event(Walk(first, o, sm, sc, ns, s.touch_tol, s.min_time,
                                        s.sec_pred), mode)
    return st, t, what, i
