"""One errors module: every error class of the library is defined in filippov.errors,
and both engines raise those classes."""
import ast
from pathlib import Path

import pytest

import filippov
from filippov import errors, fastmap

LIBRARY = Path(filippov.__file__).parent


def _is_exception(node: ast.ClassDef) -> bool:
    return any(isinstance(b, ast.Name) and (b.id.endswith("Error") or b.id.endswith("Exception")
                                            or b.id in ("Warning", "RuntimeWarning"))
               for b in node.bases)


def test_every_error_class_of_the_library_is_defined_in_the_errors_module():
    elsewhere = []
    for path in LIBRARY.rglob("*.py"):
        if path.name == "errors.py":
            continue
        tree = ast.parse(path.read_text(), filename=str(path))
        elsewhere += [f"{path.relative_to(LIBRARY)}:{n.name}" for n in ast.walk(tree)
                      if isinstance(n, ast.ClassDef) and _is_exception(n)]
    assert not elsewhere, elsewhere


@pytest.mark.parametrize("module, name", [
    ("simulate", "SimulationError"), ("simulate", "ZenoError"), ("simulate", "EventLimitError"),
    ("simulate", "SlidingNotBuiltError"), ("checks", "SystemContractError"),
    ("variational", "VariationalError"), ("periodic", "PeriodicOrbitError"),
    ("continuation", "ContinuationError"), ("branches", "BranchError"),
    ("io", "DatasetError")])
def test_the_modules_that_raise_an_error_re_export_the_one_class(module, name):
    import importlib

    assert getattr(importlib.import_module(f"filippov.{module}"), name) is getattr(errors, name)


def test_the_compiled_engine_s_failures_are_the_reference_driver_s_classes():
    # one table for both engines (each status on both: tests/test_end_status.py)
    raised = set(errors.RUN_ERRORS.values())
    assert raised == {errors.EventLimitError, errors.ZenoError, errors.SlidingNotBuiltError,
                      errors.SimulationError, RuntimeError, ValueError,
                      errors.SystemContractError}   # a slide that left H: SLID_OFF_H
    assert fastmap.SimulationError is errors.SimulationError
    assert not hasattr(fastmap, "_ERRORS")  # no table of its own
