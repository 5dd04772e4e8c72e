"""fig:thetalt0mfs: 3-D zoom near the grazing point p_g = (-1, 0, -1) for theta < 0:
the planes M_+ = {y = x1} and H_s, the (numerically computed) slow manifold M_-,
the grazing periodic orbit in M_+ and one trajectory switching E+ -> E- -> E+.

Thin vertical segments join the switching trajectory to M_+ along the stable
fibres {x = const} of M_+: their length is the O(eps) distance that opens in
region - and decays like exp(-t/eps) after the return to region +."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D
from matplotlib.ticker import MaxNLocator

from filippov_paper.plotting import style as st
from filippov_paper.plotting.lines import runs

VARS = ["x1", "x2", "y", "mode", "orbit_x1", "orbit_x2", "orbit_y", "switch_x1", "switch_x2",
        "switch_y", "switch_t", "y_M_plus", "y_M_minus", "y_H_s"]
COLOUR = {1: st.C_PLUS, -1: st.C_MINUS, 0: st.C_SLIDE}
VIEW = dict(elev=22.0, azim=-130.0)
FACETS = 12  # facets per side of each translucent surface
MESH = 6  # grid lines per side drawn on each surface
ALPHA = 0.14
Y_PAD = 0.3  # y window beyond M_+ and H_s, as a fraction of their span
N_FIBRES = 14  # drop lines from the trajectory to M_+


def _inside(x1, x2, y, box):
    (a1, b1), (a2, b2), (ay, by) = box
    return (x1 >= a1) & (x1 <= b1) & (x2 >= a2) & (x2 <= b2) & (y >= ay) & (y <= by)


def _curve(ax, x1, x2, y, box, **kw):
    """A curve, cut where it leaves the box (mplot3d does not clip lines itself)."""
    keep = _inside(x1, x2, y, box)
    x1, x2, y = (np.where(keep, v, np.nan) for v in (x1, x2, y))
    ax.plot(x1, x2, y, **kw)


def _surface(ax, X1, X2, Y, colour):
    ax.plot_surface(X1, X2, Y, color=colour, alpha=ALPHA, linewidth=0, shade=False,
                    antialiased=False, rcount=FACETS, ccount=FACETS)
    edge = dict(color=colour, lw=0.35, alpha=min(1.0, 3 * ALPHA))
    n1, n2 = X1.shape
    for i in np.unique(np.linspace(0, n1 - 1, MESH).round().astype(int)):
        ax.plot(X1[i], X2[i], Y[i], **edge)
    for j in np.unique(np.linspace(0, n2 - 1, MESH).round().astype(int)):
        ax.plot(X1[:, j], X2[:, j], Y[:, j], **edge)


def _fibres(ax, ds, box):
    """Vertical segments trajectory -> M_+ at equal time steps from the first switch
    to where the trajectory leaves the window."""
    t, x1, x2, y = ds.t.values, ds.x1.values, ds.x2.values, ds.y.values
    inside = _inside(x1, x2, y, box) & (t >= float(ds.switch_t[0]))
    if not inside.any():
        return
    # the first stretch inside the window after the first switch
    idx = np.flatnonzero(inside)
    gap = np.flatnonzero(np.diff(idx) > 1)
    last = idx[gap[0]] if gap.size else idx[-1]
    times = np.linspace(t[idx[0]], t[last], N_FIBRES + 1)[1:]
    for k in np.searchsorted(t, times).clip(0, t.size - 1):
        ax.plot([x1[k], x1[k]], [x2[k], x2[k]], [y[k], x1[k]], color="0.35", lw=0.45)


def draw(ds):
    st.require(ds, "fig05_thetalt0mfs", VARS)
    eps, theta = float(ds.attrs["eps"]), float(ds.attrs["theta"])
    g1, g2 = ds.x1_grid.values, ds.x2_grid.values
    X1, X2 = np.meshgrid(g1, g2, indexing="ij")
    yp, yh, ym = ds.y_M_plus.values, ds.y_H_s.values, ds.y_M_minus.values
    # The y window holds M_+ and H_s. M_- is steep in x2 (slope -eps omega), so it
    # is drawn over the x2 columns where it stays inside that window.
    lo_y, hi_y = min(yp.min(), yh.min()), max(yp.max(), yh.max())
    pad = Y_PAD * (hi_y - lo_y)
    box = ((g1[0], g1[-1]), (g2[0], g2[-1]), (lo_y - pad, hi_y + pad))
    cols = np.flatnonzero(np.all((ym >= box[2][0]) & (ym <= box[2][1]), axis=0))

    fig = st.new_figure(0.85 * st.TEXT_WIDTH, 4.2)  # printed at 0.85\textwidth
    ax = fig.add_subplot(projection="3d")
    ax.computed_zorder = False  # translucent surfaces first, curves on top
    ax.view_init(**VIEW)

    _surface(ax, X1, X2, yh, "0.45")
    _surface(ax, X1, X2, yp, st.C_PLUS)
    if cols.size >= 2:
        sl = slice(cols[0], cols[-1] + 1)
        _surface(ax, X1[:, sl], X2[:, sl], ym[:, sl], st.C_MINUS)
    # H_s meets M_+ in the line x1 = y = -1, where the grazing orbit touches
    ax.plot([-1.0, -1.0], box[1], [-1.0, -1.0], color="k", lw=0.5, ls=(0, (4, 3)))

    _curve(ax, ds.orbit_x1.values, ds.orbit_x2.values, ds.orbit_y.values, box,
           color="k", lw=st.LW_BOLD)
    _fibres(ax, ds, box)
    x1, x2, y, mode = ds.x1.values, ds.x2.values, ds.y.values, ds["mode"].values
    for a, b, m in runs(mode):
        _curve(ax, x1[a:b], x2[a:b], y[a:b], box, color=COLOUR.get(m, "k"), lw=st.LW)
    ax.plot(ds.switch_x1.values, ds.switch_x2.values, ds.switch_y.values, "o", color="k",
            mfc="white", ms=3.5, mew=0.7)
    ax.plot([-1.0], [0.0], [-1.0], "o", color="k", ms=3.5)
    ax.text(-1.0, 0.0, -1.0 - 0.12 * (hi_y - lo_y), r"$p_g$", ha="center", va="top")

    ax.set_xlim(*box[0])
    ax.set_ylim(*box[1])
    ax.set_zlim(*box[2])
    ax.set_xlabel(st.X1, labelpad=-7)
    ax.set_ylabel(st.X2, labelpad=-7)
    ax.set_zlabel(st.Y, labelpad=-7)
    ax.tick_params(pad=-3, labelsize=st.FONT_MIN)
    ax.tick_params(axis="z", pad=0)  # clear of the tick marks
    for axis, prune in ((ax.xaxis, "both"), (ax.yaxis, "both"), (ax.zaxis, None)):
        axis.set_major_locator(MaxNLocator(4, steps=[1, 2, 2.5, 5, 10], prune=prune))
        axis.pane.set_alpha(0.0)
        axis.set_rotate_label(False)  # upright x_1, x_2, y
        axis._axinfo["grid"]["linewidth"] = 0.25
    ax.set_box_aspect((1.0, 1.2, 1.0), zoom=0.95)

    # surface names next to their far (x2 max or x1 max) edges
    ax.text(g1[-1], g2[0], yp[-1, 0], " " + st.M_PLUS, color=st.C_PLUS, ha="left", va="bottom")
    if cols.size >= 2:
        k = cols[-1]
        ax.text(g1[-1], g2[k], ym[-1, k], " " + st.M_MINUS, color=st.C_MINUS, ha="left",
                va="bottom")
    ax.text(g1[-1], g2[0], yh[-1, 0], " " + st.H_S, color="0.3", ha="left", va="top")

    handles = [Line2D([], [], color="k", lw=st.LW_BOLD, label="grazing orbit"),
               Line2D([], [], color=st.C_PLUS, lw=st.LW, label=r"flow $E_{+}$"),
               Line2D([], [], color=st.C_MINUS, lw=st.LW, label=r"flow $E_{-}$"),
               Line2D([], [], ls="", marker="o", color="k", mfc="white", ms=3.5, mew=0.7,
                      label="switch"),
               Line2D([], [], color="0.35", lw=0.45, label=r"fibre to $\mathcal{M}_{+}$"),
               Line2D([], [], color="k", lw=0.5, ls=(0, (4, 3)),
                      label=r"$\mathcal{H}_s\cap\mathcal{M}_{+}$")]
    fig.legend(handles=handles, loc="upper center", bbox_to_anchor=(0.5, 0.93), ncols=3,
               handlelength=1.6, columnspacing=0.9, borderaxespad=0.0)
    fig.suptitle(rf"$\theta={theta:g}$, $\mu=1$, $\varepsilon={eps:g}$, $\omega={_omega(ds)}$",
                 x=0.02, y=0.99, ha="left", va="top")
    return fig


def _omega(ds) -> str:
    omega = float(ds.attrs.get("omega", np.nan))
    k = omega / np.pi
    return rf"{k:g}\pi" if np.isfinite(k) and abs(k - round(k)) < 1e-9 else f"{omega:g}"


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 400, eps: float = 0.01, theta: float = -0.5) -> xr.Dataset:
    """Circle arcs near p_g, a straight E_- leg and a crude exp(-t/eps) relaxation."""
    omega = 8 * np.pi
    phi = np.linspace(0.0, 2 * np.pi, n)
    ox1, ox2 = -np.cos(phi), -np.sin(phi)            # unit circle through p_g at phi = 0
    t = np.linspace(0.0, 0.3, n)
    r = np.where(t < 0.1, 1.004, 0.95)
    ang = np.pi - 0.1 + omega * (t - 0.1) * (t > 0.1)
    x1, x2 = r * np.cos(ang), r * np.sin(ang)
    leg = (t > 0.05) & (t <= 0.1)                     # E_-: x1 increases, x2 fixed
    x1 = np.where(leg, -1.0 + (t - 0.05), x1)
    x2 = np.where(leg, 0.1, x2)
    y = x1 - 3 * eps * np.where(t > 0.05, np.exp(-np.clip(t - 0.1, 0, None) / eps), 0.0)
    mode = np.where(leg, -1, 1).astype("int8")
    g1, g2 = np.linspace(-1.04, -0.9, 8), np.linspace(-0.4, 0.3, 9)
    X1, X2 = np.meshgrid(g1, g2, indexing="ij")
    ym = X1 + eps * (X1 - omega * X2 - (X1 ** 2 + X2 ** 2) * X1 - 1.0)
    return xr.Dataset(
        {"x1": ("t", x1), "x2": ("t", x2), "y": ("t", y), "mode": ("t", mode),
         "orbit_x1": ("t_orbit", ox1), "orbit_x2": ("t_orbit", ox2),
         "orbit_y": ("t_orbit", ox1),
         "switch_t": ("switch", [0.05, 0.1]), "switch_x1": ("switch", [-1.0, -0.95]),
         "switch_x2": ("switch", [0.1, 0.1]), "switch_y": ("switch", [-1.0, -0.98]),
         "y_M_plus": (("x1_grid", "x2_grid"), X1), "y_M_minus": (("x1_grid", "x2_grid"), ym),
         "y_H_s": (("x1_grid", "x2_grid"), (-1.0 - theta * X1) / (1.0 - theta))},
        coords={"t": t, "x1_grid": g1, "x2_grid": g2},
        attrs={"eps": eps, "theta": theta, "mu": 1.0, "omega": omega})
