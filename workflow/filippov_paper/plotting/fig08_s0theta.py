"""fig:s0theta: s0(theta), the positive root of eq:s0def, for theta < 0, with
s0 = -theta dashed: the paper states s0 > -theta."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

VARS = ["s0", "s0_root"]


def draw(ds):
    st.require(ds, "fig08_s0theta", VARS)
    theta = ds.theta.values
    fig = st.new_figure(0.6 * st.TEXT_WIDTH, 2.2)  # printed at 0.6\textwidth
    ax = fig.add_subplot()
    ax.plot(theta, -theta, ls="--", color=st.C_AUX, lw=st.LW, label=r"$-\theta$")
    ax.plot(theta, ds.s0.values, color=st.C_PLUS, lw=st.LW, label=st.S0)
    # The independent root-finder, sparsely, to show it lies on the curve.
    # Markers at ~15 evenly spaced theta (the grid itself may be non-uniform).
    pick = np.unique(np.abs(theta[:, None] - np.linspace(theta.min(), theta.max(), 15)).argmin(axis=0))
    ax.plot(theta[pick], ds.s0_root.values[pick], "o", ms=3, mfc="none",
            color=st.C_MINUS, lw=0, label=r"root of $(1-\theta)e^{-s}-1+s+\theta=0$")
    ax.set_xlim(theta.min(), 0.0)
    ax.set_ylim(0.0, 1.05 * np.nanmax(ds.s0.values))
    ax.set_xlabel(st.THETA)
    ax.set_ylabel(r"$s_0$")
    ax.legend(loc="upper right")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 60) -> xr.Dataset:
    # Parametrise by s0 (eq:s0def solved for theta), as the paper suggests.
    s = np.linspace(0.02, 6.0, n)
    theta = (1 - s - np.exp(-s)) / (1 - np.exp(-s))
    order = np.argsort(theta)
    return xr.Dataset({"s0": ("theta", s[order]), "s0_root": ("theta", s[order])},
                      coords={"theta": theta[order]})
