"""Trivial line geometry for annotations (no numerics on the data itself)."""
from __future__ import annotations

import numpy as np


def runs(mode):
    """(start, stop, value) of maximal constant stretches of `mode`; each stop
    includes the next sample so consecutive pieces join without a gap."""
    mode = np.asarray(mode)
    if mode.size == 0:
        return []
    cuts = np.flatnonzero(np.diff(mode)) + 1
    starts = np.r_[0, cuts]
    stops = np.r_[cuts, mode.size]
    return [(int(a), int(min(b + 1, mode.size)), int(mode[a])) for a, b in zip(starts, stops)]


def clip_line(m: float, c: float, xlim, ylim):
    """End points of the part of y = m x + c inside the box xlim x ylim, or None."""
    lo, hi = sorted(xlim)
    if m != 0:
        a, b = sorted(((ylim[0] - c) / m, (ylim[1] - c) / m))
        lo, hi = max(lo, a), min(hi, b)
    elif not min(ylim) <= c <= max(ylim):
        return None
    if lo >= hi:
        return None
    return np.array([lo, hi]), m * np.array([lo, hi]) + c


def along(xs, ys, frac: float):
    """Point a fraction `frac` of the way along a segment."""
    return xs[0] + frac * (xs[1] - xs[0]), ys[0] + frac * (ys[1] - ys[0])


def unit_arrows(u, v, xspan: float, yspan: float, length: float):
    """Rescale field vectors to the same on-screen length (a fraction of the
    axes) whatever the axis scales, keeping each direction as seen on screen."""
    a, b = np.asarray(u) / xspan, np.asarray(v) / yspan
    norm = np.hypot(a, b)
    norm = np.where(norm > 0, norm, 1.0)
    return length * a / norm * xspan, length * b / norm * yspan


def arrowhead(ax, x, y, i: int, color, size: float = 7.0) -> None:
    """Direction mark on a sampled curve at sample i (pointing to i+1)."""
    i = int(np.clip(i, 0, len(x) - 2))
    ax.annotate("", xy=(x[i + 1], y[i + 1]), xytext=(x[i], y[i]),
                arrowprops=dict(arrowstyle="-|>", color=color, lw=0, shrinkA=0, shrinkB=0,
                                mutation_scale=size))
