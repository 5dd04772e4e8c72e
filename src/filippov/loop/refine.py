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

Plain scalar Python in the subset numba compiles: the reference runs it with its
callables, the kernel compiles it with its selectors of the segment's functions.
"""
from __future__ import annotations

import math

from .. import rules


def make_refine(root, value_at):
    """``refine(ctx, f, pred, ta, tb, va, vb, mode) -> (ok, r)``: the event time of f's
    sign change ``pred`` between ta and tb (this module's docstring), from the engine's
    operations on its state ``ctx``:

    * ``root(ctx, f, ta, tb, vlo, vhi, mode) -> (ok, r, fr)``: f's root in [ta, tb] and
      f's value there (the one the root finder evaluated last); not ok when f at the
      ends shows no sign change, unless the samples' values vlo, vhi are handed (NaN:
      none) and the engine pins the bracket to them (loop.interval.WindowOps);
    * ``value_at(ctx, f, t, mode)``: f at t.
    """

    def refine(ctx, f, pred, ta, tb, va, vb, mode):
        pred = rules.far_side(pred, va)
        if va == 0.0:
            r = ta
            fr = value_at(ctx, f, r, mode)
        else:
            ok, r, fr = root(ctx, f, ta, tb, math.nan, math.nan, mode)
            if not ok:
                fa = value_at(ctx, f, ta, mode)
                if rules.after(pred, fa):  # clamped start, true value past: at once
                    r, fr = ta, fa
                else:
                    ok, r, fr = root(ctx, f, ta, tb, va, vb, mode)
                    if not ok:
                        return False, r
        done, step = False, 0.0
        while not done:  # to the far side of the crossing (rules.far_side_probe)
            done, r, step = rules.far_side_probe(r, step, tb, rules.after(pred, fr))
            if not done:
                fr = value_at(ctx, f, r, mode)
        return True, r

    return refine
