"""Each way a run can end unsuccessfully (a status of filippov.loop.status) raises the
same exception class with the same words on both engines: one table,
filippov.errors.run_error, turns a status into its exception for both."""
import re

import numpy as np
import pytest

from filippov import FilippovSystem, errors, first_returns
from filippov.loop import status
from filippov.models import hopf, pseudo_equilibrium

ENGINES = ("reference", "compiled")
EPS, MU, OMEGA = 0.01, 1.0, 8 * np.pi
T_MAX = 4.0 * 2 * np.pi / OMEGA


def _hopf(**kw):
    return hopf.system(EPS, 0.5, MU, OMEGA, **kw)


def _x1(z, p):
    return z[0]


def _far(z, p):
    return z[0] - 5.0


def _nan_beyond_two(z, p):
    return np.array([1.0, np.sqrt(2.0 - z[0]), -z[2]])


def _into_nan():
    return FilippovSystem(("x", "y", "w"), _nan_beyond_two,
                          lambda z, p: np.array([1.0, 1.0, -z[2]]),
                          lambda z, p: z[1] - 10.0, lambda z, p: np.array([0.0, 1.0, 0.0]))


def _drift(rate):
    return lambda z0, tau, p: z0 + rate * tau * np.ones(2)


def _flow_off_field():
    # region +'s exact flow 1e4 times faster than its field from the states it runs from
    # (right at the start, where the run's first start checks it: checks.flow_check)
    return FilippovSystem(("x", "y"), lambda z, p: np.array([1.0, 1.0]),
                          lambda z, p: np.array([1e-4, 1e-4]), lambda z, p: z[1],
                          lambda z, p: np.array([0.0, 1.0]), flow_minus=_drift(1.0),
                          flow_plus=lambda z0, tau, p: z0 + (
                              1e-4 if z0[1] < -0.25 else 1.0) * tau * np.ones(2),
                          sample_step=0.01)


def _two_fold():
    # slides on x < 0 < y of H = {w = 0} into the two-fold at the origin (at t = 6.5 from
    # (-1, 1.5): tests/test_zeno_accumulation.py)
    return FilippovSystem(("x", "y", "w"), lambda z, p: np.array([2.0, 1.0, z[1]]),
                          lambda z, p: np.array([-1.0, -1.0, z[0]]), lambda z, p: z[2],
                          lambda z, p: np.array([0.0, 0.0, 1.0]))


def _no_surface():
    # h = 0 for every state: ran in region + to the section with no word before
    return FilippovSystem(("x", "y"), lambda z, p: np.array([1.0, 0.0]),
                          lambda z, p: np.array([1.0, 1.0]), lambda z, p: 0.0 * z[0],
                          lambda z, p: np.array([0.0, 0.0]))


def _gradient_right_at_start_only(good=False):
    # h = x - y^2 with switch_grad (1, 0), its gradient at y = 0 only: from (-1, 0) the
    # orbit reaches H at y = 0.38 and crosses (true normal speeds 2.2 and 1.0), but the
    # wrong ones say slide: the slide left H by 0.07 and returned to y = -2 at t = 1.898
    # for 4.0, with no word, on both engines (tests/test_known_misses.py)
    grad = ((lambda z, p: np.array([1.0, -2.0 * z[1]])) if good
            else (lambda z, p: np.array([1.0, 0.0])))
    return FilippovSystem(("x", "y"), lambda z, p: np.array([3.0, 1.0]),
                          lambda z, p: np.array([-0.5, -2.0]),
                          lambda z, p: z[0] - z[1] ** 2, grad)


# status -> (system, start, section, direction, t_max, options)
CASES = {
    status.NO_RETURN: lambda: (_hopf(), [0.0, 1.01, 0.0], _x1, -1, 0.1, {}),
    status.STEP_LIMIT: lambda: (_hopf(), [0.0, 1.01, 0.0], _x1, -1, T_MAX, {"max_steps": 3}),
    status.NO_SLIDING: lambda: (_hopf(sliding=False), [0.0, 1.01, 0.0], _x1, -1, T_MAX, {}),
    status.ZENO: lambda: (pseudo_equilibrium.system(1e-13, -0.5), [1e-12, 0.0], _far, 1, 1.0,
                          {"zeno_count": 64, "zeno_span": 1e-10}),
    status.EVENT_LIMIT: lambda: (pseudo_equilibrium.system(1e-13, -0.5), [1e-12, 0.0], _far,
                                 1, 1.0, {"max_events": 10}),
    status.NON_FINITE: lambda: (_into_nan(), [0.0, 0.0, 1.0], _far, 0, 10.0, {}),
    status.FLOW_OFF_FIELD: lambda: (_flow_off_field(), [0.0, -0.5], lambda z, p: z[0] - 0.51,
                                    0, 200.0, {}),
    status.TWO_FOLD: lambda: (_two_fold(), [-1.0, 1.5, 0.0], _far, 0, 20.0, {}),
    status.NO_NORMAL: lambda: (_no_surface(), [0.5, 0.0], _far, 0, 20.0, {}),
    status.SLID_OFF_H: lambda: (_gradient_right_at_start_only(), [-1.0, 0.0],
                                lambda z, p: z[1] + 2.0, -1, 20.0, {}),
}


@pytest.mark.parametrize("code", CASES, ids=lambda c: status.STATUS[c])
def test_a_status_raises_the_same_class_and_words_on_both_engines(code):
    system, start, section, direction, t_max, opts = CASES[code]()
    head = re.compile(rf"^{re.escape(status.STATUS[code])} at t=\S+, state \[")
    for engine in ENGINES:
        with pytest.raises(Exception) as caught:
            first_returns(system, [start], section, t_max, engine=engine,
                          direction=direction, **opts)
        assert type(caught.value) is errors.RUN_ERRORS[code], (engine, caught.value)
        assert head.match(str(caught.value)), (engine, str(caught.value))


def test_every_end_status_has_its_exception():
    ends = {v for k, v in vars(status).items() if k.isupper() and isinstance(v, int)
            and v not in (status.GO_ON, status.OK, status.CUT)}
    assert set(errors.RUN_ERRORS) == ends
    assert set(errors.RUN_ERRORS) <= set(status.STATUS)
    err = errors.run_error(status.ROOT_FAILED, 1.5, np.array([1.0, 2.0]), ": detail")
    assert type(err) is errors.SimulationError
    assert str(err) == f"{status.STATUS[status.ROOT_FAILED]} at t=1.5, state [1.0, 2.0]: detail"
