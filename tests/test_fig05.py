"""fig:thetalt0mfs: facts the computed dataset must bear out.

* theta < 0: the trajectory from L1 just outside the grazing orbit crosses
  E+ -> E- -> E+ (no sliding, whether or not sliding is enabled);
* after the return, y - x1 decays like exp(-t/eps);
* M_- integrated from E_- trajectories equals the exact cubic, and differs from
  the O(eps) expansion eq:ymm by O(eps^2);
* M_+ - M_- at x = (-1, 0) is eps + O(eps^2) (text after eq:ymm).
"""
import copy
from pathlib import Path

import numpy as np
import pytest

import filippov_paper.plotting as plotting
import synthetic
from filippov import simulate
from filippov_paper.config import load_scene
from filippov.models import hopf
from filippov_paper.scenes import compute
from filippov_paper.scenes import fig05_thetalt0mfs as fig05
from filippov.system import MINUS, PLUS

ROOT = Path(__file__).resolve().parents[1]
SCENE = load_scene(ROOT / "config" / "scenes" / "fig05_thetalt0mfs.yaml",
                   ROOT / "config" / "schema" / "scene.schema.json")


@pytest.fixture(scope="module")
def ds():
    return compute(SCENE)


def _scene(**params):
    scene = copy.deepcopy(SCENE)
    scene["parameters"].update(params)
    return scene


def test_scene_parameters_are_the_papers_case():
    p = SCENE["parameters"]
    assert p["theta"] < 0 and p["mu"] == 1.0 and p["eps"] > 0
    assert p["omega"] == pytest.approx(8 * np.pi, rel=1e-15)
    assert SCENE["ingredients"] == {"system": "slow_fast", "flow": "exact", "sliding": False}


def test_switches_plus_minus_plus(ds):
    assert list(ds.switch_from.values) == [PLUS, MINUS]
    assert list(ds.switch_to.values) == [MINUS, PLUS]
    # both switches lie on H_s, the first on H_s n M_+ = {x1 = y = -1}
    theta = float(ds.attrs["theta"])
    h = theta * ds.switch_x1.values + (1 - theta) * ds.switch_y.values + 1.0
    np.testing.assert_allclose(h, 0.0, atol=1e-12)
    assert ds.switch_x1.values[0] == pytest.approx(-1.0, abs=1e-12)
    assert ds.switch_y.values[0] == pytest.approx(-1.0, abs=1e-12)
    # region - moves along x1 only: x2 is the same at both switches
    assert ds.switch_x2.values[1] == ds.switch_x2.values[0]
    # the sampled modes are + then - then +, nothing else
    mode = ds["mode"].values
    runs = mode[np.r_[0, np.flatnonzero(np.diff(mode)) + 1]]
    assert list(runs) == [PLUS, MINUS, PLUS]


def test_no_sliding_even_when_allowed():
    """theta < 0 is case 2: crossings only, also with the sliding ingredient on."""
    p = SCENE["parameters"]
    model = hopf.model(p["eps"], p["theta"], p["mu"], p["omega"])
    for sliding in (False, True):
        traj = simulate(model.full(sliding=sliding), [0.0, p["start_x2"], 0.0], 0.5,
                        sections=[fig05.section_L1()])
        kinds = [e.kind for e in traj.events if e.kind not in ("start", "section", "touch")]
        assert kinds == ["crossing", "crossing"], (sliding, kinds)


def test_relaxation_rate_is_one_over_eps(ds):
    eps = float(ds.attrs["eps"])
    assert abs(float(ds.decay_rate) * eps - 1.0) < 1e-6
    assert float(ds.decay_rate_rel_error) == pytest.approx(float(ds.decay_rate) * eps - 1.0)
    # after the return the trajectory is below M_+ by O(eps) and approaches it
    t_back = float(ds.switch_t[1])
    after = (ds.t.values > t_back) & (ds.t.values < t_back + 10 * eps)
    dev = ds.y.values[after] - ds.x1.values[after]
    assert np.all(dev < 0) and np.all(np.diff(np.abs(dev)) < 0)
    assert 0.5 * eps < abs(float(ds.switch_y[1] - ds.switch_x1[1])) < 10 * eps


def test_grazing_orbit_touches_only(ds):
    assert float(ds.orbit_min_x1) == pytest.approx(-1.0, abs=1e-12)
    assert float(ds.orbit_touch_t) == pytest.approx(0.25 * 2 * np.pi / float(ds.attrs["omega"]))
    np.testing.assert_allclose(ds.orbit_y.values, ds.orbit_x1.values, atol=1e-14)  # in M_+
    r = np.hypot(ds.orbit_x1.values, ds.orbit_x2.values)
    np.testing.assert_allclose(r, 1.0, atol=1e-12)


def test_numerical_M_minus_is_the_exact_cubic(ds):
    assert float(ds.M_minus_max_error) < 1e-10
    np.testing.assert_allclose(ds.y_M_minus.values, ds.y_M_minus_exact.values, atol=1e-10,
                               rtol=0)
    assert np.max(np.abs(ds.M_minus_invariance_residual.values)) < 1e-13
    # the E_- trajectories converge onto it like exp(-t/eps) (until round-off)
    dev, eps = ds.convergence.values, float(ds.attrs["eps"])
    t = ds.t_settle.values
    k = dev > 1e-11
    slope = np.polyfit(t[k], np.log(dev[k]), 1)[0]
    assert -slope * eps == pytest.approx(1.0, rel=1e-3)


def _expansion_gap(eps):
    p = SCENE["parameters"]
    model = hopf.model(eps, p["theta"], p["mu"], p["omega"])
    g1 = np.linspace(*p["x1_range"], 9)
    g2 = np.linspace(*p["x2_range"], 9)
    X1, X2 = np.meshgrid(g1, g2, indexing="ij")
    y, _, _ = fig05.numeric_slow_manifold_minus(model, X1, X2, p["settle"])
    return np.max(np.abs(y - hopf.slow_manifold_minus_first_order(X1, X2, eps, p["mu"], p["omega"])))


def test_expansion_error_is_order_eps_squared(ds):
    eps = float(ds.attrs["eps"])
    assert float(ds.M_minus_max_expansion_error) == pytest.approx(_expansion_gap(eps), rel=1e-8)
    ratio = _expansion_gap(eps) / _expansion_gap(eps / 2)
    assert ratio == pytest.approx(4.0, rel=0.05)
    # while M_- itself is O(eps) away from M_+
    assert np.max(np.abs(ds.y_M_minus.values - ds.y_M_plus.values)) > 10 * float(
        ds.M_minus_max_expansion_error)


def test_gap_at_grazing_point_is_eps(ds):
    eps = float(ds.attrs["eps"])
    gap = float(ds.gap_pg)
    assert gap == pytest.approx(float(ds.gap_pg_exact), abs=1e-12)
    # eps + O(eps^2): the remainder over eps^2 stays bounded (tends to -2)
    for e in (eps, eps / 2, eps / 4):
        p = SCENE["parameters"]
        model = hopf.model(e, p["theta"], p["mu"], p["omega"])
        y, _, _ = fig05.numeric_slow_manifold_minus(model, np.array([-1.0]), np.array([0.0]))
        g = -1.0 - y[0]
        assert (g - e) / e ** 2 == pytest.approx(-2.0, abs=10 * e)


def test_dataset_contract(ds):
    for name in ("x1", "x2", "y", "mode", "y_M_plus", "y_M_minus", "y_M_minus_exact",
                 "y_M_minus_expansion", "M_minus_error", "M_minus_expansion_error", "y_H_s",
                 "switch_x1", "switch_x2", "switch_y", "decay_rate", "gap_pg"):
        assert name in ds.variables
        if name != "mode":
            assert "long_name" in ds[name].attrs and ds[name].attrs.get("units") == "1", name
    for key in ("eps", "theta", "mu", "omega", "scene_id", "code_version"):
        assert key in ds.attrs


def test_positive_theta_is_rejected():
    with pytest.raises(ValueError, match="theta"):
        compute(_scene(theta=0.5))


@pytest.mark.parametrize("make", [lambda: synthetic.dataset("fig05_thetalt0mfs"), lambda: compute(SCENE)],
                         ids=["synthetic", "computed"])
def test_draw_and_save_is_deterministic(tmp_path, make):
    ds = make()
    out = []
    for run in ("one", "two"):
        pdf, png = tmp_path / f"{run}.pdf", tmp_path / f"{run}.png"
        plotting.save(plotting.draw("fig05_thetalt0mfs", ds), pdf, png)
        out.append((pdf.read_bytes(), png.read_bytes()))
    assert out[0] == out[1]
    assert out[0][0].startswith(b"%PDF")


def test_missing_variable_is_named():
    with pytest.raises(KeyError, match="y_M_minus"):
        plotting.draw("fig05_thetalt0mfs", synthetic.dataset("fig05_thetalt0mfs").drop_vars("y_M_minus"))
