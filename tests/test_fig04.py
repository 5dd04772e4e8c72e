"""The return map of the slow-fast Hopf example (fig:retmaps): the paper's stated
facts, each against an independent computation or a limit derived here."""
import numpy as np
import pytest

from filippov.analytic.s0 import s0_lambert
from filippov.models import hopf
from filippov.poincare import fixed_points
from filippov_paper.scenes.fig04_retmaps import return_map, sigma_minus, x2_grid

OMEGA, MU = 8 * np.pi, 1.0
OPTS = {"rtol": 1e-12, "atol": 1e-14}
SMOOTH_SLOPE = np.exp(-4 * np.pi * MU / OMEGA)


def P(eps, theta, x2, method="exact"):
    return return_map(hopf.model(eps, theta, MU, OMEGA), np.asarray(x2, float), method, OPTS)


@pytest.mark.parametrize("theta", [-0.5, 0.5])
def test_below_grazing_P_is_the_smooth_polar_map(theta):
    # one revolution of r' = mu r - r^3 in closed form: independent of the solver
    x2 = np.linspace(0.9, 1.0, 41)
    T = 2 * np.pi / OMEGA
    r = np.sqrt(MU * x2**2 / (x2**2 + (MU - x2**2) * np.exp(-2 * MU * T)))
    got, res, ret = P(0.01, theta, x2)
    np.testing.assert_allclose(got, r, rtol=0, atol=2e-15)
    assert np.all(ret.n_switches == 0) and np.all(res == 0)
    d = np.array([1e-7, 1e-6])
    slope = (1 - P(0.01, theta, 1 - d)[0]) / d
    np.testing.assert_allclose(slope, SMOOTH_SLOPE, rtol=2e-6)


def test_theta_negative_jump_scales_with_eps():
    # derived: the jump is eps s0(theta) at the grazing point, carried to L1 by
    # 3/4 of a revolution, which contracts radii by exp(-3 pi mu / omega)
    predicted = s0_lambert(np.array([-0.5]))[0] * np.exp(-3 * np.pi * MU / OMEGA)
    c = np.array([(1 - P(eps, -0.5, [1 + 1e-12])[0][0]) / eps for eps in (1e-2, 1e-3, 1e-4)])
    err = np.abs(c - predicted)
    assert err[0] > err[1] > err[2] and err[2] < 1e-3 * predicted
    assert np.all(c > 0.5)  # a jump of order eps, not smaller


def test_theta_negative_one_sided_slope_is_unbounded():
    d = np.array([1e-12, 1e-10, 1e-8, 1e-6])
    got = P(0.01, -0.5, 1 + d)[0]
    slopes = np.abs(np.diff(got) / np.diff(d))
    assert np.all(np.diff(slopes) < 0)  # steeper closer to x2 = 1
    # square-root singularity: 100x closer, 10x steeper
    np.testing.assert_allclose(slopes[:-1] / slopes[1:], 10.0, rtol=0.05)


@pytest.mark.parametrize("eps", [1e-2, 1e-3, 1e-4])
def test_theta_positive_is_continuous_with_order_one_slope(eps):
    theta = 0.5
    carried = (theta - 1) / theta * SMOOTH_SLOPE  # slope (theta-1)/theta carried to L1
    # the sliding layer has width O(eps^2) in x2: probe well inside it, but with
    # P - 1 large enough (>= 1e-12) that rounding in P leaves 1e-4 of the slope
    d = np.array([1e-4, 1e-3]) * max(eps**2, 1e-7)
    got, _, ret = P(eps, theta, np.concatenate([[1.0, 1 + 1e-12], 1 + d]))
    assert got[0] == 1.0 and abs(got[1] - 1) < 1e-11  # continuous
    assert np.all(ret.sliding_time[1:] > 0)
    slope = (got[2:] - 1) / d
    assert np.all(slope < -0.5)  # negative, order one, for every eps
    np.testing.assert_allclose(slope, carried, rtol=2e-2)


def test_exact_flows_and_integration_agree_on_the_grid():
    p = dict(x2_min=0.96, x2_max=1.04, n_uniform=21, n_geometric=12, closest=1e-12)
    x2 = x2_grid(p)
    for theta in (-0.5, 0.5):
        exact, res, _ = P(0.01, theta, x2)
        integ, res_i, _ = P(0.01, theta, x2, method="integrate")
        # Exactly at grazing the exact flow touches H_s; DOP853's orbit (H error
        # ~1e-14) may dip across instead. Everywhere else: 1e-10, except where the
        # map itself is ill-conditioned (theta < 0, slope ~ (x2-1)^-1/2 next to the
        # jump): there the backward error, difference / slope, is below 1e-12.
        keep = x2 != 1.0
        slope = np.ones_like(x2)
        for side in (x2 < 1, x2 > 1):
            slope[side] = np.abs(np.gradient(exact[side], x2[side]))
        diff = np.abs(exact - integ)[keep]
        assert np.all(diff < 1e-10 + 1e-12 * slope[keep])
        away = keep & (np.abs(x2 - 1) > 1e-6)
        assert np.all(np.abs(exact - integ)[away] < 1e-10)
        assert np.max(np.abs(res - res_i)[away]) < 1e-12


def test_residual_at_return_is_about_1e_minus_10():
    _, res, ret = P(0.01, -0.5, np.linspace(1.001, 1.04, 9))
    assert np.all(ret.n_switches == 2)
    assert np.all((1e-11 < res) & (res < 1e-9))


@pytest.mark.parametrize("theta,case", [(-0.5, 2), (0.5, 1), (-0.1, 2), (0.9, 1)])
def test_lemma_case_from_sigma_minus(theta, case):
    model = hopf.model(0.01, theta, MU, OMEGA)
    sigma, chi = sigma_minus(model)
    assert sigma == pytest.approx(chi, abs=1e-12)  # eq:eminus reduces to eq:chiminus at p_g
    assert (1 if sigma > 0 else 2) == case
    jump = abs(1 - return_map(model, np.array([1 + 1e-12]), "exact", OPTS)[0][0])
    assert (jump < 1e-10) if case == 1 else (jump > 1e-3)


def test_fixed_points_of_the_map():
    x2 = np.array([0.98, 0.99, 1.0, 1.01, 1.02])
    for theta in (-0.5, 0.5):
        got = P(0.01, theta, x2)[0]
        np.testing.assert_array_equal(fixed_points(x2, got), [1.0])


def test_engine_is_checked_per_scene():
    import filippov_paper.scenes
    from filippov_paper.scenes.common import engine
    scene = {"id": "fig04_retmaps", "ingredients": {"flow": "integrate"},
             "solver": {"engine": "compiled"}}
    assert engine(scene) == "compiled"   # fig04 runs both flows on both engines
    assert filippov_paper.scenes._module(scene).ENGINES == ("reference", "compiled")
    assert engine({"id": "x", "ingredients": {"flow": "exact"}}) == "reference"
    # a scene without a compiled engine says so, naming the field
    other = {"id": "fig08_s0theta", "ingredients": {"flow": "exact"},
             "solver": {"engine": "compiled"}}
    with pytest.raises(ValueError, match="solver.engine: 'compiled' not available"):
        filippov_paper.scenes.compute(other)


def test_compiled_engine_integrates_when_asked():
    """flow: integrate on the compiled engine: DOP853 inside the kernel, the same
    map as the reference driver's integration and, to the tolerance, as the exact flows."""
    from filippov_paper.scenes.fig04_retmaps import return_map
    x2 = np.array([0.97, 0.999, 1.001, 1.03])
    model = hopf.model(0.01, 0.5, 1.0, OMEGA)
    opts = {"rtol": 1e-12, "atol": 1e-14}
    fast, _, _ = return_map(model, x2, "integrate", opts, engine="compiled")
    ref, _, _ = return_map(model, x2, "integrate", opts)
    exact, _, _ = return_map(model, x2, "exact", opts, engine="compiled")
    np.testing.assert_allclose(fast, ref, rtol=0, atol=1e-12)
    np.testing.assert_allclose(fast, exact, rtol=0, atol=1e-9)


def test_scene_engines_agree():
    """The scene's compiled engine and the reference driver give the same map, to the
    map's own conditioning: the engines scan the exact flows at different sample
    spacings, so their roots of h agree to rounding, not bit for bit, and near grazing
    (theta < 0: P ~ sqrt(x2 - 1)) a rounding u of a crossing moves P by u |dP/dx2|
    (dP/dx2 from the compiled engine's derivative; 64 roundings; none at the touch)."""
    from filippov.fastmap import compute_returns
    from filippov_paper.scenes.fig04_retmaps import return_map
    x2 = np.array([0.97, 0.999, 1.0, 1.0 + 1e-9, 1.001, 1.03])
    starts = np.stack([np.zeros_like(x2), x2, np.zeros_like(x2)], axis=1)
    for theta in (-0.5, 0.5):
        model = hopf.model(0.01, theta, 1.0, OMEGA)
        opts = {"rtol": 1e-12, "atol": 1e-14}
        ref, _, rr = return_map(model, x2, "exact", opts)
        fast, _, rf = return_map(model, x2, "exact", opts, engine="compiled")
        cm = hopf.compiled(0.01, theta, 1.0, OMEGA, sliding=theta > 0)
        slope = compute_returns(cm, starts, 1.0, jacobian=True, **opts).jacobian[:, 1, 1]
        tol = 1e-14 + 64 * np.finfo(float).eps * np.nan_to_num(np.abs(slope))
        assert np.all(np.abs(fast - ref) <= tol), (fast - ref, tol)
        # the first switching time: none below grazing, the same instant above it, to its
        # conditioning in the same sense: a rounding u of h is a change u of the depth
        # of h's minimum, i.e. of x2 - 1, which moves the crossing by u |dt/dx2|
        # (central differences on the scale of x2 - 1)
        assert np.all(np.isnan(rr.first_switch[:2])) and np.all(np.isnan(rf.first_switch[:2]))
        assert np.all(rr.first_switch[3:] > 0)
        d = 1e-3 * (x2[3:] - 1.0)
        up, down = starts[3:].copy(), starts[3:].copy()
        up[:, 1] += d
        down[:, 1] -= d
        t_up = compute_returns(cm, up, 1.0, **opts).first_switch
        t_down = compute_returns(cm, down, 1.0, **opts).first_switch
        dt_dx2 = (t_up - t_down) / (up[:, 1] - down[:, 1])
        tol_t = 1e-14 + 64 * np.finfo(float).eps * np.abs(dt_dx2)
        assert np.all(np.abs(rf.first_switch[3:] - rr.first_switch[3:]) <= tol_t)
