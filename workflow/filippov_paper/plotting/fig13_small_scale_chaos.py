"""Small-scale chaos (theta > 0): orbit diagrams with the limit map, the Lyapunov
exponent against s for every theta, and the eps^2 scaling of the attractor's width."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

#: tolerated thumbnail RMS across machines (filippov_paper.manifest): panels (a)-(c) scatter
#: the points of chaotic orbits, which another machine replaces by another orbit on the
#: same attractor -- other pixels over about a third of the figure's area (0.078 measured
#: under the emulated CPU); lines and labels still have to agree
IMAGE_RMS = 0.15

VARS = ["u", "u_limit", "lyapunov", "lyapunov_limit", "width_x2", "width_exponent", "chaotic",
        "width_exponent_err",
        "slope_pdm", "period"]
S_LABEL = r"$s=(\mu-1)/\varepsilon^2$"
U_LABEL = r"$(x_2-1)/\varepsilon^2$ on $\mathcal{L}_1$"
COLORS = ["0.6", st.C_PLUS, st.C_SLIDE, "#CC79A7", st.C_MINUS, "black"]


def draw(ds):
    st.require(ds, "fig13_small_scale_chaos", VARS)
    s, eps, th = ds.s.values, ds.eps.values, ds.theta.values
    lin = s <= float(ds.attrs["s_max"]) + 1e-12
    j = len(eps) - 1
    fig = st.new_figure(st.TEXT_WIDTH, 4.9)
    axes = fig.subplots(2, 3)
    # one theta in each band past grazing: period one, period two, chaos
    picks = [i for i in np.argsort(-th) if th[i] in (0.5, 0.3, 0.2)][:3] or [0, 1, 2][:th.size]
    for k, (ax, i) in enumerate(zip(axes[0], picks)):
        st.orbit_diagram(ax, s[lin], ds.u.values[i, j][lin], color="black")
        st.orbit_diagram(ax, s[lin] + 0.3 * (s[1] - s[0]), ds.u_limit.values[i, j][lin],
                 color=st.C_MINUS)
        ax.set_xlabel(S_LABEL)
        ax.set_ylabel(U_LABEL)
        ax.set_xlim(s[lin].min(), s[lin].max())
        st.panel_label(ax, f"({'abc'[k]}) $\\theta={th[i]:g}$, "
                           f"$\\varepsilon={st.eps_value(eps[j])}$,\n"
                           f"$s(\\theta,0,0)={float(ds.slope_pdm.values[i]):.3g}$")
        if k == 0:
            ax.plot([], [], "s", ms=3, color="black", label="slow-fast")
            ax.plot([], [], "s", ms=3, color=st.C_MINUS, label="limit map")
            ax.legend(loc="lower right")  # below the attractor: empty
    ax = axes[1, 0]
    for i, t in enumerate(th):
        c = COLORS[i % len(COLORS)]
        ax.plot(s[lin], ds.lyapunov.values[i, j][lin], color=c, lw=st.LW,
                label=f"$\\theta={t:g}$")
        ax.plot(s[lin], ds.lyapunov_limit.values[i, j][lin], color=c, lw=st.LW_THIN, ls="--")
    ax.axhline(0.0, color=st.C_AUX, lw=st.LW_THIN)
    ax.set_ylim(-2.0, 1.0)
    ax.set_xlim(s[lin].min(), s[lin].max())
    ax.set_xlabel(S_LABEL)
    ax.set_ylabel("largest Lyapunov exponent")
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower left", ncol=2)  # under (d)
    st.panel_label(ax, f"(d) $\\varepsilon={st.eps_value(eps[j])}$; dashed: limit map")
    ax = axes[1, 1]
    i = int(np.argmin(np.abs(th - 0.2)))
    pos = s > 0
    for jj, e in enumerate(eps):
        w = ds.width_x2.values[i, jj][pos]
        ok = ds.chaotic.values[i, jj][pos] == 1  # chaotic attractors only
        ax.loglog((s[pos] * e * e)[ok], w[ok], "o-", ms=2, lw=st.LW_THIN,
                  color=COLORS[(jj + 2) % len(COLORS)], label=f"$\\varepsilon={st.eps_value(e)}$")
    ax.set_xlabel(r"$\mu-1$")
    ax.set_ylabel(r"width in $x_2$ (chaotic points)")
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center")  # under (e)
    st.panel_label(ax, f"(e) $\\theta={th[i]:g}$: chaos on the scale $\\varepsilon^2$")
    ax = axes[1, 2]
    for i, t in enumerate(th):
        k = ds.width_exponent.values[i]
        if np.isfinite(k).any():
            ax.errorbar(s[pos], k[pos], yerr=ds.width_exponent_err.values[i][pos], fmt="o-",
                        ms=2, lw=st.LW_THIN, elinewidth=st.LW_THIN, capsize=0,
                        color=COLORS[i % len(COLORS)], label=f"$\\theta={t:g}$")
            ax.set_xscale("log")
    ax.axhline(2.0, color=st.C_AUX, lw=st.LW_THIN, ls="--", label="$k=2$")
    ax.set_ylim(0.0, 4.0)
    ax.set_xlabel(S_LABEL)
    ax.set_ylabel(r"$k$ in width $\propto\varepsilon^k$")
    ax.legend(loc="lower left")
    st.panel_label(ax, "(f) scaling exponent\nof the width")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(k: int = 5) -> xr.Dataset:
    """Fans of made-up chaotic returns; widths ~ eps^2 (mu - 1)."""
    theta = np.array([0.5, 0.2, 0.1])
    eps = np.array([1e-2, 1e-3])
    s = np.concatenate([np.linspace(-1.0, 5.0, 13), [20.0, 100.0]])
    shape = (theta.size, eps.size, s.size)
    fan = np.maximum(s, 0)[None, None, :, None] * np.linspace(-0.3, 0.1, k)
    u = np.broadcast_to(fan, shape + (k,)).copy()
    lyap = np.broadcast_to(np.where(s > 0, 0.3, -0.5), shape).copy()
    width = np.broadcast_to(np.maximum(s, 0) * eps[None, :, None] ** 2 + 1e-12, shape).copy()
    return xr.Dataset(
        {"u": (("theta", "eps", "s", "k"), u), "u_limit": (("theta", "eps", "s", "k"), u),
         "lyapunov": (("theta", "eps", "s"), lyap), "lyapunov_limit": (("theta", "eps", "s"), lyap),
         "width_x2": (("theta", "eps", "s"), width),
         "chaotic": (("theta", "eps", "s"), (lyap > 0).astype(np.int32)),
         "width_exponent_err": (("theta", "s"), np.full((theta.size, s.size), 0.01)),
         "width_exponent": (("theta", "s"), np.broadcast_to(np.where(s > 0, 2.0, np.nan),
                                                           (theta.size, s.size)).copy()),
         "slope_pdm": ("theta", (theta - 1) / theta),
         "period": (("theta", "eps", "s"), np.where(np.broadcast_to(s, shape) > 0, 0, 1)
                    .astype(np.int32))},
        coords={"theta": theta, "eps": eps, "s": s, "k": np.arange(k)},
        attrs={"s_max": 5.0})
