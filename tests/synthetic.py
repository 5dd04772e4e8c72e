"""Small synthetic datasets with the contract's names, for plotting tests.

Crude stand-ins for the real results (fixed-step exact flows, no event
location): right names, shapes and rough geometry, nothing more.
"""
from __future__ import annotations

import numpy as np
import xarray as xr


def fig01(n: int = 201) -> xr.Dataset:
    t = np.linspace(0.0, 2.5, n)
    x1 = np.stack([-1.0 + t, -1.0 + t])
    cross = np.where(t < 1.0, -1.0 + t, 0.5 * (t - 1.0))   # crosses x2 = 0 at t = 1
    slide = np.minimum(-1.0 + t, 0.0)                     # reaches x2 = 0, then slides
    x2 = np.stack([cross, slide])
    mode = np.stack([np.where(t < 1.0, -1, 1), np.where(t < 1.0, -1, 0)]).astype("int8")
    gx, gy = np.meshgrid(np.linspace(-0.8, 1.2, 4), [-0.6, 0.3])
    ax1, ax2 = gx.ravel(), gy.ravel()
    u = np.ones((2, ax1.size))
    v = np.stack([np.where(ax2 < 0, 1.0, 0.5), np.where(ax2 < 0, 1.0, -1.0)])
    return xr.Dataset(
        {"x1": (("case", "t"), x1), "x2": (("case", "t"), x2), "mode": (("case", "t"), mode),
         "hit_x1": ("case", [0.0, 0.0]), "hit_x2": ("case", [0.0, 0.0]),
         "arrow_x1": (("case", "arrow"), np.stack([ax1, ax1])),
         "arrow_x2": (("case", "arrow"), np.stack([ax2, ax2])),
         "arrow_u": (("case", "arrow"), u), "arrow_v": (("case", "arrow"), v)},
        coords={"case": ["crossing", "sliding"], "t": t})


def _simulate(theta, eps, start, t):
    """Fixed-step exact flow of x' = -sign(h), eps y' = x - y (chatters at dt when sliding)."""
    dt = t[1] - t[0]
    x, y = np.empty_like(t), np.empty_like(t)
    x[0], y[0] = start
    for k in range(t.size - 1):
        c = -1.0 if theta * x[k] + (1 - theta) * y[k] >= 0 else 1.0
        x[k + 1] = x[k] + c * dt
        y[k + 1] = x[k + 1] - c * eps + (y[k] - x[k] + c * eps) * np.exp(-dt / eps)
    return x, y


def fig02(n: int = 1501, eps: float = 0.1) -> xr.Dataset:
    thetas = np.array([0.5, -0.5])
    t = np.linspace(0.0, 3.0, n)
    xs, ys, modes = [], [], []
    for th in thetas:
        x, y = _simulate(th, eps, (0.6, 0.3), t)
        h = th * x + (1 - th) * y
        mode = np.where(np.abs(h) < 2 * (t[1] - t[0]), 0, np.sign(h))
        xs.append(x); ys.append(y); modes.append(mode.astype("int8"))
    h = thetas[1] * xs[1] + (1 - thetas[1]) * ys[1]
    up = np.flatnonzero((h[:-1] < 0) & (h[1:] >= 0)) + 1   # f- -> f+ switches
    a, b = up[-2], up[-1]
    return xr.Dataset(
        {"x": (("theta", "t"), np.stack(xs)), "y": (("theta", "t"), np.stack(ys)),
         "mode": (("theta", "t"), np.stack(modes)),
         "period": t[b] - t[a], "x_switch": xs[1][b], "y_switch": ys[1][b],
         "sliding_x_min": -eps * thetas[0], "sliding_x_max": eps * thetas[0],
         "x_cycle": ("cycle", xs[1][a:b + 1]), "y_cycle": ("cycle", ys[1][a:b + 1])},
        coords={"theta": thetas, "t": t}, attrs={"eps": eps, "theta": -0.5})


def fig08(n: int = 60) -> xr.Dataset:
    # Parametrise by s0 (eq:s0def solved for theta), as the paper suggests.
    s = np.linspace(0.02, 6.0, n)
    theta = (1 - s - np.exp(-s)) / (1 - np.exp(-s))
    order = np.argsort(theta)
    return xr.Dataset({"s0": ("theta", s[order]), "s0_root": ("theta", s[order])},
                      coords={"theta": theta[order]})


def fig04(n: int = 81) -> xr.Dataset:
    """A return map with the right shape: smooth slope below 1, a jump (theta<0) or kink above."""
    x2 = np.linspace(0.96, 1.04, n)
    k = np.exp(-0.5)
    P = np.array([np.where(x2 <= 1, 1 + k * (x2 - 1), 0.994 - 0.3 * np.sqrt(np.abs(x2 - 1))),
                  np.where(x2 <= 1, 1 + k * (x2 - 1), 1 - 0.01 * np.tanh(60 * (x2 - 1)))])
    return xr.Dataset(
        {"P": (("theta", "x2"), P), "residual": (("theta", "x2"), np.zeros_like(P)),
         "n_switches": (("theta", "x2"), (P != 1 + k * (x2 - 1)).astype(np.int32)),
         "fixed_point": (("theta", "fixed"), [[1.0], [1.0]])},
        coords={"theta": [-0.5, 0.5], "x2": x2}, attrs={"eps": 0.01, "mu": 1.0})
