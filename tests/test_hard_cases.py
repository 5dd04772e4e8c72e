"""Hard cases: tiny eps, theta near 0 and 1, exact tangency, thousands of rapid
switches, long runs, and inputs that are wrong rather than hard.

Each test bounds its work (event and step limits, t_max) and asserts what the
theory says the result must be, so a silent NaN, a wrong side at a tangency or a
drift cannot pass. Speed is measured in `make bench`, not here.
"""
import numpy as np
import pytest

from filippov import SLIDING, ZenoError, fastmap, simulate
from filippov_paper import hard_cases
from filippov.analytic import chatter
from filippov.models import hopf, pseudo_equilibrium

OMEGA, MU = 8 * np.pi, 1.0
T_MAX = 4 * 2 * np.pi / OMEGA
SMOOTH_SLOPE = np.exp(-4 * np.pi * MU / OMEGA)


def hopf_map(eps, theta, x2, mu=MU, **opts):
    """P on L1 from the compiled kernel, with the raw output (status, switches)."""
    x2 = np.asarray(x2, dtype=float)
    starts = np.stack([np.zeros_like(x2), x2, np.zeros_like(x2)], axis=1)
    out = fastmap.compute_returns(hopf.compiled(eps, theta, mu, OMEGA), starts, T_MAX, **opts)
    assert np.all(out.status == fastmap.OK), [fastmap.STATUS[s] for s in out.status]
    assert np.all(np.isfinite(out.state))
    return out.state[:, 1], out


# ----------------------------------------------------------------------- eps to 1e-6
# The eps sweep is a workflow product (results/hard_cases.nc, filippov_paper.hard_cases);
# these tests assert on the same library code, run here over the same eps values.
EPS_SWEEP = [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]


@pytest.fixture(scope="module")
def eps_sweep():
    """filippov_paper.hard_cases.sweep over EPS_SWEEP: what results/hard_cases.nc holds."""
    ds = hard_cases.sweep(EPS_SWEEP)
    np.testing.assert_array_equal(ds.eps.values, EPS_SWEEP)
    return ds


def _statuses(values):
    return [fastmap.STATUS[int(s)] for s in np.atleast_1d(values)]


def test_theta_negative_jump_scales_like_eps_down_to_1e_6(eps_sweep):
    ds = eps_sweep
    assert ds.attrs["jump_theta"] == -0.5 and ds.attrs["jump_x2_offset"] == 1e-13
    assert np.all(ds.jump_status.values == fastmap.OK), _statuses(ds.jump_status.values)
    assert np.all(ds.jump_finite.values == 1)
    c = ds.jump_over_eps.values
    np.testing.assert_array_equal(c, ds.jump.values / np.array(EPS_SWEEP))
    # jump/eps converges (to 0.6008...): the differences shrink like eps
    assert np.all((0.55 < c) & (c < 0.65)), c
    d = np.abs(np.diff(c))
    assert np.all(d[1:] < d[:-1] * 0.5) and d[-1] < 1e-4


def test_theta_positive_slope_stays_order_one_down_to_1e_6(eps_sweep):
    ds = eps_sweep
    assert ds.attrs["slope_theta"] == 0.5
    for eps in EPS_SWEEP:
        d = ds.sel(eps=eps)
        assert int(d.slope_status_grazing) == fastmap.OK, _statuses(d.slope_status_grazing)
        assert int(d.slope_status_probe) == fastmap.OK, _statuses(d.slope_status_probe)
        assert int(d.slope_finite) == 1
        # the kink's width in x2 is O(eps^2): probe inside it, but not below the
        # spacing of doubles near 1 (the step actually taken is what 1 + dx rounds to)
        x2 = 1.0 + max(1e-3 * eps * eps, 1e-13)
        assert float(d.slope_probe) == x2 - 1.0
        assert float(d.slope_P_grazing) == 1.0 and float(d.slope_sliding_time) > 0
    slopes = ds.slope.values
    # negative and of order one for every eps, not shrinking as eps -> 0
    assert np.all((-0.7 < slopes) & (slopes < -0.5)), slopes
    assert np.ptp(slopes) < 0.03, slopes


@pytest.mark.parametrize("eps", EPS_SWEEP)
def test_chatter_period_scales_like_eps(eps_sweep, eps):
    theta = -0.5
    assert eps_sweep.attrs["chatter_theta"] == theta
    d = eps_sweep.sel(eps=eps)
    orbit = chatter.orbit(eps, theta)
    assert float(d.chatter_period) == orbit["period"]
    # 20.25 periods from the switch point: 40 switches, all at finite times
    assert int(d.chatter_switches) == 40 and int(d.chatter_times_finite) == 1
    # every simulated period (every second switching time) within 1e-9 of the formula
    assert float(d.chatter_period_max_rel_dev) <= 1e-9, float(d.chatter_period_max_rel_dev)
    assert float(d.chatter_period_over_eps) == pytest.approx(chatter.orbit(1.0, theta)["period"],
                                                             rel=1e-12)


def test_theta_positive_sliding_return_converges_like_eps_squared_at_bounded_cost(eps_sweep):
    # one return of the Hopf example at theta = 0.5 through sliding, reference driver
    d = eps_sweep
    assert np.all(d.return_finite.values == 1)
    np.testing.assert_array_equal(d.return_P_reduced.values, 1.0)   # the reduced orbit
    gap = 1.0 - d.return_P.values
    assert np.all(gap > 0)
    scaled = gap / d.eps.values ** 2                 # O(eps^2), as the theta > 0 scaling says
    assert np.all((scaled[1:] > 100) & (scaled[1:] < 200)), scaled
    assert np.ptp(scaled[2:]) < 0.05 * scaled[-1]    # converged for eps <= 1e-4
    # sliding lasts O(1) at every eps; the stiff sliding field is handed to Radau IIA
    # at small eps, so the cost stays bounded instead of growing like 1/eps
    assert np.all((d.return_sliding_time.values > 0.1) & (d.return_sliding_time.values < 0.3))
    stiff = list(d.return_stiff.values)
    assert stiff == [0, 1, 1, 1, 1]
    # a stiff return costs a few times the non-stiff one at eps = 1e-2 (64 DOP853
    # steps). Before: 1148-1617 steps with the 3-stage method (scipy's Radau order),
    # 3007 at eps = 1e-6 before the noise floor (simulate.NOISE_STEPS); measured now
    # 188, 190, 167, 124 for eps = 1e-3 .. 1e-6
    steps = d.return_steps.values
    assert steps[0] < 100 and steps[1:].max() < 4 * steps[0], steps


def test_radau_takes_over_stiff_sliding_and_agrees_with_dop853(monkeypatch):
    """Where both run (eps = 1e-4), the implicit finish agrees with DOP853."""
    import sys

    model = hopf.model(1e-4, 0.5)
    start, opts = [0.0, 1.2, 0.0], dict(dense=False, max_steps=20_000)
    explicit = simulate(model.full(), start, 0.3, stiff=False, **opts)
    # check for stiffness early, so that Radau takes over for most of the slide
    monkeypatch.setattr(sys.modules["filippov.simulate"], "STIFF_AFTER", 200)
    implicit = simulate(model.full(), start, 0.3, **opts)
    assert "sliding" in implicit.stiff_modes and not explicit.stiff_modes
    np.testing.assert_allclose(implicit.z, explicit.z, rtol=0, atol=1e-11)


@pytest.mark.parametrize("eps", EPS_SWEEP)
def test_pseudo_equilibrium_theta_positive_slides_in_for_every_eps(eps_sweep, eps):
    # theta = 0.6: the relaxed + flow meets H_s at x = -(1 - theta) eps, inside the
    # attracting band |x| < theta eps (at theta = 0.5 it would hit the band's edge).
    # Start 30 eps away (inside the fast transient, sampled on the eps scale; the
    # O(1) approach is tested below and by the compiled kernel) and slide in.
    theta = 0.6
    attrs = eps_sweep.attrs
    assert attrs["slide_theta"] == theta and attrs["slide_start_over_eps"] == 30
    d = eps_sweep.sel(eps=eps)
    # the events after the start are exactly one slide_start, and it ends sliding
    assert int(d.slide_events) == 1 and int(d.slide_starts) == 1
    assert int(d.slide_final_mode) == SLIDING
    assert abs(float(d.slide_start_x) + (1 - theta) * eps) < 1e-12
    assert float(d.slide_start_offset) == float(d.slide_start_x) + (1 - theta) * eps
    assert float(d.slide_final_abs_x) < 1e-12 and int(d.slide_finite) == 1
    # from O(1) away: the compiled kernel (exact flows, sliding by DOP853)
    assert attrs["kernel_start"] == 0.3 and attrs["kernel_t_max"] == 0.5
    assert int(d.kernel_status) == fastmap.NO_RETURN and int(d.kernel_switches) == 1
    assert float(d.kernel_final_abs_x) < 1e-12 and int(d.kernel_finite) == 1


# ----------------------------------------------------------------------- theta near 0 and 1
@pytest.mark.parametrize("theta", [-0.01, 0.01, 0.99])
def test_theta_near_zero_and_one_hopf(theta):
    x2 = np.array([1.0 - 1e-5, 1.0 - 1e-9, 1.0, 1.0 + 1e-9, 1.0 + 1e-6, 1.01])
    P, out = hopf_map(0.01, theta, x2)
    np.testing.assert_allclose(P[:2] - 1, SMOOTH_SLOPE * (x2[:2] - 1), rtol=1e-4)
    assert P[2] == 1.0
    assert np.all((0.8 < P) & (P < 1.1))
    if theta < 0:   # case 2: a jump of order eps times s0(theta), small near theta = 0
        assert out.n_switches[3] == 2 and 1e-5 < 1.0 - P[3] < 0.01
    else:           # case 1: continuous, by sliding
        assert out.sliding_time[3] > 0 and abs(P[3] - 1.0) < 1e-7


@pytest.mark.parametrize("theta", [-0.01, 0.01, 0.99])
def test_theta_near_zero_and_one_pseudo_equilibrium(theta):
    eps = 1e-3
    system = pseudo_equilibrium.model(eps, theta).full()
    if theta < 0:
        orbit = chatter.orbit(eps, theta)
        traj = simulate(system, [orbit["x_switch"], orbit["y_switch"]], 10.5 * orbit["period"],
                        dense=False, max_events=100)
        t = np.array([e.t for e in traj.switches()])
        np.testing.assert_allclose(np.diff(t[::2]), orbit["period"], rtol=1e-8)
    else:  # slides into the pseudo-equilibrium; the sliding band is |x| < eps theta
        traj = simulate(system, [0.05, 0.0], 1.0, dense=False, max_events=100)
        start = next(e for e in traj.events if e.kind == "slide_start")
        assert abs(start.state[0]) <= eps * theta * (1 + 1e-9)
        assert abs(traj.z[0]) < 1e-12


# ----------------------------------------------------------------------- exact tangency
@pytest.mark.parametrize("theta", [-0.5, 0.5])
def test_start_on_the_tangency_is_deterministic_and_on_the_right_side(theta):
    x2 = np.array([1.0 - 1e-14, 1.0, 1.0 + 1e-14])
    P1, out1 = hopf_map(0.01, theta, x2)
    P2, out2 = hopf_map(0.01, theta, x2)
    np.testing.assert_array_equal(P1, P2)            # bit for bit
    np.testing.assert_array_equal(out1.n_switches, out2.n_switches)
    # below and at grazing: no switch, the smooth map; above: the nonsmooth branch
    assert list(out1.n_switches[:2]) == [0, 0] and P1[1] == 1.0
    assert P1[0] < 1.0 and 1.0 - P1[0] < 1e-14
    assert out1.n_switches[2] == 2
    if theta < 0:
        assert 1.0 - P1[2] == pytest.approx(0.62 * 0.01, rel=0.01)   # the jump
    else:
        assert out1.sliding_time[2] > 0 and 0 < 1.0 - P1[2] < 1e-13  # continuous


def test_start_exactly_at_the_grazing_point_chooses_region_plus():
    # at p_g the + flow is tangent to H_s (b = 0); the driver must not slide or cross
    for theta in (-0.5, 0.5):
        system = hopf.model(0.01, theta, MU, OMEGA).full()
        traj = simulate(system, [-1.0, 0.0, -1.0], 0.05, dense=False)
        assert traj.mode == 1 and not traj.switches()
        assert traj.z[0] > -1.0


# ----------------------------------------------------------------------- many switches, Zeno
def test_chatter_with_1e5_switches_finishes_within_its_bound():
    eps, theta = 1e-4, -0.5
    orbit = chatter.orbit(eps, theta)
    n_half = 100_000
    cm = pseudo_equilibrium.compiled(eps, theta)
    z0 = [[orbit["x_switch"], orbit["y_switch"]]]
    out = fastmap.compute_returns(cm, z0, (n_half + 0.5) * orbit["period"] / 2,
                                  max_events=n_half + 10)
    assert out.status[0] == fastmap.NO_RETURN  # ran to t_max: neither bound nor Zeno hit
    assert out.n_switches[0] == n_half
    # still on the chatter orbit after 1e5 switches: no drift
    assert abs(out.state[0, 0]) <= orbit["x_switch"] * (1 + 1e-6)
    assert np.all(np.isfinite(out.state))


def test_event_bound_stops_endless_chatter_with_a_message():
    cm = pseudo_equilibrium.compiled(1e-4, -0.5)
    out = fastmap.compute_returns(cm, [[1e-3, 0.0]], 1e3, max_events=5_000)
    assert out.status[0] == fastmap.EVENT_LIMIT and out.n_switches[0] == 5_001


@pytest.mark.parametrize("eps", [1e-13, 1e-15])
def test_accumulating_switches_are_reported_as_zeno(eps):
    system = pseudo_equilibrium.model(eps, -0.5).full()
    with pytest.raises(ZenoError, match=r"accumulation of switches \(Zeno\) at t=.*: 64 switches within"):
        simulate(system, [10 * eps, 0.0], 1.0)
    out = fastmap.compute_returns(pseudo_equilibrium.compiled(eps, -0.5), [[10 * eps, 0.0]], 1.0)
    assert out.status[0] == fastmap.ZENO


# ----------------------------------------------------------------------- long runs
def test_ten_thousand_periods_stay_near_M_plus_without_drift():
    """Iterate the full 3-D return map 1e4 times just past grazing (mu = 1 + eps/2,
    theta < 0: a periodic orbit that visits region - every few turns). At each return
    the distance to M_+ is what the relaxation after the last switch leaves: an O(eps)
    jump decayed over the time 3 pi/(2 omega) from p_g to L1."""
    eps, theta = 0.01, -0.5
    cm = hopf.compiled(eps, theta, 1.0 + 0.5 * eps, OMEGA)
    z = np.array([[0.0, 1.02, 0.0]])
    res, x2, nsw = [], [], []
    for _ in range(10_000):
        out = fastmap.compute_returns(cm, z, T_MAX)
        assert out.status[0] == fastmap.OK
        z = out.state.copy()
        res.append(abs(z[0, 2] - z[0, 0])), x2.append(z[0, 1]), nsw.append(out.n_switches[0])
    res, x2, nsw = map(np.array, (res, x2, nsw))
    assert np.all(np.isfinite(x2)) and 0.95 < x2.min() and x2.max() < 1.03
    switched = nsw > 0
    assert switched.sum() > 1000                      # it keeps visiting region -
    assert np.all(nsw[switched] == 2)                 # in and out, no chatter
    level = eps * np.exp(-3 * np.pi / (2 * OMEGA * eps))
    ratio = res[switched] / level
    assert np.all((0.5 < ratio) & (ratio < 5)), (ratio.min(), ratio.max())
    assert np.all(res[~switched] < 1e-6 * level)      # no switch: decayed beyond all orders
    # no drift: the last thousand returns look like the first thousand
    assert res[-1000:][switched[-1000:]].max() < 10 * res[:1000][switched[:1000]].max()


# ----------------------------------------------------------------------- wrong inputs
@pytest.mark.parametrize("kwargs,field", [
    ({"eps": -1e-3, "theta": 0.5}, "eps"), ({"eps": 1e-3, "theta": 1.0}, "theta"),
    ({"eps": np.nan, "theta": 0.5}, "eps"), ({"eps": 1e-3, "theta": np.inf}, "theta")])
def test_wrong_parameters_are_rejected(kwargs, field):
    for make in (lambda: hopf.model(**kwargs), lambda: hopf.compiled(**kwargs),
                 lambda: pseudo_equilibrium.model(**kwargs),
                 lambda: pseudo_equilibrium.compiled(**kwargs)):
        with pytest.raises(ValueError, match=field):
            make()


def test_nan_initial_state_is_rejected():
    system = hopf.model(0.01, -0.5).full()
    with pytest.raises(ValueError, match="finite"):
        simulate(system, [0.0, np.nan, 0.0], 1.0)
    with pytest.raises(ValueError, match="finite"):
        fastmap.compute_returns(hopf.compiled(0.01, -0.5), [[0.0, np.nan, 0.0]], 1.0)


def test_chatter_formula_rejects_theta_without_a_chatter_orbit():
    for theta in (0.0, 0.5, 1.0, np.nan):
        with pytest.raises(ValueError, match="theta"):
            chatter.half_time(theta)


# ----------------------------------------------------------------------- tiny eps, O(1) travel
@pytest.mark.parametrize("eps", [1e-6, 1e-9, 1e-12])
def test_reference_driver_travels_order_one_at_tiny_eps_within_a_step_bound(eps):
    """After the fast relaxation of a mode entry (40 eps) exact flows are scanned
    at the slow step, so O(1) travel costs O(1) windows, not O(1/eps): a bound of
    200 windows (the eps-scale step alone would need 0.3 / (4 eps) of them) holds,
    and the orbit still meets H_s where it must and slides in."""
    theta = 0.6
    system = pseudo_equilibrium.model(eps, theta).full()
    traj = simulate(system, [0.3, 0.0], 0.5, dense=False, max_events=10, max_steps=200)
    assert [e.kind for e in traj.events[1:]] == ["slide_start"] and traj.mode == SLIDING
    hit = traj.events[1]
    assert hit.t == pytest.approx(0.3 + (1 - theta) * eps, rel=0, abs=1e-15)
    assert abs(hit.state[0] + (1 - theta) * eps) <= 1e-15 + 1e-9 * eps
    assert abs(traj.z[0]) < 1e-12 and np.all(np.isfinite(traj.z))


@pytest.mark.parametrize("theta", [-0.5, 0.5])
@pytest.mark.parametrize("eps", [1e-2, 1e-4])
def test_slow_windows_change_the_cost_not_the_result(theta, eps):
    """The Hopf map with and without the slow windows: same switches, same returns."""
    import dataclasses

    from filippov_paper.scenes.fig04_retmaps import section_L1

    fast_only = dataclasses.replace(hopf.model(eps, theta, MU, OMEGA).full(),
                                    slow_sample_step=np.nan)
    system = hopf.model(eps, theta, MU, OMEGA).full()
    assert np.isfinite(system.slow_sample_step) and system.transient_time == 40 * eps
    for x2 in (0.9, 0.99, 1.0 + 10 * eps ** 2, 1.001, 1.02):
        a = simulate(system, [0.0, x2, 0.0], T_MAX, sections=[section_L1()], dense=False)
        b = simulate(fast_only, [0.0, x2, 0.0], T_MAX, sections=[section_L1()], dense=False)
        assert a.status == b.status == "section:L1"
        # the events that change the mode; a touch (|H| <= touch_tol, no mode change)
        # just after a tangential slide exit is there or not by the last bits of the
        # exit state (x2 = 1.02, eps = 1e-4: slide ends 7e-15 apart, one run touches)
        kinds = lambda tr: [e.kind for e in tr.events if e.kind != "touch"]
        assert kinds(a) == kinds(b)
        np.testing.assert_allclose(a.z, b.z, rtol=0, atol=1e-13)
        assert a.t == pytest.approx(b.t, abs=1e-13)


def test_stiff_sliding_does_not_depend_on_the_blas_thread_count():
    # The implicit method's LU goes through OpenBLAS, whose multi-threaded path rounds
    # differently: the eps = 1e-4 return moved by 1.4e-15 between a Snakemake job (one
    # thread) and a plain process (scipy's Radau then). The driver runs the implicit
    # steps on one BLAS thread.
    import os
    import subprocess
    import sys
    code = ("from filippov_paper import hard_cases; r = hard_cases.sliding_return(1e-4); "
            "print(repr(r['return_P']), r['return_steps'], r['return_stiff'])")
    out = set()
    for threads in ("1", "2"):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads)
        run = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True,
                             text=True, check=True)
        out.add(run.stdout)
    assert len(out) == 1 and out.pop().split()[2] == "1", out
