"""The report's numbers and table for fig11_dfo_retmaps."""
from __future__ import annotations

from ..report import Macros, absent, scalar_table, var


#: the report does without this scene (its section says "not yet computed")
REPORT_OPTIONAL = True


def report(ds, m: Macros) -> str:
    """Macros for the return maps' findings (chi_-, the sticking interval, the
    saddle-node of each panel), each when present, and a table of the scalars."""
    missing = absent(m, "rpHaveEleven", ds, "fig11", "results/fig11_dfo_retmaps.nc")
    if missing:
        return missing
    for name_var, name in (("chi_minus", "rpElevenChi"), ("chi_minus_literal", "rpElevenChiLit"),
                           ("sticking_a", "rpElevenA"), ("sticking_b", "rpElevenB"),
                           ("sticking_a_literal", "rpElevenALit"),
                           ("sticking_b_literal", "rpElevenBLit")):
        if name_var in ds:
            var(m, name, ds, "fig11_dfo_retmaps", name_var, 3)
    for k, key in ((0, "A"), (1, "B")):
        if "panel" not in ds.dims or ds.sizes["panel"] <= k:
            continue
        for name_var, name, sig in (("eps", "Eps", 3), ("v0_sn", "VSN", 8), ("x1_sn", "XSN", 6),
                                    ("sliding_length_sn", "SlideSN", 3),
                                    ("sliding_time_sn", "SlideTimeSN", 3)):
            if name_var in ds:
                var(m, f"rpEleven{name}{key}", ds, "fig11_dfo_retmaps", name_var, sig, panel=k)
    return scalar_table(ds)
