"""The report's numbers and table for fig12_period_adding (the period-adding cascade)."""
from __future__ import annotations

import numpy as np

from ..report import Macros, eps_tex, head, num, source, tabular, value

_WORD = {2: "Two", 3: "Three", 4: "Four", 5: "Five", 6: "Six"}


def _edge_cell(pair) -> str:
    return " & ".join("--" if not np.isfinite(v) else f"${num(float(v), 3)}$" for v in pair)


def table(ds) -> str:
    """Window edges in s per eps (slow-fast), the eps -> 0 limit map and the fits
    (left edges: A of A + B eps; right edges: A of A + B sqrt(eps))."""
    ns = [int(n) for n in ds.n.values]
    rows = []
    for j, e in enumerate(ds.eps.values):
        rows.append(" & ".join([f"${eps_tex(float(e))}$",
                                *(_edge_cell(ds.edge.values[j, m]) for m in range(len(ns)))])
                    + r" \\")
    rows.append(r"\midrule")
    rows.append(" & ".join([r"$\to 0$", *(_edge_cell(ds.edge_limit0.values[m])
                                          for m in range(len(ns)))]) + r" \\")
    fit = [(ds.fit_lin_A.values[m, 0], ds.fit_sqrt_A.values[m, 1]) for m in range(len(ns))]
    rows.append(" & ".join(["fit", *(_edge_cell(f) for f in fit)]) + r" \\")
    top = " & ".join(["", *(rf"\multicolumn{{2}}{{c}}{{$n={n}$}}" for n in ns)]) + r" \\"
    return tabular("r" + "rr" * len(ns), [top, head(r"$\epsilon$", *(["left", "right"] * len(ns)))],
                   rows)


def report(ds, m: Macros) -> str | None:
    sid = "fig12_period_adding"
    eps = [float(e) for e in ds.eps.values]
    theta = float(ds.theta.values[0])
    m.add("rpTwelveTheta", theta, source(sid, "theta", theta=theta))
    m.add("rpTwelveEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpTwelveEpsMin", eps[-1], f"{sid}:eps[-1]")
    m.add("rpTwelveNEps", len(eps), f"{sid}:eps (size)")
    m.add("rpTwelveSMin", float(ds.attrs["s_min"]), f"{sid}:attrs.s_min")
    m.add("rpTwelveSMax", float(ds.attrs["s_max"]), f"{sid}:attrs.s_max")
    m.add("rpTwelveNMu", ds.sizes["s"], f"{sid}:s (size)")
    m.add("rpTwelveNTransient", float(ds.attrs["n_transient"]), f"{sid}:attrs.n_transient")
    m.add("rpTwelveNKeep", float(ds.attrs["n_keep"]), f"{sid}:attrs.n_keep")
    m.add("rpTwelveEdgeTol", float(ds.attrs["edge_tol"]), f"{sid}:attrs.edge_tol", 1)
    m.add("rpTwelveFitEpsMax", float(ds.attrs["fit_eps_max"]), f"{sid}:attrs.fit_eps_max", 1)
    m.add("rpTwelveMultiplier", value(ds, "multiplier"), source(sid, "multiplier"), 4)
    # below grazing the attractor is the cycle's point, u = (sqrt(mu) - 1)/eps
    s = ds.s.values
    below = s < 0
    per = ds.period.values[0]
    m.add("rpTwelveBelowEvery", None, "derived: period == 1 for every s < 0 and eps",
          text=r"\text{every}" if np.all(per[:, below] == 1) else r"\text{\emph{not} every}")
    onset = [float(s[np.flatnonzero((s > 0) & (per[j] != 1))[0]]) for j in range(len(eps))]
    m.add("rpTwelveOnsetMax", max(onset), "derived: largest first s > 0 with period != 1", 2)
    lin_l = float(np.nanmax(ds.fit_lin_rms.values[:, 0]))
    sq_l = float(np.nanmin(ds.fit_sqrt_rms.values[:, 0]))
    lin_r = float(np.nanmin(ds.fit_lin_rms.values[:, 1]))
    sq_r = float(np.nanmax(ds.fit_sqrt_rms.values[:, 1]))
    m.add("rpTwelveLeftLinRms", lin_l, "derived: max fit_lin_rms over n, left edges", 2)
    m.add("rpTwelveLeftSqrtRms", sq_l, "derived: min fit_sqrt_rms over n, left edges", 2)
    m.add("rpTwelveRightLinRms", lin_r, "derived: min fit_lin_rms over n, right edges", 2)
    m.add("rpTwelveRightSqrtRms", sq_r, "derived: max fit_sqrt_rms over n, right edges", 2)
    e0 = ds.edge_limit0.values
    m.add("rpTwelveLeftAErr", float(np.nanmax(np.abs(ds.fit_lin_A.values[:, 0] - e0[:, 0]))),
          "derived: max |fit_lin_A - edge_limit0|, left edges", 2)
    m.add("rpTwelveRightAErr", float(np.nanmax(np.abs(ds.fit_sqrt_A.values[:, 1] - e0[:, 1]))),
          "derived: max |fit_sqrt_A - edge_limit0|, right edges", 2)
    m.add("rpTwelveRightBMax", float(np.nanmax(ds.fit_sqrt_B.values[:, 1])),
          "derived: max fit_sqrt_B, right edges", 3)
    m.add("rpTwelveRightBMin", float(np.nanmin(ds.fit_sqrt_B.values[:, 1])),
          "derived: min fit_sqrt_B, right edges", 3)
    m.add("rpTwelveGapFirst", float(ds.edge_gap.values[0]), source(sid, "edge_gap", eps=eps[0]), 2)
    m.add("rpTwelveGapLast", float(ds.edge_gap.values[-1]), source(sid, "edge_gap", eps=eps[-1]), 2)
    g = ds.edge_gap.values
    ok = np.isfinite(g) & (np.array(eps) <= float(ds.attrs["fit_eps_max"]))
    rate = np.polyfit(np.log(np.array(eps)[ok]), np.log(g[ok]), 1)[0]
    m.add("rpTwelveGapRate", float(rate), "derived: slope of log edge_gap vs log eps, "
          "eps <= fit_eps_max", 2)
    for k, n in enumerate(ds.n.values):
        w = _WORD.get(int(n))
        if w:
            m.add(f"rpTwelveLeftZero{w}", float(e0[k, 0]), source(sid, "edge_limit0", n=int(n), side=0), 4)
            m.add(f"rpTwelveRightZero{w}", float(e0[k, 1]), source(sid, "edge_limit0", n=int(n), side=1), 4)
    return table(ds)
