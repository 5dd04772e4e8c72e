"""The report's numbers and table for fig08_s0theta."""
from __future__ import annotations

import numpy as np

from ..report import Macros


def report(ds, m: Macros) -> str | None:
    """The report's macros from this scene's dataset; returns its table (None: none)."""
    sid = "fig08_s0theta"
    th = ds.theta.values
    m.add("rpEightThetaMin", float(th[0]), f"{sid}:theta[0]")
    m.add("rpEightThetaMax", float(th[-1]), f"{sid}:theta[-1]")
    m.add("rpEightN", th.size, f"{sid}:theta (size)")
    m.add("rpEightLambertRoot", float(np.max(np.abs(ds.s0.values - ds.s0_root.values))),
          "derived: max |s0 - s0_root|", 2)
    m.add("rpEightResidual", float(np.max(np.abs(ds.residual.values))), "derived: max |residual|", 2)
    m.add("rpEightMargin", float(np.min(ds.s0.values + th)), "derived: min (s0 + theta) > 0", 3)
    m.add("rpEightSmallRatio", float(ds.s0.values[-1] / (-2 * th[-1] / (1 - th[-1]))),
          "derived: s0 / (-2 theta/(1-theta)) at theta[-1]", 5)
    return None
