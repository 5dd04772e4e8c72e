"""Orbits that run into an accumulation point of switches stop with a ZenoError that names
it (issue 57, 3), on both engines, against closed forms.

The invisible two-fold: H = {w = 0}, f+ = (-1, -1, x) above (its fold line x = 0, the
orbits bending back down), f- = (2, 1, y) below (fold line y = 0, bending back up). A
crossing orbit from (x, y) on H makes a + arc to (-x, y - 2x) and a - arc back, and the
map over one loop is linear: P = [[7, -4], [2, -1]], det 1, eigenvalues 3 -+ 2 sqrt 2.
On the eigenvector of lam = 3 - 2 sqrt 2 = 0.1716, y = (1 + sqrt 2 / 2) x, each loop is
lam times the one before, of duration (2 + 2 (2 - (1 + sqrt 2 / 2))) x, and the loops sum
to t* = that / (1 - lam): the orbit reaches the two-fold in finite time. Rounding grows
by 1/lam each loop against lam: past ten loops it throws the orbit out along the other
eigenvector and both engines came back with a confident O(1) state -- each a different one.

The spiral: f = ((-y, x) - c (x, y)) / r, c = c+ above y = 0 and c- below: the orbit
turns at unit speed with r' = -c, so a half turn takes r from r0 to r0 exp(-c pi) in time
r0 (1 - exp(-c pi)) / c, and the crossings of y = 0 accumulate at the origin.
"""
import importlib
import math

import numpy as np
import pytest

from filippov import FilippovSystem, SimulationError, ZenoError, first_returns, simulate
from filippov import rules

ENGINES = ("reference", "compiled")
LAM = 3.0 - 2.0 * math.sqrt(2.0)


def _two_fold():
    return FilippovSystem(("x", "y", "w"), lambda z, p: np.array([2.0, 1.0, z[1]]),
                          lambda z, p: np.array([-1.0, -1.0, z[0]]),
                          lambda z, p: z[2], lambda z, p: np.array([0.0, 0.0, 1.0]))


def _two_fold_start(s=0.5):
    """A point of the + arc from (1, 1 + sqrt 2 / 2) on H, a time s into it; t* from it."""
    x0, y0 = 1.0, 1.0 + math.sqrt(2.0) / 2.0
    loop = 2.0 * x0 + 2.0 * (2.0 * x0 - y0)
    return [x0 - s, y0 - s, x0 * s - s * s / 2.0], loop / (1.0 - LAM) - s


def _numbers(msg):
    ratio = float(msg.split("lasts ")[1].split(" times")[0])
    t_star = float(msg.split("t* = ")[1].split(" ")[0])
    return ratio, t_star


@pytest.mark.parametrize("engine", ENGINES)
def test_an_invisible_two_fold_is_named_with_its_ratio_and_time(engine):
    z0, t_star = _two_fold_start()
    with pytest.raises(ZenoError, match="accumulate geometrically") as err:
        first_returns(_two_fold(), [z0], lambda z, p: z[0] - 100.0, 20.0, engine=engine)
    ratio, got = _numbers(str(err.value))
    assert ratio == pytest.approx(LAM, rel=1e-5)   # printed to 6 digits
    # the series' sum from the last loops, each located to ~1e-15: t* to ~1e-10
    assert got == pytest.approx(t_star, rel=1e-9)
    # stopped before rounding took over: the last switch is close to the two-fold
    t = float(str(err.value).split("t=")[1].split(",")[0])
    assert 0.0 < t_star - t < 1e-3


def test_simulate_stops_at_the_two_fold_too():
    z0, t_star = _two_fold_start()
    with pytest.raises(ZenoError, match="accumulate geometrically"):
        simulate(_two_fold().python(), z0, 20.0)


def _spiral(c_plus, c_minus):
    def field(c):
        def f(z, p):
            r = np.sqrt(z[0] * z[0] + z[1] * z[1])
            return np.array([(-z[1] - c * z[0]) / r, (z[0] - c * z[1]) / r])
        return f
    return FilippovSystem(("x", "y"), field(c_minus), field(c_plus), lambda z, p: z[1],
                          lambda z, p: np.array([0.0, 1.0]))


@pytest.mark.parametrize("engine", ENGINES)
def test_a_contracting_spiral_is_named_with_its_ratio_and_time(engine):
    cp, cm = 0.1, 0.2
    e_p, e_m = math.exp(-cp * math.pi), math.exp(-cm * math.pi)
    # from (1, 1e-3) (angle th0) up to the negative x axis, then loops (a half turn below,
    # one above) from r1 there, each e_p e_m times the last
    r0, th0 = math.hypot(1.0, 1e-3), math.atan2(1e-3, 1.0)
    r1 = r0 * math.exp(-cp * (math.pi - th0))
    loop = (1.0 - e_m) / cm + e_m * (1.0 - e_p) / cp
    t_star = (r0 - r1) / cp + r1 * loop / (1.0 - e_p * e_m)
    with pytest.raises(ZenoError, match="accumulate geometrically") as err:
        first_returns(_spiral(cp, cm), [[1.0, 1e-3]], lambda z, p: z[0] - 100.0, 50.0,
                      engine=engine)
    ratio, got = _numbers(str(err.value))
    assert ratio == pytest.approx(e_p * e_m, rel=1e-5)
    # integrated (DOP853 at rtol 1e-10 on a field with 1/r) and summed from its last
    # loops: t* to 1e-8 relative
    assert got == pytest.approx(t_star, rel=1e-8)


def _ring(times, zeno_count=64):
    recent = np.empty(zeno_count)
    entries = 0
    for t in times:
        recent[entries % zeno_count] = t
        entries += 1
    return recent, entries, zeno_count


def _series(first, ratio, n, t0=0.0, other=None):
    """Switch times of intervals first, (other,) first * ratio, ... per loop."""
    times, t, d = [t0], t0, first
    for k in range(n):
        dk = d if other is None or k % 2 == 0 else d * other
        t += dk
        times.append(t)
        if k % 2 == 1:
            d *= ratio
    return times


def test_the_rule_sums_a_geometric_series():
    # loops of two intervals (1, then 0.3) shrinking by 0.5: t* = t0 + 1.3 / (1 - 0.5)
    times = _series(1.0, 0.5, 40, other=0.3)
    ratio, t_star = rules.geometric_accumulation(*_ring(times))
    assert ratio == pytest.approx(0.5, rel=1e-12)
    assert t_star == pytest.approx(2.6, rel=1e-12)
    # in a ring that wrapped round (the last loops, 1e-8 long at t = 6.7, carry the
    # rounding of the times: 1e-16 * 6.7 / 1e-8 relative)
    ratio, t_star = rules.geometric_accumulation(*_ring(_series(1.0, 0.7, 100), zeno_count=64))
    assert ratio == pytest.approx(0.7, rel=1e-6)
    assert t_star == pytest.approx(2.0 / 0.3, rel=1e-12)


@pytest.mark.parametrize("times", [
    _series(1.0, 0.5, 8),                      # too few loops to say
    _series(1.0, 0.95, 60),                    # too slow: the span rule's
    list(np.cumsum(0.2 + 0.1 * (-1.0) ** np.arange(60))),   # chatter: steady loops
    list(np.cumsum(1.0 + 0.5 ** np.arange(60))),            # converging to a period
    list(np.cumsum(0.5 ** np.arange(30) * (1 + 0.3 * np.sin(np.arange(30))))),  # unsteady
], ids=["few", "slow", "chatter", "periodic", "unsteady"])
def test_the_rule_leaves_other_series_alone(times):
    ratio, t_star = rules.geometric_accumulation(*_ring(times))
    assert math.isnan(ratio) and math.isnan(t_star)
    recent, entries, count = _ring(times[:-1])
    _, zeno = rules.note_switch(recent, entries, times[-1], count, 1e-10)
    assert not zeno


# -- a slide into a two-fold: the same two fields, starts in their sliding region x < 0 < y.
# On H the sliding field (a F+ - b F-) / (a - b), a = y, b = x, moves L = 3 y - 2 x at the
# rate -1 exactly (L' = -(y - x) / (y - x)), and L = 0 on the sliding region only at the
# two-fold: the slide reaches it at t = 3 y0 - 2 x0, where both fields are tangent to H and
# no Filippov solution goes on uniquely. The compiled engine went on through it to an O(1)
# state; the reference's steps collapsed ('step size too small'), or with DOP853 it asked
# to raise max_events.

@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("start", [(-1.0, 1.5), (-0.5, 0.3), (-1.0, 0.6)])
def test_a_slide_into_a_two_fold_is_named(engine, start):
    x0, y0 = start
    with pytest.raises(SimulationError, match="the slide reached a two-fold") as err:
        first_returns(_two_fold(), [[x0, y0, 0.0]], lambda z, p: z[0] - 100.0, 20.0,
                      engine=engine)
    t = float(str(err.value).split("t=")[1].split(",")[0])
    assert t == pytest.approx(3.0 * y0 - 2.0 * x0, abs=1e-9)


def _slide_into_nan():
    # H = y; F_- = (1, 1) up to x = 0.75 and not finite beyond, F_+ = (1, -1): a slide
    # along y = 0 at speed 1 (a = 1 > 0 > b = -1) into a field that is not finite
    return FilippovSystem(
        ("x", "y", "w"), lambda z, p: np.array([1.0 if z[0] < 0.75 else np.nan, 1.0, 0.0]),
        lambda z, p: np.array([1.0, -1.0, 0.0]), lambda z, p: z[1],
        lambda z, p: np.array([0.0, 1.0, 0.0]))


@pytest.mark.parametrize("engine", ENGINES)
def test_a_slide_into_a_field_that_is_not_finite_is_no_two_fold(engine):
    # the loop names a slide's failure a two-fold only where both fields are tangent to H
    # (loop.stay.make_failed_step); here they are not: the failure stands
    with pytest.raises(SimulationError, match="non-finite") as err:
        first_returns(_slide_into_nan(), [[0.0, 0.0, 0.0]], lambda z, p: z[0] - 100.0, 5.0,
                      engine=engine)
    assert "two-fold" not in str(err.value)


@pytest.mark.parametrize("at_two_fold", [False, True])
def test_the_references_failed_slide_step_is_raised_as_it_failed_unless_at_a_two_fold(
        monkeypatch, at_two_fold):
    # the reference's integration step fails while sliding (its stepper raises): the run
    # gets STEP_FAILED, the loop asks the pieces there, and the reference raises the very
    # exception its stepper raised -- or the two-fold, where both fields are tangent
    from filippov.errors import run_error
    from filippov.loop.status import STEP_FAILED
    sim = importlib.import_module("filippov.simulate")  # the module, not the function
    failure = run_error(STEP_FAILED, 0.0, np.zeros(3), ": the stepper's own failure")
    real = sim._IntegratingStepper.step

    def step(self):
        if self.fun(0.0, np.zeros(3))[1] == 0.0:  # the sliding field (its y-component 0)
            raise failure
        return real(self)
    monkeypatch.setattr(sim._IntegratingStepper, "step", step)
    monkeypatch.setattr(sim.rules, "tangent_to_both", lambda *args: at_two_fold)
    with pytest.raises(SimulationError) as err:
        simulate(_slide_into_nan().python(), [0.0, 0.0, 0.0], 5.0)
    if at_two_fold:
        assert "the slide reached a two-fold" in str(err.value)
        assert "steps collapsed" in str(err.value)
    else:
        assert err.value is failure


@pytest.mark.parametrize("stiff", [True, False], ids=["radau", "dop853"])
def test_simulate_names_the_two_fold_with_either_integrator(stiff):
    with pytest.raises(SimulationError, match="the slide reached a two-fold"):
        simulate(_two_fold().python(), [-1.0, 1.5, 0.0], 10.0, stiff=stiff)


def test_the_two_fold_rule_asks_both_speeds():
    assert rules.at_two_fold(1e-9, -1e-9, 1.0, -1.0)
    assert not rules.at_two_fold(0.0, -1e-3, 1.0, -1.0)   # an ordinary exit
    assert not rules.at_two_fold(1e-3, 0.0, 1.0, -1.0)


def test_a_slide_end_where_both_fields_are_tangent_to_h_is_a_two_fold_in_any_units():
    grad, fm, fp = np.array([0.0, 0.0, 2.0]), np.array([3.0, 4.0, 0.0]), np.array([0.0, 1.0, 0.0])
    # |grad H| |F_-| = 10, |grad H| |F_+| = 2: the shares are cosines
    ONE = np.ones(3)
    assert rules.tangent_to_both(9e-6, -1.9e-6, grad, fm, fp, ONE, 1.0)
    assert not rules.tangent_to_both(1.1e-5, 0.0, grad, fm, fp, ONE, 1.0)   # F_- not tangent
    assert not rules.tangent_to_both(0.0, 2.1e-6, grad, fm, fp, ONE, 1.0)   # F_+ not tangent
    for k in (1e-3, 1e3):  # H, and with it a and b, in other units
        assert rules.tangent_to_both(9e-6 * k, -1.9e-6 * k, grad * k, fm, fp, ONE, 1.0)
        assert not rules.tangent_to_both(1.1e-5 * k, 0.0, grad * k, fm, fp, ONE, 1.0)
    # a component in other units (z_1 = D y_1): its scale D keeps the cosines
    for D in (1e-9, 1e9):
        T, s = np.array([1.0, D, 1.0]), np.array([1.0, D, 1.0])
        floor = s.max()
        assert rules.tangent_to_both(9e-6, -1.9e-6, grad / T, fm * T, fp * T, s, floor)
        assert not rules.tangent_to_both(1.1e-5, 0.0, grad / T, fm * T, fp * T, s, floor)
