"""Issue 28: after a sliding exit at a visible fold, the rounding of the next stay's flow
at tau ~ 0 is no arrival at H (rules.exit_band), while a genuine return across H soon
after the exit is still found, at its closed-form time, by both engines.

The system, in coordinates u = (x, y, s) = R^T (z - z*) (R a rotation, z* ~ 10 away:
the exact flows are then built around a far point and round at tau = 0 like the
generated systems' closed forms, H reading ~1e-15 off at the exit):

    h = x;   F_- = (1, 1 - c s, 1),   F_+ = (y, 1 - c s, 1).

a = dh.F_- = 1 > 0 and b = dh.F_+ = y, so H slides where y < 0, with x' = 0; y and s
follow y' = 1 - c s, s' = 1 in every mode: s = t, y = y0 + t - c t^2 / 2. From below
H (x0 = -delta) the orbit reaches H at t1 = delta and slides; the slide ends where y
rises through 0 (a visible fold, b' = 1 - c t_e > 0) at the first root t_e of y; with
L the distance to y's second root, y = (c/2)(t - t_e)(t_e + L - t) and in region +
x = int y returns to 0 at t_r = t_e + 3L/2, crossing H downward at speed (3c/8) L^2,
where F_- points up: sliding again, to the section s = T.
"""
import math

import numpy as np
import pytest
from numba import njit

from filippov import FilippovSystem, simulate
from filippov import rules  # noqa
from filippov.kernel import base as kernel
from filippov.poincare import sliding_time
from filippov.system import MINUS, PLUS

DELTA = 0.005
ZSTAR = np.array([7.3, -5.9, 4.1])   # |z*| = 10.2, as FOLD_EXIT's region + (10.1)
_A = np.array([[0.6, -0.3, 0.2], [0.5, 0.7, -0.4], [-0.1, 0.6, 0.9]])
R = np.linalg.qr(_A)[0]


@njit(cache=True)
def _u(z, p):
    out = np.empty(3)
    for i in range(3):
        acc = 0.0
        for k in range(3):
            acc += p[5 + 3 * k + i] * (z[k] - p[2 + k])
        out[i] = acc
    return out


@njit(cache=True)
def _z(u, p):
    out = np.empty(3)
    for k in range(3):
        acc = p[2 + k]
        for i in range(3):
            acc += p[5 + 3 * k + i] * u[i]
        out[k] = acc
    return out


@njit(cache=True)
def _rot(v, p):
    out = np.empty(3)
    for k in range(3):
        acc = 0.0
        for i in range(3):
            acc += p[5 + 3 * k + i] * v[i]
        out[k] = acc
    return out


@njit(cache=True)
def field_minus(z, p):
    u = _u(z, p)
    return _rot(np.array([1.0, 1.0 - p[0] * u[2], 1.0]), p)


@njit(cache=True)
def field_plus(z, p):
    u = _u(z, p)
    return _rot(np.array([u[1], 1.0 - p[0] * u[2], 1.0]), p)


@njit(cache=True)
def flow_minus(z0, tau, p):
    u, c = _u(z0, p), p[0]
    return _z(np.array([u[0] + tau, u[1] + tau - c * (u[2] * tau + 0.5 * tau * tau),
                        u[2] + tau]), p)


@njit(cache=True)
def flow_plus(z0, tau, p):
    u, c = _u(z0, p), p[0]
    x = u[0] + u[1] * tau + 0.5 * tau * tau - c * (0.5 * u[2] * tau * tau + tau * tau * tau / 6.0)
    return _z(np.array([x, u[1] + tau - c * (u[2] * tau + 0.5 * tau * tau), u[2] + tau]), p)


@njit(cache=True)
def switch(z, p):
    return _u(z, p)[0]


@njit(cache=True)
def switch_grad(z, p):
    return np.array([p[5], p[8], p[11]])   # R's first column


@njit(cache=True)
def section(z, p):
    return _u(z, p)[2] - p[1]


def _case(c, L):
    """(system parameters p, start z0, closed form) for the fold's curvature c and the
    distance L between y's roots."""
    rise = c * L / 2                       # b' = 1 - c t_e at the exit
    assert 0 < rise < 1
    y0 = (rise ** 2 - 1) / (2 * c)
    te = (1 - rise) / c
    tr = te + 1.5 * L
    T = tr + 0.5
    assert DELTA < te
    p = np.concatenate([[c, T], ZSTAR, R.ravel()])
    z0 = ZSTAR + R @ np.array([-DELTA, y0 + 0.0, 0.0])
    # y0 at t = 0 is y0 (s0 = 0): the closed form y(t) = y0 + t - c t^2/2 holds from there
    yT = y0 + T - c * T ** 2 / 2
    return p, z0, dict(t1=DELTA, te=te, tr=tr, T=T, P=ZSTAR + R @ np.array([0.0, yT, T]),
                       slid=(te - DELTA) + (T - tr), slope=3 * c * L ** 2 / 8)


def _system(p, exact):
    flows = dict(flow_minus=flow_minus, flow_plus=flow_plus, sample_step=0.05) if exact else {}
    return FilippovSystem(("z1", "z2", "z3"), field_minus, field_plus, switch, switch_grad,
                          params=p, name="fold_return", **flows)


#: (c, L): a return 0.015 after the exit, inside the first window of the stay (the
#: compiled engine: in its first sample interval, which begins at the exit itself; exit
#: rate 0.2, the return's speed 1.5e-3), and two later ones
CASES = [(40.0, 0.01), (2.0, 0.5), (1.5, 1.0)]
#: samples per step: b > 0 for only L = 0.01 before the fold of the first case, and
#: DOP853 steps over that in one sample interval of the default 4 (its sliding flow is
#: polynomial: error estimates ~0, steps grow tenfold). The engines slid on past the exit
#: there until the scan looked for extrema of a and b between samples
#: (rules.speed_graze; tests/test_sliding_exit_hidden.py runs these cases at 4); 16
#: samples see the window at the samples themselves
SAMPLES = 16


def _run(engine, flows, c, L):
    """(n_switches, first switch, return time, P, time slid, [(kind, t)] or None)."""
    p, z0, want = _case(c, L)
    fs = _system(p, flows == "exact")
    if engine == "compiled":
        from filippov.fastmap import OK, compute_returns, failure

        cm = fs.compiled(section, direction=+1)
        out = compute_returns(cm, [z0], 2 * want["T"], samples_per_step=SAMPLES)
        assert out.status[0] == OK, failure(cm, out, 0)
        return (int(out.n_switches[0]), float(out.first_switch[0]), float(out.time[0]),
                out.state[0], float(out.sliding_time[0]), None)
    sec = fs.python_section(section, direction=+1)
    traj = simulate(fs.python(), z0, 2 * want["T"], sections=[sec], dense=False,
                    method=flows, samples_per_step=SAMPLES)
    assert traj.status == f"section:{sec.name}", traj.status
    sw = traj.switches()
    return (len(sw), sw[0].t, traj.t, np.asarray(traj.z), sliding_time(traj.events),
            [(e.kind, e.t) for e in sw])


@pytest.mark.parametrize("flows", ["exact", "integrate"])
@pytest.mark.parametrize("engine", ["compiled", "reference"])
@pytest.mark.parametrize("c, L", CASES)
def test_a_return_across_h_soon_after_a_fold_exit_is_found(engine, flows, c, L):
    want = _case(c, L)[2]
    n, first, time, P, slid, times = _run(engine, flows, c, L)
    # into sliding, out at the fold, back across H (into sliding again): nothing else
    assert n == 3, times
    if times is not None:
        assert [k for k, _ in times] == ["slide_start", "slide_end", "slide_start"]
        assert times[1][1] == pytest.approx(want["te"], abs=1e-10)
        # the return: H's rounding near the return (~eps |z*| = 2e-15) over its speed, on
        # top of the exit's error carried along (the return is well inside tolerance; a
        # return located at the band's edge instead of H = 0 would be off by band/speed)
        assert times[2][1] == pytest.approx(want["tr"], abs=1e-10)
    assert first == pytest.approx(want["t1"], abs=1e-12)
    assert time == pytest.approx(want["T"], abs=1e-10)
    assert slid == pytest.approx(want["slid"], abs=1e-9)
    np.testing.assert_allclose(P, want["P"], atol=1e-9)


@pytest.mark.parametrize("engine", ["compiled", "reference"])
def test_the_return_in_the_exits_first_window_is_located_at_h_zero(engine):
    """The return 0.015 after the exit lies in the stay's first window, where the exit's
    band is still in force (the compiled engine: in the first sample interval, from the
    exit itself). It is refined again on H itself (rules.clears_band, rules.band_probe):
    its error stays at H's rounding over the return's speed (~1e-12; HEAD's engines,
    without a band, 5e-13), not band / speed (2.5e-11, the root of the banded H)."""
    c, L = CASES[0]
    p, z0, want = _case(c, L)
    ze = ZSTAR + R @ np.array([0.0, 0.0, want["te"]])    # the exit, closed form
    band = rules.exit_band(ze, flow_plus(ze, 0.0, p), switch_grad(ze, p), 1.0, np.ones(3))
    assert band / want["slope"] > 2e-11
    # the time slid is t_e - t_1 + T - t_r: an error of the return shows there
    slid = _run(engine, "exact", c, L)[4]
    assert abs(slid - want["slid"]) < 0.1 * band / want["slope"]


# ----------------------------------------------------------------------------- the rules
@pytest.mark.parametrize("band_of", [rules.exit_band, kernel.compiled_rule("exit_band")])
def test_the_exit_band_is_the_flows_rounding_scale(band_of):
    z, grad = np.array([0.0, -0.38256777, 0.56876841]), np.array([1.0, 0.0, 0.0])
    eps = np.finfo(float).eps
    # an integrated stay (the state itself at tau = 0): 16 roundings of |z|, times |grad|
    one = np.ones(3)   # one scale for every component (filippov.scale): Euclidean
    assert band_of(z, z.copy(), grad, 1.0, one) == pytest.approx(16 * eps * np.linalg.norm(z))
    # a closed form that rounds z by 1.1e-15 at tau = 0 (FOLD_EXIT's): 16 of those
    zf = z + np.array([-1.1e-15, 0.0, 0.0])
    assert band_of(z, zf, 2 * grad, 1.0, one) == pytest.approx(16 * 2 * 1.1e-15)
    assert band_of(z, zf, 2 * grad, 1.0, one) > 1.1e-15 * 2   # H's reading lies inside
    # x in units 1e-9 of the others (its scale 1e-9): the band in H's units is the same
    D, s = np.array([1e-9, 1.0, 1.0]), np.array([2.0 ** -30, 1.0, 1.0])
    assert band_of(z * D, zf * D, 2 * grad / D, 1.0, s) == pytest.approx(
        band_of(z, zf, 2 * grad, 1.0, one), rel=0.2)


@pytest.mark.parametrize("mode", [PLUS, MINUS])
def test_the_band_moves_the_shift_to_the_wrong_side_until_cleared(mode):
    band, shift = 3e-15, 0.0
    for banded, clears in ((rules.banded_shift, rules.clears_band),
                           (kernel.compiled_rule("banded_shift"),
                            kernel.compiled_rule("clears_band"))):
        c = banded(mode, shift, band)
        sign = 1.0 if mode == PLUS else -1.0
        # H read at -band/2 on the wrong side is no crossing of the banded function
        h = -sign * band / 2
        assert rules.after(rules.TO_NEG if mode == PLUS else rules.TO_NONNEG, h - c) is False
        # one beyond the band is
        h = -sign * 2 * band
        assert rules.after(rules.TO_NEG if mode == PLUS else rules.TO_NONNEG, h - c) is True
        # out of the band on the region's side: cleared
        assert clears(mode, sign * 1.5 * band - c, band)
        assert not clears(mode, sign * 0.5 * band - c, band)


def test_no_touch_at_the_exits_own_tangency():
    tol, band = 1e-15, 3e-15
    for graze in (rules.graze, kernel.compiled_rule("graze")):
        # outside an exit's band: a touch within touch_tol, a crossing beyond it
        assert graze(PLUS, -5e-16, tol, 0.0) == rules.GRAZE_TOUCHES
        assert graze(PLUS, -2e-15, tol, 0.0) == rules.GRAZE_CROSSES
        # inside it (hm measured from the band's edge): the exit itself, no event
        assert graze(PLUS, 5e-16, tol, band) == rules.GRAZE_NONE
        assert graze(PLUS, -5e-16, tol, band) == rules.GRAZE_NONE
        assert graze(MINUS, 5e-16, tol, band) == rules.GRAZE_NONE
        # beyond the band: a crossing
        assert graze(PLUS, -2e-15, tol, band) == rules.GRAZE_CROSSES
        assert graze(MINUS, 2e-15, tol, band) == rules.GRAZE_CROSSES
    assert math.isfinite(rules.EXIT_BAND_ULPS)
