"""The same system in other units gives the same results (issue 57, item 2;
docs/decisions.md#units, filippov.scale).

Every generated system of tests/generated_systems.py is run as it is and rescaled in
closed form (gs.rescaled: its state in units 1e-6 and 1e6 times as large, or its time),
on both engines, with exact flows and integrated, with the default options: the return
point, its time, the first switch and dP/dz come back to the unscaled ones (mapped back to
the unscaled units). Before the scales (atol, touch_tol, event_xtol absolute; central
differences stepping from 1) state units 1e-6 moved times by 5.7e-8, periods by 2.4e-6
and dP/dz by 2.5e-7 relative.

Tolerances: the rescaled run is the unscaled one with its tolerances moved by the ratio of
the two measured scales (powers of two: at most a factor 2 DEAD_BAND), so the two differ
by the integration's error, not by rounding: TOL_UNITS (1e-10) for exact flows (rounding
of the closed forms, events refined to 1e-15 of the time scale) and for integrated stays
(DOP853 at rtol 1e-12 over t <= 16 on states of order one: its global errors at nearby
tolerances differ by less than 1e-10 on these systems). dP/dz and the multipliers are held
to the same 1e-10 on both engines (relative to the product of dP/dz's factors' norms; the
multipliers times the conditioning of their eigenvectors). The reference's section
gradient steps eps^(1/3) (variational.SECTION_STEP: at 1e-7 its rounding alone moved dP/dz
by 3e-10); measured, 5.4e-12 at most. The compiled engine differentiates the exact flows
and the section by Richardson's extrapolation of two central differences
(rules.richardson_step); measured over 12 relays and 4 units, 2.4e-11 at most for a
periodic orbit (one central difference of step eps^(1/3) had left 4.5e-9, the closed
forms' rounding divided by the step).
"""
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import generated_systems as gs
from filippov import (FilippovSystem, PeriodicOrbitError, first_returns, periodic_orbit,
                      return_jacobian, simulate)
from filippov.scale import DEAD_BAND, UNIT, Scale, declared, measure, power_of_two

ENGINES = ("compiled", "reference")
FLOWS = ("exact", "integrate")
#: (state unit, time unit)
UNITS = ((1e-6, 1.0), (1e6, 1.0), (1.0, 1e-6), (1.0, 1e6))
TOL_UNITS = 1e-10
TOL_UNITS_JAC = 1e-10

def _return(n, engine, flows, z0, p, time_unit=1.0):
    """One return of z0 to the section h = sigma, upwards: (P, time, first switch,
    switches, dP/dz)."""
    fs = gs.system(n, flows == "exact", time_unit)
    gs.load(fs, p)
    if engine == "compiled":
        from filippov.fastmap import OK, compute_returns, failure

        cm = fs.compiled(gs.section, direction=1)
        out = compute_returns(cm, [z0], gs.T_MAX / time_unit, jacobian=True)
        assert out.status[0] == OK, failure(cm, out, 0)
        return (out.state[0], float(out.time[0]), float(out.first_switch[0]),
                int(out.n_switches[0]), out.jacobian[0])
    python, sec = fs.python(), fs.python_section(gs.section, direction=1)
    traj = simulate(python, z0, gs.T_MAX / time_unit, sections=[sec], dense=False,
                    method=flows)
    assert traj.status == f"section:{sec.name}", traj.status
    sw = traj.switches()
    return (np.asarray(traj.z), traj.t - traj.t0, sw[0].t - traj.t0 if sw else np.nan,
            len(sw), return_jacobian(python, traj, sec, jacobian=fs.jacobian))


def _same(got, want, tol, what, scale=None):
    got, want = np.asarray(got, dtype=float), np.asarray(want, dtype=float)
    assert np.array_equal(np.isnan(got), np.isnan(want)), (what, got, want)
    if np.all(np.isnan(want)):
        return
    scale = max(1.0, float(np.nanmax(np.abs(want)))) if scale is None else scale
    err = float(np.nanmax(np.abs(got - want)))
    assert err <= tol * scale, f"{what}: {got.tolist()} against {want.tolist()} ({err:.3g})"


def _in_other_units(case, engine, flows, units, jac_scale, kinked):
    state, time = units
    n, z0, p = case.g.n, np.asarray(case.z0, dtype=float), case.g.p
    P, t, t1, k, J = _return(n, engine, flows, z0, p)
    Pu, tu, t1u, ku, Ju = _return(n, engine, flows, z0 / state, gs.rescaled(p, n, state, time),
                                  time)
    _same(Pu * state, P, TOL_UNITS, "return point")
    _same(tu * time, t, TOL_UNITS, "return time")
    if kinked and ku != k:
        # a start on H up to rounding (|h(z0)| ~ 1e-17): one run reads it as on H (within
        # touch_tol x G) and slides from t = 0, the other as a rounding off H and slides
        # in at once -- one switch more, at t ~ 0, and the same return. G is not the same
        # in both units: the fields' length lifts S only up to 1 (filippov.scale)
        extra = t1u * time if ku > k else t1
        assert abs(ku - k) == 1 and extra <= 1e-12, (k, ku, t1, t1u * time)
        return
    assert ku == k
    _same(t1u * time, t1, TOL_UNITS, "first switch")
    # dP/dz is dimensionless when every component has the same unit; time does not enter
    # (none where P has a kink: a start on H)
    if not kinked:
        _same(Ju, J, TOL_UNITS_JAC, "dP/dz", scale=jac_scale)


#: a generated return and whether its P has a kink there (no dP/dz compared)
RETURNS = {"crossing": (gs.crossings, lambda case: case.dP is None),
           "slide": (gs.slides, lambda case: case.on_h)}


@pytest.mark.parametrize("units", UNITS)
@pytest.mark.parametrize("flows", FLOWS)
@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("kind", sorted(RETURNS))
@settings(max_examples=4)
@given(data=st.data())
def test_a_return_in_other_units_comes_back_where_it_did(kind, engine, flows, units, data):
    cases, kinked = RETURNS[kind]
    case = data.draw(cases())
    _in_other_units(case, engine, flows, units, max(1.0, case.scale), kinked(case))


@pytest.mark.parametrize("units", UNITS)
@pytest.mark.parametrize("engine", ENGINES)
@settings(max_examples=3)
@given(case=gs.relays())
def test_a_relay_orbit_in_other_units_has_its_period_and_multipliers(engine, units, case):
    """periodic_orbit (exact flows) in other units: the fixed point, the period and the
    Floquet multipliers of the unscaled orbit."""
    state, time = units
    n = case.g.n
    guess = case.x0 + 1e-3 * np.cos(np.arange(n))

    def orbit(p, unit_state, unit_time):
        fs = gs.system(n, True, unit_time)
        gs.load(fs, p)
        return periodic_orbit(fs, guess / unit_state, gs.section, direction=+1,
                              engine=engine, t_max=(1.5 * case.period + 1.0) / unit_time)
    try:
        want = orbit(case.g.p, 1.0, 1.0)
    except PeriodicOrbitError as exc:   # the start itself (test_properties): not this test's
        assert "the start itself" in str(exc)
        return
    got = orbit(gs.rescaled(case.g.p, n, state, time), state, time)
    _same(got.point * state, want.point, TOL_UNITS, "fixed point")
    _same(got.period * time, want.period, TOL_UNITS, "period")
    tol = TOL_UNITS_JAC
    _same(got.jacobian, want.jacobian, tol, "dP/dz")
    # an eigenvalue moves by at most the condition number of the eigenvector matrix times
    # the change of the matrix (Bauer-Fike)
    cond = np.linalg.cond(np.linalg.eig(want.jacobian)[1])
    for part in (np.real, np.imag):
        _same(part(np.sort_complex(got.multipliers)), part(np.sort_complex(want.multipliers)),
              tol * cond, "multipliers")


# ----------------------------------------------------------------------------- the scale
def test_measured_scales_are_powers_of_two_and_one_near_one():
    assert power_of_two(3e-6) == 2.0 ** -18 and power_of_two(5e5) == 2.0 ** 19
    for x in (1.0, 0.07, 15.0, 0.0, np.nan, np.inf, -3.0):
        assert power_of_two(x) == 1.0
    assert power_of_two(1e-300) == 2.0 ** -300   # clamped: tolerances stay normal floats
    sc = measure(np.array([3e-6, -1e-7]), (np.array([2e-6, 0.0]), np.array([0.0, 1e-9])),
                 np.array([0.0, 2e5]))
    assert (sc.state, sc.time, sc.switch) == (2.0 ** -18, 1.0, 1.0)
    assert measure(np.array([1e6, 0.0])).time == 1.0   # no field: no time scale measured


@pytest.mark.parametrize("bad, field", [(0.0, "scale.state"), (-1.0, "scale.state"),
                                        ({"time": np.nan}, "scale.time"),
                                        ({"switch": "1"}, "scale.switch"),
                                        (True, "scale.state")])
def test_a_bad_scale_is_refused_by_name(bad, field):
    with pytest.raises(ValueError, match=field.replace(".", r"\.")):
        FilippovSystem(("x",), lambda z, p: -z, lambda z, p: -z, lambda z, p: z[0],
                       lambda z, p: np.ones(1), scale=bad)
    with pytest.raises(ValueError, match="unknown part"):
        declared({"length": 1.0})


def _rotor(scale=None):
    # x' = -y, y' = x (a rotation) split by y = 0 with the same field on both sides
    f = lambda z, p: np.array([-z[1], z[0]])  # noqa: E731
    return FilippovSystem(("x", "y"), f, f, lambda z, p: z[1],
                          lambda z, p: np.array([0.0, 1.0]), scale=scale)


def test_a_declared_scale_is_the_one_used_and_the_paper_models_declare_unit():
    from filippov.models import dry_friction, hopf, pseudo_equilibrium

    traj = simulate(_rotor(1e-6), [1e-6, 0.0], 1.0)
    # H = y: in states of size 1e-6 its values are that small too (2^-20 measured)
    assert traj.scale == Scale(1e-6, 1.0, 2.0 ** -20, "declared+measured")
    assert simulate(_rotor(), [1e-6, 0.0], 1.0).scale.state == 2.0 ** -20
    assert simulate(_rotor(UNIT), [1e-6, 0.0], 1.0).scale == UNIT
    assert simulate(_rotor(), [1e-6, 0.0], 1.0, scale=UNIT).scale == UNIT
    # the paper's models are written in units of their own size: their runs, and with
    # them the paper's data, are those of before the scales
    for fs in (hopf.system(1e-3, 0.2), dry_friction.system(1e-3, 1.5),
               pseudo_equilibrium.system(1e-3, 0.2)):
        assert fs.scale is UNIT and fs.python().scale is UNIT
        assert fs.compiled(lambda z, p: z[0]).scale is UNIT


@pytest.mark.parametrize("engine", ENGINES)
def test_newton_that_runs_away_from_its_guess_says_so(engine):
    # a slow spiral about (X, 0), X = 1e4: on the section y = 0 (downwards, at x < X) the
    # return map is affine, P(x) = X + e^{2 pi a} (x - X), slope 1 + 6.3e-6, and its only
    # fixed point is the focus itself, where Newton lands in one step from the guess x = 1:
    # 1e4 times the guess's size away. Said as such (H = y - 1e9 is never reached)
    X, a = 1e4, 1e-6
    f = lambda z, p: np.array([a * (z[0] - X) - z[1], (z[0] - X) + a * z[1]])  # noqa: E731
    fs = FilippovSystem(("x", "y"), f, f, lambda z, p: z[1] - 1e9,
                        lambda z, p: np.array([0.0, 1.0]), scale=1.0)
    # (declared: in units of order one. Measured, the field's length is the spiral's
    # radius 1e4, and a step to its centre is no runaway in those units)
    with pytest.raises(PeriodicOrbitError, match="ran away from the guess"):
        periodic_orbit(fs, [1.0, 0.0], lambda z, p: z[1], direction=-1, engine=engine,
                       t_max=20.0)


def test_a_batch_takes_the_smaller_scale_of_its_smallest_and_largest_starts():
    from filippov.fastmap import batch_scale

    cm = _rotor().compiled(lambda z, p: z[0], direction=1)
    sc = batch_scale(cm, np.array([[1e-9, 0.0], [3e-6, 0.0], [1e-7, 0.0]]))
    assert sc.state == 2.0 ** -30 and sc.how == "measured"
    assert batch_scale(cm, np.array([[3e-6, 0.0]])).state == 2.0 ** -18
    assert DEAD_BAND >= 2.0
    for engine in ENGINES:
        # from the section once round (the rotor is integrated: DOP853 at atol 1e-14 S);
        # with the unit scale the times were off by 2e-10 (3e-6) and 7e-7 (1e-9)
        out = first_returns(_rotor(), [[0.0, -1e-6], [0.0, -3e-6]], lambda z, p: z[0],
                            10.0, direction=1, engine=engine)
        assert np.allclose(out.time, 2 * np.pi, rtol=TOL_UNITS, atol=0), out.time


def _swirl():
    # a rotation at rate 1 (region -) or 2 (region +) damped by d(r) = 0.3 r^2/(1e-6 + r^2):
    # its length near r = 2e-3 is far below that near r = 40 (a review's reproducer)
    def field(w):
        def f(z, p):
            d = 0.3 * (z[0] ** 2 + z[1] ** 2) / (1e-6 + z[0] ** 2 + z[1] ** 2)
            return np.array([-w * z[1] - d * z[0], w * z[0] - d * z[1]])
        return f
    return FilippovSystem(("x", "y"), field(1.0), field(2.0), lambda z, p: z[0],
                          lambda z, p: np.array([1.0, 0.0]))


@pytest.mark.parametrize("engine", ENGINES)
def test_a_small_start_beside_a_large_one_returns_as_it_does_alone(engine):
    # the largest start's scale alone (2^5) put the return time of the start at 2e-3 off
    # by 1.3e-10 and its dP/dz by 1.1%
    fs, section = _swirl(), lambda z, p: z[1]
    both = first_returns(fs, [[2e-3, 0.0], [40.0, 0.0]], section, 50.0, direction=1,
                         engine=engine)
    alone = first_returns(fs, [[2e-3, 0.0]], section, 50.0, direction=1, engine=engine)
    assert both.time[0] == pytest.approx(alone.time[0], rel=TOL_UNITS, abs=0)
    assert np.allclose(both.state[0], alone.state[0], rtol=TOL_UNITS, atol=0)


def test_dp_dz_of_a_small_start_beside_a_large_one_is_that_alone():
    from filippov.fastmap import compute_returns

    cm = _swirl().compiled(lambda z, p: z[1], direction=1)
    both = compute_returns(cm, [[2e-3, 0.0], [40.0, 0.0]], 50.0, jacobian=True)
    alone = compute_returns(cm, [[2e-3, 0.0]], 50.0, jacobian=True)
    # central differences at the same steps: the same to rounding over the step
    assert np.allclose(both.jacobian[0], alone.jacobian[0], rtol=0, atol=1e-7)


def test_a_sweep_measures_each_start_with_its_own_model():
    from filippov.fastmap import batch_scale

    import dataclasses

    # a rotation at rate k: its time scale is 1/k
    f = lambda z, p: p[0] * np.array([-z[1], z[0]])  # noqa: E731
    cm = FilippovSystem(("x", "y"), f, f, lambda z, p: z[1] - 1e3,
                        lambda z, p: np.array([0.0, 1.0]),
                        params=(1.0,)).compiled(lambda z, p: z[0], direction=1)
    starts = np.array([[1.0, 0.0], [2.0, 0.0]])
    slow, fast = cm, dataclasses.replace(cm, params=np.array([1e6]))
    assert batch_scale([slow, fast], starts).time == batch_scale(fast, starts[1:]).time
    assert batch_scale([slow, fast], starts).time < 1e-5


def _circle(r):
    # inside: rotation, growth and a drift c r (F_- is not 0 at the centre); outside:
    # rotation and decay; on the circle of radius r both push onto it: a slide at rate 1
    a, b, c = 0.5, 1.0, 0.3
    fm = lambda z, p: np.array([-z[1] + a * z[0] + c * r, z[0] + a * z[1]])  # noqa: E731
    fp = lambda z, p: np.array([-z[1] - b * z[0], z[0] - b * z[1]])  # noqa: E731
    return FilippovSystem(("x", "y"), fm, fp, lambda z, p: z[0] ** 2 + z[1] ** 2 - r * r,
                          lambda z, p: 2.0 * np.asarray(z))


@pytest.mark.parametrize("engine", ENGINES)
def test_a_start_where_grad_h_vanishes_measures_h_away_from_it(engine):
    # from the centre of a circle of radius 1e-6, where grad H = 0: G from grad H at
    # the start alone was 1 and touch_tol absolute again (1e-15 against values of H of
    # 1e-12: a review lost a slide to two touches so); now G is H's change over S
    r = 1e-6
    assert simulate(_circle(r), [0.0, 0.0], 1.0).scale.switch == 2.0 ** -43
    sec = lambda z, p: z[1]   # noqa: E731 -- the first upward crossing of y = 0 at x > 0
    where = lambda z, p: z[0] > 0   # noqa: E731
    got = first_returns(_circle(r), [[0.0, 0.0]], sec, 20.0, direction=1, where=where,
                        engine=engine, min_time=1.0)
    want = first_returns(_circle(1.0), [[0.0, 0.0]], sec, 20.0, direction=1, where=where,
                         engine=engine, min_time=1.0)
    assert got.sliding_time[0] > 1.0
    assert got.sliding_time[0] == pytest.approx(want.sliding_time[0], rel=1e-9)
    assert np.allclose(got.state[0] / r, want.state[0], rtol=0, atol=1e-10)
    assert got.time[0] == pytest.approx(want.time[0], rel=1e-10)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_start_next_to_an_equilibrium_is_no_zeno(engine):
    # a focus at (1, 0) split by H = x - 1; from 1e-13 above it the start's speed is 1e-13,
    # and S / speed made T = 2^44: a chatter-free orbit of 64 switches in 150 time units
    # was refused as Zeno
    fm = lambda z, p: np.array([z[1], -(z[0] - 1) + 0.3 * z[1]])  # noqa: E731
    fp = lambda z, p: np.array([z[1], -4 * (z[0] - 1) + 0.1 * z[1]])  # noqa: E731
    fs = FilippovSystem(("x", "y"), fm, fp, lambda z, p: z[0] - 1.0,
                        lambda z, p: np.array([1.0, 0.0]))
    # (the spiral grows at rate 0.05 to 0.15: y = 0.5 after about 100 switches)
    out = first_returns(fs, [[1.0, 1e-13]], lambda z, p: z[1] - 0.5, 600.0, direction=1,
                        engine=engine)
    assert out.n_switches[0] > 64 and out.time[0] > 150.0


def test_a_switching_function_at_a_nanometre_passes_its_gradient_check():
    # H = y - r sin(x / r), r = 1e-9: the gradient check stepped from max(1, |z0|), far
    # beyond the surface's wiggles, and refused a correct switch_grad
    r = 1e-9
    f = lambda z, p: np.array([1e-9, -1e-9])  # noqa: E731
    fs = FilippovSystem(("x", "y"), f, f, lambda z, p: z[1] - r * np.sin(z[0] / r),
                        lambda z, p: np.array([-np.cos(z[0] / r), 1.0]))
    traj = simulate(fs, [0.0, 2e-9], 5.0)
    assert traj.status == "t_end" and traj.switches()


def test_fixed_points_of_a_map_in_micrometres_skip_its_jumps():
    from filippov.poincare import fixed_points

    um = 1e-6
    # a jump of 1e-4 of the map's size: 1e-10 was below the absolute 1e-9 of before
    jump = lambda x: x + 1e-4 * um * np.sign(x - 0.5 * um)  # noqa: E731 -- no fixed point
    grid = np.linspace(0.12, 0.92, 9) * um
    assert fixed_points(grid, jump(grid), refine=jump).size == 0
    line = lambda x: 0.5 * x + 0.25 * um   # noqa: E731 -- fixed at 0.5 um
    got = fixed_points(grid, line(grid), refine=line)
    assert got.size == 1 and got[0] == pytest.approx(0.5 * um, rel=1e-12, abs=0)


def test_newton_of_the_continuation_converges_in_the_unknowns_units():
    from filippov.continuation import newton

    a = 1e-9   # u^2 = a^2 from 2a: steps below 1e-12 absolute came at 4.6e-8 relative
    u, _ = newton(lambda u: u * u - a * a, lambda u: np.diag(2.0 * u), np.array([2 * a]),
                  floor=a)
    assert u[0] == pytest.approx(a, rel=1e-14, abs=0)
    # the default floor stays 1: the guess's size cannot tell the unknowns' scale (a small
    # guess near a root at 0 of a residual with terms of order one never met a test at
    # its own size; a review's reproducer)
    G = lambda u: np.array([np.cos(u[0]) - 1 + u[0] + 0.3 * u[1], u[1] - 0.5 * u[0]])  # noqa: E731
    J = lambda u: np.array([[1 - np.sin(u[0]), 0.3], [-0.5, 1.0]])  # noqa: E731
    assert np.abs(newton(G, J, [1e-6, 1e-6])[0]).max() < 1e-12


def _sine_wall(a, good=True):
    # H = y - a/2 sin(x/a) crossed by F_- = (1, 1), F_+ = (1, -1): a slide along a wiggly
    # wall; zero Jacobians, so the sliding Jacobian is the curvature of H alone
    grad = ((lambda z, p: np.array([-0.5 * np.cos(z[0] / a), 1.0])) if good
            else (lambda z, p: np.array([0.0, 1.0])))
    return FilippovSystem(("x", "y"), lambda z, p: np.array([1.0, 1.0]),
                          lambda z, p: np.array([1.0, -1.0]),
                          lambda z, p: z[1] - 0.5 * a * np.sin(z[0] / a), grad,
                          jacobians={"minus": lambda z, p: np.zeros((2, 2)),
                                     "plus": lambda z, p: np.zeros((2, 2))})


def test_a_sliding_jacobian_does_not_depend_on_what_was_asked_before():
    # a review's reproducer: a kept first scale made the sliding Jacobian's difference
    # step depend on the first state ever asked (-0.402 against -0.495 for dz/dz0)
    from filippov import transition_matrix
    from filippov.system import SLIDING

    a, z = 1e-3, np.array([0.0, 0.0])
    fresh = _sine_wall(a).jacobian(SLIDING, z)
    fs = _sine_wall(a)
    transition_matrix(fs, simulate(fs, [100.0, -1.0], 2.0))   # an orbit far away first
    assert np.array_equal(fs.jacobian(SLIDING, z), fresh)
    traj = simulate(fs, [0.0, -2e-4], 3e-3)
    got = transition_matrix(fs, traj)
    want = transition_matrix(_sine_wall(a), simulate(_sine_wall(a), [0.0, -2e-4], 3e-3))
    assert np.array_equal(got, want)


def test_the_gradient_check_steps_from_the_start_not_from_a_huge_field_length():
    # a nearly uniform field (length 1e6) made S = 2^20, and the gradient check stepped
    # over H's wiggles: it refused a correct switch_grad and took a wrong one
    w = 2 * np.pi * 50
    fm = lambda z, p: np.array([1.0, -1e-6 * z[1]])  # noqa: E731
    fp = lambda z, p: np.array([1.0, -1e-6 * z[1] - 1e-3])  # noqa: E731
    H = lambda z, p: z[1] - 0.5 - 0.01 * np.sin(w * z[0])  # noqa: E731
    good = lambda z, p: np.array([-0.01 * w * np.cos(w * z[0]), 1.0])  # noqa: E731
    bad = lambda z, p: np.array([0.0, 1.0])  # noqa: E731
    traj = simulate(FilippovSystem(("t", "y"), fm, fp, H, good), [0.0, 0.4], 1.0)
    assert traj.scale.state == 1.0 and traj.status == "t_end"
    from filippov.checks import SystemContractError
    with pytest.raises(SystemContractError, match="switch_grad does not match"):
        simulate(FilippovSystem(("t", "y"), fm, fp, H, bad), [0.0, 0.4], 1.0)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_steep_switching_function_crosses_where_it_crosses(engine):
    # H = exp(k (x - 1)) - 1, k = 50, is steep beyond H = 0: G from its gradient a
    # distance S away was 4.4e12 (touch_tol 4.4e-3), and an orbit that crosses H (to
    # H = +1e-3) was taken for a touch and came back round its circle unswitched
    k = 50.0
    fs = FilippovSystem(("x", "y"), lambda z, p: np.array([-z[1], z[0] - 0.5]),
                        lambda z, p: np.array([1.0, 1.0]),
                        lambda z, p: np.exp(k * (z[0] - 1)) - 1,
                        lambda z, p: np.array([k * np.exp(k * (z[0] - 1)), 0.0]))
    assert simulate(fs, [0.5, -0.50002], 1.0).scale.switch < 1e-9   # grad H at the start
    # it switches to F_+ and leaves: no return (or H, or first its gradient, overflows on
    # the way out)
    with pytest.raises(Exception, match="did not return|switch(_grad)? returned a non-finite"):
        first_returns(fs, [[0.5, -0.50002]], lambda z, p: z[0] - 0.5, 20.0, direction=1,
                      engine=engine)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_start_too_small_for_any_scale_is_refused_by_name(engine):
    # an oscillator started at (1e-300, 0): S is clamped at 2^-300 = 4.9e-91, far above
    # the state, and the reference returned at t = 2.72 for 4.71 while the compiled
    # engine raised ZeroDivisionError (a review's reproducer); with the unit scale
    # declared the run is the user's to judge
    fs = FilippovSystem(("x", "v"), lambda z, p: np.array([z[1], -z[0]]),
                        lambda z, p: np.array([z[1], -4 * z[0]]), lambda z, p: z[0],
                        lambda z, p: np.array([1.0, 0.0]))
    with pytest.raises(ValueError, match=r"initial state: its size 1e-300 .* outside "
                                         r"2\^-300 \.\. 2\^300"):
        first_returns(fs, [[1e-300, 0.0], [1.0, 0.0]], lambda z, p: z[1], 100.0,
                      direction=-1, engine=engine)
    with pytest.raises(ValueError, match="initial state: its size 1e-300"):
        simulate(fs, [1e-300, 0.0], 1.0)
    out = first_returns(fs, [[1e-9, 0.0]], lambda z, p: z[1], 100.0, direction=-1,
                        engine=engine)
    assert out.time[0] == pytest.approx(1.5 * np.pi, rel=1e-10)
