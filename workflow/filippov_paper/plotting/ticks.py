"""Tick steps that no machine's libm can flip.

matplotlib's MaxNLocator (AutoLocator) picks the smallest "nice" step (1, 2, 2.5, 5, 10
times a power of ten) at least as large as range / nbins. The power of ten comes from
``matplotlib.ticker.scale_range`` as ``10 ** floor(log10(range / nbins))``: libm's pow
and log10, whose last bits differ between machines. When a range sits on an edge
(fig07's xi1 in [-2.5, 1.5] in 8 bins: 4 / 8 = 0.5 exactly; fig09's [-5, 1.25] with a
tick on its limit), one ulp of that power decides the step: under `make cross-cpu`'s
emulated libm fig07's step flipped from 0.5 to 1 and its image failed the check.

:func:`scale_range` returns the same powers of ten exactly rounded on every machine
(the exponent from log10 is checked against correctly rounded decimal literals), so the
rest of the locator is IEEE arithmetic that every machine does alike. Where libm gets
the power right (glibc here), the ticks are matplotlib's to the bit:
tests/test_tick_edges.py draws every built figure both ways.
"""
from __future__ import annotations

import contextlib
import math

from matplotlib import ticker


def power_of_ten(x: float) -> float:
    """10 ** floor(log10(x)) for x > 0, exactly rounded: log10 only proposes the
    exponent, the comparison with the decimal literal 1eK decides it."""
    e = math.floor(math.log10(x))
    if float(f"1e{e + 1}") <= x:
        e += 1
    elif float(f"1e{e}") > x:
        e -= 1
    return float(f"1e{e}")


def scale_range(vmin, vmax, n=1, threshold=100):
    """``matplotlib.ticker.scale_range``'s contract (scale, offset) with exact powers."""
    dv = abs(vmax - vmin)  # > 0: the locator makes the range nonsingular first
    meanv = (vmax + vmin) / 2
    offset = 0 if abs(meanv) / dv < threshold else \
        math.copysign(power_of_ten(abs(meanv)), meanv)
    return power_of_ten(dv / n), offset


@contextlib.contextmanager
def exact_scale():
    """Every MaxNLocator (AutoLocator included) uses :func:`scale_range` inside."""
    plain = ticker.scale_range
    ticker.scale_range = scale_range
    try:
        yield
    finally:
        ticker.scale_range = plain
