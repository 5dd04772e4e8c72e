"""A value numba compiled into a piece (a global or a closure cell the piece reads) that
changes afterwards is refused by name, on both engines, instead of being run with its old
value (filippov.frozen); unchanged values, and a system built again, run as before."""
import sys

import numpy as np
import pytest
from numba import njit

from filippov import FilippovSystem, SystemContractError, first_returns

K = 1.0                              # read as a global by the pieces below
A = np.array([[-1.0]])
HERE = sys.modules[__name__]
ENGINES = ("reference", "compiled")


def _decay(field, **kw):
    """x' = field(z, p) on both sides of h = x + 10 (never reached): from x = 1 the
    section x = 0.5 is reached at t = ln(2) / rate."""
    return FilippovSystem(("x",), field_minus=field, field_plus=field,
                          switch=lambda z, p: z[0] + 10.0,
                          switch_grad=lambda z, p: np.array([1.0]), **kw)


def _return_time(system, engine):
    out = first_returns(system, [[1.0]], lambda z, p: z[0] - 0.5, 10.0, direction=-1,
                        engine=engine)
    return float(out.time[0])


@pytest.mark.parametrize("engine", ENGINES)
def test_a_changed_global_is_refused_by_name(engine, monkeypatch):
    system = _decay(lambda z, p: np.array([-K * z[0]]))
    assert _return_time(system, engine) == pytest.approx(np.log(2), rel=1e-9)
    assert _return_time(system, engine) == pytest.approx(np.log(2), rel=1e-9)  # unchanged
    monkeypatch.setattr(HERE, "K", 2.0)
    for eng in ENGINES:  # the other engine's pieces are the same compiled functions
        with pytest.raises(SystemContractError, match=r"field_minus: reads the global 'K'"
                                                      r".*compiled in as 1\.0.*params="):
            _return_time(system, eng)
    # built again, the system compiles the new value
    assert _return_time(_decay(lambda z, p: np.array([-K * z[0]])), engine) == \
        pytest.approx(np.log(2) / 2, rel=1e-9)


def test_a_changed_closure_cell_and_an_array_changed_in_place_are_refused(monkeypatch):
    rate = 1.0
    system = _decay(lambda z, p: np.array([-rate * z[0]]))
    _return_time(system, "compiled")
    rate = 3.0  # noqa: F841 (the lambda's cell)
    with pytest.raises(SystemContractError, match="closes over 'rate'"):
        _return_time(system, "compiled")

    monkeypatch.setattr(HERE, "A", np.array([[-1.0]]))
    system = _decay(lambda z, p: A[0] * z[0])
    _return_time(system, "reference")
    A[0, 0] = -2.0
    with pytest.raises(SystemContractError, match=r"reads the global 'A'.*\[\[-1\.\]\]"):
        _return_time(system, "reference")


def test_a_global_of_a_compiled_helper_and_of_a_jacobian_is_followed(monkeypatch):
    @njit
    def rate():
        return K

    system = _decay(lambda z, p: np.array([-rate() * z[0]]),
                    jacobians={"minus": lambda z, p: np.array([[-K]]),
                               "plus": lambda z, p: np.array([[-1.0]])})
    _return_time(system, "compiled")
    assert system.jacobian(-1, np.array([1.0]))[0, 0] == -1.0
    monkeypatch.setattr(HERE, "K", 5.0)
    with pytest.raises(SystemContractError, match=r"field_minus: reads the global 'K' \(.*rate"):
        _return_time(system, "compiled")
    with pytest.raises(SystemContractError, match="'K'"):
        system.jacobian(-1, np.array([1.0]))


def test_values_that_stay_are_no_alarm(monkeypatch):
    # the same values bound again: a new float object, a new tuple with NaN for NaN
    monkeypatch.setattr(HERE, "T", (1.0, np.nan), raising=False)
    system = _decay(lambda z, p: np.array([-K * T[0] * z[0]]))
    first = _return_time(system, "compiled")
    monkeypatch.setattr(HERE, "K", float("1.0"))
    monkeypatch.setattr(HERE, "T", (1.0, float("nan")))
    assert _return_time(system, "compiled") == first
    assert _return_time(system, "reference") == pytest.approx(first, rel=1e-9)


def test_a_deleted_global_is_a_change(monkeypatch):
    monkeypatch.setattr(HERE, "GONE", 1.0, raising=False)
    system = _decay(lambda z, p: np.array([-GONE * z[0]]))  # noqa: F821
    _return_time(system, "reference")
    monkeypatch.delattr(HERE, "GONE")
    with pytest.raises(SystemContractError, match="'GONE'"):
        _return_time(system, "reference")


def test_a_model_compiled_on_its_own_is_checked_by_the_compiled_front_doors(monkeypatch):
    # compile_system's CompiledModel, run by compute_returns / sweep_returns directly
    from filippov import compile_system, compute_returns, sweep_returns
    cm = compile_system(("x",), lambda z, p: np.array([-K * z[0]]),
                        lambda z, p: np.array([-K * z[0]]), switch=lambda z, p: z[0] + 10.0,
                        switch_grad=lambda z, p: np.array([1.0]),
                        section=lambda z, p: z[0] - 0.5, section_direction=-1)
    assert compute_returns(cm, [[1.0]], 10.0).time[0] == pytest.approx(np.log(2), rel=1e-9)
    assert sweep_returns([cm], [[1.0]], 10.0).time[0] == pytest.approx(np.log(2), rel=1e-9)
    monkeypatch.setattr(HERE, "K", 2.0)
    for run in (lambda: compute_returns(cm, [[1.0]], 10.0),
                lambda: sweep_returns([cm], [[1.0]], 10.0)):
        with pytest.raises(SystemContractError, match=r"field_minus: reads the global 'K'"):
            run()
