"""Work-precision diagram: error of the return map against wall time, log-log,
one panel per problem, one line per method swept over its tolerance."""
from __future__ import annotations

import re

import numpy as np
import xarray as xr

from filippov_paper.plotting import style as st

VARS = ["error_map", "wall_time", "status", "reference_check"]
# the project's modes solid, scipy's dashed; markers tell the families apart
LOOK = {"project compiled exact": ("o", "-", "black"),
        "project python exact": ("s", "-", "0.45"),
        "project compiled DOP853": ("d", "-", "#e7298a"),
        "project DOP853": ("D", "-", st.C_PLUS),
        "solve_ivp RK45": ("^", "--", st.C_MINUS),
        "solve_ivp DOP853": ("v", "--", "#7b3294"),
        "solve_ivp Radau": ("P", "--", "#1b9e77"),
        "solve_ivp LSODA": ("X", "--", "#d95f02")}
FLOOR = 1e-16  # an error of exactly zero is drawn here


def draw(ds):
    st.require(ds, "bench_work_precision", VARS)
    n = ds.sizes["problem"]
    ncols = min(n, 2)
    nrows = -(-n // ncols)
    fig = st.new_figure(st.TEXT_WIDTH, 2.4 * nrows)
    axes = np.atleast_1d(fig.subplots(nrows, ncols, squeeze=False).ravel())
    for ax in axes[n:]:
        ax.set_visible(False)
    axes = axes[:n]
    methods = list(dict.fromkeys(str(m) for m in ds.method.values))
    for i, ax in enumerate(axes):
        for fam in methods:
            sel = np.flatnonzero(ds.method.values == fam)
            err = np.maximum(ds.error_map.values[i, sel], FLOOR)
            t = ds.wall_time.values[i, sel]
            ok = np.isfinite(err) & np.isfinite(t)
            marker, ls, color = LOOK.get(fam, (".", ":", "0.3"))
            if ok.any():
                order = np.argsort(t[ok])
                ax.plot(t[ok][order], err[ok][order], marker=marker, ls=ls, color=color,
                        ms=4, lw=1.0, label=fam)
                if "wall_time_q1" in ds and "wall_time_q3" in ds:
                    # the spread of the runs: first to third quartile, a horizontal bar
                    q1 = ds.wall_time_q1.values[i, sel][ok]
                    q3 = ds.wall_time_q3.values[i, sel][ok]
                    ax.errorbar(t[ok], err[ok], xerr=[t[ok] - q1, q3 - t[ok]], fmt="none",
                                ecolor=color, elinewidth=0.7, capsize=1.5)
        check = max(float(ds.reference_check.values[i]), FLOOR)
        ax.axhline(check, color=st.C_AUX, lw=0.8, ls=":", label="reference check")
        ax.set_xscale("log")
        ax.set_yscale("log")
        # the statistic the sweep shows (filippov_paper.benchmarks.timing; older sweeps: median)
        ax.set_xlabel(f"{ds.attrs.get('timing_statistic', 'median')} wall time of one map [s]")
        name = str(ds.problem.values[i])   # the paper's symbols, the value in math (a minus)
        for key, sym in (("theta", r"\theta"), ("eps", r"\varepsilon")):
            name = re.sub(rf"{key}=(\S+)", lambda m, sym=sym: f"${sym}={m.group(1)}$", name)
        st.panel_label(ax, f"({'abcd'[i]}) {name}, {int(ds.n_points.values[i])} points")
    for ax in axes[::ncols]:
        ax.set_ylabel(r"max $|P - P_{\mathrm{ref}}|$")
    # one legend for all panels, below them
    handles = {}
    for ax in axes:
        for h, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, h)
    fig.legend(list(handles.values()), list(handles), loc="outside lower center", ncol=3,
               frameon=False)
    return fig


# ----------------------------------------------------------------------------- test knob
# (filippov_paper.product) a crude stand-in for the real dataset: its names, shapes and
# rough geometry, for the plotting tests; no solver, no event location
def synthetic_dataset() -> xr.Dataset:
    """Two problems, two methods at three tolerances each."""
    method = ["project compiled exact"] * 3 + ["solve_ivp RK45"] * 3
    err = np.array([[1e-12, 1e-11, 1e-10, 1e-3, 1e-5, 1e-7]] * 2)
    wall = np.array([[1e-3, 1.2e-3, 1.5e-3, 0.1, 0.3, 1.0]] * 2)
    return xr.Dataset(
        {"error_map": (("problem", "config"), err), "wall_time": (("problem", "config"), wall),
         "wall_time_q1": (("problem", "config"), 0.9 * wall),
         "wall_time_q3": (("problem", "config"), 1.3 * wall),
         "status": (("problem", "config"), np.full(err.shape, "ok", dtype=object)),
         "reference_check": ("problem", [1e-13, 1e-13]), "n_points": ("problem", [60, 9])},
        coords={"problem": ["fig04 theta=-0.5", "fig11 (a) eps=0.1"],
                "method": ("config", method), "tolerance": ("config", [1e-6, 1e-8, 1e-10] * 2)})
