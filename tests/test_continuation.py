"""The continuation pieces on problems with known answers."""
import numpy as np

from filippov import continuation as cont


def test_pseudo_arclength_follows_a_circle_through_its_folds():
    # u = (x, p) on x^2 + p^2 = 1: folds in p at x = 0 (p = +-1)
    G = lambda u: np.array([u[0] ** 2 + u[1] ** 2 - 1.0])
    br = cont.pseudo_arclength(G, np.array([-1.0, 0.0]), [0.0, 1.0], ds=0.1, ds_max=0.1,
                               n_max=25)
    assert np.max(np.abs(br.u[:, 0] ** 2 + br.u[:, 1] ** 2 - 1)) < 1e-10
    assert len(br.folds) >= 1
    i = br.folds[0]
    u, kind = cont.locate_fold(G, br.u[i], br.u[i + 1], param_index=1, state_index=0)
    assert kind == "max"
    assert abs(u[1] - 1.0) < 1e-12 and abs(u[0]) < 1e-5


def test_shooting_finds_the_hopf_normal_form_cycle():
    # x' = p x - y - r^2 x, y' = x + p y - r^2 y: cycle of radius sqrt(p), period 2 pi,
    # nontrivial multiplier exp(-4 pi p)
    def make(p):
        def f(x):
            r2 = x[0] ** 2 + x[1] ** 2
            return np.array([p * x[0] - x[1] - r2 * x[0], x[0] + p * x[1] - r2 * x[1]])

        def dfdx(x):
            a, b = x
            return np.array([[p - 3 * a * a - b * b, -1 - 2 * a * b],
                             [1 - 2 * a * b, p - a * a - 3 * b * b]])
        return f, dfdx, lambda x: np.array([x[0], x[1]])
    G, J, _ = cont.shooting_residual(make, 1, 0.0, 2)
    u, _ = cont.newton(G, J, np.array([0.6, 6.0, 0.3]),
                       extra=lambda u: (u[2] - 0.3, np.array([0.0, 0.0, 1.0])))
    assert abs(u[0] - np.sqrt(0.3)) < 1e-10 and abs(u[1] - 2 * np.pi) < 1e-10
    f, dfdx, dfdp = make(0.3)
    _, Phi, _, _ = cont.flow_with_sensitivities(f, dfdx, dfdp, [u[0], 0.0], u[1])
    m = np.sort(np.abs(np.linalg.eigvals(Phi)))
    assert abs(m[0] - np.exp(-4 * np.pi * 0.3)) < 1e-8 and abs(m[1] - 1) < 1e-8


def test_saltation_projects_onto_the_switching_surface():
    fb, fa, n = np.array([1.0, -1.0]), np.array([1.0, 0.0]), np.array([0.0, 1.0])
    S = cont.saltation(fb, fa, n)
    assert np.allclose(n @ S, 0.0)
    assert np.allclose(S @ fb, fa)
