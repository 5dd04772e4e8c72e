"""One front door per capability (issue 32, item 2): simulate, first_returns and
periodic_orbit take a system and ``engine=``; the engine is chosen in one place
(filippov.engines); the same question gets the same answer on both engines; a wrong
engine or a system the engine cannot run is an error naming what to do."""
import re
from pathlib import Path

import numpy as np
import pytest

from filippov import (FilippovSystem, PiecewiseSystem, Section, first_returns,
                      periodic_orbit, simulate)
from filippov import engines

SRC = Path(__file__).resolve().parents[1] / "src" / "filippov"


def _planar():
    # h = x2 in the plane; f_- = (1, 1 + x1/2), f_+ = (1, 1): from (-1, -1) the orbit
    # crosses H at t = sqrt(5) - 1 and meets x1 = 2 at t = 3 (tests/test_engines.py)
    return FilippovSystem(("x1", "x2"), lambda z, p: np.array([1.0, 1.0 + 0.5 * z[0]]),
                          lambda z, p: np.array([1.0, 1.0]), switch=lambda z, p: z[1],
                          switch_grad=lambda z, p: np.array([0.0, 1.0]))


def _stick_slip():
    # a unit oscillator on a belt (speed 1) with Coulomb friction 0.5 and damping 0.1:
    # a stick-slip orbit (examples/stick_slip.py's kind)
    def slip(friction):
        return lambda z, p: np.array([z[1], -z[0] + friction + 0.1 * (z[1] - 1.0)])
    return FilippovSystem(("x", "x'"), slip(-0.5), slip(0.5),
                          switch=lambda z, p: 1.0 - z[1],
                          switch_grad=lambda z, p: np.array([0.0, -1.0]))


def _section(z, p):
    return z[0] - 2.0


def test_first_returns_gives_the_same_return_on_both_engines():
    system, start = _planar(), [[-1.0, -1.0]]
    ref = first_returns(system, start, _section, 5.0, engine="reference", direction=+1,
                        method="integrate")
    com = first_returns(system, start, _section, 5.0, engine="compiled", direction=+1)
    for out in (ref, com):
        assert out.time[0] == pytest.approx(3.0, rel=1e-13)
        assert out.first_switch[0] == pytest.approx(np.sqrt(5) - 1, rel=1e-12)
    np.testing.assert_allclose(ref.state, com.state, rtol=0, atol=1e-12)
    assert ref.n_switches[0] == com.n_switches[0] == 1


def test_first_returns_of_the_reference_view_and_of_a_section_object_agree():
    # the FilippovSystem with its section function, and its python() view with a
    # Section: the same run of the reference driver, bit for bit
    system = _planar()
    a = first_returns(system, [[-1.0, -1.0]], _section, 5.0, direction=+1, method="integrate")
    sec = Section("s", lambda z: z[0] - 2.0, direction=+1)
    b = first_returns(system.python(), [[-1.0, -1.0]], sec, 5.0, method="integrate")
    assert a.state.tolist() == b.state.tolist() and a.time.tolist() == b.time.tolist()


def test_the_old_compiled_name_is_the_front_door():
    from filippov import first_returns_compiled

    cm = _planar().compiled(_section, direction=+1)
    old = first_returns_compiled(cm, [[-1.0, -1.0]], 5.0)
    new = first_returns(cm, [[-1.0, -1.0]], None, 5.0, engine="compiled")
    assert old.state.tolist() == new.state.tolist() and old.time.tolist() == new.time.tolist()
    assert "first_returns" in first_returns_compiled.__doc__


def test_periodic_orbit_gives_the_same_orbit_on_both_engines():
    orbits = [periodic_orbit(_stick_slip(), [1.2, 0.0], lambda z, p: z[1], direction=-1,
                             engine=engine, t_max=50.0) for engine in ("reference", "compiled")]
    np.testing.assert_allclose(orbits[0].point, orbits[1].point, rtol=0, atol=1e-9)
    assert orbits[0].period == pytest.approx(orbits[1].period, rel=1e-9)


def test_simulate_runs_a_system_defined_once_on_its_reference_view():
    system = _planar()
    a = simulate(system, [-1.0, -1.0], 3.0, method="integrate", dense=False)
    b = simulate(system.python(), [-1.0, -1.0], 3.0, method="integrate", dense=False)
    assert a.z.tolist() == b.z.tolist() and len(a.events) == len(b.events) == 2


def test_simulate_on_the_compiled_engine_says_what_it_lacks():
    with pytest.raises(ValueError, match=r"engine='compiled'.*no trajectory output"):
        simulate(_planar(), [-1.0, -1.0], 3.0, engine="compiled")


@pytest.mark.parametrize("call", [
    lambda e: simulate(_planar(), [-1.0, -1.0], 1.0, engine=e),
    lambda e: first_returns(_planar(), [[-1.0, -1.0]], _section, 5.0, engine=e),
    lambda e: periodic_orbit(_planar(), [0.0, 0.0], _section, engine=e, t_max=1.0),
], ids=["simulate", "first_returns", "periodic_orbit"])
@pytest.mark.parametrize("engine", ["python", "numba", None, ""])
def test_an_unknown_engine_is_refused_naming_the_choices(call, engine):
    with pytest.raises(ValueError, match=r"engine must be one of \('reference', 'compiled'\)"):
        call(engine)


def _piecewise():
    return PiecewiseSystem(names=("x1", "x2"),
                           field_minus=lambda z: np.array([1.0 + 0 * z[0], 1.0 + 0.5 * z[0]]),
                           field_plus=lambda z: np.array([1.0 + 0 * z[0], 1.0 + 0 * z[0]]),
                           switch=lambda z: z[1],
                           switch_grad=lambda z: np.array([0 * z[0], 1.0 + 0 * z[0]]))


def test_a_piecewise_system_on_the_compiled_engine_says_how_to_build_one():
    sec = Section("s", lambda z: z[0] - 2.0, direction=+1)
    with pytest.raises(TypeError, match=r"engine='compiled'.*PiecewiseSystem.*FilippovSystem"):
        first_returns(_piecewise(), [[-1.0, -1.0]], sec, 5.0, engine="compiled")
    # and it runs on the reference engine as before
    out = first_returns(_piecewise(), [[-1.0, -1.0]], sec, 5.0, method="integrate")
    assert out.time[0] == pytest.approx(3.0, rel=1e-12)


def test_a_compiled_model_on_the_reference_engine_is_refused():
    cm = _planar().compiled(_section, direction=+1)
    with pytest.raises(TypeError, match=r"engine='reference'.*CompiledModel"):
        first_returns(cm, [[-1.0, -1.0]], None, 5.0, engine="reference")
    with pytest.raises(TypeError, match=r"engine='reference'.*CompiledModel"):
        simulate(cm, [-1.0, -1.0], 1.0)


def test_a_section_object_on_the_compiled_engine_is_refused():
    sec = Section("s", lambda z: z[0] - 2.0, direction=+1)
    with pytest.raises(TypeError, match=r"section: .*s\(z, p\)"):
        first_returns(_planar(), [[-1.0, -1.0]], sec, 5.0, engine="compiled")


def test_periodic_orbit_refuses_a_system_without_both_views():
    with pytest.raises(TypeError, match=r"system: periodic_orbit expected a FilippovSystem"):
        periodic_orbit(_piecewise(), [0.0, 0.0], _section, engine="reference", t_max=1.0)


def test_every_front_door_has_a_runner_or_a_reason_on_each_engine():
    for capability, runs in engines.RUNS.items():
        assert set(runs) == set(engines.ENGINES)
        for engine, target in runs.items():
            if target is None:
                assert (capability, engine) in engines.LACKS
            else:  # a function, not a "module:function" string (issue 58)
                assert callable(target) and engines.runner(capability, engine) is target


_CHOICE = re.compile(r"\bengine\s*(==|!=|\bin\b|\bnot in\b)")


def test_the_engine_is_compared_in_one_module_of_src_only():
    # the engine's name is checked in filippov.views, and each front door looks it up in
    # its table of functions (views.pick); any other module comparing the string is a
    # second place that chooses it
    where = {p.relative_to(SRC).as_posix() for p in SRC.rglob("*.py")
             if _CHOICE.search(p.read_text())}
    assert where <= {"views.py"}, where
    assert _CHOICE.search("if engine == 'compiled':")  # the pattern catches the old form


def test_two_public_system_types():
    """A numeric system and its symbolic front-end; what the engines run is built from
    them (importable below the front doors, not exported)."""
    import inspect

    import filippov

    types = {n for n in filippov.__all__ if inspect.isclass(getattr(filippov, n))
             and n.endswith("System")}
    assert types == {"FilippovSystem", "SymbolicSystem"}
    for name in ("PiecewiseSystem", "compile_system", "SymbolicSlowFast", "CompiledModel",
                 "first_returns_compiled", "SurfacesSystem"):
        assert name not in filippov.__all__ and getattr(filippov, name) is not None


def test_the_analysis_functions_take_the_system_the_front_doors_take():
    """transition_matrix, return_jacobian, monodromy and floquet_multipliers take a
    FilippovSystem as simulate does (its reference view), and its own Jacobians where it
    has them: the same numbers as the reference view with the Jacobian passed."""
    from filippov import (floquet_multipliers, monodromy, return_jacobian,
                          transition_matrix)

    A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -3.0, -3.0]])
    relay = FilippovSystem(
        ("x1", "x2", "x3"),
        lambda z, p: np.array([z[1], z[2], -z[0] - 3.0 * z[1] - 3.0 * z[2] + 1.0]),
        lambda z, p: np.array([z[1], z[2], -z[0] - 3.0 * z[1] - 3.0 * z[2] - 1.0]),
        switch=lambda z, p: z[0], switch_grad=lambda z, p: np.array([1.0, 0.0, 0.0]),
        jacobians={"minus": lambda z, p: A.copy(), "plus": lambda z, p: A.copy()})
    up = Section("up", lambda z: z[0], direction=1, terminal=1)
    orbit = simulate(relay, [0.0, 0.29063092, 0.14460608], 20.0, sections=[up],
                     method="integrate")
    view, jac = relay.python(), (lambda mode, z: A)
    assert isinstance(view, PiecewiseSystem)
    for fn, args in ((transition_matrix, ()), (return_jacobian, (up,))):
        np.testing.assert_array_equal(fn(relay, orbit, *args),
                                      fn(view, orbit, *args, jacobian=jac))
    np.testing.assert_array_equal(monodromy(relay, orbit)[0],
                                  monodromy(view, orbit, jacobian=jac)[0])
    np.testing.assert_array_equal(floquet_multipliers(relay, orbit),
                                  floquet_multipliers(view, orbit, jacobian=jac))
    with pytest.raises(TypeError, match="system: monodromy expected"):
        monodromy(object(), orbit)
