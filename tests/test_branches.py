"""branches.follow on maps whose bifurcations are known in closed form: a flip, a fold,
a border collision, an orbit stable to the end of the range, and a Newton that fails a
step ahead although the orbit is there (the follower must not take that for an end)."""
import numpy as np
import pytest

from filippov import branches


def _logistic(r, guess):
    # x' = r x (1 - x): fixed point 1 - 1/r, multiplier 2 - r: flip at r = 3
    x = 1.0 - 1.0 / r
    return branches.Orbit(np.array([x]), x, complex(2.0 - r), ())


def _saddle_node(r, guess):
    # x' = x + r - x^2: stable fixed point sqrt(r) (multiplier 1 - 2 sqrt(r)) for
    # 0 < r < 1, none for r < 0: a fold at r = 0
    if r < 0:
        raise ValueError("no fixed point")
    x = np.sqrt(r)
    return branches.Orbit(np.array([x]), x, complex(1.0 - 2.0 * x), ())


def _border(mu, guess):
    # x' = 0.5 x + mu for x < 0, -0.5 x + mu for x >= 0: the fixed point 2 mu (mu < 0)
    # reaches the border x = 0 at mu = 0 and continues as 2 mu / 3 on the other piece
    x = 2.0 * mu if mu < 0 else 2.0 * mu / 3.0
    return branches.Orbit(np.array([x]), x, complex(0.5 if x < 0 else -0.5), (x >= 0,))


def test_a_flip_is_found_at_the_multiplier_minus_one():
    end = branches.follow(_logistic, 2.5, [0.6], 3.5, step=0.1, xtol=1e-10, near=1.0)
    assert end.kind == branches.FLIP
    assert end.parameter == pytest.approx(3.0, abs=1e-9)
    assert end.inside.multiplier.real == pytest.approx(-1.0, abs=1e-9)


def test_a_fold_is_found_where_the_orbit_disappears_with_multiplier_one():
    end = branches.follow(_saddle_node, 0.2, [0.4], -0.5, step=0.03, xtol=1e-12, near=1.0)
    assert end.kind == branches.FOLD
    assert end.parameter == pytest.approx(0.0, abs=1e-11)


def test_a_border_collision_is_a_change_of_itinerary():
    end = branches.follow(_border, -0.5, [-1.0], 0.5, step=0.07, xtol=1e-12, near=1.0)
    assert end.kind == branches.BORDER
    assert end.parameter == pytest.approx(0.0, abs=1e-11)
    assert "itinerary" in end.outside


def test_an_orbit_stable_to_the_limit_has_no_edge():
    end = branches.follow(_logistic, 2.0, [0.5], 2.9, step=0.1, xtol=1e-10, near=1.0)
    assert end.kind == branches.BEYOND and np.isnan(end.parameter)


def test_newton_failing_from_a_far_guess_is_not_the_end():
    # the orbit exists up to r = 3, but "Newton" fails when the guess is more than 0.01
    # away from the fixed point: the follower must retry from next to it and go on
    def picky(r, guess):
        o = _logistic(r, guess)
        if abs(o.value - float(np.asarray(guess)[0])) > 0.01:
            raise RuntimeError("Newton diverged")
        return o
    end = branches.follow(picky, 2.5, [0.6], 3.5, step=0.1, xtol=1e-10, near=1.0)
    assert end.kind == branches.FLIP
    assert end.parameter == pytest.approx(3.0, abs=1e-9)


def test_a_start_that_is_not_stable_is_refused():
    with pytest.raises(branches.BranchError, match="not stable"):
        branches.follow(_logistic, 3.2, [0.6], 4.0, step=0.1, xtol=1e-10, near=1.0)
    with pytest.raises(ValueError, match="step"):
        branches.follow(_logistic, 2.5, [0.6], 3.5, step=0.0, xtol=1e-10, near=1.0)
