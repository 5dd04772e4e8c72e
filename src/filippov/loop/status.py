"""The status codes of a run, one set for both engines: what the compiled kernel writes
per start (:data:`filippov.fastmap.STATUS`) and what the loop's shared functions
(:mod:`filippov.loop.event`) hand back, which the reference driver turns into its
exceptions (:mod:`filippov.errors`). Plain integers: numba compiles them as literals."""
from __future__ import annotations

GO_ON = -1         # the orbit goes on (never a run's final status)
# a value not finite met between two samples (a root finder's, a hidden extremum's):
# the window's search ends there and the engine searches up to it as past a sample not
# finite (never a run's final status; loop.interval, loop.refine)
CUT = -3
OK = 0
NO_RETURN = 1      # t_max reached before the section
EVENT_LIMIT = 2    # more than max_events switches
STEP_LIMIT = 3     # more than max_steps windows / integration steps
ZENO = 4           # zeno_count switches within zeno_span
NON_FINITE = 5     # non-finite state, or value of a piece (a field, switch, a section)
NO_SLIDING = 6     # attracting sliding reached, but the model declares no sliding
STEP_FAILED = 7    # the sliding integrator's step size collapsed
ROOT_FAILED = 8    # an event could not be bracketed / refined
BAD_START = 9      # non-finite start point
SECTION_SLIDING = 10  # the orbit slides inside the section (a section on H)
FLOW_OFF_FIELD = 11  # an exact flow moved the state farther than its field allows
TWO_FOLD = 12      # a slide ran into a two-fold: both fields tangent to H at once
NO_NORMAL = 13     # a start on H where grad H is 0: no side of H to decide on
SLID_OFF_H = 14    # a slide left H far beyond its integration's error (a wrong switch_grad)

STATUS = {OK: "ok", NO_RETURN: "no return within t_max", EVENT_LIMIT: "event limit",
          STEP_LIMIT: "step limit", ZENO: "accumulation of switches (Zeno)",
          NON_FINITE: "non-finite state or value of a piece",
          NO_SLIDING: "attracting sliding reached, but the model declares no sliding",
          STEP_FAILED: "sliding integrator: step size too small",
          ROOT_FAILED: "event refinement failed (no bracket or no convergence)",
          BAD_START: "non-finite start point",
          SECTION_SLIDING: "the orbit slides along H inside the section (a section on the "
                           "switching surface): its crossings there would be rounding noise",
          FLOW_OFF_FIELD: "the exact flow does not follow its field",
          TWO_FOLD: "the slide reached a two-fold (both fields tangent to H): the Filippov "
                    "solution does not go on uniquely from there",
          NO_NORMAL: "the start lies on H where switch_grad is 0: H has no normal there "
                     "(a switch that does not depend on the state, or a singular point of "
                     "H), so no side of it can be decided",
          SLID_OFF_H: "the slide left H far beyond its integration's error: switch_grad is "
                      "not the gradient of switch along the slide (right where it was "
                      "checked, wrong here), or the tolerances are too loose for it"}
