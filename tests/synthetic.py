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


def fig05(n: int = 400, eps: float = 0.01, theta: float = -0.5) -> xr.Dataset:
    """Circle arcs near p_g, a straight E_- leg and a crude exp(-t/eps) relaxation."""
    omega = 8 * np.pi
    phi = np.linspace(0.0, 2 * np.pi, n)
    ox1, ox2 = -np.cos(phi), -np.sin(phi)            # unit circle through p_g at phi = 0
    t = np.linspace(0.0, 0.3, n)
    r = np.where(t < 0.1, 1.004, 0.95)
    ang = np.pi - 0.1 + omega * (t - 0.1) * (t > 0.1)
    x1, x2 = r * np.cos(ang), r * np.sin(ang)
    leg = (t > 0.05) & (t <= 0.1)                     # E_-: x1 increases, x2 fixed
    x1 = np.where(leg, -1.0 + (t - 0.05), x1)
    x2 = np.where(leg, 0.1, x2)
    y = x1 - 3 * eps * np.where(t > 0.05, np.exp(-np.clip(t - 0.1, 0, None) / eps), 0.0)
    mode = np.where(leg, -1, 1).astype("int8")
    g1, g2 = np.linspace(-1.04, -0.9, 8), np.linspace(-0.4, 0.3, 9)
    X1, X2 = np.meshgrid(g1, g2, indexing="ij")
    ym = X1 + eps * (X1 - omega * X2 - (X1 ** 2 + X2 ** 2) * X1 - 1.0)
    return xr.Dataset(
        {"x1": ("t", x1), "x2": ("t", x2), "y": ("t", y), "mode": ("t", mode),
         "orbit_x1": ("t_orbit", ox1), "orbit_x2": ("t_orbit", ox2),
         "orbit_y": ("t_orbit", ox1),
         "switch_t": ("switch", [0.05, 0.1]), "switch_x1": ("switch", [-1.0, -0.95]),
         "switch_x2": ("switch", [0.1, 0.1]), "switch_y": ("switch", [-1.0, -0.98]),
         "y_M_plus": (("x1_grid", "x2_grid"), X1), "y_M_minus": (("x1_grid", "x2_grid"), ym),
         "y_H_s": (("x1_grid", "x2_grid"), (-1.0 - theta * X1) / (1.0 - theta))},
        coords={"t": t, "x1_grid": g1, "x2_grid": g2},
        attrs={"eps": eps, "theta": theta, "mu": 1.0, "omega": omega})


def fig03(n: int = 300, omega: float = 8 * np.pi) -> xr.Dataset:
    """Circles of radius sqrt(mu), clipped at x1 = -1 (a crude stand-in for sliding)."""
    mus = np.array([0.8, 1.0, 1.2])
    phi = np.linspace(np.pi / 2, np.pi / 2 + 2 * np.pi, n)
    x1 = np.sqrt(mus)[:, None] * np.cos(phi)
    x2 = np.sqrt(mus)[:, None] * np.sin(phi)
    mode = np.where(x1 < -1.0, 0, 1).astype("int8")
    x1 = np.maximum(x1, -1.0)
    nan2 = [np.nan, np.nan]
    return xr.Dataset(
        {"x1": (("mu", "sample"), x1), "x2": (("mu", "sample"), x2),
         "mode": (("mu", "sample"), mode), "fixed_x2": ("mu", np.sqrt(mus)),
         "x_g": ("component", [-1.0, 0.0]),
         "x_h": (("mu", "component"), [nan2, nan2, [-1.0, np.sqrt(0.2)]]),
         "x_l": (("mu", "component"), [nan2, nan2, [-1.0, -np.sqrt(0.2)]])},
        coords={"mu": mus, "component": ["x1", "x2"]}, attrs={"omega": omega})


def fig06(n: int = 200, theta: float = 0.5, omega: float = 8 * np.pi) -> xr.Dataset:
    """eq:xi1r evaluated naively (no care for cancellation: t_s >= 1e-3 only)."""
    t = np.geomspace(1e-3, 5.0, n)
    e = np.exp(-t / theta)
    d = theta + (1 - theta) * e
    xi1 = -0.5 * omega ** 2 * theta ** 2 * (((1 - theta) * (1 - e) + t) / d) ** 2
    img = omega ** 2 * (1 - theta) * (theta - (theta + t) * e) / d
    return xr.Dataset(
        {"xi1": ("t_s", xi1), "image": ("t_s", img), "s": ("t_s", img / xi1),
         "slope_at_zero": (theta - 1) / theta, "image_limit": omega ** 2 * (1 - theta)},
        coords={"t_s": t}, attrs={"theta": theta, "omega": omega})


def _pdm_common(xi, eps, P, extra):
    """Variables both discontinuity-map figures read, on dims (eps, xi1)."""
    d2 = ("eps", "xi1")
    data = {"P_DM": (d2, P), "P_flow": (d2, P.copy())}
    data.update(extra)
    return xr.Dataset(data, coords={"eps": eps, "xi1": xi}, attrs={"theta": 0.0})


def fig07(n: int = 81, theta: float = -0.5, omega: float = 8 * np.pi) -> xr.Dataset:
    # the corrected expansion plus a made-up O(eps) remainder
    from filippov.analytic import pdm as a
    from filippov.analytic.s0 import s0_lambert

    eps = np.array([1e-2, 1e-3, 1e-4])
    xi = np.linspace(-2.5, 1.5, n)
    e = eps[:, None]
    first = a.pdm_theta_neg(xi, theta, omega, e)
    P = first + np.where(xi < 0, 5 * e * xi ** 2, 0.0)
    P[-1, xi < -2] -= 3.0  # a stretch where the true flow re-crosses H_s
    err = np.abs(P - first).max(axis=1)
    d2 = ("eps", "xi1")
    ds = _pdm_common(xi, eps, P, {
        "P_first_order": (d2, first), "P_zero_order": (d2, np.broadcast_to(a.pdm_theta_neg(xi, theta, omega, e, order=0),
                                             P.shape).copy()),
        "P_printed": (d2, a.pdm_theta_neg_printed(xi, theta, omega, e)),
        "s0": float(s0_lambert(theta)), "theta": theta,
        "error_first_order": ("eps", err), "error_zero_order": ("eps", 3 * np.sqrt(eps)),
        "error_printed": ("eps", 2.5 + 0 * eps), "left_limit_error": ("eps", 0.2 * eps)})
    ds["P_flow"].values[-1, xi < -2] += 1.0
    return ds


def fig09(n: int = 121, theta: float = 0.5, omega: float = 8 * np.pi) -> xr.Dataset:
    from filippov.analytic import pdm as a

    eps = np.array([1e-2, 1e-3, 1e-4])
    xi = np.unique(np.concatenate([np.linspace(-600, 60, n), np.linspace(-5, 0, 21)]))
    zero = a.pdm_theta_pos(xi, theta, omega)
    P = zero[None, :] * (1 + 10 * eps[:, None])
    d2 = ("eps", "xi1")
    ds = _pdm_common(xi, eps, P, {
        "P_zero_order": (d2, np.broadcast_to(zero, P.shape).copy()),
        "P_printed": (d2, np.broadcast_to(a.pdm_theta_pos(xi, theta, omega, printed=True),
                                          P.shape).copy()),
        "P_linear": ("xi1", a.pdm_theta_pos_linear(xi, theta)),
        "P_reduced": ("xi1", a.pdm_reduced(xi)), "slope_theory": (theta - 1) / theta,
        "theta": theta, "error": ("eps", np.abs(P - zero).max(axis=1)),
        "error_core": ("eps", 30 * eps), "error_printed": ("eps", 20 + 0 * eps)})
    ds.attrs["core"] = 5.0
    return ds


def fig10(n: int = 40) -> xr.Dataset:
    """Rough shapes: equilibrium line, a square-root Hopf branch, a stick-slip line."""
    vh, vgs = 2.12, 3.156
    ev = np.linspace(0.5, 3.6, n)
    pv = np.linspace(vh + 0.01, vgs, n)
    sv = np.linspace(0.5, vgs, n)
    nu = np.linspace(-6, 6, 121)
    nu = nu[nu != 0]
    F = np.sign(nu) * (2 - 2.5 * (1 - np.exp(-np.abs(nu)))) + 0.3 * nu
    return xr.Dataset(
        {"v_hopf": vh, "v_gs": vgs, "x1_gs": 4.52, "F_c_static": 2.0,
         "eq_v": ("eq", ev), "eq_x1": ("eq", 0.4 + 0.05 * ev),
         "eq_stable": ("eq", (ev > vh).astype(np.int8)),
         "po_v": ("po", pv), "po_x1": ("po", 0.5 + 4 * np.sqrt((pv - vh) / (vgs - vh))),
         "po_stable": ("po", np.zeros(n, np.int8)),
         "ss_v": ("ss", sv), "ss_x1": ("ss", 2.5 + 0.6 * sv), "ss_stable": ("ss", np.ones(n, np.int8)),
         "nu": ("nu", nu), "F_c": ("nu", F), "F_c_literal": ("nu", -F)})


def fig11(n: int = 41) -> xr.Dataset:
    x1 = np.linspace(4.15, 4.6, n)
    P = np.array([np.where(x1 < 4.3, x1 + 2 * (x1 - 4.29), 4.43 - 0.1 * (x1 - 4.3)),
                  np.where(x1 < 4.3, x1 + 2 * (x1 - 4.29), 4.43 + 0 * x1)])
    sl = np.where(x1 < 4.3, 0.0, x1 - 4.3)
    return xr.Dataset(
        {"P": (("panel", "x1"), P), "sliding_length": (("panel", "x1"), np.stack([sl, sl])),
         "fixed_point": (("panel", "fixed"), [[4.29, 4.43], [4.29, 4.43]]),
         "eps": ("panel", [0.1, 0.01]), "v0": ("panel", [3.32, 3.1]),
         "v0_sn": ("panel", [3.3228, 3.1721])},
        coords={"panel": [0, 1], "x1": x1})


def fig12(n_s: int = 19, k: int = 6) -> xr.Dataset:
    """Orbit diagrams of made-up period-n windows; edges converging like eps."""
    s = np.linspace(-0.5, 4.0, n_s)
    eps = np.array([1e-2, 1e-3, 1e-4])
    per = np.where(s < 0, 1, 2 + (np.floor(s) % 3)).astype(np.int32)
    u0 = 0.1 * s[:, None] - 0.2 * (np.arange(k)[None, :] % per[:, None])
    u = np.broadcast_to(u0, (1, eps.size, n_s, k)) + 0.01 * eps[None, :, None, None]
    n = np.array([2, 3])
    edge0 = np.array([[1.0, 1.6], [0.5, 0.8]])
    return xr.Dataset(
        {"u": (("theta", "eps", "s", "k"), u.copy()), "u_limit": (("theta", "eps", "s", "k"), u.copy()),
         "u_limit0": (("theta", "s", "k"), u0[None]),
         "period": (("theta", "eps", "s"), np.broadcast_to(per, (1, eps.size, n_s)).copy()),
         "period_limit0": (("theta", "s"), per[None]),
         "edge": (("eps", "n", "side"), edge0[None] + eps[:, None, None]),
         "edge_limit0": (("n", "side"), edge0), "edge_gap": ("eps", 2 * eps),
         "edge_kind": (("eps", "n", "side"),
                       np.broadcast_to(np.array([-1, 0], dtype=np.int32), (eps.size, 2, 2)).copy())},
        coords={"theta": [-0.5], "eps": eps, "s": s, "k": np.arange(k), "n": n, "side": [0, 1]},
        attrs={"theta": -0.5, "s_max": 4.0})


def fig13(k: int = 5) -> xr.Dataset:
    """Fans of made-up chaotic returns; widths ~ eps^2 (mu - 1)."""
    theta = np.array([0.5, 0.2, 0.1])
    eps = np.array([1e-2, 1e-3])
    s = np.concatenate([np.linspace(-1.0, 5.0, 13), [20.0, 100.0]])
    shape = (theta.size, eps.size, s.size)
    fan = np.maximum(s, 0)[None, None, :, None] * np.linspace(-0.3, 0.1, k)
    u = np.broadcast_to(fan, shape + (k,)).copy()
    lyap = np.broadcast_to(np.where(s > 0, 0.3, -0.5), shape).copy()
    width = np.broadcast_to(np.maximum(s, 0) * eps[None, :, None] ** 2 + 1e-12, shape).copy()
    return xr.Dataset(
        {"u": (("theta", "eps", "s", "k"), u), "u_limit": (("theta", "eps", "s", "k"), u),
         "lyapunov": (("theta", "eps", "s"), lyap), "lyapunov_limit": (("theta", "eps", "s"), lyap),
         "width_x2": (("theta", "eps", "s"), width),
         "chaotic": (("theta", "eps", "s"), (lyap > 0).astype(np.int32)),
         "width_exponent_err": (("theta", "s"), np.full((theta.size, s.size), 0.01)),
         "width_exponent": (("theta", "s"), np.broadcast_to(np.where(s > 0, 2.0, np.nan),
                                                           (theta.size, s.size)).copy()),
         "slope_pdm": ("theta", (theta - 1) / theta),
         "period": (("theta", "eps", "s"), np.where(np.broadcast_to(s, shape) > 0, 0, 1)
                    .astype(np.int32))},
        coords={"theta": theta, "eps": eps, "s": s, "k": np.arange(k)},
        attrs={"s_max": 5.0})


def fig14() -> xr.Dataset:
    """Every attractor class once or more on a coarse (theta, s) grid."""
    theta = np.linspace(-1.0, 0.8, 7)
    s = np.linspace(-1.0, 5.0, 7)
    kind = (np.add.outer(np.arange(theta.size), np.arange(s.size)) % 10 - 2).astype(np.int32)
    sb, eb = np.array([0.5, 1.0, 2.0]), np.array([1e-2, 1e-3])
    flip = 0.38 + 0.01 * sb
    return xr.Dataset(
        {"attractor_type": (("theta", "eps", "s"), kind[:, None, :]),
         "attractor_type_limit": (("theta", "eps", "s"), kind[::-1, None, :].copy()),
         "theta_critical": 0.3775, "theta_chaos": 0.2689,
         "theta_flip": (("eps_boundary", "s_boundary"), np.stack([flip, flip])),
         "theta_chaos_flip": (("eps_boundary", "s_boundary"), np.stack([flip, flip]) - 0.1),
         "theta_flip_limit": ("s_boundary", flip), "theta_chaos_limit": ("s_boundary", flip - 0.1)},
        coords={"theta": theta, "eps": [1e-3], "s": s, "s_boundary": sb, "eps_boundary": eb})


def work_precision() -> xr.Dataset:
    """Two problems, two methods at three tolerances each."""
    method = ["project compiled exact"] * 3 + ["solve_ivp RK45"] * 3
    err = np.array([[1e-12, 1e-11, 1e-10, 1e-3, 1e-5, 1e-7]] * 2)
    wall = np.array([[1e-3, 1.2e-3, 1.5e-3, 0.1, 0.3, 1.0]] * 2)
    return xr.Dataset(
        {"error_map": (("problem", "config"), err), "wall_time": (("problem", "config"), wall),
         "status": (("problem", "config"), np.full(err.shape, "ok", dtype=object)),
         "reference_check": ("problem", [1e-13, 1e-13]), "n_points": ("problem", [60, 9])},
        coords={"problem": ["fig04 theta=-0.5", "fig11 (a) eps=0.1"],
                "method": ("config", method), "tolerance": ("config", [1e-6, 1e-8, 1e-10] * 2)})
