"""The small-scale instabilities the paper announces, computed from the slow-fast Hopf
example (exact flows, compiled engine) and tested claim by claim; the scenes
fig12_period_adding and fig13_small_scale_chaos show the same on finer grids."""
import numpy as np
import pytest

from filippov import attractors, branches
from filippov.fastmap import compute_returns
from filippov_paper.scenes import fig12_period_adding as fig12
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


def _window(eps, n, s0, order=None):
    """(left end, right end) of the period-n orbit followed from s0 (branches.follow):
    slow-fast for order None, else the limit map of that order."""
    if order is None:
        at = fig12._slow_fast_orbit_at(hopf, {"omega": OMEGA}, -0.5, eps, n, {})
        guess = _attractor(eps, -0.5, s0, transient=400).states[-1]
    else:
        at = fig12._limit_orbit_at(-0.5, eps, OMEGA, n, order)
        guess = limit_map.orbit([s0], eps=eps, theta=-0.5, omega=OMEGA, transient=400,
                                keep=1, order=order)[0]
    return [branches.follow(at, s0, guess, lim, step=0.025, xtol=1e-9, near=0.5)
            for lim in (-0.5, 4.0)]


def test_past_the_window_of_two_the_periods_rise_until_period_one_is_back():
    # theta = -0.5, eps = 1e-5 (fig12): 2 -> 3 -> 4 -> back to 1 as s grows past the
    # window of period two; at eps = 1e-3 the window of two still holds at s = 3.9
    periods = [_attractor(1e-5, -0.5, s, transient=400).period for s in (1.5, 2.3, 2.6, 3.0)]
    assert periods == [2, 3, 4, 1]
    assert _attractor(1e-3, -0.5, 3.9, transient=400).period == 2


def test_window_edges_converge_in_s_left_like_eps_right_like_sqrt_eps():
    # the window of period 3 at theta = -0.5: its edges in s = (mu - 1)/eps, where its
    # orbit followed in s stops being stable, tend to those of the eps -> 0 limit map;
    # the left edge with O(eps) corrections, the right one with O(sqrt(eps))
    limit = np.array([e.parameter for e in _window(1e-6, 3, 0.7, order=0)])
    err = {eps: np.abs([e.parameter for e in _window(eps, 3, 0.7)] - limit)
           for eps in (1e-4, 1e-6)}
    ratio = err[1e-4] / err[1e-6]
    assert 30 < ratio[0] < 300   # ~eps: a factor 100 over two decades (measured 98)
    assert 5 < ratio[1] < 20     # ~sqrt(eps): a factor 10 (measured 11.3)
    assert err[1e-6][1] < 0.05


def test_window_edges_are_a_period_doubling_and_a_border_collision():
    # eps = 1e-3, period 3: the left end has the multiplier -1; at the right end one
    # orbit point sits where a single return's number of switches changes (grazing),
    # found here by bisection in u on the engine's switch count, not by the follower
    eps = 1e-3
    left, right = _window(eps, 3, 1.5)
    assert left.kind == branches.FLIP
    assert left.inside.multiplier.real == pytest.approx(-1.0, abs=1e-3)
    assert right.kind == branches.BORDER and abs(right.inside.multiplier) < 0.5
    mu = 1.0 + right.parameter * eps
    cm = hopf.compiled(eps, -0.5, mu, OMEGA, sliding=False)
    run = attractors.iterate(cm, right.inside.state, transient=0, keep=3, t_max=T_RETURN)
    u = (run.orbit[0, :, 1] - 1.0) / eps

    def switches(v):
        out = compute_returns(cm, [[0.0, 1.0 + eps * v, 0.0]], T_RETURN)
        return int(out.n_switches[0])
    lo, hi = -1.5, 0.5   # a bracket of u with 0 switches at one end and 2 at the other
    a, b = lo, hi
    assert switches(a) != switches(b)
    while b - a > 1e-9:
        m = 0.5 * (a + b)
        if switches(m) == switches(a):
            a = m
        else:
            b = m
    graze = 0.5 * (a + b)
    assert np.min(np.abs(u - graze)) < 1e-5, (u, graze)


def test_two_windows_orbits_coexist_where_the_followed_branches_overlap():
    # eps = 1e-3: the period-2 orbit is stable down to its flip, below the border
    # collision that ends the period-3 orbit; between them a run from each orbit's point
    # stays on it (two attractors), while the cycle's start sees only one
    eps = 1e-3
    two_left, _ = _window(eps, 2, 3.0)
    _, three_right = _window(eps, 3, 1.5)
    assert two_left.parameter < three_right.parameter - 0.1
    s = 0.5 * (two_left.parameter + three_right.parameter)
    mu = 1.0 + s * eps
    cm = hopf.compiled(eps, -0.5, mu, OMEGA, sliding=False)
    periods = []
    for n, start in ((2, 3.0), (3, 1.5)):
        at = fig12._slow_fast_orbit_at(hopf, {"omega": OMEGA}, -0.5, eps, n, {})
        end = branches.follow(at, start, _attractor(eps, -0.5, start, transient=400)
                              .states[-1], s, step=0.025, xtol=1e-9, near=0.5)
        assert end.kind == branches.BEYOND   # still stable at s
        # perturb the orbit's point a little and let the map settle
        z = end.inside.state + np.array([0.0, 1e-3 * eps, 0.0])
        got = attractors.settle(cm, z, coordinate=1, transient=300, keep=60, t_max=T_RETURN,
                                scale=eps, max_period=30, window=(0.8, 1.2))
        periods.append(got.period)
    assert periods == [2, 3]


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


@pytest.mark.parametrize("eps", [1e-3, 1e-4])
def test_inside_the_band_of_period_two_the_attractor_has_period_two(eps):
    # theta = 0.3: lambda^2/(1 + lambda^2) < theta < lambda/(1 + lambda) (the normal
    # form's band of period two past grazing); a confirmed, stable period-two orbit
    lam = limit_map.multiplier(1.0, OMEGA)
    assert limit_map.chaos_threshold(lam) < 0.3 < limit_map.flip_threshold(lam)
    for s in (0.5, 2.0, 4.0):
        at = _attractor(eps, 0.3, s, transient=300, keep=100, lyapunov=True)
        assert at.period == 2 and at.cycle.radius < 1.0, (s, at.period)


def test_the_chaos_ends_at_smaller_s_as_eps_shrinks():
    # theta = 0.2: at s = 70.7 (fig13's geometric grid) the attractor is chaotic at
    # eps = 1e-3 (an exponent above three standard errors) but periodic at eps = 1e-5,
    # where the chaos ended by s = 18.8: the chaotic range is not one multiple of eps^2
    def chaotic(eps, s):
        at = _attractor(eps, 0.2, s, transient=300, keep=100, lyapunov=True)
        return at.period == 0 and at.lyapunov > attractors.LYAPUNOV_SIGMAS * at.lyapunov_err
    assert chaotic(1e-3, 70.71067811865474)
    assert not chaotic(1e-5, 70.71067811865474)
    assert not chaotic(1e-5, 18.80301546543197)
    assert chaotic(1e-5, 5.0)


def test_width_exponents_are_fitted_over_three_eps_with_their_error():
    from filippov_paper.scenes.fig13_small_scale_chaos import width_exponents
    eps = np.array([1e-2, 1e-3, 1e-4, 1e-5])
    fitted = eps <= 1e-3
    w = np.array([3.0, 2.0, 1.0])[None, None, :] * eps[None, :, None] ** 2
    w[0, 2, 1] *= 1.1                                   # one width off by 10%
    chaos = np.ones((1, 4, 3), dtype=np.int32)
    chaos[0, 3, 2] = 0                                  # periodic at eps = 1e-5 here
    k, err = width_exponents(w, chaos, fitted, eps)
    assert k[0, 0] == pytest.approx(2.0) and err[0, 0] == pytest.approx(0.0, abs=1e-12)
    assert abs(k[0, 1] - 2.0) < 0.03 and err[0, 1] > 0.01
    assert np.isnan(k[0, 2]) and np.isnan(err[0, 2])   # not chaotic at every fitted eps
    k2, _ = width_exponents(w, chaos, eps <= 1e-4, eps)  # two eps: no fit
    assert np.all(np.isnan(k2))


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


@pytest.mark.parametrize("order", [0, 1])
def test_the_limit_maps_of_many_parameters_at_once_are_each_ones_bit_for_bit(order):
    # limit_map.orbits iterates all (theta, eps) of a scene in one array (fig12-fig14's
    # limit diagrams); each point must get exactly what orbit() gives it alone
    s = np.linspace(-1.0, 5.0, 7)
    thetas, eps = [-0.5, 0.3, -0.1, 0.7], [1e-2, 1e-3]
    kw = dict(omega=OMEGA, transient=30, keep=5, order=order)
    together = limit_map.orbits(s, thetas, eps, **kw)
    assert together.shape == (4, 2, 7, 5)
    for i, th in enumerate(thetas):
        for j, e in enumerate(eps):
            alone = limit_map.orbit(s, eps=e, theta=th, **kw)
            assert together[i, j].tobytes() == alone.tobytes(), (th, e)
    with pytest.raises(ValueError, match="boundary between the two cases"):
        limit_map.orbits(s, [0.3, 0.0], eps, **kw)
    with pytest.raises(ValueError, match="one sign per call"):
        limit_map.step(np.zeros(2), np.zeros(2), eps=1e-3, theta=np.array([-0.5, 0.5]),
                       omega=OMEGA)
