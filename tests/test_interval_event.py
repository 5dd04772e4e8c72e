"""The event search of one sample interval is written once (filippov.loop.interval): its
order and ties on scripted operations, and both engines running that one function."""
import ast
import math
from pathlib import Path

import pytest

from filippov import rules
from filippov.loop import interval
from filippov.loop.interval import NONE, OK, SECTION, make_interval_event
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


EVENT = make_interval_event(
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
             for name in ("section_first", "same_instant", "make_interval_event")}
    assert where["section_first"] == ["loop/interval.py"]
    assert where["same_instant"] == ["rules.py"]            # within section_first
    assert sorted(where["make_interval_event"]) == ["kernel/scan.py", "simulate.py"]


def test_both_engines_run_the_one_event_search():
    """The kernel compiles the very function the reference driver runs, and each engine's
    scan asks it; the old per-engine orders are gone."""
    import importlib

    simulate = importlib.import_module("filippov.simulate")  # the module, not the function
    from filippov.kernel import scan

    assert scan._interval_event.py_func.__code__ is simulate._interval_event.__code__
    assert "_interval_event" in _calls(SRC / "simulate.py")
    assert "_interval_event" in _calls(SRC / "kernel/scan.py")
    for gone in ("_event_in", "_leave_crossing", "_section_hit"):
        assert not hasattr(simulate._Scan, gone) and not hasattr(scan, gone)
