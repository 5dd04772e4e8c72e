"""Known answers on both engines through the public API: one definition of each system
(filippov.FilippovSystem), asked through the one front door (first_returns(engine=...))
for the same first return on the reference driver and on the compiled engine, each
checked against the closed form -- not only against each other."""
import numpy as np
import pytest

from filippov import FilippovSystem, first_returns
from filippov.scale import UNIT

ENGINES = ("reference", "compiled")


def _returns(system, engine, start, section, direction, t_max, method="exact", **options):
    """``method``: the reference driver's; the compiled engine integrates a system
    without exact flows and uses the flows of one that has them, by construction."""
    if engine == "reference":
        options["method"] = method
    return first_returns(system, [start], section, t_max, engine=engine, direction=direction,
                         **options)


def _planar(field_minus, field_plus, **kw):
    # h = x2 in the plane; each piece written once, for one state
    return FilippovSystem(("x1", "x2"), field_minus, field_plus,
                          switch=lambda z, p: z[1],
                          switch_grad=lambda z, p: np.array([0.0, 1.0]), **kw)


@pytest.mark.parametrize("engine", ENGINES)
def test_crossing_time_and_return(engine):
    # f_- = (1, 1 + x1/2) from (-1, -1): x2 = -1 + t/2 + t^2/4 meets H at t = sqrt(5) - 1;
    # then f_+ = (1, 1): x2 = t - (sqrt(5) - 1) at the section x1 = 2 (t = 3)
    system = _planar(lambda z, p: np.array([1.0, 1.0 + 0.5 * z[0]]),
                     lambda z, p: np.array([1.0, 1.0]))
    out = _returns(system, engine, [-1.0, -1.0], lambda z, p: z[0] - 2.0, +1, 5.0,
                   method="integrate")
    assert out.first_switch[0] == pytest.approx(np.sqrt(5) - 1, rel=1e-12)
    assert out.time[0] == pytest.approx(3.0, rel=1e-13)
    assert out.state[0, 1] == pytest.approx(4 - np.sqrt(5), rel=1e-11)
    assert out.n_switches[0] == 1 and out.sliding_time[0] == 0.0


@pytest.mark.parametrize("engine", ENGINES)
def test_sliding_ends_where_the_field_turns_tangent(engine):
    # f_- = (1, 1), f_+ = (1, x1): from (-2, -0.5) H is reached at t = 0.5 where b = x1 < 0
    # (sliding), the slide ends at x1 = 0 (t = 2), then x2 = (t - 2)^2/2: 0.5 at x1 = 1
    system = _planar(lambda z, p: np.array([1.0, 1.0]), lambda z, p: np.array([1.0, z[0]]))
    out = _returns(system, engine, [-2.0, -0.5], lambda z, p: z[0] - 1.0, +1, 5.0,
                   method="integrate")
    assert out.first_switch[0] == pytest.approx(0.5, rel=1e-12)
    assert out.sliding_time[0] == pytest.approx(1.5, rel=1e-11)
    assert out.n_switches[0] == 2
    assert out.state[0, 1] == pytest.approx(0.5, rel=1e-10)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_crossing_hidden_between_samples_is_found(engine):
    # f_+ = (1, x1) from (-1, 1/2 - 1e-6): x2 = x2_0 - t + t^2/2 dips 1e-6 below H around
    # t = 1, between samples 5 apart where H > 0 (exact flows): only the sign change of
    # dH/dt shows it. The crossing is at t = 1 - sqrt(2e-6); in region -, f_- = (1, 0).
    depth = 1e-6
    system = _planar(
        lambda z, p: np.array([1.0, 0.0]), lambda z, p: np.array([1.0, z[0]]),
        flow_plus=lambda z0, tau, p: np.array([z0[0] + tau, z0[1] + z0[0] * tau + 0.5 * tau ** 2]),
        flow_minus=lambda z0, tau, p: np.array([z0[0] + tau, z0[1]]),
        sample_step=5.0)
    out = _returns(system, engine, [-1.0, 0.5 - depth], lambda z, p: z[0] - 2.0, +1, 5.0,
                   samples_per_step=1)
    assert out.first_switch[0] == pytest.approx(1 - np.sqrt(2 * depth), rel=1e-12)
    assert out.n_switches[0] == 1
    assert abs(out.state[0, 1]) < 1e-15  # x2 stays where it crossed H


@pytest.mark.parametrize("engine", ENGINES)
def test_a_shallow_crossing_is_followed_past_the_rounding_of_h(engine):
    # A point of the Hopf example's chaotic attractor (theta = 0.2, eps = 1e-2,
    # mu = 1 + 3 eps^2) reaches H with normal speed a = -3.5e-3 at x1 = y = -1, where
    # H = theta x1 + (1 - theta) y + 1 is rounding noise ~2e-16; in region - it dips
    # and comes back 7e-5 later into sliding (rules.dips_and_returns). Before, the
    # refinement converged to the noise 1.7e-14 after the entry: a ZenoError on the
    # reference driver, a failed root on the compiled engine. The start is 2.4e-15 off
    # the clean start (0, x2, 0), so the return must agree with the clean one.
    from filippov.fastmap import compute_returns
    from filippov.models import hopf
    from filippov.poincare import first_returns as returns
    from filippov_paper.scenes.fig04_retmaps import section_L1

    eps, theta, mu = 1e-2, 0.2, 1 + 3e-4
    noisy = np.array([[-2.374618293487855e-15, 1.0000380794232673, -2.374618293487855e-15]])
    clean = np.array([[0.0, 1.0000380794232673, 0.0]])
    out = []
    for z in (noisy, clean):
        if engine == "reference":
            r = returns(hopf.model(eps, theta, mu).full(), z, section_L1(), 1.0)
        else:
            r = compute_returns(hopf.compiled(eps, theta, mu), z, 1.0)
            assert r.status[0] == 0
        out.append((r.state[0], r.time[0], r.n_switches[0]))
    (zn, tn, nn), (zc, tc, nc) = out
    assert nn == nc == 3  # into region -, into sliding, out of it
    assert abs(zn[1] - zc[1]) < 1e-12 and abs(tn - tc) < 1e-12


# ---------------------------------------------------------------------------------------
# The rest of test_solver_events' known answers on both engines (a run to t_max, not a
# return: the compiled engine reports where it stopped and its first switch)
def _run(system, engine, start, t_max, **options):
    """(first switch time or NaN, number of mode changes, time slid, state at t_max); a
    slide still going at t_max is not counted in the time slid (on either engine)."""
    from filippov import compute_returns, simulate
    from filippov.fastmap import NO_RETURN
    from filippov.poincare import sliding_time

    never = lambda z, p: z[0] - 1e6  # noqa: E731 -- a section no orbit here reaches
    if engine == "reference":
        traj = simulate(system.python(), start, t_max, dense=False, **options)
        sw = traj.switches()
        return (sw[0].t if sw else np.nan), len(sw), sliding_time(traj.events), traj.z
    out = compute_returns(system.compiled(never), [start], t_max, **options)
    assert out.status[0] == NO_RETURN  # ran to t_max
    return out.first_switch[0], out.n_switches[0], out.sliding_time[0], out.state[0]


def _pseudo_equilibrium(eps, theta, **kw):
    """x' = -sign(h), eps y' = x - y, h = theta x + (1 - theta) y, with the exact flows
    of its regions (y relaxes to x - c eps under x' = c)."""
    def flow(c):
        def phi(z0, tau, p):
            x = z0[0] + c * tau
            return np.array([x, x - c * eps + (z0[1] - z0[0] + c * eps) * np.exp(-tau / eps)])
        return phi

    return FilippovSystem(("x", "y"), lambda z, p: np.array([1.0, (z[0] - z[1]) / eps]),
                          lambda z, p: np.array([-1.0, (z[0] - z[1]) / eps]),
                          switch=lambda z, p: theta * z[0] + (1 - theta) * z[1],
                          switch_grad=lambda z, p: np.array([theta, 1 - theta]),
                          flow_minus=flow(1.0), flow_plus=flow(-1.0), sample_step=eps / 4,
                          **kw)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("theta", [-0.5, 0.3, 0.9])
def test_switch_time_of_the_slow_fast_example(engine, theta):
    from scipy.optimize import brentq

    eps, x0, y0 = 0.05, 0.4, 0.7
    t1, _, _, _ = _run(_pseudo_equilibrium(eps, theta), engine, [x0, y0], 1.0)
    # independent: h along the closed-form solution of region +, by Brent
    h = lambda t: (theta * (x0 - t)  # noqa: E731
                   + (1 - theta) * (x0 - t + eps + (y0 - x0 - eps) * np.exp(-t / eps)))
    assert t1 == pytest.approx(brentq(h, 0.0, 1.0, xtol=1e-300, rtol=8.9e-16), rel=1e-12)


@pytest.mark.parametrize("engine", ENGINES)
def test_an_exact_tangency_touches_without_switching(engine):
    # f_+ = (1, x1) from (-1, 1/2): x2 = 1/2 - t + t^2/2 touches H at t = 1 and stays
    # above: no switch; at t = 3, x = (2, 2)
    system = _planar(
        lambda z, p: np.array([1.0, 0.0]), lambda z, p: np.array([1.0, z[0]]),
        flow_plus=lambda z0, tau, p: np.array([z0[0] + tau, z0[1] + z0[0] * tau + 0.5 * tau ** 2]),
        flow_minus=lambda z0, tau, p: np.array([z0[0] + tau, z0[1]]), sample_step=0.1)
    t1, n, slid, z = _run(system, engine, [-1.0, 0.5], 3.0)
    assert np.isnan(t1) and n == 0 and slid == 0.0
    np.testing.assert_allclose(z, [2.0, 2.0], rtol=0, atol=1e-14)


@pytest.mark.parametrize("engine", ENGINES)
def test_sliding_into_the_pseudo_equilibrium(engine):
    # from (0.2, 0.1) the orbit crosses H outside the attracting segment |x| < eps theta,
    # comes back from region - inside it and slides into x = y = 0 (x' = -x/(eps theta))
    eps, theta = 0.02, 0.4
    t1, n, slid, z = _run(_pseudo_equilibrium(eps, theta), engine, [0.2, 0.1], 2.0)
    assert n == 2 and 0 < t1 < 2.0 and slid == 0.0  # the slide lasts beyond t_max
    # the slide is integrated (no sliding flow given): x = x_s exp(-t/(eps theta)) ~ 1e-100
    # by t_max, reached to the integration's absolute tolerance (atol = 1e-14)
    assert np.abs(z).max() < 10 * 1e-14


@pytest.mark.parametrize("engine", ENGINES)
def test_a_system_built_without_sliding_errs_instead_of_sliding(engine):
    from filippov.simulate import SlidingNotBuiltError

    system = _pseudo_equilibrium(0.02, 0.4, sliding=False)
    with pytest.raises(SlidingNotBuiltError, match="sliding"):
        _returns(system, engine, [0.2, 0.1], lambda z, p: z[0] - 1e6, 0, 2.0)


@pytest.mark.parametrize("engine", ENGINES)
def test_the_reduced_example_reaches_its_pseudo_equilibrium_in_finite_time(engine):
    # eps = 0, theta = -0.5: x' = -sign(x) from 0.7 reaches x = 0 at t = 0.7 and slides
    system = FilippovSystem(("x",), lambda z, p: np.array([1.0]), lambda z, p: np.array([-1.0]),
                            switch=lambda z, p: z[0], switch_grad=lambda z, p: np.array([1.0]))
    t1, n, slid, z = _run(system, engine, [0.7], 2.0)
    assert n == 1 and t1 == pytest.approx(0.7, rel=1e-14)
    assert z[0] == pytest.approx(0.0, abs=4e-15)  # event time to ~1e-15


# ---------------------------------------------------------------------------------------
# The guards (tests/test_guards.py) on both engines through the public API
_NEVER = lambda z, p: z[0] - 1e6  # noqa: E731 -- a section no orbit here reaches


@pytest.mark.parametrize("engine", ENGINES)
def test_the_event_limit_is_an_error_on_both_engines(engine):
    from filippov import EventLimitError

    with pytest.raises(EventLimitError):
        _returns(_pseudo_equilibrium(1e-3, -0.5), engine, [0.01, 0.0], _NEVER, 0, 10.0,
                 max_events=100)


@pytest.mark.parametrize("engine", ENGINES)
def test_chatter_below_time_resolution_is_zeno_on_both_engines(engine):
    from filippov import ZenoError

    # below the resolution of a system written in units of order one (scale=UNIT): in
    # units of its own start (1e-12) and time scale (eps = 1e-13) the same chatter is
    # resolved, and is run until the event limit (tests/test_units.py)
    with pytest.raises(ZenoError):
        _returns(_pseudo_equilibrium(1e-13, -0.5, scale=UNIT), engine, [1e-12, 0.0], _NEVER,
                 0, 1.0)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("bad,match", [([np.nan, 0.0], "finite"), ([0.0, np.inf], "finite"),
                                       ([0.0], "components|shape")])
def test_bad_start_points_are_refused_on_both_engines(engine, bad, match):
    with pytest.raises(ValueError, match=match):
        _returns(_pseudo_equilibrium(0.1, -0.5), engine, bad, _NEVER, 0, 1.0)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_nan_field_is_not_handed_on_by_either_engine(engine):
    from filippov import SimulationError

    # (the compiled system's construction already refuses a piece that is non-finite at
    # its probe point, 0.5: a field that is NaN only away from it reaches the engine)
    half = lambda z, p: np.array([np.nan if z[1] > 0.75 else 1.0, 1.0])  # noqa: E731
    system = FilippovSystem(("a", "b"), half, half, switch=lambda z, p: z[1],
                            switch_grad=lambda z, p: np.array([0.0, 1.0]))
    with pytest.raises(SimulationError, match="non-finite|failed"):
        _returns(system, engine, [0.0, 1.0], _NEVER, 0, 1.0, method="integrate")


@pytest.mark.parametrize("engine", ENGINES)
def test_thousands_of_switches_stay_bounded_on_both_engines(engine):
    # 2000 half-periods of the chatter orbit of the pseudo-equilibrium example
    from filippov.analytic import chatter

    eps = 1e-4
    f = chatter.orbit(eps, -0.5)
    t1, n, _, z = _run(_pseudo_equilibrium(eps, -0.5), engine, [f["x_switch"], f["y_switch"]],
                       1000 * f["period"], max_events=4_000)
    assert n >= 1999
    assert abs(z[0]) <= abs(f["x_switch"]) * (1 + 1e-9)
