"""Period-adding cascade (theta < 0): orbit diagrams of the slow-fast return map with
the limit map beside them, the period against s, and how the window edges converge."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

#: tolerated thumbnail RMS across machines (filippov_paper.manifest): panel (a) scatters the
#: points of chaotic orbits at eps = 1e-2, which another machine replaces by another
#: orbit on the same attractor (0.0203 measured with every result moved by one ulp,
#: 0.0209 by two, against the default 0.02); lines and labels still have to agree
IMAGE_RMS = 0.05

VARS = ["u", "u_limit", "u_limit0", "period", "period_limit0", "edge", "edge_limit0",
        "edge_gap", "edge_kind"]
S_LABEL = r"$s=(\mu-1)/\varepsilon$"
U_LABEL = r"$(x_2-1)/\varepsilon$ on $\mathcal{L}_1$"


def draw(ds):
    st.require(ds, "fig12_period_adding", VARS)
    s, eps = ds.s.values, ds.eps.values
    theta = float(ds.theta.values[0])
    fig = st.new_figure(st.TEXT_WIDTH, 5.0)
    axes = fig.subplots(2, 3)
    shown = [0, len(eps) // 2, len(eps) - 1]
    for k, (ax, j) in enumerate(zip(axes[0], shown)):
        st.orbit_diagram(ax, s, ds.u.values[0, j], color="black", rasterized=False)
        st.orbit_diagram(ax, s + 0.35 * (s[1] - s[0]), ds.u_limit.values[0, j], color=st.C_MINUS)
        ax.set_xlabel(S_LABEL)
        ax.set_ylabel(U_LABEL)
        ax.set_xlim(s.min(), s.max())
        st.panel_label(ax, f"({'abc'[k]}) $\\varepsilon={st.eps_value(eps[j])}$, $\\theta={theta:g}$")
        if k == 0:
            ax.plot([], [], "s", ms=3, color="black", label="slow-fast")
            ax.plot([], [], "s", ms=3, color=st.C_MINUS, label="limit map")
            ax.legend(loc="lower left")
    ax = axes[1, 0]
    st.orbit_diagram(ax, s, ds.u_limit0.values[0], color=st.C_PLUS)
    ax.set_xlabel(S_LABEL)
    ax.set_ylabel(U_LABEL)
    ax.set_xlim(s.min(), s.max())
    st.panel_label(ax, r"(d) limit map, $\varepsilon\to 0$")
    ax = axes[1, 1]
    # one hue per eps from a sequential map (five greys could not be told apart)
    from matplotlib import colormaps
    colors = [colormaps["viridis"](x) for x in np.linspace(0.0, 0.85, max(len(eps), 2))]
    for j, e in enumerate(eps):
        per = np.where(ds.period.values[0, j] > 0, ds.period.values[0, j], np.nan)
        ax.step(s, per, where="mid", color=colors[j % len(colors)], lw=st.LW_THIN,
                label=f"$\\varepsilon={st.eps_value(e)}$")
    # the window's orbit followed in s: stable between its two bifurcations (bars, one
    # height per eps), so overlapping bars of n and n + 1 are coexisting attractors
    for j in range(len(eps)):
        for m, n in enumerate(ds.n.values):
            lo, hi = ds.edge.values[j, m]
            lo = s.min() if not np.isfinite(lo) else lo
            hi = s.max() if not np.isfinite(hi) else hi
            if ds.edge_kind.values[j, m, 0] == -9:
                continue
            y = n * (1.0 + 0.035 * (j - (len(eps) - 1) / 2))
            ax.plot([lo, hi], [y, y], color=colors[j % len(colors)], lw=1.6,
                    solid_capstyle="butt")
    per0 = np.where(ds.period_limit0.values[0] > 0, ds.period_limit0.values[0], np.nan)
    ax.step(s, per0, where="mid", color=st.C_PLUS, lw=st.LW, ls="--",
            label=r"$\varepsilon\to 0$")
    ax.set_yscale("log")
    ax.set_yticks([1, 2, 3, 4, 5, 6, 8, 10])
    ax.set_yticklabels(["1", "2", "3", "4", "5", "6", "8", "10"])
    ax.set_xlabel(S_LABEL)
    ax.set_ylabel("period of the attractor")
    ax.set_xlim(s.min(), s.max())
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower center", ncol=2)  # under (e)
    st.panel_label(ax, "(e) period; bars: orbit\nstable (its bifurcations)")
    ax = axes[1, 2]
    edge, edge0 = ds.edge.values, ds.edge_limit0.values
    for m, n in enumerate(ds.n.values):
        for side, marker in ((0, "o"), (1, "s")):
            d = np.abs(edge[:, m, side] - edge0[m, side])
            ok = np.isfinite(d) & (d > 0)
            ax.loglog(eps[ok], d[ok], marker=marker, ms=3, lw=st.LW_THIN,
                      mfc="none" if side else None,
                      color=[st.C_PLUS, st.C_MINUS, st.C_SLIDE, "black"][m % 4],
                      label=f"$n={n}$: edge $-$ edge$_{{\\varepsilon\\to0}}$" if side == 0 else None)
    ax.loglog(eps, ds.edge_gap.values, color=st.C_AUX, lw=st.LW, ls="--",
              label="max gap, slow-fast vs limit map")  # (a text | prints as l)
    ax.set_xlabel(st.EPS)
    ax.set_ylabel(r"distance of window edges in $s$")
    fig.legend(*ax.get_legend_handles_labels(), loc="outside lower right")  # under (f)
    st.panel_label(ax, "(f) window edges:\nleft \u25cf, right \u25a1")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n_s: int = 19, k: int = 6) -> xr.Dataset:
    """Orbit diagrams of made-up period-n windows; edges converging like eps."""
    s = np.linspace(-0.5, 4.0, n_s)
    eps = np.array([1e-2, 1e-3, 1e-4])
    per = np.where(s < 0, 1, 2 + (np.floor(s) % 3)).astype(np.int32)
    u0 = 0.1 * s[:, None] - 0.2 * (np.arange(k)[None, :] % per[:, None])
    u = np.broadcast_to(u0, (1, eps.size, n_s, k)) + 0.01 * eps[None, :, None, None]
    n = np.array([2, 3])
    edge0 = np.array([[1.0, 1.6], [0.5, 0.8]])
    return xr.Dataset(
        {"u": (("theta", "eps", "s", "k"), u.copy()), "u_limit": (("theta", "eps", "s", "k"), u.copy()),
         "u_limit0": (("theta", "s", "k"), u0[None]),
         "period": (("theta", "eps", "s"), np.broadcast_to(per, (1, eps.size, n_s)).copy()),
         "period_limit0": (("theta", "s"), per[None]),
         "edge": (("eps", "n", "side"), edge0[None] + eps[:, None, None]),
         "edge_limit0": (("n", "side"), edge0), "edge_gap": ("eps", 2 * eps),
         "edge_kind": (("eps", "n", "side"),
                       np.broadcast_to(np.array([-1, 0], dtype=np.int32), (eps.size, 2, 2)).copy())},
        coords={"theta": [-0.5], "eps": eps, "s": s, "k": np.arange(k), "n": n, "side": [0, 1]},
        attrs={"theta": -0.5, "s_max": 4.0})
