"""fig:pdmthgt0: (a) the numerical P_DM(xi1) for theta > 0 and several eps with the
zero-order curve along the sliding time (corrected, and as printed); (b) zoom at
the grazing point with the linear map eq:p:pdm of slope (theta-1)/theta;
(c) the largest deviation from the zero-order curve against eps, log-log."""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st
from filippov_paper.plotting.fig07_pdm_theta_neg import (eps_colours, eps_label, reference_slope,
                                                           synthetic_pdm_common)

VARS = ["P_DM", "P_zero_order", "P_printed", "P_linear", "P_reduced", "slope_theory",
        "error", "error_core", "error_printed"]


def draw(ds):
    st.require(ds, "fig09_pdm_theta_pos", VARS)
    xi = ds.xi1.values
    eps = ds.eps.values
    theta = float(ds.theta) if "theta" in ds else float(ds.attrs.get("theta", np.nan))
    core = float(ds.attrs.get("core", 5.0))
    cols = eps_colours(eps.size)
    fig = st.new_figure(st.TEXT_WIDTH, 3.2)
    ax, zx, bx = fig.subplots(1, 3, gridspec_kw={"width_ratios": [1.35, 1.0, 1.0]})
    neg, pos = xi < 0, xi >= 0

    for a, window in ((ax, (xi.min(), xi.max())), (zx, (-core, 0.25 * core))):
        sel = neg & (xi >= window[0])
        a.axhline(0, color=st.C_AUX, lw=st.LW_THIN, zorder=0)
        a.axvline(0, color=st.C_AUX, lw=st.LW_THIN, zorder=0)
        a.plot(window, window, color=st.C_AUX, lw=st.LW_THIN, ls="--", zorder=0)
        for k, e in enumerate(eps):
            a.plot(xi[sel], ds.P_DM.values[k][sel], color=cols[k], lw=st.LW_BOLD * 0.8,
                   label=rf"$\varepsilon=${eps_label(e)}")
        a.plot(xi[sel], ds.P_zero_order.values[-1][sel], color="black", lw=st.LW,
               label="corrected zero order")
        a.plot(xi[sel], ds.P_printed.values[-1][sel], color="0.35", lw=st.LW, ls=(0, (4, 2)),
               label=r"printed: $s(\theta,\omega,\xi_1,0)\,\xi_1$")
        a.plot(xi[sel], ds.P_reduced.values[sel], color=st.C_AUX, lw=st.LW, ls=":",
               label=r"reduced model ($\varepsilon=0$)")
        keep = pos & (xi <= window[1])
        a.plot(xi[keep], ds.P_DM.values[-1][keep], color="black", lw=st.LW)
        a.set_xlim(*window)
        a.set_xlabel(r"$\xi_1$")
    zsel = neg & (xi >= -core)
    zx.plot(xi[zsel], ds.P_linear.values[zsel], color=st.C_MINUS, lw=st.LW, ls="-.",
            label=rf"slope $(\theta-1)/\theta={float(ds.slope_theory):g}$")
    top = float(np.nanmax(ds.P_zero_order.values[-1][neg]))
    ax.set_ylim(-0.12 * top, 1.55 * top)
    zx.set_ylim(-0.25 * core, 1.3 * core)
    ax.set_ylabel(r"$P_{\mathrm{DM}}(\xi_1)$")
    st.panel_label(ax, rf"(a) $\theta={theta:g}$, $\mu=1$, $x_1=-1+\varepsilon^2\xi_1$")
    st.panel_label(zx, "(b) near the grazing point")
    # off the curves, below the panels: one legend for (a) and (b) (the same curves;
    # numerical eps in the first column), lower left; (c)'s lower right
    handles, labels = ax.get_legend_handles_labels()
    zh, zl = zx.get_legend_handles_labels()
    fig.legend(handles + zh[-1:], labels + zl[-1:], loc="outside lower left", ncol=2,
               handlelength=2.2)

    err, core_err, errp = (ds[v].values for v in ("error", "error_core", "error_printed"))
    bx.loglog(eps, errp, "^-", ms=3.5, lw=st.LW_THIN, color="0.45",
              label="printed, all $\\xi_1<0$")
    bx.loglog(eps, err, "o-", ms=3.5, lw=st.LW_THIN, color=st.C_PLUS,
              label="corrected, all $\\xi_1<0$")
    bx.loglog(eps, core_err, "s-", ms=3.5, lw=st.LW_THIN, color=st.C_SLIDE,
              label=rf"corrected, $-{core:g}\leq\xi_1<0$")
    reference_slope(bx, eps, core_err[0] * 0.25, 1.0, r"$\varepsilon$", above=False,
                    color="0.2", lw=st.LW_THIN, ls=":")
    bx.set_xlabel(r"$\varepsilon$")
    bx.set_ylabel(r"$\max\,|P_{\mathrm{DM}}-P_{\mathrm{zero\ order}}|$")
    bx.invert_xaxis()
    st.panel_label(bx, "(c) deviation from\nzero order")
    fig.legend(*bx.get_legend_handles_labels(), loc="outside lower right")
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset(n: int = 121, theta: float = 0.5, omega: float = 8 * np.pi) -> xr.Dataset:
    from filippov.analytic import pdm as a

    eps = np.array([1e-2, 1e-3, 1e-4])
    xi = np.unique(np.concatenate([np.linspace(-600, 60, n), np.linspace(-5, 0, 21)]))
    zero = a.pdm_theta_pos(xi, theta, omega)
    P = zero[None, :] * (1 + 10 * eps[:, None])
    d2 = ("eps", "xi1")
    ds = synthetic_pdm_common(xi, eps, P, {
        "P_zero_order": (d2, np.broadcast_to(zero, P.shape).copy()),
        "P_printed": (d2, np.broadcast_to(a.pdm_theta_pos(xi, theta, omega, printed=True),
                                          P.shape).copy()),
        "P_linear": ("xi1", a.pdm_theta_pos_linear(xi, theta)),
        "P_reduced": ("xi1", a.pdm_reduced(xi)), "slope_theory": (theta - 1) / theta,
        "theta": theta, "error": ("eps", np.abs(P - zero).max(axis=1)),
        "error_core": ("eps", 30 * eps), "error_printed": ("eps", 20 + 0 * eps)})
    ds.attrs["core"] = 5.0
    return ds
