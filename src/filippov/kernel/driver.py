"""The driver loop: one start point from its initial mode through its stays and events
to the section (_one), the batch kernel over many start points (_batch), and its
compilation with the on-disk cache kept in step with the sources.

The kernel comes in two builds of this one source: with the dP/dz code (_batch) and
without it (_batch_plain, what returns without derivatives run on; why:
docs/decisions.md#kernel-two-builds).

The batch kernel releases the GIL (nogil) and keeps no state between calls but its
arguments: each call allocates its own work arrays, and start i writes row i of the
outputs only, so fastmap runs contiguous slices of a batch on threads at once."""
from __future__ import annotations

import contextlib
import hashlib
import sys
import types as pytypes
import warnings
from pathlib import Path

import numpy as np
from numba import njit
from numba.extending import register_jitable
from numba.core.errors import NumbaExperimentalFeatureWarning

from .. import rules
from ..system import MINUS, PLUS, SLIDING
from .base import (BAD_START, FLOW_OFF_FIELD, NON_FINITE, NO_RETURN, OK,
                   STEP_FAILED, ZENO, _W_NONE, _dot,
                   _W_SECTION, _flow_minus, _flow_plus, _jit, _jit_inline, _speeds,
                   _h, _section)
from .dop853 import (_FIRST_CALL, _NI, _NS, _NSE, _checked_field, _dense_eval, _dop_dense,
                     _dop_initial_step, _dop_step, _non_finite_stage)
from .segment import _zat
from .scan import (_carry_sample, _find, _flow_follows, _sample)
from .state import (COUNT_SIZE, N_RING, N_SWITCHES, SEG_BAND, SEG_ENTRY,
                    SEG_EXIT_SHIFT, SEG_INTEGRATED, SEG_NEXT_STEP, SEG_SHIFT, SEG_SIZE,
                    SEG_NOT_FINITE, SEG_STEP_H, SEG_SUSPECT, SEG_STEP_T, T_AGE, T_SLID, T_SLIDE_START, TALLY_SIZE, Control, Deriv, Dop,
                    Fill, Orbit, Outputs, RunCtx, Samples, Scratch, Settings, Work,
                    kernel_signature)  # noqa: F401
from .derivative import (_apply, _flow_jacobian, _section_derivative, _switch_derivative,
                         _var_step)
from ..loop.event import SECTION, Pieces, RunOps, make_run, make_start
from ..loop.run_state import Limits, RunState, count_step, count_switch
from ..loop.stay import UNRESOLVED, before_stay
from ..loop.status import CUT, GO_ON


# ------------------------------------------------------------------ the pieces at the state
# The run's pieces at the state w.z (at an event, at the start), and section_along (with
# them, the test of a slide inside the section at the start and at an arrival on H,
# filippov.loop.event.make_sliding_section); section_along calls _section_along_at with
# only what it reads (docs/decisions.md#kernel-small-records).

@_jit_inline
def _event_pieces(ctx):
    """loop.event.Pieces at the state w.z: grad h, F_- and F_+ in w.wg, w.wf, w.wp (what
    _exit_state and _event_section_along read there), a and b, H, and the run's state
    scale and its components'."""
    fns, p, s, w = ctx
    a, b = _speeds(w.z, fns, p, w.wg, w.wf, w.wp)
    return Pieces(w.z, w.wg, w.wf, w.wp, a, b, _h(fns, w.z, p), s.state_scale, s.scales)


@_jit_inline
def _event_section_along(k, mode, d, ctx):
    """The section at w.z + d (cm F_- + cp F_+), the field of ``mode`` as its weights
    (Filippov's while sliding, from F_-, F_+ and grad h left by _event_pieces); d = 0:
    at w.z."""
    fns, p, s, w = ctx
    # the loop passes k and the modes as Python int constants, literals to numba: + 0
    # makes them int64, so the call is compiled once, not once per mode
    # (docs/decisions.md#kernel-codes-are-numpy-integers)
    return _section_along_at(k + 0, mode + 0, d, (fns, p, w.z, w.wg, w.wf, w.wp, w.wz))


@_jit  # a call: the test asks it seven times (inlined, it grew the cold compile)
def _section_along_at(k, mode, d, at):
    fns, p, z, wg, wm, wp, wz = at
    if d == 0.0:
        return _section(fns, z, p)
    if mode == MINUS:
        cm, cp = 1.0, 0.0
    elif mode == PLUS:
        cm, cp = 0.0, 1.0
    else:
        a, b = _dot(wg, wm), _dot(wg, wp)
        cm, cp = -b / (a - b), a / (a - b)
    for c in range(z.size):
        wz[c] = z[c] + d * (cm * wm[c] + cp * wp[c])
    return _section(fns, wz, p)


# The kernel's ABI: _batch(fns, params, starts, ages, settings, out): the compiled
# addresses of the model's pieces (a tuple of integers in the order of
# filippov.abi.PIECES: base._PIECE_ADDRS), arrays and two named tuples (kernel.state:
# Settings, Outputs; their types and the signature declared there once);
# fastmap.compute_returns builds them.

_GO_ON = GO_ON  # no event yet / the orbit goes on (never a returned status)
# the run (filippov.loop.event) asks before_stay and count_switch by their names, as a
# rule is asked (kernel.base: compiled into its caller)
register_jitable(_nrt=False)(before_stay)
register_jitable(_nrt=False)(count_switch)
register_jitable(_nrt=False)(count_step)
assert _W_SECTION == SECTION

#: the compile-time switch of the dP/dz code: every branch that carries the derivative
#: (Settings.jac) is guarded by it too, and numba prunes a branch on a False global before
#: typing, so the build without it (_batch_plain) never compiles kernel.derivative
_DERIVATIVES = True


@_jit_inline
def _resolved(mode, ns, sm):
    """The window's first ns samples resolve its leave functions and its section
    (rules.resolves; h with its slopes dh/dt; rounding as 64 ulps of the samples:
    engines.py asymmetry 12)."""
    return (rules.resolves(sm.vals[0], sm.dvals[0], sm.ts, ns, mode != SLIDING, 0.0)
            and (mode != SLIDING
                 or rules.resolves(sm.vals[1], sm.vals[1], sm.ts, ns, False, 0.0))
            and rules.resolves(sm.svals, sm.svals, sm.ts, ns, False, 0.0))


@_jit_inline
def _all_finite(z):
    for c in range(z.size):
        if not np.isfinite(z[c]):
            return False
    return True


@_jit_inline
def _window(mode, ta, tb, first, may_split, ctx):
    """Samples the segment [ta, tb] of the current mode (ctx: the run's RunCtx (fns, p, s, w);
    at the fractions of an exact window or of an integration step) and finds its earliest
    event: (_GO_ON, tb, _W_NONE) if there is none (the state at tb in w.z), (OK, te, what)
    at an event (its state in w.z), NO_RETURN at t_max, or an error (status, ta);
    (UNRESOLVED, ta) when ``may_split`` and the samples of an integration step do not
    resolve what they sample (loop.stay.make_step_windows; an exact flow's window is the
    flow's own, rules.exact_window: never split)."""
    fns, p, s, w = ctx
    o = Orbit(fns, p, w.seg, w.za, w.F, w.y_old, s.xtol, s.state_scale)
    exact = mode != SLIDING and w.seg[SEG_INTEGRATED] == 0.0
    frac = s.frac_ex if exact else s.frac_in
    ns = frac.size
    sm = Samples(w.ts, w.vals, w.dvals, w.svals, w.ynew, w.touched)
    sc = Scratch(w.wz, w.wg, w.wf, w.wp)
    # an exact flow's window after the first of its stay starts at the last one's end
    k0 = 1 if (exact and not first) else 0
    if k0 == 1:
        _carry_sample(ns, w.seg, sm)
    bad, speed2_a = _sample(mode, ta, tb, frac, k0, o, sm, sc)
    # a sample whose state or value is not finite (bad >= 0) ends the samples searched:
    # an event before it stands (past an event the samples follow this mode's field, not
    # the orbit); with none, the interval up to it is searched in sub-windows (_past_cut)
    # and with none there the run stops at the field's edge (_stop_non_finite)
    if bad == 0:  # at ta (or where the rates a step ahead of it were evaluated)
        return _stop_non_finite(sm.ts[0], ta, ta, mode, o, sc, w)
    # an exact flow (SEG_INTEGRATED == 0) must follow its field over the window: from the
    # state at ta (w.z) to that at tb (w.ynew), the field at tb left in w.wf by the last
    # sample; else the run stops at ta (w.z)
    if bad < 0 and exact and not _flow_follows(w.z, w.ynew, tb - ta, speed2_a, w.wf,
                                               s.state_scale):
        return FLOW_OFF_FIELD, ta, _W_NONE
    # a window cut at sample bad: unresolved where the samples kept are too few to judge
    # (rules.cut_resolves) or do not resolve; its shorter windows end at the cut's
    # sample time (loop.stay.make_step_windows; ts[bad] is where a rate a step ahead of
    # it was not finite)
    if may_split and not exact and not (
            rules.cut_resolves(bad, ns) and _resolved(mode, ns if bad < 0 else bad, sm)):
        return UNRESOLVED, (ta if bad < 0 else _sample_time(ta, tb, frac, bad)), _W_NONE
    t_stop, cut = ta, bad >= 0
    st, te, what, i = _find(mode, ns if bad < 0 else bad, first, s, o, sm, sc)  # bad = 1: none
    if st == CUT:  # a value not finite between samples i and i + 1, at te: searched to it
        st, te, what, t_stop = _past_cut(mode, sm.ts[i], te, first and i == 0, s, o, sm, sc)
        cut = True
    elif st == OK and what == _W_NONE and bad >= 1:
        st, te, what, t_stop = _past_cut(mode, sm.ts[bad - 1], sm.ts[bad],
                                         first and bad == 1, s, o, sm, sc)
    # P is not differentiable where the orbit touches H
    if _DERIVATIVES and s.jac and w.touched[0]:
        for i in range(w.z.size):
            for j in range(w.z.size):
                w.deriv.M[i, j] = np.nan
    if st != OK:
        return st, ta, _W_NONE
    if what == _W_NONE and cut:  # te: the last finite sample (_past_cut)
        return _stop_non_finite(t_stop, te, ta, mode, o, sc, w)
    if what == _W_NONE:
        for c in range(w.z.size):
            w.z[c] = w.ynew[c]
        return (NO_RETURN if tb >= s.t_max else _GO_ON), tb, _W_NONE
    _zat(te, mode, o, w.z)
    return OK, te, what


@_jit_inline
def _sample_time(ta, tb, frac, k):
    """The time of sample k of the window [ta, tb] (as scan._sample places it)."""
    return ta + frac[k] * (tb - ta) if k < frac.size - 1 else tb


@_jit_inline
def _stop_non_finite(t, t_last, ta, mode, o, sc, w):
    """NON_FINITE: at t (the state there in w.z) where a piece's value was not finite, or
    where the state was not at t_last, the last finite sample before it (at ta: w.z)."""
    _zat(t, mode, o, sc.wz)
    if not _all_finite(sc.wz):
        if t_last != ta:
            _zat(t_last, mode, o, w.z)
        return NON_FINITE, t_last, _W_NONE
    for c in range(w.z.size):
        w.z[c] = sc.wz[c]
    return NON_FINITE, t, _W_NONE


#: _sample from a sub-window's first sample: an int64 as _window's k0 is, so that
#: _sample is compiled once (docs/decisions.md#kernel-codes-are-numpy-integers)
_ALL_SAMPLES = np.int64(0)


@_jit  # a call: the path past a non-finite sample is rare
def _past_cut(mode, lo, hi, first, s, o, sm, sc):
    """The interval [lo, hi] of a window whose sample at hi was not finite (or a value
    between its samples: CUT), with no event up to lo: searched in sub-windows [lo, mid]
    sampled as the window was, halving the bracket (rules.cut_midpoint) to the field's
    edge -- an event before it stands (docs/decisions.md#past-a-non-finite-sample).
    (status, t, what, t_stop): the event, or _W_NONE and the time the run stops at (the
    last sample or value found not finite)."""
    exact = mode != SLIDING and o.seg[SEG_INTEGRATED] == 0.0
    frac = s.frac_ex if exact else s.frac_in
    ns = frac.size
    t_stop = hi  # where the last sample not finite was (the rates: a step ahead of it)
    t_first = lo if first else -np.inf  # the stay's first sample, while lo stays there
    mid = rules.cut_midpoint(lo, hi, o.xtol)
    while mid == mid:
        bad, _ = _sample(mode, lo, mid, frac, _ALL_SAMPLES, o, sm, sc)
        if bad == 0:  # lo's own sample (the rates a step ahead of it): the edge is there
            return OK, lo, _W_NONE, sm.ts[0]
        if bad < 0 or bad >= 2:  # from the stay's first sample: clamped as it is there
            st, te, what, i = _find(mode, ns if bad < 0 else bad, lo == t_first, s, o, sm, sc)
            if st == CUT:  # a value between samples i and i + 1 not finite, at te
                t_stop, lo, hi = te, sm.ts[i], te
                mid = rules.cut_midpoint(lo, hi, o.xtol)
                continue
            if st != OK or what != _W_NONE:
                return st, te, what, t_stop
        if bad < 0:
            lo = mid
        else:  # the bracket by the samples' times (the rates' a step ahead would widen it)
            t_stop = sm.ts[bad]
            lo, hi = sm.ts[bad - 1], _sample_time(lo, mid, frac, bad)
        mid = rules.cut_midpoint(lo, hi, o.xtol)
    return OK, lo, _W_NONE, t_stop


# ------------------------------------------------------------------ a stay's operations
# For filippov.loop.event, which holds a stay's order (start, then per step: the step, its
# windows, its end). In region + or - of a model with exact flows the stay follows the
# exact flow from the mode entry, in the windows of rules.exact_window (hwin growing with
# the time since the entry during the fast transient, then hwin_slow), each a step; else
# it is integrated by DOP853 with the mode's field (Filippov's when sliding).

@_jit_inline
def _start_stay(mode, t, ctx):
    """The stay in ``mode`` begins at t (the state w.z): GO_ON, or NON_FINITE where the
    integrated field is not finite there."""
    fns, p, s, w = ctx
    n = w.z.size
    w.seg[SEG_SUSPECT] = np.inf
    w.seg[SEG_NOT_FINITE] = np.inf
    if mode != SLIDING and s.exact:
        for k in range(n):
            w.za[k] = w.z[k]
        w.seg[SEG_ENTRY] = t
        w.seg[SEG_INTEGRATED] = 0.0
        return _GO_ON
    w.seg[SEG_INTEGRATED] = 1.0
    for k in range(n):
        w.y[k] = w.z[k]
    fl = Fill(w.wg, w.wf, w.wp)
    if not _checked_field(w.y, mode, _FIRST_CALL, fns, p, fl, w.f):
        return NON_FINITE
    w.seg[SEG_NEXT_STEP] = _dop_initial_step(
        mode, t, Control(s.t_max, s.max_step, s.rtol, s.atol), fns, p, fl,
        Dop(w.y, w.f, w.y_old, w.f_old, w.K, w.ynew, w.ytmp, w.scale, w.F))
    return _GO_ON


@_jit_inline
def _next_step(mode, ta, first, ctx):
    """The stay's next step from ta (``first``: the stay begins there, _start_stay): (GO_ON,
    its end tb -- or the time in it where the orbit's field is not finite,
    _passed_suspect), or (NON_FINITE, STEP_FAILED: why not, ta) (the step budget is the
    run's: filippov.loop.event). An exact flow's step is its window; an
    integrated one leaves its dense output in w.F."""
    fns, p, s, w = ctx
    if first:
        st = _start_stay(mode, ta, ctx)
        if st != _GO_ON:
            return st, ta
    if w.seg[SEG_NOT_FINITE] <= ta:  # the orbit ran through a field not finite there
        _dense_eval(ta, w.seg[SEG_STEP_T], w.seg[SEG_STEP_H], w.y_old, w.F, w.z)
        return NON_FINITE, ta
    if w.seg[SEG_INTEGRATED] == 0.0:
        age = ta - w.seg[SEG_ENTRY] + w.tally[T_AGE]
        tb = min(ta + rules.exact_window(age, s.hwin, s.hwin_slow, s.transient), s.t_max)
        return _GO_ON, (np.nextafter(ta, np.inf) if tb == ta else tb)
    fl = Fill(w.wg, w.wf, w.wp)
    d = Dop(w.y, w.f, w.y_old, w.f_old, w.K, w.ynew, w.ytmp, w.scale, w.F)
    ok, tb, hstep, h_next, t_guard = _dop_step(
        mode, ta, w.seg[SEG_NEXT_STEP], Control(s.t_max, s.max_step, s.rtol, s.atol),
        fns, p, fl, d)
    w.seg[SEG_NEXT_STEP] = h_next
    if not ok:  # a non-finite field collapses the step too: say which
        return (NON_FINITE if _non_finite_stage(w.y, hstep, w.K, w.z) else STEP_FAILED), ta
    for k in range(w.z.size):
        w.y_old[k] = w.y[k]
        w.f_old[k] = w.f[k]
        w.y[k] = w.ynew[k]
        w.f[k] = w.K[_NS, k]
    _dop_dense(hstep, d)
    w.seg[SEG_STEP_T] = ta
    w.seg[SEG_STEP_H] = tb - ta
    t_s = min(w.seg[SEG_SUSPECT], t_guard)
    w.seg[SEG_SUSPECT] = t_s
    if t_s <= tb and _passed_suspect(mode, ta, tb, fl, ctx) != _GO_ON:
        # the orbit passed a time a stage met the guard at, where its field is not
        # finite: the run searches the step up to there (an event before it stands),
        # and the next step stops it there
        w.seg[SEG_NOT_FINITE] = t_s
        return _GO_ON, t_s
    return _GO_ON, tb


@_jit
def _passed_suspect(mode, ta, tb, fl, ctx):
    """The step [ta, tb] passed SEG_SUSPECT, a time a trial stage met the non-finite
    guard at: the field on the orbit found, there, is finite (GO_ON, the suspect
    cleared), or the orbit runs through a non-finite field (NON_FINITE): a band of NaN
    a shorter step may have stepped over (D16 (5))."""
    fns, p, s, w = ctx
    t = w.seg[SEG_SUSPECT]
    w.seg[SEG_SUSPECT] = np.inf
    _dense_eval(t, ta, tb - ta, w.y_old, w.F, w.ytmp)
    if _checked_field(w.ytmp, mode, _FIRST_CALL, fns, p, fl, w.ynew):
        return _GO_ON
    return NON_FINITE


@_jit_inline
def _end_step(mode, ta, tb, st, te, ctx):
    """After the windows of the step [ta, tb] (their status st, the event's time te):
    dP/dz carried over the step (an exact flow's at its event, from the mode entry); st."""
    fns, p, s, w = ctx
    if _DERIVATIVES and s.jac:
        dv = w.deriv
        if w.seg[SEG_INTEGRATED] == 0.0:
            if st == OK:
                _flow_jacobian(mode, w.za, te - w.seg[SEG_ENTRY], fns, p, dv, s.flow_jac)
                _apply(dv.Mt, dv.M, dv.KP[0])
        elif st == _GO_ON or (st == OK and te > ta):
            _var_step(mode, w.y_old, (tb if st == _GO_ON else te) - ta, fns, p,
                      Fill(w.wg, w.wf, w.wp), dv, s.jac == 2)
    return st


@_jit_inline
def _end_slide(t, w):
    """Counts the slide that ends at t (time, and change of state)."""
    w.tally[T_SLID] += t - w.tally[T_SLIDE_START]
    for k in range(w.z.size):
        w.slide_dz[k] += w.z[k] - w.slide_z0[k]


# ------------------------------------------------------------------ the run's operations
# What the kernel does in a run, for filippov.loop.event, which holds the order: each
# takes ctx = RunCtx(fns, p, s, w) (the model's pieces, its parameters, kernel.state's Settings
# and Work); at an event it works at the event's state w.z.

@_jit_inline
def _at_section(mode, t, ctx):
    """A section hit ends the run: the age in this mode at the hit (the next return of an
    iterated run goes on from it: a hit is no mode entry), the slide it ends, dP/dz."""
    fns, p, s, w = ctx
    w.tally[T_AGE] = (t - w.seg[SEG_ENTRY] + w.tally[T_AGE] if (mode != SLIDING and s.exact)
                      else 0.0)
    if mode == SLIDING:
        _end_slide(t, w)
    if _DERIVATIVES and s.jac:
        _section_derivative(mode, fns, p, w.z, Fill(w.wg, w.wf, w.wp), w.deriv)
    return OK


@_jit_inline
def _exit_state(new_mode, ctx):
    """The event's state w.z, grad h there (left in w.wg by _event_pieces), h, and the
    exact flow of w.z in new_mode over time 0 (its rounding, in w.wz), or w.z itself when
    integrated."""
    fns, p, s, w = ctx
    for k in range(w.z.size):
        w.wz[k] = w.z[k]
    if s.exact:
        if new_mode == PLUS:
            _flow_plus(fns, w.z, 0.0, p, w.wz)
        else:
            _flow_minus(fns, w.z, 0.0, p, w.wz)
    return w.z, w.wg, _h(fns, w.z, p), w.wz


@_jit_inline
def _record_switch(mode, new_mode, what, t, ctx):
    """The sliding tallies: the slide that ends, the one that starts."""
    w = ctx.w
    if mode == SLIDING:
        _end_slide(t, w)
    if new_mode == SLIDING:
        w.tally[T_SLIDE_START] = t
        for k in range(w.z.size):
            w.slide_z0[k] = w.z[k]


@_jit_inline
def _record(mode, new_mode, what, t, shift, banded, band, ctx):
    """A section hit (_at_section: OK, or GO_ON) or a switch (_record_switch), after which
    the orbit goes on in new_mode: the next stay's shifts and band (_store_exit), dP/dz
    across a switch from a region (into the other, or into sliding), the age (_entered);
    GO_ON."""
    if what == SECTION:
        return _at_section(mode, t, ctx)
    _record_switch(mode, new_mode, what, t, ctx)
    _store_exit(shift, banded, band, ctx)
    if mode != SLIDING and new_mode != mode:
        _event_switch_derivative(mode, new_mode, ctx)
    _entered(mode, new_mode, t, ctx)
    return _GO_ON


@_jit_inline
def _store_exit(shift, banded, band, ctx):
    """The next stay's shift of H (rules.exit_shift) and the one it measures H from while
    inside the exit's band (rules.banded_shift: the loop's), and the band."""
    seg = ctx.w.seg
    seg[SEG_EXIT_SHIFT] = shift
    seg[SEG_BAND] = band
    seg[SEG_SHIFT] = banded


@_jit_inline
def _event_switch_derivative(mode, new_mode, ctx):
    fns, p, s, w = ctx
    if _DERIVATIVES and s.jac:
        _switch_derivative(mode, new_mode, fns, p, w.z, Fill(w.wg, w.wf, w.wp), w.deriv)


@_jit_inline
def _entered(mode, new_mode, t, ctx):
    """The age in the mode the orbit goes on in (rules.exact_window's transient)."""
    s, w = ctx.s, ctx.w
    if new_mode != mode:
        w.tally[T_AGE] = 0.0  # an entry: the fast transient starts again
    elif mode != SLIDING and s.exact:
        w.tally[T_AGE] += t - w.seg[SEG_ENTRY]  # the stay goes on from here


# inlined into the run: as a call it took the run's whole ctx member by member once per
# return (+0.7% instructions per return, docs/decisions.md#kernel-start-inlined)
@_jit_inline
def _begin(z0, age0, ctx):
    """The run's start from z0 (its state in w.z): (status, 0.0, its mode); the counters
    cleared first, so a start refused reports none. w.first_sw[0]: time of the first
    change of mode (left untouched if there is none); w.slide_dz: the change of state
    summed over the sliding stretches (counted like the sliding time w.tally[T_SLID]);
    age0: the time already spent in the start's region (rules.carried_age),
    w.tally[T_AGE] the same at the return."""
    fns, p, s, w = ctx
    n = z0.size
    for k in range(COUNT_SIZE):
        w.count[k] = 0
    w.tally[T_SLID] = 0.0
    for k in range(n):
        w.slide_dz[k] = 0.0
    for k in range(n):
        w.z[k] = z0[k]
        if not np.isfinite(z0[k]):
            return BAD_START, 0.0, 0
    st, mode, _, age = _start(_h(fns, w.z, p), s.touch_tol, s.sliding, 1, age0, ctx)
    if st != _GO_ON:
        return st, 0.0, mode
    w.touched[0] = False
    if _DERIVATIVES and s.jac:
        # a start that slides: the return is not differentiable across H there
        for i in range(n):
            for j in range(n):
                w.deriv.M[i, j] = np.nan if mode == SLIDING else (1.0 if i == j else 0.0)
    for k in range(n):
        w.slide_z0[k] = w.z[k]
    w.tally[T_SLIDE_START] = 0.0
    w.tally[T_AGE] = age
    w.seg[SEG_SHIFT] = 0.0
    w.seg[SEG_BAND] = 0.0
    w.seg[SEG_EXIT_SHIFT] = 0.0
    return _GO_ON, 0.0, mode


#: the kernel's side of the seam (filippov.contracts.RunOperations): each operation's
#: function by name
_RUN_OPS = {"begin": "_begin", "next_step": "_next_step", "window": "_window",
            "end_step": "_end_step", "record": "_record", "pieces": "_event_pieces",
            "section_along": "_event_section_along",
            "exit_state": "_exit_state"}


def _operations(ns) -> RunOps:
    """The run's operations from the namespace ``ns`` (this module's globals, or the
    plain build's copies of them)."""
    return RunOps(**{op: ns[name] for op, name in _RUN_OPS.items()})


def _build_run(ns):
    """The first return of one start (filippov.loop.event.make_run) on the operations of
    the namespace ``ns`` (this module's globals, or the plain build's copies of them):
    ``_one(z0, age0, RunCtx(fns, p, s, w), rs) -> (status, t, mode)`` (rs: the loop's record,
    filippov.loop.run_state, on the batch's arrays), the state at the return (or
    where the run stopped) in w.z. A call _batch makes per return, the run's loop and its
    operations inlined into it."""
    plain = not ns["_DERIVATIVES"]

    def named(f):  # numba names a cache file by the qualified name
        if plain:
            f.__qualname__ += "_plain"
        return f
    # the step's walk over its windows (loop.stay.make_step_windows) inlined into it
    return _jit(named(make_run(_operations(ns), inline=lambda f: _jit_inline(named(f)),
                               call=lambda f: _jit(named(f)))))


_build_run.builds = True  # _without_derivatives builds it, not copies it
_one = _build_run(globals())
#: the seam as the kernel fills it (tests/test_contracts.py checks it against the Protocol)
RUN_OPERATIONS = _operations(globals())
#: the start's mode and its refusal to slide in the section (filippov.loop.event), on the
#: run's operations at the state w.z (_begin asks it; both builds share it)
_start = _jit_inline(make_start(RUN_OPERATIONS, inline=_jit_inline, call=_jit))


_KERNEL_SIG = kernel_signature()


@_jit_inline
def _run_record(s, w):
    """The loop's record of a run (filippov.loop.run_state) on the batch's own arrays: its
    counters are w.count's first, its ring w.recent, its first switch w.first_sw; the
    event budget is the hard bound only (projects_budget False: filippov.engines,
    item 2)."""
    return RunState(Limits(s.t_max, s.sliding, s.max_events, s.zeno_count, s.zeno_span,
                           s.touch_tol, s.state_scale, s.time_scale, False, 1, s.max_steps,
                           s.rtol),
                    w.count,
                    w.recent, w.first_sw)


@_jit_inline
def _write_end(i, t, st, mode, s, w, out):
    """Where start i's run ended: its time, switches, sliding time and mode; at a ZENO
    stop the geometric series of its switches (rules.geometric_accumulation), else NaN."""
    out.time[i] = t
    ratio, t_star = np.nan, np.nan
    if st == ZENO:
        ratio, t_star = rules.geometric_accumulation(w.recent, w.count[N_RING], s.zeno_count)
    out.accumulation[i, 0] = ratio
    out.accumulation[i, 1] = t_star
    out.n_switches[i] = w.count[N_SWITCHES]
    out.sliding_time[i] = w.tally[T_SLID]
    out.mode[i] = mode


@njit(cache=True, nogil=True)
def _batch(fns, params, starts, ages, s, out):
    """Each start is mapped s.iterations times by the first-return map, each return
    starting from the last one's state; the outputs describe the last return made
    (or where it stopped) and out.orbit[i] holds the last keep returns (with s.jac:
    out.jacobian and out.orbit_jacobian their derivatives dP/dz, NaN where not made).
    ``params``: one row for the whole batch, or row i for start i (a parameter sweep)."""
    m, n = starts.shape
    per_start = params.shape[0] > 1
    nsmax = max(s.frac_ex.size, s.frac_in.size)
    ts = np.empty(nsmax)
    vals, dvals = np.empty((2, nsmax)), np.empty((2, nsmax))
    svals = np.empty(nsmax)
    recent = np.empty(max(s.zeno_count, 1))
    seg = np.zeros(SEG_SIZE)
    za, y, f = np.zeros(n), np.zeros(n), np.zeros(n)
    y_old, f_old, ynew, ytmp, scale = (np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n),
                                       np.zeros(n))
    wz, wg, wf, wp = np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n)
    K, F = np.zeros((_NSE, n)), np.zeros((_NI, n))
    first = np.zeros(1)
    if _DERIVATIVES:
        deriv = Deriv(np.zeros((n, n)), np.zeros((n, n)), np.zeros((_NS, n)),
                      np.zeros((_NS, n, n)), np.zeros(n), np.zeros(n), np.zeros(n),
                      np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n), np.zeros(n * n),
                      s.state_scale, s.scales)
    else:
        deriv = 0  # the build without the dP/dz code carries no derivative
    w = Work(ts, vals, dvals, svals, recent, seg, za, y, f, y_old, f_old, K, ynew, ytmp, scale,
             F, wz, wg, wf, wp, np.zeros(n), first, np.zeros(n), np.zeros(n),
             np.zeros(COUNT_SIZE, dtype=np.int64), np.zeros(TALLY_SIZE),
             np.zeros(1, dtype=np.bool_), deriv)
    rs = _run_record(s, w)
    keep_jac = out.orbit_jacobian.shape[1]
    n_iter, keep = s.iterations, out.orbit.shape[1]
    zin = np.empty(n)
    for i in range(m):
        for c in range(n):
            zin[c] = starts[i, c]
        done = 0
        age = ages[i]
        p = params[i] if per_start else params[0]  # a C-contiguous row, as pieces take
        # once per start: built, the tuple increfs its 30 (42) arrays (_batch counts refs)
        ctx = RunCtx(fns, p, s, w)
        while True:
            first[0] = np.nan
            st, t, mode = _one(zin, age, ctx, rs)
            if st != OK:
                break
            done += 1
            j = done - 1 - (n_iter - keep)
            if j >= 0:
                for c in range(n):
                    out.orbit[i, j, c] = w.z[c]
                # element by element: a slice assignment compiles
                # (docs/decisions.md#kernel-elementwise-copy)
                if _DERIVATIVES and keep_jac > 0:
                    for a in range(n):
                        for b in range(n):
                            out.orbit_jacobian[i, j, a, b] = w.deriv.M[a, b]
            if done >= n_iter:
                break
            for c in range(n):
                zin[c] = w.z[c]
            age = w.tally[T_AGE]
        out.returns_done[i] = done
        out.age[i] = w.tally[T_AGE]
        out.first_switch[i] = first[0]
        for c in range(n):
            out.state[i, c] = w.z[c]
            out.sliding_displacement[i, c] = w.slide_dz[c]
        out.status[i] = st
        for a in range(n):
            for b in range(n):
                out.jacobian[i, a, b] = np.nan
        if _DERIVATIVES and s.jac != 0 and st == OK:
            for a in range(n):
                for b in range(n):
                    out.jacobian[i, a, b] = w.deriv.M[a, b]
        _write_end(i, t, st, mode, s, w, out)


#: the files whose code the kernel contains: every module of this package and of the
#: event loop's orchestration (filippov.loop, compiled in), and the library modules it
#: compiles or reads. numba's on-disk cache checks only the file of each cached function,
#: not those of the functions it calls (a kernel cached before an edit of rules.py would
#: go on running the old rules: seen, and numba's documented limit), so the kernel's cache
#: carries a stamp of all of them (_fresh_cache)
KERNEL_SOURCES = tuple(sorted(f"{package}/{p.name}" for package in ("kernel", "loop")
                              for p in (Path(__file__).parents[1] / package).glob("*.py"))
                       ) + ("rules.py", "dop853_tableau.py", "abi.py", "system.py")


def _without_derivatives(decorated):
    """The driver functions ``decorated`` ({name: decorator}, callees first) built again
    from the same code with _DERIVATIVES False, in globals of their own (each copy calls
    the others' copies); each copy gets a qualified name of its own, which numba names
    its cache files by. A decorator marked ``builds`` (_build_run) builds its function
    from the copies' globals instead (a closure over them). Returns the copies by name."""
    env = dict(globals(), _DERIVATIVES=False)
    for name, decorator in decorated.items():
        if getattr(decorator, "builds", False):  # a closure over the copies: built again
            env[name] = decorator(env)
            continue
        f = globals()[name].py_func
        g = pytypes.FunctionType(f.__code__, env, f.__name__, f.__defaults__, f.__closure__)
        g.__qualname__, g.__doc__ = f"{f.__qualname__}_plain", f.__doc__
        env[name] = decorator(g)
    return {name: env[name] for name in decorated}


# the functions on the way from _batch to a _DERIVATIVES branch
_PLAIN = _without_derivatives({"_window": _jit_inline,
                               "_end_step": _jit_inline, "_at_section": _jit_inline,
                               "_record": _jit_inline,
                               "_event_switch_derivative": _jit_inline,
                               "_begin": _jit_inline, "_one": _build_run,
                               "_batch": njit(cache=True, nogil=True)})
_one_plain, _batch_plain = _PLAIN["_one"], _PLAIN["_batch"]


def _kernel_stamp() -> str:
    digest = hashlib.sha256()
    for name in KERNEL_SOURCES:
        digest.update(name.encode() + (Path(__file__).parents[1] / name).read_bytes())
    return digest.hexdigest()


def _compiled(objects) -> list:
    """The compiled functions among ``objects`` and every one reachable from them through
    their closures: the loop's pieces the kernel compiles inside a factory (the event
    search's refinement, loop.interval) are no module's attribute, and a cache of theirs
    written by other sources would be read (numba unpickles an index before it checks its
    stamp: a type since removed fails to load)."""
    out, seen, todo = [], set(), list(objects)
    while todo:
        obj = todo.pop()
        if id(obj) in seen or not (hasattr(obj, "py_func") and hasattr(obj, "_cache")):
            continue
        seen.add(id(obj))
        out.append(obj)
        todo.extend(cell.cell_contents for cell in obj.py_func.__closure__ or ())
    return out


def _fresh_cache() -> None:
    """Drop every cached compiled function of the kernel (the rules compiled for it
    included) when the kernel's sources changed since the cache was written."""
    stamp_file = Path(_batch._cache.cache_path) / "kernel.sha256"
    stamp = _kernel_stamp()
    try:
        if stamp_file.read_text() == stamp:
            return
    except OSError:
        pass  # no stamp yet: a cache of unknown sources
    from . import base, derivative, dop853, roots, scan, segment
    # the plain build's copies (_PLAIN) too: _begin's is a call with a cache of its own
    modules = (base, derivative, dop853, roots, scan, segment, sys.modules[__name__])
    for obj in _compiled([o for m in modules for o in vars(m).values()] + list(_PLAIN.values())):
        obj._cache.flush()
    try:
        stamp_file.parent.mkdir(parents=True, exist_ok=True)
        stamp_file.write_text(stamp)
    except OSError:
        pass  # a read-only cache: numba compiles in memory and caches nothing anyway


def kernel(derivatives: bool = False):
    """The kernel with (or without) the dP/dz code, compiled for its one signature or
    loaded from numba's on-disk cache (if that was written from the same sources)."""
    batch = _batch if derivatives else _batch_plain
    if not batch.overloads:  # (its signatures list costs microseconds: this is per call)
        with _compile_lock():
            _fresh_cache()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NumbaExperimentalFeatureWarning)
                batch.compile(_KERNEL_SIG)
        batch.disable_compile()  # any other argument types are an error, not a recompile
    return batch


@contextlib.contextmanager
def _compile_lock():
    """One process at a time checks, compiles and caches the kernel: jobs that start
    together (a workflow's first jobs, one per core) wait for the first one's compile
    and load its cache, instead of each compiling the same kernel (19-40 s of CPU each;
    a cold `make figures` on 2 cores compiled it twice). Without a writable cache
    directory, or where flock is missing, each process compiles on its own as before."""
    try:
        import fcntl
        folder = Path(_batch._cache.cache_path)
        folder.mkdir(parents=True, exist_ok=True)
        handle = open(folder / "kernel.lock", "a")
    except (ImportError, OSError):
        yield
        return
    with handle:
        fcntl.flock(handle, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(handle, fcntl.LOCK_UN)


# what a cold compile is made of, and what cutting it costs per return:
# docs/decisions.md#kernel-compile-floor
def compile_kernel(derivatives: bool = False) -> bool:
    """Compile the kernel (:func:`kernel`) now rather than at its first use; True if it
    was loaded from the cache."""
    return sum(kernel(derivatives).stats.cache_hits.values()) > 0
