"""Event location, switching decisions and sliding, against exactly known answers."""
import numpy as np
import pytest
from scipy.optimize import brentq

from filippov import MINUS, PLUS, SLIDING, PiecewiseSystem, simulate
from filippov.models import planar_sketch, pseudo_equilibrium


def planar(fm, fp, flows=None, sample_step=np.inf):
    return PiecewiseSystem(names=("x1", "x2"), field_minus=fm, field_plus=fp,
                           switch=lambda z: z[1],
                           switch_grad=lambda z: np.stack([np.zeros_like(z[0]), np.ones_like(z[1])]),
                           flows=flows or {}, sample_step=sample_step)


@pytest.mark.parametrize("method", ["exact", "integrate"])
def test_crossing_time_planar(method):
    # from (-1, -1) under f_- = (1, 1 + x1/2): x2 = -1 + t/2 + t^2/4 hits 0 at t = sqrt(5) - 1
    traj = simulate(planar_sketch.system("crossing"), [-1.0, -1.0], 2.5, method=method)
    hit, = traj.switches()
    assert hit.kind == "crossing" and (hit.mode_before, hit.mode_after) == (MINUS, PLUS)
    assert hit.t == pytest.approx(np.sqrt(5) - 1, rel=1e-12, abs=0)


@pytest.mark.parametrize("method", ["exact", "integrate"])
@pytest.mark.parametrize("theta", [-0.5, 0.3, 0.9])
def test_switch_time_slow_fast(method, theta):
    eps, x0, y0 = 0.05, 0.4, 0.7
    system = pseudo_equilibrium.model(eps, theta).full()
    traj = simulate(system, [x0, y0], 1.0, method=method)
    first = traj.switches()[0]
    # independent: h along the closed-form solution of region +, by Brent
    h = lambda t: theta * (x0 - t) + (1 - theta) * (x0 - t + eps + (y0 - x0 - eps) * np.exp(-t / eps))
    t_exact = brentq(h, 0.0, 1.0, xtol=1e-300, rtol=8.9e-16)
    assert first.t == pytest.approx(t_exact, rel=1e-12 if method == "exact" else 1e-10)
    assert abs(system.switch(first.state)) < 1e-13


def test_hidden_grazing_crossing_is_found():
    # f_+ = (1, x1): x2 = x2_0 - t + t^2/2 from x1 = -1; it dips 1e-6 below 0 near t = 1,
    # between two samples 5 apart where H > 0: only the dH/dt check can see it.
    depth = 1e-6
    flows = {PLUS: lambda z0, tau: np.stack([z0[0] + tau, z0[1] + z0[0] * tau + 0.5 * np.asarray(tau) ** 2]),
             MINUS: lambda z0, tau: np.stack([z0[0] + tau, z0[1] + 0 * np.asarray(tau)])}
    system = planar(lambda z: np.stack([np.ones_like(z[0]), np.zeros_like(z[0])]),
                    lambda z: np.stack([np.ones_like(z[0]), z[0]]), flows, sample_step=5.0)
    traj = simulate(system, [-1.0, 0.5 - depth], 5.0, samples_per_step=1)
    cross = traj.switches()[0]
    assert cross.t == pytest.approx(1 - np.sqrt(2 * depth), rel=1e-12)
    assert cross.mode_after == MINUS


def test_exact_tangency_touches_without_switching():
    flows = {PLUS: lambda z0, tau: np.stack([z0[0] + tau, z0[1] + z0[0] * tau + 0.5 * np.asarray(tau) ** 2])}
    system = planar(lambda z: np.stack([np.ones_like(z[0]), np.zeros_like(z[0])]),
                    lambda z: np.stack([np.ones_like(z[0]), z[0]]), flows, sample_step=0.1)
    traj = simulate(system, [-1.0, 0.5], 3.0)
    assert traj.switches() == []
    touch, = [e for e in traj.events if e.kind == "touch"]
    assert touch.t == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("method", ["exact", "integrate"])
def test_sliding_ends_where_f_plus_becomes_tangent(method):
    # f_- = (1, 1), f_+ = (1, x1) on h = x2: slides while x1 < 0 (b = x1), leaves into + at x1 = 0
    fm = lambda z: np.stack([np.ones_like(z[0]), np.ones_like(z[0])])
    fp = lambda z: np.stack([np.ones_like(z[0]), z[0]])
    system = planar(fm, fp)
    traj = simulate(system, [-2.0, -0.5], 3.0, method="integrate")
    kinds = [(e.kind, e.mode_after) for e in traj.switches()]
    assert kinds == [("slide_start", SLIDING), ("slide_end", PLUS)]
    start, end = traj.switches()
    assert start.t == pytest.approx(0.5, rel=1e-12)
    assert end.t == pytest.approx(2.0, rel=1e-12)
    assert traj.z[1] == pytest.approx(0.5, rel=1e-10)  # x2 = t^2/2 after leaving at t = 2


def test_sliding_segment_of_pseudo_equilibrium():
    from filippov.sliding import attracting_intervals
    eps, theta = 0.02, 0.4
    system = pseudo_equilibrium.model(eps, theta).full()
    line = lambda s: np.stack([s, -theta / (1 - theta) * s])
    (lo, hi), = attracting_intervals(system, line, np.linspace(-0.5, 0.5, 101))
    assert lo == pytest.approx(-eps * theta, rel=1e-13)
    assert hi == pytest.approx(eps * theta, rel=1e-13)
    # from (0.2, 0.1) the orbit first crosses H_s outside the segment (x < -eps theta),
    # comes back from region - inside it, and slides into x = y = 0
    traj = simulate(system, [0.2, 0.1], 2.0)
    cross, start = traj.switches()
    assert cross.kind == "crossing" and cross.state[0] < -eps * theta
    assert start.kind == "slide_start" and abs(start.state[0]) < eps * theta
    assert abs(traj.z[0]) < 1e-20


def test_a_system_built_without_sliding_errs_instead_of_sliding():
    system = pseudo_equilibrium.model(0.02, 0.4).full(sliding=False)
    from filippov import SimulationError
    with pytest.raises(SimulationError, match="sliding reached.* built with sliding=False"):
        simulate(system, [0.2, 0.1], 2.0)


def test_reduced_system_reaches_pseudo_equilibrium_in_finite_time():
    system = pseudo_equilibrium.model(0.0, -0.5).reduced()
    traj = simulate(system, [0.7], 2.0)
    start, = traj.switches()
    assert start.kind == "slide_start" and start.t == pytest.approx(0.7, rel=1e-14)
    assert traj.z[0] == pytest.approx(0.0, abs=4e-15)  # event time to ~1e-15


def test_dense_samples_follow_the_exact_solution():
    eps, theta, x0, y0 = 0.05, 0.3, 0.4, 0.7
    system = pseudo_equilibrium.model(eps, theta).full()
    traj = simulate(system, [x0, y0], 0.2)
    t, z, mode = traj.sample(np.linspace(0, 0.2, 41), include_events=False)
    assert np.all(mode == PLUS)
    y = x0 - t + eps + (y0 - x0 - eps) * np.exp(-t / eps)
    assert np.max(np.abs(z[1] - y)) < 1e-15


def test_a_sign_change_the_samples_saw_survives_refinement():
    """Samples are array evaluations, the refinement's values scalar ones; the two may
    round differently (numpy's SIMD loops, another CPU: found by the emulated CPU on
    fig09, where dH/dt near the grazing point changed sign in the samples but not at the
    ends of the bracket). The bracket keeps the sampled end values instead of failing."""
    from test_loop_refine import _reference_refine

    from filippov import rules
    from filippov.simulate import _brent

    fun = lambda t: 1e-17 + 0.0 * t          # noqa: E731  (scalar: positive at both ends)
    # the samples saw +1e-17 at t = 0 and -1e-17 at t = 1: a root in [0, 1], not an error
    r = _brent(fun, 0.0, 1.0, 1e-17, -1e-17, 1e-12)
    assert 0.0 <= r <= 1.0
    r = _reference_refine(fun, rules.TO_NEG, 0.0, 1.0, 1e-17, -1e-17, 1e-12)
    assert r == 1.0                          # the scalar never crosses: the sampled end
    with pytest.raises(ValueError):          # no sign change anywhere: still an error
        _brent(fun, 0.0, 1.0, 1e-17, 2e-17, 1e-12)
