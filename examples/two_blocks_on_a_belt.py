r"""
Two blocks on a belt: sticking on an intersection of two surfaces
=================================================================

Two blocks on springs to a wall (:math:`k`), joined by a spring (:math:`k_c`), on a belt
at speed :math:`V`, each with its own dry friction:

.. math::

   \ddot x_1 = -k x_1 + k_c (x_2 - x_1) + F \operatorname{sign}(V - \dot x_1), \qquad
   \ddot x_2 = -k x_2 - k_c (x_2 - x_1) + F \operatorname{sign}(V - \dot x_2).

Block :math:`i` sticks (slides on :math:`h_i = V - \dot x_i`) while its spring force
:math:`g_i` is within :math:`\pm F`; both stick on :math:`h_1 = h_2 = 0`, where every
sliding field agrees (each acceleration depends on its own sign only).

From :math:`(x_1, \dot x_1, x_2, \dot x_2) = (0, V, 0, 0)` block 2 slips (harmonic about a
point carried with :math:`x_1 = V t`) until :math:`\dot x_2 = V`: both stick, :math:`g_1`
falling at :math:`k V` to :math:`-F`; block 1 slips until :math:`g_2 = -F` releases
block 2; both slip (an exponential) until block 2 sticks again.

Run: python examples/two_blocks_on_a_belt.py   (filippov installed, or PYTHONPATH=src)
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from filippov import FilippovSystem, simulate
from filippov.surfaces import mode_name

K, KC, V, F = 1.0, 0.5, 0.5, 1.0


def _field(sigma, z, p):   # p = (k, k_c, V, F)
    return np.array([z[1], -p[0] * z[0] + p[1] * (z[2] - z[0]) + p[3] * sigma[0],
                     z[3], -p[0] * z[2] - p[1] * (z[2] - z[0]) + p[3] * sigma[1]])


SYSTEM = FilippovSystem(("x1", "x1'", "x2", "x2'"), fields=_field, params=(K, KC, V, F),
                        switch=lambda z, p: np.array([p[2] - z[1], p[2] - z[3]]),
                        switch_grad=lambda z, p: np.array([[0, -1.0, 0, 0], [0, 0, 0, -1.0]]))


def _slip(c0, c1, x0, v0):
    """x'' = -(k + k_c) x + c0 + c1 s from (x0, v0): s -> (x, x')."""
    w2 = K + KC
    w, a, b = np.sqrt(w2), x0 - c0 / w2, (v0 - c1 / w2) / np.sqrt(w2)
    return lambda s: np.array([(c0 + c1 * s) / w2 + a * np.cos(w * s) + b * np.sin(w * s),
                               c1 / w2 - a * w * np.sin(w * s) + b * w * np.cos(w * s)])


def closed_form(orbit=False):
    """The events (kind, time, state, mode after), by brentq; ``orbit``: z(t) along them."""
    b2 = _slip(F, KC * V, 0.0, 0.0)                      # block 1 carried: x1 = V t
    z1 = np.array([V * (t1 := brentq(lambda s: b2(s)[1] - V, 0.1, 1.0)), V, b2(t1)[0], V])
    t2 = t1 + (F - (K + KC) * z1[0] + KC * z1[2]) / (K * V)  # g1 = -F, both carried
    z2 = z1 + V * (t2 - t1) * (carried := np.array([1.0, 0.0, 1.0, 0.0]))
    b1 = _slip(F + KC * z2[2], KC * V, z2[0], V)         # block 2 carried from z2
    s3 = brentq(lambda s: F - (K + KC) * (z2[2] + V * s) + KC * b1(s)[0], 0.01, 2.0)
    t3, z3 = t2 + s3, np.r_[b1(s3), z2[2] + V * s3, V]
    A = np.array([[0, 1, 0, 0, 0], [-K - KC, 0, KC, 0, F], [0, 0, 0, 1, 0],
                  [KC, 0, -K - KC, 0, F], [0, 0, 0, 0, 0]])  # both slip: z' = A (z, 1)
    both = lambda s: (expm(A * s) @ np.r_[z3, 1.0])[:4]  # noqa: E731
    t4 = t3 + brentq(lambda s: both(s)[3] - V, 3.0, 6.0)
    if orbit:
        return lambda t: (np.r_[V * t, V, b2(t)] if t < t1 else z1 + V * (t - t1) * carried
                          if t < t2 else np.r_[b1(t - t2), z2[2] + V * (t - t2), V]
                          if t < t3 else both(t - t3))
    return [("start", 0.0, np.array([0.0, V, 0.0, 0.0]), "0+"), ("slide_start", t1, z1, "00"),
            ("slide_end", t2, z2, "+0"), ("slide_end", t3, z3, "++"),
            ("slide_start", t4, both(t4 - t3), "+0")]


def computed():
    """The run to 0.1 after the last event of :func:`closed_form`."""
    return simulate(SYSTEM, [0, V, 0, 0], closed_form()[-1][1] + 0.1, method="integrate")


def main():
    run, want = computed(), closed_form()
    print("event        mode  t                  closed form - t  |state error|")
    for e, (kind, t, z, mode) in zip(run.events, want):
        print(f"{e.kind:12s} {mode_name(e.mode_after, 2):>4s} {e.t:18.15f} {t - e.t:15.1e} "
              f"{np.abs(e.state - z).max():14.1e}")
    ts = np.linspace(0.0, want[-1][1], 400)
    exact = np.array([closed_form(orbit=True)(t) for t in ts]).T
    z = run.sample(ts[::8], include_events=False)[1]
    fig, ax = plt.subplots(figsize=(6.5, 4.2))
    ax.plot(ts, exact[[1, 3]].T, "-", color="0.7", lw=3, label=["closed form", None])
    ax.plot(ts[::8], z[[1, 3]].T, ".", label=[f"simulate: $\\dot x_{i}$" for i in (1, 2)])
    ax.set(xlabel="time $t$", ylabel="velocity $\\dot x_i$",
           title="both stick, then block 2, then neither")
    ax.legend(loc="lower left")
    if "agg" not in plt.get_backend().lower():   # a window when run with a display
        plt.show()


if __name__ == "__main__":
    main()
