"""The report's numbers and table for fig05_thetalt0mfs."""
from __future__ import annotations

from ..report import Macros, var


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig05_thetalt0mfs"
    m.add("rpFiveEps", float(ds.attrs["eps"]), f"{sid}:attrs.eps")
    m.add("rpFiveTheta", float(ds.attrs["theta"]), f"{sid}:attrs.theta")
    m.add("rpFiveStart", float(ds.attrs["start_x2"]), f"{sid}:attrs.start_x2", 6)
    m.add("rpFiveSettle", float(ds.attrs["settle"]), f"{sid}:attrs.settle")
    m.add("rpFiveReturn", float(ds.attrs["x2_return"]), f"{sid}:attrs.x2_return", 6)
    var(m, "rpFiveGap", ds, sid, "gap_pg", sig=6)
    var(m, "rpFiveDecay", ds, sid, "decay_rate", sig=8)
    var(m, "rpFiveDecayErr", ds, sid, "decay_rate_rel_error", sig=2)
    var(m, "rpFiveMminusErr", ds, sid, "M_minus_max_error", sig=2)
    var(m, "rpFiveExpansionErr", ds, sid, "M_minus_max_expansion_error", sig=3)
    var(m, "rpFiveSwitchTwoXone", ds, sid, "switch_x1", sig=5, switch=1)
    var(m, "rpFiveSwitchTwoY", ds, sid, "switch_y", sig=5, switch=1)
    var(m, "rpFiveSwitchXtwo", ds, sid, "switch_x2", sig=4, switch=0)
    return None
