"""attractors.settle reports only an attractor its returns approach (found by an
independent review, 2026-11-28): a 2-cycle that repeats exactly was reported as the fixed
point of the other piece 0.006 from one of its points (with the transient one return
longer), and chaotic returns as a fixed point they never came near, both silently.

The system: four phases of a unit rotation (c, s) apply, one after the other, smooth
shears to (x, y), so that its first return to s = 0 is the map x' = T(x) - b y, y' = x
(b = 1e-3), T a cubic on either side of the switching line x = 0 (region -: x < 0)."""
import numpy as np
import pytest
from scipy.special import beta

from filippov import FilippovSystem, attractors

_NORM = float(2.0 * np.pi / (beta(3.5, 3.5) / 2))   # each phase's weight integrates to 1
_B = 1e-3
_KAPPA = np.log(_B)
_CB = (_B - 1.0) / _KAPPA


def _field(offset):
    def f(z, p):
        x, y, c, s = z[0], z[1], z[2], z[3]
        cp, cm, sp, sm = max(c, 0.0), max(-c, 0.0), max(s, 0.0), max(-s, 0.0)
        w1, w2 = _NORM * (cp * sp) ** 6, _NORM * (cm * sp) ** 6
        w3, w4 = _NORM * (cm * sm) ** 6, _NORM * (cp * sm) ** 6
        T = p[offset] + p[offset + 1] * x + p[offset + 2] * x * x + p[offset + 3] * x * x * x
        g = 5.0 * (1.0 - c * c - s * s)   # the unit circle attracts
        # phase 1: y <- b y - T(x) (exactly: y' = kappa y - kappa T / (b - 1), kappa = ln b);
        # phases 2-4: x <- x - y, y <- y + x, x <- x - y
        return np.array([-(w2 + w4) * y,
                         w1 * (_KAPPA * y - T / _CB) + w3 * x,
                         -2.0 * np.pi * s + g * c, 2.0 * np.pi * c + g * s])
    return f


def _model(left, right):
    system = FilippovSystem(("x", "y", "c", "s"), _field(0), _field(4),
                            switch=lambda z, p: z[0],
                            switch_grad=lambda z, p: np.array([1.0, 0.0, 0.0, 0.0]),
                            params=np.array([*left, *right], dtype=float))
    return system.compiled(lambda z, p: z[3], direction=+1)


def _settle(cmodel, x0, y0, transient, lyapunov=False):
    return attractors.settle(cmodel, np.array([x0, y0, 1.0, 0.0]), coordinate=0,
                             transient=transient, keep=60, t_max=1.5, scale=1.0,
                             max_period=30, window=(-0.5, 1.5), lyapunov=lyapunov)


def test_an_exact_two_cycle_next_to_another_fixed_point_is_the_two_cycle():
    # right cubic: T(0.001) = 0.8, T(0.8) = 0.001, slopes 2 and 0.1 there (a stable
    # 2-cycle, multiplier ~0.2); left: x -> 0.5 x - 0.0025, a stable fixed point at -0.005
    p, q = 0.001, 0.8
    A = np.array([[1, x, x * x, x ** 3] for x in (p, q)] + [[0, 1, 2 * x, 3 * x * x]
                                                          for x in (p, q)])
    right = np.linalg.solve(A, [q, p, 2.0, 0.1])
    cm = _model((-0.0025, 0.5, 0.0, 0.0), right)
    for transient in (200, 201, 203):   # the last kept return on either point of the cycle
        a = _settle(cm, q + 0.01, p, transient)
        assert a.period == 2, transient
        assert a.width == pytest.approx(np.ptp(a.values), abs=1e-10) and a.width > 0.79


def test_chaotic_returns_are_not_a_fixed_point_they_never_visit():
    # right: the logistic map 3.9 x (1 - x), chaotic on [0.095, 0.975]; left:
    # x -> 0.5 x - 0.15, a stable fixed point at -0.2994 the returns never come near
    cm = _model((-0.15, 0.5, 0.0, 0.0), (0.0, 3.9, -3.9, 0.0))
    a = _settle(cm, 0.3, 0.3, 200)
    assert a.cycle is None and a.period == 0
    assert a.values.min() > 0.05
