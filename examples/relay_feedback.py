"""
Relay feedback
==============

x' = A x - b sign(c^T x): the lag 1/(s+1)^3 under an ideal relay.

The plant (companion form of 1/(s+1)^3, output c^T x = x1) settles on a symmetric
periodic orbit that crosses c^T x = 0 every half-period h (the relay auto-tuning
experiment). Closed form: each field is linear, so from x0 on c^T x = 0 the orbit
with x(h) = -x0 has (I + e^{Ah}) x0 = A^{-1} (e^{Ah} - I) b, and h is the root of
c^T x0(h) = 0. As c^T b = 0 both saltation matrices equal S = I - 2 b c^T / (c^T A x0),
so the monodromy matrix from x0 is M = (S e^{Ah})^2 (scipy.linalg.expm). The solver
finds the orbit by itself: 20 periods from a point near the origin.

Run: python examples/relay_feedback.py   (filippov installed, or PYTHONPATH=src)
"""
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
            "multipliers": floquet_multipliers(SYSTEM, one, rtol=rtol)}


def main():
    got, want = computed(), closed_form()
    print(f"{'':16s} {'computed':>20s} {'closed form':>20s} {'|difference|':>12s}")
    for key in want:
        for i, (g, w) in enumerate(zip(np.ravel(got[key]), np.ravel(want[key]))):
            idx = np.unravel_index(i, np.shape(want[key]))  # () for a number
            name = key + (f"[{','.join(map(str, idx))}]" if idx else "")
            print(f"{name:16s} {g:20.15g} {w:20.15g} {abs(g - w):12.1e}")


if __name__ == "__main__":
    main()
