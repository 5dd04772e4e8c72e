"""Atlas of the attractor near grazing over (theta, s): slow-fast system and limit map,
with the paper's condition s(theta,0,0) = -1 and the threshold lambda s(theta,0,0) = -1."""
from __future__ import annotations

import matplotlib.colors as mcolors
import numpy as np

from . import style as st

VARS = ["attractor_type", "attractor_type_limit", "theta_critical"]
# classes: escaped, aperiodic, chaotic, period 1, 2, 3, 4, 5, >= 6
CLASSES = ["escaped", "aperiodic", "chaotic", "period 1", "period 2", "period 3", "period 4",
           "period 5", r"period $\geq 6$"]
COLORS = ["white", "0.45", "black", "0.88", st.C_PLUS, st.C_SLIDE, st.C_MINUS, "#CC79A7",
          "#E69F00"]


def _index(kind: np.ndarray) -> np.ndarray:
    """Class index of each attractor type (see the scene module's codes)."""
    return np.where(kind <= 0, kind + 2, np.minimum(kind, 6) + 2)


def _edges(x: np.ndarray) -> np.ndarray:
    mid = 0.5 * (x[1:] + x[:-1])
    return np.concatenate([[x[0] - (mid[0] - x[0])], mid, [x[-1] + (x[-1] - mid[-1])]])


def draw(ds):
    st.require(ds, "fig14_atlas", VARS)
    th, s = ds.theta.values, ds.s.values
    eps = float(ds.eps.values[0])
    cmap = mcolors.ListedColormap(COLORS)
    norm = mcolors.BoundaryNorm(np.arange(len(COLORS) + 1) - 0.5, len(COLORS))
    fig = st.new_figure(st.WIDTH_DOUBLE, 3.3)
    axes = fig.subplots(1, 2, sharey=True)
    crit = float(ds.theta_critical.values)
    for k, (ax, name, label) in enumerate(zip(axes, ("attractor_type", "attractor_type_limit"),
                                              ("slow-fast", "limit map"))):
        idx = _index(ds[name].values[:, 0, :])
        mesh = ax.pcolormesh(_edges(th), _edges(s), idx.T, cmap=cmap, norm=norm,
                             edgecolors="face", linewidth=0)
        mesh.set_rasterized(False)
        ax.axvline(0.5, color="white", ls="--", lw=st.LW)
        ax.axvline(crit, color="white", ls="-", lw=st.LW)
        ax.axvline(0.0, color="black", lw=st.LW_THIN)
        ax.set_xlabel(st.THETA)
        st.panel_label(ax, f"({'ab'[k]}) {label}, $\\varepsilon={st.eps_value(eps)}$")
    axes[0].set_ylabel(r"$s=(\mu-1)/\varepsilon$ ($\theta<0$), $(\mu-1)/\varepsilon^2$ ($\theta>0$)")
    handles = [axes[0].fill_between([], [], color=c, label=n, ec="0.5", lw=0.3)
               for c, n in zip(COLORS, CLASSES)]
    handles += [axes[0].plot([], [], color="0.3", ls="--", label=r"$s(\theta,0,0)=-1$")[0],
                axes[0].plot([], [], color="0.3", ls="-",
                             label=r"$\lambda s(\theta,0,0)=-1$")[0]]
    fig.legend(handles=handles, loc="outside right center", fontsize=6, frameon=False)
    return fig
