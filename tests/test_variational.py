"""dP/dz0 of return maps from the variational equations and saltation matrices
(filippov.variational) against central differences of P itself."""
import numpy as np
import pytest

from filippov import simulate
from filippov.models import hopf
from filippov_paper.scenes.fig04_retmaps import section_L1
from filippov.variational import VariationalError, return_jacobian, transition_matrix

T_MAX = 4 * 2 * np.pi / (8 * np.pi)   # four rotation periods: one return to L1


def _P(system, z0):
    traj = simulate(system, z0, T_MAX, sections=[section_L1()], dense=False)
    assert traj.status == "section:L1", traj.status
    return traj


def _fd_column(system, z0, k, h):
    """Central difference of P along coordinate k (the start stays on L1: k != 0)."""
    up, um = np.array(z0, float), np.array(z0, float)
    up[k] += h
    um[k] -= h
    return (_P(system, up).z - _P(system, um).z) / (2 * h)


@pytest.mark.parametrize("kind,theta,x2", [
    ("reduced", 0.5, 1.2),    # grazes into sliding, slides, leaves: P is constant there
    ("full", -0.5, 1.1),      # crossings into H_- and back, no sliding
    ("full", -0.5, 0.9),      # no switch at all: the smooth flow alone
])
def test_return_jacobian_matches_finite_differences(kind, theta, x2):
    model = hopf.model(0.01, theta)
    system = model.system(kind)
    z0 = [0.0, x2] + ([0.0] if kind == "full" else [])
    traj = _P(system, z0)
    J = return_jacobian(system, traj, section_L1(), rtol=1e-11, atol=1e-13)
    kinds = {e.kind for e in traj.events}
    if x2 > 1:
        assert "crossing" in kinds or "slide_start" in kinds
    # central differences: truncation O(h^2 P''') and rounding O(1e-13 / h), balanced
    # near h = 1e-5 (P has O(1) derivatives here); the agreement is limited by them
    for k in range(1, system.dim):
        fd = _fd_column(system, z0, k, 1e-5)
        np.testing.assert_allclose(J[:, k], fd, rtol=0, atol=2e-7 * max(1.0, np.abs(fd).max()),
                                   err_msg=f"column {k}")
    # P lies on x1 = 0: no perturbation leaves the section
    np.testing.assert_allclose(J[0], 0.0, atol=1e-12)


def test_transition_matrix_of_the_smooth_flow_is_its_jacobian():
    # region + of the reduced Hopf example has the exact flow polar_flow: compare
    # dz(t)/dz0 with central differences of it (no events)
    model = hopf.model(0.01, -0.5)
    system = model.reduced()
    z0, t = np.array([0.3, 0.8]), 0.1
    traj = simulate(system, z0, t, dense=False)
    assert [e.kind for e in traj.events] == ["start"]
    Phi = transition_matrix(system, traj, rtol=1e-12, atol=1e-14)
    flow = lambda z: np.array(hopf.polar_flow(z[0], z[1], np.array(t), 1.0, 8 * np.pi))
    fd = np.stack([(flow(z0 + e) - flow(z0 - e)) / 2e-6 for e in 1e-6 * np.eye(2)], axis=1)
    np.testing.assert_allclose(Phi, fd, atol=1e-8)


def test_return_jacobian_refuses_a_run_that_did_not_end_on_the_section():
    model = hopf.model(0.01, 0.5)
    traj = simulate(model.reduced(), [0.0, 1.2], 0.05, sections=[section_L1()], dense=False)
    with pytest.raises(VariationalError, match="not at a hit of section 'L1'"):
        return_jacobian(model.reduced(), traj, section_L1())


def _sliding_plane():
    """z = (x, y, w), H = y: region + has y' = -1 + x/2, region - has y' = 1 + x/2,
    both x' = 1 and w' = -0.3 w + 0.2 sin x. Orbits from y > 0 slide on y = 0 for
    -2 < x < 2 and leave it at the fold x = 2 (y' = 0 there): the slide collapses y,
    x and w keep their perturbations, so dP is neither zero nor the smooth flow's."""
    from filippov import PiecewiseSystem

    def fields(sign):
        def f(z):
            z = np.asarray(z, float)
            return np.stack([np.ones_like(z[0]), sign + 0.5 * z[0],
                             -0.3 * z[2] + 0.2 * np.sin(z[0])])
        return f

    return PiecewiseSystem(names=("x", "y", "w"), field_minus=fields(1.0),
                           field_plus=fields(-1.0), switch=lambda z: np.asarray(z)[1],
                           switch_grad=lambda z: np.stack([0 * np.asarray(z)[0],
                                                           np.ones_like(np.asarray(z)[0]),
                                                           0 * np.asarray(z)[0]]))


def test_return_jacobian_through_sliding_matches_finite_differences():
    from filippov import Section

    system = _sliding_plane()
    section = Section("x3", lambda z: np.asarray(z)[0] - 3.0, direction=1, terminal=1)
    run = lambda z0: simulate(system, z0, 10.0, sections=[section], dense=False)
    z0 = np.array([0.0, 0.5, 0.2])
    traj = run(z0)
    assert traj.status == "section:x3"
    assert [e.kind for e in traj.events][1:3] == ["slide_start", "slide_end"]
    J = return_jacobian(system, traj, section, rtol=1e-11, atol=1e-13)

    def fd(h):  # all three directions: x0 moves the start off x = 0, fine here
        return np.stack([(run(z0 + e).z - run(z0 - e).z) / (2 * h) for e in h * np.eye(3)],
                        axis=1)

    # The difference quotient carries the noise of P (integration to rtol 1e-12, event
    # location) divided by h: ~2e-13/h here, and another CPU rounds differently. Its
    # error is estimated from two step sizes (the noise differs, the O(h^2) part is
    # far below it) and bounded, so the check adapts to the noise, not to this machine.
    fd1, fd2 = fd(1e-5), fd(2e-5)
    tol = 4 * np.abs(fd1 - fd2).max() + 1e-10
    assert tol < 1e-6
    np.testing.assert_allclose(J, fd1, atol=tol)
    assert abs(J[2, 2]) > 0.1 and abs(J[1, 1]) < 1e-8   # w survives, y is collapsed
