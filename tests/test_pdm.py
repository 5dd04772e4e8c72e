"""The discontinuity map P_DM of the slow-fast Hopf example (lemma thm:pdm, appendix):
numerical map by the solver against the asymptotic formulas."""
import numpy as np
import pytest

from filippov.analytic import pdm as asym
from filippov.analytic.s0 import s0_lambert
from filippov.models import hopf
from filippov.pdm import discontinuity_map, l2_x2, scale_for

OMEGA = 8 * np.pi
OPTS = dict(rtol=1e-12, atol=1e-16)


def pdm(eps, theta, xi):
    model = hopf.model(eps, theta, 1.0, OMEGA)
    return discontinuity_map(model, np.asarray(xi, float), sliding=theta > 0, **OPTS)


# ----------------------------------------------------------------------------- both cases
def test_l2_is_where_x1_has_its_minimum():
    x1 = -1 + np.array([-1e-2, -1e-5, 0.0, 1e-3])
    x2 = l2_x2(x1, 1.0, OMEGA)
    f1 = hopf.hopf_rhs(x1, x2, 1.0, OMEGA)[0]
    assert np.all(np.abs(f1) < 1e-14)
    assert np.all(np.abs(x2) < 1e-3)


@pytest.mark.parametrize("theta, eps", [(-0.5, 1e-2), (-0.5, 1e-4), (-0.5, 1e-6),
                                        (0.5, 1e-2), (0.5, 1e-3), (0.5, 1e-4)])
def test_identity_for_nonnegative_xi1(theta, eps):
    xi = [0.0, 1e-3, 0.5, 2.0]
    r = pdm(eps, theta, xi)
    assert np.all(r.n_switches == 0)
    # the bound is the rounding of x1 near -1 (2.2e-16) seen in the scaled coordinate
    tol = max(1e-9, 4.5e-16 / r.scale)
    assert np.max(np.abs(r.P - r.xi1)) <= tol
    assert np.max(np.abs(r.P - r.xi1)) * r.scale <= 4.5e-16
    assert np.array_equal(r.P, r.P_flow)


def test_scale():
    assert scale_for(1e-3, -0.5) == 1e-3 and scale_for(1e-3, 0.5) == 1e-6
    with pytest.raises(ValueError):
        scale_for(1e-3, 0.0)


# ----------------------------------------------------------------------------- theta < 0
def test_theta_negative_left_limit_is_s0():
    s0 = float(s0_lambert(-0.5))
    err = np.array([abs(pdm(e, -0.5, [-1e-8]).P[0] - s0) for e in (1e-2, 1e-3, 1e-4, 1e-5)])
    assert np.all(np.diff(err) < 0)
    # measured 2.46e-2, 2.60e-3, 3.16e-4, 4.95e-5: O(eps) (the delta term vanishes at 0-)
    assert err[2] < 4e-4
    assert err[3] < 7e-5


def test_theta_negative_converges_to_corrected_expansion():
    xi = np.array([-2.0, -1.0, -0.5, -0.1, -1e-3])
    errs, printed = [], []
    for eps in (1e-3, 1e-4, 1e-5):
        r = pdm(eps, -0.5, xi)
        assert np.all(r.n_switches[xi > -0.8] == 2)  # one excursion into region -
        errs.append(np.max(np.abs(r.P - asym.pdm_theta_neg(r.xi1, -0.5, OMEGA, eps))))
        printed.append(np.max(np.abs(r.P - asym.pdm_theta_neg_printed(r.xi1, -0.5, OMEGA, eps))))
        # the pieces Pi_1 (eq:xi2int) and Pi_2 (eq:hittime) hold as printed
        assert np.max(np.abs(r.xi2_entry - asym.xi2_entry_theta_neg(r.xi1, OMEGA, eps))) < 20 * eps
        # Pi_3 lowers xi1 by xi2^2/2 (the printed eq:xi14 has no such term)
        drop = r.xi1_exit - r.P
        assert np.allclose(drop, 0.5 * r.xi2_exit ** 2, rtol=0.05, atol=0.05)
    errs = np.array(errs)
    rate = np.log(errs[1:] / errs[:-1]) / np.log(10.0 ** -1)
    assert np.all(rate > 0.75)         # O(eps): the remainder is O(delta^2)
    assert errs[-1] < 2e-2
    assert min(printed) > 1.0           # the printed formula misses the term xi1


# ----------------------------------------------------------------------------- theta > 0
@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
def test_theta_positive_slope_and_continuity_at_grazing(eps):
    xi = np.array([-1e-1, -1e-2, -1e-3])
    r = pdm(eps, 0.5, xi)
    assert np.all(r.sliding_time > 0)
    slope = r.P / r.xi1
    dev = np.abs(slope - (0.5 - 1) / 0.5)
    assert np.all(np.diff(dev) < 0)     # approaches (theta-1)/theta as xi1 -> 0-
    assert dev[-1] < 1.5e-2
    assert abs(r.P[-1]) < 2e-3          # continuous at 0 (P_DM(0) = 0)


def test_theta_positive_slope_limit_improves_with_eps():
    dev = [abs(pdm(e, 0.5, [-1e-3]).P[0] / -1e-3 + 1.0) for e in (1e-2, 1e-3)]
    assert dev[1] < dev[0]


def test_theta_positive_converges_to_corrected_zero_order():
    xi = np.array([-500.0, -200.0, -50.0, -5.0, -1.0])
    errs, printed = [], []
    for eps in (1e-2, 1e-3, 1e-4):
        r = pdm(eps, 0.5, xi)
        errs.append(np.max(np.abs(r.P - asym.pdm_theta_pos(r.xi1, 0.5, OMEGA))))
        printed.append(np.max(np.abs(r.P - asym.pdm_theta_pos(r.xi1, 0.5, OMEGA, printed=True))))
    errs = np.array(errs)
    assert np.all(np.diff(errs) < 0)
    # measured 65.6, 25.8, 3.91 over this grid
    assert errs[-1] < 4.5
    assert printed[-1] > 10.0           # eq:p:xi14t2 as printed stays O(1) off


# ----------------------------------------------------------------------------- formulas
def test_sliding_time_inverts_the_curve():
    t = np.array([1e-3, 0.1, 0.7, 2.0])
    xi10, _, _ = asym.sliding_curve(t, 0.5, OMEGA)
    assert np.allclose(asym.sliding_time_theta_pos(xi10, 0.5, OMEGA), t, rtol=1e-10)


@pytest.mark.parametrize("printed", [False, True])
def test_theta_positive_formula_slope_at_zero(printed):
    xi = np.array([-1e-8, 1e-8])
    P = asym.pdm_theta_pos(xi, 0.3, OMEGA, printed=printed)
    assert P[0] / xi[0] == pytest.approx((0.3 - 1) / 0.3, rel=1e-3)
    assert P[1] == xi[1]


def test_theta_negative_formulas_agree_at_zero_minus():
    s0 = float(s0_lambert(-0.5))
    for f in (asym.pdm_theta_neg, asym.pdm_theta_neg_printed):
        assert f(-1e-14, -0.5, OMEGA, 1e-4) == pytest.approx(s0, abs=1e-5)
        assert f(0.3, -0.5, OMEGA, 1e-4) == 0.3
