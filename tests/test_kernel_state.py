"""The compiled kernel's state is named and declared once (filippov.kernel.state): the
positions of its small state vectors are distinct and inside the arrays _batch allocates,
the kernel's signature is built from the Settings and Outputs declarations (a field added
there changes it), the values fastmap hands over have the declared types, and no kernel
helper takes more than 8 arguments or runs over 80 lines; the states its operations are
handed are read by name."""
import ast
from pathlib import Path

import numpy as np
import pytest
from numba import typeof, types

from filippov import fastmap
from filippov.kernel import driver, state
from filippov.models import hopf

KERNEL_DIR = Path(driver.__file__).parent
ROOT = Path(__file__).resolve().parent.parent


@pytest.mark.parametrize("names, prefix, size", [
    (state.SEG, "SEG_", state.SEG_SIZE), (state.COUNT, "N_", state.COUNT_SIZE),
    (state.TALLY, "T_", state.TALLY_SIZE)])
def test_the_named_positions_are_distinct_and_inside_their_array(names, prefix, size):
    positions = {name: value for name, value in vars(state).items()
                 if name.startswith(prefix) and name != f"{prefix}SIZE"
                 and isinstance(value, int)}
    assert len(positions) == len(names) == size
    assert sorted(positions.values()) == list(range(size)), positions


def bare_indices(kernel_dir=KERNEL_DIR):
    """Where a kernel source indexes a state vector by a number, not a named position."""
    bare = []
    for path in sorted(kernel_dir.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not (isinstance(node, ast.Subscript) and isinstance(node.slice, ast.Constant)):
                continue
            name = getattr(node.value, "attr", getattr(node.value, "id", None))
            if name in ("sg", "seg", "count", "tally"):  # w.seg[...] or an alias sg[...]
                bare.append(f"{path.name}:{node.lineno}")
    return bare


def test_no_kernel_source_indexes_its_state_vectors_by_a_bare_number():
    assert not bare_indices()


def test_no_kernel_source_reads_a_state_it_is_handed_by_position():
    """The states the kernel's operations are handed (the run's, the window walk's, an
    interval's, a refinement's: kernel.state.RunCtx, Walk, Interval, Eval, Band) are
    named records, read by name: a ``ctx[N]`` read (56 of them when the seam was a
    positional tuple, issue 58) is refused."""
    import re

    found = [f"{path.name}:{k}: {line.strip()}" for path in sorted(KERNEL_DIR.glob("*.py"))
             for k, line in enumerate(path.read_text().splitlines(), 1)
             if re.search(r"\b(ctx|at)\[\d+\]", line)]
    assert not found, found


def _sig_args():
    return driver._KERNEL_SIG.args


def test_the_kernel_signature_is_built_from_the_declarations():
    settings, outputs = _sig_args()[4:6]
    assert settings.instance_class is state.Settings
    assert outputs.instance_class is state.Outputs
    assert list(settings.types) == [t for _, t in state.SETTINGS]
    assert list(outputs.types) == [t for _, t in state.OUTPUTS]
    assert state.kernel_signature() == driver._KERNEL_SIG


def test_a_field_added_to_a_declaration_changes_the_signature():
    base = state.kernel_signature()
    more_settings = state.SETTINGS + (("new_limit", types.int64),)
    more_outputs = state.OUTPUTS + (("new_count", types.int64[::1]),)
    grown = state.kernel_signature(settings=more_settings)
    assert grown != base
    assert grown.args[4].fields[-1] == "new_limit" and len(grown.args[4]) == len(base.args[4]) + 1
    grown = state.kernel_signature(outputs=more_outputs)
    assert grown != base and grown.args[5].fields[-1] == "new_count"
    retyped = tuple((n, types.float64 if n == "max_events" else t) for n, t in state.SETTINGS)
    assert state.kernel_signature(settings=retyped) != base


@pytest.mark.parametrize("jacobian", [False, True])
def test_what_fastmap_hands_the_kernel_has_the_declared_types(jacobian):
    cm = hopf.compiled(1e-2, -0.5, 1.01)
    starts = np.array([[0.0, 1.0, 0.0]])
    settings = fastmap._settings(cm, 5.0, rtol=1e-12, atol=1e-14, max_step=np.inf,
                                 max_events=10, max_steps=100, samples_per_step=4,
                                 touch_tol=1e-15, event_xtol=1e-15, zeno_count=64,
                                 zeno_span=1e-10, min_time=0.0, iterations=1,
                                 jacobian=jacobian)
    outputs = fastmap._outputs(starts, 1, jacobian)
    for value, (name, declared) in zip(settings, state.SETTINGS):
        assert typeof(value) == declared, name
    for value, (name, declared) in zip(outputs, state.OUTPUTS):
        assert typeof(value) == declared, name


def _functions():
    for path in sorted(KERNEL_DIR.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.FunctionDef):
                yield path.name, node


def test_no_kernel_helper_takes_more_than_8_arguments_or_runs_over_80_lines():
    long = [(f, n.name, len(n.args.args), n.end_lineno - n.lineno + 1)
            for f, n in _functions()
            if len(n.args.args) > 8 or n.end_lineno - n.lineno + 1 > 80]
    assert not long, long


def test_no_function_of_the_library_or_the_pipeline_runs_over_80_lines():
    # issue 32: the largest function fits on a screen (docstring included)
    long = []
    for folder in (ROOT / "src" / "filippov", ROOT / "workflow" / "filippov_paper"):
        for path in sorted(folder.rglob("*.py")):
            for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
                if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    lines = node.end_lineno - node.lineno + 1
                    if lines > 80:
                        long.append(f"{path.relative_to(ROOT)}:{node.name} ({lines})")
    assert not long, long
