"""fig:grazingsketch (reduced Hopf example eq:red) and fig:p:xi12 (eq:xi1r):
the paper's stated facts, checked on the computed data and against independent
computations (exact polar flow, the tangency formula, high-precision decimals)."""
from decimal import Decimal, getcontext
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import brentq

from filippov.analytic import sgraph
from filippov_paper.config import SceneError, load_scene
from filippov.models import hopf
from filippov_paper.scenes import compute
from filippov_paper.scenes.fig03_grazingsketch import x_l_tangency

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"
OMEGA, THETA = 8 * np.pi, 0.5


def scene(sid):
    return load_scene(ROOT / "config" / "scenes" / f"{sid}.yaml", SCHEMA)


@pytest.fixture(scope="module")
def grazing():
    return compute(scene("fig03_grazingsketch"))


@pytest.fixture(scope="module")
def sgraph_ds():
    return compute(scene("fig06_sgraph"))


# --------------------------------------------------------------------------- fig03
def test_fig03_parameters_bracket_grazing(grazing):
    mus = grazing.mu.values
    assert mus[0] < 1 and mus[1] == 1 and mus[2] > 1
    assert float(grazing.attrs["omega"]) == pytest.approx(OMEGA, rel=1e-15)


def test_mu_below_one_orbit_is_the_circle_and_never_touches(grazing):
    d = grazing.sel(mu=grazing.mu.values[0])
    mu = float(d.mu)
    r = np.hypot(d.x1.values, d.x2.values)
    assert np.max(np.abs(r - np.sqrt(mu))) < 1e-10
    assert d.x1.values.min() > -1 + 0.1          # 1 - sqrt(0.8) = 0.106 away from x1 = -1
    assert np.all(d["mode"].values == 1) and float(d.sliding_time) == 0
    assert np.all(np.isnan(d.x_h.values)) and np.all(np.isnan(d.x_l.values))
    assert float(d.period) == pytest.approx(2 * np.pi / OMEGA, rel=1e-12)


def test_mu_one_orbit_grazes_at_x_g(grazing):
    d = grazing.sel(mu=1.0)
    assert abs(d.x1.values.min() + 1) < 1e-10
    np.testing.assert_allclose(d.x_left.values, grazing.x_g.values, rtol=0, atol=1e-10)
    np.testing.assert_array_equal(grazing.x_g.values, [-1.0, 0.0])
    # at most a degenerate slide (floating-point radius 1 + O(ulp)), never a visible one
    assert float(d.sliding_time) < 1e-8
    # ... which is reported as the grazing contact (no x_h, x_l) on every machine
    assert np.all(np.isnan(d.x_h.values)) and np.all(np.isnan(d.x_l.values))
    np.testing.assert_allclose(d.x_l_formula.values, [-1.0, 0.0], atol=0)


def test_mu_above_one_x_l_solver_matches_tangency(grazing):
    d = grazing.sel(mu=grazing.mu.values[2])
    mu = float(d.mu)
    xl, xh = d.x_l.values, d.x_h.values
    np.testing.assert_allclose(xl, d.x_l_formula.values, rtol=0, atol=1e-10)
    # the formula is the tangency dh0/dx f_+ = 0 on x1 = -1
    b = -mu - OMEGA * xl[1] + (1 + xl[1] ** 2)
    assert abs(b) < 1e-12
    assert xl[0] == -1.0 or abs(xl[0] + 1) < 1e-14
    assert xh[1] > 0 > xl[1]                       # x_{h,2} > 0, x_{l,2} < 0 as in the paper
    assert float(d.sliding_time) > 0 and np.any(d["mode"].values == 0)


def test_mu_above_one_x_h_from_exact_flow(grazing):
    # independent of the solver: follow the closed-form polar flow from x_l until x1 = -1
    d = grazing.sel(mu=grazing.mu.values[2])
    mu = float(d.mu)
    xl = d.x_l_formula.values
    T = 2 * np.pi / OMEGA
    x1 = lambda t: hopf.polar_flow(xl[0], xl[1], np.array(t), mu, OMEGA)[0] + 1.0
    th = brentq(x1, T / 2, T, xtol=1e-16, rtol=1e-15)
    xh = np.array(hopf.polar_flow(xl[0], xl[1], np.array(th), mu, OMEGA))
    np.testing.assert_allclose(d.x_h.values, xh, rtol=0, atol=1e-10)


def test_mu_above_one_multiplier_zero(grazing):
    # sliding collapses every nearby orbit onto x_l: settled after one period
    d = grazing.sel(mu=grazing.mu.values[2])
    assert int(d.n_periods) <= 2 and float(d.settle_error) < 1e-14


def test_x_l_tangency_small_root():
    for mu in (1.0 + 1e-12, 1.05, 1.2, 2.0):
        x2 = x_l_tangency(mu, OMEGA)
        assert x2 < 0
        assert abs(x2 ** 2 - OMEGA * x2 + 1 - mu) < 1e-14 * max(1.0, mu)


def test_fig03_dataset_is_documented(grazing):
    for name, var in grazing.data_vars.items():
        assert "long_name" in var.attrs and "units" in var.attrs, name
    assert grazing.attrs["scene_id"] == "fig03_grazingsketch"


# --------------------------------------------------------------------------- fig06
def _reference(t, theta=THETA, omega=OMEGA):
    """eq:xi1r in 60-digit decimals, as printed in the paper."""
    getcontext().prec = 60
    t, T, O = Decimal(float(t)), Decimal(theta), Decimal(float(omega))
    e = (-t / T).exp()
    D = T + (1 - T) * e
    xi = -(O * O * T * T / 2) * (((1 - T) * (1 - e) + t) / D) ** 2
    img = O * O * (1 - T) * (T - (T + t) * e) / D
    return float(xi), float(img), float(img / xi)


def test_closed_forms_match_high_precision():
    t = np.r_[np.geomspace(1e-9, 20.0, 60), 0.4999, 0.5, 0.5001, 1.0]
    got = np.stack([sgraph.xi1(t, THETA, OMEGA), sgraph.image(t, THETA, OMEGA),
                    sgraph.slope(t, THETA, OMEGA)], axis=1)
    ref = np.array([_reference(v) for v in t])
    np.testing.assert_allclose(got, ref, rtol=2e-14, atol=0)


@pytest.mark.parametrize("theta", [0.1, 0.5, 0.9])
def test_s_tends_to_theta_minus_one_over_theta(theta):
    s0 = (theta - 1) / theta
    assert sgraph.slope_at_zero(theta) == s0
    assert abs(sgraph.slope(1e-10, theta, OMEGA) - s0) < 1e-8
    # first correction derived in analytic.sgraph: 2 (1 - theta) t_s / (3 theta^2)
    t = 1e-6
    c = (sgraph.slope(t, theta, OMEGA) - s0) / t
    assert c == pytest.approx(2 * (1 - theta) / (3 * theta ** 2), rel=1e-4)


def test_large_t_s_levels_off():
    t = np.array([10.0, 20.0, 40.0])
    img, xi = sgraph.image(t, THETA, OMEGA), sgraph.xi1(t, THETA, OMEGA)
    lim = sgraph.image_limit(THETA, OMEGA)
    assert lim == pytest.approx(OMEGA ** 2 * (1 - THETA))
    rel = np.abs(img / lim - 1)
    assert rel[-1] < 1e-30 + 1e-15 and np.all(np.diff(rel) < 0)
    np.testing.assert_allclose(xi / sgraph.xi1_asymptote(t, THETA, OMEGA), 1, rtol=1e-6)
    s = img / xi
    assert np.all(s < 0) and np.all(np.diff(np.abs(s)) < 0)
    np.testing.assert_allclose(s * xi, lim, rtol=1e-6)      # s ~ image_limit / xi1 -> 0


def test_sgraph_dataset(sgraph_ds):
    ds = sgraph_ds
    t = ds.t_s.values
    assert t[0] == pytest.approx(1e-8) and t[-1] == pytest.approx(5.0) and ds.sizes["t_s"] > 1900
    assert np.all(np.diff(t) > 0)
    # a graph over xi1: xi1 strictly decreasing, image increasing along t_s
    assert np.all(np.diff(ds.xi1.values) < 0) and np.all(np.diff(ds.image.values) > 0)
    np.testing.assert_allclose(ds.s.values, ds.image.values / ds.xi1.values, rtol=1e-15)
    assert abs(float(ds.s[0]) - float(ds.slope_at_zero)) < 1e-7
    assert float(ds.slope_at_zero) == -1.0
    assert float(ds.image[-1]) == pytest.approx(float(ds.image_limit), rel=1e-3)
    for name, var in ds.data_vars.items():
        assert "long_name" in var.attrs and "units" in var.attrs, name


@pytest.mark.parametrize("theta", [0.0, 1.0, -0.5, float("nan")])
def test_sgraph_rejects_theta_outside_unit_interval(theta):
    with pytest.raises(ValueError, match="theta"):
        sgraph.xi1([1.0], theta, OMEGA)


def test_sgraph_scene_schema_rejects_bad_theta(tmp_path):
    text = (ROOT / "config" / "scenes" / "fig06_sgraph.yaml").read_text()
    path = tmp_path / "fig06_sgraph.yaml"
    path.write_text(text.replace("theta: 0.5", "theta: 1.5"))
    with pytest.raises(SceneError, match="parameters.theta"):
        load_scene(path, SCHEMA)
