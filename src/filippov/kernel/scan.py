"""The event scan of one window: its samples, and the earliest event among them (the
order of the questions in a sample interval: filippov.loop.interval)."""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from .. import rules
from ..loop.interval import IntervalOps, WalkOps, make_past_band, make_window_event
from ..system import MINUS, PLUS, SLIDING
from .base import (OK, ROOT_FAILED, _MAXITER_EXTREMUM, _S_A, _S_B, _S_DA, _S_DB, _S_H,
                   _S_SEC, _TO_NEG, _TO_NONNEG, _TO_NONPOS, _W_NONE, _dot, _jit,
                   _jit_inline, _speeds, _field_minus, _field_plus, _grad_h, _h, _section,
                   _where)
from .segment import (_fval, _rates, _zat)
from .state import (SEG_BAND, SEG_EXIT_SHIFT, SEG_INTEGRATED, SEG_LAST_H, SEG_LAST_SPEED2,
                    SEG_RATE_STEP, SEG_SHIFT, Band, Eval, Interval, Walk)
from .roots import (_brentq, _refine)


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
            if not np.isfinite(svals[k] + a + b):  # one test: finite where each term is
                return k, speed2_a                  # (or on overflow)
            if sg[SEG_RATE_STEP] > 0.0:  # (overwrites wz: the state at tk + the step)
                da, db = _rates(tk, a, b, mode, o, sc)
                dvals[0, k] = da
                dvals[1, k] = db
                if not np.isfinite(da + db):  # stopped where the rates evaluated a, b
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
            if not np.isfinite(svals[k] + hk + dvals[0, k]):
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


#: how an orbit leaves its mode: through n leave functions (1: h; 2 while sliding: a and
#: b), the first of them ``sel`` crossing by ``pred``, and the rate ``sel_d`` whose zero
#: is the first one's extremum (which event a crossing is: loop.interval)
_Leave = namedtuple("_Leave", ["n", "sel", "pred", "sel_d"])


@_jit_inline
def _leave_of(mode):
    if mode == PLUS:
        return _Leave(1, _S_H, _TO_NEG, _S_B)
    if mode == MINUS:
        return _Leave(1, _S_H, _TO_NONNEG, _S_A)
    return _Leave(2, _S_A, _TO_NONPOS, _S_A)


@_jit_inline
def _banded_h(ctx, t, mode):
    return _fval(_S_H, t, mode, ctx.o, ctx.sc)


@_jit_inline
def _refine_unbanded(ctx, lo, hi, mode):
    """h's root in [lo, hi] on H itself: the exit's shift in force of the banded one."""
    lv, o, sc = ctx
    sg = o.seg
    banded = sg[SEG_SHIFT]
    sg[SEG_SHIFT] = sg[SEG_EXIT_SHIFT]
    # vb: not sampled here, and the kernel's refinement never reads it (roots._lost_bracket)
    ok, r = _refine(Eval(o, sc), lv.sel, lv.pred, lo, hi, _fval(_S_H, lo, mode, o, sc), np.nan,
                    mode)
    sg[SEG_SHIFT] = banded
    return r if ok else hi


#: a crossing of H found beyond the exit's band, refined again on H itself (loop.interval)
_past_band = _jit_inline(make_past_band(_banded_h, _refine_unbanded))


@_jit
def _leave_root(i, mode, first, lv, o, sm, sc):
    """The crossing of the first leave function between samples i and i + 1; (t, ok)."""
    ta, tb = sm.ts[i], sm.ts[i + 1]
    lo, vlo = ta, sm.vals[0, i]
    if (first and i == 0 and mode != SLIDING
            and rules.dips_and_returns(mode, sm.dvals[0, 0], sm.dvals[0, 1])):
        tm, ok = _brentq(lv.sel_d, ta, tb, _MAXITER_EXTREMUM, mode, o, sc)
        hm = _fval(_S_H, tm, mode, o, sc)
        if ok and not rules.after(lv.pred, hm):  # refine beyond the dip (rules)
            lo, vlo = tm, hm
    ok, r = _refine(Eval(o, sc), lv.sel, lv.pred, lo, tb, vlo, sm.vals[0, i + 1], mode)
    if not ok:
        return r, False
    if o.seg[SEG_BAND] > 0.0:  # found beyond the exit's band: again on H itself
        r = _past_band(Band(lv, o, sc), r, lo, mode, o.seg[SEG_BAND])
    return r, True


# ------------------------------------------------------------------ the event search
# The order of the questions in one sample interval and its ties, and the walk over the
# window's intervals, are the one event search (filippov.loop.interval); what follows is
# how the kernel answers each, on its samples (sm) and its segment (o). The walk's state
# is a state.Walk (the window's records and its number of samples), the event search's a
# state.Interval (the window's records and the sign changes _candidate_at saw there).

@_jit_inline
def _leave_crosses(ctx, q, i):
    return ctx.c0 if q == 0 else ctx.c1


@_jit_inline
def _leave_root_at(ctx, q, i, mode):
    """The root of leave function q (h or a; b) between samples i and i + 1."""
    first, lv, o, sm, sc = ctx.first, ctx.lv, ctx.o, ctx.sm, ctx.sc
    if q == 0:
        r, ok = _leave_root(i, mode, first, lv, o, sm, sc)
    else:
        ok, r = _refine(Eval(o, sc), _S_B, _TO_NONNEG, sm.ts[i], sm.ts[i + 1], sm.vals[1, i],
                        sm.vals[1, i + 1], mode)
    return (OK if ok else ROOT_FAILED), r


@_jit_inline
def _slide_end_between(ctx, q, i):
    return ctx.ha if q == 0 else ctx.hb


@_jit_inline
def _speed_exit(ctx, q, i, mode):
    """The extremum of a (q = 0) or b hidden between samples i and i + 1, judged by
    rules.speed_graze: (status, the speed's root before it, GRAZE_CROSSES), (status, its
    time, GRAZE_TOUCHES) or GRAZE_NONE."""
    s, o, sm, sc = ctx.s, ctx.o, ctx.sm, ctx.sc
    ta, tb = sm.ts[i], sm.ts[i + 1]
    sel_v, sel_r = (_S_A, _S_DA) if q == 0 else (_S_B, _S_DB)
    pred = _TO_NONPOS if q == 0 else _TO_NONNEG
    tm, ok = _brentq(sel_r, ta, tb, _MAXITER_EXTREMUM, mode, o, sc)
    if not ok:
        return ROOT_FAILED, tm, rules.GRAZE_NONE
    vm = _fval(sel_v, tm, mode, o, sc)
    kind = rules.speed_graze(pred, vm, sm.dvals[q, i], sm.dvals[q, i + 1], tb - ta, s.touch_tol)
    if kind == rules.GRAZE_CROSSES:
        ok, r = _refine(Eval(o, sc), sel_v, pred, ta, tm, sm.vals[q, i], vm, mode)
        return (OK if ok else ROOT_FAILED), r, kind
    return OK, tm, kind


@_jit_inline
def _extremum_between_at(ctx, i):
    return ctx.cd


@_jit_inline
def _h_extremum(ctx, i, mode):
    """A minimum (in +) or maximum (in -) of h hidden between samples i and i + 1, judged
    by rules.graze (the exit's band): (status, h's root before it, GRAZE_CROSSES),
    (status, its time, GRAZE_TOUCHES) or GRAZE_NONE."""
    lv, s, o, sm, sc = ctx.lv, ctx.s, ctx.o, ctx.sm, ctx.sc
    ta, tb = sm.ts[i], sm.ts[i + 1]
    tm, ok = _brentq(lv.sel_d, ta, tb, _MAXITER_EXTREMUM, mode, o, sc)
    if not ok:
        return ROOT_FAILED, tm, rules.GRAZE_NONE
    hm = _fval(_S_H, tm, mode, o, sc)
    kind = rules.graze(mode, hm, s.touch_tol, o.seg[SEG_BAND])
    if kind == rules.GRAZE_CROSSES:
        ok, r = _refine(Eval(o, sc), _S_H, lv.pred, ta, tm, sm.vals[0, i], hm, mode)
        return (OK if ok else ROOT_FAILED), r, kind
    return OK, tm, kind


@_jit_inline
def _touch(ctx, t, mode):
    ctx.sm.touched[0] = True  # no event; P has a kink here


@_jit_inline
def _n_sections(ctx):
    return 1


@_jit_inline
def _section_crosses(ctx, k, i):
    return ctx.cs


@_jit_inline
def _section_root(ctx, k, i, mode):
    s, o, sm, sc = ctx.s, ctx.o, ctx.sm, ctx.sc
    ok, r = _refine(Eval(o, sc), _S_SEC, s.sec_pred, sm.ts[i], sm.ts[i + 1], sm.svals[i],
                    sm.svals[i + 1], mode)
    return (OK if ok else ROOT_FAILED), r


@_jit_inline
def _section_bounds(ctx, k):
    return ctx.s.min_time, ctx.o.xtol  # the run starts at t = 0


@_jit_inline
def _section_counts(ctx, k, i, r, mode):
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


#: how the kernel answers the questions of a sample interval (loop.interval.IntervalOps)
_INTERVAL_OPS = IntervalOps(
    _leave_crosses, _leave_root_at, _slide_end_between, _speed_exit, _extremum_between_at,
    _h_extremum, _touch, _n_sections, _section_crosses, _section_root, _section_bounds,
    _section_counts)


@_jit_inline
def _skip_to(ctx, i, mode):
    # each interval is tested as the walk comes to it (_candidate_at); i + 0, not i: the
    # walk starts at the constant 0, and a call given that literal i would be compiled
    # twice (docs/decisions.md#kernel-codes-are-numpy-integers)
    return i + 0


@_jit_inline
def _candidate_at(ctx, i, mode):
    """Sample interval i shows a sign change, and the event search's state there: the
    window's records and the sign changes seen."""
    first, lv, s, o, sm, sc, ns = ctx
    vals, dvals, svals, sg = sm.vals, sm.dvals, sm.svals, o.seg
    c0 = rules.crosses(lv.pred, vals[0, i], vals[0, i + 1])
    c1 = lv.n == 2 and rules.crosses(_TO_NONNEG, vals[1, i], vals[1, i + 1])
    cd = mode != SLIDING and rules.extremum_between(mode, dvals[0, i], dvals[0, i + 1])
    cs = rules.crosses(s.sec_pred, svals[i], svals[i + 1])
    # while sliding: a minimum of a, a maximum of b between the samples (rules)
    ha = lv.n == 2 and sg[SEG_RATE_STEP] > 0.0 and rules.speed_extremum_between(
        _TO_NONPOS, dvals[0, i], dvals[0, i + 1])
    hb = lv.n == 2 and sg[SEG_RATE_STEP] > 0.0 and rules.speed_extremum_between(
        _TO_NONNEG, dvals[1, i], dvals[1, i + 1])
    return ((c0 or c1 or cd or cs or ha or hb),
            Interval(first, lv, s, o, sm, sc, c0, c1, cd, cs, ha, hb))


@_jit_inline
def _clears_band_at(ctx, i, mode):
    sg = ctx.o.seg
    return sg[SEG_BAND] > 0.0 and rules.clears_band(mode, ctx.sm.vals[0, i], sg[SEG_BAND])


@_jit_inline
def _last_sample(ctx):
    return ctx.ns - 1


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


#: a call with its pieces inlined, as _find was (docs/decisions.md#kernel-inlined-driver)
_window_event = _jit(make_window_event(
    WalkOps(_skip_to, _candidate_at, _last_sample, _clears_band_at, _unband),
    _INTERVAL_OPS))


@_jit_inline
def _find(mode, ns, first, s, o, sm, sc):
    """The earliest event on the samples (the one event search of loop.interval, asked in
    each interval where a sign change shows); (status, t, what). A touch of H on the way
    (no event) sets sm.touched[0]."""
    lv = _leave_of(mode)
    if first:  # just entered this mode: its start is inside by construction
        sm.vals[0, 0] = rules.clamp(lv.pred, sm.vals[0, 0])
        if lv.n == 2:
            sm.vals[1, 0] = rules.clamp(_TO_NONNEG, sm.vals[1, 0])
    st, t, what, _ = _window_event(Walk(first, lv, s, o, sm, sc, ns), mode)
    return st, t, what
