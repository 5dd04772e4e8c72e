"""No figure's tick step hangs on a last bit of libm (plotting/ticks.py).

The other machine is emulated where `make cross-cpu` found fig07's flip: the power of
ten of matplotlib's tick scale (libm's log10 and pow) one ulp off, either way."""
import math
from pathlib import Path

import matplotlib as mpl
import numpy as np
import pytest
import xarray as xr
from matplotlib import ticker

import filippov_paper.plotting as plotting
from filippov_paper.plotting import style, ticks

MATPLOTLIB_SCALE = ticker.scale_range


@pytest.fixture(params=[-1, 1], ids=["ulp_down", "ulp_up"])
def direction(request):
    return np.inf * request.param


def _autolocator(nbins):
    loc = ticker.AutoLocator()
    loc.set_params(nbins=nbins)
    return loc


def _step(loc, vmin, vmax):
    return float(np.diff(loc.tick_values(vmin, vmax))[0])


#: ranges of built figures on an edge: (vmin, vmax, nbins) -> the step drawn here
EDGES = {(-2.5, 1.5, 8): 0.5,     # fig07 (a), xi1: 4 / 8 = 0.5 exactly
         (-5.0, 1.25, 2): 5.0}    # fig09 (b): a tick on the limit, two needed


@pytest.mark.parametrize("edge", sorted(EDGES))
def test_one_ulp_of_matplotlibs_scale_flips_a_step_on_an_edge(monkeypatch, edge):
    vmin, vmax, nbins = edge
    steps = {_step(_autolocator(nbins), vmin, vmax)}
    for d in (-np.inf, np.inf):
        monkeypatch.setattr(ticker, "scale_range", lambda *a, d=d, **k: (
            float(np.nextafter(MATPLOTLIB_SCALE(*a, **k)[0], d)), MATPLOTLIB_SCALE(*a, **k)[1]))
        steps.add(round(_step(_autolocator(nbins), vmin, vmax), 9))
    assert EDGES[edge] in steps and len(steps) == 2


@pytest.mark.parametrize("x", [1e-300, 3e-7, 0.1, 0.5, 0.09999999999999999, 1.0, 9.999999999999998,
                               10.0, 10.000000000000002, 123.0, 1e22, 1e300])
def test_power_of_ten_is_exact_whichever_way_log10_rounds(monkeypatch, direction, x):
    want = float(f"1e{math.floor(math.log10(x))}") if x not in (0.09999999999999999,
                                                               9.999999999999998) else \
        {0.09999999999999999: 0.01, 9.999999999999998: 1.0}[x]
    plain = math.log10
    monkeypatch.setattr(math, "log10", lambda v: float(np.nextafter(plain(v), direction)))
    assert ticks.power_of_ten(x) == want
    assert want <= x < want * 10


def test_the_exact_scale_is_matplotlibs_where_libm_is_right():
    # every figure drawn here is matplotlib's to the bit (glibc rounds these powers right)
    rng = np.random.default_rng(1)
    ranges = [(-2.5, 1.5), (0.0, 10.0), (-5.0, 1.25), (-1.0, 5.0), (0.0, 4.0), (-2.0, 1.0),
              (0.96, 1.04), (1e5, 1e5 + 3.0)] + \
        [tuple(sorted(rng.normal(0, 10.0 ** rng.integers(-8, 8), 2))) for _ in range(2000)]
    for vmin, vmax in ranges:
        for n in (1, 3, 4, 5, 7, 8, 9):
            assert ticks.scale_range(vmin, vmax, n) == MATPLOTLIB_SCALE(vmin, vmax, n), \
                (vmin, vmax, n)


def test_the_figures_context_keeps_the_step_on_an_edge_on_every_machine(monkeypatch, direction):
    plain = math.log10
    monkeypatch.setattr(math, "log10", lambda v: float(np.nextafter(plain(v), direction)))
    with style.context():
        assert ticker.scale_range is ticks.scale_range
        for (vmin, vmax, nbins), step in EDGES.items():
            assert _step(_autolocator(nbins), vmin, vmax) == step
    assert ticker.scale_range is MATPLOTLIB_SCALE   # restored outside


@pytest.mark.parametrize("scene_id", sorted(plotting.figure_ids()))
def test_a_built_figures_ticks_are_matplotlibs_here(workflow_build, tmp_path, scene_id):
    """Drawn with the exact scale, each linear axis of the built figure has the ticks
    matplotlib's own scale gives it on this machine: the exact scale changes no image
    here, it only keeps the same ticks where libm rounds otherwise."""
    nc = Path(workflow_build["work"]) / "results" / f"{scene_id}.nc"
    fig = plotting.draw(scene_id, xr.load_dataset(nc))
    plotting.save(fig, tmp_path / "f.pdf", tmp_path / "f.png")   # the printed layout
    axes = [(i, name, axis) for i, ax in enumerate(fig.axes)
            for name, axis in (("x", ax.xaxis), ("y", ax.yaxis)) if axis.get_scale() == "linear"]
    assert fig.axes   # (work_precision's axes are all logarithmic: LogLocator, not this)
    for i, name, axis in axes:
        loc, (lo, hi) = axis.get_major_locator(), axis.get_view_interval()
        with mpl.rc_context(style.RC):   # the tick space depends on the fonts
            plain = loc.tick_values(lo, hi)
            with ticks.exact_scale():
                exact = loc.tick_values(lo, hi)
        np.testing.assert_array_equal(exact, plain, err_msg=f"{scene_id} axes {i} {name}")
