"""A user's system on the compiled engine from plain scalar functions
(filippov.compiled_system): same answers as the Python driver, errors that name
the piece."""
import numpy as np
import pytest

from filippov import FilippovSystem, PiecewiseSystem, Section, first_returns, fastmap
from filippov.compiled_system import compile_system, with_section

A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -3.0, -3.0]])   # lag 1/(s+1)^3
B, C = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
STARTS = np.array([[0.0, 0.1, 0.0], [0.0, 0.29, 0.14], [0.0, 0.5, -0.2]])


def _relay_python():
    col = lambda v, z: v.reshape((-1,) + (1,) * (np.ndim(z) - 1))
    return PiecewiseSystem(("x1", "x2", "x3"), lambda z: A @ z + col(B, z),
                           lambda z: A @ z - col(B, z), lambda z: C @ z,
                           lambda z: np.broadcast_to(col(C, z), np.shape(z)).copy())


# the relay as scalar pieces (one state z, parameters p = (relay amplitude,))
RELAY = dict(
    field_minus=lambda z, p: np.array([z[1], z[2], -z[0] - 3 * z[1] - 3 * z[2] + p[0]]),
    field_plus=lambda z, p: np.array([z[1], z[2], -z[0] - 3 * z[1] - 3 * z[2] - p[0]]),
    switch=lambda z, p: z[0], switch_grad=lambda z, p: np.array([1.0, 0.0, 0.0]),
    params=[1.0])


def _relay_compiled(**kw):
    return compile_system(("x1", "x2", "x3"), **RELAY, **kw)


def _sliding_example():
    """examples/sliding_segment.py: its PiecewiseSystem, and the same system as
    scalar pieces with exact flows."""
    import importlib.util
    from pathlib import Path

    path = Path(__file__).resolve().parents[1] / "examples" / "sliding_segment.py"
    spec = importlib.util.spec_from_file_location("sliding_segment", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    pieces = dict(
        field_minus=lambda z, p: np.array([1.0, 1.0 - z[0]]),
        field_plus=lambda z, p: np.array([2.0, -1.0]), switch=lambda z, p: z[1],
        switch_grad=lambda z, p: np.array([0.0, 1.0]),
        flow_plus=lambda z0, s, p: np.array([z0[0] + 2.0 * s, z0[1] - s]),
        flow_minus=lambda z0, s, p: np.array([z0[0] + s, z0[1] + (1.0 - z0[0]) * s - s * s / 2]),
        sample_step=module.SYSTEM.sample_step)
    return module.SYSTEM, pieces


def test_a_users_relay_system_returns_as_on_the_python_driver():
    # a section on the switching surface itself, crossed upwards: both engines run the
    # same DOP853 and event rules; they agree to the last few bits
    cm = _relay_compiled(section=lambda z, p: z[0], section_direction=1)
    fast = fastmap.first_returns_compiled(cm, STARTS, 20.0)
    up = Section("up", lambda z: C @ z, direction=1)
    ref = first_returns(_relay_python(), STARTS, up, 20.0, method="integrate")
    np.testing.assert_allclose(fast.state, ref.state, rtol=0, atol=1e-14)
    np.testing.assert_allclose(fast.time, ref.time, rtol=0, atol=1e-13)
    np.testing.assert_array_equal(fast.n_switches, ref.n_switches)


def test_another_section_on_the_same_compiled_system():
    cm = with_section(_relay_compiled(section=lambda z, p: z[0]),
                      lambda z, p: z[1], direction=-1, where=lambda z, p: z[0] > 0)
    fast = fastmap.first_returns_compiled(cm, STARTS, 20.0)
    sec = Section("x2down", lambda z: np.asarray(z)[1], direction=-1,
                  where=lambda z: np.asarray(z)[0] > 0)
    ref = first_returns(_relay_python(), STARTS, sec, 20.0, method="integrate")
    np.testing.assert_allclose(fast.state, ref.state, rtol=0, atol=1e-14)


def test_exact_flows_and_sliding_of_a_users_system():
    # examples/sliding_segment.py's system: F_+ = (2, -1), F_- = (1, 1 - x), H = y;
    # slides on y = 0 from x = -1 to the fold x = 1; returns to x = 3
    system, pieces = _sliding_example()
    cm = compile_system(("x", "y"), **pieces, section=lambda z, p: z[0] - 3.0,
                        section_direction=1)
    start = np.array([[-2.0, 0.5]])
    out = fastmap.compute_returns(cm, start, 10.0)
    assert out.status[0] == fastmap.OK and out.sliding_time[0] > 0
    ref = first_returns(system, start, Section("x3", lambda z: np.asarray(z)[0] - 3.0,
                                               direction=1), 10.0)
    np.testing.assert_allclose(out.state, ref.state, rtol=0, atol=1e-12)
    np.testing.assert_allclose(out.sliding_time, ref.sliding_time, rtol=0, atol=1e-12)


@pytest.mark.parametrize("kw,match", [
    (dict(field_minus=lambda z, p: np.array([1.0])), r"field_minus failed .*expected 2 values"),
    (dict(field_plus=lambda z, p: {"a": 1.0}), r"field_plus: numba cannot compile it"),
    (dict(switch_grad=lambda z, p: np.array([np.nan, 1.0])), r"switch_grad must return 2 finite"),
    (dict(flow_plus=lambda z0, s, p: z0), r"give both exact flows or neither"),
    (dict(flow_plus=lambda z0, s, p: z0, flow_minus=lambda z0, s, p: z0),
     r"sample_step: exact flows need a finite sample_step"),
    (dict(section_direction=2), r"section_direction must be -1, 0 or \+1"),
])
def test_a_broken_piece_is_named(kw, match):
    args = dict(field_minus=lambda z, p: np.array([1.0, -z[0]]),
                field_plus=lambda z, p: np.array([-1.0, -z[0]]), switch=lambda z, p: z[0],
                switch_grad=lambda z, p: np.array([1.0, 0.0]), section=lambda z, p: z[1])
    args.update(kw)
    with pytest.raises(ValueError, match=match):
        compile_system(("x", "y"), **args)


def test_one_definition_runs_on_both_engines():
    # FilippovSystem: written once as scalar pieces; .python() for the reference
    # driver (pieces evaluated by compiled loops over the samples), .compiled(section)
    # for the kernel
    from filippov import FilippovSystem

    relay = FilippovSystem(("x1", "x2", "x3"), **RELAY)
    up = Section("up", lambda z: np.asarray(z)[0], direction=1)
    ref = first_returns(relay.python(), STARTS, up, 20.0, method="integrate")
    fast = fastmap.first_returns_compiled(relay.compiled(lambda z, p: z[0], direction=1),
                                          STARTS, 20.0)
    np.testing.assert_allclose(fast.state, ref.state, rtol=0, atol=1e-14)
    # and the same numbers as the hand-written numpy definition
    hand = first_returns(_relay_python(), STARTS, up, 20.0, method="integrate")
    np.testing.assert_allclose(ref.state, hand.state, rtol=0, atol=1e-14)
    np.testing.assert_allclose(ref.time, hand.time, rtol=0, atol=1e-13)


def test_one_definition_with_exact_flows_and_sliding():
    from filippov import FilippovSystem, simulate

    system, pieces = _sliding_example()
    seg = FilippovSystem(("x", "y"), **pieces)
    got = simulate(seg.python(), [-2.0, 0.5], 4.0, dense=False)
    want = simulate(system, [-2.0, 0.5], 4.0, dense=False)
    assert [e.kind for e in got.events] == [e.kind for e in want.events]
    np.testing.assert_allclose([e.t for e in got.events], [e.t for e in want.events], atol=1e-14)
    np.testing.assert_allclose(got.z, want.z, atol=1e-14)
    out = fastmap.compute_returns(seg.compiled(lambda z, p: z[0] - 3.0, direction=1),
                                  [[-2.0, 0.5]], 10.0)
    ref = first_returns(seg.python(), [[-2.0, 0.5]], Section("x3", lambda z: np.asarray(z)[0] - 3.0,
                                                              direction=1), 10.0)
    np.testing.assert_allclose(out.state, ref.state, atol=1e-12)


@pytest.mark.parametrize("piece,value,match", [
    ("field_plus", lambda z, p, out: None, r"CompiledModel\.field_plus: expected a numba njit"),
    ("switch", "njit-lazy", r"CompiledModel\.switch: expected a numba njit function compiled with"),
    ("section", "cfunc", r"CompiledModel\.section: expected a numba njit"),
])
def test_a_piece_the_kernel_cannot_call_is_refused(piece, value, match):
    # the kernel calls each piece at its compiled address (kernel.base._piece): a plain
    # function, a numba function not yet compiled with its signature and a numba cfunc
    # (which has no such address: it would crash the process) are refused by name
    import dataclasses

    from numba import cfunc, njit

    from filippov.abi import SCALAR_SIG
    if value == "njit-lazy":
        value = njit(lambda z, p: z[0])
    elif value == "cfunc":
        value = cfunc(SCALAR_SIG)(lambda z, p: z[0])
    cm = dataclasses.replace(_relay_compiled(section=lambda z, p: z[0]), **{piece: value})
    with pytest.raises(TypeError, match=match):
        fastmap.compute_returns(cm, STARTS, 20.0)


def test_a_given_jacobian_is_compared_with_its_field_once_per_mode():
    # x' = y, y' = -x -+ 1, w' = -k w: a typo in dw'/dw (-2k for -k) gave the reference
    # engine's multiplier exp(-2kT) for exp(-kT), silently (the flow's stayed 1)
    from filippov import MINUS, PLUS, SystemContractError
    k = 0.5
    A = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -k]])
    wrong = A.copy()
    wrong[2, 2] = -2 * k

    def system(J):
        return FilippovSystem(("x", "y", "w"),
                              lambda z, p: np.array([z[1], -z[0] + 1.0, -p[0] * z[2]]),
                              lambda z, p: np.array([z[1], -z[0] - 1.0, -p[0] * z[2]]),
                              switch=lambda z, p: z[0], switch_grad=lambda z, p: np.array(
                                  [1.0, 0.0, 0.0]), params=[k],
                              jacobians={"minus": lambda z, p: A.copy(),
                                         "plus": lambda z, p: J.copy()})
    z = np.array([0.3, -0.2, 1.5])
    good = system(A)
    assert np.array_equal(good.jacobian(PLUS, z), A)
    bad = system(wrong)
    assert np.array_equal(bad.jacobian(MINUS, z), A)   # the right one passes
    with pytest.raises(SystemContractError, match=r"jacobians\['plus'\]: at z=.*entry \[2, 2\] "
                                                  r"is -1\.0, central differences of "
                                                  r"field_plus give -0\.49999"):
        bad.jacobian(PLUS, z)
