"""Periodic orbits by Newton on the return map with the engine's dP/dz, on both engines
from one definition, against closed forms (examples/relay_feedback.py and
examples/stick_slip.py)."""
import importlib.util
from pathlib import Path

import numpy as np
import pytest

from filippov import FilippovSystem, PeriodicOrbitError, periodic_orbit
from filippov.periodic import floquet_from_return

ROOT = Path(__file__).resolve().parents[1]
ENGINES = ("compiled", "reference")


def _example(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _relay():
    # x' = A x - b sign(x1), A the companion matrix of (s + 1)^3
    def field(u):
        return lambda z, p: np.array([z[1], z[2], -z[0] - 3 * z[1] - 3 * z[2] + u])
    return FilippovSystem(("x1", "x2", "x3"), field(1.0), field(-1.0),
                          switch=lambda z, p: z[0],
                          switch_grad=lambda z, p: np.array([1.0, 0.0, 0.0]))


@pytest.mark.parametrize("engine", ENGINES)
def test_the_relay_orbit_through_its_switching_surface(engine):
    # the section is the switching surface itself (crossed upwards)
    want = _example("relay_feedback").closed_form()
    orbit = periodic_orbit(_relay(), [0.0, 0.1, 0.0], lambda z, p: z[0], direction=+1,
                           engine=engine, t_max=20.0)
    assert orbit.period == pytest.approx(want["period"], rel=1e-12)
    np.testing.assert_allclose(orbit.point[1:], want["x0"][1:], rtol=0, atol=1e-10)
    # the nontrivial multipliers through dP/dz: the compiled engine's (internal
    # differentiation at rtol 1e-12) and the reference driver's (variational equations
    # at rtol 1e-10, finite-difference Jacobians)
    np.testing.assert_allclose(orbit.multipliers, want["multipliers"], rtol=0, atol=1e-9)
    assert orbit.iterations <= 8


@pytest.mark.parametrize("engine", ENGINES)
def test_the_stick_slip_orbit_has_a_flat_return_map(engine):
    ex = _example("stick_slip")
    want = ex.closed_form()

    def slip(friction):
        return lambda z, p: np.array([z[1], -z[0] + friction + ex.D * (z[1] - ex.V)])
    system = FilippovSystem(("x", "x'"), slip(-ex.F), slip(ex.F),
                            switch=lambda z, p: ex.V - z[1],
                            switch_grad=lambda z, p: np.array([0.0, -1.0]))
    orbit = periodic_orbit(system, [ex.F + 0.8, 0.0], lambda z, p: z[1], direction=-1,
                           engine=engine, t_max=50.0)
    assert orbit.point[0] == pytest.approx(want["fixed_point"], rel=1e-10)
    assert orbit.period == pytest.approx(want["period"], rel=1e-10)
    # every nearby start sticks and is released at x = F: dP/dz = 0, multipliers 1 and 0
    np.testing.assert_allclose(orbit.multipliers, want["multipliers"], rtol=0, atol=1e-9)


def test_a_derivative_that_keeps_the_flow_direction_is_refused():
    with pytest.raises(PeriodicOrbitError, match="annihilate the flow"):
        floquet_from_return(np.eye(2), np.array([1.0, 0.0]))
    with pytest.raises(PeriodicOrbitError, match="not finite"):
        floquet_from_return(np.full((2, 2), np.nan), np.array([1.0, 0.0]))


def test_no_convergence_and_bad_guesses_are_errors():
    with pytest.raises(PeriodicOrbitError, match="did not converge"):
        periodic_orbit(_relay(), [0.0, 2.0, 0.0], lambda z, p: z[0], direction=+1,
                       t_max=20.0, max_iter=1)
    with pytest.raises(ValueError, match="guess"):
        periodic_orbit(_relay(), [0.0, np.nan, 0.0], lambda z, p: z[0], t_max=20.0)
    with pytest.raises(ValueError, match="engine"):
        periodic_orbit(_relay(), [0.0, 0.1, 0.0], lambda z, p: z[0], t_max=20.0,
                       engine="fortran")


@pytest.mark.parametrize("engine", ENGINES)
def test_an_orbit_counted_twice_has_the_squared_multipliers(engine):
    # returns=2: the same orbit as a fixed point of P^2 -- twice the period, d(P^2)/dz, and
    # the multipliers squared (the flow's 1 stays 1)
    want = _example("relay_feedback").closed_form()
    once = periodic_orbit(_relay(), [0.0, 0.1, 0.0], lambda z, p: z[0], direction=+1,
                          engine=engine, t_max=20.0)
    twice = periodic_orbit(_relay(), once.point, lambda z, p: z[0], direction=+1,
                           returns=2, engine=engine, t_max=20.0)
    assert twice.period == pytest.approx(2 * want["period"], rel=1e-12)
    np.testing.assert_allclose(twice.point, once.point, rtol=0, atol=1e-10)
    np.testing.assert_allclose(twice.multipliers, np.asarray(want["multipliers"]) ** 2,
                               rtol=0, atol=1e-9)
    with pytest.raises(ValueError, match="returns must be an integer >= 1"):
        periodic_orbit(_relay(), once.point, lambda z, p: z[0], returns=0, t_max=20.0)
