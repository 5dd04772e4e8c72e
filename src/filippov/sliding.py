"""Where on the switching manifold sliding attracts (Eq. (9)), found by root finding.

For a curve ``s -> z(s)`` lying in H_s the attracting sliding set is where
``a(s) = dH.F_-`` is positive and ``b(s) = dH.F_+`` negative; its ends are roots
of ``a`` or ``b``, bracketed on a grid and refined with Brent's method.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq

from .system import PiecewiseSystem


def attracting_intervals(system: PiecewiseSystem, curve, s_grid, xtol: float = 1e-15):
    """Intervals ``(s_lo, s_hi)`` of ``s_grid`` where sliding attracts."""
    s_grid = np.asarray(s_grid, dtype=float)
    a, b = system.normal_speeds(curve(s_grid))
    inside = (a > 0) & (b < 0)

    def edge(i):  # boundary between grid points i and i + 1
        fa = lambda s: float(system.normal_speeds(curve(np.array([s])))[0][0])
        fb = lambda s: float(system.normal_speeds(curve(np.array([s])))[1][0])
        lo, hi = s_grid[i], s_grid[i + 1]
        roots = [brentq(f, lo, hi, xtol=xtol, rtol=4 * np.finfo(float).eps)
                 for f, v in ((fa, a), (fb, b)) if np.sign(v[i]) != np.sign(v[i + 1])]
        return min(roots) if inside[i + 1] else max(roots)

    out, start = [], None
    for i in range(s_grid.size):
        if inside[i] and start is None:
            start = s_grid[0] if i == 0 else edge(i - 1)
        if start is not None and (i == s_grid.size - 1 or not inside[i + 1]):
            out.append((start, s_grid[-1] if i == s_grid.size - 1 else edge(i)))
            start = None
    return out
