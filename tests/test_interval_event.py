"""The event search of a window's sample intervals is written once
(filippov.loop.interval): its order and ties on scripted operations, and both engines
running that one function."""
import ast
import math
from pathlib import Path

import pytest

from filippov import rules
from filippov.loop import interval
from filippov.loop.interval import NONE, OK, SECTION, make_window_event
from filippov.system import MINUS, PLUS, SLIDING

SRC = Path(interval.__file__).resolve().parents[1]
XTOL = 1e-15


class Script:
    """An engine whose answers are given: ``leave`` {q: root}, ``slide`` {q: (t, kind)},
    ``extremum`` (t, kind) or None, ``sections`` [(root, t_min, counts)], ``fail`` the
    question that fails; ``asked`` records the questions in the order they came."""

    def __init__(self, leave=(), slide=(), extremum=None, sections=(), fail=None):
        self.leave, self.slide, self.extremum = dict(leave), dict(slide), extremum
        self.sections, self.fail = list(sections), fail
        self.asked, self.touches = [], []

    def answer(self, name, *value):
        self.asked.append(name)
        return (7 if self.fail == name else OK,) + value


ASK = interval.IntervalOps(
    leave_crosses=lambda c, q, i: q in c.leave,
    leave_root=lambda c, q, i, mode: c.answer(f"leave{q}", c.leave[q]),
    slide_end_between=lambda c, q, i: q in c.slide,
    hidden_slide_end=lambda c, q, i, mode: c.answer(f"slide{q}", *c.slide[q]),
    extremum_between=lambda c, i: c.extremum is not None,
    hidden_extremum=lambda c, i, mode: c.answer("extremum", *c.extremum),
    touch=lambda c, t, mode: c.touches.append(t),
    n_sections=lambda c: len(c.sections),
    section_crosses=lambda c, k, i: c.sections[k] is not None,
    section_root=lambda c, k, i, mode: c.answer(f"section{k}", c.sections[k][0]),
    section_bounds=lambda c, k: (c.sections[k][1], XTOL),
    section_counts=lambda c, k, i, r, mode: c.sections[k][2])
#: a window of one sample interval, the questions asked on it
ONE_INTERVAL = make_window_event(
    interval.WalkOps(skip_to=lambda c, i, mode: i,
                     candidate_at=lambda c, i, mode: (True, c), last_sample=lambda c: 1,
                     clears_band_at=lambda c, i, mode: False, unband=None),
    ASK)


def EVENT(c, i, mode):
    """The event of sample interval i = 0 on the scripted engine c."""
    assert i == 0
    return ONE_INTERVAL(c, mode)


def test_the_earliest_leave_crossing_is_the_event_and_hidden_extrema_are_not_asked():
    c = Script(leave={0: 2.0, 1: 1.5}, slide={0: (1.0, rules.GRAZE_CROSSES)})
    assert EVENT(c, 0, SLIDING) == (OK, 1.5, rules.EXIT_PLUS, -1)
    assert c.asked == ["leave0", "leave1"]
    c = Script(leave={0: 2.0}, extremum=(1.0, rules.GRAZE_CROSSES))
    assert EVENT(c, 0, PLUS) == (OK, 2.0, rules.SWITCH, -1)
    assert c.asked == ["leave0"]


def test_a_hidden_end_of_sliding_the_earliest_exit_and_the_touches_before_it():
    c = Script(slide={0: (3.0, rules.GRAZE_CROSSES), 1: (2.5, rules.GRAZE_CROSSES)})
    assert EVENT(c, 0, SLIDING) == (OK, 2.5, rules.EXIT_PLUS, -1)
    c = Script(slide={0: (2.0, rules.GRAZE_TOUCHES), 1: (1.0, rules.GRAZE_TOUCHES)})
    assert EVENT(c, 0, SLIDING) == (OK, math.inf, NONE, -1)
    assert c.touches == [1.0, 2.0]                      # in time order
    c = Script(slide={0: (2.0, rules.GRAZE_TOUCHES), 1: (1.0, rules.GRAZE_CROSSES)})
    assert EVENT(c, 0, SLIDING) == (OK, 1.0, rules.EXIT_PLUS, -1)
    assert c.touches == []                              # after the exit: none


@pytest.mark.parametrize("mode", (PLUS, MINUS))
def test_a_hidden_extremum_of_h_is_a_switch_or_a_touch_in_a_region(mode):
    c = Script(extremum=(1.0, rules.GRAZE_CROSSES))
    assert EVENT(c, 0, mode) == (OK, 1.0, rules.SWITCH, -1)
    c = Script(extremum=(1.0, rules.GRAZE_TOUCHES))
    assert EVENT(c, 0, mode) == (OK, math.inf, NONE, -1) and c.touches == [1.0]
    c = Script(extremum=(1.0, rules.GRAZE_CROSSES), slide={0: (0.5, rules.GRAZE_CROSSES)})
    assert EVENT(c, 0, mode)[2] == rules.SWITCH and "slide0" not in c.asked


def test_a_section_wins_at_the_instant_of_a_switch_and_the_first_of_two_hits_stays():
    tie = rules.same_instant(XTOL, 2.0)
    c = Script(leave={0: 2.0}, sections=[(2.0 + 0.5 * tie, 0.0, True)])
    assert EVENT(c, 0, PLUS) == (OK, 2.0 + 0.5 * tie, SECTION, 0)
    c = Script(leave={0: 2.0}, sections=[(2.0 + 2.0 * tie, 0.0, True)])
    assert EVENT(c, 0, PLUS) == (OK, 2.0, rules.SWITCH, -1)
    c = Script(sections=[(2.0, 0.0, True), (2.0, 0.0, True), (1.0, 0.0, False)])
    assert EVENT(c, 0, MINUS) == (OK, 2.0, SECTION, 0)
    assert c.asked == ["section0", "section1", "section2"]
    c = Script(sections=[(2.0, 0.0, True), (1.0, 0.0, True)])
    assert EVENT(c, 0, MINUS) == (OK, 1.0, SECTION, 1)
    c = Script(sections=[(1.0, 1.5, True)])                    # before min_time
    assert EVENT(c, 0, PLUS) == (OK, math.inf, NONE, -1)


def test_a_failed_question_ends_the_search_with_its_status():
    c = Script(leave={0: 1.0}, sections=[(0.5, 0.0, True)], fail="leave0")
    assert EVENT(c, 0, PLUS) == (7, 1.0, NONE, -1) and c.asked == ["leave0"]


# ------------------------------------------------------------------ written once
def _calls(path):
    """The names of the functions called in the file (f(...) and x.f(...))."""
    names = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call):
            f = node.func
            names.append(f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", None))
    return names


def test_the_tie_break_is_called_only_by_the_one_event_search():
    sources = sorted(SRC.rglob("*.py"))
    where = {name: [p.relative_to(SRC).as_posix() for p in sources
                    for call in _calls(p) if call == name]
             for name in ("section_first", "same_instant", "make_window_event")}
    assert where["section_first"] == ["loop/interval.py"]
    assert where["same_instant"] == ["rules.py"]            # within section_first
    assert sorted(where["make_window_event"]) == ["kernel/scan.py", "simulate.py"]


def test_both_engines_run_the_one_event_search():
    """The kernel compiles the very function the reference driver runs, and each engine's
    scan asks it; the old per-engine orders are gone."""
    import importlib

    simulate = importlib.import_module("filippov.simulate")  # the module, not the function
    from filippov.kernel import scan

    assert scan._window_event.py_func.__code__ is simulate._window_event.__code__
    # each engine's window walk asks its own operations
    for walk, ops in ((simulate._window_event, (simulate._Scan._leave_root,
                                                simulate._Scan._section_counts)),
                      (scan._window_event.py_func, (scan._leave_root_at,
                                                    scan._section_counts))):
        cells = [cell.cell_contents for cell in walk.__closure__]
        assert all(op in cells for op in ops)
    for gone in ("_event_in", "_leave_crossing", "_section_hit", "_interval_event"):
        assert not hasattr(simulate._Scan, gone) and not hasattr(scan, gone)
    assert not hasattr(simulate, "_interval_event")  # the questions are in the walk


# ----------------------------------------------------------- the walk over a window
class Window:
    """A window of ``n`` samples whose intervals are scripted: ``cand`` the candidate
    intervals (banded), ``unbanded`` those once the band ends, ``clear`` the first sample
    out of the band, ``events`` {i: t}; ``asked`` the intervals the event search was
    asked, ``unbands`` the samples the band ended at."""

    def __init__(self, cand, events, clear=None, unbanded=(), n=12, fail=False):
        self.cand, self.events, self.clear, self.unbanded = list(cand), events, clear, unbanded
        self.n, self.band, self.asked, self.unbands = n, clear is not None, [], []
        self.fail = fail

    def crosses(self, q, i):
        """The scripted interval: h changes sign at an event (or the search fails)."""
        if q == 0:
            self.asked.append(i)
        return q == 0 and (i in self.events or self.fail)

    def root(self, q, i, mode):
        return (7, 0.25) if self.fail else (OK, self.events[i])


def _walk(skip=True):
    """The walk on a scripted Window; ``skip``: jump to the next candidate (as the
    reference does) or test every interval (as the kernel does)."""
    return interval.make_window_event(
        interval.WalkOps(
            skip_to=lambda c, i, mode: (min((j for j in c.cand if j >= i), default=c.n - 1)
                                        if skip else i),
            candidate_at=lambda c, i, mode: (i in c.cand, c),
            last_sample=lambda c: c.n - 1,
            clears_band_at=lambda c, i, mode: c.band and i >= c.clear,
            unband=lambda c, i, mode: (c.unbands.append(i), setattr(c, "band", False),
                                       setattr(c, "cand", [j for j in c.unbanded if j >= i]))),
        interval.IntervalOps(
            leave_crosses=Window.crosses, leave_root=Window.root,
            slide_end_between=lambda c, q, i: False, hidden_slide_end=None,
            extremum_between=lambda c, i: False, hidden_extremum=None, touch=None,
            n_sections=lambda c: 0, section_crosses=None, section_root=None,
            section_bounds=None, section_counts=None))


WALKS = [_walk(), _walk(skip=False)]
walks = pytest.mark.parametrize("WALK", WALKS, ids=["skipping", "every-interval"])


@walks
def test_the_window_asks_its_candidates_in_time_order_up_to_the_first_event(WALK):
    c = Window(cand=[2, 5, 9, 11], events={9: 4.5, 11: 5.5})
    assert WALK(c, PLUS) == (OK, 4.5, rules.SWITCH, -1)
    assert c.asked == [2, 5, 9] and c.unbands == []
    c = Window(cand=[], events={})
    assert WALK(c, MINUS) == (OK, math.inf, NONE, -1) and c.asked == []


@walks
def test_the_band_ends_at_the_first_candidate_out_of_it_and_that_interval_is_asked_again(WALK):
    # out of the band at interval 5: h unbiased from there shows no change at 5 any more
    c = Window(cand=[2, 5, 9], events={7: 3.5}, clear=5, unbanded=[0, 7, 9])
    assert WALK(c, PLUS) == (OK, 3.5, rules.SWITCH, -1)
    assert c.unbands == [5] and c.asked == [2, 7]  # 0 lies before the band's end
    # ... or still does: then that interval is asked at once
    c = Window(cand=[2, 5], events={5: 2.5}, clear=5, unbanded=[5])
    assert WALK(c, PLUS) == (OK, 2.5, rules.SWITCH, -1)
    assert c.unbands == [5] and c.asked == [2, 5]


@walks
def test_a_window_with_no_event_ends_the_band_at_its_last_sample_out_of_it(WALK):
    # no candidate out of the band, but the last sample (11) is: the band ends there,
    # with no sample after it to take again
    c = Window(cand=[2], events={}, clear=8)
    assert WALK(c, PLUS) == (OK, math.inf, NONE, -1)
    assert c.asked == [2] and c.unbands == [12] and not c.band
    # still in the band at the last sample: it stays in force for the next window
    c = Window(cand=[2], events={}, clear=20)
    assert WALK(c, PLUS) == (OK, math.inf, NONE, -1) and c.unbands == [] and c.band
    # an event in the window: the window ends there, the band with it only if passed
    c = Window(cand=[2], events={2: 1.0}, clear=8)
    assert WALK(c, PLUS) == (OK, 1.0, rules.SWITCH, -1) and c.unbands == [] and c.band


def test_a_failed_search_stops_the_walk():
    c = Window(cand=[1, 3], events={}, fail=True)
    assert WALKS[0](c, SLIDING) == (7, 0.25, NONE, -1) and c.asked == [1]


def test_both_engines_walk_their_windows_with_the_one_function():
    import importlib

    simulate = importlib.import_module("filippov.simulate")
    from filippov.kernel import scan

    assert scan._window_event.py_func.__code__ is simulate._window_event.__code__
    assert "_window_event" in _calls(SRC / "simulate.py")
    assert "_window_event" in _calls(SRC / "kernel/scan.py")


def test_a_switch_beyond_the_band_is_refined_again_from_the_first_probe_out_of_it():
    """make_past_band probes back from r toward lo (rules.band_probe) and refines the
    unbiased h from the first probe whose banded h clears the band; none: r stands."""
    band, asked = 0.1, []

    def walk(clear_before):  # banded h in region +: clears the band before clear_before
        refined = []
        past = interval.make_past_band(
            lambda c, t, mode: (asked.append(t), 1.0 if t < clear_before else 0.0)[1],
            lambda c, lo, hi, mode: (refined.append((lo, hi)), 0.5 * (lo + hi))[1])
        return past(None, 2.0, 1.0, PLUS, band), refined

    t, refined = walk(clear_before=1.5)
    assert asked[0] == 2.0 and all(b < a for a, b in zip(asked, asked[1:]))
    tq = asked[-1]
    assert tq < 1.5 <= asked[-2] and refined == [(tq, 2.0)] and t == 0.5 * (tq + 2.0)
    asked.clear()
    t, refined = walk(clear_before=1.0)  # never out of the band after lo: r stands
    assert t == 2.0 and refined == [] and asked[-1] == 1.0


def test_both_engines_probe_past_the_band_with_the_one_function():
    import importlib

    simulate = importlib.import_module("filippov.simulate")
    from filippov.kernel import scan

    assert scan._past_band.py_func.__code__ is simulate._past_band.__code__
    for gone in ("_band_root",):
        assert not hasattr(scan, gone)
    assert not hasattr(simulate._Scan, "_past_band")


def test_the_walk_is_one_loop_asking_each_question_in_one_place():
    """The kernel inlines every call of an operation (numba, inline="always"): the walk
    asks each question in one place (a touch: while sliding and in a region), is one loop
    over the intervals (a walk that restarted an inner loop of candidates after each
    interval cost the kernel about 2% of its instructions per return), and its only other
    loops are the questions' own (the leave functions q, the two touches, the sections k):
    docs/decisions.md#kernel-inlined-driver."""
    import inspect
    import textwrap

    tree = ast.parse(textwrap.dedent(inspect.getsource(interval.make_window_event)))
    calls = [node.func.id for node in ast.walk(tree)
             if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)]
    for op in interval.IntervalOps._fields:
        assert calls.count(op) == (2 if op == "touch" else 1), op
    assert calls.count("last_sample") == 1
    # an interval is asked once: after the band's end the loop asks it again itself
    assert calls.count("candidate_at") == 1
    for op in ("skip_to", "clears_band_at", "unband"):
        assert calls.count(op) == 2, op  # at the start and after the band's end
    assert sum(isinstance(node, ast.While) for node in ast.walk(tree)) == 1
    assert sorted(node.target.id for node in ast.walk(tree)
                  if isinstance(node, ast.For)) == ["k", "q", "q", "tm"]
