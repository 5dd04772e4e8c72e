"""A non-finite value of any piece, met anywhere in a run, stops it by name (issue 57, 1).

Each system below is well defined where the orbit starts, and one of its pieces turns
NaN (a square root of a negative number) on the way, before anything else happens:

    x' = 1,  y' = -1 / +1 (below / above H),  w' = -w,

started at (0, -1, 1): the orbit moves right at unit speed. With a sound switch
H = y - 3 it never switches, and it meets the section x = 5 at t = 5. Each case makes one
piece NaN for x > 2, so the run must stop at t = 2 (up to a sample step) naming that
piece -- not return at t = 5 with the switch never seen (what both engines did: NaN
samples show no sign change).
"""
import re

import numpy as np
import pytest

from filippov import FilippovSystem, SimulationError, first_returns, simulate

ENGINES = ("reference", "compiled")
START = [0.0, -1.0, 1.0]
T_NAN = 2.0


def _field(sign):
    return lambda z, p: np.array([1.0, sign * 1.0, -z[2]])


def _switch(z, p):
    return z[1] - 3.0


def _nan_switch(z, p):
    return z[1] - 3.0 + 0.0 * np.sqrt(T_NAN - z[0])


def _grad(z, p):
    return np.array([0.0, 1.0, 0.0])


def _nan_grad(z, p):
    return np.array([0.0 * np.sqrt(T_NAN - z[0]), 1.0, 0.0])


def _section(z, p):
    return z[0] - 5.0


def _nan_section(z, p):
    return z[0] - 5.0 + 0.0 * np.sqrt(T_NAN - z[0])


def _system(switch=_switch, grad=_grad, **kw):
    return FilippovSystem(("x", "y", "w"), _field(-1.0), _field(1.0), switch, grad, **kw)


def _exact_flow(sign):
    def flow(z0, tau, p):
        return np.array([z0[0] + tau, z0[1] + sign * tau, z0[2] * np.exp(-tau)])
    return flow


CASES = {
    "switch": (dict(switch=_nan_switch), _section, "switch"),
    "switch_grad": (dict(grad=_nan_grad), _section, "switch_grad"),
    "section": ({}, _nan_section, "section"),
}


def test_the_sound_system_returns_at_t5_without_a_switch():
    for engine in ENGINES:
        ret = first_returns(_system(), [START], _section, 10.0, engine=engine)
        assert ret.time[0] == pytest.approx(5.0, abs=1e-12)


@pytest.mark.parametrize("engine", ENGINES)
@pytest.mark.parametrize("exact", [False, True], ids=["integrated", "exact"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_a_non_finite_piece_stops_the_return_by_name(engine, exact, case):
    kw, section, piece = CASES[case]
    if exact:
        kw = dict(kw, flow_minus=_exact_flow(-1.0), flow_plus=_exact_flow(1.0),
                  sample_step=0.1)
    system = _system(**kw)
    with pytest.raises(SimulationError, match="non-finite") as err:
        first_returns(system, [START], section, 10.0, engine=engine)
    msg = str(err.value)
    # (the reference names a section by its name: 'section')
    assert re.search(f"{piece}( '[a-z]+')? returned a non-finite value", msg), msg
    t = float(msg.split("t=")[1].split(",")[0])
    # where the piece's domain ends, up to a window of samples (0.1 / 16 for an exact
    # flow, a DOP853 step here) -- and before the section at t = 5
    assert T_NAN - 1.0 <= t <= T_NAN + 0.5, msg


@pytest.mark.parametrize("case", ["switch", "switch_grad"])
def test_simulate_stops_at_a_non_finite_switch(case):
    kw, _, piece = CASES[case]
    with pytest.raises(SimulationError, match=f"{piece} returned a non-finite value"):
        simulate(_system(**kw).python(), START, 10.0)


def _sliding_system(grad):
    """Sliding on y = 0 (f- pushes up, f+ down), the orbit moving right: the sliding
    field needs switch_grad, NaN for x > 2."""
    return FilippovSystem(("x", "y", "w"), lambda z, p: np.array([1.0, 1.0, -z[2]]),
                          lambda z, p: np.array([1.0, -1.0, -z[2]]),
                          lambda z, p: z[1], grad)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_non_finite_gradient_while_sliding_stops_the_return_by_name(engine):
    system = _sliding_system(_nan_grad)
    with pytest.raises(SimulationError, match="non-finite") as err:
        first_returns(system, [[0.0, -0.5, 1.0]], _section, 10.0, engine=engine)
    msg = str(err.value)
    assert "mode sliding (switch_grad returned a non-finite value" in msg, msg
    t = float(msg.split("t=")[1].split(",")[0])
    assert T_NAN - 1.5 <= t <= T_NAN + 0.5, msg
    # and the sound one slides to the section
    ret = first_returns(_sliding_system(_grad), [[0.0, -0.5, 1.0]], _section, 10.0,
                        engine=engine)
    assert ret.time[0] == pytest.approx(5.0, abs=1e-10)


@pytest.mark.parametrize("engine", ENGINES)
def test_a_switch_not_finite_at_the_start_is_named(engine):
    """switch is finite at the probe state of the system's checks (x = 0.5) and NaN at
    the start (x = 0 < 0.25): the run stops at t = 0 naming it."""
    system = _system(switch=lambda z, p: z[1] - 3.0 + 0.0 * np.sqrt(z[0] - 0.25))
    with pytest.raises(SimulationError, match=r"at t=0\.0, .*switch returned a non-finite"):
        first_returns(system, [START], _section, 10.0, engine=engine)
