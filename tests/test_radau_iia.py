"""The Radau IIA stepper (filippov.radau_iia): tableau, order, stiff accuracy."""
import numpy as np
import pytest
from numpy.polynomial import legendre
from scipy.integrate import solve_ivp
from scipy.integrate._ivp import radau as scipy_radau

from filippov.radau_iia import RadauIIA, tableau


def _tableau_from_definition(stages):
    """The tableau in double precision from its definition (see Tableau)."""
    s = stages
    basis = np.zeros(s + 1)
    basis[s], basis[s - 1] = 1.0, -1.0
    c = np.sort((legendre.legroots(basis).real + 1.0) / 2.0)
    c[-1] = 1.0
    powers = np.arange(1, s + 1)
    vander = c[:, None] ** (powers - 1)
    A = np.linalg.solve(vander.T, (c[:, None] ** powers / powers).T).T
    eig = np.linalg.eigvals(A)
    gamma0 = float(eig[np.argmin(np.abs(eig.imag))].real)
    rhs = 1.0 / powers
    rhs[0] -= gamma0
    b_hat = np.linalg.solve(vander.T, rhs)
    e = np.linalg.solve(A.T, b_hat - A[-1])
    return c, A, gamma0, e, np.linalg.inv(c[:, None] ** powers)


@pytest.mark.parametrize("stages", [3, 5, 7])
def test_vendored_tableaux_are_their_definitions(stages):
    tab = tableau(stages)
    c, A, gamma0, e, to_poly = _tableau_from_definition(stages)
    # the double-precision derivation solves with Vandermonde matrices: its error
    # is u times their condition number (1e3 at 7 stages), not the constants'
    powers = np.arange(1, stages + 1)
    tol = 8 * np.finfo(float).eps * np.linalg.cond(c[:, None] ** powers)
    np.testing.assert_allclose(tab.c, c, rtol=0, atol=4 * np.finfo(float).eps)
    np.testing.assert_allclose(tab.A, A, rtol=0, atol=tol)
    assert abs(tab.gamma0 - gamma0) < tol
    np.testing.assert_allclose(tab.e, e, rtol=0, atol=tol * np.abs(e).max())
    np.testing.assert_allclose(tab.to_poly, to_poly, rtol=0, atol=tol * np.abs(to_poly).max())


def test_three_stage_tableau_is_scipys_radau5():
    # scipy hard-codes the 3-stage method: nodes, error weights, 1/gamma0
    t3 = tableau(3)
    np.testing.assert_allclose(t3.c, scipy_radau.C, rtol=0, atol=2e-16)
    np.testing.assert_allclose(t3.e / t3.gamma0, scipy_radau.E, rtol=1e-14)
    assert abs(1 / t3.gamma0 - scipy_radau.MU_REAL) < 1e-14


@pytest.mark.parametrize("stages", [3, 5, 7])
def test_tableau_is_the_collocation_method(stages):
    tab = tableau(stages)
    # A integrates polynomials of degree < s exactly up to each node; b = last row
    for k in range(1, stages + 1):
        # absolute: the sum of |A_ij c_j^(k-1)| is <= 1, so its rounding is a few u
        np.testing.assert_allclose(tab.A @ tab.c ** (k - 1), tab.c ** k / k, rtol=0,
                                   atol=1e-15)
    # the quadrature b has order 2s - 1
    for k in range(1, 2 * stages):
        assert abs(tab.A[-1] @ tab.c ** (k - 1) - 1 / k) < 1e-14
    assert tab.c[-1] == 1.0


def test_even_stage_counts_are_refused():
    with pytest.raises(ValueError, match="stages must be one of"):
        tableau(4)


def _linear(t, y):  # y'' = -y as a first-order system; exact: (cos t, -sin t)
    return np.stack([y[1], -y[0]])


@pytest.mark.parametrize("stages, order", [(3, 5), (5, 9)])
def test_convergence_order_on_fixed_steps(stages, order):
    # fixed steps (tolerances so loose the step is max_step): error ~ h^order
    errors = []
    for n in (4, 8):
        sol = solve_ivp(_linear, [0, 2.0], [1.0, 0.0], method=RadauIIA, stages=stages,
                        rtol=1e-1, atol=1e3, max_step=2.0 / n, first_step=2.0 / n,
                        vectorized=True)
        assert sol.status == 0 and sol.t.size == n + 1
        errors.append(abs(sol.y[0, -1] - np.cos(2.0)))
    measured = np.log2(errors[0] / errors[1])
    assert order - 0.6 < measured < order + 0.8, measured


def test_stiff_van_der_pol_agrees_with_scipys_radau_at_tight_tolerance_in_fewer_steps():
    eps = 1e-6

    def vdp(t, y):
        return np.stack([y[1], ((1 - y[0] ** 2) * y[1] - y[0]) / eps])

    ref = solve_ivp(vdp, [0, 0.8], [2, -0.66], method="Radau", rtol=1e-13, atol=1e-13)
    five = solve_ivp(vdp, [0, 0.8], [2, -0.66], method=RadauIIA, rtol=1e-12, atol=1e-12,
                     vectorized=True)
    three = solve_ivp(vdp, [0, 0.8], [2, -0.66], method="Radau", rtol=1e-12, atol=1e-12)
    assert abs(five.y[0, -1] - ref.y[0, -1]) < 1e-12
    # measured 172 steps against 1655 (order 9 with an order-5 estimate)
    assert 4 * five.t.size < three.t.size


def test_dense_output_is_the_collocation_polynomial_and_accurate_between_steps():
    solver = RadauIIA(_linear, 0.0, np.array([1.0, 0.0]), 10.0, rtol=1e-10, atol=1e-12,
                      vectorized=True)
    solver.step()
    solver.step()
    dense = solver.dense_output()
    # ends where the step ends, up to the rounding of the polynomial's sum (a few
    # ulps of its largest term: here x2 ~ -9e-4 from terms of size ~1)
    np.testing.assert_allclose(dense(solver.t), solver.y, rtol=0,
                               atol=8 * np.finfo(float).eps)
    t = solver.t_old + 0.37 * (solver.t - solver.t_old)
    exact = np.array([np.cos(t), -np.sin(t)])
    assert np.abs(dense(t) - exact).max() < 1e-9
    np.testing.assert_array_equal(dense(np.array([t, t]))[:, 0], dense(t))


def test_atol_is_read_in_every_step():
    # the driver lifts atol between steps (its noise floor): the next step sees it
    def run(loosen):
        solver = RadauIIA(_linear, 0.0, np.array([1.0, 0.0]), 10.0, rtol=1e-12,
                          atol=1e-14, vectorized=True)
        for _ in range(3):
            solver.step()
        if loosen:
            solver.atol, solver.rtol = 1e-4, 1e-4
        for _ in range(3):
            solver.step()
        return solver.t
    assert run(True) > 2 * run(False)
