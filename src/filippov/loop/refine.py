"""The refinement of a sign change to an event time, written once for both engines.

The scan saw a function f change sign between two samples ta < tb (va at ta, vb at
tb). Its event time r is:

1. ta itself when va is exactly 0 (the crossing is there);
2. else the engine's bracketing root of f on [ta, tb] (scipy's brentq; the kernel's port
   of it, bit for bit the same steps);
3. when f at the ends shows no sign change, ta if f(ta) is already past the crossing: the
   start sample of a just-entered mode was clamped inside while the true value is a
   hair past it, so the event is at once; else the engine's root finder asked again with
   the samples' values va, vb handed (the reference pins the bracket's ends to them, the
   kernel fails: :mod:`filippov.engines`, item 5);
4. then walked to the far side of the crossing (``rules.far_side``, ``far_side_probe``):
   a root finder may stop a hair before the sign flips.

A value of f that is not finite where the root finder or the walk evaluated it ends the
refinement with CUT and that time: the window is searched up to there as past a sample
that is not finite (docs/decisions.md#past-a-non-finite-sample), not decided on a NaN.

Plain scalar Python in the subset numba compiles: the reference runs it with its
callables, the kernel compiles it with its selectors of the segment's functions.
"""
from __future__ import annotations

import math

from .. import rules
from .status import CUT, OK, ROOT_FAILED


def make_refine(root, value_at):
    """``refine(ctx, f, pred, ta, tb, va, vb, mode) -> (status, r)``: the event time of
    f's sign change ``pred`` between ta and tb (this module's docstring): OK, or
    ROOT_FAILED, or CUT where f was not finite at r; from the engine's operations on its
    state ``ctx``:

    * ``root(ctx, f, ta, tb, vlo, vhi, mode) -> (ok, r, fr)``: f's root in [ta, tb] and
      f's value there (the one the root finder evaluated last; not ok with fr NaN where
      f was not finite at r); not ok when f at the ends shows no sign change, unless the
      samples' values vlo, vhi are handed (NaN: none) and the engine pins the bracket to
      them (loop.interval.WindowOps);
    * ``value_at(ctx, f, t, mode)``: f at t (NaN where it is not finite).
    """

    def refine(ctx, f, pred, ta, tb, va, vb, mode):
        pred = rules.far_side(pred, va)
        if va == 0.0:
            r = ta
            fr = value_at(ctx, f, r, mode)
        else:
            ok, r, fr = root(ctx, f, ta, tb, math.nan, math.nan, mode)
            if not ok:
                if not math.isfinite(fr):
                    return CUT, r
                fa = value_at(ctx, f, ta, mode)
                if rules.after(pred, fa):  # clamped start, true value past: at once
                    r, fr = ta, fa
                else:
                    ok, r, fr = root(ctx, f, ta, tb, va, vb, mode)
                    if not ok:
                        return (CUT if not math.isfinite(fr) else ROOT_FAILED), r
        done, step = False, 0.0
        while not done:  # to the far side of the crossing (rules.far_side_probe)
            if not math.isfinite(fr):
                return CUT, r
            done, r, step = rules.far_side_probe(r, step, tb, rules.after(pred, fr))
            if not done:
                fr = value_at(ctx, f, r, mode)
        return OK, r

    return refine
