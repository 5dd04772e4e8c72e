"""The report's numbers and table for fig13_small_scale_chaos."""
from __future__ import annotations

import numpy as np

from ..report import Macros, eps_tex, head, num, source, tabular, value

_WORD = {0.7: "Seven", 0.5: "Half", 0.4: "Four", 0.2: "Two", 0.1: "One"}


def _near(s, ds) -> np.ndarray:
    """The uniform grid's part above grazing: 0 < s <= s_max."""
    return (s > 0) & (s <= float(ds.attrs["s_max"]) + 1e-12)


def table(ds) -> str:
    """Per theta: the largest Lyapunov exponent on 0 < s <= s_max at each eps, and its
    median distance to the limit map's at each eps."""
    s = ds.s.values
    near = _near(s, ds)
    eps = [float(e) for e in ds.eps.values]
    rows = []
    for i, t in enumerate(ds.theta.values):
        ly = ds.lyapunov.values[i][:, near]
        gap = np.abs(ly - ds.lyapunov_limit.values[i][:, near])
        cells = [f"${float(t):g}$", f"${num(float(ds.slope_pdm.values[i]), 3)}$"]
        cells += [f"${num(float(np.max(r)), 2)}$" for r in ly]
        cells += [f"${num(float(np.median(g)), 1)}$" for g in gap]
        rows.append(" & ".join(cells) + r" \\")
    e_head = [f"${eps_tex(e)}$" for e in eps]
    top = " & ".join(["", "", rf"\multicolumn{{{len(eps)}}}{{c}}{{largest exponent}}",
                      rf"\multicolumn{{{len(eps)}}}{{c}}{{gap to the limit map}}"]) + r" \\"
    return tabular("rr" + "r" * 2 * len(eps),
                   [top, head(r"$\theta$", r"$s(\theta,0,0)$", *e_head, *e_head)], rows)


def report(ds, m: Macros) -> str | None:
    sid = "fig13_small_scale_chaos"
    eps = [float(e) for e in ds.eps.values]
    s = ds.s.values
    near = _near(s, ds)
    m.add("rpThirteenEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpThirteenEpsMin", eps[-1], f"{sid}:eps[-1]")
    m.add("rpThirteenSMin", float(ds.attrs["s_min"]), f"{sid}:attrs.s_min")
    m.add("rpThirteenSMax", float(ds.attrs["s_max"]), f"{sid}:attrs.s_max")
    m.add("rpThirteenSGeoMax", float(ds.attrs["s_geo_max"]), f"{sid}:attrs.s_geo_max")
    m.add("rpThirteenFitEpsMax", float(ds.attrs["fit_eps_max"]), f"{sid}:attrs.fit_eps_max", 1)
    lam = value(ds, "multiplier")
    m.add("rpThirteenMultiplier", lam, source(sid, "multiplier"), 4)
    m.add("rpThirteenThetaCrit", lam / (1.0 + lam), "derived: lambda/(1 + lambda), where "
          "lambda s(theta,0,0) = -1", 3)
    j = len(eps) - 1
    for i, t in enumerate(ds.theta.values):
        w = _WORD.get(round(float(t), 6))
        if not w:
            continue
        m.add(f"rpThirteenTheta{w}", float(t), source(sid, "theta", theta=float(t)))
        m.add(f"rpThirteenSlope{w}", float(ds.slope_pdm.values[i]),
              source(sid, "slope_pdm", theta=float(t)), 3)
        m.add(f"rpThirteenSlopeReturn{w}", float(ds.slope_return.values[i]),
              source(sid, "slope_return", theta=float(t)), 3)
        ly = ds.lyapunov.values[i][:, near]
        small = np.array(eps) <= float(ds.attrs["fit_eps_max"])
        m.add(f"rpThirteenLyapMax{w}", float(np.max(ly[small])),
              "derived: max lyapunov over eps <= fit_eps_max and 0 < s <= s_max", 2)
        m.add(f"rpThirteenLyapMaxAll{w}", float(np.max(ly)),
              "derived: max lyapunov over all eps and 0 < s <= s_max", 2)
        m.add(f"rpThirteenLyapMin{w}", float(np.min(ly)),
              "derived: min lyapunov over all eps and 0 < s <= s_max", 2)
        per = ds.period.values[i, j]
        chaotic = np.flatnonzero((s > 0) & (ds.lyapunov.values[i, j] > 0))
        if chaotic.size:
            m.add(f"rpThirteenChaosEnd{w}", float(s[chaotic[-1]]),
                  "derived: largest s with a positive exponent at the smallest eps", 3)
        k = ds.width_exponent.values[i][near]
        if np.isfinite(k).any():
            m.add(f"rpThirteenK{w}", float(np.nanmedian(k)),
                  "derived: median width_exponent over 0 < s <= s_max", 3)
            m.add(f"rpThirteenKMax{w}", float(np.nanmax(np.abs(k - 2.0))),
                  "derived: max |width_exponent - 2| over 0 < s <= s_max", 2)
        m.add(f"rpThirteenPeriodOne{w}", float(np.all(per[near] == 1)),
              "derived: 1 if period == 1 on 0 < s <= s_max at the smallest eps", 1)
    return table(ds)
