"""
A sliding segment
=================

Solvable by hand: slide in on H = y = 0, slide off at a fold.

Above y = 0 the field is ``F_+ = (2, -1)``, below it ``F_- = (1, 1 - x)``. Along y = 0,
``a = dH.F_- = 1 - x`` and ``b = dH.F_+ = -1``: sliding attracts for x < 1 and ends at the
fold x = 1 of ``F_-`` (a = 0). Filippov's field ``(a F_+ - b F_-)/(a - b)`` is
x' = (3 - 2x)/(2 - x), y' = 0, so dt = dx (1/2 + 1/(2 (3 - 2x))): from (x0, y0), y0 > 0::

    slide start  t1 = y0,                                  x1 = x0 + 2 y0  (< 1),
    slide end    t2 = t1 + (1 - x1)/2 + ln(3 - 2 x1)/4,   x = 1,
    afterwards   x = 1 + s, y = -s^2/2,  s = t - t2       (F_- leaves tangentially).

The + and - modes have exact flows here (the sliding mode is always integrated):
method "exact" uses them, "integrate" integrates every mode with DOP853.

Run: python examples/sliding_segment.py   (filippov installed, or PYTHONPATH=src)
"""
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
            "slide_end_x": end.state[0], "end_x": traj.z[0], "end_y": traj.z[1]}


def main():
    want = closed_form()
    got = {m: computed(m) for m in ("exact", "integrate")}
    print(f"{'':14s} {'closed form':>18s} {'|exact - cf|':>13s} {'|integrate - cf|':>17s}")
    for k, w in want.items():
        print(f"{k:14s} {w:18.15f} {abs(got['exact'][k] - w):13.1e} "
              f"{abs(got['integrate'][k] - w):17.1e}")


if __name__ == "__main__":
    main()
