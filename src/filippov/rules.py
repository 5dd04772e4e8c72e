"""The decisions of the event-driven method, each written once.

Plain scalar Python: :mod:`filippov.simulate` and the event loop
(:mod:`filippov.loop`) call these functions as they are, and the compiled kernel
compiles the same functions with numba where they are called (every public function
here is registered as compilable by :mod:`filippov.kernel.base`; a new rule needs no
list entry), so the two engines cannot drift apart on a decision (the engines differ
only in how they step, sample and store). Modes are the integers of :mod:`filippov.system`;
``a = grad H . F_-`` and ``b = grad H . F_+`` are the normal speeds (Eq. (9)).
"""
from __future__ import annotations

import math

import numpy as np

from .system import MINUS, PLUS, SLIDING

_EPS = float(np.finfo(float).eps)

#: the rules an engine may call itself (tests/test_rule_askers.py): how it computes what it
#: reports -- a window's length, a difference step, a probe of a section's rounding, a
#: section's sign change from its direction -- and the estimates its messages and outputs
#: quote; every other rule is a decision of the method, which the loop (filippov.loop)
#: asks for both engines
ENGINE_NUMERICS = ("exact_window", "rate_step", "central_step", "richardson_step",
                   "section_probe", "section_noise", "section_pred", "cut_midpoint",
                   "geometric_accumulation", "budget_projection")

_TINY = float(np.finfo(float).tiny)

#: the sign changes events are made of: leaving region + (H >= 0 -> H < 0), leaving
#: region - (H < 0 -> H >= 0), a positive quantity reaching zero (a normal speed while
#: sliding, a decreasing section), and either way (a section without direction)
TO_NEG, TO_NONNEG, TO_NONPOS, EITHER = 0, 1, 2, 3


def after(pred: int, v):
    """v is on the far side of the sign change ``pred`` (elementwise on arrays).
    EITHER has no far side of its own: a refinement takes that of the crossing at
    hand (:func:`far_side`). The near side is the complement."""
    if pred == TO_NEG:
        return v < 0.0
    if pred == TO_NONNEG:
        return v >= 0.0
    return v <= 0.0  # TO_NONPOS


def crosses(pred: int, v0, v1):
    """The samples v0 -> v1 hold the sign change ``pred``: v0 on the near side, v1 on
    the far side (elementwise on arrays). Self-contained, so that numba compiles it
    as it stands."""
    if pred == TO_NEG:
        return (v0 >= 0.0) & (v1 < 0.0)
    if pred == TO_NONNEG:
        return (v0 < 0.0) & (v1 >= 0.0)
    if pred == TO_NONPOS:
        return (v0 > 0.0) & (v1 <= 0.0)
    return ((v0 < 0.0) & (v1 >= 0.0)) | ((v0 > 0.0) & (v1 <= 0.0))  # EITHER


def far_side(pred: int, v0: float) -> int:
    """The crossing a refinement must end beyond: for EITHER, the one leaving v0's
    side (else a non-terminal hit left on the near side is found again after each
    restart, and the run never gets past it)."""
    if pred == EITHER:
        return TO_NONPOS if v0 > 0.0 else TO_NONNEG
    return pred


def far_side_probe(r: float, step: float, tb: float, past: bool):
    """One step of the walk of a refined root to the far side of its crossing (a root
    finder may stop a hair before the sign flips: rounding near a shallow crossing).
    ``past``: whether the event function is past the crossing at the probe ``r``;
    ``step``: the last increment (0.0 at the first probe). Returns (done, r, step): done
    with the event time r (the probe, or ``tb`` when no probe before it is past), else the
    next probe -- increments double from 2 ulp of the first probe, capped at ``tb``. The
    engine loops ``done, r, step = far_side_probe(r, step, tb, after(pred, f(r)))``."""
    if past:
        return True, r, step
    if r >= tb:
        return True, tb, step
    if step == 0.0:
        a = max(abs(r), _TINY)
        step = 2.0 * (np.nextafter(a, np.inf) - a)
    return False, min(r + step, tb), 2.0 * step


def clamp(pred: int, v0: float) -> float:
    """The start sample of a just-entered mode, inside by construction: a value that
    rounding put on the far side is moved to the near side's edge."""
    if pred == TO_NEG:
        return v0 if v0 >= 0.0 else 0.0
    if pred == TO_NONNEG:
        return v0 if v0 < 0.0 else -_TINY
    return v0 if v0 > 0.0 else _TINY  # TO_NONPOS


def section_pred(direction: int) -> int:
    """The sign change a section with this direction counts (-1, +1, 0: either)."""
    if direction < 0:
        return TO_NONPOS
    if direction > 0:
        return TO_NONNEG
    return EITHER


def extremum_between(mode: int, d0, d1):
    """dH/dt changes sign between two samples so that H has a minimum (region +) or a
    maximum (region -) there, which may hide a crossing of H between samples where H
    has the same sign (elementwise on arrays)."""
    if mode == PLUS:
        return (d0 < 0.0) & (d1 >= 0.0)
    return (d0 > 0.0) & (d1 <= 0.0)


def carried_age(H: float, touch_tol: float, age: float) -> float:
    """The time already spent in the region of a start point that continues an orbit
    (a return map iterated from its last hit: a section hit is no mode entry), counted
    only where the start's region is unambiguous (|H| > touch_tol); else 0, as after an
    entry. It sets where the exact-flow windows stand in the fast transient
    (:func:`exact_window`)."""
    return age if abs(H) > touch_tol else 0.0


def exact_window(elapsed: float, h: float, h_slow: float, transient: float) -> float:
    """The next window of an exact flow, ``elapsed`` after the mode entry: ``h`` (the
    eps scale) at first, then as long as the time elapsed -- the fast part of the flow
    decays like exp(-t/eps), so after k windows it is below exp(-4k) of its size and
    needs no finer look than the time gone by -- never longer than ``h_slow``, and
    ``h_slow`` once ``transient`` has passed (docs/decisions.md#exact-windows-grow)."""
    if elapsed >= transient:
        return h_slow
    return min(max(h, elapsed), h_slow)


def dips_and_returns(mode: int, d0: float, d1: float) -> bool:
    """On the first sample interval of a stay entered at H = 0: the orbit leaves H
    (dH/dt = d0 points into the region) and heads back by the interval's end (d1).
    A crossing back then lies beyond the extremum of H between them, and is refined
    from there: next to the entry H is rounding noise (at a crossing with normal speed
    3.5e-3 on the Hopf example's chaotic attractor, theta = 0.2, H read >= 0 again
    1.7e-14 after the entry), and a bracket starting at the entry converged to that
    noise instead of the real return 7e-5 later (a ZenoError, a failed root)."""
    if mode == PLUS:
        return d0 > 0.0 and d1 <= 0.0
    return d0 < 0.0 and d1 >= 0.0


#: what a hidden extremum hm of H is: nothing, a crossing (the extremum lies beyond
#: touch_tol on the other side), or a touch (|hm| <= touch_tol: no switch)
GRAZE_NONE, GRAZE_CROSSES, GRAZE_TOUCHES = 0, 1, 2


def graze(mode: int, hm: float, touch_tol: float, band: float = 0.0) -> int:
    """``band`` > 0: the stay has not yet left the rounding band of the sliding exit it
    began at (:func:`exit_band`; hm is then measured from the band's far edge,
    :func:`banded_shift`). An extremum inside it is the exit's own tangency (at a
    visible fold H has its minimum at the exit point itself), neither a touch nor a
    crossing; one beyond the band is a crossing."""
    if (mode == PLUS and hm < -touch_tol) or (mode == MINUS and hm > touch_tol):
        return GRAZE_CROSSES
    if band == 0.0 and abs(hm) <= touch_tol:
        return GRAZE_TOUCHES
    return GRAZE_NONE


#: central-difference step (relative to the state's size) and the tolerance of the
#: test whether sliding stays in a section: truncation and rounding of the
#: differences are ~1e-10 relative
FD_STEP = float(np.cbrt(np.finfo(float).eps))
SLIDE_TANGENT = 1e-6
#: the larger step (relative to the state's size) of the compiled engine's Richardson
#: differences (:func:`richardson_step`): truncation ~step^4, rounding ~kappa u / step with
#: kappa the closed form's own conditioning; a power of two a little above u^(1/5)
#: (docs/decisions.md#richardson-dpdz)
RICHARDSON_STEP = 2.0 ** -9


# ------------------------------------------------------------- the end of sliding, hidden
# While sliding, the samples hold the normal speeds a (> 0) and b (< 0); a slide ends
# where a sign change puts one of them past 0 (a <= 0: TO_NONPOS, b >= 0: TO_NONNEG). A
# window where b > 0 (or a < 0) shorter than the sample spacing shows at no sample
# (docs/decisions.md#hidden-slide-end): as for a hidden extremum of h, the rates of a and
# b at the samples show an extremum toward the exit between two of them; it is refined
# (a root of the rate), and the speed there decides: an exit, a touch, or nothing.

def asks_hidden_end(mode: int, own_crossed: bool, crossed: bool) -> bool:
    """Is an extremum of a leave function hidden between two samples looked for? In a
    region, only where h shows no sign change (``crossed``: the crossing is then the event,
    and its root is refined on the way past any extremum). While sliding, wherever the
    speed's own sign change does not show (``own_crossed``), whether or not the other
    speed's does: an exit hidden before the other speed's crossing ends the slide first
    (a dips below 0 and back between the samples while b crosses 0 later in the same
    interval: the orbit leaves into region - at a's root, not into + at b's)."""
    if mode != SLIDING:
        return not crossed
    return not own_crossed


def speed_extremum_between(pred: int, d0, d1):
    """While sliding: the normal speed whose sign change ``pred`` ends the slide (a:
    TO_NONPOS, b: TO_NONNEG) has an extremum toward that change between two samples where
    its rate is d0 and d1 -- a minimum of a (d0 < 0 <= d1), a maximum of b (d0 > 0 >= d1)
    -- which may put it past 0 between samples that are not (elementwise on arrays)."""
    if pred == TO_NONPOS:
        return (d0 < 0.0) & (d1 >= 0.0)
    return (d0 > 0.0) & (d1 <= 0.0)


#: (4 sqrt 2) / 3: the area of the cap v > 0 of v = vm - kappa t^2 / 2 is
#: (4 sqrt 2 / 3) vm^(3/2) / sqrt(kappa)
_CAP = 4.0 * np.sqrt(2.0) / 3.0


def speed_graze(pred: int, vm: float, d0: float, d1: float, dt: float,
                touch_tol: float) -> int:
    """What the extremum ``vm`` of a normal speed hidden between two samples of a slide
    (speed_extremum_between; its rates d0, d1 at the samples, dt apart) is: GRAZE_CROSSES
    (an exit: the slide ends at the speed's root before it), GRAZE_TOUCHES (no exit; the
    return map has a kink there, as at a touch of h) or GRAZE_NONE.

    Near the extremum the speed is v ~ vm - kappa (t - tm)^2 / 2 (kappa ~ |d1 - d0| / dt,
    the change of its rate over the interval). Past 0 it drives the orbit off H for
    2 sqrt(2 |vm| / kappa), by at most the cap's area (4 sqrt2 / 3) |vm|^1.5 / sqrt(kappa)
    in h (h' = v there), and the orbit differs from the one that slides on by that times
    |F_+ - F_-| / (a - b): the same scale. So a touch is an extremum whose cap is within
    touch_tol, on either side of 0, as graze's |hm| <= touch_tol for a hidden extremum
    of h; beyond it an extremum past 0 is an exit. (An extremum at 0 up to rounding of the
    speed, ~1e-15, makes a cap ~1e-23 at kappa = 40: a touch; b's maximum 5e-4 there,
    over a window of 0.01, makes 3e-6: an exit.)"""
    kappa = abs(d1 - d0) / dt if dt > 0.0 else np.inf
    v = abs(vm)
    if v == 0.0:
        cap = 0.0
    elif kappa > 0.0 and np.isfinite(kappa):
        cap = _CAP * v * np.sqrt(v / kappa)
    else:
        cap = np.inf
    if cap <= touch_tol:
        return GRAZE_TOUCHES
    past = vm < 0.0 if pred == TO_NONPOS else vm > 0.0
    return GRAZE_CROSSES if past else GRAZE_NONE


#: the forward-difference step of the rates of a and b along a slide, relative to the
#: state's size (rate_step): truncation and rounding are then both ~u^(1/2) of the rate
RATE_STEP = float(np.sqrt(np.finfo(float).eps))


def rate_step(z, fm, fp, a: float, b: float, floor: float = 1.0) -> float:
    """The time step d of the forward differences (v(t + d) - v(t)) / d on the orbit that
    give the rates of a and b along a slide, from a sample (state z, F_-, F_+, a and b
    there): the orbit moves RATE_STEP max(floor, |z|_inf) (floor: the run's state scale,
    filippov.scale) along Filippov's field
    (a F_+ - b F_-)/(a - b) over it, so truncation and rounding of the rates are ~u^(1/2)
    of them, plenty for their signs; a forward difference is the rate at t + d/2, which
    moves a located extremum by d/2 and its value by ~u |z|^2 |v''| / |F|^2: nothing. One
    evaluation of a and b per sample, where a central difference took two (the cost of a
    return on the Hopf example's chaotic attractor: +9% against +18% at eps = 1e-2).
    0 (no rates, no check) where that field is zero, not finite or not defined."""
    den = a - b
    if not den > 0.0:  # not sliding at this sample (a <= b): no Filippov field
        return 0.0
    size, speed = floor, 0.0
    for k in range(z.size):
        size = max(size, abs(z[k]))
        speed = max(speed, abs((a * fp[k] - b * fm[k]) / den))
    if not (np.isfinite(speed) and speed > 0.0):
        return 0.0
    return RATE_STEP * size / speed


def central_step(size: float, speed: float) -> float:
    """The central-difference step along a direction (largest component ``speed``: a
    field, a column of a derivative) at a state of size ``size`` (at least the run's
    state scale, filippov.scale); 0 where the
    direction is zero or not finite. Truncation and rounding are then both ~u^(2/3)
    of the derivative (the sliding test, the compiled engine's dP/dz)."""
    if not (np.isfinite(speed) and speed > 0.0):
        return 0.0
    return FD_STEP * size / speed


def richardson_step(size: float) -> float:
    """The larger of the two central-difference steps whose Richardson extrapolation
    (4 D(d/2) - D(d)) / 3 differentiates a closed-form flow or a section in the compiled
    engine's dP/dz, at a state of size ``size`` (at least the run's state scale): error
    ~1e-12 of the derivative where one central difference of step u^(1/3) left ~1e-10."""
    return RICHARDSON_STEP * size


def slides_in_section(s_at_z: float, d: float, rate_minus: float, rate_plus: float,
                      rate_sliding: float) -> bool:
    """The sliding flow stays in the section (a section on H): the state lies on it
    and the section changes along F_- or F_+ but not along the Filippov field (rates
    of the section along each field by central differences of step d); its crossings
    while sliding would be rounding noise."""
    if d == 0.0:
        return False
    scale = max(abs(rate_minus), abs(rate_plus))
    return abs(s_at_z) <= SLIDE_TANGENT * d * scale and abs(rate_sliding) <= SLIDE_TANGENT * scale


#: what ended a stay in a mode: a crossing of H (from region + or -), or, while
#: sliding, a normal speed reaching zero (F_- or F_+ turning tangent to H)
SWITCH, EXIT_MINUS, EXIT_PLUS = 0, 1, 2


def leave_pred(mode: int, q: int) -> int:
    """The sign change of leave function ``q`` that ends a stay in ``mode``: in region +
    H turning negative, in region - H reaching 0 or above (q = 0); while sliding a
    reaching 0 or below (q = 0), b reaching 0 or above (q = 1)."""
    if mode == PLUS:
        return TO_NEG
    if mode == MINUS:
        return TO_NONNEG
    return TO_NONPOS if q == 0 else TO_NONNEG


def ended_by(mode: int, q: int) -> int:
    """What a sign change of leave function ``q`` ends a stay in ``mode`` with (the
    ``ended_by`` of :func:`next_mode`): in a region q = 0 is H, a SWITCH; while sliding
    q = 0 is a (F_- turned tangent: EXIT_MINUS) and q = 1 is b (EXIT_PLUS), whether the
    crossing shows at the samples or hides between them."""
    if mode != SLIDING:
        return SWITCH
    return EXIT_MINUS if q == 0 else EXIT_PLUS


def start_side(H: float, touch_tol: float) -> int:
    """PLUS or MINUS for a start off H (beyond ``touch_tol``); SLIDING (0) for a
    start on H, where the field directions decide (:func:`start_on_switch`)."""
    if abs(H) > touch_tol:
        return PLUS if H > 0 else MINUS
    return SLIDING


#: a slide may leave H by this share of H's size at the state (the sum of ``|dH/dz_k|``
#: times the larger of ``|z_k|`` and the component's scale) before it is refused, or by
#: SLIDE_DRIFT_RTOLS times the integration's rtol where that is larger: the sliding field
#: keeps H constant wherever grad H is H's gradient, and its integration drifts by its
#: errors only -- 5.7e-14 after a million explicit sliding steps of the Hopf example at
#: rtol 1e-12, and on a curved H about rtol per unit of time slid (a circle: H = -2.75e-6
#: after 100 at rtol 1e-6, a review) -- while a switch_grad right where it was checked
#: and wrong along the slide left H by 0.07
SLIDE_DRIFT_SHARE = 1e-6
SLIDE_DRIFT_RTOLS = 1e4


def slid_off(h: float, z, grad, scales, rtol: float) -> bool:
    """A state reached by sliding whose H is beyond the drift a slide's integration
    makes (SLIDE_DRIFT_SHARE of H's size there, or SLIDE_DRIFT_RTOLS times ``rtol``;
    ``scales``: each component's, filippov.scale); a value not finite is another
    status's. docs/decisions.md#wrong-on-the-way"""
    size = 0.0
    for k in range(z.size):
        size += abs(grad[k]) * max(abs(z[k]), scales[k])
    return abs(h) > max(SLIDE_DRIFT_SHARE, SLIDE_DRIFT_RTOLS * rtol) * size


def no_normal(grad) -> bool:
    """grad H is 0 in every component (a start on H there has no side to decide on: a
    switch that does not depend on the state ran silently in region + before, a review
    found)."""
    for k in range(grad.size):
        if grad[k] != 0.0:
            return False
    return True


def start_on_switch(H: float, a: float, b: float, sliding: bool) -> tuple[int, bool]:
    """The mode a start on H begins in, and whether H repels there (either side
    is a solution; region + is taken). A start that rounding puts a hair on the
    wrong side is thereby no switch."""
    if a > 0 and b < 0:
        return (SLIDING if sliding else PLUS), False
    # a tangent field (a or b exactly 0) whose partner pushes into its region: the partner's
    # region is no solution (its field points across H at once; tests/test_properties.py
    # FOLD_START_AT_ORIGIN: a = 0, b < 0 took region + and changed mode twice at t = 1e-323)
    if a <= 0 and b < 0:
        return MINUS, False
    if a > 0 and b >= 0:
        return PLUS, False
    if a < 0 < b:
        return PLUS, True
    return (PLUS if H >= 0 else MINUS), False  # a tangency: the sign of H decides


def next_mode(mode: int, ended_by: int, a: float, b: float) -> int:
    """The Filippov decision at a point of H = 0 (Eq. (9)). A slide ends into the
    region whose field turned tangent; a crossing from H > 0 (F_+ points down)
    slides when F_- points back up (a > 0), one from H < 0 when F_+ points back
    down (b < 0), and crosses otherwise."""
    if ended_by == EXIT_MINUS:
        return MINUS
    if ended_by == EXIT_PLUS:
        return PLUS
    if mode == PLUS:
        return SLIDING if a > 0 else MINUS
    return SLIDING if b < 0 else PLUS


#: a sliding exit's H beyond this many roundings of H's terms is drift, not rounding
DRIFT_ULPS = 16.0


def exit_drift(mode: int, h0: float, z, grad, touch_tol: float) -> bool:
    """A sliding exit into region ``mode`` whose state lies on the wrong side of H
    beyond rounding: beyond touch_tol and beyond DRIFT_ULPS roundings of the terms
    grad_k z_k (H cannot be evaluated closer to 0 than that: the dry-friction
    model's H = w - g1 x2 with w ~ 3 reads +-2e-15 on H). Then the integrated slide
    drifted off H by its local errors (the Hopf example at eps = 1e-7, a million
    explicit sliding steps: H = -5.7e-14 at the exit, 57 times touch_tol); left
    there, the next stay starts across H and crosses back at once (slide_end and
    slide_start cycled into a Zeno stop). The state is moved onto H instead
    (onto_switch)."""
    wrong_side = h0 < 0 if mode == PLUS else h0 >= 0
    scale = 0.0
    for k in range(z.size):
        scale += abs(grad[k] * z[k])
    return wrong_side and abs(h0) > max(touch_tol, DRIFT_ULPS * _EPS * scale)


def onto_switch(z, h: float, grad) -> None:
    """Moves z onto H in place: one Newton step along grad H (z -= h grad / |grad|^2);
    a Filippov solution lies on H while it slides. What rounding leaves after the
    step is exit_shift's."""
    g2 = 0.0
    for k in range(z.size):
        g2 += grad[k] * grad[k]
    if g2 > 0.0:
        for k in range(z.size):
            z[k] -= h * grad[k] / g2


def exit_shift(mode: int, h0: float, touch_tol: float, projected: bool) -> float:
    """What a stay in region ``mode`` entered at a sliding exit subtracts from H:
    the exit point's own H when it lies on the wrong side within touch_tol, or at
    any distance once the exit was moved onto H (``projected``: what is left is
    the rounding of that step), else 0. The exit is tangential, and a state one
    rounding below H would otherwise read as an immediate crossing back (at eps =
    1e-9 the Hopf example's exit point has H = -2.2e-16 while dH/dt = 3e-14, below
    the 1e-7 noise of that speed: the driver cycled slide_end -> slide_start at one
    instant into a ZenoError). A real return across H from there is still a sign
    change of the shifted function."""
    wrong_side = h0 < 0 if mode == PLUS else h0 >= 0
    if wrong_side and (projected or abs(h0) <= touch_tol):
        return h0
    return 0.0


#: the rounding band of H around a sliding exit, in roundings of the stay's state (see
#: exit_band): the widest noise measured was 8.9 of them, 16 leaves a factor ~2
EXIT_BAND_ULPS = 16.0
#: the largest rounding of an exact flow at tau = 0 that exit_band accepts, relative to
#: the state's size (the generated systems' worst is ~1e-14; FOLD_EXIT's 1.1e-15)
EXIT_BAND_FLOW_MAX = 1e-10


#: an exact flow may move a state by at most this many times the window times the
#: larger field speed at the window's two ends (the mean-value bound, with room for a
#: speed that peaks inside the window)
FLOW_SPEED_FACTOR = 100.0


def flow_consistent(dz: float, dt: float, speed_a: float, speed_b: float,
                    size: float, floor: float = 1.0) -> bool:
    """Whether an exact flow's move |dz| over a window dt agrees with its own field:
    |dz| <= FLOW_SPEED_FACTOR dt max(|f(z_a)|, |f(z_b)|) plus the rounding of the
    states (1e3 ulps of their size, at least of ``floor``: the state scale). A closed form that fails this computes something
    else than the field's flow (the Hopf example at eps = 1e6: y from 0 to 1e9 in
    8e-10 time units, the field's speed there 1e3), and the run must not go on."""
    return dz <= FLOW_SPEED_FACTOR * dt * max(speed_a, speed_b) + 1e3 * _EPS * max(floor, size)


def exit_band(z, z_flow, grad, floor: float, scales) -> float:
    """The rounding of H along the stay that begins at the sliding exit ``z``: H cannot
    be read closer to its value at z than this while the orbit is still next to z.
    The stay's states are z + d(tau), d the rounding of the flow that gives them (for
    an exact flow, its closed form at tau ~ 0; for an integration step, its dense
    output), so H reads h(z) + grad.d, and |grad.d| <= |grad| |d|. A backward-stable
    evaluation around z has |d| ~ eps |z|; a closed form built around another point
    (an affine flow z* + V e^{B tau} V^-1 (z - z*) rounds at the scale of |z*| and
    cond(V) |z - z*|) rounds more, and says by how much at tau = 0: ``z_flow``, the
    flow of z over time 0 (z itself for an integrated stay), differs from z by that
    rounding. So the band is EXIT_BAND_ULPS |grad| max(eps |z|, |z_flow - z|).
    Measured: at the exits of 1600 generated sliding cases (tests/generated_systems.py,
    exact flows, tau in [0, 1e-7]) the noise of H was at most 8.9 times
    |grad| max(eps |z|, |z_flow - z|) (p99 5.5), but 43 times |grad| eps |z| alone.
    At the fold exit of FOLD_EXIT (tests/test_properties.py) H read -1.1e-15 at tau = 0,
    where z = 0.68 and |z*| = 10: the flow's own rounding, and 7 roundings of |z|.
    ``floor``: the state scale (filippov.scale) below which the cap does not shrink;
    the norms in the metric of the components' ``scales`` (ratios scales / floor, powers
    of two: 1 for a run of one scale, whose arithmetic is the Euclidean one's bit for
    bit), so that a large constant component beside a small one does not make the band
    swallow a crossing (a review: an exit's band of 0.36 in H's units)."""
    g2, z2, d2 = 0.0, 0.0, 0.0
    for k in range(z.size):
        r = scales[k] / floor
        g, y, e = grad[k] * r, z[k] / r, (z_flow[k] - z[k]) / r
        g2 += g * g
        z2 += y * y
        d2 += e * e
    # a closed form that misses its own start by more than EXIT_BAND_FLOW_MAX of the
    # state's size is no rounding to step over (eps = 1e6 in the Hopf example: the band
    # would swallow genuine crossings and the run drift to y ~ 1e16 without a word):
    # the band stays at that size, and the crossings it cannot hide are seen
    d = min(np.sqrt(d2), EXIT_BAND_FLOW_MAX * max(floor, np.sqrt(z2)))
    return EXIT_BAND_ULPS * np.sqrt(g2) * max(_EPS * np.sqrt(z2), d)


def banded_shift(mode: int, shift: float, band: float) -> float:
    """What the stay after a sliding exit into region ``mode`` subtracts from H while
    the orbit is inside the exit's rounding band: exit_shift's shift moved by the
    band to the wrong side, so that a sign change of H within the band (the rounding
    of the flow at tau ~ 0, not an arrival at H) is no crossing. A genuine return
    across H is one of the banded function too: it goes beyond the band."""
    return shift - band if mode == PLUS else shift + band


def clears_band(mode: int, v: float, band: float) -> bool:
    """The stay's banded H at a sample (``v`` = H - banded_shift) shows the orbit out of
    the exit's rounding band on the side of its region (H - shift beyond the band):
    from there the stay measures H without the band, a later crossing unbiased."""
    if mode == PLUS:
        return v > 2.0 * band
    return v < -2.0 * band


def accumulates(oldest: float, newest: float, zeno_span: float,
                time_scale: float = 1.0) -> bool:
    """The last zeno_count switches, from ``oldest`` to ``newest``, fall within
    zeno_span (relative to |t| beyond the run's time scale, filippov.scale): a Zeno
    point or chatter below the time resolution."""
    return newest - oldest <= zeno_span * max(time_scale, abs(newest))


#: An integration step's samples must resolve what is sampled on them (the leave functions,
#: the sections) before its sign changes are trusted: on a nearly constant field the steps
#: grow without bound while h or a section may wind between two samples (two crossings, or
#: a section window, between samples: docs/decisions.md#resolved-windows). Five samples
#: resolve a function when the parabola through the 1st, 3rd and 5th predicts the 2nd and
#: 4th within RESOLVE_SHARE of the five's range (of sin(w t): always at w dt <= 0.8, never
#: at w dt >= 1.5, whatever the phase; two extrema between samples need w dt >= pi) and,
#: where the slopes are sampled too (h in a region), the Hermite cubic of every other
#: sample's value and slope predicts the one between, and Simpson's rule on the slopes the
#: change across it (samples that alias a fast function into a smooth-looking one do not:
#: their slopes give it away).
RESOLVE_SHARE = 0.2
#: an unresolved window is shortened by SPLIT and sampled again, down to a SPLIT **
#: MAX_SPLITS-th (1/4096) of its integration step (loop.stay.make_step_windows)
SPLIT = 16.0
MAX_SPLITS = 3
#: the rounding of a sample a prediction's miss must exceed, in ulps of the largest sample
RESOLVE_NOISE_ULPS = 64.0
#: where that is not enough (a and b of a stiff slide carry the state's rounding times the
#: fast rate: 1e-7 of a = 0.5 at eps = 1e-9), the reference engine measures the rounding:
#: the function's changes when each component of a sample's state moves by this many
#: ulps, summed and scaled to RESOLVE_NOISE_ULPS (a feature of the function that shows
#: less than that at the samples is below its own rounding; docs/decisions.md#resolved-windows)
RESOLVE_PROBE_ULPS = 4.0


def misses(predicted: float, v: float, lo: float, hi: float, floor: float) -> bool:
    """A prediction of the sample v misses it by more than RESOLVE_SHARE of the samples'
    range [lo, hi], and by more than their rounding: RESOLVE_NOISE_ULPS of the largest,
    or ``floor`` where larger (the rounding of the state carried through the function,
    measured by the reference engine: :data:`RESOLVE_PROBE_ULPS`)."""
    miss = abs(v - predicted)
    return (miss > RESOLVE_SHARE * (hi - lo)
            and miss > RESOLVE_NOISE_ULPS * _EPS * max(abs(lo), abs(hi)) and miss > floor)


def resolves(v, d, ts, n: int, slopes: bool, floor: float) -> bool:
    """The first n samples v of a function at the equally spaced times ts (slopes d where
    ``slopes``) resolve it (:data:`RESOLVE_SHARE`): in every run of five, from sample 0 at
    a stride of 4 and the last five, the parabola through the 1st, 3rd and 5th predicts
    the 2nd and 4th, and (``slopes``) the Hermite cubic of the samples either side of the
    2nd, 3rd and 4th predicts it, and Simpson's rule on the slopes the change across it
    (:func:`misses`, above ``floor``). Fewer than five samples are not judged
    (True: samples_per_step < 4)."""
    if n < 5:
        return True
    dt = (ts[n - 1] - ts[0]) / (n - 1)
    k = 0
    while True:
        lo = min(v[k], v[k + 1], v[k + 2], v[k + 3], v[k + 4])
        hi = max(v[k], v[k + 1], v[k + 2], v[k + 3], v[k + 4])
        if (misses((3.0 * v[k] + 6.0 * v[k + 2] - v[k + 4]) / 8.0, v[k + 1], lo, hi, floor)
                or misses((6.0 * v[k + 2] + 3.0 * v[k + 4] - v[k]) / 8.0, v[k + 3], lo, hi,
                          floor)):
            return False
        if slopes:
            for j in range(k + 1, k + 4):
                if (misses((v[j - 1] + v[j + 1]) / 2.0 + dt * (d[j - 1] - d[j + 1]) / 4.0,
                           v[j], lo, hi, floor)
                        or misses(v[j - 1] + dt * (d[j - 1] + 4.0 * d[j] + d[j + 1]) / 3.0,
                                  v[j + 1], lo, hi, floor)):
                    return False
        if k + 4 >= n - 1:
            return True
        k = min(k + 4, n - 5)


def window_end(t0: float, span: float, tb: float) -> float:
    """The end of a window of length ``span`` from t0 in an integration step that ends at
    tb: tb when the window reaches it."""
    return t0 + span if t0 + span < tb else tb


def can_split(ta: float, tb: float, t0: float, t1: float) -> bool:
    """The window [t0, t1] of the integration step [ta, tb] may be shortened by SPLIT: the
    shorter one is no shorter than a SPLIT ** MAX_SPLITS-th of the step, and longer than
    t0's rounding."""
    d = (t1 - t0) / SPLIT
    return d >= (tb - ta) / SPLIT ** MAX_SPLITS and t0 + d > t0


def cut_resolves(kept: int, n: int) -> bool:
    """Whether the ``kept`` samples of a window of n cut at its sample ``kept`` (that one
    not finite; -1: not cut) may be judged as an uncut window's are (:func:`resolves`):
    five or more kept, or a window of fewer than five (never judged). Else the window is
    shortened, its windows ending at the cut (docs/decisions.md#past-a-non-finite-sample,
    :func:`to_cut`)."""
    return kept < 0 or kept >= 5 or n < 5


def to_cut(t0: float, cap: float, last: float) -> tuple:
    """The end of a window from t0 that the step's walk would end at ``cap``, the time of
    a sample found not finite, and whether it may be split: a window no longer than
    ``last``, the last one searched (0: none yet), is searched as it is (its samples as
    dense as that one's, which were judged; those to the cut cannot be: the last is not
    finite); a longer one ends ``last`` short of the cut, all its samples before it, so
    that the one after it is no longer than ``last``
    (docs/decisions.md#past-a-non-finite-sample)."""
    if cap - t0 <= last:
        return cap, False
    if last > 0.0:
        return cap - last, True
    return cap, True


def cut_midpoint(lo: float, hi: float, xtol: float) -> float:
    """The end of the next sub-window an engine samples past a window's first sample that
    is not finite (at hi; the samples up to lo finite, no event among them): the middle
    of [lo, hi], or NaN once the bracket is within xtol and the rounding of hi -- the run
    then stops at hi. The sub-windows [lo, mid] are sampled as the window was and searched
    for an event before the field's edge (docs/decisions.md#past-a-non-finite-sample)."""
    mid = lo + 0.5 * (hi - lo)
    if hi - lo <= xtol + 4.0 * _EPS * abs(hi) or not lo < mid < hi:
        return math.nan
    return mid


#: the non-finite guard both engines keep on an integration step: a non-finite field value
#: at a stay's first evaluation is an error (NON_FINITE); on a trial stage it is replaced
#: by this huge finite value (a NaN norm loops scipy's step control forever), and a step
#: that met it is rejected and shrinks -- never accepted, whatever its error norm (where
#: several stages take this one constant, the estimate, zero for a constant, passes); a
#: step size that collapses on it ends the run NON_FINITE, naming the stage's state
NON_FINITE_STAGE = 1e300


def step_budget_spent(n_steps: int, max_steps: int) -> bool:
    """The hard step bound both engines keep: the run has taken more than max_steps
    steps (accepted integration steps, and exact-flow windows; a step's rejected trials
    count once with it; the reference also projects the steps still to come, engines.py
    asymmetry 3)."""
    return n_steps > max_steps


#: Switch times that shrink geometrically accumulate: the intervals sum to a finite time,
#: where the orbit reaches a Zeno point (at an invisible two-fold, crossings accumulate so;
#: past it rounding, amplified each loop, throws the orbit out and a confident wrong state
#: comes back). Detected on the Zeno ring, before the intervals come near the time
#: resolution: each interval is compared with the one two switches before it (a loop of
#: a crossing orbit), newest first; the ratios must stay at most GEOMETRIC_RATIO_MAX, within
#: a factor 1 + GEOMETRIC_SPREAD of each other, over at least GEOMETRIC_MIN_RATIOS of them,
#: and the newest interval must have shrunk to GEOMETRIC_SHRINK of the oldest of the run of
#: steady ratios (a series of ratio 0.9 needs 44 ratios for that: the ring's 64 switches
#: hold 62; a slower one is left to :func:`accumulates`). An orbit converging to a
#: periodic one has ratios that tend to 1; one that chatters, ratios that alternate
#: (docs/decisions.md#named-edges).
GEOMETRIC_RATIO_MAX = 0.9
GEOMETRIC_SPREAD = 0.1
GEOMETRIC_MIN_RATIOS = 8
GEOMETRIC_SHRINK = 1e-2


def geometric_accumulation(recent, entries: int, zeno_count: int):
    """(ratio, t_star): the switch times in the Zeno ring (as :func:`note_switch` keeps
    it) shrink geometrically, the newest loop (two intervals) ``ratio`` times the one
    before, and the loops still to come sum to the accumulation time t_star; (nan, nan)
    where they do not (see GEOMETRIC_RATIO_MAX)."""
    held = min(entries, zeno_count)
    lo, hi = np.inf, 0.0
    d0 = recent[(entries - 1) % zeno_count] - recent[(entries - 2) % zeno_count]
    for j in range(held - 3):  # interval j (0: the newest) against interval j + 2
        t0 = recent[(entries - 1 - j) % zeno_count]
        t1 = recent[(entries - 2 - j) % zeno_count]
        t2 = recent[(entries - 3 - j) % zeno_count]
        t3 = recent[(entries - 4 - j) % zeno_count]
        near, far = t0 - t1, t2 - t3
        if not (near > 0.0 and far > 0.0 and near <= GEOMETRIC_RATIO_MAX * far):
            return np.nan, np.nan
        r = near / far
        lo, hi = min(lo, r), max(hi, r)
        if hi > lo * (1.0 + GEOMETRIC_SPREAD):
            return np.nan, np.nan
        if j + 1 >= GEOMETRIC_MIN_RATIOS and d0 <= GEOMETRIC_SHRINK * far:
            newest = recent[(entries - 1) % zeno_count]
            loop = newest - recent[(entries - 3) % zeno_count]
            ratio = loop / (recent[(entries - 3) % zeno_count]
                            - recent[(entries - 5) % zeno_count])
            return ratio, newest + loop * ratio / (1.0 - ratio)
    return np.nan, np.nan


#: A slide ends at a two-fold where both normal speeds vanish at its end: each within
#: TWO_FOLD_SHARE of its size where the slide began (a, b of a slide go to zero linearly
#: in the distance to a two-fold; at an ordinary exit the other speed is of the order of
#: its size along the slide, and one located to the integration's accuracy is ~1e-10 of
#: it), or of its field's size there (:func:`tangent_to_both`)
TWO_FOLD_SHARE = 1e-6


def at_two_fold(a: float, b: float, a_in: float, b_in: float) -> bool:
    """The slide that began with the normal speeds a_in > 0 > b_in (F_-, F_+ along grad
    H) ends where they are a and b at a two-fold: both tangent to H."""
    return abs(a) <= TWO_FOLD_SHARE * abs(a_in) and abs(b) <= TWO_FOLD_SHARE * abs(b_in)


def tangent_to_both(a: float, b: float, grad, f_minus, f_plus, scales, floor: float) -> bool:
    """Both fields within TWO_FOLD_SHARE of tangent to H at a slide's end, the normal
    speeds a = grad H . F_-, b = grad H . F_+ against |grad H| |F_-|, |grad H| |F_+|
    there: a two-fold, whatever the speeds where the slide began. The sliding field is
    not Lipschitz at a two-fold (homogeneous of degree 0 about it, where the fold lines
    cross), so an integrated step across it can miss it by far more than its tolerance
    (seen: the other speed 3.7e-6 and 5.7e-5 of its size where the slide began, past
    :func:`at_two_fold`'s share, where the slide ran straight into it), and a slide that
    began next to a two-fold starts with speeds as small as that. The shares are
    cosines in the metric of the components' ``scales`` (filippov.scale; ``floor``: the
    state scale): grad H times them, the fields over them, so that they are
    independent of the units of H, of time and of each component (an ordinary fold exit
    was refused as a two-fold with y in units 1e7 smaller than x, in the Euclidean
    metric). The ratios ``scales / floor`` are powers of two, 1 for a run of one scale:
    its arithmetic is the Euclidean one's, bit for bit."""
    g2, m2, p2 = 0.0, 0.0, 0.0
    for c in range(grad.size):
        r = scales[c] / floor
        g, m, p = grad[c] * r, f_minus[c] / r, f_plus[c] / r
        g2 += g * g
        m2 += m * m
        p2 += p * p
    return at_two_fold(a, b, np.sqrt(g2 * m2), np.sqrt(g2 * p2))


def budget_projection(recent, entries: int, t: float, zeno_count: int, t_end: float):
    """At the rate of the last zeno_count switches (the Zeno ring: :func:`note_switch`),
    the time between switches and how many more come before t_end: (every, ahead);
    (nan, nan) where the ring spans no time."""
    oldest = recent[entries % zeno_count]
    if not t > oldest:
        return np.nan, np.nan
    return (t - oldest) / (zeno_count - 1), (t_end - t) * (zeno_count - 1) / (t - oldest)


def budget_runs_out(recent, entries: int, t: float, zeno_count: int, t_end: float,
                    switches: int, max_events: int) -> bool:
    """The event budget would not last to t_end at the rate of the last zeno_count
    switches (:func:`budget_projection`); asked by the loop of an engine whose record
    says it projects (:mod:`filippov.engines`, item 2)."""
    _, ahead = budget_projection(recent, entries, t, zeno_count, t_end)
    return ahead == ahead and switches + ahead > max_events


def note_switch(recent, entries: int, t: float, zeno_count: int, zeno_span: float,
                time_scale: float = 1.0):
    """The Zeno ring both engines keep: enters the switch at ``t`` in ``recent`` (an array
    of zeno_count times, entry k at k % zeno_count; ``entries`` so far) and says whether
    the last zeno_count switches, from the oldest the ring holds to ``t``, accumulate
    (:func:`accumulates`), or the switches it holds shrink geometrically to a finite time
    (:func:`geometric_accumulation`). Returns (entries, zeno)."""
    recent[entries % zeno_count] = t
    entries += 1
    if entries >= zeno_count and accumulates(recent[entries % zeno_count], t, zeno_span,
                                             time_scale):
        return entries, True
    if entries < GEOMETRIC_MIN_RATIOS + 3 or zeno_count < GEOMETRIC_MIN_RATIOS + 3:
        return entries, False
    ratio, _ = geometric_accumulation(recent, entries, zeno_count)
    return entries, ratio == ratio


#: the iteration bound of Brent's method on both engines, for an event's root and for the
#: extremum of h (or of a normal speed) between two samples alike
BRENT_MAXITER = 200


def same_instant(xtol: float, t: float) -> float:
    """Events closer than this are one instant to the solver: each root is located
    to xtol + 4 eps |t| (brentq's tolerance) and then stepped to its far side."""
    return 4.0 * (xtol + 4.0 * _EPS * abs(t))


def section_first(r: float, t_min: float, best_t: float, best_is_section: bool,
                  xtol: float) -> bool:
    """A section's root ``r`` in a sample interval comes first: not before ``t_min`` (the
    run's start plus the section's min_time), and before the event found so far in the
    interval (at ``best_t``; inf: none) -- or at its instant (:func:`same_instant`) when
    that event is a switch or an exit: a section on H is hit where the orbit arrives on
    H, before the switch, which follows at once on restart. Of two sections' hits at one
    instant the one found first stays (``best_is_section``)."""
    if r < t_min:
        return False
    return r < best_t or (not best_is_section and r <= best_t + same_instant(xtol, best_t))


#: A section crossing in the first sample interval of a run that lies within
#: START_ULPS rounding errors (eps times the largest component of the state) of the
#: start point is the start itself, put a hair before the section by rounding: not a
#: hit (ignored, not an error: a start exactly on the section is no hit either). The
#: test is in state, not in time; the crossing point is interpolated between the start
#: and the refined root; within one sample interval nothing the sampling resolves returns
#: to the start, so a periodic orbit's P(z) = z is never taken for this
#: (docs/decisions.md#start-on-section).
START_ULPS = 64


def starts_on_section(s0: float, z0, sr: float, zr, z_start, floor: float = 1.0) -> bool:
    """The start ``z0`` (section value ``s0``) lies on the section up to rounding,
    given the refined root ``zr`` (section value ``sr``); 1-D float arrays. ``z0`` is
    the first sample as the stay's stepper gives it -- for an exact flow, the closed
    form at tau = 0 from the run's start ``z_start`` (else z_start itself) --, whose
    rounding counts too, as in :func:`exit_band`: a closed form built around another
    point (z* + V e^{B tau} V^-1 (z - z*)) rounds at the scale of |z*|, not of |z|
    (docs/decisions.md#start-on-section). ``floor``: the state scale, as exit_band's."""
    # linear interpolation to the crossing; sr is on the far side, so the fraction is <= 1
    frac = min(1.0, abs(s0) / abs(s0 - sr)) if s0 != sr else 1.0
    size, moved, flow = 0.0, 0.0, 0.0
    for k in range(z0.size):
        size = max(size, abs(z0[k]), abs(zr[k]))
        moved = max(moved, abs(zr[k] - z0[k]))
        flow = max(flow, abs(z0[k] - z_start[k]))
    # a closed form that misses its start by more than exit_band accepts is no rounding
    flow = min(flow, EXIT_BAND_FLOW_MAX * max(floor, size))
    return frac * moved <= START_ULPS * max(_EPS * size, flow)


#: Probes each side of the start (2 SECTION_PROBES + 1 points) that measure the section
#: function's own rounding there: a section whose terms are large against the state puts
#: a start "on" it a hair below by more than the state's rounding, and the section is a
#: black box, so its rounding is measured, not assumed from |z|
#: (docs/decisions.md#start-on-section).
SECTION_PROBES = 8
#: Probes only for a crossing this close to the start (relative to the state): a start
#: rounding puts below a section whose terms are up to ~1e10 times the state. Over a
#: span this short s is straight far below its rounding (its curvature term s'' L^2
#: against s' L at L <= 1e-6), so a genuine crossing's change is never taken for noise.
SECTION_PROBE_REACH = 1e-6


def section_probe(z0, zr, j: int, out) -> bool:
    """Probe point j (|j| <= SECTION_PROBES) of the section's rounding at the start z0:
    ``out`` <- z0 + j steps along the straight way to the crossing zr, each step 8
    rounding units of the state or 1/SECTION_PROBES of the way, whichever is longer (the
    probes span the crossing, so a section that rounds coarsely against its change per
    unit of state shows its steps). False (``out`` untouched) when zr is beyond
    SECTION_PROBE_REACH of z0: then no rounding explains the crossing."""
    size, dist2 = _TINY, 0.0
    for k in range(z0.size):
        size = max(size, abs(z0[k]), abs(zr[k]))
        dist2 += (zr[k] - z0[k]) * (zr[k] - z0[k])
    dist = np.sqrt(dist2)
    if not dist <= SECTION_PROBE_REACH * size:
        return False
    step = max(8.0 * _EPS * size, dist / SECTION_PROBES) * j / dist if dist > 0.0 else 0.0
    for k in range(z0.size):
        out[k] = z0[k] + step * (zr[k] - z0[k])
    return True


def section_noise(worst: float, s_2: float, s_1: float, s: float) -> float:
    """One step of the section's rounding measured at consecutive probes (values s_2,
    s_1, s at probes j-2, j-1, j): the largest half second difference so far. The probes
    are equally spaced on a line, so s's straight part cancels and, over their span,
    its curvature is far below rounding: what is left is the steps of its rounding (a
    coarse staircase: half a unit at each step). Streamed so the compiled engine needs
    no array for it. A non-finite value makes it NaN."""
    d = 0.5 * abs(s - 2.0 * s_1 + s_2)
    return d if (d > worst or d != d) else worst


def on_section_by_value(s0: float, noise: float) -> bool:
    """The start's section value s0 is within START_ULPS of the section's measured
    rounding (:func:`section_noise` over the probes) of 0: the start is on the section,
    and a crossing in its first sample interval is the start itself, not a return. A
    non-finite value is no evidence (False)."""
    return abs(s0) <= START_ULPS * noise


def band_probe(r: float, step: float, lo: float, clear: bool):
    """One step of the walk back from a crossing found while the stay is still inside
    its exit's rounding band (at ``r`` H is beyond the band's far edge: the banded
    function's root, off the true crossing by band / |dH/dt|) to a point where H clears
    the band on the region's side (``clear``: whether it does at the probe r). Returns
    (done, r, step): done at a probe that clears, or at ``lo`` (the bracket's start)
    when none after it does -- then the orbit never left the band before crossing, and
    the banded root stands; else the next probe, increments doubling from 2 ulp of r.
    From a probe that clears, the crossing is refined again on H itself, so a genuine
    return soon after a fold exit is located at H = 0."""
    if clear:
        return True, r, step
    if r <= lo:
        return True, lo, step
    if step == 0.0:
        a = max(abs(r), _TINY)
        step = 2.0 * (np.nextafter(a, np.inf) - a)
    return False, max(r - step, lo), 2.0 * step


# --------------------------------------------------------- several switching surfaces
# (filippov.several: a run on a filippov.surfaces.SurfacesSystem, stay by stay)

#: an event on one surface is also on another (a corner) when that one's value there is
#: within touch_tol plus this many event tolerances' worth of its rate along the orbit:
#: the event time is refined to event_xtol, so the other surface's value at it is known
#: to |rate| event_xtol only (docs/decisions.md#several-surfaces-as-stays)
CORNER_XTOLS = 4.0


def at_corner(g: float, rate: float, xtol: float, touch_tol: float) -> bool:
    """Is a surface whose value (oriented: >= 0 on the orbit's side) is ``g`` at an
    event on another one, changing at ``rate`` there, reached at the same instant? Not
    one the orbit moves away from (rate > 0: one it has just crossed, a rounding behind
    it; the region across the event's surface may turn back to it, a switch of its own
    at that instant): such a corner was refused as one the fields do not all cross."""
    return rate <= 0.0 and abs(g) <= touch_tol + CORNER_XTOLS * abs(rate) * xtol


def left_band(g: float, speed: float, xtol: float, touch_tol: float) -> float:
    """The band a slide allows the surface it has just left at the end of a slide on an
    intersection (``g``: that surface's value there, oriented to the side the orbit
    leaves to): the slide on the intersection kept the rounding the event that began
    sliding on it left (the state a hair past it, up to what :func:`at_corner` takes,
    ``speed`` the largest normal speed of the fields meeting there), which reads as a
    crossing back at the next stay's first sample where it exceeds touch_tol. 0 where g
    is on the orbit's side; NaN (refuse) where it is short by more than such a rounding."""
    if g >= 0.0:
        return 0.0
    if -g <= touch_tol + CORNER_XTOLS * abs(speed) * xtol:
        return -g
    return math.nan


def through_corner(speeds) -> bool:
    """The corner rule: an orbit that reaches several surfaces at once goes straight
    through into the region across all of them when every field of the regions that
    meet there crosses every one of those surfaces in the orbit's direction
    (``speeds``: each region's field along each surface's normal, oriented to the
    orbit's side, flat; < 0 toward the far side): then every Filippov solution crosses
    them, and only that one goes on. Anything else (a field that turns back: sliding on
    a surface or their intersection, or a choice between regions) is not settled by
    this rule."""
    for v in speeds:
        if not v < 0.0:
            return False
    return True


def slide_crosses(a_far: float, b_far: float, v_near: float, v_far: float) -> bool:
    """A slide on one surface that reaches another goes on across it, sliding on the
    first beyond, when the first attracts beyond (``a_far > 0 > b_far``: the normal
    speeds of the fields beside it in the far regions, as :func:`next_mode` reads them)
    and both sliding fields, this side's and the far side's, cross the second surface
    toward the far side (``v_near``, ``v_far`` < 0 along its normal oriented to this
    side): on the first surface the orbit is a one-surface Filippov system that crosses
    there. Anything else (a slide that leaves there, or one along the intersection) is
    not settled by this rule."""
    return a_far > 0.0 > b_far and v_near < 0.0 and v_far < 0.0


def slides_into_intersection(v_near: float, v_far: float) -> bool:
    """A slide on one surface that reaches another slides on their intersection when the
    sliding fields on either side of the second push toward it (``v_near`` < 0 < ``v_far``,
    along its normal oriented to the near side): on the first surface the intersection
    attracts as a surface of Filippov's, one dimension down."""
    return v_near < 0.0 < v_far


#: the bilinear sliding field on an intersection and the two nested choices agree when
#: they differ by at most this much relative to the field: the system settles the field
#: there (a decoupled system's agree to rounding, ~1e-16)
CHOICE_AGREES = 1e-9


def choices_agree(spread: float, size: float) -> bool:
    """Do the choices of a sliding field on an intersection differ by at most
    CHOICE_AGREES of the field's size (``spread``: the largest difference)?"""
    return spread <= CHOICE_AGREES * max(size, 1e-300)
