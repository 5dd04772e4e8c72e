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
from .status import EVENT_LIMIT, GO_ON, STEP_LIMIT, ZENO

#: the run's fixed limits: its end time; whether the system builds sliding; the hard
#: bound on switches (max_events); the Zeno ring's size and span (rules.note_switch);
#: H's touch tolerance; the run's state and time scales (filippov.scale); whether the
#: event budget is also projected from the switching rate (rules.budget_runs_out: the
#: reference engine, filippov.engines item 2); the number of the run's sections (an
#: arrival on H that would slide inside one is refused: filippov.loop.event); the step
#: budget (max_steps: rules.step_budget_spent, asked by the run before each step); the
#: integration's relative tolerance (how far a slide may drift off H: rules.slid_off)
Limits = namedtuple("Limits", ["t_end", "sliding", "max_events", "zeno_count", "zeno_span",
                               "touch_tol", "state_scale", "time_scale", "projects_budget",
                               "sections", "max_steps", "rtol"])

#: the record: ``limits`` (:data:`Limits`); ``count`` (int64, positions :data:`COUNT`:
#: changes of mode so far, entries into the ring so far, steps so far (an exact flow's
#: windows, integration steps); an engine may keep counters of its own after them);
#: ``ring`` (float64, the last zeno_count switch times, entry k at k % zeno_count);
#: ``first_switch`` (float64[1]: the time of the run's first change of mode, written when
#: it happens)
RunState = namedtuple("RunState", ["limits", "count", "ring", "first_switch"])

#: the loop's positions in ``count``
COUNT = ("switches", "ring", "steps")
SWITCHES, RING, STEPS = range(len(COUNT))


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


def count_step(rs: RunState) -> int:
    """The record at a step about to be taken (an integration step, or an exact flow's
    window): counted; GO_ON, or STEP_LIMIT once the run's step budget is spent
    (rules.step_budget_spent). The run (filippov.loop.event) asks it before each step."""
    rs.count[STEPS] += 1
    return STEP_LIMIT if rules.step_budget_spent(rs.count[STEPS], rs.limits.max_steps) else GO_ON
