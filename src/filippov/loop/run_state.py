"""What the loop keeps of a run, in one record both engines build alike
(:func:`filippov.loop.event.make_run`'s ``rs``): the run's limits, its counters, the Zeno
ring and the time of its first change of mode.

The loop reads and writes these fields itself; an engine only builds the record (the
reference driver once per run, the compiled kernel once per batch, on arrays it also
reads for its outputs) and never hands the loop an operation to reach them. The record is
a named tuple of scalars and arrays: numba passes it to the kernel's run as its members,
and the reference driver's Python reads the same names.
"""
from __future__ import annotations

from collections import namedtuple

import numpy as np

from .. import rules
from .status import EVENT_LIMIT, GO_ON, ZENO

#: the run's fixed limits: its end time; whether the system builds sliding; the hard
#: bound on switches (max_events); the Zeno ring's size and span (rules.note_switch);
#: H's touch tolerance; the run's state and time scales (filippov.scale); whether the
#: event budget is also projected from the switching rate (rules.budget_runs_out: the
#: reference engine, filippov.engines item 2); the number of the run's sections (an
#: arrival on H that would slide inside one is refused: filippov.loop.event)
Limits = namedtuple("Limits", ["t_end", "sliding", "max_events", "zeno_count", "zeno_span",
                               "touch_tol", "state_scale", "time_scale", "projects_budget",
                               "sections"])

#: the record: ``limits`` (:data:`Limits`); ``count`` (int64, positions :data:`COUNT`:
#: changes of mode so far, entries into the ring so far; an engine may keep counters of
#: its own after them); ``ring`` (float64, the last zeno_count switch times, entry k at
#: k % zeno_count); ``first_switch`` (float64[1]: the time of the run's first change of
#: mode, written when it happens)
RunState = namedtuple("RunState", ["limits", "count", "ring", "first_switch"])

#: the loop's positions in ``count``
COUNT = ("switches", "ring")
SWITCHES, RING = range(len(COUNT))


def new_run_state(limits: Limits) -> RunState:
    """A fresh record for one run: counters at zero, an empty ring, no first switch."""
    return RunState(limits, np.zeros(len(COUNT), dtype=np.int64),
                    np.empty(max(int(limits.zeno_count), 1)), np.full(1, np.nan))


def count_switch(rs: RunState, t: float, changed: bool) -> int:
    """The record at a switch at t (``changed``: a change of mode, counted; the run's first
    one's time kept): GO_ON, or EVENT_LIMIT past the hard bound max_events, ZENO where the
    Zeno ring says the switches accumulate (rules.note_switch), EVENT_LIMIT where the
    budget projected from the switching rate runs out (rules.budget_runs_out, where the
    limits say so). The run (filippov.loop.event) asks it at every switch it records."""
    limits = rs.limits
    if changed:
        rs.count[SWITCHES] += 1
        if rs.count[SWITCHES] == 1:
            rs.first_switch[0] = t
    if rs.count[SWITCHES] > limits.max_events:
        return EVENT_LIMIT
    entries, zeno = rules.note_switch(rs.ring, rs.count[RING], t, limits.zeno_count,
                                      limits.zeno_span, limits.time_scale)
    rs.count[RING] = entries
    if zeno:
        return ZENO
    if entries >= limits.zeno_count and limits.projects_budget and rules.budget_runs_out(
            rs.ring, entries, t, limits.zeno_count, limits.t_end, rs.count[SWITCHES],
            limits.max_events):
        return EVENT_LIMIT
    return GO_ON
