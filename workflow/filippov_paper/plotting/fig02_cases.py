"""fig:cases: eq:peqslow/eq:peqfast near the origin. (a) theta>0: sliding into the
pseudo-equilibrium; (b) theta<0: small chatter orbit. Both panels are zoomed to
a few eps (the dataset holds the whole transient from the start point)."""
from __future__ import annotations

import math

import numpy as np
import xarray as xr
from matplotlib.ticker import FuncFormatter, MultipleLocator

from filippov_paper.plotting import style as st
from filippov_paper.plotting.lines import along, arrowhead, clip_line, runs

VARS = ["x", "y", "mode", "period", "x_switch", "y_switch", "sliding_x_min",
        "sliding_x_max", "x_cycle", "y_cycle"]
COLOUR = {1: st.C_PLUS, -1: st.C_MINUS, 0: st.C_SLIDE}


def _half_width(ds, eps: float) -> float:
    """Window half-width: 3 eps, widened if the chatter orbit or sliding segment needs it."""
    extent = [np.abs(ds.x_cycle.values).max(), np.abs(ds.y_cycle.values).max(),
              abs(float(ds.sliding_x_min)), abs(float(ds.sliding_x_max))]
    return max(3.0 * eps, 1.25 * max(extent))


def _eps_ticks(ax, eps: float, half: float) -> None:
    """Ticks at multiples of eps, labelled in the paper's notation."""
    step = eps * max(1, math.ceil(half / eps / 3))

    def label(v, _pos):
        k = round(v / eps)
        return "0" if k == 0 else {1: r"$\varepsilon$", -1: r"$-\varepsilon$"}.get(k, rf"${k}\varepsilon$")

    for axis in (ax.xaxis, ax.yaxis):
        axis.set_major_locator(MultipleLocator(step))
        axis.set_major_formatter(FuncFormatter(label))


def _lines(ax, theta: float, eps: float, lim) -> None:
    """M0, M+, M- (invariant lines, grey) and H_s (black), each labelled on itself."""
    specs = [(1.0, 0.0, st.M_0, "-", 0.88), (1.0, eps, st.M_PLUS, "--", 0.88),
             (1.0, -eps, st.M_MINUS, "--", 0.88)]
    for m, c, name, ls, frac in specs:
        seg = clip_line(m, c, lim, lim)
        if seg is not None:
            ax.plot(*seg, color=st.C_AUX, lw=st.LW_THIN, ls=ls)
            ax.text(*along(*seg, frac), name, ha="center", va="center", color="0.3",
                    bbox=dict(fc="white", ec="none", pad=0.3))
    seg = clip_line(-theta / (1.0 - theta), 0.0, lim, lim)  # H_s: theta x + (1-theta) y = 0
    ax.plot(*seg, color="k", lw=st.LW)
    ax.text(*along(*seg, 0.12), st.H_S, ha="center", va="center",
            bbox=dict(fc="white", ec="none", pad=0.3))


def _trajectory(ax, x, y, mode, lim) -> None:
    for a, b, m in runs(mode):
        ax.plot(x[a:b], y[a:b], color=COLOUR.get(m, "k"), lw=st.LW_THIN)
    inside = np.flatnonzero((np.abs(x) < 0.9 * lim[1]) & (np.abs(y) < 0.9 * lim[1]))
    if inside.size:  # show from where the transient enters the window
        i = inside[0]
        arrowhead(ax, x, y, i, COLOUR.get(int(mode[i]), "k"))


def _panel(ax, d, theta: float, eps: float, half: float) -> None:
    lim = (-half, half)
    ax.set_xlim(lim)
    ax.set_ylim(lim)
    ax.set_aspect("equal")
    _lines(ax, theta, eps, lim)
    _trajectory(ax, d.x.values, d.y.values, d["mode"].values, lim)
    _eps_ticks(ax, eps, half)
    ax.set_xlabel(st.X)
    ax.set_ylabel(st.Y)


def draw(ds):
    st.require(ds, "fig02_cases", VARS)
    eps = float(ds.attrs["eps"])
    thetas = ds.theta.values
    pos, neg = float(thetas[thetas > 0][0]), float(thetas[thetas < 0][0])
    half = _half_width(ds, eps)
    fig = st.new_figure(st.TEXT_WIDTH, 2.7)
    ax_a, ax_b = fig.subplots(1, 2)

    # (a) theta > 0: the attracting sliding segment |x| < eps theta on H_s.
    _panel(ax_a, ds.sel(theta=pos), pos, eps, half)
    slope = -pos / (1.0 - pos)
    xs = np.array([float(ds.sliding_x_min), float(ds.sliding_x_max)])
    ax_a.plot(xs, slope * xs, color=st.C_SLIDE, lw=4, alpha=0.45, solid_capstyle="butt", zorder=1)
    ax_a.plot([0.0], [0.0], "o", color="k", ms=3.5, zorder=5)
    ax_a.annotate("sliding", (xs[1], slope * xs[1]), xytext=(6, 4), textcoords="offset points",
                  color=st.C_SLIDE, ha="left", va="bottom")
    st.panel_label(ax_a, rf"(a) $\theta={pos:g}$, $\varepsilon={eps:g}$")

    # (b) theta < 0: one period of the chatter orbit, bold, and its f- -> f+ switch.
    _panel(ax_b, ds.sel(theta=neg), neg, eps, half)
    ax_b.plot(ds.x_cycle.values, ds.y_cycle.values, color="k", lw=st.LW_BOLD, zorder=4)
    xw, yw = float(ds.x_switch), float(ds.y_switch)
    ax_b.plot([xw], [yw], "o", color="k", mfc="white", ms=4, zorder=6)
    # Label below-right, clear of the orbit (the switch point is its right end).
    ax_b.annotate(r"$(x_\mathrm{switch}, y_\mathrm{switch})$", (xw, yw), xytext=(22, -34),
                  textcoords="offset points", ha="center", va="top",
                  bbox=dict(fc="white", ec="none", pad=0.3),
                  arrowprops=dict(arrowstyle="-", lw=0.5, color="k", shrinkA=0, shrinkB=3))
    st.panel_label(ax_b, rf"(b) $\theta={neg:g}$, period $={float(ds.period) / eps:.3g}\,\varepsilon$")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def _simulate(theta, eps, start, t):
    """Fixed-step exact flow of x' = -sign(h), eps y' = x - y (chatters at dt when sliding)."""
    dt = t[1] - t[0]
    x, y = np.empty_like(t), np.empty_like(t)
    x[0], y[0] = start
    for k in range(t.size - 1):
        c = -1.0 if theta * x[k] + (1 - theta) * y[k] >= 0 else 1.0
        x[k + 1] = x[k] + c * dt
        y[k + 1] = x[k + 1] - c * eps + (y[k] - x[k] + c * eps) * np.exp(-dt / eps)
    return x, y


def synthetic_dataset(n: int = 1501, eps: float = 0.1) -> xr.Dataset:
    thetas = np.array([0.5, -0.5])
    t = np.linspace(0.0, 3.0, n)
    xs, ys, modes = [], [], []
    for th in thetas:
        x, y = _simulate(th, eps, (0.6, 0.3), t)
        h = th * x + (1 - th) * y
        mode = np.where(np.abs(h) < 2 * (t[1] - t[0]), 0, np.sign(h))
        xs.append(x); ys.append(y); modes.append(mode.astype("int8"))
    h = thetas[1] * xs[1] + (1 - thetas[1]) * ys[1]
    up = np.flatnonzero((h[:-1] < 0) & (h[1:] >= 0)) + 1   # f- -> f+ switches
    a, b = up[-2], up[-1]
    return xr.Dataset(
        {"x": (("theta", "t"), np.stack(xs)), "y": (("theta", "t"), np.stack(ys)),
         "mode": (("theta", "t"), np.stack(modes)),
         "period": t[b] - t[a], "x_switch": xs[1][b], "y_switch": ys[1][b],
         "sliding_x_min": -eps * thetas[0], "sliding_x_max": eps * thetas[0],
         "x_cycle": ("cycle", xs[1][a:b + 1]), "y_cycle": ("cycle", ys[1][a:b + 1])},
        coords={"theta": thetas, "t": t}, attrs={"eps": eps, "theta": -0.5})
