"""The Hopf example's NumPy helpers are derived from its definition (filippov.models.hopf):
each equals the symbolic expression it is printed from, and that expression is the
paper's (M_- to O(eps), the fast field g, H_s solved for y, the gap at p_g)."""
import numpy as np
import pytest
import sympy as sp

from filippov.models import hopf
from filippov.models.hopf import eps, mu, omega, theta, x1, x2, y

RNG = np.random.default_rng(7)
POINTS = [dict(zip((x1, x2, y, eps, mu, omega, theta), row)) for row in
          np.column_stack([RNG.uniform(-1.5, 1.5, (12, 3)), RNG.uniform(1e-3, 0.2, 12),
                           RNG.uniform(0.5, 2.0, 12), RNG.uniform(1.0, 30.0, 12),
                           RNG.uniform(-3.0, 0.9, 12)])]


def _at(expr, point):
    return float(sp.N(expr.subs(point), 30))


@pytest.mark.parametrize("helper, expr, args", [
    (hopf.slow_manifold_minus_first_order,
     sp.series(hopf.SLOW_MANIFOLD_MINUS, eps, 0, 2).removeO(), (x1, x2, eps, mu, omega)),
    (hopf.fast_field, hopf.DEFINITION.g_minus[0], (x1, x2, y, eps, mu, omega)),
    (hopf.switching_surface_y, sp.solve(hopf.DEFINITION.switch, y)[0], (x1, theta)),
    (hopf.slow_manifold_minus, hopf.SLOW_MANIFOLD_MINUS, (x1, x2, eps, mu, omega)),
    (hopf.grazing_gap, (x1 - hopf.SLOW_MANIFOLD_MINUS).subs({x1: -1, x2: 0, mu: 1}), (eps,)),
])
def test_helper_equals_the_definition_at_sample_points(helper, expr, args):
    for point in POINTS:
        got = helper(*(float(point[a]) for a in args))
        assert got == pytest.approx(_at(expr, point), rel=1e-13, abs=1e-14)


def test_derived_pieces_are_the_papers():
    # eq:ymm: y_m- = x1 + eps (mu x1 - omega x2 - r^2 x1 - 1) + O(eps^2)
    r2 = x1 ** 2 + x2 ** 2
    first = x1 + eps * (mu * x1 - omega * x2 - r2 * x1 - 1)
    assert sp.expand(hopf.SLOW_MANIFOLD_MINUS_FIRST_ORDER.doit() - first) == 0
    assert sp.expand(hopf.SLOW_MANIFOLD_MINUS - first).as_poly(eps).degree() == 4
    assert sp.expand(hopf.SLOW_MANIFOLD_MINUS - first).coeff(eps, 1) == 0
    # g = eps x1' + x1 - y with x1' the Hopf field's first component (eq:exfast2)
    assert sp.expand(hopf.FAST.doit() - (eps * hopf.HOPF_FIELD[0] + x1 - y)) == 0
    # H_s: theta x1 + (1 - theta) y + 1 = 0
    assert sp.simplify(hopf.SWITCH.subs(y, hopf.SWITCHING_SURFACE_Y)) == 0
    # M_+ - M_- at (-1, 0), mu = 1: eps - 2 eps^2 - 6 eps^3 - 6 eps^4 (text after eq:ymm)
    assert sp.expand(hopf.GRAZING_GAP.doit() - (eps - 2 * eps ** 2 - 6 * eps ** 3
                                               - 6 * eps ** 4)) == 0


def test_written_pieces_round_as_written():
    """The helpers printed in written order give the bits of the NumPy text they are
    written as (what fig05 computed by hand before they were derived)."""
    X1, X2 = np.meshgrid(np.linspace(-1.04, -0.9, 36), np.linspace(-0.4, 0.3, 36),
                         indexing="ij")
    e, m, o, th = 0.01, 1.0, 8 * np.pi, -0.5
    assert np.array_equal(hopf.slow_manifold_minus_first_order(X1, X2, e, m, o),
                          X1 + e * (m * X1 - o * X2 - (X1 * X1 + X2 * X2) * X1 - 1.0))
    Y = hopf.slow_manifold_minus(X1, X2, e, m, o)
    assert np.array_equal(hopf.fast_field(X1, X2, Y, e, m, o),
                          e * hopf.hopf_rhs(X1, X2, m, o)[0] + X1 - Y)
    assert np.array_equal(hopf.switching_surface_y(X1, th), (-1.0 - th * X1) / (1.0 - th))
    for e in (0.1, 0.01, 0.005, 1e-3):
        assert hopf.grazing_gap(e) == e - 2 * e ** 2 - 6 * e ** 3 - 6 * e ** 4
