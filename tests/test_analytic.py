"""The paper's closed forms: s0(theta) both ways, and the chatter orbit (with its slip)."""
import numpy as np
import pytest

from filippov import simulate
from filippov.analytic import chatter, s0
from filippov.models import pseudo_equilibrium
from filippov.system import PLUS


def test_s0_lambert_and_root_agree():
    theta = -np.geomspace(1e-3, 5, 300)
    a, b = s0.s0_lambert(theta), s0.s0_root(theta)
    assert np.max(np.abs(a - b)) <= 1e-12
    assert np.all(b > -theta)  # the paper's bound s0 > -theta
    assert np.max(np.abs(s0.residual(b, theta))) < 1e-14


def test_s0_small_theta_limit():
    # expanding eq:s0def: s0 = -2 theta / (1 - theta) + O(theta^2)
    th = -1e-3
    assert s0.s0_root(np.array([th]))[0] == pytest.approx(-2 * th / (1 - th), rel=2e-3)


def test_s0_rejects_nonnegative_theta():
    with pytest.raises(ValueError, match="theta"):
        s0.s0_lambert(np.array([0.1]))


@pytest.mark.parametrize("theta,eps", [(-0.5, 0.1), (-2.0, 0.01), (-0.1, 0.05)])
def test_chatter_orbit_matches_solver(theta, eps):
    f = chatter.orbit(eps, theta)
    system = pseudo_equilibrium.model(eps, theta).full()
    traj = simulate(system, [f["x_switch"], f["y_switch"]], 1.5 * f["period"])
    ups = [e for e in traj.switches() if e.mode_after == PLUS]
    assert ups[0].t == pytest.approx(f["period"], rel=1e-12)
    np.testing.assert_allclose(ups[0].state, [f["x_switch"], f["y_switch"]], rtol=1e-11, atol=1e-15)


def test_chatter_orbit_is_attracting_from_far_away():
    theta, eps = -0.5, 0.1
    f = chatter.orbit(eps, theta)
    traj = simulate(pseudo_equilibrium.model(eps, theta).full(), [0.6, 0.3], 8.0)
    ups = [e for e in traj.switches() if e.mode_after == PLUS]
    assert ups[-1].t - ups[-2].t == pytest.approx(f["period"], rel=1e-10)


def test_printed_theta_formula_is_off_by_tanh():
    # the printed theta(T) is -theta tanh(T/2); y_switch as printed is right
    T = np.linspace(0.1, 8, 50)
    theta = chatter.theta_of_T(T)
    np.testing.assert_allclose(chatter.theta_of_T_as_printed(T), -theta * np.tanh(T / 2), rtol=1e-12, atol=1e-15)
    assert np.all(chatter.theta_of_T_as_printed(T) > 0) and np.all(theta < 0)


def test_s0_of_one_theta_is_the_array_value_and_still_checked():
    # s0_lambert memoizes a scalar theta (the limit maps ask for it at every return):
    # the same bits and type as the array path, and a bad theta is refused every time
    thetas = np.array([-2.0, -0.5, -0.1, -1e-9])
    array = s0.s0_lambert(thetas)
    for k, th in enumerate(thetas):
        for value in (float(th), th):   # a Python float and numpy's
            one = s0.s0_lambert(value)
            assert type(one) is np.float64 and one.tobytes() == array[k].tobytes()
    for bad in (0.5, float("nan"), float("nan")):
        with pytest.raises(ValueError, match="theta must be finite and < 0"):
            s0.s0_lambert(bad)
