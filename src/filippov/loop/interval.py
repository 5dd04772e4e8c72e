"""The event search of one sample interval, and the walk over a window's intervals,
written once for both engines: every decision is taken here, from the samples and
values the engine reports, by the rule book.

Between two samples of a stay the search asks, in this order:

1. does a leave function change sign (h: a switch; while sliding, a or b: an exit into
   region - or +: ``rules.leave_pred``, ``rules.ended_by``)? Its root, refined; the
   earliest of them is the event so far. The root of h is refined beyond the dip after
   an entry at H (``rules.dips_and_returns``), and again on h itself when found beyond the
   exit's band (:func:`make_leave_root`);
2. has a leave function an extremum toward its sign change hidden between the samples
   (h in a region: ``rules.extremum_between``; a or b while sliding, where their rates
   are sampled: ``rules.speed_extremum_between``), asked where ``rules.asks_hidden_end``
   says (in a region when h shows no crossing; while sliding when the speed's own does
   not)? Its time is the root of the rate, and the value there decides
   (``rules.graze``, ``rules.speed_graze``): an exit or switch at the function's root
   before it (the earliest event wins), or a touch, recorded when it comes before any
   event, in time order;
3. each section that changes sign, in order (where step 2 found the event, between the
   first sample and that event: the samples past it follow the old mode's field, which
   turned back there): its root is the event when it comes first
   (``rules.section_first``: not before its min_time; before the event so far, or at its
   instant when that is a switch or an exit -- a section on H is hit where the orbit
   arrives on H) and the engine counts it there (``where`` holds, and it is not the run's
   start on the section up to rounding).

A window's intervals are asked in time order, only those where a sign change shows (the
start sample of a just-entered mode clamped inside: ``rules.clamp``); while the exit's
rounding band is in force, the first such interval whose start is out of the band
(``rules.clears_band``) ends it: h is sampled again unbiased from there and that
interval is asked again whether it still holds a sign change; a window with no event
ends it when its last sample is out of the band.

The engine reports, on its state ``ctx`` (:data:`WindowOps`), the samples of the
window's functions, their values and roots between the samples, and the touches; the
functions are named by the codes below, which each engine maps to its own. The
reference driver (:class:`filippov.simulate._Scan`) runs the result as it is; the
compiled kernel (:mod:`filippov.kernel.scan`) compiles it with numba, its operations
inlined (``inline="always"``), so this module is plain scalar Python in the subset numba
compiles (what the split costs: docs/decisions.md#window-seam).

An event is ``(status, t, what, k)``: ``status`` OK or the engine's failure code (the
reference raises instead, so its operations return OK or CUT); ``what`` one of
:data:`NONE`, ``rules.SWITCH``, ``rules.EXIT_MINUS``, ``rules.EXIT_PLUS``,
:data:`SECTION` (the kernel's codes); ``k`` the index of the section hit (-1 for any
other event), or with a status other than OK the sample interval it arose in. CUT: a
function asked between samples i and i + 1 was not finite at t (a root finder met it, or
the value at a hidden extremum): nothing is decided on it, and the engine searches
[ts[i], t] as the interval before a sample that is not finite
(docs/decisions.md#past-a-non-finite-sample): an event before t stands, else the run
stops at the field's edge.
"""
from __future__ import annotations

import math
from collections import namedtuple

import numpy as np

from .. import rules
from ..rules import GRAZE_CROSSES, GRAZE_NONE, GRAZE_TOUCHES
from ..system import SLIDING
from .refine import make_refine
from .status import CUT, ROOT_FAILED

#: the status of an operation that succeeded (the kernel's OK)
OK = 0
#: what an event is besides the ends of a stay (rules.SWITCH, EXIT_MINUS, EXIT_PLUS):
#: nothing in the interval, or a section hit
NONE, SECTION = -1, 3


#: the functions of a window, by the codes the engine's operations take: the sample
#: times; the leave functions (F_LEAVE + q: h in a region, a and b while sliding) and
#: their rates (F_RATE + q: dh/dt along the mode's field; while sliding the rates of a and
#: b, where sampled); h measured from the exit shift alone, without the band (its second
#: refinement); the sections (F_SECTION + k)
F_TIME, F_LEAVE, F_RATE, F_UNBANDED, F_SECTION = -1, 0, 2, 4, 5

#: what the engine reports of a window as it begins: the index of its last sample, whether
#: the stay just began (its start sample is then clamped inside), the exit's band in force
#: (0: none), whether the rates of a and b are sampled (while sliding), the touch
#: tolerance and the tolerance roots are located to; its sections, each one's sign change
#: (``preds``) and the earliest time it may be hit (``t_mins``); and ``cand``, which
#: intervals the walk asks (a mask, one entry per interval: the reference flags those
#: where its array operations saw a sign change, :func:`candidate_mask`; None: every
#: one, the kernel's; the search tests each one it asks again: :func:`asks`)
Window = namedtuple("Window", (
    "last", "first", "band", "rates", "touch_tol", "xtol", "preds", "t_mins", "cand"))

#: The engine's operations on a window, each a function of its state ``ctx``:
#:
#: * ``window(ctx) -> Window``;
#: * ``sampled(ctx, f, i)``: function f (the codes above) at sample i;
#: * ``value(ctx, f, t, mode)``: f at time t on the window;
#: * ``root(ctx, f, lo, hi, vlo, vhi, mode) -> (ok, t, f(t))``: the engine's root finder on
#:   f in [lo, hi]; not ok where f at the ends shows no sign change, unless the loop
#:   hands the samples' values there (vlo, vhi; NaN: none), to which the reference pins
#:   the bracket and the kernel does not (filippov.engines, item 5). The loop refines a
#:   sign change with it (:mod:`filippov.loop.refine`: to its far side) and finds the
#:   extremum of a function hidden between two samples as the root of its rate (F_RATE
#:   + q, the samples' values handed);
#: * ``counts(ctx, k, i, t, mode)``: section k's crossing at t in interval i is a hit
#:   (``where`` holds; not the run's start on it up to rounding);
#: * ``touch(ctx, t, mode)``: H touched at t (no event; the return map has a kink);
#: * ``unband(ctx, i, mode)``: the band ends; h is sampled again unbiased from sample i
#:   on (none when i is past the last sample), and the window's ``cand`` found again.
WindowOps = namedtuple("WindowOps", (
    "window", "sampled", "value", "root", "counts", "touch", "unband"))


def as_is(f):
    """A loop piece run as it is (the reference's); the kernel hands numba's decorators
    in its place (make_window_event's ``call`` and ``inline``, make_run's ``inline``)."""
    return f


def make_extremum(ops: WindowOps):
    """``extremum(ctx, f, i, mode) -> (status, t)``: the root of the rate f between samples
    i and i + 1 (an extremum of the function it is the rate of), on the engine's root
    finder with the samples' values handed (:data:`WindowOps`' ``root``); CUT where the
    rate was not finite at t."""
    sampled, root = ops.sampled, ops.root

    def extremum(ctx, f, i, mode):
        ok, tm, fm = root(ctx, f, sampled(ctx, F_TIME, i), sampled(ctx, F_TIME, i + 1),
                          sampled(ctx, f, i), sampled(ctx, f, i + 1), mode)
        return (OK if ok else CUT if not math.isfinite(fm) else ROOT_FAILED), tm

    return extremum


def make_leave_root(ops: WindowOps, refine, extremum):
    """``leave_root(ctx, q, i, mode, first, band, va, vb) -> (status, t)``: the sign
    change of leave function q between samples i and i + 1 (va, vb as read there). The
    root of h in the first interval of a stay entered at H, where h dips and returns
    (``rules.dips_and_returns``), is refined beyond the extremum of h; one found while the
    exit's band is in force is probed back toward the bracket's start
    (``rules.band_probe``) to a time out of the band (``rules.clears_band``) and refined
    again from there on h itself (r stands if none clears, or if that refinement fails).
    CUT at the time where h, asked between the samples, was not finite.
    ``refine``: the loop's refinement on the engine's root finder (loop.refine);
    ``extremum``: :func:`make_extremum`'s."""
    sampled, value = ops.sampled, ops.value

    def leave_root(ctx, q, i, mode, first, band, va, vb):
        pred = rules.leave_pred(mode, q)
        lo, vlo = sampled(ctx, F_TIME, i), va
        if (first and i == 0 and mode != SLIDING and rules.dips_and_returns(
                mode, sampled(ctx, F_RATE, 0), sampled(ctx, F_RATE, 1))):
            st, tm = extremum(ctx, F_RATE, 0, mode)
            if st == CUT:
                return st, tm
            if st == OK:
                hm = value(ctx, F_LEAVE, tm, mode)
                if not math.isfinite(hm):
                    return CUT, tm
                if not rules.after(pred, hm):  # next to the entry h is noise (rules)
                    lo, vlo = tm, hm
        st, r = refine(ctx, F_LEAVE + q, pred, lo, sampled(ctx, F_TIME, i + 1), vlo, vb, mode)
        if st != OK or band == 0.0 or mode == SLIDING:
            return st, r
        tq, step, done, clear = r, 0.0, False, False
        while not done:
            hq = value(ctx, F_LEAVE, tq, mode)
            if not math.isfinite(hq):
                return CUT, tq
            clear = rules.clears_band(mode, hq, band)
            done, tq, step = rules.band_probe(tq, step, lo, clear)
        if not clear:
            return OK, r
        st, r2 = refine(ctx, F_UNBANDED, pred, tq, r, value(ctx, F_UNBANDED, tq, mode),
                        value(ctx, F_UNBANDED, r, mode), mode)
        return (st, r2) if st == CUT else (OK, (r2 if st == OK else r))

    return leave_root


def make_hidden_end(ops: WindowOps, refine, extremum):
    """``hidden_end(ctx, q, i, mode, w, band, va) -> (status, t, kind)``: the extremum of
    leave function q hidden between samples i and i + 1 (va: its value at i as read),
    judged by ``rules.graze`` in a region, ``rules.speed_graze`` while sliding: the
    function's root before it (GRAZE_CROSSES), the extremum's time (GRAZE_TOUCHES), or
    GRAZE_NONE; CUT (status) where the function was not finite there: no judgement on a
    NaN. ``refine``, ``extremum``: as :func:`make_leave_root`'s."""
    sampled, value = ops.sampled, ops.value

    def hidden_end(ctx, q, i, mode, w, band, va):
        pred = rules.leave_pred(mode, q)
        ta, tb = sampled(ctx, F_TIME, i), sampled(ctx, F_TIME, i + 1)
        st, tm = extremum(ctx, F_RATE + q, i, mode)
        if st != OK:
            return st, tm, GRAZE_NONE
        vm = value(ctx, F_LEAVE + q, tm, mode)
        if not math.isfinite(vm):
            return CUT, tm, GRAZE_NONE
        if mode == SLIDING:
            kind = rules.speed_graze(pred, vm, sampled(ctx, F_RATE + q, i),
                                     sampled(ctx, F_RATE + q, i + 1), tb - ta, w.touch_tol)
        else:
            kind = rules.graze(mode, vm, w.touch_tol, band)
        if kind == GRAZE_CROSSES:
            st, r = refine(ctx, F_LEAVE + q, pred, ta, tm, va, vm, mode)
            return st, r, kind
        return OK, tm, kind

    return hidden_end


def make_candidate(ops: WindowOps):
    """``candidate(ctx, i, mode, w, clamp_at, pred0, pred1) -> (hit, va0, vb0, va1, vb1, c0,
    c1, x0, x1)``: the sign changes sample interval i shows -- the leave functions' (q = 0,
    1; va, vb as read at its ends, the start clamped inside at i = ``clamp_at``, 0 when the
    stay just began, else -1: c0, c1), a
    hidden extremum of one (x0, x1), a section's -- and whether any does (``hit``). Each
    function by a constant code: the kernel asks this of every interval."""
    sampled = ops.sampled

    def candidate(ctx, i, mode, w, clamp_at, pred0, pred1):
        va0, vb0 = sampled(ctx, F_LEAVE, i), sampled(ctx, F_LEAVE, i + 1)
        if i == clamp_at:
            va0 = rules.clamp(pred0, va0)
        da, db = sampled(ctx, F_RATE, i), sampled(ctx, F_RATE, i + 1)
        va1, vb1, c1, x1 = 0.0, 0.0, False, False
        if mode != SLIDING:
            x0 = rules.extremum_between(mode, da, db)
        else:
            x0 = w.rates and rules.speed_extremum_between(pred0, da, db)
            va1, vb1 = sampled(ctx, F_LEAVE + 1, i), sampled(ctx, F_LEAVE + 1, i + 1)
            if i == clamp_at:
                va1 = rules.clamp(pred1, va1)
            c1 = rules.crosses(pred1, va1, vb1)
            x1 = w.rates and rules.speed_extremum_between(
                pred1, sampled(ctx, F_RATE + 1, i), sampled(ctx, F_RATE + 1, i + 1))
        c0 = rules.crosses(pred0, va0, vb0)
        cs = False
        for k in range(len(w.preds)):
            cs = cs or rules.crosses(w.preds[k], sampled(ctx, F_SECTION + k, i),
                                     sampled(ctx, F_SECTION + k, i + 1))
        return (c0 or c1 or x0 or x1 or cs), va0, vb0, va1, vb1, c0, c1, x0, x1

    return candidate


def make_window_event(ops: WindowOps, call=as_is, inline=as_is):
    """``window_event(ctx, mode) -> (status, t, what, k)``: the earliest event over a
    window's intervals (this module's docstring) on the engine's :data:`WindowOps`; a
    leave function's root compiled by ``call``, a hidden extremum by ``inline``."""
    window, sampled, value, counts, touch, unband = (
        ops.window, ops.sampled, ops.value, ops.counts, ops.touch, ops.unband)
    refine = call(make_refine(ops.root, ops.value))
    extremum = inline(make_extremum(ops))
    leave_root = call(make_leave_root(ops, refine, extremum))
    hidden_end = inline(make_hidden_end(ops, refine, extremum))
    candidate = inline(make_candidate(ops))

    def window_event(ctx, mode):
        w = window(ctx)
        n, band, clamp_at = w.last, w.band, (0 if w.first else -1)
        pred0, pred1 = rules.leave_pred(mode, 0), rules.leave_pred(mode, 1)
        i, nl = 0, (2 if mode == SLIDING else 1)
        while i < n:
            if not asks(w.cand, i):
                i += 1
                continue
            hit, va0, vb0, va1, vb1, c0, c1, x0, x1 = candidate(ctx, i, mode, w, clamp_at,
                                                                pred0, pred1)
            if hit and band > 0.0 and rules.clears_band(mode, va0, band):
                unband(ctx, i, mode)  # interval i asked again, h unbiased (band now 0)
                w, band, clamp_at = window(ctx), 0.0, -1
                continue
            if hit:
                best_t, best_w, best_k, touch_0, touch_1 = math.inf, NONE, -1, math.inf, math.inf
                hidden = False  # the event so far ends a hidden extremum (step 2)
                # 1. the leave functions' crossings: the earliest
                for q in range(nl):
                    if not (c0 if q == 0 else c1):
                        continue
                    st, r = leave_root(ctx, q, i, mode, w.first, band, va0 if q == 0 else va1,
                                       vb0 if q == 0 else vb1)
                    if st != OK:
                        return st, r, NONE, i
                    if best_w == NONE or r < best_t:
                        best_t, best_w = r, rules.ended_by(mode, q)
                # 2. an extremum of a leave function hidden between the samples
                for q in range(nl):
                    if not ((x0 if q == 0 else x1) and rules.asks_hidden_end(
                            mode, c0 if q == 0 else c1, best_w != NONE)):
                        continue
                    st, r, kind = hidden_end(ctx, q, i, mode, w, band, va0 if q == 0 else va1)
                    if st != OK:
                        return st, r, NONE, i
                    if kind == GRAZE_CROSSES and (best_w == NONE or r < best_t):
                        best_t, best_w, hidden = r, rules.ended_by(mode, q), True
                    elif kind == GRAZE_TOUCHES:
                        touch_0, touch_1 = (r, touch_1) if q == 0 else (touch_0, r)
                for tm in (min(touch_0, touch_1), max(touch_0, touch_1)):
                    if tm < best_t:  # a touch before any exit, in time order: P has a kink
                        touch(ctx, tm, mode)
                # 3. the sections in order: a hit first, or at a switch (hidden: at its time)
                for k in range(len(w.preds)):
                    pred, t_min = w.preds[k], w.t_mins[k]
                    sa, sb = sampled(ctx, F_SECTION + k, i), sampled(ctx, F_SECTION + k, i + 1)
                    tb = math.inf   # the interval's end, read only for a crossing
                    if hidden and not rules.crosses(pred, sa, sb):
                        tb, sb = best_t, value(ctx, F_SECTION + k, best_t, mode)
                        if not math.isfinite(sb):
                            return CUT, best_t, NONE, i
                    if rules.crosses(pred, sa, sb):
                        st, r = refine(ctx, F_SECTION + k, pred, sampled(ctx, F_TIME, i),
                                       min(tb, sampled(ctx, F_TIME, i + 1)), sa, sb, mode)
                        if st != OK:
                            return st, r, NONE, i
                        if (rules.section_first(r, t_min, best_t, best_w == SECTION, w.xtol)
                                and counts(ctx, k, i, r, mode)):
                            best_t, best_w, best_k = r, SECTION, k
                if best_w != NONE:
                    return OK, best_t, best_w, best_k
            i += 1
        if band > 0.0 and rules.clears_band(mode, sampled(ctx, F_LEAVE, n), band):
            unband(ctx, n + 1, mode)  # no sample after the last one to take again
        return OK, math.inf, NONE, -1

    return window_event


def asks(cand, i):
    """Whether the walk asks interval i of a window whose ``cand`` is as
    :data:`Window`'s: every interval where it is None, else those it flags. The kernel
    compiles it for None as the constant True (kernel.scan), so its walk tests nothing
    more per interval than it did when it asked every one (a mask of all True cost it
    0.7% of its instructions per return: docs/decisions.md#window-seam)."""
    return cand is None or cand[i]


def candidate_mask(mode, leaves, rates, sections, first):
    """The sample intervals where the event search may find something, by array
    operations (the reference's :data:`Window` ``cand``; the search tests each one it
    asks again): a leave function's sign change (``leaves``: their samples), an extremum of
    one hidden between samples (``rates``: the samples of their rates, None while
    sliding without them), a section's sign change (``sections``: (pred, samples)
    pairs); interval 0 whenever the stay just began (its start sample is clamped)."""
    cand = np.zeros(leaves[0].size - 1, dtype=bool)
    for q, v in enumerate(leaves):
        cand |= rules.crosses(rules.leave_pred(mode, q), v[:-1], v[1:])
    for q, d in enumerate(rates if rates is not None else ()):
        cand |= (rules.extremum_between(mode, d[:-1], d[1:]) if mode != SLIDING else
                 rules.speed_extremum_between(rules.leave_pred(mode, q), d[:-1], d[1:]))
    for pred, sv in sections:
        cand |= rules.crosses(pred, sv[:-1], sv[1:])
    if first and cand.size:
        cand[0] = True
    return cand
