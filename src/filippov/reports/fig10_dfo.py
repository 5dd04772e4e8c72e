"""The report's numbers and table for fig10_dfo."""
from __future__ import annotations

import numpy as np

from ..report import Macros, absent, scalar_table, var


#: the report does without this scene (its section says "not yet computed")
REPORT_OPTIONAL = True


def report(ds, m: Macros) -> str:
    """Macros for the bifurcation diagram's findings (Hopf and grazing-sliding points,
    multipliers), each when its variable is present, and a table of the scalars."""
    missing = absent(m, "rpHaveTen", ds, "fig10", "results/fig10_dfo.nc")
    if missing:
        return missing
    for name_var, name, sig in (("v_hopf", "rpTenVHopf", 10), ("v_hopf_numeric", "rpTenVHopfNum", 10),
                                ("v_gs", "rpTenVGS", 9), ("v_gs_branch", "rpTenVGSBranch", 9),
                                ("x1_gs", "rpTenXGS", 5), ("period_gs", "rpTenPeriodGS", 5),
                                ("F_c_static", "rpTenStatic", 3)):
        if name_var in ds:
            var(m, name, ds, "fig10_dfo", name_var, sig)
        else:
            m.add(name, None, f"fig10_dfo:{name_var} (missing)",
                  text=r"\emph{(" + name_var + " missing)}")
    if "ss_multiplier" in ds:
        m.add("rpTenSSMultMax", float(np.nanmax(ds.ss_multiplier.values)),
              "derived:max(fig10_dfo:ss_multiplier)", 2)
    if "po_multiplier" in ds:
        m.add("rpTenPOMultMin", float(np.nanmin(ds.po_multiplier.values)),
              "derived:min(fig10_dfo:po_multiplier)", 5)
    return scalar_table(ds)
