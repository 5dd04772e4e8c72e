"""The start (filippov.loop.event.make_start) and the check before each stay, written
once (filippov.loop.stay): the decisions the reference driver runs as Python and the
kernel compiles."""
import numpy as np
import pytest
from numba import njit

from filippov import rules
from filippov.loop import stay
from filippov.loop.event import Pieces
from filippov.loop.status import (GO_ON, NO_RETURN, NO_SLIDING, NON_FINITE, SECTION_SLIDING,
                                  STEP_FAILED, TWO_FOLD)
from filippov.system import MINUS, PLUS, SLIDING

BEFORE = [stay.before_stay, njit(stay.before_stay)]


@pytest.mark.parametrize("before", BEFORE, ids=["python", "compiled"])
def test_a_stay_begins_before_the_end_time_and_slides_only_if_built(before):
    assert before(PLUS, 0.5, 1.0, False) == GO_ON
    assert before(SLIDING, 0.5, 1.0, True) == GO_ON
    assert before(SLIDING, 0.5, 1.0, False) == NO_SLIDING
    assert before(MINUS, 1.0, 1.0, True) == NO_RETURN
    assert before(SLIDING, 2.0, 1.0, False) == NO_RETURN  # the end time first


def _start(slides):
    """The loop's start on operations whose speeds are ctx's (a, b) and whose section
    lies on H (slides: the sliding flow stays in it) or across it."""
    from filippov.loop.event import RunOps, make_start
    section = (lambda z: z[1]) if slides else (lambda z: z[0] - 0.3)
    pieces, along = _plane(section)
    return make_start(RunOps(*[None] * 5, lambda ctx: pieces(ctx)._replace(a=ctx[0], b=ctx[1]),
                             along, None))


@pytest.mark.parametrize("h, a, b, sliding, slides, expected", [
    (1.0, -1.0, 1.0, True, True, (GO_ON, PLUS, False)),        # off H: its side
    (-1.0, -1.0, 1.0, True, True, (GO_ON, MINUS, False)),
    (0.0, 1.0, -1.0, True, False, (GO_ON, SLIDING, False)),    # on attracting H
    (0.0, 1.0, -1.0, True, True, (SECTION_SLIDING, SLIDING, False)),  # ... in a section
    (0.0, 1.0, -1.0, False, True, (GO_ON, PLUS, False)),  # not built: no slide, no refusal
])
def test_the_start_mode_and_its_refusal_to_slide_in_a_section(h, a, b, sliding, slides,
                                                             expected):
    status, mode, repelling, age = _start(slides)(h, 1e-15, sliding, 1, 2.5, (a, b))
    assert _start(True)(h, 1e-15, sliding, 0, 2.5, (a, b))[0] == GO_ON  # no section
    assert (status, mode, repelling) == expected
    assert age == (2.5 if h != 0.0 else 0.0)  # the age carried off H only (rules.carried_age)
    assert (mode, repelling) == ((rules.start_side(h, 1e-15), False) if h != 0.0
                                 else rules.start_on_switch(h, a, b, sliding))


def _plane(section):
    """F_- = (1, 1), F_+ = (1, -1) about H = y: sliding along y = 0 with field (1, 0);
    the pieces there and section_along as the engines' operations (the field of a mode at
    z + d f)."""
    z, fm, fp = np.array([0.3, 0.0]), np.array([1.0, 1.0]), np.array([1.0, -1.0])
    fields = {MINUS: fm, PLUS: fp, SLIDING: np.array([1.0, 0.0])}
    grad = np.array([0.0, 1.0])
    return (lambda ctx: Pieces(z, grad, fm, fp, grad @ fm, grad @ fp, 0.0, 1.0, np.ones(2)),
            lambda k, mode, d, ctx: section(z + d * fields[mode]))


@pytest.mark.parametrize("section, inside", [
    (lambda z: z[1], True),           # the section is H: the slide stays in it
    (lambda z: z[0] - 0.3, False),    # across the slide
])
def test_a_slide_inside_a_section_is_told_from_one_across_it(section, inside):
    assert bool(stay.make_slides_in(*_plane(section))(0, None)) is inside


def _walk_calls(resolved_length, ta=0.0, tb=1.0, event_at=None):
    """The windows make_step_windows asks for on [ta, tb] when a window resolves once it is
    at most ``resolved_length`` long (and may not be split), with an event at ``event_at``."""
    calls = []

    def window(mode, t0, t1, first, may_split, ctx):
        calls.append((t0, t1, first, may_split))
        if may_split and t1 - t0 > resolved_length:
            return stay.UNRESOLVED, t0, -1
        if event_at is not None and t0 <= event_at <= t1:
            return 0, event_at, 7
        return GO_ON, t1, -1

    result = stay.make_step_windows(window)(PLUS, ta, tb, True, None)
    return calls, result


def test_a_resolved_step_is_one_window():
    calls, result = _walk_calls(2.0)
    assert calls == [(0.0, 1.0, True, True)] and result == (GO_ON, 1.0, -1)


def test_the_first_window_is_the_whole_step_where_its_length_rounds():
    # ta + (tb - ta) rounds below tb here: the first window still ends at tb, so no
    # window one rounding unit long is sampled after it (an exact flow's step is one
    # window, never split: the model's own)
    ta, tb = 0.1180799059133742, 0.8703491968556812
    assert ta + (tb - ta) < tb
    calls, result = _walk_calls(2.0, ta, tb)
    assert calls == [(ta, tb, True, True)] and result == (GO_ON, tb, -1)


def test_an_unresolved_step_is_searched_in_shorter_windows_up_to_its_end():
    calls, result = _walk_calls(0.1)
    asked = [(t0, t1) for t0, t1, _, _ in calls]
    assert asked[:2] == [(0.0, 1.0), (0.0, 1.0 / rules.SPLIT)]
    searched = [(t0, t1) for t0, t1, _, may in calls if not may or t1 - t0 <= 0.1]
    # the searched windows tile the step, in order, each first one of the stay only once
    assert searched[0][0] == 0.0 and searched[-1][1] == 1.0
    assert all(a[1] == b[0] for a, b in zip(searched, searched[1:]))
    assert [c[2] for c in calls if c[0] > 0.0] == [False] * sum(c[0] > 0.0 for c in calls)
    assert result == (GO_ON, 1.0, -1)


def test_an_event_in_a_shorter_window_ends_the_step():
    calls, result = _walk_calls(0.1, event_at=0.2)
    assert result == (0, 0.2, 7)
    assert calls[-1][0] <= 0.2 <= calls[-1][1] and calls[-1][1] < 1.0


def test_splits_stop_after_max_splits_in_a_row():
    """A window that never resolves (noise at every scale) is taken after
    rules.MAX_SPLITS shortenings: the walk is bounded, never a hang."""
    calls, result = _walk_calls(0.0)
    first = [c for c in calls if c[0] == 0.0]
    assert len(first) == rules.MAX_SPLITS + 1 and first[-1][3] is False
    assert first[-1][1] - first[-1][0] == pytest.approx(rules.SPLIT ** -rules.MAX_SPLITS)
    assert result == (GO_ON, 1.0, -1)
    # each later window first tries SPLIT times the last one: two tries a window at most
    assert len(calls) <= rules.MAX_SPLITS + 2 * rules.SPLIT ** rules.MAX_SPLITS


def test_a_window_too_short_to_split_is_taken_as_it_is():
    t = 1.0
    tb = np.nextafter(t, 2.0)
    assert not rules.can_split(t, tb, t, tb)
    calls, result = _walk_calls(0.0, ta=t, tb=tb)
    assert calls == [(t, tb, True, False)] and result == (GO_ON, tb, -1)


@pytest.mark.parametrize("status, mode, tangent, expected", [
    (STEP_FAILED, SLIDING, True, TWO_FOLD),     # a slide's steps collapsed at a two-fold
    (NON_FINITE, SLIDING, True, TWO_FOLD),      # its field 0/0 there
    (STEP_FAILED, SLIDING, False, STEP_FAILED),  # a failure elsewhere: as it is
    (STEP_FAILED, MINUS, True, STEP_FAILED),     # in a region: no slide to name
    (NON_FINITE, PLUS, True, NON_FINITE),
])
def test_a_slides_failed_step_is_named_a_two_fold_where_both_fields_are_tangent(
        status, mode, tangent, expected):
    # both engines' failed step reaches the run through this one function (the
    # reference's slide into a two-fold, tests/test_zeno_accumulation.py, is named here)
    grad = np.array([0.0, 1.0])
    fm, fp = np.array([1.0, 0.0 if tangent else 1.0]), np.array([2.0, 0.0])

    def pieces(ctx):
        return Pieces(np.zeros(2), grad, fm, fp, grad @ fm, grad @ fp, 0.0, 1.0, np.ones(2))
    assert stay.make_failed_step(pieces)(status, mode, None) == expected


def _cut_walk(cut_at, resolved_length, ns=5, ta=0.0, tb=1.0):
    """The windows make_step_windows asks for on [ta, tb] when every state from ``cut_at``
    on is not finite: a window of ``ns`` samples cut at its sample k >= 1 is unresolved
    while it may split and k < 5 (rules.cut_resolves), with the cut's time; an uncut one
    is unresolved while longer than ``resolved_length``; a window that keeps the cut
    stops the run there (NON_FINITE, as the engines' search past it does)."""
    calls = []

    def window(mode, t0, t1, first, may_split, ctx):
        calls.append((t0, t1, may_split))
        ts = [t0 + j * (t1 - t0) / (ns - 1) for j in range(ns - 1)] + [t1]
        k = next((j for j, t in enumerate(ts) if t >= cut_at), -1)
        if k == 0:
            return NON_FINITE, t0, -1
        if may_split and k > 0 and not rules.cut_resolves(k, ns):
            return stay.UNRESOLVED, ts[k], -1
        if may_split and k < 0 and t1 - t0 > resolved_length:
            return stay.UNRESOLVED, t0, -1
        return (NON_FINITE, cut_at, -1) if k > 0 else (GO_ON, t1, -1)

    return calls, stay.make_step_windows(window)(PLUS, ta, tb, True, None)


@pytest.mark.parametrize("cut_at", [0.3, 0.26, 0.51, 0.9999])
@pytest.mark.parametrize("resolved_length", [1.0, 0.01])
def test_a_cut_window_is_approached_without_creeping(cut_at, resolved_length):
    # five samples a window: a window to the cut keeps four, too few to judge. Before
    # rules.to_cut each window to the cut was shortened again and the walk crept on by
    # 1/16 of what was left, down to the shortest window; now the window to the cut is
    # no longer than the last one searched, and is searched as it is
    calls, result = _cut_walk(cut_at, resolved_length)
    assert result == (NON_FINITE, cut_at, -1)
    t0, t1, may = calls[-1]
    assert not may and t0 < cut_at <= t1
    before = calls[-2]
    assert before[1] == t0 and t1 - t0 <= before[1] - before[0]
    # the windows an uncut walk of the step would ask, and a dozen to the cut (without
    # rules.to_cut: 69 to 140)
    uncut, _ = _walk_calls(resolved_length)
    assert len(calls) <= len(uncut) + 12
