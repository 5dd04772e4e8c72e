"""A run's stays -- when a stay may begin, the test of a slide inside a section (the
run's refusal at the start and at an arrival on H: :mod:`filippov.loop.event`), the walk
over a step's windows, a slide's failed step at a two-fold -- written once for both
engines.

Like :mod:`filippov.loop.event` this is plain scalar Python in the subset numba
compiles: the reference driver (:mod:`filippov.simulate`) calls these functions as they
are, with its Python operations; the compiled kernel (:mod:`filippov.kernel.driver`)
compiles them inlined, with its compiled operations (:func:`before_stay`, which the run
asks by its name, as a rule: compiled into its caller). A function built from operations
(:func:`make_slides_in`) takes the engine's state ``ctx`` last, as the run's operations
do.
"""
from __future__ import annotations

from .. import rules
from ..system import MINUS, PLUS, SLIDING
from .status import GO_ON, NON_FINITE, NO_RETURN, NO_SLIDING, STEP_FAILED, TWO_FOLD


def before_stay(mode, t, t_end, sliding):
    """May a stay in ``mode`` begin at ``t``? GO_ON; NO_RETURN at the run's end time
    (the reference's end of its trajectory, the kernel's t_max); NO_SLIDING for a slide
    the system does not build."""
    if t >= t_end:
        return NO_RETURN
    if mode == SLIDING and not sliding:
        return NO_SLIDING
    return GO_ON


def make_failed_step(pieces):
    """``failed_step(status, mode, ctx) -> status``: why a stay's step did not come, as
    the run reports it -- TWO_FOLD where a slide's step failed (STEP_FAILED, or
    NON_FINITE: the sliding field is 0/0 there) with both fields tangent to H at the
    state the engine holds (rules.tangent_to_both): a slide into a two-fold, where the
    steps of its field, not Lipschitz there, collapse before any exit is found; else the
    status as it is. The engine's operation: ``pieces(ctx)`` at that state -- the
    reference's, the step's start; the kernel's, the step's start, or after NON_FINITE
    the stage's state that was not finite (kernel.dop853._non_finite_stage), nearer the
    two-fold."""

    def failed_step(status, mode, ctx):
        if mode == SLIDING and (status == STEP_FAILED or status == NON_FINITE):
            pc = pieces(ctx)
            if rules.tangent_to_both(pc.a, pc.b, pc.grad, pc.f_minus, pc.f_plus, pc.scales,
                                     pc.floor):
                return TWO_FOLD
        return status
    return failed_step


def make_slides_in(pieces, section_along):
    """``slides_in(k, ctx) -> bool``: does the sliding flow at the state (on H) stay in
    section k? rules.slides_in_section from the section's value there and its rates along
    F_-, F_+ and the sliding field, by central differences of the step rules.central_step
    gives (0: no). The engine's operations: ``pieces(ctx)``, the pieces at the state
    (filippov.loop.event.Pieces: z, F_-, F_+ and the run's state scale read here);
    ``section_along(k, mode, d, ctx)``: section k at z + d times the field of ``mode``
    (MINUS, PLUS, SLIDING; d = 0: at z)."""

    def slides_in(k, ctx):
        pc = pieces(ctx)
        z, fm, fp, floor = pc.z, pc.f_minus, pc.f_plus, pc.floor
        speed, size = 0.0, floor
        for c in range(z.size):
            speed = max(speed, abs(fm[c]), abs(fp[c]))
            size = max(size, abs(z[c]))
        d = rules.central_step(size, speed)
        if d == 0.0:
            return False
        rate_m = (section_along(k, MINUS, d, ctx) - section_along(k, MINUS, -d, ctx)) / (2.0 * d)
        rate_p = (section_along(k, PLUS, d, ctx) - section_along(k, PLUS, -d, ctx)) / (2.0 * d)
        rate_s = (section_along(k, SLIDING, d, ctx)
                  - section_along(k, SLIDING, -d, ctx)) / (2.0 * d)
        return rules.slides_in_section(section_along(k, SLIDING, 0.0, ctx), d, rate_m,
                                       rate_p, rate_s)
    return slides_in


#: a window whose samples do not resolve what is sampled on it (rules.resolves): not
#: searched; the step's walk shortens it (never a run's status)
UNRESOLVED = -2


def make_step_windows(window):
    """``walk(mode, ta, tb, first, ctx) -> (status, t, what)``: a step [ta, tb] searched
    window by window, the first the whole step. A window whose samples do not resolve its
    leave functions or sections is shortened by rules.SPLIT and sampled again, down to a
    rules.SPLIT ** rules.MAX_SPLITS-th of the step (rules.can_split); a resolved window
    without an event hands on to the next, rules.SPLIT times longer (to the step's end at
    most). The engine's operation: ``window(mode, t0, t1, first, may_split, ctx) ->
    (status, t, what)``, its status UNRESOLVED (only when ``may_split``, and never for an
    exact flow's step: the model's own window), GO_ON (no event: the orbit goes on from
    t1) or the event's. With UNRESOLVED, t is t0, or the time of a sample that was not
    finite, the window cut there: the windows then end there at the latest until one
    has reached it (the shorter windows' samples could step over a thin band of the
    field's edge the cut met), the window to it no longer than the last one searched
    (rules.to_cut: docs/decisions.md#past-a-non-finite-sample)."""

    def walk(mode, ta, tb, first, ctx):
        # cap: where the windows end at the latest (a cut's time, else tb); last: the
        # length of the last window searched
        t0, t1, cap, cut, last = ta, tb, tb, False, 0.0
        while True:
            split = True
            if cut and t1 == cap:  # a window to the cut (rules.to_cut)
                t1, split = rules.to_cut(t0, cap, last)
            st, t, what = window(mode, t0, t1, first,
                                 split and rules.can_split(ta, tb, t0, t1), ctx)
            if st == UNRESOLVED:
                if t > t0:
                    cap, cut = min(cap, t), True
                t1 = rules.window_end(t0, (t1 - t0) / rules.SPLIT, cap)
            elif st != GO_ON or t1 >= tb:
                return st, t, what
            else:
                if t1 >= cap:  # the cut's sample reached, finite this time: on to tb
                    cap, cut = tb, False
                last = t1 - t0
                t0, t1, first = t1, rules.window_end(t1, (t1 - t0) * rules.SPLIT, cap), False
    return walk
