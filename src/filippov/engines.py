"""Which engine runs what, and what differs between the engines, and why.

**The choice.** The front doors :func:`filippov.simulate`, :func:`filippov.first_returns`
and :func:`filippov.periodic_orbit` take a system and ``engine=``: ``"reference"`` (the
Python driver, :mod:`filippov.simulate`) or ``"compiled"`` (numba: :mod:`filippov.fastmap`,
:mod:`filippov.kernel`). This module is the one place that maps them to what runs:
:data:`RUNS` (capability x engine -> function, or None with its reason in :data:`LACKS`:
the compiled engine has no trajectory output), :func:`runner`, and the system each engine
runs -- :func:`reference_system` (a PiecewiseSystem, or the ``python()`` view of a
system defined once) and :func:`compiled_model` (a CompiledModel, or the ``compiled()``
view with the caller's section). A PiecewiseSystem asked for the compiled engine, a
CompiledModel for the reference one, or an unknown engine is an error naming the field.
Each front door keeps its default engine (simulate and first_returns: reference;
periodic_orbit: compiled).

**The differences.**

The reference driver (:mod:`filippov.simulate`) and the compiled engine
(:mod:`filippov.fastmap`, :mod:`filippov.kernel`) take every decision from one rule book
(:mod:`filippov.rules`), and the event loop's structure is written once, beside it, in
:mod:`filippov.loop` (the reference runs it as Python, the kernel compiles it, each
with its own operations). Over a window both walk its candidate intervals in
time order with one function (``make_window_event``: the exit's rounding band ended at
the first candidate whose start is out of it, ``rules.clears_band``, and that interval
asked again, or at the last sample of a window with no event; a switch found beyond
the band refined again on H, ``make_past_band``), each finding its candidates its own
way (the reference with array operations, the kernel with scalars). In a sample
interval both run one event search, :mod:`filippov.loop.interval`, which asks in one
order -- the crossing of H (or of a or b while sliding), the end of sliding hidden
between the samples, then a hidden extremum of H, then each section, whose root at the
instant of a switch wins the tie (``rules.section_first``) -- each engine answering with
its own samples and root finder; a crossing becomes an event time by one function,
:mod:`filippov.loop.refine` (a sample exactly on it, the bracketing root, an event at
once where a clamped start is already past it, then the walk to its far side). What is
done at an event is written once, in the run's loop both engines run,
:mod:`filippov.loop.event`:
the decision (``rules.next_mode``), sliding the system does not build, the refusal to
slide inside a section at an arrival on H, the fold exit (``rules.exit_drift``,
``onto_switch``, ``exit_band``, ``exit_shift``), the switch counted against
``max_events`` before the Zeno ring (``rules.accumulates`` over the last ``zeno_count``
switches: one array ring, ``rules.note_switch``), then the
engine's own budget verdict (item 2). The start is one function too,
:mod:`filippov.loop.stay` (the start mode, ``rules.start_side`` and
``rules.start_on_switch``, and the refusal to slide inside a section, whose test
``make_slides_in`` is shared with the event), and so is the check before each stay (the
run's end time; sliding the system does not build), asked by the run. A stay is written
in the run's loop too: its start, then step by step the step, its windows (the step
searched window by window, ``loop.stay.make_step_windows``: the first the whole step,
shorter ones where its samples do not resolve what they sample) and the step's end,
each engine answering with its own stepper. Both share one
set of status codes (:mod:`filippov.loop.status`), and one table turns a status into its
exception class and message (:func:`filippov.errors.run_error`, item 10). The
rest they ask in the same order on each side: the hard bound ``max_steps``
(``rules.step_budget_spent``: integration steps, or exact-flow windows, counted alike); a
start on the section up to rounding (``rules.starts_on_section``, the probes of
``rules.section_probe``); the exact-flow check
(``rules.flow_consistent``); non-finite states and fields (an error, or a status; on an
integration step the guard of ``rules.NON_FINITE_STAGE``);
the options (:mod:`filippov.options`, one check for both). What remains different is
listed here, each entry with its reason and the test that pins it; a change of either
engine that moves one of these makes its test fail.

1. **Samples of an exact flow.** The compiled engine samples an exact-flow window
   once per ``sample_step`` (the model's declared resolution); the reference
   ``samples_per_step`` times more densely, since its samples are also the stored
   trajectory. Deliberate (cost: the kernel's work is its samples); results agree to
   rounding, not bit for bit. ``samples_per_step`` counts the samples of an
   integration step only on the compiled engine.
   Test: tests/test_engine_asymmetries.py::test_the_compiled_engine_scans_exact_flows_once_per_sample_step

2. **The event budget projected from the switching rate.** At each switch past the
   Zeno ring's ``zeno_count``, the reference projects the rate of the last ones to
   ``t_end`` and stops (EventLimitError, "switching every ...") when it would exceed
   ``max_events``; the compiled engine has the hard bound only (its ``over_budget``
   operation of the shared event says no). Deliberate: the
   projection saves minutes of a Python run that will hit the bound anyway; the kernel
   gets there in milliseconds, and a return ends at the section, often long before
   ``t_max``, where a projection to ``t_max`` refuses a return that would have come.
   Test: tests/test_engine_asymmetries.py::test_the_event_budget_is_projected_by_the_reference_engine_only

3. **The step budget projected from the mean step.** After ``PROJECT_AFTER`` steps of
   one stepper the reference projects its mean step to ``t_end`` and stops when the
   steps would exceed ``max_steps``; the compiled engine has the hard bound only
   (status STEP_LIMIT). Deliberate, as 2.
   Test: tests/test_engine_asymmetries.py::test_the_step_budget_is_projected_by_the_reference_engine_only

4. **Stiff stays.** The reference continues an integrated stay whose DOP853 steps are
   bounded by stability with the implicit Radau IIA (``stiff=True``, every
   ``STIFF_AFTER`` steps; its atol kept above the field's noise); the kernel has DOP853
   only (no ``stiff`` option), so a stiff stay costs steps up to ``max_steps``.
   Deliberate: the implicit method is not ported to the kernel (exact flows carry the
   stiff regions of the paper's models).
   Tests: tests/test_engine_asymmetries.py::test_the_compiled_engine_has_no_stiff_switch,
   tests/test_reliability.py::test_integrating_a_stiff_field_switches_to_radau_with_a_note

5. **The pinned-bracket fallback.** The reference samples with array evaluations
   (numpy's loops) and refines with scalar ones, which may round differently: where the
   scalar ends lost the sign change the samples saw, ``simulate._brent`` keeps the
   sampled end values (its ``lost_bracket`` in :mod:`filippov.loop.refine`). The kernel
   samples and refines through the same compiled scalar
   code (``kernel.scan._sample`` and ``kernel.segment._fval``), so its ends agree with
   its samples bit for bit and it has no fallback: a bracket that fails is status
   ROOT_FAILED (a SimulationError), and the re-refinement after the band probe or at
   the dip after an entry keeps the first root where it fails. Deliberate (nothing to
   pin on the kernel side but the one code path).
   Test: tests/test_solver_events.py::test_a_sign_change_the_samples_saw_survives_refinement

6. **Brent's iteration bound (fixed).** The kernel bounded the extremum's bracket at 100
   iterations (scipy's default) where the reference's ``_brent`` allows 200, under a
   comment that called 100 the reference's. A defect: both now take
   ``rules.BRENT_MAXITER``.
   Test: tests/test_engine_asymmetries.py::test_both_engines_give_brent_the_same_iteration_bound

7. **Sliding time of a start that slides (a defect, fixed).** The compiled engine
   counted the slide a start on H begins in; the reference's ``poincare.sliding_time``
   opened a stretch at a ``slide_start`` event only and reported 0. A ``start`` event in
   sliding now opens one too: both count it (fig11, the one dataset that uses it, is
   unchanged bit for bit: its returns never start sliding).
   Test: tests/test_engine_asymmetries.py::test_a_start_that_slides_counts_its_first_slide_on_both_engines

8. **Iterated returns and sections.** The reference follows several sections, counts
   non-terminal hits and goes on in the same mode after one, and logs every event
   (touches, starts) in a Trajectory; the compiled engine has one terminal section and
   returns only, and an iterated return (``iterations``) starts from the last hit as a
   start does (``rules.start_side``/``start_on_switch``), carrying its time in the
   region (``rules.carried_age``, ``start_age``), where the reference's
   ``first_returns`` starts each return's exact-flow windows afresh. Deliberate (the
   kernel computes return maps; results agree to rounding).
   Tests: tests/test_attractors.py::test_iterating_in_one_call_is_chaining_first_returns,
   tests/test_attractors.py::test_a_carried_age_skips_only_the_scan_of_a_transient_that_has_decayed

9. **Exact sliding flows.** Under ``method="exact"`` the reference uses a system's
   ``flows[SLIDING]`` if it has one; the compiled model has no sliding flow piece
   (:data:`filippov.abi.PIECES`) and integrates every slide. Deliberate (a piece the
   kernel's one signature would have to carry for every model).
   Test: tests/test_engine_asymmetries.py::test_the_compiled_model_has_no_sliding_flow

10. **Failures.** The reference raises where a run fails; the compiled engine gives each
    start a status and goes on with the batch, and its front door raises the first
    failure. Both turn a status into its exception through one table,
    :func:`filippov.errors.run_error` (the class, the status's words, where), so a
    status gives the same class and words on both; the detail after them is each
    engine's own. Deliberate (one failing start must not lose a batch).
    Tests: tests/test_errors.py::test_the_compiled_engine_s_failures_are_the_reference_driver_s_classes,
    tests/test_end_status.py::test_a_status_raises_the_same_class_and_words_on_both_engines

11. **dP/dz of a return that starts sliding.** Where a return starts on H and slides
    (a section across a sliding arc, a start with h = 0 there), the kernel leaves dP/dz
    NaN (status OK: the return is made, its derivative is not); the reference derives it
    from the variational equations along the sliding flow, after the projection a
    perturbation off H meets on its way back onto it.
    ``periodic_orbit`` on the compiled engine refuses such an orbit by name
    (PeriodicOrbitError, "dP/dz is not finite") instead of taking a Newton step from
    NaN. Not ported: the kernel carries no derivative along a slide it starts in.
    Test: tests/test_engine_asymmetries.py::test_dpdz_of_a_return_that_starts_sliding_is_the_reference_engine_s_only
12. **The rounding below which samples need not resolve a function.** Both engines ask
    rules.resolves whether a step's samples resolve h (a and b while sliding) and the
    sections, with misses under 64 ulps of the samples taken for rounding. Where a
    window fails that, the reference measures the rounding at its samples (the
    function's changes when each state component moves by 4 ulps; the smallest over the
    samples) and judges again above it: a and b of a stiff slide carry the state's
    rounding times the fast rate (1e-7 of a = 0.5 at eps = 1e-9), and Radau IIA's long
    steps on such a slide were split down to 1/4096 on every step (10 to 25 times the
    time). The compiled engine steps explicitly, at the stability limit, where that
    rounding is not what fails its windows, and keeps the kernel free of the probes: it
    may split a window the reference does not, never the reverse. Test: tests/test_engine_asymmetries.py::test_the_reference_measures_the_rounding_a_function_carries
"""
from __future__ import annotations

import sys

#: the engines, by the name the front doors' ``engine=`` takes
REFERENCE, COMPILED = "reference", "compiled"
ENGINES = (REFERENCE, COMPILED)

# What runs each front door on each engine. Each is a function here that imports its
# module when first called, so that the reference engine never imports numba and the
# compiled one never imports scipy's integrators it does not use (filippov.__init__).

def _simulate_reference(system, z0, sections, opts):
    from .simulate import _simulate
    return _simulate(system, z0, sections, opts)


def _first_returns_reference(*args, **kwargs):
    from .poincare import _first_returns
    return _first_returns(*args, **kwargs)


def _first_returns_compiled(*args, **kwargs):
    from .fastmap import _first_returns
    return _first_returns(*args, **kwargs)


def _periodic_reference(*args, **kwargs):
    from .periodic import _reference_return
    return _reference_return(*args, **kwargs)


def _periodic_compiled(*args, **kwargs):
    from .periodic import _compiled_return
    return _compiled_return(*args, **kwargs)


#: what runs each front door on each engine, or None where the engine lacks that output
#: (the reason is in :data:`LACKS`)
RUNS = {
    "simulate": {REFERENCE: _simulate_reference, COMPILED: None},
    "first_returns": {REFERENCE: _first_returns_reference, COMPILED: _first_returns_compiled},
    "periodic_orbit": {REFERENCE: _periodic_reference, COMPILED: _periodic_compiled},
}

LACKS = {
    ("simulate", COMPILED): (
        "the compiled engine has no trajectory output: it computes returns to a section "
        "(state, time, switches, sliding time), not the events, samples and dense output "
        "of a Trajectory; use engine='reference' for a trajectory, or "
        "first_returns(..., engine='compiled') for returns"),
}

_HOW_TO_COMPILE = (
    "build a filippov.FilippovSystem from plain functions of (z, p) (or a "
    "filippov.SymbolicSystem from SymPy expressions), which runs on both engines")


def checked(engine) -> str:
    """``engine`` if it names an engine, else a ValueError naming ``engine``."""
    if not (isinstance(engine, str) and engine in ENGINES):
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    return engine


def runner(capability: str, engine):
    """The function that runs ``capability`` (a key of :data:`RUNS`) on ``engine``: the
    one place where the engine is chosen."""
    target = RUNS[capability][checked(engine)]
    if target is None:
        raise ValueError(f"engine={engine!r}: {capability} is not available on this "
                         f"engine: {LACKS[capability, engine]}")
    return target


def _is_compiled_model(system) -> bool:
    abi = sys.modules.get(f"{__package__}.abi")  # no CompiledModel without it imported
    return abi is not None and isinstance(system, abi.CompiledModel)


def reference_system(system, capability: str):
    """The :class:`~filippov.system.PiecewiseSystem` the reference driver runs for
    ``system``: itself, or the ``python()`` view of a system defined once
    (:class:`~filippov.FilippovSystem`, :class:`~filippov.SymbolicSystem`)."""
    from .system import PiecewiseSystem

    if isinstance(system, PiecewiseSystem):
        return system
    if _is_compiled_model(system):
        raise TypeError(f"system: {capability}(engine='reference') cannot run a "
                        "CompiledModel (numba pieces for the compiled engine only); "
                        f"use engine='compiled', or {_HOW_TO_COMPILE}")
    view = getattr(system, "python", None)
    if callable(view):
        return view()
    raise TypeError(f"system: {capability} expected a PiecewiseSystem, a FilippovSystem "
                    f"or a SymbolicSystem, got {type(system).__name__}")


def compiled_model(system, capability: str, section=None, *, direction: int = 0,
                   where=None):
    """The :class:`~filippov.abi.CompiledModel` the compiled engine runs for ``system``
    with the section ``section(z, p) = 0`` (None: a CompiledModel's own section)."""
    from .system import PiecewiseSystem

    if isinstance(system, PiecewiseSystem):
        raise TypeError(f"system: {capability}(engine='compiled') cannot run a "
                        "PiecewiseSystem (Python functions the compiled kernel cannot "
                        f"call); {_HOW_TO_COMPILE}, or use engine='reference'")
    if _is_compiled_model(system):
        if section is None:
            return system
        from .compiled_system import with_section

        return with_section(system, _section_function(section, capability),
                            direction=direction, where=where)
    build = getattr(system, "compiled", None)
    if not callable(build):
        raise TypeError(f"system: {capability}(engine='compiled') expected a "
                        f"FilippovSystem, a SymbolicSystem or a CompiledModel, got "
                        f"{type(system).__name__}")
    if section is None:
        raise TypeError(f"section: {capability}(engine='compiled') of a "
                        f"{type(system).__name__} needs a section s(z, p) -> float")
    return build(_section_function(section, capability), direction=direction, where=where)


def _section_function(section, capability: str):
    from .simulate import Section

    if isinstance(section, Section):
        raise TypeError(f"section: {capability}(engine='compiled') takes the section as "
                        f"a function s(z, p) -> float (compiled with the system's "
                        f"pieces), not a Section of the reference driver")
    return section
