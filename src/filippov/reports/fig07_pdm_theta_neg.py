"""The report's numbers and table for fig07_pdm_theta_neg."""
from __future__ import annotations

from ..report import Macros, head, num, per_eps_rows, rate_cell, source, tabular, value, var


def table(ds) -> str:
    """Convergence over eps, one row per eps."""
    def cells(d):
        return [f"${num(float(d.P_left), 5)}$", f"${num(float(d.left_limit_error), 2)}$",
                f"${num(float(d.error_printed))}$", f"${num(float(d.error_zero_order))}$",
                f"${num(float(d.error_first_order))}$", rate_cell(float(d.rate_first_order), 2)]
    return tabular("rrrrrrr", [head(
        r"$\epsilon$", r"$P_\mathrm{DM}(0^-)$", r"$|P_\mathrm{DM}(0^-)$//$-s_0|$", "printed",
        r"$\xi_1+s_0$", "corrected//1st order", "rate")], per_eps_rows(ds, cells))


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig07_pdm_theta_neg"
    eps = [float(e) for e in ds.eps.values]
    m.add("rpSevenTheta", value(ds, "theta"), source(sid, "theta"))
    var(m, "rpSevenSzero", ds, sid, "s0", sig=6)
    m.add("rpSevenXiMin", float(ds.attrs["xi1_min"]), f"{sid}:attrs.xi1_min")
    m.add("rpSevenXiMinAbs", abs(float(ds.attrs["xi1_min"])), "derived: |xi1_min|")
    m.add("rpSevenEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpSevenEpsMin", eps[-1], f"{sid}:eps[-1]")
    m.add("rpSevenRateFirst", float(ds.attrs["rate_first_order_fit"]),
          f"{sid}:attrs.rate_first_order_fit", 2)
    m.add("rpSevenRateZero", float(ds.attrs["rate_zero_order_fit"]),
          f"{sid}:attrs.rate_zero_order_fit", 2)
    for name_var, name in (("error_printed", "ErrPrinted"), ("error_first_order", "ErrFirst"),
                      ("error_zero_order", "ErrZero"), ("left_limit_error", "LeftErr"),
                      ("jump_x1", "Jump")):
        var(m, f"rpSeven{name}Max", ds, sid, name_var, eps=eps[0])
        var(m, f"rpSeven{name}Min", ds, sid, name_var, eps=eps[-1])
    m.add("rpSevenIdentityErr", float(ds.identity_error_x1.max()),
          "derived: max identity_error_x1 over eps", 2)
    return table(ds)
