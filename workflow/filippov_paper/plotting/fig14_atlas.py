"""Atlas of the attractor near grazing over (theta, s): slow-fast system and limit map,
with the paper's condition s(theta,0,0) = -1, the normal form's thresholds (period one
to two: lambda s = -1; two to chaos: lambda^2 s = -1) and the computed flips of each."""
from __future__ import annotations

import matplotlib.colors as mcolors
import matplotlib.patheffects as pe
import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

VARS = ["attractor_type", "attractor_type_limit", "theta_critical", "theta_chaos",
        "theta_flip", "theta_chaos_flip", "theta_flip_limit", "theta_chaos_limit"]
#: boundary lines: white with a dark edge, visible on every class colour (legend alike)
_EDGE = [pe.Stroke(linewidth=2.2, foreground="black"), pe.Normal()]
_LINE = dict(color="white", lw=st.LW, path_effects=_EDGE)
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
    fig = st.new_figure(st.TEXT_WIDTH, 2.8)
    axes = fig.subplots(1, 2, sharey=True)
    crit, chaos = float(ds.theta_critical.values), float(ds.theta_chaos.values)
    sb = ds.s_boundary.values
    at = np.flatnonzero(np.isclose(ds.eps_boundary.values, eps, rtol=1e-12))
    flips = {"attractor_type": ((ds.theta_flip.values[at[0]], ds.theta_chaos_flip.values[at[0]])
                                if at.size else None),
             "attractor_type_limit": (ds.theta_flip_limit.values, ds.theta_chaos_limit.values)}
    for k, (ax, name, label) in enumerate(zip(axes, ("attractor_type", "attractor_type_limit"),
                                              ("slow-fast", "limit map"))):
        idx = _index(ds[name].values[:, 0, :])
        mesh = ax.pcolormesh(_edges(th), _edges(s), idx.T, cmap=cmap, norm=norm,
                             edgecolors="face", linewidth=0)
        mesh.set_rasterized(False)
        ax.axvline(0.5, ls="--", **_LINE)
        for x in (crit, chaos):
            ax.axvline(x, ls=":", **_LINE)
        if flips[name] is not None:
            for curve in flips[name]:
                ax.plot(curve, sb, ls="-", marker="o", ms=3, mfc="white", mec="black",
                        mew=0.6, **_LINE)
        ax.axvline(0.0, color="black", lw=st.LW_THIN)
        ax.set_xlabel(st.THETA)
        st.panel_label(ax, f"({'ab'[k]}) {label}, $\\varepsilon={st.eps_value(eps)}$")
    axes[0].set_ylabel(r"$s=(\mu-1)/\varepsilon$ ($\theta<0$), $(\mu-1)/\varepsilon^2$ ($\theta>0$)")
    handles = [axes[0].fill_between([], [], color=c, label=n, ec="0.5", lw=0.3)
               for c, n in zip(COLORS, CLASSES)]
    handles += [axes[0].plot([], [], ls="--", label=r"$s(\theta,0,0)=-1$", **_LINE)[0],
                axes[0].plot([], [], ls=":", label=r"$\lambda s=-1$, $\lambda^2 s=-1$",
                             **_LINE)[0],
                axes[0].plot([], [], ls="-", marker="o", ms=3, mfc="white", mec="black",
                             mew=0.6, label="multiplier $-1$ of\nperiod one, two", **_LINE)[0]]
    fig.legend(handles=handles, loc="outside right center", frameon=False)
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset() -> xr.Dataset:
    """Every attractor class once or more on a coarse (theta, s) grid."""
    theta = np.linspace(-1.0, 0.8, 7)
    s = np.linspace(-1.0, 5.0, 7)
    kind = (np.add.outer(np.arange(theta.size), np.arange(s.size)) % 10 - 2).astype(np.int32)
    sb, eb = np.array([0.5, 1.0, 2.0]), np.array([1e-2, 1e-3])
    flip = 0.38 + 0.01 * sb
    return xr.Dataset(
        {"attractor_type": (("theta", "eps", "s"), kind[:, None, :]),
         "attractor_type_limit": (("theta", "eps", "s"), kind[::-1, None, :].copy()),
         "theta_critical": 0.3775, "theta_chaos": 0.2689,
         "theta_flip": (("eps_boundary", "s_boundary"), np.stack([flip, flip])),
         "theta_chaos_flip": (("eps_boundary", "s_boundary"), np.stack([flip, flip]) - 0.1),
         "theta_flip_limit": ("s_boundary", flip), "theta_chaos_limit": ("s_boundary", flip - 0.1)},
        coords={"theta": theta, "eps": [1e-3], "s": s, "s_boundary": sb, "eps_boundary": eb})
