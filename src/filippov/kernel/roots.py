"""Root finding: a port of scipy's brentq (the kernel's root finder; the refinement of a
crossing to its far side is the loop's, filippov.loop.refine, asked by the event search)."""
from __future__ import annotations

import numpy as np

from .base import _EPS, _jit
from .segment import _fval

# brentq's relative tolerance: scipy's default (4 eps), the reference driver's
_RTOL = 4.0 * _EPS


@_jit
def _brentq_f(sel, xa, xb, maxiter, mode, o, sc):
    """scipy.optimize.brentq (scipy/optimize/Zeros/brentq.c) of the event function sel
    on the segment o (state.Orbit), to xtol o.xtol and rtol 4 eps (scipy's default);
    returns (root, the function's value there, ok): the value at the root is the one it
    evaluated last (or at xa), which the refinement's far-side probe needs first."""
    xtol, rtol = o.xtol, _RTOL
    xpre, xcur = xa, xb
    xblk, fblk, spre, scur = 0.0, 0.0, 0.0, 0.0
    fpre = _fval(sel, xpre, mode, o, sc)
    fcur = _fval(sel, xcur, mode, o, sc)
    if not np.isfinite(fpre):  # (where it was not finite, with it: loop.refine's CUT)
        return xpre, fpre, False
    if not np.isfinite(fcur):
        return xcur, fcur, False
    if fpre == 0.0:
        return xpre, fpre, True
    if fcur == 0.0:
        return xcur, fcur, True
    if (fpre < 0.0) == (fcur < 0.0):
        return xcur, fcur, False
    for _ in range(maxiter):
        if fpre != 0.0 and fcur != 0.0 and ((fpre < 0.0) != (fcur < 0.0)):
            xblk = xpre
            fblk = fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre = xcur
            xcur = xblk
            xblk = xpre
            fpre = fcur
            fcur = fblk
            fblk = fpre
        delta = (xtol + rtol * abs(xcur)) / 2.0
        sbis = (xblk - xcur) / 2.0
        if fcur == 0.0 or abs(sbis) < delta:
            return xcur, fcur, True
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:
                stry = -fcur * (xcur - xpre) / (fcur - fpre)  # interpolate
            else:  # extrapolate
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2.0 * abs(stry) < min(abs(spre), 3.0 * abs(sbis) - delta):
                spre = scur
                scur = stry
            else:
                spre = sbis
                scur = sbis
        else:
            spre = sbis
            scur = sbis
        xpre = xcur
        fpre = fcur
        if abs(scur) > delta:
            xcur += scur
        else:
            xcur += delta if sbis > 0 else -delta
        fcur = _fval(sel, xcur, mode, o, sc)
        if not np.isfinite(fcur):
            return xcur, fcur, False
    return xcur, fcur, False
