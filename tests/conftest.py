"""Shared paths and the one Snakemake build the workflow tests share.

Makes `src/` importable when the package is not installed.
"""
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
if str(SRC) not in sys.path:
    sys.path.insert(0, str(SRC))


# one definition of "a fresh copy of the project" and "run snakemake there",
# shared with `make verify`
sys.path.insert(0, str(ROOT / "workflow" / "scripts"))
from verify import copy_project, run_snakemake  # noqa: E402


@pytest.fixture(scope="session")
def workflow_build(tmp_path_factory):
    """`snakemake` (rule all) once in a fresh copy of the project, as a clone would
    run it; every test that needs built results, figures or the report reads this
    build instead of computing the scenes again. Tests must not modify it."""
    work = copy_project(tmp_path_factory.mktemp("build") / "project")
    t0 = time.perf_counter()
    run = run_snakemake(work, cores="all")
    return {"work": work, "run": run, "seconds": time.perf_counter() - t0}
