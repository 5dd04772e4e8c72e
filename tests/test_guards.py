"""Guards: bad input, event limits, accumulation of switches, non-finite states."""
import numpy as np
import pytest

from filippov import EventLimitError, PiecewiseSystem, SimulationError, ZenoError, simulate
from filippov.models import pseudo_equilibrium


def test_event_limit_names_time_and_state():
    system = pseudo_equilibrium.model(1e-3, -0.5).full()
    # stopped as soon as the switching rate projects past the budget, or at the budget
    with pytest.raises(EventLimitError, match=r"event limit at t=.*state.*switching"):
        simulate(system, [0.01, 0.0], 10.0, max_events=100)


def test_chatter_below_time_resolution_is_reported_as_zeno():
    system = pseudo_equilibrium.model(1e-13, -0.5).full()
    with pytest.raises(ZenoError, match="accumulation of switches"):
        simulate(system, [1e-12, 0.0], 1.0)


@pytest.mark.parametrize("bad", [[np.nan, 0.0], [0.0, np.inf]])
def test_non_finite_initial_state_rejected(bad):
    system = pseudo_equilibrium.model(0.1, -0.5).full()
    with pytest.raises(ValueError, match="finite"):
        simulate(system, bad, 1.0)


def test_wrong_dimension_rejected():
    system = pseudo_equilibrium.model(0.1, -0.5).full()
    with pytest.raises(ValueError, match="components"):
        simulate(system, [0.0], 1.0)


@pytest.mark.parametrize("eps,theta,match", [(-0.1, 0.5, "eps"), (0.1, 1.0, "theta"),
                                             (np.nan, 0.5, "eps")])
def test_bad_model_parameters_rejected(eps, theta, match):
    with pytest.raises(ValueError, match=match):
        pseudo_equilibrium.model(eps, theta)


def test_nan_from_field_is_not_handed_on():
    bad = lambda z: np.stack([np.full_like(z[0], np.nan), np.ones_like(z[1])])
    system = PiecewiseSystem(names=("a", "b"), field_minus=bad, field_plus=bad,
                             switch=lambda z: z[1],
                             switch_grad=lambda z: np.stack([0 * z[0], 1 + 0 * z[1]]))
    with pytest.raises(SimulationError, match="non-finite|failed"):
        simulate(system, [0.0, 1.0], 1.0, method="integrate")


def test_many_switches_finish_within_bound():
    # 2000 half-periods of the chatter orbit; bounded and periodic throughout
    eps = 1e-4
    system = pseudo_equilibrium.model(eps, -0.5).full()
    from filippov.analytic import chatter
    f = chatter.orbit(eps, -0.5)
    traj = simulate(system, [f["x_switch"], f["y_switch"]], 1000 * f["period"], dense=False,
                    max_events=4_000)
    sw = traj.switches()
    assert len(sw) >= 1999
    assert np.max(np.abs([e.state[0] for e in sw])) == pytest.approx(f["x_switch"], rel=1e-9)
