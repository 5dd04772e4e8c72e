"""Shared paths and the one Snakemake build the workflow tests share.

Makes `src/` (the library) and `workflow/` (the paper's pipeline, filippov_paper)
importable from this tree first, installed or not.
"""
import fcntl
import filecmp
import json
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
# (HYPOTHESIS_PROFILE=deep, `make test-deep`) draws many more, at random. "ci" reports a
# failing example as drawn, without shrinking it: a shrink runs the engines hundreds of
# times (hypothesis stops it after five minutes; four failing properties held a run for
# twenty), and the example with its blob is enough to reproduce it; "deep" shrinks.
import os  # noqa: E402

from hypothesis import HealthCheck, Phase, settings  # noqa: E402

settings.register_profile("ci", derandomize=True, max_examples=12, deadline=None,
                          print_blob=True, phases=[Phase.explicit, Phase.reuse, Phase.generate],
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.register_profile("deep", max_examples=400, deadline=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))


# one definition of "a fresh copy of the project" and "run snakemake there",
# shared with `make verify`
sys.path.insert(0, str(ROOT / "workflow" / "scripts"))
from verify import copy_project, report_args, run_snakemake  # noqa: E402


#: a finished clean build of this tree to reuse (CI: verify's first build), instead of
#: building it once more here
REUSE_BUILD = "FILIPPOV_TEST_BUILD"


def _project_files(work: Path) -> dict[str, Path]:
    """The files copy_project copies (Snakefile, config/, workflow/, paper/*.tex), by
    relative path; bytecode and the editable install's metadata left out (Python and pip
    write them into workflow/ as the pipeline is imported or installed, after any copy)."""
    def copied(rel: Path) -> bool:
        if rel.parts[0] == "paper":
            return len(rel.parts) == 2 and rel.suffix == ".tex"
        return (rel.parts[0] in ("Snakefile", "config", "workflow")
                and not any(part == "__pycache__" or part.endswith(".egg-info")
                            for part in rel.parts) and rel.suffix != ".pyc")
    return {rel.as_posix(): p for p in work.rglob("*")
            if p.is_file() and copied(rel := p.relative_to(work))}


def _reused_build(work: Path):
    """``work`` as the shared build, only if it is a finished build of this tree: the
    files copy_project copies are this tree's, both ways and byte for byte; every
    scene's figure is there; and no dataset is older than the library's sources
    (src/ is not copied: a build reads it from this tree). A CompletedProcess stands
    for its (successful) run; anything else raises, naming the variable."""
    from filippov_paper.config import scene_files
    from filippov_paper.manifest import data_files

    fresh = Path(tempfile.mkdtemp(prefix="filippov-reuse-"))
    try:
        ours, theirs = _project_files(copy_project(fresh / "p")), _project_files(work)
        same = set(ours) == set(theirs) and all(
            filecmp.cmp(ours[n], theirs[n], shallow=False) for n in ours)
    finally:
        shutil.rmtree(fresh, ignore_errors=True)
    if not same:
        raise pytest.UsageError(f"{REUSE_BUILD}={work}: not a build of this tree "
                                "(its Snakefile, config/, workflow/ or paper/ differ)")
    missing = [s for s in scene_files(work / "config" / "scenes")
               if not (work / "figures" / f"{s}.pdf").is_file()]
    datasets = data_files(work / "results")
    if missing:
        raise pytest.UsageError(f"{REUSE_BUILD}={work}: not a finished build (no figure "
                                f"of {', '.join(missing)})")
    if not datasets:
        raise pytest.UsageError(f"{REUSE_BUILD}={work}: not a finished build (no dataset)")
    newest = max(p.stat().st_mtime for p in SRC.rglob("*.py"))
    if min(p.stat().st_mtime for p in datasets) < newest:
        raise pytest.UsageError(f"{REUSE_BUILD}={work}: a dataset is older than the "
                                "library's sources in src/ (a stale build)")
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
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        return _build(tmp_path_factory.mktemp("build"))
    # `make test` runs one pytest-xdist worker per core: they share one build, made by
    # the first worker that asks while the others wait on its lock, then read its record
    shared = tmp_path_factory.getbasetemp().parent   # one folder per run, all workers'
    record = shared / "build.json"
    with open(shared / "build.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not record.is_file():
            built = _build(shared / "build")
            run = built["run"]
            record.write_text(json.dumps({
                "work": str(built["work"]), "seconds": built["seconds"], "args": run.args,
                "returncode": run.returncode, "stdout": run.stdout, "stderr": run.stderr}))
        saved = json.loads(record.read_text())
    run = subprocess.CompletedProcess(saved["args"], saved["returncode"], saved["stdout"],
                                      saved["stderr"])
    return {"work": Path(saved["work"]), "run": run, "seconds": saved["seconds"]}


def _build(folder: Path) -> dict:
    work = copy_project(folder / "project")
    t0 = time.perf_counter()
    run = run_snakemake(work, cores="all")
    return {"work": work, "run": run, "seconds": time.perf_counter() - t0}


#: a finished `make docs` site (docs/_build/html) to read instead of building one here
REUSE_DOCS = "FILIPPOV_DOCS_BUILD"


@pytest.fixture(scope="session")
def docs_site(tmp_path_factory):
    """The documentation site, built once as `make docs` builds it (sphinx, warnings as
    errors) from a copy of docs/ and examples/ (sphinx writes generated pages into its
    source folder: the tree's docs/ is left alone); the folder of its HTML.
    ``FILIPPOV_DOCS_BUILD=DIR``: DIR is such a site already (e.g. docs/_build/html)."""
    reuse = os.environ.get(REUSE_DOCS)
    if reuse:
        html = Path(reuse).resolve()
        if not (html / "index.html").is_file():
            raise pytest.UsageError(f"{REUSE_DOCS}={html}: no index.html there")
        return html
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        return _build_docs(tmp_path_factory.mktemp("docs"))
    shared = tmp_path_factory.getbasetemp().parent   # one site for all workers
    with open(shared / "docs.lock", "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)
        if not (shared / "docs" / "html" / "index.html").is_file():
            _build_docs(shared / "docs")
    return shared / "docs" / "html"


def _build_docs(folder: Path) -> Path:
    project = folder / "project"
    skip = shutil.ignore_patterns("_build", "generated", "auto_examples", "__pycache__")
    shutil.copytree(ROOT / "docs", project / "docs", ignore=skip)
    shutil.copytree(ROOT / "examples", project / "examples", ignore=skip)
    for name in ("src", "workflow"):   # read only: the sources the pages document
        (project / name).symlink_to(ROOT / name)
    html = folder / "html"
    env = dict(os.environ, MPLBACKEND="Agg", SOURCE_DATE_EPOCH="0",
               PYTHONPATH=os.pathsep.join([str(SRC), str(PIPELINE)]
                                          + [p for p in [os.environ.get("PYTHONPATH")] if p]))
    run = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-q", "-b",
                          "html", "-d", str(folder / "doctrees"), str(project / "docs"),
                          str(html)], cwd=project, env=env, capture_output=True, text=True)
    if run.returncode != 0:
        raise AssertionError(f"the docs do not build (exit {run.returncode}):\n"
                             f"{run.stdout[-3000:]}\n{run.stderr[-5000:]}")
    return html
