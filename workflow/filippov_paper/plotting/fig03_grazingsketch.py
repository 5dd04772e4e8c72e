"""fig:grazingsketch: the periodic orbit of the reduced example eq:red for
(a) mu < 1, (b) mu = 1 (grazing at x_g), (c) mu > 1 (sliding from x_h to x_l),
with the switching line H_s^0 = {x1 = -1} and the section L1."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st
from filippov_paper.plotting.lines import arrowhead, runs

VARS = ["x1", "x2", "mode", "x_g", "x_h", "x_l", "fixed_x2"]
COLOUR = {1: st.C_PLUS, -1: st.C_MINUS, 0: st.C_SLIDE}
XLIM, YLIM = (-1.5, 1.3), (-1.3, 1.4)


def _frame(ax) -> None:
    """Switching line, region - with its constant field, section L1, axes."""
    ax.axvspan(XLIM[0], -1.0, color="0.93", lw=0, zorder=0)
    ax.axvline(-1.0, color="k", lw=st.LW, zorder=1)
    ax.text(-1.0, YLIM[1], r"$\mathcal{H}_s^0$ ", ha="right", va="top")
    ax.text(XLIM[0] + 0.05, YLIM[0] + 0.06, r"$\mathcal{H}_-$", ha="left", va="bottom")
    ax.text(XLIM[1] - 0.05, YLIM[0] + 0.06, r"$\mathcal{H}_+$", ha="right", va="bottom")
    for y in (-0.75, 0.75):  # f_- = (1, 0)
        ax.annotate("", xy=(-1.08, y), xytext=(-1.40, y),
                    arrowprops=dict(arrowstyle="-|>", color=st.C_MINUS, lw=st.LW_THIN,
                                    mutation_scale=7, shrinkA=0, shrinkB=0))
    ax.text(-1.24, -0.72, st.F_MINUS, color=st.C_MINUS, ha="center", va="bottom")
    ax.plot([0.0, 0.0], [0.0, YLIM[1]], color="k", lw=st.LW_BOLD, solid_capstyle="butt", zorder=2)
    ax.text(0.05, YLIM[1] - 0.06, r"$\mathcal{L}_1$", ha="left", va="top")
    ax.plot([0.0], [0.0], "+", color=st.C_AUX, ms=5, mew=st.LW_THIN)
    ax.set_xlim(XLIM)
    ax.set_ylim(YLIM)
    ax.set_aspect("equal")
    ax.set_xlabel(st.X1)
    ax.set_xticks([-1, 0, 1])
    ax.set_yticks([-1, 0, 1])


def _point(ax, xy, label, offset, ha, va) -> None:
    ax.plot([xy[0]], [xy[1]], "o", color="k", ms=3.2, zorder=6)
    ax.annotate(label, xy, xytext=offset, textcoords="offset points", ha=ha, va=va, zorder=6)


def _orbit(ax, d) -> None:
    x, y, mode = d.x1.values, d.x2.values, d["mode"].values
    for a, b, m in runs(mode):
        lw = st.LW_BOLD if m == 0 else st.LW
        ax.plot(x[a:b], y[a:b], color=COLOUR.get(m, "k"), lw=lw, solid_capstyle="butt", zorder=3)
    # direction marks on the smooth arcs, upper left and lower right
    angle = np.angle(x + 1j * y)
    for target in (0.7 * np.pi, -0.3 * np.pi):
        i = int(np.argmin(np.abs(np.angle(np.exp(1j * (angle[:-1] - target))))))
        arrowhead(ax, x, y, i, COLOUR.get(int(mode[i]), "k"))
    # where the orbit crosses L1 (the fixed point of the return map)
    ax.plot([0.0], [float(d.fixed_x2)], "o", ms=3.2, mfc="white", mec="k", mew=st.LW_THIN, zorder=6)


def draw(ds):
    st.require(ds, "fig03_grazingsketch", VARS)
    mus = ds.mu.values
    if mus.size != 3:
        raise ValueError(f"fig03_grazingsketch: expected three values of mu, got {mus.tolist()}")
    fig = st.new_figure(st.TEXT_WIDTH, 2.0)
    axes = fig.subplots(1, 3, sharey=True)
    relation = {-1: "<1", 0: "=1", 1: ">1"}
    for k, (ax, mu) in enumerate(zip(axes, mus)):
        d = ds.sel(mu=mu)
        _frame(ax)
        _orbit(ax, d)
        rel = relation[int(np.sign(np.round(mu - 1.0, 12)))]
        tex = rf"\mu={mu:g}" + ("" if rel == "=1" else rel)
        st.panel_label(ax, f"({'abc'[k]}) ${tex}$")
        if np.isclose(mu, 1.0, rtol=0, atol=1e-12):
            _point(ax, ds.x_g.values, r"$x_g$", (-4, 0), "right", "center")
        elif mu > 1:
            xh, xl = d.x_h.values, d.x_l.values
            _point(ax, xh, r"$x_h$", (-4, 2), "right", "bottom")
            _point(ax, xl, r"$x_l$", (-4, -2), "right", "top")
    axes[0].set_ylabel(st.X2)
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 300, omega: float = 8 * np.pi) -> xr.Dataset:
    """Circles of radius sqrt(mu), clipped at x1 = -1 (a crude stand-in for sliding)."""
    mus = np.array([0.8, 1.0, 1.2])
    phi = np.linspace(np.pi / 2, np.pi / 2 + 2 * np.pi, n)
    x1 = np.sqrt(mus)[:, None] * np.cos(phi)
    x2 = np.sqrt(mus)[:, None] * np.sin(phi)
    mode = np.where(x1 < -1.0, 0, 1).astype("int8")
    x1 = np.maximum(x1, -1.0)
    nan2 = [np.nan, np.nan]
    return xr.Dataset(
        {"x1": (("mu", "sample"), x1), "x2": (("mu", "sample"), x2),
         "mode": (("mu", "sample"), mode), "fixed_x2": ("mu", np.sqrt(mus)),
         "x_g": ("component", [-1.0, 0.0]),
         "x_h": (("mu", "component"), [nan2, nan2, [-1.0, np.sqrt(0.2)]]),
         "x_l": (("mu", "component"), [nan2, nan2, [-1.0, -np.sqrt(0.2)]])},
        coords={"mu": mus, "component": ["x1", "x2"]}, attrs={"omega": omega})
