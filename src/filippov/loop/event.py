"""What is done at an event -- a section hit or a switch -- and in what order, against
the event budget and the Zeno ring: written once for both engines.

:func:`make_event` builds the event function from the engine's own operations
(:class:`EventOps`: how it evaluates the speeds, h and grad h at the event's state, the
exact flow over time 0, how it records a hit or a switch, keeps its counters and the next
stay's shift, updates dP/dz); the rules it asks it calls as ``rules.<name>`` on both
engines (the kernel registers every rule as compilable: :mod:`filippov.kernel.base`).
The result, ``event(mode, t, what, ctx) -> (status, mode)``, is plain scalar Python in
the subset numba compiles: the reference driver (:mod:`filippov.simulate`) calls it as
it is, with ``ctx`` its run, and turns a status into its exception; the compiled kernel
(:mod:`filippov.kernel.driver`) compiles it inlined into its driver, with ``ctx`` its
records. The Zeno ring both engines keep, an array of the last ``zeno_count`` switch
times, is rules.note_switch.

The order at a switch: the decision (rules.next_mode); sliding that the system does not
build (NO_SLIDING); an arrival on H that would slide inside a section
(SECTION_SLIDING); the end of a slide (rules.exit_drift, onto_switch, exit_band,
exit_shift: the exact flow over time 0); the switch recorded and counted; the hard
bound max_events (EVENT_LIMIT); the Zeno ring (rules.note_switch: ZENO); the engine's own
budget verdict (the reference's projection of the switching rate, :mod:`filippov.engines`
item 2);
then the next stay's shift and band, dP/dz across the switch and the engine's entry
into the new mode.
"""
from __future__ import annotations

from collections import namedtuple

from .. import rules
from ..system import SLIDING
from .status import EVENT_LIMIT, GO_ON, NO_SLIDING, SECTION_SLIDING, ZENO

#: what an event is: a crossing of H or an end of sliding (rules.SWITCH, EXIT_MINUS,
#: EXIT_PLUS: rules.next_mode's ``ended_by``), or a hit of a section
SECTION = 3
assert SECTION not in (rules.SWITCH, rules.EXIT_MINUS, rules.EXIT_PLUS)

#: the engine's operations at an event (``ctx``: the engine's state; the state at the
#: event is the engine's, each operation evaluates at it):
#: section_hit(mode, t, ctx) -> status: records a hit (OK ends the run, GO_ON goes on);
#: speeds(ctx) -> (a, b); h(ctx) -> H; grad_h(ctx) -> grad H, an array (called after
#: speeds, before the state moves); state(ctx) -> the state as an array the event may
#: move onto H; flow_at_zero(mode, z, ctx) -> the state the next stay in ``mode`` starts
#: from as it evaluates it (rules.exit_band); sliding_built(ctx) -> bool;
#: slides_in_section(ctx) -> bool; record_switch(mode, new_mode, what, t, ctx);
#: count_switch(changed, t, ctx) -> switches so far; limits(ctx) -> (max_events,
#: zeno_count, zeno_span, touch_tol); ring(ctx) -> (times, entries);
#: store_ring(entries, ctx); over_budget(t, new_mode, switches, ctx) -> bool, asked once
#: the ring is full; store_exit(new_mode, shift, band, ctx): the next stay's shift of H
#: and rounding band; switch_derivative(mode, new_mode, ctx): dP/dz across a crossing;
#: entered(mode, new_mode, t, ctx): the engine's bookkeeping as the orbit goes on
EventOps = namedtuple("EventOps", [
    "section_hit", "speeds", "h", "grad_h", "state", "flow_at_zero", "sliding_built",
    "slides_in_section", "record_switch", "count_switch", "limits", "ring", "store_ring",
    "over_budget", "store_exit", "switch_derivative", "entered"])


def make_event(ops: EventOps):
    """``event(mode, t, what, ctx) -> (status, mode)``: the event ``what`` (:data:`SECTION`
    or rules.SWITCH/EXIT_MINUS/EXIT_PLUS) at time ``t`` of an orbit in ``mode``, done in
    the order of this module's doc with the rule book's rules and ``ops``'s operations. The
    status is GO_ON with the mode to go on in, or the run's end (OK at a terminal section
    hit, NO_SLIDING, SECTION_SLIDING, EVENT_LIMIT, ZENO) with ``mode`` itself."""
    (section_hit, speeds, h, grad_h, state, flow_at_zero, sliding_built, slides_in_section,
     record_switch, count_switch, limits, ring, store_ring, over_budget, store_exit,
     switch_derivative, entered) = ops

    def event(mode, t, what, ctx):
        if what == SECTION:
            return section_hit(mode, t, ctx), mode
        a, b = speeds(ctx)
        new_mode = rules.next_mode(mode, what, a, b)
        if new_mode == SLIDING and not sliding_built(ctx):
            return NO_SLIDING, mode
        if new_mode == SLIDING and mode != SLIDING and slides_in_section(ctx):
            return SECTION_SLIDING, mode
        max_events, zeno_count, zeno_span, touch_tol = limits(ctx)
        shift, band = 0.0, 0.0
        if mode == SLIDING and new_mode != SLIDING:
            # the end of a slide: a state the slide left off H beyond rounding is moved
            # onto it; the next stay measures H from the exit's rounding
            z, grad, h0 = state(ctx), grad_h(ctx), h(ctx)
            drift = rules.exit_drift(new_mode, h0, z, grad, touch_tol)
            if drift:
                rules.onto_switch(z, h0, grad)
                h0 = h(ctx)  # what rounding left
            band = rules.exit_band(z, flow_at_zero(new_mode, z, ctx), grad)
            shift = rules.exit_shift(new_mode, h0, touch_tol, drift)
        record_switch(mode, new_mode, what, t, ctx)
        switches = count_switch(new_mode != mode, t, ctx)
        if switches > max_events:
            return EVENT_LIMIT, mode
        recent, entries = ring(ctx)
        entries, zeno = rules.note_switch(recent, entries, t, zeno_count, zeno_span)
        store_ring(entries, ctx)
        if zeno:
            return ZENO, mode
        if entries >= zeno_count and over_budget(t, new_mode, switches, ctx):
            return EVENT_LIMIT, mode
        store_exit(new_mode, shift, band, ctx)
        if mode != SLIDING and new_mode != mode:
            switch_derivative(mode, new_mode, ctx)
        entered(mode, new_mode, t, ctx)
        return GO_ON, new_mode
    return event
