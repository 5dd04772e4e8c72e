"""fig:dfo-retmap: return maps P to L with the diagonal, fixed points and the
part of the map whose orbits stick (slide) marked."""
from __future__ import annotations

import numpy as np

from . import style as st

VARS = ["P", "fixed_point", "sliding_length", "eps", "v0"]


def draw(ds):
    st.require(ds, "fig11_dfo_retmaps", VARS)
    x1 = ds.x1.values
    fig = st.new_figure(st.WIDTH_DOUBLE, 3.1)
    axes = fig.subplots(1, ds.sizes["panel"], squeeze=False)[0]
    lo, hi = x1.min(), x1.max()
    for k, ax in enumerate(axes):
        P = ds.P.values[k]
        slide = ds.sliding_length.values[k] > 0
        ax.plot([lo, hi], [lo, hi], color=st.C_AUX, lw=st.LW_THIN, ls="--", label="$P=x_1$")
        ax.plot(np.where(~slide, x1, np.nan), np.where(~slide, P, np.nan), color=st.C_PLUS,
                lw=st.LW, marker=".", ms=2, label="no sticking")
        ax.plot(np.where(slide, x1, np.nan), np.where(slide, P, np.nan), color=st.C_SLIDE,
                lw=st.LW, marker=".", ms=2, label="with sticking (sliding)")
        first = True
        for fp in ds.fixed_point.values[k]:
            if np.isfinite(fp):
                ax.plot(fp, fp, "o", ms=4, color="black", zorder=5,
                        label="fixed point" if first else None)
                first = False
        ax.set_xlim(lo, hi)
        ax.set_ylim(min(np.nanmin(P), lo), max(np.nanmax(P), hi))
        ax.set_xlabel(r"$x_1$ on $\mathcal{L}$")
        ax.set_ylabel(r"$P(x_1)$")
        eps, v0 = float(ds.eps.values[k]), float(ds.v0.values[k])
        st.panel_label(ax, f"({'ab'[k]}) $\\varepsilon={eps:g}$, $v_0={v0:g}$")
        if "v0_sn" in ds:
            ax.text(0.97, 0.04, f"saddle-node at $v_0={float(ds.v0_sn.values[k]):.5f}$",
                    transform=ax.transAxes, ha="right", fontsize=7)
        ax.legend(loc="upper left", fontsize=7)
    return fig
