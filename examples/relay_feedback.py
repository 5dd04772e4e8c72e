r"""
Relay feedback
==============

:math:`\dot x = A x - b \operatorname{sign}(c^T x)`: the lag :math:`1/(s+1)^3` under an
ideal relay.

The plant (companion form of :math:`1/(s+1)^3`, output :math:`c^T x = x_1`) settles on a
symmetric periodic orbit that crosses :math:`c^T x = 0` every half-period :math:`h` (the
relay auto-tuning experiment). Closed form: each field is linear, so from :math:`x_0` on
:math:`c^T x = 0` the orbit with :math:`x(h) = -x_0` is

.. math::

   x(t) = e^{At} x_0 - A^{-1} (e^{At} - I)\, b, \quad 0 \le t \le h, \qquad
   x(t + h) = -x(t), \qquad (I + e^{Ah})\, x_0 = A^{-1} (e^{Ah} - I)\, b,

and :math:`h` is the root of :math:`c^T x_0(h) = 0`. As :math:`c^T b = 0` both saltation
matrices equal :math:`S = I - 2\, b c^T / (c^T A x_0)`, so the monodromy matrix from
:math:`x_0` is :math:`M = (S e^{Ah})^2` (``scipy.linalg.expm``). The solver finds the
orbit by itself: 20 periods from a point near the origin.

Run: python examples/relay_feedback.py   (filippov installed, or PYTHONPATH=src)
"""
import matplotlib.pyplot as plt
import numpy as np
from scipy.linalg import expm
from scipy.optimize import brentq

from filippov import PLUS, FilippovSystem, floquet_multipliers, monodromy, simulate

A = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [-1.0, -3.0, -3.0]])  # (s + 1)^3
b, c = np.array([0.0, 0.0, 1.0]), np.array([1.0, 0.0, 0.0])
RTOL = 1e-12  # DOP853's relative tolerance, for the orbit and its variational equations
# A x + b u for one state (compiled pieces); u = -sign(x1): +1 in region -, -1 in +
SYSTEM = FilippovSystem(
    ("x1", "x2", "x3"),
    field_minus=lambda z, p: np.array([z[1], z[2], -z[0] - 3.0 * z[1] - 3.0 * z[2] + 1.0]),
    field_plus=lambda z, p: np.array([z[1], z[2], -z[0] - 3.0 * z[1] - 3.0 * z[2] - 1.0]),
    switch=lambda z, p: z[0], switch_grad=lambda z, p: np.array([1.0, 0.0, 0.0]),
    jacobians={"minus": lambda z, p: A.copy(), "plus": lambda z, p: A.copy()})


def start_point(h):
    E = expm(A * h)
    return np.linalg.solve(np.eye(3) + E, np.linalg.solve(A, (E - np.eye(3)) @ b))


def closed_form():
    h = brentq(lambda h: c @ start_point(h), 1.0, 3.0, xtol=1e-15)  # h = 0 is spurious
    x0 = start_point(h)
    M = np.linalg.matrix_power((np.eye(3) - 2 * np.outer(b, c) / (c @ A @ x0)) @ expm(A * h), 2)
    return {"half_period": h, "period": 2 * h, "x0": x0, "monodromy": M,
            "multipliers": np.sort(np.linalg.eigvals(M).real)[::-1]}


def computed(periods=20, rtol=RTOL):
    sw = simulate(SYSTEM, [0.1, 0.0, 0.0], periods * 3.7, method="integrate", rtol=rtol).switches()
    up = [e for e in sw if e.mode_after == PLUS]  # crossings into c^T x > 0
    down = [e for e in sw if e.mode_after != PLUS and e.t > up[-2].t]
    one = simulate(SYSTEM, up[-1].state, up[-1].t - up[-2].t, method="integrate", rtol=rtol)
    # both fields are linear: the system carries their Jacobian A (jacobians=)
    return {"half_period": down[0].t - up[-2].t, "period": up[-1].t - up[-2].t,
            "x0": up[-1].state, "monodromy": monodromy(SYSTEM, one, rtol=rtol)[0],
            "multipliers": floquet_multipliers(SYSTEM, one, rtol=rtol), "orbit": one}


def closed_orbit(t, x0, h):
    """x(t) of the closed form, from x0 at t = 0 (one state per row)."""
    s, sign = np.mod(t, h), np.where(np.mod(t, 2 * h) < h, 1.0, -1.0)
    return np.array([g * (expm(A * si) @ x0 - np.linalg.solve(A, (expm(A * si) - np.eye(3)) @ b))
                     for si, g in zip(s, sign)])


def main():
    got, want = computed(), closed_form()
    print(f"{'':16s} {'computed':>20s} {'closed form':>20s} {'|difference|':>12s}")
    for key in want:
        for i, (g, w) in enumerate(zip(np.ravel(got[key]), np.ravel(want[key]))):
            idx = np.unravel_index(i, np.shape(want[key]))  # () for a number
            name = key + (f"[{','.join(map(str, idx))}]" if idx else "")
            print(f"{name:16s} {g:20.15g} {w:20.15g} {abs(g - w):12.1e}")
    # the last period the solver found (points), and the closed form through x0 (line)
    t, z, _ = got["orbit"].sample(np.linspace(0.0, got["period"], 60), include_events=False)
    line = closed_orbit(np.linspace(0.0, want["period"], 400), want["x0"], want["half_period"])
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(line[:, 0], line[:, 1], "-", color="0.6", lw=3, label="closed form")
    ax.plot(z[0], z[1], ".", color="C0", label="simulate (DOP853, rtol 1e-12)")
    ax.plot(*want["x0"][:2], "o", mfc="none", color="C3", ms=9, label="$x_0$ (crossing up)")
    ax.set(xlabel="$x_1 = c^T x$", ylabel="$x_2$", title="relay feedback: the periodic orbit")
    ax.axvline(0.0, color="k", lw=0.5)
    ax.legend(loc="center")
    if "agg" not in plt.get_backend().lower():   # a window when run with a display
        plt.show()


if __name__ == "__main__":
    main()
