"""The kernel's state, declared once: its ABI (Settings, Outputs: the fields and their
numba types, from which the kernel's one signature is built), its work arrays (Work;
dP/dz's in a record of their own, Deriv), the groups of them its helpers take (Orbit,
Scratch, Samples, ...), and the named positions of its small state vectors (w.seg,
w.count, w.tally).

The positions are module constants, not a numba record: a global int is a compile-time
literal to numba, so ``w.seg[SEG_ENTRY]`` compiles to the very code ``w.seg[0]`` did (no
speed, no bit of arithmetic changes). The groups are named tuples, which numba passes to a
helper as their members (the same arguments the helper took one by one before)."""
from __future__ import annotations

from collections import namedtuple

from numba import types

from ..loop.run_state import COUNT as _LOOP_COUNT
from ..loop.run_state import RING, STEPS, SWITCHES
from .base import _PIECE_ADDRS, _vec

_f8, _i8, _b1 = types.float64, types.int64, types.boolean

#: what a batch runs with: t_max per return; exact flows in regions + and - (else DOP853)
#: in windows hwin (hwin_slow after the transient time); the section predicate; sliding
#: declared; sample fractions of an exact window and of an integration step; tolerances and
#: limits as compute_returns' options; iterations: returns per start; jac: dP/dz (0 none,
#: 1 Jacobian-vector products by differences, 2 the model's Jacobians); flow_jac: an exact
#: stay's dP/dz from the model's flow Jacobians (else Richardson); the run's state and
#: time scales (filippov.scale: the floors of the rules, atol etc. already scaled; atol
#: per component); each component's scale (the steps of dP/dz's differences)
SETTINGS = (
    ("t_max", _f8), ("exact", _b1), ("hwin", _f8), ("hwin_slow", _f8), ("transient", _f8),
    ("sec_pred", _i8), ("sliding", _b1), ("frac_ex", _vec), ("frac_in", _vec), ("rtol", _f8),
    ("atol", _vec), ("touch_tol", _f8), ("xtol", _f8), ("zeno_span", _f8), ("max_step", _f8),
    ("min_time", _f8), ("max_events", _i8), ("max_steps", _i8), ("zeno_count", _i8),
    ("jac", _i8), ("flow_jac", _b1), ("iterations", _i8), ("state_scale", _f8),
    ("time_scale", _f8), ("scales", _vec))

#: what a batch returns, per start (m) -- fastmap.BatchReturns' fields: state (m, n), time,
#: n_switches, sliding_time, status, first_switch, sliding_displacement (m, n), orbit
#: (m, keep, n), returns_done, jacobian (m, n, n), orbit_jacobian (m, keep or 0, n, n), age,
#: mode (the mode at the return, or the one the run stopped in), accumulation (m, 2: at a
#: ZENO stop where the switches shrink geometrically, their ratio per loop and the
#: accumulation time: rules.geometric_accumulation; else NaN)
OUTPUTS = (
    ("state", types.float64[:, ::1]), ("time", _vec), ("n_switches", types.int64[::1]),
    ("sliding_time", _vec), ("status", types.int64[::1]), ("first_switch", _vec),
    ("sliding_displacement", types.float64[:, ::1]), ("orbit", types.float64[:, :, ::1]),
    ("returns_done", types.int64[::1]), ("jacobian", types.float64[:, :, ::1]),
    ("orbit_jacobian", types.float64[:, :, :, ::1]), ("age", _vec),
    ("mode", types.int64[::1]), ("accumulation", types.float64[:, ::1]))

Settings = namedtuple("Settings", [name for name, _ in SETTINGS])
Outputs = namedtuple("Outputs", [name for name, _ in OUTPUTS])


def kernel_signature(settings=SETTINGS, outputs=OUTPUTS):
    """The kernel's one signature, _batch(fns, params, starts, ages, settings, out), built
    from the declarations of its two named tuples (fastmap builds their values)."""
    def record(fields, declared, cls):
        if fields is not declared:  # another declaration (a test's): a class of its own
            cls = namedtuple(cls.__name__, [name for name, _ in fields])
        return types.NamedTuple([t for _, t in fields], cls)
    return types.void(
        _PIECE_ADDRS,               # the model: its pieces' addresses (filippov.abi.PIECES)
        types.float64[:, ::1],      # params: one row for every start, or one row a start
        types.float64[:, ::1],      # starts (m, n)
        _vec,                       # their ages in their regions (rules.carried_age)
        record(settings, SETTINGS, Settings), record(outputs, OUTPUTS, Outputs))


#: the kernel's named work arrays, allocated once per batch by driver._batch
Work = namedtuple("Work", [
    "ts", "vals", "dvals", "svals", "recent", "seg", "za", "y", "f", "y_old", "f_old", "K",
    "ynew", "ytmp", "scale", "F", "wz", "wg", "wf", "wp", "z", "first_sw", "slide_dz",
    "slide_z0", "count", "tally", "touched",
    # dP/dz (Settings.jac): a Deriv (in the build without the dP/dz code: 0, no arrays)
    "deriv"])

#: dP/dz's arrays: the derivative so far (M), workspaces, the variational stages; a record
#: of their own (docs/decisions.md#kernel-small-records); the run's state scale, from which
#: the central differences step (filippov.scale), and each component's (Richardson's
#: steps along one component)
Deriv = namedtuple("Deriv", ["M", "Mt", "KV", "KP", "ys", "jv", "jo", "jz1", "jz2", "jf1",
                             "jf2", "Jm", "floor", "floors"])

# ----------------------------------------------------------------- w.seg (float64)
# The current segment of the orbit and its stay. The state on it is the exact flow from
# w.za since the mode entry at SEG_ENTRY, or (always when sliding, and in regions + and -
# when SEG_INTEGRATED != 0: a model without flows) the dense output (w.F, w.y_old) of the
# integration step [SEG_STEP_T, SEG_STEP_T + SEG_STEP_H].
# SEG_SHIFT: what the stay subtracts from H (rules.exit_shift; 0 but after a slide),
# moved by SEG_BAND, the rounding band of the exit the stay began at, while the orbit is
# inside it (rules.exit_band, rules.banded_shift; 0 once it is out); SEG_EXIT_SHIFT: the
# exit_shift alone; SEG_RATE_STEP: while sliding, the step of the forward differences that
# give the rates of a and b along the orbit in the current window (rules.rate_step; 0:
# none); SEG_LAST_H, SEG_LAST_SPEED2: outside sliding, h and |f|^2 at the last sample of
# the last window (the next window's first sample: scan._carry_sample); SEG_NEXT_STEP:
# the size DOP853 proposes for the stay's next step; SEG_SUSPECT: the earliest time of
# the stay a trial stage met the non-finite guard at that the orbit has not yet passed
# (inf: none; there the orbit's own field is asked, driver._next_step); SEG_NOT_FINITE:
# where it was not finite (inf: nowhere), the end of the step searched, where the next
# step stops the run.
SEG = ("entry", "step_t", "step_h", "integrated", "shift", "band", "exit_shift",
       "rate_step", "last_h", "last_speed2", "next_step", "suspect", "not_finite")
(SEG_ENTRY, SEG_STEP_T, SEG_STEP_H, SEG_INTEGRATED, SEG_SHIFT, SEG_BAND, SEG_EXIT_SHIFT,
 SEG_RATE_STEP, SEG_LAST_H, SEG_LAST_SPEED2, SEG_NEXT_STEP, SEG_SUSPECT,
 SEG_NOT_FINITE) = range(len(SEG))

# ----------------------------------------------------------------- w.count (int64)
# the loop's counters (filippov.loop.run_state: changes of mode, entries into the Zeno
# ring w.recent, steps; w.count is the run record's ``count``); the kernel keeps none of
# its own
COUNT = _LOOP_COUNT
N_SWITCHES, N_RING, N_STEPS = SWITCHES, RING, STEPS

# ----------------------------------------------------------------- w.tally (float64)
# time slid, start of the current slide, time already spent in the current mode when the
# current exact stay began (its age: 0 after an entry; carried from the last hit when a
# return continues an orbit)
TALLY = ("slid", "slide_start", "age")
T_SLID, T_SLIDE_START, T_AGE = range(len(TALLY))

#: the sizes _batch allocates them with
SEG_SIZE, COUNT_SIZE, TALLY_SIZE = len(SEG), len(COUNT), len(TALLY)

# ----------------------------------------------------------------- groups for the helpers
#: what the event functions are evaluated on: the model (its pieces' addresses, params),
#: the current segment (w.seg, w.za, w.F, w.y_old), the tolerance events are refined to and
#: the run's state scale (filippov.scale: the floor of the rules' state sizes)
Orbit = namedtuple("Orbit", ["fns", "p", "seg", "za", "F", "y_old", "xtol", "floor"])
#: the scratch vectors a model evaluation fills (a state, grad h, F_- or the mode's field,
#: F_+)
Scratch = namedtuple("Scratch", ["wz", "wg", "wf", "wp"])
#: one window's samples: times, leave functions (h, or a and b when sliding), their rates,
#: the section; the state at the last sample (end); touched[0]: H touched in the window
Samples = namedtuple("Samples", ["ts", "vals", "dvals", "svals", "end", "touched"])
#: the scratch vectors of a field evaluation (grad h, F_-, F_+: the Filippov field's)
Fill = namedtuple("Fill", ["wg", "wm", "wp"])
#: the stages of a DOP853 step and the state of the stage being evaluated
Stages = namedtuple("Stages", ["K", "ytmp"])
#: the step-size control of DOP853: the end of integration, the step bound, tolerances
Control = namedtuple("Control", ["t_bound", "max_step", "rtol", "atol"])
#: DOP853's arrays: the state and its field after (y, f) and before (y_old, f_old) the
#: last step, its stages, the new state, a stage state, the error scale, the interpolant
Dop = namedtuple("Dop", ["y", "f", "y_old", "f_old", "K", "ynew", "ytmp", "scale", "F"])

# ----------------------------------------------------------------- the loop's states
#: the run's state as the engine seam's operations take it (filippov.contracts.
#: RunOperations' ``ctx``): the model's pieces, its parameters, the Settings, the Work
RunCtx = namedtuple("RunCtx", ["fns", "p", "s", "w"])
#: the window walk's state (filippov.loop.interval.WindowOps' ``ctx``): whether the
#: stay just began, the segment, the samples, the scratch vectors, the number of samples
#: and of the Settings only what the search asks (docs/decisions.md#window-seam)
Walk = namedtuple("Walk", ["first", "o", "sm", "sc", "ns", "touch_tol", "min_time",
                           "sec_pred"])
