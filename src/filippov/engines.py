"""Which engine runs what, and what differs between the engines, and why.

**The choice.** The front doors :func:`filippov.simulate`, :func:`filippov.first_returns`
and :func:`filippov.periodic_orbit` take a system and ``engine=``: ``"reference"`` (the
Python driver, :mod:`filippov.simulate`) or ``"compiled"`` (numba: :mod:`filippov.fastmap`,
:mod:`filippov.kernel`). Each front door maps them to what runs in a table of its own,
next to it, and this module shows them in one place:
:data:`RUNS` (capability x engine -> function, or None with its reason in :data:`LACKS`:
the compiled engine has no trajectory output), gathered from the front doors' own tables
(``filippov.simulate.RUNS``, ``filippov.poincare.RUNS``, ``filippov.periodic.RUNS``), and
:func:`runner`. The system each engine runs -- :func:`reference_system` (a
PiecewiseSystem, or the ``python()`` view of a system defined once) and
:func:`compiled_model` (a CompiledModel, or the ``compiled()`` view with the caller's
section) -- comes from :mod:`filippov.views`, at the bottom of the library: this module
is at its top, and nothing in the library imports it (tests/test_import_graph.py). A
PiecewiseSystem asked for the compiled engine, a CompiledModel for the reference one, or
an unknown engine is an error naming the field.
Each front door keeps its default engine (simulate and first_returns: reference;
periodic_orbit: compiled).

**The differences.**

The reference driver (:mod:`filippov.simulate`) and the compiled engine
(:mod:`filippov.fastmap`, :mod:`filippov.kernel`) take every decision from one rule book
(:mod:`filippov.rules`), and the event loop's structure is written once, beside it, in
:mod:`filippov.loop` (the reference runs it as Python, the kernel compiles it, each
with its own operations). Over a window both run one event search,
:mod:`filippov.loop.interval` (``make_window_event``), which takes every decision of it
from what the engine reports (the window seam, ``contracts.WindowOperations``: the
samples of the window's functions, their values and roots between samples, a touch, the
band's end): the intervals where a sign change shows, in time order (the reference sends
it to the next candidate its array operations found, ``candidate_mask``; the kernel
tests each); the exit's rounding band ended at the first of them whose start is out of
it (``rules.clears_band``) and that interval asked again, or at the last sample of a
window with no event; then in one order -- the crossing of H (or of a or b while
sliding; after an entry at H beyond its dip, and a switch found beyond the band refined
again on H, ``make_leave_root``), the extremum of H or of a, b hidden between the
samples (``rules.graze``, ``rules.speed_graze``), then each section, whose root at the
instant of a switch wins the tie (``rules.section_first``); a crossing becomes an event time by one function,
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
:func:`filippov.loop.event.make_start` (the start mode, ``rules.start_side`` and
``rules.start_on_switch``, and the refusal to slide inside a section, whose test
``make_sliding_section`` the run asks at an arrival on H too), and so is the check before each stay (the
run's end time; sliding the system does not build) and the step budget before each step
(the hard bound ``max_steps``, ``rules.step_budget_spent`` in
:func:`filippov.loop.run_state.count_step`: integration steps, or exact-flow windows,
counted alike), asked by the run. A stay is written
in the run's loop too: its start, then step by step the step, its windows (the step
searched window by window, ``loop.stay.make_step_windows``: the first the whole step,
shorter ones where its samples do not resolve what they sample) and the step's end,
each engine answering with its own stepper. Both share one
set of status codes (:mod:`filippov.loop.status`), and one table turns a status into its
exception class and message (:func:`filippov.errors.run_error`, item 10). The
rest they ask in the same order on each side: a start on the section up to rounding (``rules.starts_on_section``, the probes of
``rules.section_probe``); the exact-flow check
(``rules.flow_consistent``); non-finite states and fields (an error, or a status; on an
integration step the guard of ``rules.NON_FINITE_STAGE``);
the options (:mod:`filippov.options`, one check for both). What remains different is
data, :data:`ASYMMETRIES` (rendered below as a table): each entry with what each engine
does, why, and the tests that pin it; a change of either engine that moves one of these
makes its test fail.
"""
from __future__ import annotations

from dataclasses import dataclass

from .periodic import RUNS as _PERIODIC_RUNS
from .poincare import RUNS as _FIRST_RETURNS_RUNS
from .simulate import RUNS as _SIMULATE_RUNS
from .views import (COMPILED, ENGINES, LACKS, REFERENCE, checked,  # noqa: F401  (re-exported)
                    compiled_model, pick, reference_system)

#: what runs each front door on each engine, or None where the engine lacks that output
#: (the reason in :data:`LACKS`): the front doors' own tables, in one place
RUNS = {"simulate": _SIMULATE_RUNS, "first_returns": _FIRST_RETURNS_RUNS,
        "periodic_orbit": _PERIODIC_RUNS}


def runner(capability: str, engine):
    """The function that runs ``capability`` (a key of :data:`RUNS`) on ``engine``."""
    return pick(RUNS[capability], capability, engine)


@dataclass(frozen=True)
class Asymmetry:
    """One way the engines differ: what each does, whether that is ``"deliberate"`` or a
    ``"defect, fixed"`` (kept on the list with its test, so that it stays fixed), why, and
    the tests (``file::name``) that pin it."""

    number: int
    title: str
    reference: str
    compiled: str
    verdict: str
    why: str
    tests: tuple


#: what still differs between the engines (the table of this module's documentation)
ASYMMETRIES = (
    Asymmetry(
        1, "Samples of an exact flow",
        "``samples_per_step`` samples per ``sample_step``: its samples are also the stored "
        "trajectory",
        "one sample per ``sample_step`` (the model's declared resolution); "
        "``samples_per_step`` counts the samples of an integration step only",
        "deliberate", "the kernel's work is its samples; results agree to rounding, not "
        "bit for bit",
        ("tests/test_engine_asymmetries.py::test_the_compiled_engine_scans_exact_flows_once_per_sample_step",)),
    Asymmetry(
        2, "The event budget projected from the switching rate",
        "at each switch past the Zeno ring's ``zeno_count``, projects the rate of the last "
        "ones to ``t_end`` and stops (EventLimitError, \"switching every ...\") when it "
        "would exceed ``max_events``",
        "the hard bound only (its run record says ``projects_budget = False``: "
        "filippov.loop.run_state)",
        "deliberate", "the projection saves minutes of a Python run that will hit the "
        "bound anyway; the kernel gets there in milliseconds, and a return ends at the "
        "section, often long before ``t_max``, where a projection to ``t_max`` refuses a "
        "return that would have come",
        ("tests/test_engine_asymmetries.py::test_the_event_budget_is_projected_by_the_reference_engine_only",)),
    Asymmetry(
        3, "The step budget projected from the mean step",
        "after ``PROJECT_AFTER`` steps of one stepper, projects its mean step to ``t_end`` "
        "and stops when the steps would exceed ``max_steps``",
        "the hard bound only (status STEP_LIMIT)",
        "deliberate", "as 2",
        ("tests/test_engine_asymmetries.py::test_the_step_budget_is_projected_by_the_reference_engine_only",)),
    Asymmetry(
        4, "Stiff stays",
        "continues an integrated stay whose DOP853 steps are bounded by stability with the "
        "implicit Radau IIA (``stiff=True``, every ``STIFF_AFTER`` steps; its atol kept "
        "above the field's noise)",
        "DOP853 only (no ``stiff`` option): a stiff stay costs steps up to ``max_steps``",
        "deliberate", "the implicit method is not ported to the kernel (exact flows carry "
        "the stiff regions of the paper's models)",
        ("tests/test_engine_asymmetries.py::test_the_compiled_engine_has_no_stiff_switch",
         "tests/test_reliability.py::test_integrating_a_stiff_field_switches_to_radau_with_a_note")),
    Asymmetry(
        5, "The pinned-bracket fallback",
        "samples with array evaluations (numpy's loops) and refines with scalar ones, which "
        "may round differently: where the scalar ends lost the sign change the samples saw, "
        "``simulate._brent`` keeps the sampled end values (the root finder asked again "
        "with the samples' values: :mod:`filippov.loop.refine`)",
        "samples and refines through the same compiled scalar code (``kernel.scan._sample``, "
        "``kernel.segment._fval``), so its ends agree with its samples bit for bit: no "
        "fallback; a bracket that fails is status ROOT_FAILED (a SimulationError), and the "
        "re-refinement after the band probe or at the dip after an entry keeps the first "
        "root where it fails",
        "deliberate", "nothing to pin on the kernel side but the one code path",
        ("tests/test_solver_events.py::test_a_sign_change_the_samples_saw_survives_refinement",)),
    Asymmetry(
        6, "Brent's iteration bound",
        "``rules.BRENT_MAXITER`` (200)",
        "``rules.BRENT_MAXITER`` (it bounded the extremum's bracket at scipy's default 100, "
        "under a comment that called 100 the reference's)",
        "defect, fixed", "both take one bound from the rule book",
        ("tests/test_engine_asymmetries.py::test_both_engines_give_brent_the_same_iteration_bound",)),
    Asymmetry(
        7, "Sliding time of a start that slides",
        "a ``start`` event in sliding opens a stretch of sliding (``poincare.sliding_time`` "
        "opened one at a ``slide_start`` only and reported 0)",
        "counts the slide a start on H begins in",
        "defect, fixed", "both count it; fig11, the one dataset that uses it, is unchanged "
        "bit for bit (its returns never start sliding)",
        ("tests/test_engine_asymmetries.py::test_a_start_that_slides_counts_its_first_slide_on_both_engines",)),
    Asymmetry(
        8, "Iterated returns and sections",
        "follows several sections, counts non-terminal hits and goes on in the same mode "
        "after one, logs every event (touches, starts) in a Trajectory; its "
        "``first_returns`` starts each return's exact-flow windows afresh",
        "one terminal section, returns only; an iterated return (``iterations``) starts "
        "from the last hit as a start does (``rules.start_side``, ``start_on_switch``), "
        "carrying its time in the region (``rules.carried_age``, ``start_age``)",
        "deliberate", "the kernel computes return maps; results agree to rounding",
        ("tests/test_attractors.py::test_iterating_in_one_call_is_chaining_first_returns",
         "tests/test_attractors.py::test_a_carried_age_skips_only_the_scan_of_a_transient_that_has_decayed")),
    Asymmetry(
        9, "Exact sliding flows",
        "under ``method=\"exact\"`` uses a system's ``flows[SLIDING]`` if it has one",
        "no sliding flow piece (:data:`filippov.abi.PIECES`): integrates every slide",
        "deliberate", "a piece the kernel's one signature would have to carry for every "
        "model",
        ("tests/test_engine_asymmetries.py::test_the_compiled_model_has_no_sliding_flow",)),
    Asymmetry(
        10, "Failures",
        "raises where a run fails",
        "gives each start a status and goes on with the batch; its front door raises the "
        "first failure",
        "deliberate", "one failing start must not lose a batch; both turn a status into "
        "its exception through one table, :func:`filippov.errors.run_error` (the class, the "
        "status's words, where), so a status gives the same class and words on both; the "
        "detail after them is each engine's own",
        ("tests/test_errors.py::test_the_compiled_engine_s_failures_are_the_reference_driver_s_classes",
         "tests/test_end_status.py::test_a_status_raises_the_same_class_and_words_on_both_engines")),
    Asymmetry(
        11, "dP/dz of a return that starts sliding",
        "derives it from the variational equations along the sliding flow, after the "
        "projection a perturbation off H meets on its way back onto it",
        "leaves dP/dz NaN (status OK: the return is made, its derivative is not); "
        "``periodic_orbit`` refuses such an orbit by name (PeriodicOrbitError, \"dP/dz is "
        "not finite\") instead of taking a Newton step from NaN",
        "deliberate", "not ported: the kernel carries no derivative along a slide it "
        "starts in (a section across a sliding arc, a start with h = 0 there)",
        ("tests/test_engine_asymmetries.py::test_dpdz_of_a_return_that_starts_sliding_is_the_reference_engine_s_only",)),
    Asymmetry(
        12, "The rounding below which samples need not resolve a function",
        "where a window fails ``rules.resolves`` (misses under 64 ulps of the samples "
        "taken for rounding), measures the rounding at its samples (the function's changes "
        "when each state component moves by 4 ulps; the smallest over the samples) and "
        "judges again above it",
        "no probes: may split a window the reference does not, never the reverse",
        "deliberate", "a and b of a stiff slide carry the state's rounding times the fast "
        "rate (1e-7 of a = 0.5 at eps = 1e-9), and Radau IIA's long steps on such a slide "
        "were split down to 1/4096 on every step (10 to 25 times the time); the compiled "
        "engine steps explicitly, at the stability limit, where that rounding is not what "
        "fails its windows, and keeps the kernel free of the probes",
        ("tests/test_engine_asymmetries.py::test_the_reference_measures_the_rounding_a_function_carries",)),
    Asymmetry(
        13, "dP/dz through an exact-flow stay",
        "integrates the variational equation along the stay (the field's Jacobian: the "
        "system's own, or central differences), at ``rtol``",
        "differentiates the closed-form flow from the mode entry: the model's flow "
        "Jacobians (``flow_jacobian_plus``/``_minus``: a ``SymbolicSystem`` generates "
        "them, a ``FilippovSystem`` takes them as ``flow_jacobians``) where it has them, else Richardson's extrapolation of central "
        "differences of the flow (``rules.richardson_step``)",
        "deliberate", "the kernel follows an exact stay in one closed-form evaluation per "
        "sample, with no steps a variational equation could ride on; the three agree to "
        "1e-10 (tests/test_units.py, across units; the Richardson error 1.4e-12 on a "
        "return of the paper's flow)",
        ("tests/test_symbolic.py::test_compiled_dpdz_takes_the_generated_flow_jacobians",
         "tests/test_flow_jacobians.py::test_dpdz_from_given_flow_jacobians_is_the_closed_form",
         "tests/test_units.py::test_a_relay_orbit_in_other_units_has_its_period_and_multipliers")),
    Asymmetry(
        14, "Several switching surfaces",
        "``simulate`` runs a ``SurfacesSystem`` stay by stay, each stay the one-surface "
        "loop on a view of the system (filippov.several; docs/decisions.md D24), and a "
        "``FilippovSystem`` or ``SymbolicSystem`` given ``fields=`` as the "
        "``SurfacesSystem`` of its compiled pieces (filippov.surfaces_defined); "
        "``first_returns``, the derivatives (filippov.variational) and ``periodic_orbit`` "
        "take it too; sliding "
        "on an intersection of two surfaces by Dieci and Lopez's bilinear field "
        "(filippov.intersection)",
        "refuses a system of several surfaces by name (``SurfacesSystem``, or a "
        "``FilippovSystem``/``SymbolicSystem`` with ``fields=``); one of one surface is "
        "today's system",
        "deliberate", "the views reuse every rule of one surface without touching the "
        "loop the kernel compiles, whose per-return budget and compile time are spent "
        "(D22, D23); the kernel's own surfaces are issue 59's next part",
        ("tests/test_several_surfaces.py::test_generated_crossings_returns_and_dpdz_of_two_and_three_surfaces",
         "tests/test_several_surfaces.py::test_engines_and_front_doors_that_take_one_surface_refuse_several",
         "tests/test_surfaces_defined.py::test_one_surface_given_as_fields_is_today_s_system_bit_for_bit",
         "tests/test_surfaces_defined.py::test_what_a_definition_of_several_surfaces_cannot_do_is_refused_by_name")),
    Asymmetry(
        15, "The step after one a non-finite stage rejected",
        "scipy's DOP853 taken back and stepped again shorter (``_guarded_step``): scipy "
        "forgets the rejection, and the next accepted step may grow up to tenfold",
        "``_dop_step`` rejects it in its own loop: the step after a rejection grows at "
        "most to the rejected size",
        "deliberate", "the reference steps as scipy does; both stop where the orbit runs "
        "through a field that is not finite "
        "(at a stage, or at the time a stage met it once the orbit passes it: D16 (5)); "
        "past a rejection the steps differ, so which band thinner than the steps a stage "
        "meets at all can differ -- a field is a black box between its evaluations",
        ("tests/test_both_engines_refuse.py::test_a_nan_band_only_the_interpolant_meets_stops_the_run_never_a_number",
         "tests/test_both_engines_refuse.py::test_a_nan_band_past_the_return_never_stops_the_return")),
)


def _cell(text: str, first: bool) -> str:
    lead = "   * - " if first else "     - "
    return lead + text


def table(entries=ASYMMETRIES) -> str:
    """``entries`` as a reStructuredText list-table (the one in this module's doc)."""
    rows = [".. list-table:: What differs between the engines",
            "   :header-rows: 1", "   :widths: 3 14 24 24 9 26", "",
            _cell("#", True), _cell("What", False), _cell("Reference", False),
            _cell("Compiled", False), _cell("Verdict", False), _cell("Why; tests", False)]
    for a in entries:
        tests = ", ".join(f"``{t}``" for t in a.tests)
        rows += [_cell(str(a.number), True), _cell(f"**{a.title}**", False),
                 _cell(a.reference, False), _cell(a.compiled, False),
                 _cell(a.verdict, False), _cell(f"{a.why}. Tests: {tests}", False)]
    return "\n".join(rows) + "\n"


if __doc__:   # (None under python -OO)
    __doc__ += "\n" + table()
