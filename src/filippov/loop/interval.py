"""The event search of one sample interval, and the walk over a window's intervals,
written once for both engines.

Between two samples of a stay the scan asks, in this order:

1. does a leave function change sign (h: a switch; while sliding, a or b: an exit into
   region - or +: ``rules.ended_by``)? Its root, refined; the earliest of them is the
   event so far;
2. none, and sliding: has a or b an extremum toward its sign change hidden between the
   samples (``rules.speed_extremum_between``)? The engine refines it and
   ``rules.speed_graze`` tells an exit (the earliest wins) from a touch, which is
   recorded when it comes before any exit;
3. none, and in a region: has h an extremum hidden between the samples
   (``rules.extremum_between``)? ``rules.graze``: a switch at h's root before it, or a
   touch (recorded);
4. each section that changes sign, in order: its root is the event when it comes first
   (``rules.section_first``: not before its min_time; before the event so far, or at its
   instant when that is a switch or an exit -- a section on H is hit where the orbit
   arrives on H) and the engine counts it there (``where`` holds, and it is not the run's
   start on the section up to rounding).

A window's intervals are asked in time order (:func:`make_window_event`), only those
where a sign change shows; while the exit's rounding band is in force, the first such
interval whose start is out of the band (``rules.clears_band``) ends it: h is sampled
again unbiased from there and that interval is asked again whether it still holds a
sign change; a window with no event ends it when its last sample is out of the band.
A switch found while the band is in force, at a time where the orbit is
already out of it, is refined again on h itself (:func:`make_past_band`).

:func:`make_window_event` builds the search from the engine's own operations -- how it
tests its samples, refines a root, finds a hidden extremum, records a touch --, each a
function of the engine's state ``ctx`` first. The reference driver
(:class:`filippov.simulate._Scan`) passes its Python methods and runs the result as it
is; the compiled kernel (:mod:`filippov.kernel.scan`) passes its compiled pieces and
compiles the result with numba (``inline="always"``), so this module is plain scalar
Python in the subset numba compiles.

An event is ``(status, t, what, k)``: ``status`` OK or the engine's failure code (the
reference raises instead, so its operations always return OK); ``what`` one of
:data:`NONE`, ``rules.SWITCH``, ``rules.EXIT_MINUS``, ``rules.EXIT_PLUS``,
:data:`SECTION` (the kernel's codes); ``k`` the index of the section hit (-1 for any
other event).
"""
from __future__ import annotations

import math
from collections import namedtuple

from .. import rules
from ..rules import GRAZE_CROSSES, GRAZE_TOUCHES, SWITCH
from ..system import SLIDING

#: the status of an operation that succeeded (the kernel's OK)
OK = 0
#: what an event is besides the ends of a stay (rules.SWITCH, EXIT_MINUS, EXIT_PLUS):
#: nothing in the interval, or a section hit
NONE, SECTION = -1, 3


#: How an engine walks a window's sample intervals, each a function of its state ``ctx``:
#:
#: * ``skip_to(ctx, i, mode)``: the first interval from i on that may show a sign change
#:   (``last_sample(ctx)`` if none): an engine that found its candidates with array
#:   operations jumps to the next one, an engine that tests each interval as it comes
#:   answers i itself;
#: * ``candidate_at(ctx, i, mode) -> (hit, at)``: interval i shows a sign change (one of
#:   the questions may hold), and the state ``at`` the questions are asked on there (ctx
#:   itself, or ctx with what the engine saw at i);
#: * ``last_sample(ctx)``: the index of the window's last sample;
#: * ``clears_band_at(ctx, i, mode)``: the exit's band is in force and the orbit is out
#:   of it at sample i; ``unband(ctx, i, mode)``: the band ends, h is sampled again
#:   unbiased from sample i on and the candidates from i on are found again (none when i
#:   is past the last sample).
WalkOps = namedtuple("WalkOps", (
    "skip_to", "candidate_at", "last_sample", "clears_band_at", "unband"))

#: How an engine answers the questions of sample interval i, each on the state ``at``:
#:
#: * ``leave_crosses(at, q, i)``: leave function q (0: h, or a while sliding; 1: b)
#:   changes sign; ``leave_root(at, q, i, mode) -> (status, t)``: its root;
#: * ``slide_end_between(at, q, i)``: while sliding, speed q has an extremum toward its
#:   sign change; ``hidden_slide_end(at, q, i, mode) -> (status, t, kind)``: judged by
#:   rules.speed_graze, GRAZE_CROSSES with the speed's root before it, GRAZE_TOUCHES with
#:   the extremum's time, or GRAZE_NONE; ``extremum_between(at, i)``,
#:   ``hidden_extremum(at, i, mode)``: the same for h in a region (rules.graze);
#: * ``touch(at, t, mode)``: a touch of H at t (no event; the return map has a kink);
#: * ``n_sections(at)``, ``section_crosses(at, k, i)``, ``section_root(at, k, i, mode)
#:   -> (status, t)``, ``section_bounds(at, k) -> (t_min, xtol)``, ``section_counts(at,
#:   k, i, t, mode)``: the crossing at t is a hit (where holds, not the start itself).
IntervalOps = namedtuple("IntervalOps", (
    "leave_crosses", "leave_root", "slide_end_between", "hidden_slide_end",
    "extremum_between", "hidden_extremum", "touch", "n_sections", "section_crosses",
    "section_root", "section_bounds", "section_counts"))


def make_window_event(walk: WalkOps, ask: IntervalOps):
    """``window_event(ctx, mode) -> (status, t, what, k)``: the earliest event over a
    window's sample intervals in time order, each interval's questions in the order of
    this module's docstring, from the engine's operations (:data:`WalkOps`,
    :data:`IntervalOps`). The questions are written in the walk's loop, not called: the
    kernel inlines each operation here, and a composed function inlined whole costs the
    cold compile a copy of all of it (docs/decisions.md#kernel-inlined-driver)."""
    skip_to, candidate_at, last_sample, clears_band_at, unband = walk
    (leave_crosses, leave_root, slide_end_between, hidden_slide_end, extremum_between,
     hidden_extremum, touch, n_sections, section_crosses, section_root, section_bounds,
     section_counts) = ask

    def window_event(ctx, mode):
        n = last_sample(ctx)
        i = skip_to(ctx, 0, mode)
        while i < n:
            hit, at = candidate_at(ctx, i, mode)
            if hit and clears_band_at(ctx, i, mode):
                unband(ctx, i, mode)  # interval i asked again, h unbiased (band now 0)
                continue
            if hit:
                best_t, best_w = math.inf, NONE
                # 1. the leave functions' crossings: the earliest
                for q in range(2 if mode == SLIDING else 1):
                    if leave_crosses(at, q, i):
                        st, r = leave_root(at, q, i, mode)
                        if st != OK:
                            return st, r, NONE, -1
                        if best_w == NONE or r < best_t:
                            best_t, best_w = r, rules.ended_by(mode, q)
                # 2. none while sliding: the end of sliding hidden between the samples
                if mode == SLIDING and best_w == NONE:
                    touch_a, touch_b = math.inf, math.inf
                    for q in range(2):
                        if not slide_end_between(at, q, i):
                            continue
                        st, r, kind = hidden_slide_end(at, q, i, mode)
                        if st != OK:
                            return st, r, NONE, -1
                        if kind == GRAZE_CROSSES:
                            if best_w == NONE or r < best_t:
                                best_t, best_w = r, rules.ended_by(mode, q)
                        elif kind == GRAZE_TOUCHES:
                            if q == 0:
                                touch_a = r
                            else:
                                touch_b = r
                    # a touch before any exit, in time order: P has a kink there
                    for tm in (min(touch_a, touch_b), max(touch_a, touch_b)):
                        if tm < best_t:
                            touch(at, tm, mode)
                # 3. none in a region: an extremum of h hidden between the samples
                if mode != SLIDING and best_w == NONE and extremum_between(at, i):
                    st, r, kind = hidden_extremum(at, i, mode)
                    if st != OK:
                        return st, r, NONE, -1
                    if kind == GRAZE_CROSSES:
                        best_t, best_w = r, SWITCH
                    elif kind == GRAZE_TOUCHES:
                        touch(at, r, mode)
                # 4. the sections in order: a hit that comes first, or at a switch
                best_k = -1
                for k in range(n_sections(at)):
                    if not section_crosses(at, k, i):
                        continue
                    st, r = section_root(at, k, i, mode)
                    if st != OK:
                        return st, r, NONE, -1
                    t_min, xtol = section_bounds(at, k)
                    if (rules.section_first(r, t_min, best_t, best_w == SECTION, xtol)
                            and section_counts(at, k, i, r, mode)):
                        best_t, best_w, best_k = r, SECTION, k
                if best_w != NONE:
                    return OK, best_t, best_w, best_k
            i = skip_to(ctx, i + 1, mode)
        if clears_band_at(ctx, n, mode):
            unband(ctx, n + 1, mode)  # no sample after the last one to take again
        return OK, math.inf, NONE, -1

    return window_event


def make_past_band(banded_h, refine_unbanded):
    """``past_band(ctx, r, lo, mode, band) -> t``: a switch found at r (the root of h as
    biased by the exit's band, searched from lo) refined again on h itself when the orbit
    is out of the band before r: probed back from r toward lo (``rules.band_probe``)
    until a time out of the band (``rules.clears_band``), the root of the unbiased h
    between it and r; r itself if no probe clears the band. The engine's operations:

    * ``banded_h(ctx, t, mode)``: h as biased by the band, at t;
    * ``refine_unbanded(ctx, lo, hi, mode)``: the root of the unbiased h in [lo, hi]
      (hi if the engine's refinement fails).
    """

    def past_band(ctx, r, lo, mode, band):
        tq, step, done, clear = r, 0.0, False, False
        while not done:
            clear = rules.clears_band(mode, banded_h(ctx, tq, mode), band)
            done, tq, step = rules.band_probe(tq, step, lo, clear)
        if clear:
            return refine_unbanded(ctx, tq, r, mode)
        return r

    return past_band
