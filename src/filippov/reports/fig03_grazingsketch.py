"""The report's numbers and table for fig03_grazingsketch."""
from __future__ import annotations

import math

from ..report import Macros, source, value, var


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig03_grazingsketch"
    mus = [float(v) for v in ds.mu.values]
    m.add("rpThreeOmega", float(ds.attrs["omega"]), f"{sid}:attrs.omega", 6)
    m.add("rpThreeStart", float(ds.attrs["x2_start"]), f"{sid}:attrs.x2_start")
    m.add("rpThreeSettle", float(ds.attrs["settle_tol"]), f"{sid}:attrs.settle_tol")
    for mu, word in zip(mus, ("Below", "At", "Above")):
        m.add(f"rpThreeMu{word}", mu, source(sid, "mu", mu=mu))
        var(m, f"rpThreeFixed{word}", ds, sid, "fixed_x2", sig=6, mu=mu)
        var(m, f"rpThreePeriod{word}", ds, sid, "period", sig=6, mu=mu)
        var(m, f"rpThreeSlideTime{word}", ds, sid, "sliding_time", sig=3, mu=mu)
    mu = mus[2]
    var(m, "rpThreeXhTwo", ds, sid, "x_h", sig=4, mu=mu, component="x2")
    var(m, "rpThreeXlTwo", ds, sid, "x_l", sig=6, mu=mu, component="x2")
    var(m, "rpThreeXlFormulaTwo", ds, sid, "x_l_formula", sig=6, mu=mu, component="x2")
    m.add("rpThreeXlErr", abs(value(ds, "x_l", mu=mu, component="x2")
                              - value(ds, "x_l_formula", mu=mu, component="x2")),
          "derived: |x_l - x_l_formula| at mu above 1", 2)
    m.add("rpThreeSqrtMuBelow", math.sqrt(mus[0]), "derived: sqrt(mu below 1)", 6)
    return None
