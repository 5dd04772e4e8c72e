"""The report's numbers and table for fig04_retmaps."""
from __future__ import annotations

import math

import numpy as np

from ..report import Macros, source, value, var


def _first_above(x, d0):
    d = x - 1.0
    idx = np.where(d >= d0)[0]
    return int(idx[0])


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig04_retmaps"
    eps, mu, omega = (float(ds.attrs[k]) for k in ("eps", "mu", "omega"))
    m.add("rpFourEps", eps, f"{sid}:attrs.eps")
    m.add("rpFourMu", mu, f"{sid}:attrs.mu")
    m.add("rpFourOmegaOverPi", omega / math.pi, "derived: omega/pi", 4)
    m.add("rpFourNPoints", ds.sizes["x2"], f"{sid}:x2 (size)")
    m.add("rpFourXMin", float(ds.attrs["x2_min"]), f"{sid}:attrs.x2_min")
    m.add("rpFourXMax", float(ds.attrs["x2_max"]), f"{sid}:attrs.x2_max")
    var(m, "rpFourSlopeSmooth", ds, sid, "slope_smooth", sig=4)
    x2 = ds.x2.values
    below = np.where((x2 < 1) & (1 - x2 >= 1e-6))[0][-1]
    Pm, Pp = ds.P.sel(theta=-0.5).values, ds.P.sel(theta=0.5).values
    m.add("rpFourSlopeBelow", (1 - Pm[below]) / (1 - x2[below]),
          "derived: (1 - P(x2))/(1 - x2) at theta=-0.5, 1 - x2 ~ 1e-6", 4)
    m.add("rpFourFixed", value(ds, "fixed_point", theta=-0.5, fixed=0),
          source(sid, "fixed_point", theta=-0.5, fixed=0), 6)
    j = _first_above(x2, 0.0 + 1e-300)
    jump = 1.0 - Pm[j]
    m.add("rpFourJump", jump, "derived: 1 - P(theta=-0.5, smallest x2 > 1)", 4)
    m.add("rpFourJumpOverEps", jump / eps, "derived: jump/eps", 3)
    m.add("rpFourClosest", x2[j] - 1.0, "derived: smallest x2 - 1 > 0 on the grid", 2)
    from ..analytic.s0 import s0_lambert
    pred = float(s0_lambert(np.array([-0.5]))[0]) * math.exp(-3 * math.pi * mu / omega)
    m.add("rpFourJumpPredOverEps", pred, "derived: s0(-0.5) exp(-3 pi mu/omega)", 3)
    k = _first_above(x2, 1e-8)
    m.add("rpFourSlopeAbovePos", (Pp[k] - 1.0) / (x2[k] - 1.0),
          "derived: (P - 1)/(x2 - 1) at theta=0.5, first x2 - 1 >= 1e-8", 3)
    m.add("rpFourSlopeAboveProbe", x2[k] - 1.0, "derived: x2 - 1 used for the slope", 2)
    m.add("rpFourSlopeCarried", -1.0 * value(ds, "slope_smooth"),
          "derived: (theta-1)/theta * slope_smooth at theta=0.5", 3)
    # one-sided slope next to the jump (theta < 0): difference quotients near 1+
    d = x2 - 1.0
    i1, i2 = _first_above(x2, 1e-10), _first_above(x2, 1e-6)
    s1 = abs((Pm[i1 + 1] - Pm[i1]) / (x2[i1 + 1] - x2[i1]))
    s2 = abs((Pm[i2 + 1] - Pm[i2]) / (x2[i2 + 1] - x2[i2]))
    m.add("rpFourNegSlopeNear", s1, "derived: |dP/dx2| at theta=-0.5, x2 - 1 ~ 1e-10", 2)
    m.add("rpFourNegSlopeFar", s2, "derived: |dP/dx2| at theta=-0.5, x2 - 1 ~ 1e-6", 2)
    m.add("rpFourNegProbeNear", d[i1], "derived: x2 - 1 for rpFourNegSlopeNear", 2)
    m.add("rpFourNegProbeFar", d[i2], "derived: x2 - 1 for rpFourNegSlopeFar", 2)
    res = ds.residual.sel(theta=-0.5).values[(x2 - 1) > 1e-3]
    m.add("rpFourResMin", float(res.min()), "derived: min residual, theta=-0.5, x2 > 1.001", 2)
    m.add("rpFourResMax", float(res.max()), "derived: max residual, theta=-0.5, x2 > 1.001", 2)
    for th, word in ((-0.5, "Neg"), (0.5, "Pos")):
        var(m, f"rpFourSigma{word}", ds, sid, "sigma_minus", sig=3, theta=th)
    return None
