"""The report's numbers and table for fig06_sgraph."""
from __future__ import annotations

from ..report import Macros, source, var


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig06_sgraph"
    m.add("rpSixTheta", float(ds.attrs["theta"]), f"{sid}:attrs.theta")
    var(m, "rpSixSlopeZero", ds, sid, "slope_at_zero")
    var(m, "rpSixImageLimit", ds, sid, "image_limit", sig=5)
    m.add("rpSixSFirst", float(ds.s.values[0]), source(sid, "s") + "[0]", 6)
    m.add("rpSixTsMin", float(ds.t_s.values[0]), "fig06_sgraph:t_s[0]", 2)
    m.add("rpSixTsMax", float(ds.t_s.values[-1]), "fig06_sgraph:t_s[-1]", 2)
    m.add("rpSixXiMin", float(ds.xi1.values[-1]), "fig06_sgraph:xi1[-1]", 4)
    return None
