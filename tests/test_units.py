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
tolerances differ by less than 1e-10 on these systems). dP/dz differs by the truncation of
central differences at steps that differ by that ratio (~eps^(2/3) relative to the
factors' product, as in test_properties' TOL_JAC): TOL_UNITS_JAC.
"""
import numpy as np
import pytest
from hypothesis import given, settings

import generated_systems as gs
from filippov import (FilippovSystem, PeriodicOrbitError, first_returns, periodic_orbit,
                      return_jacobian, simulate)
from filippov.scale import DEAD_BAND, UNIT, Scale, declared, measure, power_of_two

ENGINES = ("compiled", "reference")
FLOWS = ("exact", "integrate")
#: (state unit, time unit)
UNITS = ((1e-6, 1.0), (1e6, 1.0), (1.0, 1e-6), (1.0, 1e6))
TOL_UNITS = 1e-10
TOL_UNITS_JAC = 1e-8


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
    assert ku == k
    _same(Pu * state, P, TOL_UNITS, "return point")
    _same(tu * time, t, TOL_UNITS, "return time")
    _same(t1u * time, t1, TOL_UNITS, "first switch")
    # dP/dz is dimensionless when every component has the same unit; time does not enter
    # (none where P has a kink: a start on H)
    if not kinked:
        _same(Ju, J, TOL_UNITS_JAC, "dP/dz", scale=jac_scale)


@pytest.mark.parametrize("units", UNITS)
@pytest.mark.parametrize("flows", FLOWS)
@pytest.mark.parametrize("engine", ENGINES)
@settings(max_examples=4)
@given(case=gs.crossings())
def test_a_crossing_in_other_units_returns_where_it_did(engine, flows, units, case):
    _in_other_units(case, engine, flows, units, max(1.0, case.scale), case.dP is None)


@pytest.mark.parametrize("units", UNITS)
@pytest.mark.parametrize("flows", FLOWS)
@pytest.mark.parametrize("engine", ENGINES)
@settings(max_examples=4)
@given(case=gs.slides())
def test_a_slide_in_other_units_returns_where_it_did(engine, flows, units, case):
    _in_other_units(case, engine, flows, units, max(1.0, case.scale), case.on_h)


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
    _same(got.jacobian, want.jacobian, TOL_UNITS_JAC, "dP/dz")
    # an eigenvalue moves by at most the condition number of the eigenvector matrix times
    # the change of the matrix (Bauer-Fike)
    cond = np.linalg.cond(np.linalg.eig(want.jacobian)[1])
    for part in (np.real, np.imag):
        _same(part(np.sort_complex(got.multipliers)), part(np.sort_complex(want.multipliers)),
              TOL_UNITS_JAC * cond, "multipliers")


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


def test_a_batch_takes_one_scale_from_its_largest_start():
    from filippov.fastmap import batch_scale

    cm = _rotor().compiled(lambda z, p: z[0], direction=1)
    sc = batch_scale(cm, np.array([[1e-9, 0.0], [3e-6, 0.0]]))
    assert sc.state == 2.0 ** -18 and sc.how == "measured"
    assert DEAD_BAND >= 2.0
    for engine in ENGINES:
        # from the section once round (the rotor is integrated: DOP853 at atol 1e-14 S);
        # with the unit scale the times were off by 2e-10 (3e-6) and 7e-7 (1e-9)
        out = first_returns(_rotor(), [[0.0, -1e-6], [0.0, -3e-6]], lambda z, p: z[0],
                            10.0, direction=1, engine=engine)
        assert np.allclose(out.time, 2 * np.pi, rtol=TOL_UNITS, atol=0), out.time


def _wrapped(z, p):
    # an angle wrapped by a loop: asked at 2^300 it would never return
    th = z[0]
    while th > np.pi:
        th -= 2.0 * np.pi
    if abs(z[1]) > 10.0:
        raise ValueError("outside the table")
    return np.array([1.0, np.cos(th) - 0.5 * z[1]])


@pytest.mark.parametrize("engine", ENGINES)
def test_measuring_the_scale_never_fails_nor_hangs_a_run(engine):
    # the measurement probes the fields away from the start: a probe that raises or is
    # not finite tells nothing, and the probes stay within 2^20 of the start's size
    from filippov.scale import measure_system

    fs = FilippovSystem(("th", "v"), _wrapped, _wrapped, lambda z, p: z[1] - 5.0,
                        lambda z, p: np.array([0.0, 1.0]))
    out = first_returns(fs, [[0.0, 0.0]], lambda z, p: z[0] - 3.0, 10.0, direction=1,
                        engine=engine)
    assert out.time[0] == pytest.approx(3.0, rel=1e-12)
    bad = lambda z: np.array([np.nan, 1.0]) if z[0] != 0.0 else np.array([1.0, 1.0])  # noqa: E731
    sc = measure_system(np.zeros(2), bad, bad, lambda z: np.array([0.0, 1.0]))
    assert sc.state == 1.0
    boom = lambda z: 1 / 0  # noqa: E731
    assert measure_system(np.array([3e-6, 0.0]), boom, boom, boom).state == 2.0 ** -18
