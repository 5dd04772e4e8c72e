# The workflow's functions, kept apart from its rules (snakemake --lint): the
# library fingerprints, the scene helpers of compute.smk, the hard-case chunks of
# hard_cases.smk and the report's inputs of report.smk.
#
# Library fingerprints. Snakemake reruns a job when its script changes, but not
# when the library code the script imports changes; passing a hash of that code
# as a param makes it do so (params are a default rerun trigger in Snakemake 8+).
import functools
import hashlib
import importlib.util
import posixpath
import shutil
import subprocess
import sys
from pathlib import Path

import yaml

from filippov_paper.config import (DEFAULT_RESOLUTION, SceneError, apply_resolution, check_limits,
                             limits)

# Library parts no scene computation imports: editing them must not recompute data.
# (hard_cases.py is the hard-case sweep's own module: rule hard_cases hashes it.)
# The report part of each scene and benchmark module and of hard_cases.py
# (filippov_paper.config.is_report_part) is left out of their hash as well (strip_reports=True).
NOT_COMPUTE = ("plotting/", "benchmarks/", "report.py", "manifest.py",
               "hard_cases.py", "paper_labels.py", "report_html.py")


def library_hash(include="", exclude=(), strip_reports=False):
    """See _library_hash; every rule asks, so each distinct question is answered once
    per workflow run (the files are read, and the scene modules parsed, once)."""
    exclude = (exclude,) if isinstance(exclude, str) else tuple(exclude)
    return _library_hash(include, exclude, strip_reports)


@functools.lru_cache(maxsize=None)
def _library_hash(include, exclude, strip_reports):
    """sha256 over the *.py files of the library (filippov) and of the paper's pipeline
    (filippov_paper) under `include`, minus the paths in `exclude` (a folder "name/" or a
    file "name.py", relative to the package that holds it: the two packages share no
    name, so "plotting" or "report.py" is the pipeline's); with `strip_reports`, the
    scene and benchmark modules and hard_cases.py without their report part."""
    from filippov_paper.config import without_report_part

    files = []
    for package in ("filippov", "filippov_paper"):
        spec = importlib.util.find_spec(package)  # locates without importing numerics
        if spec is None or not spec.origin:
            return f"{package}-not-found"
        root = Path(spec.origin).parent
        files += [(path.relative_to(root).as_posix(), path)
                  for path in (root / include).rglob("*.py")]
    # a bare name is a folder ("plotting" == "plotting/"); join(e, "") adds the slash
    exclude = tuple(e if e.endswith(".py") else posixpath.join(e, "") for e in exclude)
    digest = hashlib.sha256()
    for rel, path in sorted(files):
        if any(rel == e or (e.endswith("/") and rel.startswith(e)) for e in exclude):
            continue
        text = path.read_bytes()
        if strip_reports and (rel.startswith(("scenes/", "benchmarks/"))
                              or rel == "hard_cases.py"):
            text = without_report_part(text.decode("utf-8")).encode("utf-8")
        digest.update(b"\0".join([rel.encode(), text, b""]))  # rel NUL text NUL
    return digest.hexdigest()[:16]


def fail(message):
    """Stop while the workflow is being read: one line naming the file and field,
    no traceback and no plan."""
    print(f"error: {message}", file=sys.stderr)
    sys.exit(1)


# (the HTML report's captions: report_html.smk and filippov_paper.report_html)


# ----------------------------------------------------------------------------- scenes
# (compute.smk) The resolution each scene is built at, and the scenes split into chunks.
RESOLUTION = config.get("resolution", DEFAULT_RESOLUTION)


@functools.lru_cache(maxsize=None)
def scene_resolution(scene):
    """The resolution scene `scene` is built at: the run's, if the scene file has a
    block of that name under `resolutions`, else the default -- so that asking for
    another resolution reruns only the scenes that have one."""
    try:
        data = yaml.safe_load(Path(f"config/scenes/{scene}.yaml").read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return DEFAULT_RESOLUTION
    if not isinstance(data, dict):
        return DEFAULT_RESOLUTION
    return apply_resolution(data, RESOLUTION).get("resolution", DEFAULT_RESOLUTION)


def scene_chunks():
    """{id: N} for the scene files with a top-level `chunks: N` (N >= 1).

    Read when the DAG is built, so the chunk jobs are known statically (no
    checkpoint). Each scene is checked against the size limits first (cheap,
    from its parameters), so that no oversized plan is ever built: a scene over
    a limit stops the run here with one line. A malformed file or `chunks`
    value is left to rule `compute`, whose job reports it (schema validation
    names the field).
    """
    found = {}
    try:
        lim = limits(config)
    except SceneError as exc:
        fail(exc)
    for path in sorted(Path("config/scenes").glob("*.yaml")):
        try:
            data = yaml.safe_load(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            continue
        try:
            if isinstance(data, dict) and isinstance(data.get("parameters", {}), dict):
                data = apply_resolution(data, RESOLUTION)
                check_limits(data, lim, path)
        except SceneError as exc:
            fail(exc)
        except (TypeError, ValueError, AttributeError):
            pass  # malformed: the schema check of the job names the field
        n = data.get("chunks") if isinstance(data, dict) else None
        if isinstance(n, int) and not isinstance(n, bool) and n >= 1:
            n = sweep_jobs(n)
            if n > 1 or SWEEP_JOBS is None:  # capped to one job: rule compute runs it
                found[path.stem] = n
    return found


# How many jobs a split sweep runs as (config["sweep_jobs"]): at most that many, or,
# with "scene", as many as the scene file's `chunks` (or hard_cases.chunks) asks. A
# layout choice only: the merged datasets are byte-identical for any split
# (tests/test_chunks.py, tests/test_hard_cases_workflow.py). Read from the config, not
# from the executor, so that a cluster's job steps plan the same jobs as the host.
SWEEP_JOBS = None if config.get("sweep_jobs", "scene") == "scene" else int(config["sweep_jobs"])


def sweep_jobs(declared):
    """The jobs a sweep that asks for `declared` chunks is split into in this run."""
    return declared if SWEEP_JOBS is None else min(declared, SWEEP_JOBS)


# ----------------------------------------------------------------------------- hard cases
def hard_cases_chunks():
    """`chunks` of config["hard_cases"], read when the DAG is built (hard_cases.smk). A
    malformed block is left to the jobs, which report it naming the field (as rule
    `compute` does for scenes), so one job is planned for it."""
    block = config.get("hard_cases")
    n = block.get("chunks", 1) if isinstance(block, dict) else 1
    return sweep_jobs(n) if isinstance(n, int) and not isinstance(n, bool) and n >= 1 else 1


# ----------------------------------------------------------------------------- report
# (report.smk)
def tex_available():
    """pdflatex, latexmk and elsarticle.cls are all installed."""
    if not (shutil.which("latexmk") and shutil.which("pdflatex") and shutil.which("kpsewhich")):
        return False
    found = subprocess.run(["kpsewhich", "elsarticle.cls"], capture_output=True, text=True)
    return found.returncode == 0 and bool(found.stdout.strip())


def report_scenes():
    return list(config["scenes"])


def report_data(wildcards):
    data = [f"results/{s}.nc" for s in report_scenes()]
    return data


# The benchmarks' report parts (filippov_paper.product.report_benchmarks, read from the
# modules' source): the dataset each reads and the table its block goes into. A dataset of
# `make bench` (results/bench_<name>.nc of a generated rule bench_<name>) is read when present
# but is no input: an input would make every library edit rerun the minutes-long benchmark
# before the report. Its modification time is a param instead, so a new benchmark run still
# refreshes the report. Any other (work_precision: the default build's sweep) is an input.
def report_benchmarks():
    from filippov_paper.product import report_benchmarks as declared

    try:
        return declared()
    except (ValueError, SyntaxError) as exc:
        fail(exc)


def report_bench_datasets(optional):
    """results/<dataset>.nc of the benchmarks' report parts: those made by `make bench`
    (optional=True) or the others (inputs of the report)."""
    made_by_bench = {f"bench_{name}" for name in workflow_benchmarks()}
    return [f"results/{place['dataset']}.nc" for place in report_benchmarks().values()
            if (place["dataset"] in made_by_bench) == optional]


def hard_case_tables():
    """The files of paper/generated/ the hard-case sweep's report part writes."""
    from filippov_paper.product import hard_case_tables as declared

    try:
        return declared()
    except (ValueError, SyntaxError) as exc:
        fail(exc)


def report_bench_tables():
    """The files of paper/generated/ the benchmarks' report parts write (tab_bench.tex)."""
    return list(dict.fromkeys(place["table"] for place in report_benchmarks().values()
                              if place["table"]))


def workflow_benchmarks():
    """{name: WORKFLOW} of the benchmarks of `make bench` that bench.smk makes a rule for
    (filippov_paper.product; read from the modules' source). A malformed WORKFLOW stops
    the run with one line naming the file."""
    from filippov_paper.product import workflow_benchmarks as declared

    try:
        return declared()
    except (ValueError, SyntaxError) as exc:
        fail(exc)


def benchmark_figures():
    """The benchmarks with a figure of `make bench` (filippov_paper.product; from the
    plotting modules' file names): bench.smk makes a rule plot_bench_<name> for each."""
    from filippov_paper.product import benchmark_figures as found

    return found()


def bench_stamps():
    return {p: Path(p).stat().st_mtime_ns for p in report_bench_datasets(optional=True)
            if Path(p).exists()}


def report_figures(wildcards):
    return [f"figures/{s}.pdf" for s in report_scenes()]
