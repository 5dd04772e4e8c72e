"""fig:dfo-retmap: return maps P to L with the diagonal, fixed points (filled:
stable, open: unstable), the onset of sticking and the part of the map whose
orbits stick (slide) marked.

The map is continuous (case 1 of lemma thm:gen): the branch without sticking
and the branch with sticking are drawn up to and from the onset point, which
is a grid point of the (refined) x1 grid. One legend below both panels, so no
data are covered.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

VARS = ["P", "fixed_point", "sliding_length", "eps", "v0"]


def _branches(x1, P, slide, onset):
    """(no sticking, with sticking) as (x, P) pairs that share the onset point."""
    if onset is not None and np.isfinite(onset):
        before, after = x1 <= onset, x1 >= onset
    else:  # no onset stored: join the branches at the first sticking grid point
        i = np.flatnonzero(slide)
        k = i[0] if i.size else x1.size
        before, after = np.arange(x1.size) <= k, slide.copy()
    return (x1[before], P[before]), (x1[after], P[after])


def _stable(fp, x1, P):
    """|P'| < 1 at the fixed point, from the grid (one-sided near a kink)."""
    d = np.gradient(P, x1)
    return abs(float(np.interp(fp, x1, d))) < 1.0


def draw(ds):
    st.require(ds, "fig11_dfo_retmaps", VARS)
    x1 = ds.x1.values
    fig = st.new_figure(st.TEXT_WIDTH, 2.7)
    axes = fig.subplots(1, ds.sizes["panel"], squeeze=False)[0]
    lo, hi = x1.min(), x1.max()
    handles = {}
    for k, ax in enumerate(axes):
        P = ds.P.values[k]
        slide = ds.sliding_length.values[k] > 0
        onset = float(ds.x1_onset.values[k]) if "x1_onset" in ds else None
        (xa, pa), (xb, pb) = _branches(x1, P, slide, onset)
        handles["diag"], = ax.plot([lo, hi], [lo, hi], color=st.C_AUX, lw=st.LW_THIN, ls="--",
                                   label="$P=x_1$")
        handles["free"], = ax.plot(xa, pa, color=st.C_PLUS, lw=st.LW,
                                   label="orbit without sticking")
        handles["stick"], = ax.plot(xb, pb, color=st.C_SLIDE, lw=st.LW,
                                    label="orbit with sticking (sliding)")
        if onset is not None and np.isfinite(onset):
            handles["onset"], = ax.plot(onset, float(np.interp(onset, x1, P)), "D", ms=3.5,
                                        mfc="white", mec=st.C_SLIDE, mew=1.0, zorder=6,
                                        label="onset of sticking")
        for fp in ds.fixed_point.values[k]:
            if not np.isfinite(fp):
                continue
            stable = _stable(fp, x1, P)
            key = "fp_s" if stable else "fp_u"
            handles[key], = ax.plot(fp, fp, "o", ms=4.5, zorder=7, mec="black", mew=1.0,
                                    mfc="black" if stable else "white",
                                    label="stable fixed point" if stable else "unstable fixed point")
        ax.set_xlim(lo, hi)
        pad = 0.03 * (hi - lo)
        ax.set_ylim(min(np.nanmin(P), lo) - pad, max(np.nanmax(P), hi) + pad)
        ax.set_xlabel(r"$x_1$ (start point on $\mathcal{L}$)")
        ax.set_ylabel(r"$P(x_1)$")
        eps, v0 = float(ds.eps.values[k]), float(ds.v0.values[k])
        st.panel_label(ax, f"({'ab'[k]}) $\\epsilon={eps:g}$, $v_0={v0:g}$")
        if "v0_sn" in ds:
            ax.text(0.97, 0.04, f"saddle-node at $v_0={float(ds.v0_sn.values[k]):.6f}$",
                    transform=ax.transAxes, ha="right", va="bottom", fontsize=st.FONT_MIN)
    order = ["diag", "free", "stick", "onset", "fp_s", "fp_u"]
    hs = [handles[n] for n in order if n in handles]
    fig.legend(hs, [h.get_label() for h in hs], loc="outside lower center", ncol=3,
               frameon=False)
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 41) -> xr.Dataset:
    x1 = np.linspace(4.15, 4.6, n)
    P = np.array([np.where(x1 < 4.3, x1 + 2 * (x1 - 4.29), 4.43 - 0.1 * (x1 - 4.3)),
                  np.where(x1 < 4.3, x1 + 2 * (x1 - 4.29), 4.43 + 0 * x1)])
    sl = np.where(x1 < 4.3, 0.0, x1 - 4.3)
    return xr.Dataset(
        {"P": (("panel", "x1"), P), "sliding_length": (("panel", "x1"), np.stack([sl, sl])),
         "fixed_point": (("panel", "fixed"), [[4.29, 4.43], [4.29, 4.43]]),
         "eps": ("panel", [0.1, 0.01]), "v0": ("panel", [3.32, 3.1]),
         "v0_sn": ("panel", [3.3228, 3.1721])},
        coords={"panel": [0, 1], "x1": x1})
