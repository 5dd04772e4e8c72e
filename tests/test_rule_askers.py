"""Who asks the rule book (issue 58: "no engine module calls rules. for a decision").

The rule book (filippov.rules) holds two kinds of function. Most are decisions of the
event-driven method -- what an event is, where a stay ends, whether a run goes on -- and
the loop (filippov.loop) asks them, once, for both engines. A few say how an engine
computes something it then reports: a step size, a probe, a window's length, an estimate
its error message quotes. ``rules.ENGINE_NUMERICS`` names those; an engine module may call
them itself.

This test reads every engine module's calls of ``rules.<name>(...)`` and holds them to
``ENGINE_NUMERICS`` plus a ratchet, :data:`DECISIONS_IN_ENGINES`: the decisions an engine
still asks itself, each with why it is not the loop's yet. The ratchet only shrinks: a
decision moved into the loop must leave it (the test fails while it stays listed), and a
new one called from an engine fails until it is either moved or listed here with its
reason.
"""
import ast
from pathlib import Path

from filippov import rules

SRC = Path(__file__).resolve().parents[1] / "src" / "filippov"

#: the engine modules: the reference driver, and the compiled engine's front door and kernel
ENGINE_MODULES = ("simulate.py", "fastmap.py", *(
    f"kernel/{p.name}" for p in sorted((SRC / "kernel").glob("*.py"))))

#: decisions an engine module still asks itself: (module, rule) -> why not the loop's yet
DECISIONS_IN_ENGINES = {
    ("simulate.py", "resolves"): "the window's samples resolve what they sample: asked on "
        "the engine's sample arrays inside its window operation, with the reference's own "
        "rounding floor (engines.py asymmetry 12); the window seam reports one sample at a "
        "time",
    ("kernel/driver.py", "resolves"): "as the reference's, with no floor",
    ("simulate.py", "cut_resolves"): "whether a window cut at a sample that is not finite "
        "keeps samples enough for resolves to judge: asked with it, on the same arrays",
    ("kernel/driver.py", "cut_resolves"): "as the reference's",
    ("simulate.py", "flow_consistent"): "an exact flow follows its field over a window: "
        "from the states and field values the engine's sampling evaluated",
    ("kernel/scan.py", "flow_consistent"): "as the reference's",
    ("simulate.py", "starts_on_section"): "a section crossing at the run's start is the "
        "start on it up to rounding (the window seam's counts): it needs states, not "
        "scalars",
    ("kernel/scan.py", "starts_on_section"): "as the reference's",
    ("simulate.py", "on_section_by_value"): "the same test by the section's rounding "
        "measured at probes about the start (section_probe, section_noise)",
    ("kernel/scan.py", "on_section_by_value"): "as the reference's",
}


def _rule_calls(path: Path) -> set:
    """The names ``f`` of the calls ``rules.f(...)`` in ``path``."""
    return {node.func.attr for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name) and node.func.value.id == "rules"}


def test_engine_numerics_are_rules_of_the_book():
    public = {name for name in vars(rules) if callable(getattr(rules, name))
              and not name.startswith("_") and getattr(rules, name).__module__ == rules.__name__}
    assert set(rules.ENGINE_NUMERICS) <= public
    assert len(set(rules.ENGINE_NUMERICS)) == len(rules.ENGINE_NUMERICS)


def test_an_engine_asks_the_rule_book_only_for_its_numerics_and_the_listed_decisions():
    asked = {(module, name) for module in ENGINE_MODULES
             for name in _rule_calls(SRC / module)}
    decisions = {(m, name) for m, name in asked if name not in rules.ENGINE_NUMERICS}
    unlisted = decisions - set(DECISIONS_IN_ENGINES)
    assert not unlisted, f"decisions asked by an engine, not the loop: {sorted(unlisted)}"
    gone = set(DECISIONS_IN_ENGINES) - decisions
    assert not gone, f"no longer asked by the engine: strike from the ratchet {sorted(gone)}"


def test_the_decisions_moved_into_the_loop_are_asked_there():
    # the decisions issue 58 moved out of the engines: the event's, the start's, the run's
    # record's; the step budget, the carried age and the banded shift last
    loop = set().union(*(_rule_calls(p) for p in (SRC / "loop").glob("*.py")))
    moved = {"step_budget_spent", "carried_age", "banded_shift", "next_mode",
             "at_two_fold", "tangent_to_both", "exit_drift", "exit_band", "exit_shift",
             "note_switch", "budget_runs_out", "start_side", "start_on_switch",
             "slides_in_section"}
    assert moved <= loop, moved - loop
    engines = set().union(*(_rule_calls(SRC / m) for m in ENGINE_MODULES))
    assert not ({"step_budget_spent", "carried_age", "banded_shift"} & engines)
