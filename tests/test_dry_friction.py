"""Dry-friction oscillator (sec:dfo1): sign convention, Hopf, GS, stick-slip
stability, slow manifold, reduced vs slow-fast, return-map fixed points and the
saddle-node, each against an independent check or a refinement."""
import numpy as np
import pytest

from filippov.models import dry_friction as df
from filippov_paper.scenes import fig10_dfo as f10
from filippov_paper.scenes import fig11_dfo_retmaps as f11
from filippov.simulate import Section, simulate

LAW = {"f0": -2.0, "fv": 0.3, "fc": 2.5, "convention": "stribeck"}
LAW11 = dict(LAW, gamma=2.0)


def test_adopted_law_makes_sticking_attract_and_literal_law_repel():
    for conv, attracting in (("stribeck", True), ("literal", False)):
        s = df.model(0.0, 3.0, **dict(LAW, convention=conv)).reduced()
        a, b = s.normal_speeds(np.array([0.0, 3.0]))
        assert (a > 0 > b) == attracting
        assert (a < 0 < b) == (not attracting)
    # static level 2, decaying to -0.5 + 0.3|nu| (the paper's commented-out curve)
    nu = np.array([1e-9, 1.0, 5.0])
    np.testing.assert_allclose(df.friction(nu, **LAW), -0.5 + 2.5 * np.exp(-nu) + 0.3 * nu)
    np.testing.assert_allclose(df.friction(-nu, **LAW), -df.friction(nu, **LAW))


def test_model_fields_match_fast_system_and_reduce_to_dfo1():
    full, fast = df.model(0.05, 3.1, **LAW11).full(), df.full_system(0.05, 3.1, **LAW11)
    z = np.array([[1.0, -0.5], [0.2, 2.9], [3.3, 9.0]])
    for mode in (-1, 0, 1):
        np.testing.assert_allclose(full.field(mode, z), fast.field(mode, z), rtol=1e-13, atol=1e-13)
    red = df.model(0.0, 3.1, **LAW11).reduced()
    f = df.plus_field_reduced(3.1, **LAW)[0]
    np.testing.assert_allclose(red.field(1, np.array([1.0, 0.2])), f(np.array([1.0, 0.2])))


def test_hopf_point_matches_analytic_condition():
    vh = df.hopf_speed(**{k: LAW[k] for k in ("fv", "fc")})
    assert abs(vh - np.log(2.5 / 0.3)) < 1e-15
    assert abs(f10.hopf_numeric(df, LAW, (1.0, 3.0)) - vh) < 1e-9
    assert np.isnan(df.hopf_speed(0.3, 2.5, "literal"))


def test_grazing_point_converges_under_tolerance_refinement():
    v = [f10.grazing_speed(df, LAW, (2.2, 3.6), rtol=r, atol=r * 1e-2) for r in (1e-9, 1e-11, 1e-13)]
    assert abs(v[1] - v[2]) < 1e-9 and abs(v[1] - v[2]) <= abs(v[0] - v[2]) + 1e-12
    assert 3.15 < v[2] < 3.16
    # the orbit grazing at GS passes through the sticking exit point (2, v)
    assert abs(f10.gs_mismatch(df, v[2], LAW)) < 1e-10


def test_stick_slip_multipliers_match_forward_simulation():
    v = 2.6
    r = f10.stick_slip_orbit(df, v, LAW)
    m = np.abs(r["multipliers"])
    assert abs(m[0] - 1) < 1e-6 and m[1] < 1e-6   # sticking collapses the neighbourhood
    # forward simulation from a perturbed start: back on the orbit after one period
    system = df.model(0.0, v, **LAW).reduced()
    sec = Section("s", lambda z: z[1], direction=-1, where=lambda z: z[0] > 1.0, terminal=2)
    tr = simulate(system, [r["x1"] + 0.05, 0.0], 100.0, method="integrate", sections=[sec],
                  dense=False)
    assert abs(tr.section_hits("s")[0].state[0] - r["x1"]) < 1e-9
    # the unstable cycle in x2 < v: multiplier > 1
    u = f10.start_cycle(df, 2.64, LAW)
    assert np.abs(f10.multipliers_smooth(df, u, LAW)[0]) > 1.5


def test_slow_manifold_is_invariant_and_attracting():
    x1 = np.array([3.0, 4.0])
    w, est = df.slow_manifold_plus(x1, 0.0, 0.01, 3.1, **LAW11)
    assert np.all(est < 1e-12)
    # first-order check: w = v0 + eps gamma F(x2 - v0) + O(eps^2)
    F = df.friction_branches(**LAW)[0](-3.1)
    assert np.all(np.abs(w - (3.1 + 0.01 * 2 * F)) < 1e-3)


def test_reduced_and_slow_fast_returns_converge_as_eps_to_zero():
    # a start point whose orbit sticks: P(x1) approaches the reduced stick-slip amplitude
    v = 3.1
    ref = f10.stick_slip_orbit(df, v, LAW)["x1"]
    errs = []
    for eps in (0.04, 0.01):
        r = f11.return_map(df, [4.5], eps, v, LAW11, with_residual=False)
        errs.append(abs(r["P"][0] - ref))
    assert errs[1] < errs[0] / 2 and errs[1] < 0.05


def test_lemma_case_quantity():
    chi, a, b = f11.lemma_quantity(df, LAW11, 3.1)
    assert chi == pytest.approx(2 * 2.0 * 3.0)   # -2 f0 (1 + gamma) > 0: case 1
    chi_l, _, _ = f11.lemma_quantity(df, dict(LAW11, convention="literal"), 3.1)
    assert chi_l < 0


def test_return_map_fixed_point_stable_under_refinement():
    fp = [f11.P_pair(df, f11.fixed_point_near(df, 4.43, 3.1, 0.01, LAW11, r, r * 1e-2), 3.1, 0.01,
                     LAW11, r, r * 1e-2)[0] for r in (1e-10, 1e-12)]
    assert abs(fp[0] - fp[1]) < 1e-8


# ---------------------------------------------------------------- fig11: grid, onset, saddle-node
def test_saddle_node_converges_under_tolerance_refinement():
    # eps = 0.1 (cheap); search and correction at rtol 1e-9 and at 1e-11
    out = [f11.saddle_node(df, 0.1, LAW11, 4.25, 4.55, 3.15625 + 1.7 * 0.1, rtol=r, atol=r * 1e-2,
                           search_rtol=r * 100) for r in (1e-9, 1e-11)]
    (x_a, v_a, _, vs_a), (x_b, v_b, _, vs_b) = out
    assert abs(v_a - v_b) < 1e-7          # measured: about 1e-9
    assert abs(vs_b - v_b) < 1e-7         # search tolerance vs full-tolerance correction
    assert 3.3227 < v_b < 3.3230 and 4.30 < x_b < 4.37
    # at the fold, P - x1 has a double zero: G(x) = 0 and the max over x1 is ~ 0
    g = f11.P_scalar(df, x_b, v_b, 0.1, LAW11, 1e-11, 1e-13) - x_b
    assert abs(g) < 1e-7


def test_onset_of_sticking_is_located_and_refined_grid_makes_P_continuous():
    eps, v0 = 0.01, 3.1
    start = df.slow_manifold_plus_on_L(4.2, 4.4, eps, v0, **LAW11)
    on = {r: f11.sticking_onset(df, eps, v0, LAW11, 4.30, 4.32, rtol=r, atol=r * 1e-2, start=start)
          for r in (1e-12, 1e-13)}
    x_on = on[1e-12][0]
    assert on[1e-12][1] < 1e-10                    # the iteration converged
    assert abs(on[1e-12][0] - on[1e-13][0]) < 1e-10  # and the tolerance (measured: 7e-12)
    # no sticking just below the onset, sticking just above it, P continuous across
    r = f11.return_map(df, [x_on - 1e-8, x_on + 1e-8], eps, v0, LAW11, with_residual=False,
                       start=start)
    assert r["slide_length"][0] == 0 and r["slide_length"][1] > 0
    assert abs(r["P"][1] - r["P"][0]) < 1e-5
    # refined grid (looser rtol, cheap): the onset is a grid point, and neighbouring
    # values of P differ by at most dP_max everywhere, in particular across the onset
    dP, rt = 0.03, 1e-10
    maps, onsets = f11.refined_return_maps(df, np.linspace(4.27, 4.35, 4), [(eps, v0)], LAW11,
                                           rtol=rt, atol=rt * 1e-2, dP_max=dP, max_rounds=5,
                                           starts=[start])
    x, P = maps[0]["x1"], maps[0]["P"]
    assert np.all(np.diff(x) > 0) and np.all(np.isfinite(P))
    assert abs(onsets[0][0] - x_on) < 1e-7           # rtol 1e-10: measured 4e-8
    k = np.argmin(np.abs(x - onsets[0][0]))
    assert x[k] == onsets[0][0]
    assert maps[0]["slide_length"][k - 1] == 0 and maps[0]["slide_length"][k + 1] > 0
    assert np.max(np.abs(np.diff(P))) <= dP
    assert np.max(np.abs(np.diff(P)[k - 2:k + 2])) <= dP  # near the onset, explicitly


def test_grid_fixed_points_are_fixed_points():
    # as in the scene: fixed points from sign changes of P - x1 on the grid,
    # refined by Brent on the same map (same start points on M_+)
    for eps, v0 in ((0.1, 3.32), (0.01, 3.1)):
        start = df.slow_manifold_plus_on_L(4.2, 4.55, eps, v0, **LAW11)
        x = np.linspace(4.25, 4.5, 6)
        P = lambda a: f11.return_map(df, a, eps, v0, LAW11, with_residual=False, start=start)["P"]
        fps = f11.fixed_points(x, P(x), refine=lambda a: P([a])[0], xtol=1e-12)
        assert len(fps) == 2
        assert np.max(np.abs(P(fps) - fps)) < 1e-10
        # the other construction of the start (pulled back along the slow flow,
        # P_pair; its first hit of L is a hair off x1, amplified by P' - 1 at the
        # unstable point) agrees to that offset and to the ambiguity of M_+
        alt = [f11.P_pair(df, a, v0, eps, LAW11, 1e-12, 1e-14) for a in fps]
        assert max(abs(b - a) for a, b in alt) < (1e-6 if eps < 0.05 else 1e-4)


def test_interpolated_start_points_match_the_relaxation():
    for eps, v0 in ((0.1, 3.32), (0.01, 3.1)):
        start = df.slow_manifold_plus_on_L(3.3, 4.6, eps, v0, **LAW11)
        x = np.array([3.41, 4.217, 4.3049, 4.59])
        w, _ = df.slow_manifold_plus(x, 0.0, eps, v0, **LAW11)
        assert np.max(np.abs(start(x)[0] - w)) < 1e-11
        with pytest.raises(ValueError):
            start([4.7])


def test_fig11_engines_agree():
    """The scene's compiled engine (DOP853 inside the numba kernel) and the
    reference driver give the same returns, sliding times and sticking lengths,
    and the same pair of hits for the saddle-node search."""
    eps, v0 = 0.1, 3.32
    x1 = np.array([4.2, 4.3, 4.35, 4.45, 4.55])
    ref = f11.return_map(df, x1, eps, v0, LAW11, with_residual=False)
    fast = f11.return_map(df, x1, eps, v0, LAW11, with_residual=False, engine="compiled")
    np.testing.assert_array_equal(fast["n_switches"], ref["n_switches"])
    assert np.any(ref["slide_length"] > 0) and np.any(ref["slide_length"] == 0)
    for key in ("P", "time", "slide_time", "slide_length"):
        np.testing.assert_allclose(fast[key], ref[key], rtol=0, atol=1e-11, err_msg=key)
    np.testing.assert_allclose(fast["w"], ref["w"], rtol=0, atol=1e-10)
    a = f11.P_pair(df, 4.4, v0, eps, LAW11, 1e-12, 1e-14)
    b = f11.P_pair(df, 4.4, v0, eps, LAW11, 1e-12, 1e-14, engine="compiled")
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-11)


def test_the_reduced_jacobian_first_then_the_slow_fast_system():
    # both are derived once and kept in one module cache; asking for the reduced
    # Jacobian first once made system() fail with KeyError (found by test order in
    # tests/test_cross_cpu.py: fig10's continuation, then fig11's compiled returns)
    from filippov.models import dry_friction as df
    df._FULL.clear()
    jac = df.reduced_jacobian(1.0)
    assert callable(jac)
    assert df.system(0.1, 3.32).names


def test_numpy_helpers_are_the_definition_printed_in_written_order():
    """The helpers come from the SymPy definition: they agree with its canonical form to
    rounding, and (printed in written order) round exactly like the NumPy text they were
    written as -- which is what keeps the datasets bit-identical."""
    import sympy as sp

    rng = np.random.default_rng(7)
    nu = rng.uniform(-6, 6, 5000)
    x = rng.uniform(-5, 5, (2, 5000))
    for law in (LAW, dict(LAW, convention="literal")):
        a, c, fv = df.law_coefficients(**law)
        Fp, dFp, Fm, dFm = df.friction_branches(**law)
        canon = {m: sp.lambdify(df.nu, df.FRICTION[m].doit().subs({df.s0: a, df.sc: c, df.fv: fv}))
                 for m in ("plus", "minus")}
        np.testing.assert_allclose(Fp(nu), canon["plus"](nu), rtol=1e-13, atol=1e-13)
        np.testing.assert_allclose(Fm(nu), canon["minus"](nu), rtol=1e-13, atol=1e-13)
        # bit for bit the NumPy text the law is written as
        assert np.array_equal(Fp(nu), -a - c * (1 - np.exp(nu)) + fv * nu)
        assert np.array_equal(Fm(nu), a + c * (1 - np.exp(-nu)) + fv * nu)
        assert np.array_equal(dFp(nu), c * np.exp(nu) + fv)
        f, jac, dv = df.plus_field_reduced(3.1, **law)
        for z in x.T[:200]:
            assert np.array_equal(f(z), [z[1], -z[0] - Fp(z[1] - 3.1)])
            assert np.array_equal(jac(z), [[0.0, 1.0], [-1.0, -dFp(z[1] - 3.1)]])
            assert np.array_equal(dv(z), [0.0, dFp(z[1] - 3.1)])


def test_second_order_manifold_solves_the_invariance_equation():
    """W2_PLUS (used by the relaxation and by fig11) is M_+ of the model's region-+ field to
    O(eps^2): eps u' = -u + eps gamma F(x2 - v0 - u), u = w - v0 - gamma x2, leaves O(eps^3)."""
    import sympy as sp

    x1, x2, eps, v0, gamma = df.x1, df.x2, df.eps, df.v0, df.gamma
    F = sp.Function("F")
    a = x2 - v0
    w2 = df.W2_PLUS.doit().subs({df._F: F(a), df._dF: sp.Derivative(F(a), x2)}).doit()
    nu = df.NU.doit().subs(df.w, w2)
    slow = (x2, -x1 - F(nu))                               # SLOW["plus"], the branch kept generic
    assert sp.simplify(df.SLOW["plus"].doit().subs(df.nu, nu).replace(
        lambda e: isinstance(e, df._Branch), lambda e: F(e.args[0])) - slow[1]) == 0
    w_dot = sp.diff(w2, x1) * slow[0] + sp.diff(w2, x2) * slow[1]
    residual = eps * w_dot - df.FAST.doit().subs(df.w, w2)  # eps w' - (eps w')_field on W2
    series = sp.series(residual, eps, 0, 3).removeO()
    assert sp.simplify(series) == 0


def test_definition_is_the_written_pieces():
    """DEFINITION's fields are the written pieces, evaluated (one definition)."""
    import sympy as sp

    law = {df.F_plus: df.FRICTION["plus"].doit()}
    want = df.SLOW["plus"].doit().replace(lambda e: isinstance(e, df.F_plus),
                                          lambda e: law[df.F_plus].subs(df.nu, e.args[0]))
    assert sp.simplify(df.DEFINITION.f_plus[1] - want.subs(df.nu, df.NU.doit())) == 0
    assert sp.simplify(df.DEFINITION.g_plus[0] - df.FAST.doit()) == 0
