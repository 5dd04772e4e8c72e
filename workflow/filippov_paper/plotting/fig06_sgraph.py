"""fig:p:xi12: the graph s(theta, omega, xi1, 0) xi1 against xi1 (eq:xi1r),
traced by the sliding time t_s (dots mark a few values of t_s).

(a) the whole computed range: for t_s -> infinity the graph levels off at
omega^2 (1 - theta) (dotted), i.e. slope s -> 0 as in the reduced model;
(b) the start near xi1 = 0 (the box in (a)), with the slope
(theta - 1)/theta at xi1 = 0 (t_s -> 0) dashed.
"""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.patches import Rectangle

from filippov_paper.plotting import style as st

VARS = ["xi1", "image", "s", "slope_at_zero", "image_limit"]
XI1, IMAGE = r"$\xi_1$", r"$s\,\xi_1$"
MARK_FULL = (1.0, 2.0, 3.0, 4.0)
MARK_ZOOM = (0.2, 0.3, 0.4, 0.5)
ZOOM_T = 0.55  # panel (b) shows the graph up to about this sliding time


def _axes_lines(ax) -> None:
    ax.axhline(0.0, color=st.C_AUX, lw=st.LW_THIN, zorder=1)
    ax.axvline(0.0, color=st.C_AUX, lw=st.LW_THIN, zorder=1)


def _marks(ax, ts, xi, img, values, offset, ha, va) -> None:
    for t in values:
        if ts.min() <= t <= ts.max():
            k = int(np.argmin(np.abs(ts - t)))
            ax.plot([xi[k]], [img[k]], "o", ms=2.6, color=st.C_PLUS, zorder=5)
            ax.annotate(rf"$t_s={t:g}$", (xi[k], img[k]), xytext=offset,
                        textcoords="offset points", ha=ha, va=va, fontsize=st.FONT_MIN)


def draw(ds):
    st.require(ds, "fig06_sgraph", VARS)
    xi, img, ts = ds.xi1.values, ds.image.values, ds.t_s.values
    slope, level = float(ds.slope_at_zero), float(ds.image_limit)
    fig = st.new_figure(0.8 * st.TEXT_WIDTH, 2.1)  # printed at 0.8\textwidth
    ax, zx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.25, 1.0]})

    # (a) the whole graph
    ax.plot(xi, img, color=st.C_PLUS, lw=st.LW, zorder=3)
    _axes_lines(ax)
    ax.axhline(level, ls=":", color="k", lw=st.LW_THIN, zorder=2)
    ax.text(0.5 * xi.min(), level, r"$\omega^2(1-\theta)$", ha="center", va="bottom")
    _marks(ax, ts, xi, img, MARK_FULL, (-2, -3), "right", "top")
    ax.set_xlim(xi.min(), -0.03 * xi.min())
    ax.set_ylim(-0.05 * level, 1.2 * level)
    ax.set_xlabel(XI1)
    ax.set_ylabel(IMAGE)
    st.panel_label(ax, "(a)")

    # (b) near the grazing point, equal scales
    near = ts <= ZOOM_T
    xmin = 1.2 * xi[near].min()  # room for the leftmost t_s label
    ymax = 1.3 * img[near].max()
    zx.plot(xi[near], img[near], color=st.C_PLUS, lw=st.LW, zorder=3)
    _axes_lines(zx)
    x = np.array([min(xmin, ymax / slope if slope < 0 else xmin), 0.0])
    zx.plot(x, slope * x, ls=(0, (4, 2)), color="k", lw=st.LW_THIN, zorder=4)
    # named along itself, on its empty side (a legend box would cover the curve or the line)
    xm = 0.5 * max(x[0], ymax / slope if slope < 0 else x[0])  # mid-way along the visible part
    zx.text(xm - 0.03 * xmin, slope * xm, rf"slope $(\theta-1)/\theta={slope:g}$",
            rotation=np.degrees(np.arctan(slope)), transform_rotates_text=True,
            rotation_mode="anchor", ha="center", va="bottom")
    _marks(zx, ts, xi, img, MARK_ZOOM, (-2, -3), "right", "top")
    zx.set_xlim(xmin, -0.05 * xmin)
    zx.set_ylim(-0.05 * ymax, ymax)
    zx.set_xlabel(XI1)
    zx.set_ylabel(IMAGE)
    st.panel_label(zx, r"(b) near $\xi_1=0$")
    box = zx.get_xlim(), zx.get_ylim()
    ax.add_patch(Rectangle((box[0][0], box[1][0]), box[0][1] - box[0][0], box[1][1] - box[1][0],
                           fill=False, ec="k", lw=st.LW_THIN, zorder=6))
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 200, theta: float = 0.5, omega: float = 8 * np.pi) -> xr.Dataset:
    """eq:xi1r evaluated naively (no care for cancellation: t_s >= 1e-3 only)."""
    t = np.geomspace(1e-3, 5.0, n)
    e = np.exp(-t / theta)
    d = theta + (1 - theta) * e
    xi1 = -0.5 * omega ** 2 * theta ** 2 * (((1 - theta) * (1 - e) + t) / d) ** 2
    img = omega ** 2 * (1 - theta) * (theta - (theta + t) * e) / d
    return xr.Dataset(
        {"xi1": ("t_s", xi1), "image": ("t_s", img), "s": ("t_s", img / xi1),
         "slope_at_zero": (theta - 1) / theta, "image_limit": omega ** 2 * (1 - theta)},
        coords={"t_s": t}, attrs={"theta": theta, "omega": omega})
