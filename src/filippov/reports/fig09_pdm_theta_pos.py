"""The report's numbers and table for fig09_pdm_theta_pos."""
from __future__ import annotations

from ..report import Macros, head, num, per_eps_rows, rate_cell, source, tabular, value, var


def table(ds) -> str:
    """Convergence over eps with the core correction, one row per eps."""
    def cells(d):
        return [f"${num(float(d.slope_left), 4)}$", f"${num(float(d.error_printed))}$",
                f"${num(float(d.error))}$", f"${num(float(d.error_core))}$",
                rate_cell(float(d.rate_core), 3), f"${num(float(d.sliding_limit_xi2))}$"]
    return tabular("rrrrrrr", [head(
        r"$\epsilon$", r"$P_\mathrm{DM}(\xi_1^-)$//$/\xi_1^-$", "printed", "corrected",
        "corrected,//core", "rate//(core)", r"$\xi_2$, sliding//limit")], per_eps_rows(ds, cells))


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig09_pdm_theta_pos"
    eps = [float(e) for e in ds.eps.values]
    m.add("rpNineTheta", value(ds, "theta"), source(sid, "theta"))
    var(m, "rpNineSlopeTheory", ds, sid, "slope_theory")
    m.add("rpNineEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpNineEpsMin", eps[-1], f"{sid}:eps[-1]")
    var(m, "rpNineXiLeft", ds, sid, "xi1_left")
    m.add("rpNineCore", float(ds.attrs["core"]), f"{sid}:attrs.core")
    m.add("rpNineXiMin", float(ds.attrs["xi1_min"]), f"{sid}:attrs.xi1_min")
    m.add("rpNineRateCore", float(ds.attrs["rate_core_fit"]), f"{sid}:attrs.rate_core_fit", 3)
    for name_var, name in (("error_printed", "ErrPrinted"), ("error", "Err"),
                      ("error_core", "ErrCore"), ("slope_left", "SlopeLeft")):
        var(m, f"rpNine{name}Max", ds, sid, name_var, sig=4 if name_var == "slope_left" else 3, eps=eps[0])
        var(m, f"rpNine{name}Min", ds, sid, name_var, sig=4 if name_var == "slope_left" else 3, eps=eps[-1])
    var(m, "rpNineSlideLimitMax", ds, sid, "sliding_limit_xi2", eps=eps[0])
    return table(ds)
