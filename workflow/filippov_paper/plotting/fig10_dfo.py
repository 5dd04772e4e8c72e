"""fig:dfo: (a) the set-up, drawn from shapes; (b) the friction law F_c;
(c) the bifurcation diagram of eq:dfo1 over the belt speed v (max x1 per orbit)."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib.patches import Circle, FancyArrowPatch, Rectangle

from filippov_paper.plotting import style as st

VARS = ["v_hopf", "v_gs", "eq_v", "eq_x1", "eq_stable", "po_v", "po_x1", "po_stable",
        "ss_v", "ss_x1", "ss_stable", "nu", "F_c", "x1_gs"]


def _setup(ax):
    """Wall (right), spring K, block M on a belt moving toward the wall at speed v."""
    ax.set_xlim(0, 10)
    ax.set_ylim(0, 5)
    ax.set_aspect("equal")
    ax.axis("off")
    ax.add_patch(Rectangle((9.2, 1.9), 0.3, 2.6, color="0.35", lw=0))
    for y in np.linspace(2.0, 4.4, 9):   # hatching of the wall
        ax.plot([9.5, 9.8], [y, y + 0.25], color="0.35", lw=st.LW_THIN)
    ax.add_patch(Rectangle((3.2, 2.3), 2.0, 1.5, fc="#dddddd", ec="black", lw=st.LW))
    ax.text(4.2, 3.05, "$M$", ha="center", va="center")
    xs = np.linspace(5.2, 9.2, 41)       # zig-zag spring between block and wall
    ys = 3.05 + 0.3 * np.where(np.arange(41) % 4 == 1, 1, np.where(np.arange(41) % 4 == 3, -1, 0))
    ys[:4], ys[-4:] = 3.05, 3.05
    ax.plot(xs, ys, color="black", lw=st.LW)
    ax.text(7.2, 3.65, "$K$", ha="center")
    for cx in (1.0, 8.0):                # belt on two rollers
        ax.add_patch(Circle((cx, 1.6), 0.6, fc="white", ec="black", lw=st.LW))
        ax.plot(cx, 1.6, "k.", ms=3)
    ax.plot([1.0, 8.0], [2.2, 2.2], color="black", lw=st.LW)
    ax.plot([1.0, 8.0], [1.0, 1.0], color="black", lw=st.LW)
    ax.add_patch(FancyArrowPatch((3.0, 0.45), (6.0, 0.45), arrowstyle="-|>", mutation_scale=9,
                                 color=st.C_PLUS, lw=st.LW))
    ax.text(6.2, 0.45, "$v$", va="center", color=st.C_PLUS)
    ax.add_patch(FancyArrowPatch((3.2, 4.45), (5.0, 4.45), arrowstyle="-|>", mutation_scale=9,
                                 color="black", lw=st.LW_THIN))
    ax.plot([3.2, 3.2], [3.85, 4.6], color="black", lw=st.LW_THIN)
    ax.text(5.1, 4.45, "$x_1$", va="center")


def draw(ds):
    st.require(ds, "fig10_dfo", VARS)
    fig = st.new_figure(st.TEXT_WIDTH, 2.75)
    gs = fig.add_gridspec(1, 3, width_ratios=[1.0, 0.9, 1.35])
    ax_a, ax_b, ax_c = (fig.add_subplot(gs[0, i]) for i in range(3))
    _setup(ax_a)
    st.panel_label(ax_a, "(a) set-up")

    nu, F = ds.nu.values, ds.F_c.values
    for side in (nu < 0, nu > 0):
        ax_b.plot(nu[side], F[side], color="black", lw=st.LW)
    if "F_c_static" in ds:
        s = float(ds.F_c_static)
        ax_b.plot([0, 0], [-s, s], color="black", lw=st.LW, ls=":")
    if "F_c_literal" in ds:
        Fl = ds.F_c_literal.values
        for k, side in enumerate((nu < 0, nu > 0)):
            ax_b.plot(nu[side], Fl[side], color=st.C_AUX, lw=st.LW_THIN, ls="--",
                      label="printed law,\nliteral" if k == 0 else None)
        st.legend_below(ax_b)
    ax_b.axhline(0, color=st.C_AUX, lw=st.LW_THIN)
    ax_b.set_xlabel(r"$v_\mathrm{rel}=x_2-v$")
    ax_b.set_ylabel(r"$F_c$")
    st.panel_label(ax_b, "(b) friction force")

    ev, ex, es = ds.eq_v.values, ds.eq_x1.values, ds.eq_stable.values.astype(bool)
    ax_c.plot(np.where(es, ev, np.nan), np.where(es, ex, np.nan), color="black", lw=st.LW_BOLD,
              label="equilibrium, stable")
    ax_c.plot(np.where(~es, ev, np.nan), np.where(~es, ex, np.nan), color="black", lw=st.LW,
              ls="--", label="equilibrium, unstable")
    vh, vgs = float(ds.v_hopf), float(ds.v_gs)
    x_h = float(np.interp(vh, ev, ex))
    po_v = np.concatenate([[vh], ds.po_v.values])
    po_x = np.concatenate([[x_h], ds.po_x1.values])
    ax_c.plot(po_v, po_x, color=st.C_MINUS, lw=st.LW, ls="--", label="cycles in $x_2<v$, unstable")
    sv, sx, ss = ds.ss_v.values, ds.ss_x1.values, ds.ss_stable.values.astype(bool)
    ax_c.plot(np.where(ss, sv, np.nan), np.where(ss, sx, np.nan), color=st.C_SLIDE,
              lw=st.LW_BOLD, label="stick-slip, stable")
    if (~ss).any():
        ax_c.plot(np.where(~ss, sv, np.nan), np.where(~ss, sx, np.nan), color=st.C_SLIDE,
                  lw=st.LW, ls="--", label="stick-slip, unstable")
    ax_c.plot(vh, x_h, "o", color="black", ms=4, zorder=5)
    ax_c.annotate("H", (vh, x_h), xytext=(-2, 7), textcoords="offset points", ha="right")
    ax_c.plot(vgs, float(ds.x1_gs), "s", color="black", ms=4, zorder=5)
    ax_c.annotate("GS", (vgs, float(ds.x1_gs)), xytext=(5, -3), textcoords="offset points")
    ax_c.set_xlabel("belt speed $v$")
    ax_c.set_ylabel(r"$\max\,x_1$ on the orbit")
    ax_c.set_xlim(float(ev.min()), float(ev.max()))
    st.legend_below(ax_c)
    st.panel_label(ax_c, "(c) bifurcation diagram")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 40) -> xr.Dataset:
    """Rough shapes: equilibrium line, a square-root Hopf branch, a stick-slip line."""
    vh, vgs = 2.12, 3.156
    ev = np.linspace(0.5, 3.6, n)
    pv = np.linspace(vh + 0.01, vgs, n)
    sv = np.linspace(0.5, vgs, n)
    nu = np.linspace(-6, 6, 121)
    nu = nu[nu != 0]
    F = np.sign(nu) * (2 - 2.5 * (1 - np.exp(-np.abs(nu)))) + 0.3 * nu
    return xr.Dataset(
        {"v_hopf": vh, "v_gs": vgs, "x1_gs": 4.52, "F_c_static": 2.0,
         "eq_v": ("eq", ev), "eq_x1": ("eq", 0.4 + 0.05 * ev),
         "eq_stable": ("eq", (ev > vh).astype(np.int8)),
         "po_v": ("po", pv), "po_x1": ("po", 0.5 + 4 * np.sqrt((pv - vh) / (vgs - vh))),
         "po_stable": ("po", np.zeros(n, np.int8)),
         "ss_v": ("ss", sv), "ss_x1": ("ss", 2.5 + 0.6 * sv), "ss_stable": ("ss", np.ones(n, np.int8)),
         "nu": ("nu", nu), "F_c": ("nu", F), "F_c_literal": ("nu", -F)})
