"""A system written in small units is differenced at its own scale (found by an independent
review, 2026-11-28): the central differences behind dP/dz stepped by at least 6e-6 (the
compiled engine) or 1e-6 (the reference) whatever the state's size, so that on a limit
cycle of radius 1e-5 the Floquet multiplier came out 0.014 (compiled) and 0.031 (reference)
instead of 0.0316, and 4e-6 at radius 3e-6, silently on both engines
(docs/decisions.md#difference-scale)."""
import numpy as np
import pytest

from filippov import FilippovSystem, compute_returns, periodic_orbit, rules

# In each half plane r' = a r (1 - r^2 / R^2) and theta' = w (y >= 0: a+, w+; else a-, w-):
# the circle r = R crosses y = 0 transversally, the period is pi/w+ + pi/w-, and the
# radial perturbation decays at -2a: the multiplier is exp(-2 (a+ pi/w+ + a- pi/w-)).
W_PLUS, W_MINUS, A_PLUS, A_MINUS = 1.0, 2.0, 0.3, 0.5
MULTIPLIER = np.exp(-2.0 * (A_PLUS * np.pi / W_PLUS + A_MINUS * np.pi / W_MINUS))
PERIOD = np.pi / W_PLUS + np.pi / W_MINUS


def _circle(radius, jacobians=False):
    def field(w, a):
        def f(z, p):
            g = a * (1.0 - (z[0] * z[0] + z[1] * z[1]) / (p[0] * p[0]))
            return np.array([-w * z[1] + g * z[0], w * z[0] + g * z[1]])

        def jac(z, p):
            r2 = p[0] * p[0]
            g = a * (1.0 - (z[0] * z[0] + z[1] * z[1]) / r2)
            return np.array([[g - 2 * a * z[0] * z[0] / r2, -w - 2 * a * z[0] * z[1] / r2],
                             [w - 2 * a * z[0] * z[1] / r2, g - 2 * a * z[1] * z[1] / r2]])
        return f, jac
    (fm, jm), (fp, jp) = field(W_MINUS, A_MINUS), field(W_PLUS, A_PLUS)
    extra = {"jacobians": {"minus": jm, "plus": jp}} if jacobians else {}
    return FilippovSystem(("x", "y"), field_minus=fm, field_plus=fp,
                          switch=lambda z, p: z[1],
                          switch_grad=lambda z, p: np.array([0.0, 1.0]),
                          params=np.array([radius]), **extra)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
@pytest.mark.parametrize("radius", [1.0, 1e-5, 3e-6])
def test_a_small_limit_cycle_has_the_multiplier_of_a_large_one(engine, radius):
    # multipliers of the monodromy: 1 along the flow, and the radial one
    orbit = periodic_orbit(_circle(radius), [0.0, 1.1 * radius], lambda z, p: z[0],
                           direction=-1, engine=engine, t_max=50.0)
    assert orbit.period == pytest.approx(PERIOD, rel=1e-8)
    assert orbit.point[1] == pytest.approx(radius, rel=1e-7)
    assert sorted(np.abs(orbit.multipliers))[0] == pytest.approx(MULTIPLIER, rel=1e-6)


def test_the_compiled_dp_dz_on_a_small_cycle():
    """dP/dz at the fixed point (0, R) of x = 0 crossed downwards: [[0, 0], [0, lambda]]
    (the section's row is annihilated; the radial one is the multiplier)."""
    radius = 1e-5
    cm = _circle(radius).compiled(lambda z, p: z[0], direction=-1)
    J = compute_returns(cm, [[0.0, radius]], 50.0, jacobian=True).jacobian[0]
    assert J[1, 1] == pytest.approx(MULTIPLIER, rel=1e-6)
    assert np.abs(J[0]).max() < 1e-6


def test_the_right_jacobian_of_a_small_system_is_accepted():
    """The check of a given Jacobian differences at the system's scale too: it refused
    the right one at R = 1e-5 before."""
    orbit = periodic_orbit(_circle(1e-5, jacobians=True), [0.0, 1.1e-5], lambda z, p: z[0],
                           direction=-1, engine="reference", t_max=50.0)
    assert sorted(np.abs(orbit.multipliers))[0] == pytest.approx(MULTIPLIER, rel=1e-6)


def test_the_difference_scale_is_one_above_order_one_and_the_state_s_below():
    assert rules.difference_scale(np.array([3.0, -0.2])) == 1.0
    assert rules.difference_scale(np.array([1e-5, -3e-5])) == 3e-5
    assert rules.difference_scale(np.zeros(2)) == 1.0
    assert rules.difference_scale(np.array([np.nan, 1e-3])) == 1.0
