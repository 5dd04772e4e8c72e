"""Issue 28: the end of sliding where the exit condition holds only between two samples.

While sliding, the engines sample the normal speeds a = dh.F_- and b = dh.F_+; a window
where b > 0 (or a < 0) shorter than the sample spacing shows no sign change at the
samples, and a sliding run stepped over it: the orbit stayed on H, and the return came
out silently wrong. Now each sample interval is also checked for an extremum of a or b
toward its exit between the samples (rules.speed_extremum_between, from the speeds'
rates along the orbit), which is refined and classified like a hidden extremum of h
(rules.speed_graze): beyond touch_tol's reach an exit, within it a touch, else nothing.

The system, u = (x, y, s, w):

    h = x;   F_- = (1, g, 1, K y),   F_+ = (y, g, 1, K y^2),   g = -c (s - t*).

a = 1 > 0 and b = y, so H slides where y < 0, with x' = 0 and w' = (y K y^2 - y K y)/(1 - y)
= 0. s = t and y = m - (c/2)(t - t*)^2 in every mode. From x0 = -delta the orbit reaches
H at t1 = delta (w = K int_0^delta y) and slides. For m > 0, b > 0 on the window of
length L = 2 sqrt(2m/c) around t*: the slide ends at t_e = t* - L/2, x = int y returns
to 0 at t_r = t_e + 3L/2 (downward, where a > 0: sliding again) and w gains
K int y^2 = K (c^2/4) 0.1125 L^5 on the way. The section is s = T. A run that steps over
the window slides on: one switch instead of three, T - t1 slid instead of
T - t1 - 3L/2, w short of the excursion's gain.
"""
import math

import numpy as np
import pytest
from numba import njit

from filippov import FilippovSystem, rules, simulate
from filippov.kernel import base as kernel
from filippov.poincare import sliding_time
from filippov.system import MINUS, PLUS, SLIDING

DELTA = 0.005
K = 1000.0
TSTAR = 1.0
T = TSTAR + 2.5


@njit(cache=True)
def field_minus(z, p):
    return np.array([1.0, -p[0] * (z[2] - p[2]), 1.0, p[3] * z[1]])


@njit(cache=True)
def field_plus(z, p):
    return np.array([z[1], -p[0] * (z[2] - p[2]), 1.0, p[3] * z[1] * z[1]])


@njit(cache=True)
def _ints(z0, tau, p):
    """y(tau), int_0^tau y, int_0^tau y^2 from z0 (y = al + be tau + ga tau^2)."""
    al, be, ga = z0[1], -p[0] * (z0[2] - p[2]), -0.5 * p[0]
    y = al + be * tau + ga * tau * tau
    iy = al * tau + be * tau ** 2 / 2 + ga * tau ** 3 / 3
    iy2 = (al * al * tau + al * be * tau ** 2 + (be * be + 2 * al * ga) * tau ** 3 / 3
           + be * ga * tau ** 4 / 2 + ga * ga * tau ** 5 / 5)
    return y, iy, iy2


@njit(cache=True)
def flow_minus(z0, tau, p):
    y, iy, _ = _ints(z0, tau, p)
    return np.array([z0[0] + tau, y, z0[2] + tau, z0[3] + p[3] * iy])


@njit(cache=True)
def flow_plus(z0, tau, p):
    y, iy, iy2 = _ints(z0, tau, p)
    return np.array([z0[0] + iy, y, z0[2] + tau, z0[3] + p[3] * iy2])


@njit(cache=True)
def switch(z, p):
    return z[0]


@njit(cache=True)
def switch_grad(z, p):
    return np.array([1.0, 0.0, 0.0, 0.0])


@njit(cache=True)
def section(z, p):
    return z[2] - p[1]


def _case(c, m):
    """(p, z0, closed form) for the curvature c of b = y and its maximum m (m > 0: an
    exit window of length L; m = 0: b touches 0 at t*; m < 0: no exit)."""
    p = np.array([c, T, TSTAR, K])
    y0 = m - c * TSTAR ** 2 / 2
    z0 = np.array([-DELTA, y0, 0.0, 0.0])
    iy_minus = m * DELTA - (c / 6) * ((DELTA - TSTAR) ** 3 + TSTAR ** 3)
    yT = m - c * (T - TSTAR) ** 2 / 2
    want = dict(t1=DELTA, w1=K * iy_minus, yT=yT)
    if m > 0:
        L = 2 * math.sqrt(2 * m / c)
        te, tr = TSTAR - L / 2, TSTAR + L
        want.update(L=L, te=te, tr=tr, slid=(te - DELTA) + (T - tr), n=3,
                    P=np.array([0.0, yT, T, K * (iy_minus + (c * c / 4) * 0.1125 * L ** 5)]))
    else:
        want.update(slid=T - DELTA, n=1, P=np.array([0.0, yT, T, K * iy_minus]))
    return p, z0, want


_SYSTEMS = {}


def _system(p, exact):
    key = (tuple(p), exact)
    if key not in _SYSTEMS:
        flows = (dict(flow_minus=flow_minus, flow_plus=flow_plus, sample_step=0.05)
                 if exact else {})
        _SYSTEMS[key] = FilippovSystem(("x", "y", "s", "w"), field_minus, field_plus, switch,
                                       switch_grad, params=p, name="hidden_exit", **flows)
    return _SYSTEMS[key]


def _run(engine, flows, c, m, jacobian=False):
    """dict(n, first, time, P, slid, events [(kind, t, mode_before, mode_after)] or None,
    jac): default samples_per_step throughout."""
    p, z0, want = _case(c, m)
    fs = _system(p, flows == "exact")
    if engine == "compiled":
        from filippov.fastmap import OK, compute_returns, failure

        out = compute_returns(fs.compiled(section, direction=+1), [z0], 2 * T,
                              jacobian=jacobian)
        assert out.status[0] == OK, failure(fs.compiled(section, direction=+1), out, 0)
        return dict(n=int(out.n_switches[0]), first=float(out.first_switch[0]),
                    time=float(out.time[0]), P=out.state[0],
                    slid=float(out.sliding_time[0]), events=None,
                    jac=None if out.jacobian is None else out.jacobian[0])
    sec = fs.python_section(section, direction=+1)
    traj = simulate(fs.python(), z0, 2 * T, sections=[sec], dense=False, method=flows)
    assert traj.status == f"section:{sec.name}", traj.status
    sw = traj.switches()
    return dict(n=len(sw), first=sw[0].t, time=traj.t, P=np.asarray(traj.z),
                slid=sliding_time(traj.events), jac=None,
                events=[(e.kind, e.t, e.mode_before, e.mode_after) for e in traj.events
                        if e.kind not in ("start", "section")])


def _check_return(got, want):
    assert got["first"] == pytest.approx(want["t1"], abs=1e-12)
    assert got["time"] == pytest.approx(T, abs=1e-10)
    # the time slid carries the exit's error (t_e - t1 + T - t_r; t_r depends on the
    # exit time only at second order, b = 0 there)
    assert got["slid"] == pytest.approx(want["slid"], abs=1e-10)
    np.testing.assert_allclose(got["P"], want["P"], rtol=0, atol=1e-9)


#: (c, m): b > 0 for L = 0.01 (the fold of tests/test_fold_exit.py's first case) and
#: for L = 1e-3, both around t* = 1, where the sliding run's DOP853 steps (its flow is
#: polynomial: error estimates ~0) are ~0.1-1 long: 4 samples per step step over both
SHORT = [(40.0, 40.0 * 0.01 ** 2 / 8), (40.0, 40.0 * 1e-3 ** 2 / 8)]


@pytest.mark.parametrize("flows", ["exact", "integrate"])
@pytest.mark.parametrize("engine", ["compiled", "reference"])
@pytest.mark.parametrize("c, m", SHORT)
def test_a_short_exit_window_inside_one_step_ends_the_slide(engine, flows, c, m):
    want = _case(c, m)[2]
    got = _run(engine, flows, c, m)
    assert got["n"] == 3, got["events"]   # into sliding, out at t_e, back at t_r
    if got["events"] is not None:
        kinds = [(k, a, b) for k, _, a, b in got["events"]]
        assert kinds == [("slide_start", MINUS, SLIDING), ("slide_end", SLIDING, PLUS),
                         ("slide_start", PLUS, SLIDING)], got["events"]
        assert got["events"][1][1] == pytest.approx(want["te"], abs=1e-10)
        assert got["events"][2][1] == pytest.approx(want["tr"], abs=1e-10)
    _check_return(got, want)


#: a window of L = 0.5 and 1.0: seen at the samples (a sampled sign change of b), as
#: before the hidden-extremum check
WIDE = [(2.0, 2.0 * 0.5 ** 2 / 8), (1.5, 1.5 * 1.0 ** 2 / 8)]


@pytest.mark.parametrize("flows", ["exact", "integrate"])
@pytest.mark.parametrize("engine", ["compiled", "reference"])
@pytest.mark.parametrize("c, m", WIDE)
def test_an_exit_seen_at_the_samples_is_unchanged(engine, flows, c, m):
    want = _case(c, m)[2]
    got = _run(engine, flows, c, m)
    assert got["n"] == 3, got["events"]
    if got["events"] is not None:
        assert [k for k, *_ in got["events"]] == ["slide_start", "slide_end", "slide_start"]
        assert got["events"][1][1] == pytest.approx(want["te"], abs=1e-10)
        assert got["events"][2][1] == pytest.approx(want["tr"], abs=1e-10)
    _check_return(got, want)


@pytest.mark.parametrize("flows", ["exact", "integrate"])
@pytest.mark.parametrize("engine", ["compiled", "reference"])
@pytest.mark.parametrize("m", [-0.05, -1e-4])
def test_a_slide_whose_b_peaks_below_zero_goes_on(engine, flows, m):
    """b has its maximum m < 0 between two samples (the hidden-extremum check refines it
    and finds it short of 0, beyond touch_tol's reach): no exit, no touch."""
    c = 40.0
    want = _case(c, m)[2]
    got = _run(engine, flows, c, m, jacobian=True)
    assert got["n"] == 1
    if got["events"] is not None:
        assert [k for k, *_ in got["events"]] == ["slide_start"]
    else:
        assert np.all(np.isfinite(got["jac"]))   # no touch: P differentiable
    _check_return(got, want)


@pytest.mark.parametrize("flows", ["exact", "integrate"])
@pytest.mark.parametrize("engine", ["compiled", "reference"])
def test_b_touching_zero_between_samples_is_a_touch(engine, flows):
    """m = 0: F_+ turns tangent to H at t* and back (b's maximum is 0 up to rounding):
    the orbit would leave H by nothing (rules.speed_graze: the excursion is far within
    touch_tol), so it slides on, and the touch is reported as the graze of h reports
    one: a 'touch' event (reference driver), dP/dz NaN (the kink of P; compiled)."""
    c = 40.0
    want = _case(c, 0.0)[2]
    got = _run(engine, flows, c, 0.0, jacobian=True)
    assert got["n"] == 1
    if got["events"] is not None:
        assert [(k, a, b) for k, _, a, b in got["events"]] == [
            ("slide_start", MINUS, SLIDING), ("touch", SLIDING, SLIDING)]
        assert got["events"][1][1] == pytest.approx(TSTAR, abs=1e-6)
    else:
        assert np.all(np.isnan(got["jac"]))
    _check_return(got, want)


def test_the_fold_exit_cases_at_the_default_samples(monkeypatch):
    """tests/test_fold_exit.py needed 16 samples per step for its first case (b > 0 for
    L = 0.01, stepped over at 4): at the default 4 it now runs as at 16."""
    import importlib
    import sys
    from pathlib import Path

    here = str(Path(__file__).parent)
    if here not in sys.path:
        sys.path.insert(0, here)
    fold = importlib.import_module("test_fold_exit")
    monkeypatch.setattr(fold, "SAMPLES", 4)
    for engine in ("compiled", "reference"):
        for flows in ("exact", "integrate"):
            for c, L in fold.CASES:
                fold.test_a_return_across_h_soon_after_a_fold_exit_is_found(engine, flows, c, L)


# ----------------------------------------------------------------------------- the rules
@pytest.mark.parametrize("between", [rules.speed_extremum_between,
                                     kernel.compiled_rule("speed_extremum_between")])
def test_an_extremum_toward_the_exit(between):
    # b (exit TO_NONNEG): a maximum, its rate from > 0 to <= 0
    assert between(rules.TO_NONNEG, 1.0, -1.0)
    assert between(rules.TO_NONNEG, 1.0, 0.0)
    assert not between(rules.TO_NONNEG, -1.0, 1.0)
    assert not between(rules.TO_NONNEG, 1.0, 2.0)
    # a (exit TO_NONPOS): a minimum, its rate from < 0 to >= 0
    assert between(rules.TO_NONPOS, -1.0, 1.0)
    assert between(rules.TO_NONPOS, -1.0, 0.0)
    assert not between(rules.TO_NONPOS, 1.0, -1.0)
    # elementwise on arrays (the reference driver's scan)
    np.testing.assert_array_equal(
        rules.speed_extremum_between(rules.TO_NONNEG, np.array([1.0, -1.0, 2.0]),
                                     np.array([-1.0, 1.0, 1.0])), [True, False, False])


@pytest.mark.parametrize("graze", [rules.speed_graze, kernel.compiled_rule("speed_graze")])
def test_the_hidden_extremum_of_a_speed_is_judged_by_the_excursion_it_makes(graze):
    tol = 1e-15
    # b's maximum vm, its rates 1 and -1 over a sample interval of 0.5 (curvature 4): the
    # orbit leaves H by (4 sqrt2 / 3) vm^1.5 / sqrt(4)
    leave = lambda vm: 4 * math.sqrt(2) / 3 * abs(vm) ** 1.5 / 2.0  # noqa: E731
    assert graze(rules.TO_NONNEG, 5e-4, 1.0, -1.0, 0.5, tol) == rules.GRAZE_CROSSES
    assert graze(rules.TO_NONNEG, -5e-4, 1.0, -1.0, 0.5, tol) == rules.GRAZE_NONE
    assert leave(1e-10) < tol < leave(1e-9)
    assert graze(rules.TO_NONNEG, 1e-10, 1.0, -1.0, 0.5, tol) == rules.GRAZE_TOUCHES
    assert graze(rules.TO_NONNEG, -1e-10, 1.0, -1.0, 0.5, tol) == rules.GRAZE_TOUCHES
    assert graze(rules.TO_NONNEG, 1e-9, 1.0, -1.0, 0.5, tol) == rules.GRAZE_CROSSES
    assert graze(rules.TO_NONNEG, -1e-9, 1.0, -1.0, 0.5, tol) == rules.GRAZE_NONE
    # a's minimum: the far side is below 0
    assert graze(rules.TO_NONPOS, -5e-4, -1.0, 1.0, 0.5, tol) == rules.GRAZE_CROSSES
    assert graze(rules.TO_NONPOS, 5e-4, -1.0, 1.0, 0.5, tol) == rules.GRAZE_NONE
    assert graze(rules.TO_NONPOS, 1e-10, -1.0, 1.0, 0.5, tol) == rules.GRAZE_TOUCHES
    # touch_tol = 0: only an extremum exactly at 0 touches
    assert graze(rules.TO_NONNEG, 0.0, 1.0, -1.0, 0.5, 0.0) == rules.GRAZE_TOUCHES
    assert graze(rules.TO_NONNEG, 1e-100, 1.0, -1.0, 0.5, 0.0) == rules.GRAZE_CROSSES


@pytest.mark.parametrize("step", [rules.rate_step, kernel.compiled_rule("rate_step")])
def test_the_rates_difference_step(step):
    z, fm, fp = np.array([0.0, -3.0, 2.0]), np.array([1.0, 2.0, 1.0]), np.array([-1.0, 2.0, 1.0])
    # Filippov's field (a F_+ - b F_-)/(a - b) = (0, 2, 1) at a = 1, b = -1: the orbit moves
    # RATE_STEP |z|_inf over the step
    assert step(z, fm, fp, 1.0, -1.0) == pytest.approx(rules.RATE_STEP * 3.0 / 2.0)
    # no Filippov field (a = b) or a zero one: no rates, no check (and no division by 0)
    assert step(z, fm, fp, 1.0, 1.0) == 0.0
    assert step(z, np.zeros(3), np.zeros(3), 1.0, -1.0) == 0.0
    # a sample interval of no length (a window below the spacing of floats): never a touch
    for graze in (rules.speed_graze, kernel.compiled_rule("speed_graze")):
        assert graze(rules.TO_NONNEG, 1e-3, 1.0, -1.0, 0.0, 1e-15) == rules.GRAZE_CROSSES
