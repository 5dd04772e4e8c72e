"""What is done at an event is written once (filippov.loop.event), for both engines: the
decisions asked from one place, both engines running the one event function, and the
Zeno ring the same on both."""
import ast
from collections import deque
from pathlib import Path

import numpy as np
import pytest

from filippov import EventLimitError, ZenoError, compute_returns, rules, simulate
from filippov.fastmap import EVENT_LIMIT, ZENO
from filippov.models import pseudo_equilibrium

SRC = Path(__file__).resolve().parents[1] / "src" / "filippov"

#: the rules of an event: asked only by filippov.loop.event; and those of the run's record
#: (at a switch, filippov.loop.run_state.count_switch; before a step, count_step), only by
#: filippov.loop.run_state, which the run asks (rules.accumulates by rules.note_switch, the
#: Zeno ring)
EVENT_RULES = {"next_mode", "exit_drift", "onto_switch", "exit_band", "exit_shift",
               "banded_shift"}
RECORD_RULES = {"note_switch", "budget_runs_out", "step_budget_spent"}
#: asked by the loop's start (make_start), which an engine's begin calls
START_RULES = {"carried_age"}


def _calls(path):
    """The names of the functions ``path`` calls (f(...) and m.f(...))."""
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Call):
            f = node.func
            yield f.id if isinstance(f, ast.Name) else f.attr if isinstance(
                f, ast.Attribute) else None


def test_the_event_rules_are_asked_only_by_the_loop():
    askers = {}
    for path in SRC.rglob("*.py"):
        for name in _calls(path):
            if name is not None and name.lstrip("_") in EVENT_RULES | RECORD_RULES | (
                    START_RULES | {"count_switch", "count_step"}):
                askers.setdefault(name.lstrip("_"), set()).add(
                    str(path.relative_to(SRC)))
    assert set(askers) == EVENT_RULES | RECORD_RULES | START_RULES | {
        "count_switch", "count_step"}, askers
    assert all(askers[r] == {"loop/event.py"}
               for r in (EVENT_RULES | START_RULES | {"count_step"}) - {"exit_shift"}), askers
    # and a run on several surfaces, whose stays are the loop's runs up to their first
    # switch, counts its switches across them (filippov.several), and starts the stay
    # after a corner from a rounding short of a surface as the loop starts one after a
    # sliding exit (several._through)
    assert askers["count_switch"] == {"loop/event.py", "several.py"}, askers
    assert askers["exit_shift"] == {"loop/event.py", "several.py"}, askers
    assert all(askers[r] == {"loop/run_state.py"} for r in RECORD_RULES), askers
    assert {str(p.relative_to(SRC)) for p in SRC.rglob("*.py")
            if "accumulates" in set(_calls(p))} == {"rules.py"}


def test_both_engines_build_their_run_from_the_loop():
    builders = {str(p.relative_to(SRC)) for p in SRC.rglob("*.py")
                if "make_run" in set(_calls(p))}
    assert builders == {"simulate.py", "kernel/driver.py"}
    # and each calls what it built: the reference's _RUN, the kernel's _one
    assert "_RUN" in set(_calls(SRC / "simulate.py"))
    assert "_one" in set(_calls(SRC / "kernel" / "driver.py"))
    # the loop before each stay is asked in the run only
    assert {str(p.relative_to(SRC)) for p in SRC.rglob("*.py")
            if "before_stay" in set(_calls(p))} == {"loop/event.py"}
    # the reference's own copies are gone
    reference = (SRC / "simulate.py").read_text()
    assert "def _decide" not in reference and "def _check_rate" not in reference
    assert "deque" not in reference


def test_the_event_and_the_stay_are_written_in_the_run_loop():
    # not functions the loop calls (numba would copy their whole IR into the run:
    # docs/decisions.md#kernel-inlined-driver): make_run defines one function, whose
    # `while` asks the event's rules itself and holds the stay's loop over its steps,
    # which asks the engine's stay operations in their order
    tree = ast.parse((SRC / "loop" / "event.py").read_text())
    make_run = next(n for n in tree.body if isinstance(n, ast.FunctionDef)
                    and n.name == "make_run")
    inner = [n for n in ast.walk(make_run) if isinstance(n, ast.FunctionDef)]
    assert [n.name for n in inner] == ["make_run", "run"]
    loops = [n for n in ast.walk(inner[1]) if isinstance(n, ast.While)]
    assert len(loops) == 2 and loops[1] in list(ast.walk(loops[0]))
    asked = {n.func.attr if isinstance(n.func, ast.Attribute) else n.func.id
             for n in ast.walk(loops[0]) if isinstance(n, ast.Call)
             and isinstance(n.func, (ast.Attribute, ast.Name))}
    assert EVENT_RULES | {"count_switch", "count_step"} <= asked
    steps = [n.func.id for n in sorted(
        (n for n in ast.walk(loops[1]) if isinstance(n, ast.Call)
         and isinstance(n.func, ast.Name)), key=lambda n: (n.lineno, n.col_offset))]
    # the step budget, the step, why none (loop.stay.make_failed_step), the walk over the
    # step's windows (loop.stay.make_step_windows) on the engine's window, the step's end
    assert steps == ["count_step", "next_step", "failed_step", "step_windows", "end_step"]


@pytest.mark.parametrize("zeno_count", [2, 3, 7])
def test_the_ring_is_the_deque_of_the_last_switches(zeno_count):
    # the array ring answers as a deque(maxlen=zeno_count) of the switch times does
    note_switch = rules.note_switch
    ring, entries, times = np.empty(zeno_count), 0, deque(maxlen=zeno_count)
    rng = np.random.default_rng(1)
    t = 0.0
    for k in range(40):
        t += float(rng.choice([1e-3, 1e-13]))
        times.append(t)
        entries, zeno = note_switch(ring, entries, t, zeno_count, 1e-10)
        full = len(times) == zeno_count
        assert entries == k + 1
        assert zeno == (full and rules.accumulates(times[0], t, 1e-10))


# the pseudo-equilibrium example with eps = 1e-13 chatters across H at ~1e-12 (exact
# flows): (start, zeno_count, zeno_span, t_end) and the switch the ring stops at; in
# the last case the first switches are slower and the ring goes round before it does
CHATTER = [([1e-12, 0.0], 2, 1e-10, 1.0, 2), ([1e-12, 0.0], 64, 1e-10, 1.0, 64),
           ([3e-11, 0.0], 5, 3e-12, 1e-9, 6)]


@pytest.mark.parametrize("start,zeno_count,zeno_span,t_end,stop", CHATTER)
def test_both_engines_stop_chatter_at_the_same_switch(start, zeno_count, zeno_span, t_end,
                                                      stop):
    system = pseudo_equilibrium.system(1e-13, -0.5)
    opts = dict(zeno_count=zeno_count, zeno_span=zeno_span)
    model = system.compiled(lambda z, p: z[0] - 5.0, direction=1)  # never reached
    out = compute_returns(model, [start], t_end, **opts)
    assert out.status[0] == ZENO and out.n_switches[0] == stop
    with pytest.raises(ZenoError, match=f"{zeno_count} switches within"):
        simulate(system, start, t_end, **opts)
    if stop > zeno_count:
        return  # with fewer switches allowed the reference's projection stops it first
    # one switch fewer allowed: both stop at the same switch on the hard bound, which
    # is counted before the ring
    out = compute_returns(model, [start], t_end, max_events=stop - 1, **opts)
    assert out.status[0] == EVENT_LIMIT and out.n_switches[0] == stop
    with pytest.raises(EventLimitError, match=f"event limit {stop - 1} hit"):
        simulate(system, start, t_end, max_events=stop - 1, **opts)


# the plain kernel compiled without the dP/dz code: tests/test_kernel_cache.py (one cold
# compile shared with the compile lock's test)
