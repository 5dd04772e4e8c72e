"""fig:slidesketch: a trajectory through x_0 on H_s = {x2 = 0} that (a) crosses,
(b) slides. Trajectory pieces are coloured by the region whose field drives them."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st
from filippov_paper.plotting.lines import arrowhead, runs, unit_arrows

VARS = ["x1", "x2", "mode", "hit_x1", "hit_x2", "arrow_x1", "arrow_x2", "arrow_u", "arrow_v"]
COLOUR = {1: st.C_PLUS, -1: st.C_MINUS, 0: st.C_SLIDE}


def _limits(d):
    """Box around trajectory and arrows, symmetric in x2 so H_s sits mid-panel."""
    xs = np.r_[d.x1.values, d.arrow_x1.values]
    ys = np.r_[d.x2.values, d.arrow_x2.values]
    pad = 0.08 * (xs.max() - xs.min())
    ymax = 1.15 * np.abs(ys).max()
    return (xs.min() - pad, xs.max() + pad), (-ymax, ymax)


def _panel(ax, d) -> None:
    xlim, ylim = _limits(d)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    ax.axhline(0.0, color="k", lw=st.LW)
    ax.text(xlim[1], 0.0, st.H_S + "  ", ha="right", va="bottom")
    # Region tags on the right: the trajectories start bottom-left.
    ax.text(0.97, 0.95, r"$x_2>0$: " + st.F_PLUS, transform=ax.transAxes, ha="right", va="top")
    ax.text(0.97, 0.05, r"$x_2<0$: " + st.F_MINUS, transform=ax.transAxes, ha="right", va="bottom")

    # Field arrows, equal on-screen length; colour tells which field they show.
    u, v = unit_arrows(d.arrow_u.values, d.arrow_v.values,
                       np.diff(xlim)[0], np.diff(ylim)[0], length=0.07)
    above = d.arrow_x2.values >= 0
    for sel, colour in ((above, st.C_PLUS), (~above, st.C_MINUS)):
        ax.quiver(d.arrow_x1.values[sel], d.arrow_x2.values[sel], u[sel], v[sel], color=colour,
                  angles="xy", scale_units="xy", scale=1, width=0.004, headwidth=4, alpha=0.8)

    x, y = d.x1.values, d.x2.values
    for a, b, m in runs(d["mode"].values):
        lw = st.LW_BOLD if m == 0 else st.LW
        ax.plot(x[a:b], y[a:b], color=COLOUR.get(m, "k"), lw=lw, solid_capstyle="butt")
    first = runs(d["mode"].values)[0]
    arrowhead(ax, x, y, (first[0] + first[1]) // 2, COLOUR.get(first[2], "k"))
    ax.annotate(r"$x(t)$", (x[0], y[0]), xytext=(6, 0), textcoords="offset points",
                ha="left", va="center")

    hx, hy = float(d.hit_x1), float(d.hit_x2)
    ax.plot([hx], [hy], "o", color="k", ms=3.5, zorder=5)
    ax.annotate(r"$x_0$", (hx, hy), xytext=(-3, 4), textcoords="offset points",
                ha="right", va="bottom")
    ax.set_xlabel(st.X1)
    ax.set_ylabel(st.X2)


def draw(ds):
    st.require(ds, "fig01_slidesketch", VARS)
    fig = st.new_figure(st.TEXT_WIDTH, 2.1)
    axes = fig.subplots(1, 2)
    for ax, (tag, case) in zip(axes, (("a", "crossing"), ("b", "sliding"))):
        _panel(ax, ds.sel(case=case))
        st.panel_label(ax, f"({tag}) {case}")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 201) -> xr.Dataset:
    t = np.linspace(0.0, 2.5, n)
    x1 = np.stack([-1.0 + t, -1.0 + t])
    cross = np.where(t < 1.0, -1.0 + t, 0.5 * (t - 1.0))   # crosses x2 = 0 at t = 1
    slide = np.minimum(-1.0 + t, 0.0)                     # reaches x2 = 0, then slides
    x2 = np.stack([cross, slide])
    mode = np.stack([np.where(t < 1.0, -1, 1), np.where(t < 1.0, -1, 0)]).astype("int8")
    gx, gy = np.meshgrid(np.linspace(-0.8, 1.2, 4), [-0.6, 0.3])
    ax1, ax2 = gx.ravel(), gy.ravel()
    u = np.ones((2, ax1.size))
    v = np.stack([np.where(ax2 < 0, 1.0, 0.5), np.where(ax2 < 0, 1.0, -1.0)])
    return xr.Dataset(
        {"x1": (("case", "t"), x1), "x2": (("case", "t"), x2), "mode": (("case", "t"), mode),
         "hit_x1": ("case", [0.0, 0.0]), "hit_x2": ("case", [0.0, 0.0]),
         "arrow_x1": (("case", "arrow"), np.stack([ax1, ax1])),
         "arrow_x2": (("case", "arrow"), np.stack([ax2, ax2])),
         "arrow_u": (("case", "arrow"), u), "arrow_v": (("case", "arrow"), v)},
        coords={"case": ["crossing", "sliding"], "t": t})
