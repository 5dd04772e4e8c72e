r"""
A sliding segment
=================

Solvable by hand: slide in on :math:`H = y = 0`, slide off at a fold.

Above :math:`y = 0` the field is :math:`F_+ = (2, -1)`, below it :math:`F_- = (1, 1 - x)`.
Along :math:`y = 0`, :math:`a = \nabla H \cdot F_- = 1 - x` and
:math:`b = \nabla H \cdot F_+ = -1`: sliding attracts for :math:`x < 1` and ends at the
fold :math:`x = 1` of :math:`F_-` (:math:`a = 0`). Filippov's field
:math:`(a F_+ - b F_-)/(a - b)` is :math:`\dot x = (3 - 2x)/(2 - x)`, :math:`\dot y = 0`,
so :math:`dt = (1/2 + 1/(2 (3 - 2x)))\, dx`: from :math:`(x_0, y_0)`, :math:`y_0 > 0`,

.. math::

   \text{slide start:}\quad & t_1 = y_0, \qquad x_1 = x_0 + 2 y_0 \;(< 1),\\
   \text{slide end:}\quad & t_2 = t_1 + \frac{1 - x_1}{2} + \frac{\ln(3 - 2 x_1)}{4},
     \qquad x = 1,\\
   \text{afterwards:}\quad & x = 1 + s, \qquad y = -\frac{s^2}{2}, \qquad s = t - t_2
     \quad (F_- \text{ leaves tangentially}).

The + and - modes have exact flows here (the sliding mode is always integrated):
method "exact" uses them, "integrate" integrates every mode with DOP853.

Run: python examples/sliding_segment.py   (filippov installed, or PYTHONPATH=src)
"""
import matplotlib.pyplot as plt
import numpy as np

from filippov import MINUS, SLIDING, FilippovSystem, simulate

Z0, T_END = (-2.0, 0.5), 4.0

SYSTEM = FilippovSystem(
    ("x", "y"),
    field_minus=lambda z, p: np.array([1.0, 1.0 - z[0]]),
    field_plus=lambda z, p: np.array([2.0, -1.0]),
    switch=lambda z, p: z[1],
    switch_grad=lambda z, p: np.array([0.0, 1.0]),
    flow_plus=lambda z0, s, p: np.array([z0[0] + 2.0 * s, z0[1] - s]),
    flow_minus=lambda z0, s, p: np.array([z0[0] + s, z0[1] + (1.0 - z0[0]) * s - s * s / 2]),
    sample_step=0.05)  # scan step of the exact flows: H varies on the scale of 1


def closed_form(z0=Z0, t_end=T_END):
    t1, x1 = z0[1], z0[0] + 2 * z0[1]
    t2 = t1 + (1 - x1) / 2 + np.log(3 - 2 * x1) / 4
    s = t_end - t2
    return {"slide_start_t": t1, "slide_start_x": x1, "slide_end_t": t2, "slide_end_x": 1.0,
            "end_x": 1 + s, "end_y": -s * s / 2}


def computed(method, z0=Z0, t_end=T_END):
    traj = simulate(SYSTEM, z0, t_end, method=method)
    kinds = [(e.kind, e.mode_after) for e in traj.switches()]
    if kinds != [("slide_start", SLIDING), ("slide_end", MINUS)]:
        raise RuntimeError(f"expected to slide in and off once, got the switches {kinds}")
    start, end = traj.switches()
    return {"slide_start_t": start.t, "slide_start_x": start.state[0], "slide_end_t": end.t,
            "slide_end_x": end.state[0], "end_x": traj.z[0], "end_y": traj.z[1], "traj": traj}


def main():
    want = closed_form()
    got = {m: computed(m) for m in ("exact", "integrate")}
    print(f"{'':14s} {'closed form':>18s} {'|exact - cf|':>13s} {'|integrate - cf|':>17s}")
    for k, w in want.items():
        print(f"{k:14s} {w:18.15f} {abs(got['exact'][k] - w):13.1e} "
              f"{abs(got['integrate'][k] - w):17.1e}")
    # the path in the plane: straight in, along y = 0, off on the parabola y = -(x - 1)^2/2
    s = np.linspace(0.0, T_END - want["slide_end_t"], 100)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(np.r_[Z0[0], want["slide_start_x"], 1.0 + s], np.r_[Z0[1], 0.0, -s * s / 2], "-",
            color="0.6", lw=3, label="closed form")
    for method, mark in (("exact", "."), ("integrate", "x")):
        traj = got[method]["traj"]
        z = traj.sample(np.linspace(0.0, T_END, 41))[1]   # and at the switches
        ax.plot(z[0], z[1], mark, label=f'simulate, method "{method}"')
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set(xlabel="$x$", ylabel="$y$ (switching on $H = y = 0$)",
           title="slide in on $y = 0$, slide off at the fold $x = 1$")
    ax.legend(loc="lower left")
    if "agg" not in plt.get_backend().lower():   # a window when run with a display
        plt.show()


if __name__ == "__main__":
    main()
