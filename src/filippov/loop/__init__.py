"""The event loop's structure, written once for both engines.

:mod:`filippov.rules` holds each decision (which side, which mode, which tie); this
package holds the order in which the loop asks them -- at the start and before each
stay (:mod:`~filippov.loop.stay`), in a sample interval and over a window
(:mod:`~filippov.loop.interval`), from a crossing to its event time
(:mod:`~filippov.loop.refine`),
the run, stay after stay, and at each event against the budgets
(:mod:`~filippov.loop.event`) -- as plain scalar
Python built from the engine's own
operations (how it steps, samples, refines and stores). The reference driver
(:mod:`filippov.simulate`) runs these functions as they are, with its Python
operations; the compiled kernel (:mod:`filippov.kernel`) compiles the same functions
with numba, with its compiled operations. What still differs between the engines is
listed, each with its reason and its test, in :mod:`filippov.engines`.
"""
