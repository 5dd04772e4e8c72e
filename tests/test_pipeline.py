"""The Snakemake workflow end to end in a scratch copy of the project.

Skipped only while the compute package `filippov_paper.scenes` cannot be imported.
"""
import re
import shutil
from pathlib import Path

import pytest
import yaml

pytest.importorskip("filippov_paper.scenes", reason="compute code (filippov_paper.scenes) not importable yet")

from conftest import copy_project, run_snakemake
from filippov_paper.config import scene_files


def _project(tmp_path) -> Path:
    return copy_project(tmp_path / "project")


def _snakemake(work: Path, *args):
    return run_snakemake(work, *args, cores="1", timeout=1800)


def test_builds_every_figure_then_nothing_to_do(workflow_build):
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    for scene in scene_files(work / "config" / "scenes"):
        for ext in ("pdf", "png"):
            assert (work / "figures" / f"{scene}.{ext}").stat().st_size > 0
    # the hard-case eps sweep, merged from its chunks (temporary: removed after the merge)
    assert (work / "results" / "hard_cases.nc").stat().st_size > 0
    assert not list((work / "results").glob("chunks/hard_cases/*.nc"))
    again = _snakemake(work, "-n")
    assert again.returncode == 0, again.stdout + again.stderr
    out = again.stdout + again.stderr
    assert "Nothing to be done" in out, "\n".join(l for l in out.splitlines() if "reason" in l)


def _rule_counts(out: str) -> dict[str, int]:
    counts: dict[str, int] = {}
    for rule in re.findall(r"^(?:local)?rule (\w+):", out, re.M):
        counts[rule] = counts.get(rule, 0) + 1
    return counts


def _declared_chunks(work: Path) -> dict[str, int]:
    out = {}
    for path in sorted((work / "config" / "scenes").glob("*.yaml")):
        n = yaml.safe_load(path.read_text()).get("chunks")
        if n:
            out[path.stem] = n
    return out


@pytest.mark.parametrize("sweep_jobs", [None, 2, "scene"])
def test_a_build_splits_sweeps_into_at_most_sweep_jobs(sweep_jobs, tmp_path):
    """The jobs a clean build plans: a local build (config.yaml: sweep_jobs 1) one job per
    scene and one hard-case part; `scene` (the SLURM profile) every scene file's
    `chunks`; an integer caps them."""
    work = _project(tmp_path)
    extra = () if sweep_jobs is None else ("--config", f"sweep_jobs={sweep_jobs}")
    run = _snakemake(work, "-n", "--forceall", *extra)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-3000:]
    counts = _rule_counts(out)
    cap = yaml.safe_load((work / "config" / "config.yaml").read_text())["sweep_jobs"] \
        if sweep_jobs is None else sweep_jobs
    declared = _declared_chunks(work)
    hard = yaml.safe_load((work / "config" / "config.yaml").read_text())["hard_cases"]["chunks"]
    split = {s: n if cap == "scene" else min(n, cap) for s, n in declared.items()}
    split = {s: n for s, n in split.items() if n > 1}
    scenes = scene_files(work / "config" / "scenes")
    assert counts.get("compute_chunk", 0) == sum(split.values())
    assert counts.get("merge_chunks", 0) == len(split)
    assert counts["compute"] == len(scenes) - len(split)
    assert counts["hard_cases_part"] == (hard if cap == "scene" else min(hard, cap))
    assert counts["plot"] == len(scenes)
    if sweep_jobs is None:
        assert cap == 1 and "compute_chunk" not in counts and counts["hard_cases_part"] == 1


def test_sweep_jobs_must_be_a_positive_count_or_scene(tmp_path):
    work = _project(tmp_path)
    for bad in ("0", "many"):
        run = _snakemake(work, "-n", "--config", f"sweep_jobs={bad}")
        assert run.returncode != 0
        assert "error: config/config.yaml: sweep_jobs: " in run.stdout + run.stderr, bad


def test_a_chunked_build_writes_the_unsplit_dataset(workflow_build, tmp_path):
    """fig04 through the workflow's chunk and merge jobs (sweep_jobs=scene, as on a
    cluster) is byte-identical to the shared build's one compute job."""
    assert workflow_build["run"].returncode == 0
    built = workflow_build["work"]   # read only
    work = copy_project(tmp_path / "split")
    run = _snakemake(work, "results/fig04_retmaps.nc", "--config", "sweep_jobs=scene")
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    n = _declared_chunks(work)["fig04_retmaps"]
    assert n > 1 and len(list((work / "logs" / "compute_chunk" / "fig04_retmaps").glob(
        "*.log"))) == n
    assert (work / "logs" / "merge_chunks" / "fig04_retmaps.log").exists()
    assert not (built / "logs" / "compute_chunk").exists()   # the shared build: unsplit
    assert (work / "results" / "fig04_retmaps.nc").read_bytes() == \
        (built / "results" / "fig04_retmaps.nc").read_bytes()


def test_invalid_scene_fails_cleanly(tmp_path):
    work = _project(tmp_path)
    scene = work / "config" / "scenes" / "fig02_cases.yaml"
    scene.write_text(scene.read_text().replace("eps: 0.1", "eps: -0.1"))
    run = _snakemake(work, "results/fig02_cases.nc")
    assert run.returncode != 0
    assert "parameters.eps" in run.stdout + run.stderr
    assert not (work / "results" / "fig02_cases.nc").exists()


def _copy_of_build(workflow_build, tmp_path) -> Path:
    """The shared build, copied with its timestamps and Snakemake's metadata."""
    run = workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    work = tmp_path / "project"
    shutil.copytree(workflow_build["work"], work, symlinks=True)
    return work


def _planned(work: Path) -> dict[str, set]:
    """Jobs a dry run would execute: rule -> set of scene wildcards ('' if none)."""
    run = _snakemake(work, "-n")
    assert run.returncode == 0, run.stdout + run.stderr
    jobs: dict[str, set] = {}
    rule = None
    for line in (run.stdout + run.stderr).splitlines():
        m = re.match(r"^(?:local)?rule (\w+):", line)
        if m:
            rule = m.group(1)
            jobs.setdefault(rule, set()).add("")
            continue
        m = re.match(r"^\s+wildcards: scene=(\w+)", line)
        if m and rule:
            jobs[rule].discard("")
            jobs[rule].add(m.group(1))
    return jobs


def _planned_after_edit(workflow_build, tmp_path, scene_id: str, old: str, new: str) -> dict:
    """The jobs a copy of the finished build plans (none before) after ``old`` is
    replaced by ``new`` in the scene file ``scene_id``."""
    work = _copy_of_build(workflow_build, tmp_path)
    assert _planned(work) == {}
    scene = work / "config" / "scenes" / f"{scene_id}.yaml"
    text = scene.read_text()
    assert old in text
    scene.write_text(text.replace(old, new))
    return _planned(work)


def test_changing_one_scene_reruns_only_its_chain(workflow_build, tmp_path):
    jobs = _planned_after_edit(workflow_build, tmp_path, "fig08_s0theta", "n_theta: 400",
                               "n_theta: 401")
    assert jobs.pop("compute") == {"fig08_s0theta"}
    assert jobs.pop("plot") == {"fig08_s0theta"}
    jobs.pop("all", None)
    # the report (if built) quotes every dataset: it follows; nothing else does
    # the report, and the copy of the changed scene file the HTML report attaches
    assert jobs.pop("publish_scene", {"fig08_s0theta"}) == {"fig08_s0theta"}
    assert set(jobs) <= {"report_tables", "paper"}, jobs


def test_changing_a_compiled_engine_scene_reruns_only_its_chain(workflow_build, tmp_path):
    """As above for a scene on the compiled engine (one that a cluster splits into chunks;
    one job on a local build, sweep_jobs: 1): no job it shares with the
    other compiled-engine scenes, the hard cases or the work-precision sweep (a shared
    input regenerated for it -- a kernel-compiled marker was tried -- would rerun them
    all: 'input files updated by another job')."""
    jobs = _planned_after_edit(workflow_build, tmp_path, "fig04_retmaps", "n_geometric: 100",
                               "n_geometric: 101")
    assert jobs.pop("compute") == {"fig04_retmaps"}
    assert jobs.pop("plot") == {"fig04_retmaps"}
    jobs.pop("all", None)
    assert jobs.pop("publish_scene", {"fig04_retmaps"}) == {"fig04_retmaps"}
    assert set(jobs) <= {"report_tables", "paper"}, jobs


def test_editing_a_workflow_script_reruns_its_rule_only(workflow_build, tmp_path):
    work = _copy_of_build(workflow_build, tmp_path)
    script = work / "workflow" / "scripts" / "plot_scene.py"
    script.write_text(script.read_text() + "\n# an edit\n")
    jobs = _planned(work)
    scenes = set(scene_files(work / "config" / "scenes"))
    assert "compute" not in jobs
    assert jobs.pop("plot") == scenes
    jobs.pop("all", None)
    # the report includes the redrawn figures; the work-precision figure is drawn by
    # the same script
    assert set(jobs) <= {"paper", "plot_work_precision"}, jobs


def test_build_holds_the_hard_case_sweep_of_the_configured_eps(workflow_build):
    """results/hard_cases.nc of the build (chunk jobs, merged) is the sweep of
    filippov_paper.hard_cases over the configured eps in one process."""
    from filippov_paper import hard_cases
    from filippov.io import read_dataset

    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    block = yaml.safe_load((work / "config" / "config.yaml").read_text())["hard_cases"]
    built = read_dataset(work / "results" / "hard_cases.nc")
    whole = hard_cases.sweep(hard_cases.check_config(block)["eps"])
    # code_version names the commit at the time of writing; everything else is equal
    built.attrs.pop("code_version"), whole.attrs.pop("code_version")
    assert built.identical(whole)


def test_unknown_model_fails_cleanly(tmp_path):
    """A scene naming a model the registry does not have is refused, naming ``model`` and
    the choices, before anything is written."""
    work = _project(tmp_path)
    scene = work / "config" / "scenes" / "fig02_cases.yaml"
    scene.write_text(scene.read_text().replace("model: pseudo_equilibrium", "model: pseudo_equilibrum"))
    run = _snakemake(work, "results/fig02_cases.nc")
    assert run.returncode != 0
    out = run.stdout + run.stderr
    assert "model: unknown model 'pseudo_equilibrum'" in out and "pseudo_equilibrium" in out
    assert not (work / "results" / "fig02_cases.nc").exists()
