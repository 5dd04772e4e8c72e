"""The compiled first-return kernel (filippov.fastmap) against the reference driver.

The reference is the pure-Python event-driven driver (simulate.py) through the
fig04 scene's return map; the compiled path must make the same decisions (same
number of switches) and land on the same returns, and must stop with a status
code -- never hang -- where the reference raises.
"""
import dataclasses

import numpy as np
import pytest

from filippov import EventLimitError, SimulationError, ZenoError, simulate
from filippov import fastmap
from filippov.models import hopf, pseudo_equilibrium
from filippov.poincare import Returns
from filippov_paper.scenes.fig04_retmaps import return_map

EPS, MU, OMEGA = 0.01, 1.0, 8 * np.pi
OPTS = {"rtol": 1e-12, "atol": 1e-14}
T_MAX = 4.0 * 2 * np.pi / OMEGA  # as in fig04_retmaps.return_map


def grid():
    k = np.arange(2, 13)
    return np.unique(np.concatenate([np.linspace(0.96, 1.04, 21), 1 - 10.0 ** -k,
                                     1 + 10.0 ** -k, [1.0]]))


def starts(x2):
    return np.stack([np.zeros_like(x2), x2, np.zeros_like(x2)], axis=1)


@pytest.fixture(scope="module", params=[-0.5, 0.5])
def both(request):
    theta = request.param
    x2 = grid()
    _, _, ref = return_map(hopf.model(EPS, theta, MU, OMEGA), x2, "exact", OPTS)
    fast = fastmap.first_returns_compiled(hopf.compiled(EPS, theta, MU, OMEGA), starts(x2),
                                          T_MAX, **OPTS)
    return theta, x2, ref, fast


def test_compiled_returns_agree_with_the_reference(both):
    theta, x2, ref, fast = both
    assert isinstance(fast, Returns)
    np.testing.assert_array_equal(fast.n_switches, ref.n_switches)
    diff = np.abs(fast.state - ref.state).max(axis=1)
    # Away from grazing: 1e-11 absolute. At x2 -> 1+ for theta < 0 the map has a
    # square-root singularity (slope ~ (x2 - 1)^-1/2): there the backward error,
    # difference / |slope|, is what is bounded (as in test_fig04).
    P = ref.state[:, 1]
    slope = np.ones_like(x2)
    for side in (x2 < 1, x2 > 1):
        slope[side] = np.abs(np.gradient(P[side], x2[side]))
    away = np.abs(x2 - 1) > 1e-6
    assert np.all(diff[away] <= 1e-11)
    assert np.all(diff <= 1e-11 + 1e-12 * slope)
    assert np.all(np.abs(fast.time - ref.time)[away] <= 1e-11)
    assert np.all(np.abs(fast.sliding_time - ref.sliding_time)[away] <= 1e-11)
    if theta > 0:  # continuous: sliding returns, and the sliding time is used
        assert np.any(ref.sliding_time > 0)
        assert np.all(diff <= 1e-11)


def test_exactly_at_grazing_the_orbit_touches(both):
    theta, x2, ref, fast = both
    i = np.flatnonzero(x2 == 1.0)[0]
    assert ref.n_switches[i] == fast.n_switches[i] == 0
    assert fast.state[i, 1] == pytest.approx(1.0, abs=1e-15)


def test_compute_returns_reports_status_and_matches_wrapper():
    cm = hopf.compiled(EPS, 0.5, MU, OMEGA)
    x2 = np.array([0.97, 1.0, 1.001, 1.03])
    raw = fastmap.compute_returns(cm, starts(x2), T_MAX)
    assert np.all(raw.status == fastmap.OK)
    wrapped = fastmap.first_returns_compiled(cm, starts(x2), T_MAX)
    np.testing.assert_array_equal(raw.state, wrapped.state)
    np.testing.assert_array_equal(raw.n_switches, wrapped.n_switches)


def test_compiled_hopf_pieces_are_the_model_formulas():
    theta = 0.5
    model = hopf.model(EPS, theta, MU, OMEGA)
    system = model.full()
    cm = hopf.compiled(EPS, theta, MU, OMEGA)
    rng = np.random.default_rng(1)
    out = np.empty(3)
    for z in rng.uniform(-1.5, 1.5, size=(20, 3)):
        for tau in (0.0, 1e-3, 0.07):
            cm.flow_plus(z, tau, cm.params, out)
            np.testing.assert_allclose(out, system.flows[1](z, tau), rtol=0, atol=1e-14)
            cm.flow_minus(z, tau, cm.params, out)
            np.testing.assert_allclose(out, system.flows[-1](z, tau), rtol=0, atol=1e-14)
        cm.field_plus(z, cm.params, out)
        np.testing.assert_allclose(out, system.field_plus(z), rtol=1e-15, atol=1e-13)
        cm.field_minus(z, cm.params, out)
        np.testing.assert_allclose(out, system.field_minus(z), rtol=1e-15, atol=1e-13)
        assert cm.switch(z, cm.params) == pytest.approx(float(system.switch(z)), abs=1e-15)
        cm.switch_grad(z, cm.params, out)
        np.testing.assert_array_equal(out, system.switch_grad(z))


# --------------------------------------------------------------------------- integrated modes
# A model without exact flows (exact=False) has regions + and - integrated with
# the kernel's DOP853, like sliding: the compiled twin of simulate(method="integrate")
# with DOP853 throughout (stiff=False: the kernel has no implicit method to hand a
# stiff stay to; the dry-friction field at eps = 0.1 would go to Radau IIA).
def _python_integrated(system, z0s, t_max, section, **opts):
    out = []
    for z0 in z0s:
        tr = simulate(system, z0, t_max, method="integrate", sections=[section], dense=False,
                      stiff=False, **opts)
        assert tr.status == f"section:{section.name}"
        sw = tr.switches()
        slide = sum(b.t - a.t for a, b in zip(tr.events, tr.events[1:]) if a.mode_after == 0)
        out.append((tr.z.copy(), tr.t, len(sw), sw[0].t if sw else np.nan, slide))
    return out


@pytest.mark.parametrize("eps,v0", [(0.1, 3.32), (0.01, 3.1)])
def test_dry_friction_compiled_integration_agrees_with_the_python_driver(eps, v0):
    from filippov.models import dry_friction as df
    from filippov_paper.scenes.fig11_dfo_retmaps import section_L

    law = dict(gamma=2.0, f0=-2.0, fv=0.3, fc=2.5, convention="stribeck")
    x1 = np.linspace(4.15, 4.6, 10)
    w, _ = df.slow_manifold_plus(x1, 0.0, eps, v0, **law)
    z0s = np.stack([x1, np.zeros_like(x1), w], axis=1)
    cm = df.compiled(eps, v0, **law)
    assert not cm.exact
    fast = fastmap.compute_returns(cm, z0s, 200.0, samples_per_step=1, **OPTS)
    assert np.all(fast.status == fastmap.OK), [fastmap.STATUS[s] for s in fast.status]
    ref = _python_integrated(df.full_system(eps, v0, **law), z0s, 200.0, section_L(),
                             samples_per_step=1, **OPTS)
    np.testing.assert_array_equal(fast.n_switches, [r[2] for r in ref])
    assert 0 < np.sum(fast.n_switches > 0) < x1.size  # both kinds of orbit are in the test
    # Not bit for bit (numba's exp is not numpy's in the last bit, and the orbit
    # amplifies it), but at roundoff level over one orbit at rtol 1e-12 (measured:
    # P to 8e-14; the fast w, with its 1/eps stiffness, to 2e-11 for eps = 0.01).
    state = np.array([r[0] for r in ref])
    np.testing.assert_allclose(fast.state[:, :2], state[:, :2], rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast.state[:, 2], state[:, 2], rtol=0, atol=1e-10)
    tol = {"rtol": 0, "atol": 1e-11}
    np.testing.assert_allclose(fast.time, [r[1] for r in ref], **tol)
    np.testing.assert_allclose(fast.first_switch, [r[3] for r in ref], **tol)
    np.testing.assert_allclose(fast.sliding_time, [r[4] for r in ref], **tol)
    assert np.any(fast.sliding_time > 0)  # sticking is part of it


def test_compiled_dry_friction_pieces_are_the_model_formulas():
    from filippov.models import dry_friction as df

    for convention in ("stribeck", "literal"):
        system = df.full_system(0.05, 3.2, 2.0, -2.0, 0.3, 2.5, convention)
        cm = df.compiled(0.05, 3.2, 2.0, -2.0, 0.3, 2.5, convention)
        out = np.empty(3)
        for z in np.random.default_rng(2).uniform(-3, 6, size=(20, 3)):
            cm.field_plus(z, cm.params, out)
            np.testing.assert_allclose(out, system.field_plus(z), rtol=1e-14, atol=1e-13)
            cm.field_minus(z, cm.params, out)
            np.testing.assert_allclose(out, system.field_minus(z), rtol=1e-14, atol=1e-13)
            assert cm.switch(z, cm.params) == float(system.switch(z))
            cm.switch_grad(z, cm.params, out)
            np.testing.assert_array_equal(out, system.switch_grad(z))


@pytest.mark.parametrize("theta", [-0.5, 0.5])
def test_hopf_with_integrated_regions_agrees_with_the_python_driver(theta):
    """The Hopf model with its flows switched off: the kernel integrates all modes."""
    import dataclasses

    from filippov_paper.scenes.fig04_retmaps import section_L1

    x2 = np.array([0.97, 0.999, 1.001, 1.01, 1.03])
    cm = dataclasses.replace(hopf.compiled(EPS, theta, MU, OMEGA), exact=False)
    fast = fastmap.compute_returns(cm, starts(x2), T_MAX, **OPTS)
    assert np.all(fast.status == fastmap.OK)
    ref = _python_integrated(hopf.model(EPS, theta, MU, OMEGA).full(exact=False), starts(x2),
                             T_MAX, section_L1(), **OPTS)
    np.testing.assert_array_equal(fast.n_switches, [r[2] for r in ref])
    np.testing.assert_allclose(fast.state, [r[0] for r in ref], rtol=0, atol=1e-12)
    # and both agree with the exact flows to the integration tolerance
    exact = fastmap.compute_returns(hopf.compiled(EPS, theta, MU, OMEGA), starts(x2), T_MAX,
                                    **OPTS)
    np.testing.assert_allclose(fast.state, exact.state, rtol=0, atol=1e-9)


def test_integrated_mode_with_a_non_finite_field_is_a_status():
    from filippov.models import dry_friction as df

    cm = df.compiled(0.1, 3.32)
    # (1 + gamma) x2 overflows: the field is not finite at the start of the mode
    out = fastmap.compute_returns(cm, [[4.3, 1e308, 0.0]], 1.0)
    assert out.status[0] == fastmap.NON_FINITE and out.time[0] == 0.0


# --------------------------------------------------------------------------- guards
# A second model: the kernel is model-agnostic. The pseudo-equilibrium example
# x' = -sign(h), eps y' = x - y chatters for theta < 0; its default section
# x = 10 is never reached.
pseudo_compiled = pseudo_equilibrium.compiled


def test_endless_switching_stops_at_the_event_bound_where_the_reference_does():
    eps, theta, z0 = 1e-3, -0.5, [0.01, 0.0]
    cm = pseudo_compiled(eps, theta)
    out = fastmap.compute_returns(cm, [z0], 10.0, max_events=100)
    assert out.status[0] == fastmap.EVENT_LIMIT and out.n_switches[0] == 101
    # the reference's 101st switch, from an unbounded run of the same length
    system = pseudo_equilibrium.model(eps, theta).full()
    ref = simulate(system, z0, out.time[0] * (1 + 1e-9), dense=False, max_events=10_000)
    sw = ref.switches()
    assert len(sw) >= 101
    assert out.time[0] == pytest.approx(sw[100].t, rel=1e-12)
    np.testing.assert_allclose(out.state[0], sw[100].state, rtol=0, atol=1e-12)
    with pytest.raises(EventLimitError, match="event limit"):
        fastmap.first_returns_compiled(cm, [z0], 10.0, max_events=100)


def test_chatter_below_time_resolution_is_zeno():
    cm = pseudo_compiled(1e-13, -0.5)
    out = fastmap.compute_returns(cm, [[1e-12, 0.0]], 1.0)
    assert out.status[0] == fastmap.ZENO
    with pytest.raises(ZenoError):
        fastmap.first_returns_compiled(cm, [[1e-12, 0.0]], 1.0)


def test_no_return_step_limit_and_undeclared_sliding_are_status_codes():
    cm = hopf.compiled(EPS, 0.5, MU, OMEGA)
    s = starts(np.array([1.01]))
    assert fastmap.compute_returns(cm, s, 0.1).status[0] == fastmap.NO_RETURN
    with pytest.raises(RuntimeError, match="did not return"):
        fastmap.first_returns_compiled(cm, s, 0.1)
    assert fastmap.compute_returns(cm, s, T_MAX, max_steps=3).status[0] == fastmap.STEP_LIMIT
    no_slide = hopf.compiled(EPS, 0.5, MU, OMEGA, sliding=False)
    assert fastmap.compute_returns(no_slide, s, T_MAX).status[0] == fastmap.NO_SLIDING
    with pytest.raises(SimulationError, match="sliding"):
        fastmap.first_returns_compiled(no_slide, s, T_MAX)
    # the reference refuses the same orbit for the same reason
    with pytest.raises(SimulationError, match="sliding"):
        return_map(hopf.model(EPS, 0.5, MU, OMEGA), np.array([1.01]), "exact", OPTS,
                   sliding=False)


def test_bad_input_is_rejected():
    cm = hopf.compiled(EPS, 0.5, MU, OMEGA)
    with pytest.raises(ValueError, match="finite"):
        fastmap.compute_returns(cm, [[0.0, np.nan, 0.0]], T_MAX)
    with pytest.raises(ValueError, match="shape"):
        fastmap.compute_returns(cm, [[0.0, 1.0]], T_MAX)


def test_the_vendored_dop853_tableau_is_scipys_bit_for_bit():
    # the compiled kernel's DOP853 uses filippov.dop853_tableau (numbers transcribed,
    # source cited); scipy's solve_ivp(method="DOP853") is the reference driver's
    from scipy.integrate._ivp import dop853_coefficients as scipy_table

    from filippov import dop853_tableau as ours

    for name in ("A", "B", "C", "D", "E3", "E5"):
        want = np.asarray(getattr(scipy_table, name), dtype=float)
        got = getattr(ours, name)
        assert got.shape == want.shape and np.array_equal(got, want), name
    for name in ("N_STAGES", "N_STAGES_EXTENDED", "INTERPOLATOR_POWER"):
        assert getattr(ours, name) == getattr(scipy_table, name), name


LEVEL = 0.0   # read by _level_section at its compile (numba freezes globals then)


def _level_section(z, p):
    return z[0] - LEVEL


def test_a_recompiled_piece_is_called_anew():
    # compute_returns hands the kernel memoized addresses (fastmap._address); the memo is
    # checked against the piece's compiled code at every call, so a piece recompiled
    # (here: after the global it reads changed) is not run from its old code
    global LEVEL
    from numba import njit

    from filippov.abi import SCALAR_SIG
    piece = njit(SCALAR_SIG)(_level_section)
    cm = dataclasses.replace(hopf.compiled(1e-2, -0.5), section=piece)
    start = [[0.5, 1.0, 0.0]]
    try:
        first = fastmap.compute_returns(cm, start, 1.0)
        LEVEL = 0.25
        piece.recompile()
        second = fastmap.compute_returns(cm, start, 1.0)
    finally:
        LEVEL = 0.0
    assert np.all(first.status == fastmap.OK) and np.all(second.status == fastmap.OK)
    assert first.state[0, 0] == pytest.approx(0.0, abs=1e-12)
    assert second.state[0, 0] == pytest.approx(0.25, abs=1e-12)
