"""Solver options are checked by one rule on both engines (filippov.options): the same
bad value is refused by the reference driver and the compiled engine, with its name."""
import numpy as np
import pytest

from filippov import options
from filippov.fastmap import compute_returns
from filippov.models import hopf
from filippov.simulate import simulate

EPS, THETA = 1e-2, -0.5
# (option, bad value, words of the message)
BAD = [
    ("rtol", 0.0, "rtol must be a finite number > 0.0"),
    ("atol", -1e-14, "atol must be a finite number > 0.0"),
    ("max_step", 0.0, "max_step must be a number > 0.0"),
    ("touch_tol", np.nan, "touch_tol must be a finite number >= 0.0"),
    ("event_xtol", np.inf, "event_xtol must be a finite number > 0.0"),
    ("zeno_span", -1.0, "zeno_span must be a finite number >= 0.0"),
    ("max_events", 0, "max_events must be an integer >= 1"),
    ("max_steps", 2.5, "max_steps must be an integer >= 1"),
    ("samples_per_step", True, "samples_per_step must be an integer >= 1"),
    # one switch is no accumulation: the compiled engine took 1 (flagging every switch)
    ("zeno_count", 1, "zeno_count must be an integer >= 2"),
    # a number no float holds, and a bool: refused by name, not by OverflowError
    ("max_step", 10 ** 400, "max_step must be a number > 0.0"),
    ("atol", True, "atol must be a finite number > 0.0"),
]


def _compiled(**opts):
    cm = hopf.compiled(EPS, THETA, 1 + EPS)
    return compute_returns(cm, [[0.0, 1.0, 0.0]], 1.0, **opts)


def _python(**opts):
    system = hopf.model(EPS, THETA, 1 + EPS).full()
    return simulate(system, [0.0, 1.0, 0.0], 0.1, **opts)


@pytest.mark.parametrize("engine", [_compiled, _python], ids=["compiled", "reference"])
@pytest.mark.parametrize("name,value,words", BAD)
def test_both_engines_refuse_the_same_option_with_its_name(engine, name, value, words):
    with pytest.raises(ValueError) as exc:
        engine(**{name: value})
    assert words in str(exc.value)


def test_an_unknown_option_is_no_silent_default():
    with pytest.raises(TypeError, match="unknown solver option 'rtoll'"):
        options.check(rtoll=1e-9)


@pytest.mark.parametrize("engine", [_compiled, _python], ids=["compiled", "reference"])
def test_the_smallest_allowed_values_pass(engine):
    engine(zeno_count=2, touch_tol=0.0, zeno_span=0.0, max_events=1_000, samples_per_step=1)
