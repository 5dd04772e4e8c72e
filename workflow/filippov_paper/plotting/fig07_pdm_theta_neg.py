"""fig:pdmthlt0: (a) the numerical P_DM(xi1) for theta < 0 and several eps, with
the first-order expansion for each eps (dashed) and its limit xi1 + s0 (black);
(b) the largest deviation over xi1 < 0 against eps, log-log."""
from __future__ import annotations

import numpy as np
import xarray as xr
from matplotlib import colormaps

from filippov_paper.plotting import style as st

VARS = ["P_DM", "P_first_order", "P_zero_order", "P_printed", "P_flow", "s0",
        "error_first_order", "error_zero_order", "error_printed", "left_limit_error"]


def eps_label(e: float) -> str:
    return f"${st.eps_value(e)}$"


def eps_colours(n: int):
    cmap = colormaps["viridis"]
    return [cmap(v) for v in np.linspace(0.05, 0.85, n)]


def reference_slope(ax, x, y0, p, label, above=True, at=0.5, **kw):
    """A guide line y = y0 (x/x[0])^p over x, labelled at the fraction ``at`` of
    the way (in log x) from the first to the last x."""
    x = np.asarray(x, dtype=float)
    ax.plot(x, y0 * (x / x[0]) ** p, **kw)
    xm = x[0] * (x[-1] / x[0]) ** at
    ax.annotate(label, (xm, y0 * (xm / x[0]) ** p), textcoords="offset points",
                xytext=(2, 4) if above else (-4, -11), fontsize=st.FONT_MIN,
                ha="left" if above else "right", color=kw.get("color", "k"))


def draw(ds):
    st.require(ds, "fig07_pdm_theta_neg", VARS)
    xi = ds.xi1.values
    eps = ds.eps.values
    s0 = float(ds.s0)
    theta = float(ds.theta) if "theta" in ds else float(ds.attrs.get("theta", np.nan))
    cols = eps_colours(eps.size)
    fig = st.new_figure(st.TEXT_WIDTH, 3.3)
    ax, bx = fig.subplots(1, 2, gridspec_kw={"width_ratios": [1.55, 1.0]})

    neg, pos = xi < 0, xi >= 0
    lo, hi = xi.min(), xi.max()
    ylim = (min(-1.2, lo), hi + s0 + 2.2)
    ax.axhline(0, color=st.C_AUX, lw=st.LW_THIN, zorder=0)
    ax.axvline(0, color=st.C_AUX, lw=st.LW_THIN, zorder=0)
    ax.plot([lo, hi], [lo, hi], color=st.C_AUX, lw=st.LW_THIN, ls="--", zorder=0)
    ax.axhline(s0, color="0.35", lw=st.LW_THIN, ls=":", zorder=1,
               label=r"$s_0(\theta)$: printed leading term")
    for k, e in enumerate(eps):
        P = ds.P_DM.values[k]
        ax.plot(xi[neg], P[neg], color=cols[k], lw=st.LW_BOLD * 0.8,
                label=rf"$\varepsilon=${eps_label(e)}")
        ax.plot(xi[neg], ds.P_first_order.values[k][neg], color=cols[k], lw=st.LW_THIN,
                ls=(0, (4, 2)), zorder=3)
    ax.plot(xi[neg], ds.P_zero_order.values[-1][neg], color="black", lw=st.LW,
            label=r"$\xi_1+s_0(\theta)$: corrected leading term")
    ax.plot(xi[pos], ds.P_DM.values[-1][pos], color="black", lw=st.LW)
    ax.plot([0], [0], "o", ms=3.5, color="black", zorder=6)              # P_DM(0) = 0
    ax.plot([0], [s0], "o", ms=3.5, mfc="white", color="black", zorder=6)  # limit from 0-
    # true flow for the smallest eps where it differs (orbit re-crosses H_s)
    Pf, P = ds.P_flow.values[-1], ds.P_DM.values[-1]
    diff = neg & (np.abs(Pf - P) > 1e-6)
    if diff.any():
        sel = np.flatnonzero(diff)[::3]
        ax.plot(xi[sel], Pf[sel], "o", ms=2.2, mfc="none", mew=0.5, color="0.3",
                label=rf"true flow, $\varepsilon=${eps_label(eps[-1])} (crosses "
                      r"$\mathcal{H}_s$ again)")
    ax.plot([], [], color="0.3", lw=st.LW_THIN, ls=(0, (4, 2)),
            label="corrected first order (each $\\varepsilon$)")
    ax.set_xlim(lo, hi)
    ax.set_ylim(*ylim)
    ax.set_xlabel(r"$\xi_1$")
    ax.set_ylabel(r"$P_{\mathrm{DM}}(\xi_1)$")
    st.panel_label(ax, rf"(a) $\theta={theta:g}$, $\mu=1$, $x_1=-1+\varepsilon\xi_1$")
    handles, labels = ax.get_legend_handles_labels()
    is_eps = [lab.startswith(r"$\varepsilon=$") for lab in labels]
    # off the curves: the numerical eps in the empty corner right of xi1 = 0, the line
    # styles below the panels (lower left, under (a))
    ax.legend([h for h, e in zip(handles, is_eps) if e],
              [lab for lab, e in zip(labels, is_eps) if e],
              loc="upper right", handlelength=1.6, labelspacing=0.3, title="numerical")
    fig.legend([h for h, e in zip(handles, is_eps) if not e],
               [lab for lab, e in zip(labels, is_eps) if not e],
               loc="outside lower left", handlelength=2.2)

    e1 = ds.error_first_order.values
    e0 = ds.error_zero_order.values
    ep = ds.error_printed.values
    el = ds.left_limit_error.values
    bx.loglog(eps, ep, "^-", ms=3.5, lw=st.LW_THIN, color="0.45", label="printed first order")
    bx.loglog(eps, e0, "s-", ms=3.5, lw=st.LW_THIN, color=st.C_MINUS, label=r"corrected leading term $\xi_1+s_0$")
    bx.loglog(eps, e1, "o-", ms=3.5, lw=st.LW_THIN, color=st.C_PLUS,
              label="corrected first order")
    bx.loglog(eps, el, "d-", ms=3.5, lw=st.LW_THIN, color=st.C_SLIDE,
              label=r"$|P_{\mathrm{DM}}(0^-)-s_0|$")
    reference_slope(bx, eps, e0[0] * 2.2, 0.5, r"$\varepsilon^{1/2}$", at=0.8, color="0.2",
                    lw=st.LW_THIN, ls=":")
    reference_slope(bx, eps, e1[0] * 0.08, 1.0, r"$\varepsilon$", above=False,
                    color="0.2", lw=st.LW_THIN, ls=":")
    bx.set_xlabel(r"$\varepsilon$")
    bx.set_ylabel(r"$\max_{\xi_1<0}\,|P_{\mathrm{DM}}-P_{\mathrm{asymptotic}}|$")
    bx.invert_xaxis()
    st.panel_label(bx, "(b) deviation from the expansions")
    fig.legend(*bx.get_legend_handles_labels(), loc="outside lower right")  # under (b)
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_pdm_common(xi, eps, P, extra):
    """Variables both discontinuity-map figures read, on dims (eps, xi1)."""
    d2 = ("eps", "xi1")
    data = {"P_DM": (d2, P), "P_flow": (d2, P.copy())}
    data.update(extra)
    return xr.Dataset(data, coords={"eps": eps, "xi1": xi}, attrs={"theta": 0.0})


def synthetic_dataset(n: int = 81, theta: float = -0.5, omega: float = 8 * np.pi) -> xr.Dataset:
    # the corrected expansion plus a made-up O(eps) remainder
    from filippov.analytic import pdm as a
    from filippov.analytic.s0 import s0_lambert

    eps = np.array([1e-2, 1e-3, 1e-4])
    xi = np.linspace(-2.5, 1.5, n)
    e = eps[:, None]
    first = a.pdm_theta_neg(xi, theta, omega, e)
    P = first + np.where(xi < 0, 5 * e * xi ** 2, 0.0)
    P[-1, xi < -2] -= 3.0  # a stretch where the true flow re-crosses H_s
    err = np.abs(P - first).max(axis=1)
    d2 = ("eps", "xi1")
    ds = synthetic_pdm_common(xi, eps, P, {
        "P_first_order": (d2, first), "P_zero_order": (d2, np.broadcast_to(a.pdm_theta_neg(xi, theta, omega, e, order=0),
                                             P.shape).copy()),
        "P_printed": (d2, a.pdm_theta_neg_printed(xi, theta, omega, e)),
        "s0": float(s0_lambert(theta)), "theta": theta,
        "error_first_order": ("eps", err), "error_zero_order": ("eps", 3 * np.sqrt(eps)),
        "error_printed": ("eps", 2.5 + 0 * eps), "left_limit_error": ("eps", 0.2 * eps)})
    ds["P_flow"].values[-1, xi < -2] += 1.0
    return ds
