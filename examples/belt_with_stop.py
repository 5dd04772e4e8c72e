r"""
A belt, a spring and an end stop: two switching surfaces
========================================================

A block on a spring dragged by a belt, as in the stick-slip example, now against an end
stop: past :math:`x = d` a second, stiffer spring (stiffness :math:`S`) pushes back,

.. math::

   \ddot x = -x - S\,(x - d)\,[x \ge d] + F \operatorname{sign}(v - \dot x).

Two surfaces: :math:`h_1 = v - \dot x` (friction :math:`\pm F`) and :math:`h_2 = x - d`
(the stop, crossed: the field is continuous there). The block sticks (slides on
:math:`h_1`) while :math:`|x + S (x - d) [x \ge d]| < F`.

From :math:`(0, v)` the block sticks and is carried at speed :math:`v`: it reaches the stop
at :math:`t = d/v` *while sticking* and goes on sticking beyond it (the friction still
holds: the slide crosses :math:`h_2`), until the two springs overcome it at
:math:`x^* = (S d + F)/(1 + S)`, :math:`t = x^*/v`. Then it slips, a harmonic motion about
:math:`x^*` of frequency :math:`\omega = \sqrt{1 + S}` and amplitude :math:`v/\omega`,
back across the stop after :math:`\tau_1` with :math:`\sin \omega\tau_1 = (d - x^*)\omega/v`
(the second root), and about :math:`x = F` with frequency 1 below it, back to the stop
after :math:`\tau_2 = 2 \arctan(|\dot x_1| / (F - d))`. Undamped, the slip comes back to
the release point tangentially: the run stops before.

Run: python examples/belt_with_stop.py   (filippov installed, or PYTHONPATH=src)
"""
import matplotlib.pyplot as plt
import numpy as np

from filippov import simulate
from filippov.surfaces import SurfacesSystem, mode_name

F, V, D, S = 1.0, 0.5, 0.5, 3.0


def _field(sigma, z):
    stop = S * (z[0] - D) if sigma[1] > 0 else 0.0 * z[0]
    return np.array([z[1], -z[0] - stop + F * sigma[0]])


def _grads(z):
    return np.array([[0 * z[0], -1 + 0 * z[0]], [1 + 0 * z[0], 0 * z[0]]])


SYSTEM = SurfacesSystem(("x", "x'"), lambda z: np.array([V - z[1], z[0] - D]), _grads,
                        _field, m=2)


def closed_form(arcs=False):
    """The events from (0, v) in closed form: (kind, time, x, x', mode after); ``arcs``:
    the orbit in the plane instead (stick, slip about x*, below the stop, above it)."""
    xs, w = (S * D + F) / (1 + S), np.sqrt(1 + S)
    t_stop, t_free = D / V, xs / V
    tau1 = (np.pi + np.arcsin((xs - D) * w / V)) / w        # sin(w tau1) = (d - x*) w / v
    v1 = V * np.cos(w * tau1)                                 # < 0: moving back
    tau2 = 2 * np.arctan(abs(v1) / (F - D))
    t1, t2 = t_free + tau1, t_free + tau1 + tau2
    if arcs:
        a, th0 = np.linspace(0.0, w * tau1, 100), np.arctan2(-v1, D - F)
        b = np.linspace(th0, th0 + tau2, 100)
        c = np.linspace(np.arcsin((D - xs) * w / V), np.arcsin((D - xs) * w / V) + 0.1 * w, 20)
        stick = np.linspace(0.0, xs, 40)
        return (np.r_[stick, xs + V / w * np.sin(a), F + np.hypot(v1, F - D) * np.cos(b),
                      xs + V / w * np.sin(c)],
                np.r_[V + 0 * stick, V * np.cos(a), -np.hypot(v1, F - D) * np.sin(b),
                      V * np.cos(c)])
    return [("start", 0.0, 0.0, V, "0-"), ("crossing", t_stop, D, V, "0+"),
            ("slide_end", t_free, xs, V, "++"), ("crossing", t1, D, v1, "+-"),
            ("crossing", t2, D, -v1, "++")]


def computed():
    """The run to 0.1 after the last event of :func:`closed_form`."""
    return simulate(SYSTEM, [0.0, V], closed_form()[-1][1] + 0.1, method="integrate")


def main():
    run, want = computed(), closed_form()
    print(f"{'event':10s} {'mode':>4s} {'t':>18s} {'closed form':>18s} {'|state error|':>13s}")
    for e, (kind, t, x, dx, mode) in zip(run.events, want):
        err = np.abs(e.state - [x, dx]).max()
        print(f"{e.kind:10s} {mode_name(e.mode_after, 2):>4s} {e.t:18.15f} {t:18.15f} "
              f"{err:13.1e}")
    z = run.sample(np.linspace(0.0, run.t, 120))[1]
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(*closed_form(arcs=True), "-", color="0.6", lw=3, label="closed form")
    ax.plot(z[0], z[1], ".", color="C0", label="simulate (DOP853, stay by stay)")
    ax.axhline(V, color="k", lw=0.5, ls="--")   # h1 = 0 (sticking); h2 = 0 (the stop):
    ax.axvline(D, color="k", lw=0.5, ls=":")
    ax.set(xlabel="position $x$", ylabel="velocity $\\dot x$",
           title="stick across the stop, slip, and back (two surfaces)")
    ax.legend(loc="center")
    if "agg" not in plt.get_backend().lower():   # a window when run with a display
        plt.show()


if __name__ == "__main__":
    main()
