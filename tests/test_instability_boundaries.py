"""Where period one, period two and chaos meet past grazing (theta > 0): bifurcation points
of followed periodic orbits (a multiplier through -1), not edges of a basin on a grid.

The border-collision normal form of the return near grazing has the slopes lambda (the
side that misses H) and lambda s(theta,0,0) (the side that slides), s = (theta - 1)/theta:
period one for lambda s > -1, period two for lambda^2 s > -1 > lambda s, chaos below. The
tests check the limit map and the slow-fast system against these thresholds, and the
attractors on both sides of each computed flip independently (attractors.settle).
"""
import numpy as np
import pytest

from filippov import attractors
from filippov.analytic import limit_map
from filippov.models import hopf
from filippov_paper.scenes.fig14_atlas import FLIP_ONE, FLIP_STEP, FLIP_TWO_OUTSIDE, slow_fast_flip

OMEGA = 8 * np.pi
LAM = limit_map.multiplier(1.0, OMEGA)
THETA_ONE, THETA_CHAOS = limit_map.flip_threshold(LAM), limit_map.chaos_threshold(LAM)


def _limit_period(theta, s, eps=1e-3):
    u = limit_map.orbit([s], eps=eps, theta=theta, omega=OMEGA, transient=3000, keep=64)[0]
    return attractors.period_of(u, 1e-9, 32)


def _attractor(eps, theta, s):
    sigma = eps * eps
    mu = 1.0 + s * sigma
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=True)
    return attractors.settle(cm, [0.0, np.sqrt(mu), 0.0], coordinate=1, transient=800,
                             keep=64, t_max=1.0, scale=sigma, max_period=32,
                             window=(0.8, 1.2), lyapunov=True)


def test_the_normal_form_thresholds():
    # lambda = e^{-1/2} at omega = 8 pi: lambda s = -1 at lambda/(1 + lambda) = 0.3775,
    # lambda^2 s = -1 at lambda^2/(1 + lambda^2) = 0.2689
    for theta, slope in ((THETA_ONE, LAM), (THETA_CHAOS, LAM * LAM)):
        assert slope * (theta - 1) / theta == pytest.approx(-1.0, rel=1e-14)
    assert THETA_CHAOS < THETA_ONE < 0.5   # the paper's s = -1 at theta = 1/2 comes first


def test_the_limit_maps_flips_tend_to_the_normal_form_at_grazing():
    # the map is piecewise linear only at the border: its flips move with s, and tend to
    # the normal form's thresholds as s -> 0 like sqrt(s) (P_DM's curve: measured gaps
    # 1.1e-2, 5.5e-3, 2.7e-3 for the flip of period one at s = 1, 1/4, 1/16)
    gaps = []
    for s in (1.0, 0.25, 0.0625):
        one = limit_map.flip_point(s, 1, *FLIP_ONE, eps=1e-3, omega=OMEGA)
        two = limit_map.flip_point(s, 2, one - FLIP_STEP, FLIP_TWO_OUTSIDE, eps=1e-3,
                                   omega=OMEGA)
        gaps.append((THETA_ONE - one, THETA_CHAOS - two))
    gaps = np.array(gaps)
    assert np.all(gaps > 0)
    ratios = gaps[:-1] / gaps[1:]   # s / 4 per row: sqrt(s) halves the gap
    assert np.all((ratios > 1.7) & (ratios < 2.3)), ratios


@pytest.mark.parametrize("s", [0.5, 2.0])
def test_the_limit_maps_attractor_changes_type_at_its_flips(s):
    one = limit_map.flip_point(s, 1, *FLIP_ONE, eps=1e-3, omega=OMEGA)
    two = limit_map.flip_point(s, 2, one - FLIP_STEP, FLIP_TWO_OUTSIDE, eps=1e-3, omega=OMEGA)
    assert _limit_period(one + 0.005, s) == 1
    assert _limit_period(one - 0.005, s) == 2
    assert _limit_period(two + 0.005, s) == 2
    assert _limit_period(two - 0.01, s) not in (1, 2)   # chaos (or its windows)
    # the paper's condition and lambda s = -1 alone: a period-two band lies between
    # lambda s = -1 and the chaos, so lambda s < -1 is not the chaos threshold
    assert _limit_period(0.5 * (one + two), s) == 2


def test_the_slow_fast_flips_are_bifurcations_of_its_attractor():
    eps, s = 1e-3, 1.0
    one = slow_fast_flip(hopf, eps, s, 1, OMEGA, *FLIP_ONE)
    two = slow_fast_flip(hopf, eps, s, 2, OMEGA, one - FLIP_STEP, FLIP_TWO_OUTSIDE)
    assert THETA_CHAOS - 0.03 < two < one < THETA_ONE + 0.03
    above, between, below = (_attractor(eps, th, s) for th in (one + 0.005,
                                                               0.5 * (one + two), two - 0.01))
    assert above.period == 1 and above.lyapunov < 0
    assert between.period == 2 and between.lyapunov < 0
    assert below.period not in (1, 2) and below.lyapunov > 0 and not below.escaped


def test_the_slow_fast_flips_approach_the_limit_maps_like_eps():
    # the distance to the limit map's flips, fitted over three eps: exponent ~1 (the
    # corrections of the slow-fast return are O(eps) on the eps^2 scale)
    s, eps = 1.0, np.array([1e-2, 3e-3, 1e-3])
    for n in (1, 2):
        gaps = []
        for e in eps:
            lim1 = limit_map.flip_point(s, 1, *FLIP_ONE, eps=e, omega=OMEGA)
            sf1 = slow_fast_flip(hopf, e, s, 1, OMEGA, *FLIP_ONE)
            if n == 1:
                gaps.append(sf1 - lim1)
            else:
                lim2 = limit_map.flip_point(s, 2, lim1 - FLIP_STEP, FLIP_TWO_OUTSIDE, eps=e,
                                            omega=OMEGA)
                gaps.append(slow_fast_flip(hopf, e, s, 2, OMEGA, sf1 - FLIP_STEP,
                                           FLIP_TWO_OUTSIDE) - lim2)
        gaps = np.array(gaps)
        assert np.all(gaps > 0)
        k, _ = np.polyfit(np.log(eps), np.log(gaps), 1)
        assert k == pytest.approx(1.0, abs=0.15)
