"""fig:retmaps: the return map P to L1 with the diagonal and the fixed points,
(a) theta = -0.5 (jump at x2 = 1), (b) theta = 0.5 (continuous, kink at x2 = 1)."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

VARS = ["P", "residual", "fixed_point", "n_switches"]


def draw(ds):
    st.require(ds, "fig04_retmaps", VARS)
    x2 = ds.x2.values
    fig = st.new_figure(st.TEXT_WIDTH, 2.5)
    axes = fig.subplots(1, 2)
    lo, hi = x2.min(), x2.max()
    for k, (ax, theta) in enumerate(zip(axes, ds.theta.values)):
        P = ds.P.values[k]
        left, right = x2 <= 1.0, x2 > 1.0
        ax.plot([lo, hi], [lo, hi], color=st.C_AUX, lw=st.LW_THIN, ls="--", label=r"$P=x_2$")
        ax.plot(x2[left], P[left], color=st.C_PLUS, lw=st.LW, label=r"no switching")
        ax.plot(x2[right], P[right], color=st.C_MINUS, lw=st.LW,
                label="sliding" if theta > 0 else "crossing $\\mathcal{H}_s$")
        if theta < 0:  # the one-sided limit from the right, open circle
            i = np.flatnonzero(right)[0]
            ax.plot(x2[i], P[i], "o", ms=4, mfc="white", color=st.C_MINUS, zorder=4)
        for fp in ds.fixed_point.values[k]:
            if np.isfinite(fp):
                ax.plot(fp, fp, "o", ms=4, color="black", zorder=5, label="fixed point")
        ax.set_xlim(lo, hi)
        pmin = min(P.min(), lo)
        ax.set_ylim(pmin - 0.05 * (hi - pmin), hi)
        ax.set_xlabel(r"$x_2$ on $\mathcal{L}_1$")
        ax.set_ylabel(r"$P(x_2)$")
        st.panel_label(ax, f"({'ab'[k]}) $\\theta={theta:g}$, "
                           f"$\\varepsilon={float(ds.attrs['eps']):g}$, $\\mu={float(ds.attrs['mu']):g}$")
        ax.legend(loc="upper left")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 81) -> xr.Dataset:
    """A return map with the right shape: smooth slope below 1, a jump (theta<0) or kink above."""
    x2 = np.linspace(0.96, 1.04, n)
    k = np.exp(-0.5)
    P = np.array([np.where(x2 <= 1, 1 + k * (x2 - 1), 0.994 - 0.3 * np.sqrt(np.abs(x2 - 1))),
                  np.where(x2 <= 1, 1 + k * (x2 - 1), 1 - 0.01 * np.tanh(60 * (x2 - 1)))])
    return xr.Dataset(
        {"P": (("theta", "x2"), P), "residual": (("theta", "x2"), np.zeros_like(P)),
         "n_switches": (("theta", "x2"), (P != 1 + k * (x2 - 1)).astype(np.int32)),
         "fixed_point": (("theta", "fixed"), [[1.0], [1.0]])},
        coords={"theta": [-0.5, 0.5], "x2": x2}, attrs={"eps": 0.01, "mu": 1.0})
