"""The small-scale instabilities the paper announces, computed from the slow-fast Hopf
example (exact flows, compiled engine) and tested claim by claim; the scenes
fig12_period_adding and fig13_small_scale_chaos show the same on finer grids."""
import numpy as np
import pytest

from filippov import attractors
from filippov.analytic import limit_map
from filippov.models import hopf

OMEGA = 8 * np.pi
T_RETURN = 1.0


def _attractor(eps, theta, s, *, transient=200, keep=60, lyapunov=False, window=0.2):
    sigma = limit_map.scale(eps, theta)
    mu = 1.0 + s * sigma
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=theta > 0)
    return attractors.settle(cm, [0.0, np.sqrt(mu), 0.0], coordinate=1, transient=transient,
                             keep=keep, t_max=T_RETURN, scale=sigma, max_period=30,
                             window=(1 - window, 1 + window), lyapunov=lyapunov)


def _limit_period(s, eps, theta, order):
    u = limit_map.orbit([s], eps=eps, theta=theta, omega=OMEGA, transient=200, keep=60,
                        order=order)[0]
    return attractors.period_of(u, 1e-4, 30)


@pytest.mark.parametrize("s", [-0.5, -0.1])
def test_below_grazing_the_cycle_is_the_attractor(s):
    # theta < 0, mu < 1: the fixed point of P is the Hopf cycle's x2 = sqrt(mu)
    eps = 1e-3
    at = _attractor(eps, -0.5, s)
    assert at.period == 1 and not at.escaped
    assert at.values[-1] == pytest.approx(np.sqrt(1 + s * eps), abs=1e-12)


def test_above_grazing_periods_fall_as_mu_grows_in_an_inverted_adding_cascade():
    # theta = -0.5, eps = 1e-5: just above mu = 1 the period-one orbit is gone; the
    # period falls n -> n - 1 as s = (mu - 1)/eps grows, and between the windows of
    # n and n - 1 lies one of period 2n - 1 (the adding: n + (n - 1))
    eps = 1e-5
    periods = [_attractor(eps, -0.5, s).period for s in (0.05, 0.2, 0.35, 0.7, 1.5)]
    assert periods[0] > 5 and periods[1:] == [5, 4, 3, 2]
    # between the windows of 3 and 2 (order-0 limit map): 3 + 2 = 5, and between 3 and
    # 5 the window of 3 + 5 = 8, between 5 and 2 that of 5 + 2 = 7, in this order
    between = [_limit_period(s, eps, -0.5, 0) for s in np.linspace(0.80, 1.05, 26)]
    order = [between.index(p) for p in (3, 8, 5, 7, 2)]
    assert order == sorted(order)


def test_window_edges_converge_in_s_left_like_eps_right_like_sqrt_eps():
    # the first window of period 3 at theta = -0.5: its edges in s = (mu - 1)/eps
    # tend to those of the eps -> 0 limit map; the left edge (an orbit point reaching
    # grazing from the side the sqrt term does not act on) with O(eps) corrections,
    # the right one with O(sqrt(eps)) corrections
    grid = np.linspace(0.3, 2.0, 35)
    def edges(classify):
        per = np.array([classify(s) for s in grid])
        return np.array(attractors.window_edges(grid, per, 3, classify, 1e-5))
    limit = edges(lambda s: _limit_period(s, 1e-6, -0.5, 0))
    err = {}
    for eps in (1e-4, 1e-6):
        err[eps] = np.abs(edges(lambda s, e=eps: _attractor(e, -0.5, s).period) - limit)
    ratio = err[1e-4] / err[1e-6]
    assert 30 < ratio[0] < 300   # ~eps: a factor 100 over two decades
    assert 5 < ratio[1] < 20     # ~sqrt(eps): a factor 10
    assert err[1e-6][1] < 0.05


def test_the_slow_fast_map_agrees_with_the_limit_map_better_as_eps_shrinks():
    # theta = -0.5, s = 1: the attractor's points against the order-1 limit map
    gaps = []
    for eps in (1e-4, 1e-6):
        at = _attractor(eps, -0.5, 1.0)
        u = np.sort((at.values[-at.period:] - 1) / eps)
        lim = limit_map.orbit([1.0], eps=eps, theta=-0.5, omega=OMEGA, transient=200, keep=60)[0]
        assert attractors.period_of(lim, 1e-4, 30) == at.period
        gaps.append(np.abs(u - np.sort(lim[-at.period:])).max())
    assert gaps[1] < gaps[0] / 30 and gaps[1] < 5e-4  # measured 7.9e-3 -> 1.1e-4


@pytest.mark.parametrize("theta", [0.7, 0.5, 0.4])
def test_theta_positive_with_contracting_return_keeps_period_one_through_grazing(theta):
    # lambda s(theta,0,0) > -1 (lambda = exp(-4 pi/omega), s = (theta - 1)/theta): at
    # theta = 0.4 the paper's condition s < -1 holds, yet the whole return contracts
    lam = limit_map.multiplier(1.0, OMEGA)
    assert lam * (theta - 1) / theta > -1
    for s in (0.5, 2.0, 4.0):
        at = _attractor(1e-4, theta, s, lyapunov=True)
        assert at.period == 1 and at.lyapunov < 0


@pytest.mark.parametrize("theta", [0.2, 0.1])
@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
def test_small_theta_is_chaotic_on_the_eps_squared_scale(theta, eps):
    at = _attractor(eps, theta, 2.0, transient=300, keep=100, lyapunov=True)
    assert at.period == 0 and at.lyapunov > 0.1 and not at.escaped
    assert 0.2 < at.width / eps ** 2 < 20   # O(eps^2) in x2


def test_the_chaotic_attractor_shrinks_like_eps_squared():
    w = {eps: _attractor(eps, 0.2, 1.0, transient=300, keep=200).width for eps in (1e-3, 1e-4)}
    k = np.log10(w[1e-3] / w[1e-4])
    assert k == pytest.approx(2.0, abs=0.15)


def test_hard_cases_grazing_itself_tiny_eps_and_escape():
    # mu exactly 1, from the grazing orbit itself: a point, no NaN
    for theta in (-0.5, 0.2):
        at = _attractor(1e-3, theta, 0.0)
        assert at.period == 1 and np.all(np.isfinite(at.values))
    # eps = 1e-5, theta = 0.2: still chaotic on the eps^2 scale (x2 - 1 ~ 1e-10)
    at = _attractor(1e-5, 0.2, 2.0, transient=200, keep=80, lyapunov=True)
    assert at.period == 0 and at.lyapunov > 0.1 and 0.2 < at.width / 1e-10 < 20
    # eps = 1e-6: the eps^2 scale (1e-12) is below what double precision resolves on
    # x2 ~ 1 (returns carry ~1e-14): refused with the reason, not answered
    with pytest.raises(ValueError, match="below what double precision resolves"):
        _attractor(1e-6, 0.2, 2.0)
    # theta < 0 at eps = 1e-6 (scale eps) is fine: the cascade's period-3 window
    assert _attractor(1e-6, -0.5, 0.7).period == 3
    # a window the attractor leaves is an escape with its reason, not numbers
    at = _attractor(1e-2, 0.2, 3.0, window=1e-5)
    assert at.escaped and "left the window" in at.reason and np.isnan(at.width)
