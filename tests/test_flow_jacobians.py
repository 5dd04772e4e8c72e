"""Flow Jacobians a user gives with closed-form flows (``FilippovSystem(flow_jacobians=
...)``, ``compile_system(flow_jacobian_minus=, flow_jacobian_plus=)``; a
``SymbolicSystem`` generates them: tests/test_symbolic.py): the compiled engine takes an
exact stay's factor of dP/dz from one evaluation of them instead of Richardson's
differences of the flow (docs/decisions.md#richardson-dpdz).

Known answers: the generated systems of tests/generated_systems.py, whose dP/dz is a
product of closed-form factors (matrix exponentials by scipy, saltation matrices, the
section's projection), independent of both the pieces and the engine. Tolerance: TOL
(1e-10) times the product of the factors' norms, as tests/test_units.py holds dP/dz (the
factors' rounding multiplies by it). Measured over 35 draws: 2.2e-14 at most on returns
of exact stays and crossings (Richardson: 1.6e-12), 7.4e-12 on returns with a slide (the
integrated slide's own error; Richardson 7.9e-12).
"""
import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import generated_systems as gs
from filippov import FilippovSystem, SystemContractError
from filippov.fastmap import OK, compute_returns, failure

TOL = 1e-10
CASES = {"crossing": gs.crossings, "slide": gs.slides}


def _dpdz(case, flow_jacobians: bool):
    fs = gs.system(case.g.n, True, flow_jacobians=flow_jacobians)
    gs.load(fs, case.g.p)
    cm = fs.compiled(gs.section, direction=1)
    assert (cm.flow_jacobian_plus is not None) == flow_jacobians
    out = compute_returns(cm, [np.asarray(case.z0, dtype=float)], gs.T_MAX, jacobian=True)
    assert out.status[0] == OK, failure(cm, out, 0)
    return out.jacobian[0]


@pytest.mark.parametrize("kind", sorted(CASES))
@settings(max_examples=6)
@given(data=st.data())
def test_dpdz_from_given_flow_jacobians_is_the_closed_form(kind, data):
    case = data.draw(CASES[kind]())
    assume(case.dP is not None)   # a start on H: P has a kink there, no dP/dz
    scale = max(1.0, case.scale)
    J = _dpdz(case, True)
    assert np.max(np.abs(J - case.dP)) <= TOL * scale, (J, case.dP)
    # and Richardson's differences of the same flows (the model without them) agree
    assert np.max(np.abs(J - _dpdz(case, False))) <= TOL * scale


def _rotation(z0, tau, p):
    c, s = np.cos(tau), np.sin(tau)
    return np.array([[c, s], [-s, c]])


def _flow_plus(z0, tau, p):
    c, s = np.cos(tau), np.sin(tau)
    return np.array([c * z0[0] + s * z0[1], -s * z0[0] + c * z0[1]])


def _spiral(**kw):
    """z' = -z in region - (flow z0 e^-t), a rotation in region + (flow R(t) z0)."""
    jac = {"minus": lambda z0, tau, p: np.exp(-tau) * np.eye(2),
           "plus": _rotation}
    jac.update(kw.pop("flow_jacobians", {}))
    return FilippovSystem(("x", "y"), lambda z, p: -z,
                          lambda z, p: np.array([z[1], -z[0]]), lambda z, p: z[0] - 0.3,
                          lambda z, p: np.array([1.0, 0.0]), flow_jacobians=jac,
                          flow_minus=lambda z0, tau, p: np.exp(-tau) * z0,
                          flow_plus=_flow_plus, sample_step=0.05, **kw)


def test_a_wrong_flow_jacobian_is_refused_by_name():
    wrong = _spiral(flow_jacobians={"plus": lambda z0, tau, p: np.exp(-tau) * np.eye(2)})
    with pytest.raises(SystemContractError, match="flow_jacobian_plus: .* differences of "
                                                  "flow_plus give"):
        wrong.compiled(lambda z, p: z[1], direction=1)
    right = _spiral().compiled(lambda z, p: z[1], direction=1)
    assert right.flow_jacobian_minus is not None


@pytest.mark.parametrize("build, match", [
    (lambda: FilippovSystem(("x",), lambda z, p: -z, lambda z, p: -z, lambda z, p: z[0],
                            lambda z, p: np.ones(1), flow_minus=lambda z0, tau, p: z0,
                            flow_plus=lambda z0, tau, p: z0, sample_step=0.1,
                            flow_jacobians={"plus": np.eye}),
     "flow_jacobians: give those of both"),
    (lambda: FilippovSystem(("x",), lambda z, p: -z, lambda z, p: -z, lambda z, p: z[0],
                            lambda z, p: np.ones(1),
                            flow_jacobians={"minus": np.eye, "plus": np.eye}),
     "flow_jacobians: flow Jacobians need the exact flows"),
])
def test_flow_jacobians_without_their_partner_or_their_flows_are_refused(build, match):
    with pytest.raises(ValueError, match=match):
        build()
