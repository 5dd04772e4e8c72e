"""The refinement of a sign change (filippov.loop.refine), written once: its four cases
on scripted operations, and both engines running the one function."""
from __future__ import annotations

import importlib
import math

from filippov import rules
from filippov.loop.refine import make_refine
from filippov.loop.status import CUT, OK, ROOT_FAILED


class Script:
    """f on a scripted table {t: value} (a linear f elsewhere: t - root); the engine's
    root finder returns ``root`` (not ok when ``bracket`` is False); ``asked`` the times
    f was evaluated at, ``lost`` the calls of the root finder with the samples' values
    handed (a bracket f at the ends lost)."""

    def __init__(self, values=None, root=1.0, bracket=True, pinned=None):
        self.values, self.root, self.bracket, self.pinned = values or {}, root, bracket, pinned
        self.asked, self.lost = [], []

    def f(self, t):
        self.asked.append(t)
        return self.value(t)

    def value(self, t):  # (not recorded: what a root finder that fails evaluated last)
        return self.values.get(t, t - self.root)


def _script_root(c, f, ta, tb, va, vb, mode):
    if math.isnan(va):  # a bracket of f's own
        return (c.bracket, c.root, f(c.root)) if c.bracket else (False, ta, c.value(ta))
    c.lost.append((ta, tb, va, vb))
    return (True, c.pinned, f(c.pinned)) if c.pinned is not None else (False, ta, c.value(ta))


REFINE = make_refine(root=_script_root, value_at=lambda c, f, t, mode: f(t))


def test_a_sample_exactly_zero_is_the_crossing():
    c = Script(values={0.5: 0.0})
    assert REFINE(c, c.f, rules.TO_NONNEG, 0.5, 2.0, 0.0, 1.0, None) == (OK, 0.5)
    assert c.asked == [0.5] and c.lost == []  # no root finder asked
    # a section without direction (EITHER) takes the far side of the crossing at hand
    c = Script(values={0.5: 0.0})
    assert REFINE(c, c.f, rules.EITHER, 0.5, 2.0, 0.0, 1.0, None) == (OK, 0.5)


def test_the_root_is_walked_to_the_far_side_of_the_crossing():
    # the root finder stops a hair before the sign flips: f(1.0) = -1e-17 < 0 (near side
    # of TO_NONNEG); the probe walks forward until f is past it
    c = Script(values={1.0: -1e-17})
    st, r = REFINE(c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1.0, 1.0, None)
    assert st == OK and r > 1.0 and r - 1.0 < 1e-12 and c.f(r) >= 0.0
    assert c.asked[0] == 1.0 and c.lost == []
    # already past: the root stands, f evaluated there only (the finder's own value)
    c = Script()
    assert REFINE(c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1.0, 1.0, None) == (OK, 1.0)
    assert c.asked == [1.0]


def test_a_lost_bracket_with_the_start_already_past_is_an_event_at_once():
    # the start sample was clamped inside (va < 0) while f(ta) is past the crossing
    c = Script(values={0.0: 1e-18}, bracket=False)
    assert REFINE(c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1e-300, 1.0, None) == (OK, 0.0)
    assert c.lost == [] and c.asked == [0.0]


def test_a_lost_bracket_otherwise_is_the_engines_to_answer():
    c = Script(values={0.0: -1e-18}, bracket=False, pinned=1.25)  # the reference pins
    assert REFINE(c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1.0, 3.0, None) == (OK, 1.25)
    assert c.lost == [(0.0, 2.0, -1.0, 3.0)]
    c = Script(values={0.0: -1e-18}, bracket=False)  # the kernel fails
    st, _ = REFINE(c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1.0, 3.0, None)
    assert st == ROOT_FAILED and len(c.lost) == 1


def test_a_value_not_finite_met_while_refining_is_a_cut_there():
    # the root finder met f not finite (it hands its time and NaN): CUT at that time,
    # nothing more asked; the same where the walk to the far side meets it
    def nan_root(c, f, ta, tb, va, vb, mode):
        return False, 0.75, math.nan
    c = Script()
    assert make_refine(nan_root, lambda c, f, t, mode: f(t))(
        c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1.0, 1.0, None) == (CUT, 0.75)
    assert c.asked == []
    c = Script(values={1.0: -1e-17})
    c.values.update({t: math.nan for t in (1.0 + 2.0 ** -52, 1.0 + 2.0 ** -51)})
    st, r = REFINE(c, c.f, rules.TO_NONNEG, 0.0, 2.0, -1.0, 1.0, None)
    assert st == CUT and 1.0 < r < 1.0 + 1e-12 and math.isnan(c.value(r))


def test_both_engines_refine_with_the_one_function():
    """Each engine's event search refines with the loop's refinement, built by the loop
    (loop.interval.make_window_event) on the engine's root finder."""
    simulate = importlib.import_module("filippov.simulate")
    from filippov.kernel import scan

    for walk, ops in ((simulate._window_event, simulate.WINDOW_OPERATIONS),
                      (scan._window_event.py_func, scan.WINDOW_OPERATIONS)):
        cells = {name: cell.cell_contents
                 for name, cell in zip(walk.__code__.co_freevars, walk.__closure__)}
        refine = getattr(cells["refine"], "py_func", cells["refine"])
        assert refine.__code__ is make_refine(None, None).__code__
        inner = {cell.cell_contents for cell in refine.__closure__}
        assert ops.root in inner and ops.value in inner


def _reference_refine(fun, pred, ta, tb, va, vb, xtol):
    """The loop's refinement on the reference's root finder (scipy's brentq)."""
    simulate = importlib.import_module("filippov.simulate")
    refine = make_refine(lambda c, f, lo, hi, vlo, vhi, mode: simulate._root(
                             xtol, f, lo, hi, vlo, vhi),
                         lambda c, f, t, mode: f(t))
    return refine(None, fun, pred, ta, tb, va, vb, None)[1]


def test_the_reference_refines_a_crossing_to_its_far_side():
    """The reference's operations (scipy's brentq) through the shared function."""
    root = 0.1 + 0.2  # not exactly representable: brentq stops on either side of it
    r = _reference_refine(lambda t: t - root, rules.TO_NONNEG, 0.0, 1.0, -root, 1.0 - root,
                          1e-12)
    assert r - root >= 0.0 and r - root < 1e-11
    r = _reference_refine(lambda t: root - t, rules.TO_NEG, 0.0, 1.0, root, root - 1.0, 1e-12)
    assert root - r < 0.0 and r - root < 1e-11
