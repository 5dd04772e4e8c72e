"""A run -- its stays, and what is done at each event (a section hit or a switch), in
what order, against the event budget and the Zeno ring: written once for both engines.

:func:`make_run` builds the run from the engine's own operations (:class:`RunOps`: how
it starts, follows a stay to its event, evaluates the pieces, h and grad h at the
event's state and the exact flow over time 0, records a hit or a switch, keeps the next
stay's shift, updates dP/dz); what the run itself keeps -- its limits, the switches
counted, the Zeno ring, the first switch's time -- is the loop's own record
(:mod:`filippov.loop.run_state`), which each engine builds and the loop reads and
writes. The rules it asks it calls as ``rules.<name>`` on both engines (the kernel
registers every rule as compilable: :mod:`filippov.kernel.base`). The result,
``run(z0, age0, ctx, rs) -> (status, t, mode)``,
is plain scalar Python in the subset numba compiles: the reference driver
(:mod:`filippov.simulate`) calls it as it is, with ``ctx`` its run, and turns a status
into its end or its exception; the compiled kernel (:mod:`filippov.kernel.driver`)
compiles it as the call its batch makes per return, with ``ctx`` its records; ``rs``
is the run's record on both. The Zeno ring, an array of the last ``zeno_count`` switch
times in ``rs``, is rules.note_switch.

Before each stay: filippov.loop.stay.before_stay (the end time; sliding the system does
not build); before each step, the run's step budget
(:func:`filippov.loop.run_state.count_step`: rules.step_budget_spent, STEP_LIMIT). The
order at a switch: the decision (rules.next_mode); sliding that the system does not build
(NO_SLIDING); the end of a slide: a two-fold (both speeds vanished along the slide,
rules.at_two_fold, or both fields tangent to H there, rules.tangent_to_both: TWO_FOLD),
then rules.exit_drift, onto_switch, exit_band, exit_shift (the exact flow over time 0); an
arrival on H that would slide inside a section refused there (SECTION_SLIDING); the
switch recorded by the engine, with the next stay's shift, banded shift
(rules.banded_shift) and band, dP/dz across the switch and its entry into the new mode;
then counted (:func:`filippov.loop.run_state.count_switch`: the hard bound max_events,
EVENT_LIMIT; the Zeno ring, rules.note_switch, ZENO; where the run's record says so --
the reference engine: :mod:`filippov.engines` item 2 -- the budget projected from the
switching rate, rules.budget_runs_out).

The event is written in the run's loop, not as a function the loop calls: numba inlines
a function by copying its whole IR, and the event, its operations inlined, was the
largest such copy of the kernel's build (docs/decisions.md#kernel-inlined-driver).
"""
from __future__ import annotations

from collections import namedtuple

from .. import rules
from ..contracts import RunOperations, operations
from ..system import SLIDING
from .status import (GO_ON, NO_NORMAL, NO_RETURN, NO_SLIDING, OK, SECTION_SLIDING,
                     SLID_OFF_H, TWO_FOLD)
from .run_state import RING, STEPS, SWITCHES, count_step, count_switch
from .interval import as_is
from .stay import before_stay, make_failed_step, make_slides_in, make_step_windows

#: what an event is: a crossing of H or an end of sliding (rules.SWITCH, EXIT_MINUS,
#: EXIT_PLUS: rules.next_mode's ``ended_by``), or a hit of a section
SECTION = 3
assert SECTION not in (rules.SWITCH, rules.EXIT_MINUS, rules.EXIT_PLUS)

#: the engine's operations in a run, in the order of
#: :class:`filippov.contracts.RunOperations` (the seam; ``ctx``: the engine's state; the
#: state at an event is the engine's, each operation evaluates at it):
#: begin(z0, age0, ctx) -> (status, t, mode): the run's start from z0 (its age in its
#: region age0: rules.carried_age), GO_ON or why it cannot start; a stay, in the order the
#: run holds: per step next_step(mode, ta, first, ctx) -> (status, tb) (the stay begun
#: at its first step; GO_ON and the step's end, or why there is none: the stay cannot
#: begin, a failed step; the run asks the step budget before each step itself,
#: filippov.loop.run_state.count_step), window(mode, t0, t1, first, may_split, ctx) ->
#: (status, t, what) (one window of the step sampled and searched: the run searches the
#: step window by window with it, filippov.loop.stay.make_step_windows), end_step(mode, ta, tb,
#: status, t, ctx) -> status (GO_ON to the next step; OK at an event, its time t and
#: ``what``; NO_RETURN at the end time, or an error): the stay written in the run, as the
#: event is, so that the kernel copies no composed stay
#: (docs/decisions.md#kernel-inlined-driver);
#: record(mode, new_mode, what, t, shift, banded, band, ctx) -> status: an event recorded
#: and passed -- a section hit (what == SECTION: OK ends the run, GO_ON goes on in the
#: same stay; the rest unused) or a switch, after which the orbit goes on in new_mode
#: (GO_ON; before the budgets are asked): the next stay's shift of H, the one it
#: measures H from inside the exit's rounding band (rules.banded_shift) and the band,
#: dP/dz across a switch from a region (into the other, or into sliding), the engine's
#: bookkeeping;
#: pieces(ctx) -> :data:`Pieces` (the pieces at the state: the engine evaluates, the loop
#: decides with them); section_along(k, mode, d, ctx): section k at
#: z + d times the field of ``mode`` (MINUS, PLUS, SLIDING; d = 0: at z) -- with the
#: pieces, the test of a slide inside a section (filippov.loop.stay.make_slides_in), at
#: the start and at an arrival on H; exit_state(new_mode, ctx) -> (the state as an array the event
#: may move onto H, grad H and H there, and the state the next stay in new_mode starts
#: from as it evaluates it: the exact flow over time 0, rules.exit_band)
RunOps = namedtuple("RunOps", operations(RunOperations))

#: what ``pieces(ctx)`` returns, the pieces at the state as the engine evaluates them:
#: the state z, grad H, F_- and F_+ there (arrays), the normal speeds a = grad H . F_-
#: and b = grad H . F_+ (the engine's own dot products: the reference's numpy sums, the
#: kernel's loops), H there, the run's state scale and each component's (filippov.scale)
Pieces = namedtuple("Pieces", ("z", "grad", "f_minus", "f_plus", "a", "b", "h", "floor",
                               "scales"))


def make_sliding_section(ops: RunOps, inline=as_is):
    """``sliding_section(n, ctx) -> k``: the first of the run's n sections the sliding flow
    at the state (on H) stays in (filippov.loop.stay.make_slides_in on the engine's
    ``pieces`` and ``section_along``), or -1."""
    slides_in = inline(make_slides_in(ops.pieces, ops.section_along))

    def sliding_section(n, ctx):
        for k in range(n):
            if slides_in(k, ctx):
                return k
        return -1
    return sliding_section


def make_start(ops: RunOps, inline=as_is, call=as_is):
    """``start(h, touch_tol, sliding, sections, age0, ctx) -> (status, mode, repelling,
    age)``: the start's mode, decided by the rule book from H at the start
    (rules.start_side) and, on H, the normal speeds (rules.start_on_switch;
    ``repelling``: a start on repelling H); status SECTION_SLIDING for a start that slides
    inside one of the run's ``sections`` sections (:func:`make_sliding_section`), else
    GO_ON; ``age``, the time already spent in the start's region by an orbit the start
    continues (``age0``: rules.carried_age; 0 on H). On the engine's ``pieces`` and
    ``section_along`` at the start: an engine's ``begin`` asks it."""
    pieces = ops.pieces
    # ``call``: the kernel's compiled call (asked at a start on H only)
    sliding_section = call(make_sliding_section(ops, inline))

    def start(h, touch_tol, sliding, sections, age0, ctx):
        side = rules.start_side(h, touch_tol)
        age = rules.carried_age(h, touch_tol, age0)  # 0 on H (|h| <= touch_tol), as side
        if side != SLIDING:
            return GO_ON, side, False, age
        pc = pieces(ctx)
        if rules.no_normal(pc.grad):
            return NO_NORMAL, side, False, age
        mode, repelling = rules.start_on_switch(h, pc.a, pc.b, sliding)
        if mode == SLIDING and sliding_section(sections, ctx) >= 0:
            return SECTION_SLIDING, mode, repelling, age
        return GO_ON, mode, repelling, age
    return start


def make_left_h(pieces):
    """``left_h(mode, ctx, limits) -> bool``: the state a slide hands out (a section's
    hit, the run's end) lies off H beyond the slide's integration error (rules.slid_off:
    a switch_grad wrong along the slide); False outside a slide."""
    def left_h(mode, ctx, limits):
        if mode != SLIDING:
            return False
        pc = pieces(ctx)
        return rules.slid_off(pc.h, pc.z, pc.grad, pc.scales, limits.rtol)
    return left_h


def make_run(ops: RunOps, inline=as_is, call=as_is):
    """``run(z0, age0, ctx, rs) -> (status, t, mode)``: the orbit from z0 in this module's
    order, until a status ends it (OK at a terminal section hit, NO_RETURN at the end time,
    or why not); t and ``mode`` where it ended. ``rs``: the record, counters cleared."""
    begin, next_step, window, end_step, record, pieces, _, exit_state = ops
    step_windows = inline(make_step_windows(window))  # ``inline``: the kernel's, or as is
    failed_step = inline(make_failed_step(pieces))
    left_h = inline(make_left_h(pieces))
    sliding_section = call(make_sliding_section(ops, inline))  # at an arrival on H only

    def run(z0, age0, ctx, rs):
        limits = rs.limits
        rs.count[SWITCHES], rs.count[RING], rs.count[STEPS] = 0, 0, 0
        status, t, mode = begin(z0, age0, ctx)
        if status != GO_ON:
            return status, t, mode
        a_in, b_in = 0.0, 0.0  # the normal speeds where the slide began (rules.at_two_fold)
        if mode == SLIDING:
            pc = pieces(ctx)
            a_in, b_in = pc.a, pc.b
        while True:
            status = before_stay(mode, t, limits.t_end, limits.sliding)
            if status != GO_ON:
                return status, t, mode
            status, ta, first, what = GO_ON, t, True, -1  # the stay to its event (what)
            while status == GO_ON:
                status, tb = count_step(rs), ta  # within the run's step budget, or it stops
                if status == GO_ON:
                    status, tb = next_step(mode, ta, first, ctx)
                if status != GO_ON:  # no step: why (a slide's failure at a two-fold named)
                    return failed_step(status, mode, ctx), ta, mode
                status, t, what = step_windows(mode, ta, tb, first, ctx)
                status = end_step(mode, ta, tb, status, t, ctx)
                ta, first = tb, False
            if (status == NO_RETURN or what == SECTION) and left_h(mode, ctx, limits):
                return SLID_OFF_H, t, mode
            if status != OK:
                return status, t, mode
            if what == SECTION:
                status = record(mode, mode, what, t, 0.0, 0.0, 0.0, ctx)
                if status != GO_ON:
                    return status, t, mode
                continue
            pc = pieces(ctx)
            a, b = pc.a, pc.b
            new_mode = rules.next_mode(mode, what, a, b)
            if new_mode == SLIDING and mode != SLIDING:
                a_in, b_in = a, b
            if new_mode == SLIDING and not limits.sliding:
                return NO_SLIDING, t, mode
            shift, band = 0.0, 0.0
            if mode == SLIDING and new_mode != SLIDING:
                if rules.slid_off(pc.h, pc.z, pc.grad, pc.scales, limits.rtol):
                    return SLID_OFF_H, t, mode
                # a two-fold: both speeds vanished along the slide, or both fields tangent
                if (rules.at_two_fold(a, b, a_in, b_in)
                        or rules.tangent_to_both(a, b, pc.grad, pc.f_minus, pc.f_plus,
                                                 pc.scales, pc.floor)):
                    return TWO_FOLD, t, mode
                # a state left off H beyond rounding is moved onto it (H: rules.exit_band)
                z, grad, h0, z_next = exit_state(new_mode, ctx)
                drift = rules.exit_drift(new_mode, h0, z, grad, limits.touch_tol)
                if drift:
                    rules.onto_switch(z, h0, grad)
                    # what rounding left, the next stay's start from there (grad H kept)
                    z, _, h0, z_next = exit_state(new_mode, ctx)
                band = rules.exit_band(z, z_next, grad, limits.state_scale, pc.scales)
                shift = rules.exit_shift(new_mode, h0, limits.touch_tol, drift)
            # an arrival on H that would slide inside a section is refused there
            if (new_mode == SLIDING and mode != SLIDING
                    and sliding_section(limits.sections, ctx) >= 0):
                return SECTION_SLIDING, t, mode
            banded = rules.banded_shift(new_mode, shift, band) if band > 0.0 else shift
            status = record(mode, new_mode, what, t, shift, banded, band, ctx)
            if status == GO_ON:
                status = count_switch(rs, t, new_mode != mode)
            if status != GO_ON:
                return status, t, mode
            mode = new_mode
    return run
