"""The report's numbers and table for fig02_cases."""
from __future__ import annotations

import math

import numpy as np

from ..report import Macros, value, var


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig02_cases"
    eps, th_slide = float(ds.attrs["eps"]), float(ds.attrs["theta_sliding"])
    m.add("rpTwoEps", eps, f"{sid}:attrs.eps")
    m.add("rpTwoThetaSlide", th_slide, f"{sid}:attrs.theta_sliding")
    m.add("rpTwoThetaChatter", float(ds.attrs["theta"]), f"{sid}:attrs.theta")
    m.add("rpTwoEpsTheta", eps * th_slide, "derived: eps*theta_sliding")
    start = [float(v) for v in np.atleast_1d(ds.attrs["start"])]
    m.add("rpTwoStartX", start[0], "fig02_cases:attrs.start[0]")
    m.add("rpTwoStartY", start[1], "fig02_cases:attrs.start[1]")
    var(m, "rpTwoSlideMin", ds, sid, "sliding_x_min", sig=6)
    var(m, "rpTwoSlideMax", ds, sid, "sliding_x_max", sig=6)
    m.add("rpTwoSlideErr", max(abs(value(ds, "sliding_x_min") + eps * th_slide),
                               abs(value(ds, "sliding_x_max") - eps * th_slide)),
          "derived: max |sliding_x_min + eps theta|, |sliding_x_max - eps theta|", 2)
    var(m, "rpTwoXFinal", ds, sid, "x_final", sig=2)
    for name_var, name in (("period", "Period"), ("x_switch", "XSwitch"), ("y_switch", "YSwitch"),
                      ("period_formula", "PeriodFormula"), ("T_half", "THalf"),
                      ("y_switch_printed", "YSwitchPrinted"), ("theta_printed", "ThetaPrinted")):
        var(m, f"rpTwo{name}", ds, sid, name_var, sig=6 if name_var != "theta_printed" else 4)
    m.add("rpTwoPeriodOverEps", value(ds, "period") / eps, "derived: period/eps")
    m.add("rpTwoPeriodErr", abs(value(ds, "period") - value(ds, "period_formula")),
          "derived: |period - period_formula|", 2)
    m.add("rpTwoYSwitchErr", abs(value(ds, "y_switch") - value(ds, "y_switch_printed")),
          "derived: |y_switch - y_switch_printed|", 2)
    T = value(ds, "T_half")
    m.add("rpTwoMinusThetaTanh", -float(ds.attrs["theta"]) * math.tanh(T / 2),
          "derived: -theta tanh(T_half/2)", 4)
    return None
