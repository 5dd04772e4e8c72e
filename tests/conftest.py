"""Shared paths and the one Snakemake build the workflow tests share.

Makes `src/` (the library) and `workflow/` (the paper's pipeline, filippov_paper)
importable from this tree first, installed or not.
"""
import filecmp
import math
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
PIPELINE = ROOT / "workflow"   # holds the package filippov_paper
for _path in (PIPELINE, SRC):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))


# hypothesis profiles (tests/test_properties.py): "ci", the default, is derandomized (the
# same examples on every run and machine) and small enough for `make test`; "deep"
# (HYPOTHESIS_PROFILE=deep, `make test-deep`) draws many more, at random.
import os  # noqa: E402

from hypothesis import HealthCheck, settings  # noqa: E402

settings.register_profile("ci", derandomize=True, max_examples=12, deadline=None,
                          print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.register_profile("deep", max_examples=400, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


# one definition of "a fresh copy of the project" and "run snakemake there",
# shared with `make verify`
sys.path.insert(0, str(ROOT / "workflow" / "scripts"))
from verify import copy_project, run_snakemake  # noqa: E402


#: a finished clean build of this tree to reuse (CI: verify's first build), instead of
#: building it once more here
REUSE_BUILD = "FILIPPOV_TEST_BUILD"


def _reused_build(work: Path):
    """``work`` as the shared build: only a finished build of this very tree (the files
    copy_project copies, byte for byte, and every figure and dataset made); a
    CompletedProcess standing for its (successful) run."""
    from filippov_paper.manifest import data_files

    fresh = Path(tempfile.mkdtemp(prefix="filippov-reuse-"))
    try:
        copy_project(fresh)
        names = sorted(p.relative_to(fresh).as_posix() for p in fresh.rglob("*") if p.is_file())
        same = all((work / n).is_file() and filecmp.cmp(fresh / n, work / n, shallow=False)
                   for n in names)
    finally:
        shutil.rmtree(fresh, ignore_errors=True)
    if not same:
        raise pytest.UsageError(f"{REUSE_BUILD}={work}: not a build of this tree "
                                "(its Snakefile, config/, workflow/ or paper/ differ)")
    if not data_files(work / "results") or not list((work / "figures").glob("*.pdf")):
        raise pytest.UsageError(f"{REUSE_BUILD}={work}: no results or figures (not a "
                                "finished build)")
    return subprocess.CompletedProcess(["snakemake"], 0, f"(reused: {work})\n", "")


@pytest.fixture(scope="session")
def workflow_build(tmp_path_factory):
    """`snakemake` (rule all) once in a fresh copy of the project, as a clone would
    run it; every test that needs built results, figures or the report reads this
    build instead of computing the scenes again. Tests must not modify it.
    ``FILIPPOV_TEST_BUILD=DIR``: DIR is such a build already (CI hands verify's first
    build, made by the same copy_project and run_snakemake), checked to be of this tree."""
    reuse = os.environ.get(REUSE_BUILD)
    if reuse:
        work = Path(reuse).resolve()
        return {"work": work, "run": _reused_build(work), "seconds": math.nan}
    work = copy_project(tmp_path_factory.mktemp("build") / "project")
    t0 = time.perf_counter()
    run = run_snakemake(work, cores="all")
    return {"work": work, "run": run, "seconds": time.perf_counter() - t0}
