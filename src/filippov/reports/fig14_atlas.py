"""The report's numbers for fig14_atlas (no table)."""
from __future__ import annotations

import numpy as np

from ..report import Macros, source, value


def report(ds, m: Macros) -> str | None:
    sid = "fig14_atlas"
    th, s = ds.theta.values, ds.s.values
    kind, lim = ds.attractor_type.values[:, 0, :], ds.attractor_type_limit.values[:, 0, :]
    m.add("rpFourteenEps", float(ds.eps.values[0]), f"{sid}:eps[0]")
    m.add("rpFourteenNTheta", th.size, f"{sid}:theta (size)")
    m.add("rpFourteenNMu", s.size, f"{sid}:s (size)")
    m.add("rpFourteenThetaCrit", value(ds, "theta_critical"), source(sid, "theta_critical"), 3)
    above = s > 0
    pos = th > 0
    chaotic = np.array([np.any(kind[i, above] == 0) for i in range(th.size)])
    one = np.array([np.all(kind[i, above] == 1) for i in range(th.size)])
    m.add("rpFourteenChaosThetaMax", float(th[pos & chaotic].max()),
          "derived: largest theta > 0 with a chaotic point above grazing", 3)
    m.add("rpFourteenPeriodOneThetaMin", float(th[pos & one].min()),
          "derived: smallest theta > 0 with period one everywhere above grazing", 3)
    m.add("rpFourteenBelowAllOne", None, "derived: period one at every s < 0",
          text=r"\text{every}" if np.all(kind[:, s < 0] == 1) else r"\text{\emph{not} every}")
    m.add("rpFourteenAgree", 100.0 * float(np.mean(kind == lim)),
          "derived: percent of points where slow-fast and limit-map types agree", 3)
    neg = th < 0
    m.add("rpFourteenNegChaos", float(np.sum(kind[neg][:, above] == 0)),
          "derived: chaotic points at theta < 0", 1)
    return None
