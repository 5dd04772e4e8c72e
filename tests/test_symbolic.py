"""The symbolic front-end: one SymPy definition, generated derivatives, both engines.

Known answers: the relay feedback system's periodic orbit and Floquet multipliers
(closed form by matrix exponentials, examples/relay_feedback.py) on both engines
with the generated Jacobians; the paper's Hopf example written symbolically equals
the hand-written model (models/hopf.py) piece by piece, slow-fast and reduced
(y0 solved by SymPy); Filippov's sliding-field Jacobian against central
differences; generated exact flows against the hand-written closed form.
"""
import importlib.util
from pathlib import Path

import numpy as np
import pytest
import sympy as sp

from filippov import (MINUS, PLUS, SLIDING, first_returns_compiled, periodic_orbit,
                      simulate)
from filippov.models import hopf
from filippov.symbolic import SymbolicError, SymbolicSlowFast, SymbolicSystem
from filippov.compiled_system import _flow_of
from filippov.differences import richardson_jacobian
from filippov.variational import fd_jacobian

ROOT = Path(__file__).resolve().parents[1]
U = np.finfo(float).eps


def _relay_example():
    spec = importlib.util.spec_from_file_location("relay_feedback",
                                                  ROOT / "examples" / "relay_feedback.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


x1, x2, x3, y, eps, theta, mu, omega, t = sp.symbols("x1 x2 x3 y eps theta mu omega t")


def relay():
    u = -x1 - 3 * x2 - 3 * x3          # companion form of 1/(s+1)^3
    return SymbolicSystem((x1, x2, x3), [x2, x3, u + 1], [x2, x3, u - 1], x1, name="relay")


def hopf_symbolic(e=1e-2, th=-0.5, m=1.0, om=8 * np.pi):
    r2 = x1 ** 2 + x2 ** 2
    fp = [mu * x1 - omega * x2 - r2 * x1, omega * x1 + mu * x2 - r2 * x2]
    g = [eps * fp[0] + x1 - y]
    return SymbolicSlowFast((x1, x2), (y,), [1, 0], fp, g, g,
                            theta * x1 + (1 - theta) * y + 1, eps=eps,
                            params={eps: e, theta: th, mu: m, omega: om}, name="hopf")


def test_generated_derivatives_of_the_relay():
    S = relay()
    assert S.switch_grad == (1, 0, 0)
    A = np.array([[0, 1, 0], [0, 0, 1], [-1, -3, -3]], dtype=float)
    system = S.system()
    z = np.array([0.3, -0.2, 0.7])
    assert np.array_equal(system.jacobian(PLUS, z), A)
    assert np.array_equal(system.jacobian(MINUS, z), A)
    # dh.(F_- - F_+) = 0 identically: the relay cannot slide, no sliding field to differentiate
    assert S.sliding_field is None
    with pytest.raises(ValueError, match="no Jacobian of mode"):
        system.jacobian(SLIDING, z)


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_relay_periodic_orbit_from_the_symbolic_definition(engine):
    want = _relay_example().closed_form()
    orbit = periodic_orbit(relay().system(), [0.0, 0.5, -0.2], lambda z, p: z[0],
                           direction=+1, engine=engine, t_max=20.0)
    assert abs(orbit.period - want["period"]) < 1e-12
    assert np.max(np.abs(orbit.multipliers - want["multipliers"])) < 1e-9
    assert np.max(np.abs(orbit.point - want["x0"])) < 1e-12


def _hopf_by_hand(z, e, th, m=1.0, om=8 * np.pi):
    """The example's pieces written out in NumPy (eq:exslow2, eq:exfast2)."""
    a, b = z[0], z[1]
    r2 = a * a + b * b
    f1, f2 = m * a - om * b - r2 * a, om * a + m * b - r2 * b
    if z.shape[0] == 2:                  # the reduced system: y = y0(x) = x1
        return {"field_minus": np.stack([np.ones_like(a), np.zeros_like(a)]),
                "field_plus": np.stack([f1, f2]), "switch": a + 1.0,
                "switch_grad": np.stack([np.ones_like(a), np.zeros_like(a)])}
    g = (e * f1 + a - z[2]) / e
    return {"field_minus": np.stack([np.ones_like(a), np.zeros_like(a), g]),
            "field_plus": np.stack([f1, f2, g]), "switch": th * a + (1 - th) * z[2] + 1.0,
            "switch_grad": np.stack([th + 0 * a, 0 * a, (1 - th) + 0 * a])}


@pytest.mark.parametrize("which", ["test definition", "models.hopf"])
def test_hopf_written_once_equals_the_formulas(which):
    """The example written symbolically -- here and in models/hopf.py -- gives, on both
    engines' sides, the pieces written out by hand; y0 = x1 solved by SymPy."""
    M = hopf_symbolic() if which == "test definition" else hopf.DEFINITION
    values = {"eps": 1e-2, "theta": -0.5, "mu": 1.0, "omega": 8 * np.pi}
    assert M.quasi_static() == {y: x1}
    z = np.random.default_rng(0).normal(size=(3, 64))
    ref = hopf.model(1e-2, -0.5)
    for kind, zz in (("full", z), ("reduced", z[:2])):
        want = _hopf_by_hand(zz, 1e-2, -0.5)
        for got in (getattr(M, kind)(values=values).system().python(), getattr(ref, kind)()):
            for piece in ("field_minus", "field_plus", "switch", "switch_grad"):
                a = getattr(got, piece)(zz)
                # the same formulas summed in another order: a few ulp of the largest term
                scale = 1 + np.abs(want[piece]) + 8 * np.pi * np.max(np.abs(zz), axis=0) / 1e-2
                assert np.all(np.abs(a - want[piece]) <= 8 * U * scale), (kind, piece)


def test_sliding_jacobian_against_central_differences():
    S = hopf_symbolic(e=1e-2).full()
    system, python = S.system(), S.system().python()
    for xa in (-0.9, -0.5, 0.2):
        z = np.array([xa, 0.4, (-1 + 0.5 * xa) / 1.5])       # on h = 0 (theta = -0.5)
        J = system.jacobian(SLIDING, z)
        fd = fd_jacobian(lambda zz: python.sliding_field(zz), z, 1e-6)
        # central differences: truncation h^2 |F'''| and rounding u |F| / h, F ~ 1/eps
        assert np.max(np.abs(J - fd)) < 1e-6 * np.max(np.abs(J)), xa


def test_generated_exact_flows_equal_the_closed_form_and_the_integration():
    r02 = x1 ** 2 + x2 ** 2
    e = sp.exp(-2 * mu * t)
    scale = sp.sqrt(mu / (mu + (mu - r02) * (e - 1)))
    c, s = sp.cos(omega * t), sp.sin(omega * t)
    plus = [scale * (c * x1 - s * x2), scale * (s * x1 + c * x2)]
    r2 = x1 ** 2 + x2 ** 2
    fp = [mu * x1 - omega * x2 - r2 * x1, omega * x1 + mu * x2 - r2 * x2]
    params = {mu: 1.0, omega: 8 * np.pi}
    exact = SymbolicSystem((x1, x2), [1, 0], fp, x1 + 1, params=params, time=t,
                           flows={"minus": [x1 + t, x2], "plus": plus},
                           sample_step=0.25 / 16, name="hopf reduced")
    flow = exact.system().python().flows[PLUS]
    z0, tau = np.array([0.3, -0.8]), np.linspace(0, 0.3, 7)
    want = np.stack(hopf.polar_flow(z0[0], z0[1], tau, 1.0, 8 * np.pi))
    assert np.max(np.abs(flow(z0, tau) - want)) < 16 * U
    integrated = SymbolicSystem((x1, x2), [1, 0], fp, x1 + 1, params=params, name="integrated")
    starts = [[0.0, 0.9], [0.0, 1.1], [0.0, 1.3]]
    # the section L1 as an expression (generated) and as a function (compiled)
    got = [first_returns_compiled(exact.system().compiled(x1, direction=-1, where=x2 > 0),
                                  starts, 5.0),
           first_returns_compiled(integrated.system().compiled(
               lambda z, p: z[0], direction=-1, where=lambda z, p: z[1] > 0), starts, 5.0)]
    assert np.all(np.isfinite(got[0].state)) and np.all(got[0].n_switches == got[1].n_switches)
    assert np.max(np.abs(got[0].state - got[1].state)) < 1e-9
    assert np.max(np.abs(got[0].time - got[1].time)) < 1e-9
    # the reference driver with the generated section and its condition
    system = exact.system()
    sec = system.python_section(x1, direction=-1, where=x2 > 0)
    traj = simulate(system.python(), starts[1], 5.0, sections=[sec], dense=False)
    assert traj.status == "section:section"
    assert abs(traj.t - got[0].time[1]) < 1e-9


def _richardson_flow_jacobian(flow, z0, tau, p):
    """d flow / d z0 by Richardson's extrapolation of central differences of a compiled
    flow piece (the compiled engine's way without flow Jacobians), an independent check
    of the generated ones."""
    return richardson_jacobian(_flow_of(flow, tau, p, z0.size), z0)


def test_generated_flow_jacobians_equal_differences_of_the_flows():
    """The flow Jacobians generated for the compiled engine's dP/dz (row by row, d flow /
    d z0) against Richardson differences of the generated flows, the paper's slow-fast
    flows in both regions (their truncation and rounding: below 1e-10 here)."""
    cm = hopf.compiled(1e-2, -0.5)
    rng = np.random.default_rng(5)
    for mode in ("plus", "minus"):
        flow, jac = getattr(cm, f"flow_{mode}"), getattr(cm, f"flow_jacobian_{mode}")
        for _ in range(5):
            z0, tau = rng.uniform(-1.2, 1.2, 3), float(rng.uniform(0.0, 0.1))
            got = np.empty(9)
            jac(z0, tau, cm.params, got)
            want = _richardson_flow_jacobian(flow, z0, tau, cm.params)
            assert np.max(np.abs(got.reshape(3, 3) - want)) < 1e-10 * np.max(np.abs(want)), \
                (mode, z0, tau)


def test_compiled_dpdz_takes_the_generated_flow_jacobians():
    """dP/dz of the compiled engine through exact stays comes from the model's flow
    Jacobians where it has them: with them and without (Richardson) the same to 1e-10
    (Richardson's error: 1.4e-12 here), and a wrong flow
    Jacobian (region -'s given for region +) changes it; one without the other is refused
    by name."""
    import dataclasses

    from filippov.fastmap import OK, compute_returns

    # four crossings, no sliding: dP/dz of order 0.3 (sliding's projection leaves 1e-5
    # of the factors' product, so that 1e-12 of Richardson's error reads as 1e-7)
    cm = hopf.compiled(1e-2, -0.5)
    start = np.array([[0.0, 1.3, 0.0]])
    runs = {"exact": cm,
            "richardson": dataclasses.replace(cm, flow_jacobian_plus=None,
                                              flow_jacobian_minus=None),
            "wrong": dataclasses.replace(cm, flow_jacobian_plus=cm.flow_jacobian_minus)}
    out = {k: compute_returns(m, start, 5.0, jacobian=True)
           for k, m in runs.items()}
    assert all(o.status[0] == OK for o in out.values())
    assert out["exact"].n_switches[0] == 4
    J = out["exact"].jacobian[0]
    assert np.array_equal(out["exact"].state, out["richardson"].state)
    assert np.max(np.abs(J - out["richardson"].jacobian[0])) < 1e-10 * np.max(np.abs(J))
    assert np.max(np.abs(J - out["wrong"].jacobian[0])) > 1e-3 * np.max(np.abs(J))
    half = dataclasses.replace(cm, flow_jacobian_minus=None)
    with pytest.raises(ValueError, match="flow_jacobian_plus, flow_jacobian_minus"):
        compute_returns(half, start, 5.0, jacobian=True)


def test_with_params_shares_the_generated_pieces():
    M = hopf_symbolic()
    a = M.full()
    b = a.with_params(theta=0.5)
    assert a.module() is b.module()
    z = np.array([0.1, 0.2, 0.3])
    assert a.system().python().switch(z) == pytest.approx(-0.5 * 0.1 + 1.5 * 0.3 + 1)
    assert b.system().python().switch(z) == pytest.approx(0.5 * 0.1 + 0.5 * 0.3 + 1)
    with pytest.raises(SymbolicError, match="unknown parameter.*kappa"):
        a.with_params(kappa=1.0)


@pytest.mark.parametrize("build, match", [
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1 + y], x1), r"field_plus: unknown symbol\(s\) y"),
    (lambda: SymbolicSystem((x1, x2), [x2], [x2, -x1], x1), "field_minus: expected 2 expressions"),
    (lambda: SymbolicSystem(("x1", x2), [x2, -x1], [x2, -x1], x1), "states: expected SymPy symbols"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1], x1 / 0), "switch: .* not finite"),
    (lambda: SymbolicSystem(sp.symbols("x numpy"), [1, 0], [-1, 0], x1),
     "states: the symbol name 'numpy' cannot be a variable"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1], x1, params={sp.Symbol("_k"): 1}),
     "params: the symbol name '_k'"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [mu, -x1], x1, params={mu: np.nan}),
     "params: values of mu must be finite"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1], x1, time=t,
                            flows={"plus": [x1, x2]}), "flows: give the flows of both regions"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1], x1, flows={"plus": [x1, x2],
                            "minus": [x1, x2]}), "time: exact flows need a time symbol"),
    (lambda: SymbolicSlowFast((x1,), (y,), [1], [-1], [y ** 2 - x1], [y ** 2 - x1], y,
                              eps=eps, params={eps: 0.1}).reduced(),
     "g_minus: g = 0 at eps = 0 has 2 solution"),
    (lambda: SymbolicSlowFast((x1,), (y,), [1], [-1], [x1 - y], [-x1 - y], y,
                              eps=eps, params={eps: 0.1}).reduced(), "y0\\(x\\) differ"),
    (lambda: SymbolicSlowFast((x1,), (y,), [1], [-1], [x1 - y], [x1 - y], y,
                              eps=eps, params={}), "eps: the small parameter"),
    (lambda: SymbolicSlowFast((x1,), (y,), [1], [-1], [x1 - y], [x1 - y], y,
                              eps=eps, params={eps: 0.0}).full(), "eps: the slow-fast system"),
    # a jump inside a region (sign, Heaviside): the printer's raw error about its
    # derivative before
    (lambda: SymbolicSystem((x1, x2), [x2, -x1 - sp.sign(x2)], [x2, -x1], x1),
     r"field_minus: sign\(x2\) jumps inside a region"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1 + sp.Heaviside(x2 - 1)], x1),
     r"field_plus: Heaviside\(x2 - 1\) jumps inside a region"),
    (lambda: SymbolicSystem((x1, x2), [x2, -x1], [x2, -x1], x1 + sp.floor(x2)),
     r"switch: floor\(x2\) jumps"),
    # a kink has no Jacobian formula: named where the module is generated
    (lambda: SymbolicSystem((x1, x2), [x2, -x1 - sp.Abs(x2)], [x2, -x1], x1).module(),
     r"jacobian_minus: cannot be written as code .*kink"),
])
def test_bad_definitions_are_refused_naming_the_piece(build, match):
    with pytest.raises(SymbolicError, match=match):
        build()


_CACHE_PROBE = """
import sys, numpy as np, sympy as sp
from filippov.symbolic import SymbolicSystem
x1, x2 = sp.symbols("x1 x2")
S = SymbolicSystem((x1, x2), [x2, -x1 + 1], [x2, -x1 - 1], x1, name="cache probe")
mod = S.module()
out = np.empty(2)
mod.field_plus(np.array([0.5, 0.25]), np.empty(0), out)
print(out.tolist(), sum(mod.field_plus.stats.cache_hits.values()))
"""


def test_generated_pieces_are_compiled_once_per_machine(tmp_path):
    """A second process loads the generated pieces from numba's cache; an unwritable
    cache directory still gives correct pieces (compiled in memory)."""
    import os
    import subprocess
    import sys

    def run(cache):
        env = dict(os.environ, FILIPPOV_CACHE_DIR=str(cache),
                   PYTHONPATH=str(ROOT / "src") + os.pathsep + os.environ.get("PYTHONPATH", ""))
        res = subprocess.run([sys.executable, "-c", _CACHE_PROBE], env=env,
                             capture_output=True, text=True, timeout=300)
        assert res.returncode == 0, res.stderr[-2000:]
        return res.stdout.split()
    first, second = run(tmp_path / "c"), run(tmp_path / "c")
    assert first[:2] == second[:2] == ["[0.25,", "-1.5]"]
    assert first[2] == "0" and int(second[2]) > 0
    blocked = tmp_path / "file"
    blocked.write_text("not a directory")
    assert run(blocked / "c")[:2] == ["[0.25,", "-1.5]"]
