"""Every error the library raises of its own, in one place, for both engines.

The reference driver (:func:`filippov.simulate.simulate`) and the compiled engine
(:mod:`filippov.fastmap`: a failed start's status code becomes one of these, with the
same meaning) raise the same classes, so a caller catches one name whatever engine ran.
The modules that raise them re-export them (``filippov.simulate.ZenoError`` is this
``ZenoError``).

- :class:`SystemContractError`: a piece of the system breaks its contract (a wrong shape,
  a non-finite value at the start, a gradient that disagrees with its function).
- :class:`SimulationError` and its kinds: an orbit that cannot be continued.
- :class:`VariationalError`, :class:`PeriodicOrbitError`, :class:`ContinuationError`,
  :class:`BranchError`: the analyses on top (dP/dz, periodic orbits, continuation).
- :class:`SymbolicError`: a symbolic definition that cannot become a system.
- :class:`DatasetError`: a file that is not a sound dataset.
"""


class SystemContractError(ValueError):
    """A piece of a :class:`~filippov.system.PiecewiseSystem` breaks its contract."""


class SimulationError(RuntimeError):
    """A trajectory could not be continued (non-finite state, bad input, ...)."""


class EventLimitError(SimulationError):
    """The bound on events or steps was hit (typically rapid switching)."""


class ZenoError(SimulationError):
    """Switching times accumulate: infinitely many switches in finite time."""


class SlidingNotBuiltError(SimulationError):
    """Attracting sliding reached by a system built with ``sliding=False``."""


class SurfacesError(SimulationError):
    """A run on several switching surfaces that no rule it has continues: a corner the
    corner rule does not settle, a slide that reaches another surface."""


class VariationalError(RuntimeError):
    """The variational equations could not be integrated, or a switch or section
    is met tangentially (the derivative does not exist there)."""


class PeriodicOrbitError(RuntimeError):
    """Newton's method did not converge, a return failed, or the derivative at the
    fixed point does not annihilate the flow direction."""


class ContinuationError(RuntimeError):
    """Newton failed to converge or the step size collapsed."""


class BranchError(RuntimeError):
    """The orbit to follow is not there, or not stable, at the start."""


class SymbolicError(ValueError):
    """A symbolic definition that cannot be turned into a system (names the piece)."""


class DatasetError(ValueError):
    """A file that is not a sound dataset of this project (unreadable, damaged,
    truncated, written by something else, or of another scene)."""


class ValueNotFinite(Exception):
    """Inside the reference engine only, never raised to a caller: a function of time on
    a segment was not finite at ``t``, which stops the root finder asking it (scipy's
    brentq would go on with NaN); the event search turns it into its CUT there
    (filippov.loop.interval)."""

    def __init__(self, t):
        super().__init__(t)
        self.t = t


# ------------------------------------------------------------------ a run's end status
# What a run that ends with a status of filippov.loop.status raises, one table for both
# engines: the reference driver raises it where its run stops, the compiled engine's front
# door for a start that did not return (tests/test_errors.py pins each status on both).
def _run_errors():
    from .loop import status as s
    return {s.NO_RETURN: RuntimeError, s.EVENT_LIMIT: EventLimitError,
            s.STEP_LIMIT: EventLimitError, s.ZENO: ZenoError, s.NON_FINITE: SimulationError,
            s.NO_SLIDING: SlidingNotBuiltError, s.STEP_FAILED: SimulationError,
            s.ROOT_FAILED: SimulationError, s.BAD_START: ValueError,
            s.SECTION_SLIDING: SimulationError, s.FLOW_OFF_FIELD: SimulationError,
            s.TWO_FOLD: SimulationError, s.NO_NORMAL: SimulationError,
            s.SLID_OFF_H: SystemContractError}


#: status -> the exception class a run that ends with it raises
RUN_ERRORS = _run_errors()


def run_error(status: int, t, z, detail: str = "") -> Exception:
    """The exception of a run that ended with ``status`` at time ``t`` in state ``z``, on
    either engine: the class of :data:`RUN_ERRORS`, the message the status's words
    (:data:`filippov.loop.status.STATUS`), where, then the engine's ``detail``."""
    import numpy as np

    from .loop.status import STATUS

    state = np.asarray(z, dtype=float).reshape(-1).tolist()
    return RUN_ERRORS[status](f"{STATUS[status]} at t={float(t)!r}, state {state}{detail}")


def accumulation_detail(ratio: float, t_star: float) -> str:
    """What both engines say of switches that shrink geometrically
    (:func:`filippov.rules.geometric_accumulation`): the ratio, and the accumulation
    time their series sums to."""
    return (f": the switches accumulate geometrically -- each loop (two switches) lasts "
            f"{ratio:.6g} times the one before -- and sum to a finite time: the orbit reaches "
            f"a Zeno point (an invisible two-fold, say) at t* = {float(t_star)!r} (estimated from "
            "the series), where no Filippov solution goes on by crossing; stopped at the "
            "last switch, the state given")
