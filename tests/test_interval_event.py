"""The event search of a window's sample intervals is written once
(filippov.loop.interval): its order, ties and decisions on a scripted engine (functions of
time given in closed form, roots by bisection), and both engines running that one
function, neither deciding anything of it."""
import ast
import math
from pathlib import Path

import numpy as np
import pytest

from filippov import rules
from filippov.loop import interval, refine
from filippov.loop.interval import (F_LEAVE, F_RATE, F_SECTION, F_TIME, F_UNBANDED, NONE, OK,
                                    SECTION, make_window_event)
from filippov.loop.status import CUT, ROOT_FAILED
from filippov.system import MINUS, PLUS, SLIDING

SRC = Path(interval.__file__).resolve().parents[1]
XTOL = 1e-15


class Engine:
    """An engine whose functions are given as callables of time by the loop's codes
    (``funcs``), sampled at ``ts``; roots and extrema by bisection. ``sections``: (pred,
    t_min, counts) per section, whose values are funcs[F_SECTION + k]; ``fail`` the
    function whose root or extremum fails; ``asked`` records the roots and extrema asked
    in order, ``touches`` the touches, ``unbands`` the samples the band ended at.
    ``skip``: None, every interval asked (the kernel); a mode, the intervals flagged by
    the reference's array operations in that mode (interval.candidate_mask)."""

    def __init__(self, funcs, ts, first=False, band=0.0, rates=True, sections=(), fail=None,
                 unbanded=None):
        self.funcs, self.ts, self.first, self.band, self.rates = dict(funcs), list(ts), first, \
            band, rates
        self.sections, self.fail, self.unbanded = list(sections), fail, unbanded
        self.asked, self.touches, self.unbands = [], [], []
        self.skip, self.from_i = None, 0

    def window(self):
        return interval.Window(len(self.ts) - 1, self.first, self.band, self.rates, 1e-9, XTOL,
                               tuple(s[0] for s in self.sections),
                               tuple(s[1] for s in self.sections), self._cand())

    def _cand(self):
        if self.skip is None:
            return None
        mode, nl = self.skip, 2 if self.skip == SLIDING else 1

        def samples(f):
            return np.array([self.sampled(f, j) for j in range(len(self.ts))])
        mask = interval.candidate_mask(
            mode, [samples(F_LEAVE + q) for q in range(nl)],
            [samples(F_RATE + q) for q in range(nl)],
            [(sec[0], samples(F_SECTION + k)) for k, sec in enumerate(self.sections)],
            self.first)
        mask[:self.from_i] = False
        return mask

    def sampled(self, f, i):
        return self.ts[i] if f == F_TIME else self.funcs[f](self.ts[i]) if f in self.funcs \
            else math.nan

    def value(self, f, t, mode):
        return self.funcs[f](t)

    def _bisect(self, g, lo, hi):
        for _ in range(200):
            mid = 0.5 * (lo + hi)
            if g(mid):
                hi = mid
            else:
                lo = mid
        return hi

    def root(self, f, lo, hi, vlo, vhi, mode):
        """Bisection to the side of the sign change f has at hi (the refinement, the
        loop's, walks the root to its far side); a rate's (F_RATE + q: an extremum, the
        samples' values handed) to the side where the rate's sign has flipped. A bracket
        the ends lost is not pinned (as the kernel)."""
        g = self.funcs[f]
        if F_RATE <= f < F_UNBANDED:
            self.asked.append(("extremum", f))
            if self.fail == ("extremum", f):
                return False, lo, g(lo)
            d0 = g(lo)
            r = self._bisect(lambda t: (g(t) > 0) != (d0 > 0), lo, hi)
            return True, r, g(r)
        if not math.isnan(vlo):
            return False, lo, vlo
        self.asked.append(("root", f))
        if self.fail == f or (g(lo) > 0) == (g(hi) > 0):
            return False, lo, g(lo)
        r = self._bisect(lambda t: (g(t) > 0) == (g(hi) > 0), lo, hi)
        return True, r, g(r)

    def counts(self, k, i, t, mode):
        return self.sections[k][2]

    def touch(self, t, mode):
        self.touches.append(t)

    def unband(self, i, mode):
        self.unbands.append(i)
        self.funcs[F_LEAVE], self.band, self.from_i = self.unbanded, 0.0, i


OPS = interval.WindowOps(Engine.window, Engine.sampled, Engine.value, Engine.root,
                         Engine.counts, Engine.touch, Engine.unband)
EVENT = make_window_event(OPS)
#: a window of one sample interval [0, 2]
T2 = (0.0, 2.0)


def test_the_earliest_leave_crossing_is_the_event_and_hidden_extrema_are_not_asked():
    # while sliding: a reaches 0 at 1.8, b at 1.5; b's rate also shows a maximum between
    # the samples, not asked
    c = Engine({F_LEAVE: lambda t: 1.8 - t, F_LEAVE + 1: lambda t: t - 1.5,
                F_RATE: lambda t: -1.0, F_RATE + 1: lambda t: 1 - 2 * (t - 1)}, T2)
    st, t, what, k = EVENT(c, SLIDING)
    assert (st, what, k) == (OK, rules.EXIT_PLUS, -1) and abs(t - 1.5) < 1e-12
    assert c.asked == [("root", F_LEAVE), ("root", F_LEAVE + 1)]
    c = Engine({F_LEAVE: lambda t: 1.5 - t, F_RATE: lambda t: -1.0}, T2)
    st, t, what, _ = EVENT(c, PLUS)
    assert what == rules.SWITCH and abs(t - 1.5) < 1e-12


def test_a_hidden_end_of_sliding_the_earliest_exit_and_the_touches_before_it():
    # b has its maximum 0.5 at t = 1 between samples where it is -0.5: an exit at its
    # root before the maximum, 1 - sqrt(0.5)
    exit_b = {F_LEAVE: lambda t: 1.0, F_RATE: lambda t: 0.0,
              F_LEAVE + 1: lambda t: 0.5 - (t - 1) ** 2, F_RATE + 1: lambda t: -2 * (t - 1)}
    c = Engine(exit_b, T2)
    st, t, what, _ = EVENT(c, SLIDING)
    assert what == rules.EXIT_PLUS and abs(t - (1 - math.sqrt(0.5))) < 1e-12
    # ... unless the rates of a and b are not sampled: nothing seen
    c = Engine(exit_b, T2, rates=False)
    assert EVENT(c, SLIDING) == (OK, math.inf, NONE, -1) and c.asked == []
    # maxima within the touch tolerance: touches, recorded in time order
    touch = {F_LEAVE: lambda t: 1e-12 + (t - 1.5) ** 2, F_RATE: lambda t: 2 * (t - 1.5),
             F_LEAVE + 1: lambda t: -1e-12 - (t - 0.5) ** 2, F_RATE + 1: lambda t: -2 * (t - 0.5)}
    c = Engine(touch, T2)
    assert EVENT(c, SLIDING) == (OK, math.inf, NONE, -1)
    assert len(c.touches) == 2 and abs(c.touches[0] - 0.5) < 1e-12 \
        and abs(c.touches[1] - 1.5) < 1e-12
    # a touch after an exit: none
    touch_after_exit = {**touch, F_LEAVE + 1: exit_b[F_LEAVE + 1],
                        F_RATE + 1: exit_b[F_RATE + 1]}
    c = Engine(touch_after_exit, T2)
    assert EVENT(c, SLIDING)[2] == rules.EXIT_PLUS and c.touches == []


def test_an_exit_hidden_before_the_other_speeds_crossing_ends_the_slide_first():
    """rules.asks_hidden_end: while sliding, b crossing 0 at 1.5 does not stop the search
    for a hidden minimum of a, which dips below 0 around t = 0.5: the slide ends into
    region - at a's root 0.5 - sqrt(0.01), not into region + at 1.5 (before the rule the
    hidden end was asked only where neither speed crossed)."""
    dip = {F_LEAVE: lambda t: (t - 0.5) ** 2 - 0.01, F_RATE: lambda t: 2 * (t - 0.5),
           F_LEAVE + 1: lambda t: t - 1.5, F_RATE + 1: lambda t: 1.0}
    c = Engine(dip, (0.0, 2.0))
    st, t, what, _ = EVENT(c, SLIDING)
    assert what == rules.EXIT_MINUS and abs(t - 0.4) < 1e-12
    assert c.asked == [("root", F_LEAVE + 1), ("extremum", F_RATE), ("root", F_LEAVE)]
    # a touch of a before b's crossing is recorded, one after it is not
    touch = {**dip, F_LEAVE: lambda t: (t - 0.5) ** 2 + 1e-12}
    c = Engine(touch, (0.0, 2.0))
    assert EVENT(c, SLIDING)[2] == rules.EXIT_PLUS and len(c.touches) == 1
    c = Engine({**touch, F_LEAVE: lambda t: (t - 1.75) ** 2 + 1e-12,
                F_RATE: lambda t: 2 * (t - 1.75)}, (0.0, 2.0))
    assert EVENT(c, SLIDING)[2] == rules.EXIT_PLUS and c.touches == []
    # in a region the crossing of h is the event: its extremum is not asked
    c = Engine({F_LEAVE: lambda t: 1.5 - t - 0.1 * (t - 1) ** 2,
                F_RATE: lambda t: -1.0 - 0.2 * (t - 1) if t < 1 else 1.0}, (0.0, 2.0))
    assert EVENT(c, PLUS)[2] == rules.SWITCH and [a for a, _ in c.asked] == ["root"]


@pytest.mark.parametrize("mode", (PLUS, MINUS))
def test_a_hidden_extremum_of_h_is_a_switch_or_a_touch_in_a_region(mode):
    sign = 1.0 if mode == PLUS else -1.0  # h's minimum in +, maximum in -
    for hm, kind in ((-0.25, "switch"), (-1e-12, "touch"), (0.25, "nothing")):
        c = Engine({F_LEAVE: lambda t: sign * (hm + (t - 1) ** 2),
                    F_RATE: lambda t: sign * 2 * (t - 1)}, T2)
        st, t, what, _ = EVENT(c, mode)
        if kind == "switch":
            assert what == rules.SWITCH and abs(t - (1 - math.sqrt(0.25))) < 1e-12
        else:
            assert what == NONE and len(c.touches) == (kind == "touch")
    # within the exit's band the extremum is the exit's own tangency: no touch
    c = Engine({F_LEAVE: lambda t: sign * (1e-12 + 1e-4 * (t - 1) ** 2),
                F_RATE: lambda t: sign * 2e-4 * (t - 1)}, T2, band=1e-3)
    assert EVENT(c, mode)[2] == NONE and c.touches == []


def test_a_section_wins_at_the_instant_of_a_switch_and_the_first_of_two_hits_stays():
    tie = rules.same_instant(XTOL, 1.0)
    h = {F_LEAVE: lambda t: 1.0 - t, F_RATE: lambda t: -1.0}

    def sec(root):
        return lambda t: t - root
    up = rules.TO_NONNEG
    c = Engine({**h, F_SECTION: sec(1.0 + 0.25 * tie)}, T2, sections=[(up, 0.0, True)])
    st, t, what, k = EVENT(c, PLUS)
    assert (what, k) == (SECTION, 0) and t > 1.0
    c = Engine({**h, F_SECTION: sec(1.0 + 4 * tie)}, T2, sections=[(up, 0.0, True)])
    assert EVENT(c, PLUS)[2:] == (rules.SWITCH, -1)
    c = Engine({F_LEAVE: lambda t: 1.0, F_RATE: lambda t: 0.0, F_SECTION: sec(1.0),
                F_SECTION + 1: sec(1.0), F_SECTION + 2: sec(0.5)}, T2,
               sections=[(up, 0.0, True), (up, 0.0, True), (up, 0.0, False)])
    assert EVENT(c, MINUS)[2:] == (SECTION, 0)
    assert c.asked == [("root", F_SECTION), ("root", F_SECTION + 1), ("root", F_SECTION + 2)]
    c = Engine({F_LEAVE: lambda t: 1.0, F_RATE: lambda t: 0.0, F_SECTION: sec(1.0)}, T2,
               sections=[(up, 1.5, True)])                       # before min_time
    assert EVENT(c, PLUS) == (OK, math.inf, NONE, -1)


def test_a_failed_question_ends_the_search_with_its_status():
    c = Engine({F_LEAVE: lambda t: 1.0 - t, F_RATE: lambda t: -1.0,
                F_SECTION: lambda t: t - 0.5}, T2, sections=[(rules.TO_NONNEG, 0.0, True)],
               fail=F_LEAVE)
    assert EVENT(c, PLUS)[:1] == (ROOT_FAILED,) and EVENT(c, PLUS)[2:] == (NONE, 0)
    assert c.asked[0] == ("root", F_LEAVE) and ("root", F_SECTION) not in c.asked


@pytest.mark.parametrize("mode", [PLUS, MINUS])
def test_a_value_not_finite_between_the_samples_ends_the_search_with_a_cut(mode):
    # h's hidden extremum at t = 1 lies where h is not finite: nothing is decided on it
    # (rules.graze would read NaN as no crossing), the search ends with CUT at its time
    # and the interval it is in, 0 of [0, 2, 4]; a section crossing before it in that
    # interval is left to the engine's search up to the cut
    sign = 1.0 if mode == PLUS else -1.0
    c = Engine({F_LEAVE: lambda t: math.nan if 0.9 < t < 1.1 else sign * ((t - 1) ** 2 - 0.25),
                F_RATE: lambda t: sign * 2 * (t - 1), F_SECTION: lambda t: t - 0.5},
               [0.0, 2.0, 4.0], sections=[(rules.TO_NONNEG, 0.0, True)])
    st, t, what, k = EVENT(c, mode)
    assert (st, what, k) == (CUT, NONE, 0) and abs(t - 1.0) < 1e-12
    assert ("root", F_SECTION) not in c.asked


def test_a_just_entered_modes_start_sample_is_clamped_inside():
    # h a hair below 0 at the entry in region +, falling: the samples show no sign
    # change, the clamped start does (a switch at once)
    h = {F_LEAVE: lambda t: -1e-17 - 0.25 * t, F_RATE: lambda t: -0.25}
    assert EVENT(Engine(h, T2), PLUS) == (OK, math.inf, NONE, -1)
    st, t, what, _ = EVENT(Engine(h, T2, first=True), PLUS)
    assert what == rules.SWITCH and t < 1e-12
    c = Engine({F_LEAVE: lambda t: -1e-17 + t * (1.5 - t), F_RATE: lambda t: 1.5 - 2 * t}, T2,
               first=True)
    st, t, what, _ = EVENT(c, PLUS)
    assert what == rules.SWITCH and abs(t - 1.5) < 1e-12


def test_the_root_of_h_after_an_entry_at_h_is_refined_beyond_its_dip():
    # entered at H: h rises from rounding noise and comes back across H at 1.5; a bracket
    # from the entry would be lost in the noise, so the root is searched from h's maximum
    noise = {F_LEAVE: lambda t: t * (1.5 - t) if t > 1e-9 else -1e-18,
             F_RATE: lambda t: 1.5 - 2 * t}
    c = Engine(noise, T2, first=True)
    st, t, what, _ = EVENT(c, PLUS)
    assert what == rules.SWITCH and abs(t - 1.5) < 1e-12
    assert c.asked[:1] == [("extremum", F_RATE)]


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
    # within section_first, and section.tied_hits: the sections the search's tie leaves
    # behind, hit at that one instant (docs/decisions.md, D25)
    assert sorted(set(where["same_instant"])) == ["rules.py", "section.py"]
    assert sorted(where["make_window_event"]) == ["kernel/scan.py", "simulate.py"]


def test_both_engines_run_the_one_event_search():
    """The kernel compiles the very function the reference driver runs, each engine's
    scan asks it with its own operations, and both refine a leave function's root with
    the one function of the loop."""
    import importlib

    simulate = importlib.import_module("filippov.simulate")  # the module, not the function
    from filippov.kernel import scan

    assert scan._window_event.py_func.__code__ is simulate._window_event.__code__
    for walk, ops in ((simulate._window_event, (simulate._Scan._counts,)),
                      (scan._window_event.py_func, (scan._counts,))):
        cells = [cell.cell_contents for cell in walk.__closure__]
        assert all(any(op is c for c in cells) for op in ops)
        roots = [getattr(c, "py_func", c) for c in cells
                 if getattr(getattr(c, "py_func", c), "__name__", "") == "leave_root"]
        assert len(roots) == 1 and roots[0].__module__ == interval.__name__
    for gone in ("_leave_root", "_hidden_slide_end", "_hidden_extremum", "_past_band",
                 "_banded_h", "_refine_unbanded", "_candidate_at", "_clears_band_at"):
        assert not hasattr(simulate._Scan, gone) and not hasattr(scan, gone), gone
    for gone in ("_leave_root_at", "_speed_exit", "_h_extremum", "_leave_of"):
        assert not hasattr(scan, gone), gone


#: the rules that decide the event search: asked by the loop only
DECISIONS = ("crosses", "after", "clamp", "graze", "speed_graze", "extremum_between",
             "speed_extremum_between", "clears_band", "dips_and_returns", "band_probe",
             "section_first", "ended_by", "leave_pred", "asks_hidden_end")


def _rule_calls(tree):
    return sorted({node.func.attr for node in ast.walk(tree)
                   if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
                   and isinstance(node.func.value, ast.Name) and node.func.value.id == "rules"
                   and node.func.attr in DECISIONS})


def test_no_engine_takes_a_decision_of_the_event_search():
    """The engines report samples, values and roots; every decision of the search (a sign
    change, a hidden extremum and what it is, the clamped start, the band's end, the dip
    after an entry, the tie of a section and a switch) is the loop's."""
    kernel = ast.parse((SRC / "kernel/scan.py").read_text())
    assert _rule_calls(kernel) == []
    reference = next(node for node in ast.parse((SRC / "simulate.py").read_text()).body
                     if isinstance(node, ast.ClassDef) and node.name == "_Scan")
    assert _rule_calls(reference) == []
    loop = ast.parse((SRC / "loop/interval.py").read_text())
    assert set(_rule_calls(loop)) == set(DECISIONS)


# ----------------------------------------------------------- the walk over a window
def _piecewise(values):
    """A function of time through ``values`` at t = 0, 1, 2, ... (linear between)."""
    return lambda t: float(np.interp(t, np.arange(len(values)), values))


TS = [float(t) for t in range(12)]


def _skipping(c, mode):
    """The walk over the intervals the reference's array operations flag."""
    c.skip = mode
    return EVENT(c, mode)


WALKS = [_skipping, EVENT]
walks = pytest.mark.parametrize("WALK", WALKS, ids=["skipping", "every-interval"])


@walks
def test_the_window_asks_its_candidates_in_time_order_up_to_the_first_event(WALK):
    h = [1.0] * 10 + [-1.0, -1.0]                      # crosses in interval 9, at 9.5
    sec = [-1.0] * 3 + [1.0] * 9                       # crosses in interval 2, no hit
    c = Engine({F_LEAVE: _piecewise(h), F_RATE: lambda t: 0.0, F_SECTION: _piecewise(sec)},
               TS, sections=[(rules.TO_NONNEG, 0.0, False)])
    st, t, what, _ = WALK(c, PLUS)
    assert what == rules.SWITCH and abs(t - 9.5) < 1e-12
    assert c.asked == [("root", F_SECTION), ("root", F_LEAVE)]
    c = Engine({F_LEAVE: lambda t: 1.0, F_RATE: lambda t: 0.0}, TS)
    assert WALK(c, MINUS) == (OK, math.inf, NONE, -1) and c.asked == []


@walks
def test_the_band_ends_at_the_first_candidate_out_of_it_and_that_interval_is_asked_again(WALK):
    # banded h (band 0.1 in region +: out of it above 0.2) crosses in interval 5 at 5.5;
    # the section's crossing in interval 1 lies in the band, the one in 5 out of it
    banded = [0.05, 0.1, 0.15, 0.3, 0.3, 0.3, -0.3] + [-0.3] * 5
    sec = [-1.0, -1.0] + [1.0] * 10
    c = Engine({F_LEAVE: _piecewise(banded), F_RATE: lambda t: 0.0,
                F_SECTION: _piecewise(sec)}, TS, band=0.1,
               sections=[(rules.TO_NONNEG, 0.0, False)],
               unbanded=_piecewise([v - 0.1 for v in banded]))
    st, t, what, _ = WALK(c, PLUS)
    # asked again on h unbiased: its root 5 + 0.2 / 0.6
    assert what == rules.SWITCH and abs(t - (5 + 0.2 / 0.6)) < 1e-12
    assert c.unbands == [5]


@walks
def test_a_window_with_no_event_ends_the_band_at_its_last_sample_out_of_it(WALK):
    # no candidate out of the band, but the last sample (11) is: the band ends there,
    # with no sample after it to take again
    rising = [0.05 + 0.05 * k for k in range(12)]
    c = Engine({F_LEAVE: _piecewise(rising), F_RATE: lambda t: 0.0}, TS, band=0.1,
               unbanded=_piecewise(rising))
    assert WALK(c, PLUS) == (OK, math.inf, NONE, -1) and c.unbands == [12]
    # still in the band at the last sample: it stays in force for the next window
    c = Engine({F_LEAVE: lambda t: 0.1, F_RATE: lambda t: 0.0}, TS, band=0.1)
    assert WALK(c, PLUS) == (OK, math.inf, NONE, -1) and c.unbands == []


def test_a_failed_search_stops_the_walk():
    h = [1.0, 1.0, -1.0, -1.0] + [1.0] * 8
    c = Engine({F_LEAVE: _piecewise(h), F_RATE: lambda t: 0.0}, TS, fail=F_LEAVE)
    assert WALKS[0](c, PLUS)[0] == ROOT_FAILED and c.asked == [("root", F_LEAVE)]


def test_a_switch_beyond_the_band_is_refined_again_from_the_first_probe_out_of_it():
    """The root of banded h (band 0.1 in region +: h unbiased is banded h - 0.1) is
    probed back toward the bracket's start (rules.band_probe) to a time out of the band
    (banded h > 0.2, before t = 0.3), and refined again from there on h unbiased: its root
    0.4, not the banded one at 0.5. If no probe after the start clears, r stands."""
    leave_root = interval.make_leave_root(OPS, refine.make_refine(OPS.root, OPS.value),
                                          interval.make_extremum(OPS))
    c = Engine({F_LEAVE: lambda t: 0.5 - t, F_UNBANDED: lambda t: 0.4 - t,
                F_RATE: lambda t: -1.0}, T2, band=0.1)
    st, t = leave_root(c, 0, 0, PLUS, False, 0.1, 0.5, -1.5)
    assert st == OK and abs(t - 0.4) < 1e-12
    assert c.asked == [("root", F_LEAVE), ("root", F_UNBANDED)]
    c = Engine({F_LEAVE: lambda t: 0.15 - t, F_UNBANDED: lambda t: 0.05 - t,
                F_RATE: lambda t: -1.0}, T2, band=0.1)
    st, t = leave_root(c, 0, 0, PLUS, False, 0.1, 0.15, -1.85)
    assert st == OK and abs(t - 0.15) < 1e-12 and c.asked == [("root", F_LEAVE)]


def test_the_walk_is_one_loop_asking_each_question_in_one_place():
    """The kernel inlines every call of an operation (numba, inline="always"): the walk
    asks each question in one place (a touch: sliding or in a region alike), is one loop
    over the intervals (a walk that restarted an inner loop of candidates after each
    interval cost the kernel about 2% of its instructions per return), and its only other
    loops are the questions' own (the leave functions q, the two touches, the sections k):
    docs/decisions.md#kernel-inlined-driver."""
    import inspect
    import textwrap

    tree = ast.parse(textwrap.dedent(inspect.getsource(interval.make_window_event)))
    calls = [node.func.id for node in ast.walk(tree)
             if isinstance(node, ast.Call) and isinstance(node.func, ast.Name)]
    for op in ("candidate", "leave_root", "hidden_end", "touch", "refine", "counts"):
        assert calls.count(op) == 1, op
    for op in ("window", "unband"):
        assert calls.count(op) == 2, op  # at the start and after the band's end
    assert calls.count("asks") == 1
    assert sum(isinstance(node, ast.While) for node in ast.walk(tree)) == 1
    assert sorted(node.target.id for node in ast.walk(tree)
                  if isinstance(node, ast.For)) == ["k", "q", "q", "tm"]


# ------------------------------------------- the search against brute force, drawn at random
from hypothesis import assume, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

SAMPLE = st.floats(-1.0, 1.0, allow_nan=False).filter(lambda v: abs(v) > 1e-3)


def _first_crossing(values, pred):
    """The first sign change ``pred`` of the piecewise-linear function through ``values``
    at t = 0, 1, ... (linear interpolation), or inf."""
    for i in range(len(values) - 1):
        if rules.crosses(pred, values[i], values[i + 1]):
            return i + values[i] / (values[i] - values[i + 1])
    return math.inf


@settings(max_examples=60)
@given(mode=st.sampled_from((PLUS, MINUS, SLIDING)), data=st.data(),
       n=st.integers(2, 9), with_section=st.booleans())
def test_the_search_finds_the_earliest_sign_change_of_piecewise_linear_samples(
        mode, data, n, with_section):
    """On functions linear between their samples (no extremum hidden between two: their
    rates are 0), the walk's event is the earliest sign change that ends the mode (h; a
    or b while sliding) or crosses the section, found by brute force; the walk that skips
    to the reference's candidates and the one that tests every interval agree."""
    leave = [data.draw(st.lists(SAMPLE, min_size=n + 1, max_size=n + 1))
             for _ in range(2 if mode == SLIDING else 1)]
    sec = data.draw(st.lists(SAMPLE, min_size=n + 1, max_size=n + 1))
    funcs = {F_LEAVE + q: _piecewise(v) for q, v in enumerate(leave)}
    funcs.update({F_RATE: lambda t: 0.0, F_RATE + 1: lambda t: 0.0})
    sections = []
    if with_section:
        funcs[F_SECTION] = _piecewise(sec)
        sections = [(rules.TO_NONNEG, 0.0, True)]
    ends = [_first_crossing(v, rules.leave_pred(mode, q)) for q, v in enumerate(leave)]
    hit = _first_crossing(sec, rules.TO_NONNEG) if with_section else math.inf
    first = min(ends)
    assume(abs(hit - first) > 1e-6 or first == hit == math.inf)
    ts = [float(k) for k in range(n + 1)]
    got = [walk(Engine(dict(funcs), ts, sections=sections), mode) for walk in WALKS]
    assert got[0] == got[1]
    st_, t, what, k = got[0]
    assert st_ == OK
    if hit < first:
        assert (what, k) == (SECTION, 0) and abs(t - hit) < 1e-12
    elif first < math.inf:
        assert what == rules.ended_by(mode, ends.index(first)) and abs(t - first) < 1e-12
    else:
        assert (t, what) == (math.inf, NONE)
