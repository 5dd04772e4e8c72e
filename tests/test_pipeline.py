"""The Snakemake workflow end to end in a scratch copy of the project.

Skipped only while the compute package `filippov.scenes` cannot be imported.
"""
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

pytest.importorskip("filippov.scenes", reason="compute code (filippov.scenes) not importable yet")

from conftest import ROOT, copy_project, run_snakemake


def _project(tmp_path) -> Path:
    return copy_project(tmp_path / "project")


def _snakemake(work: Path, *args):
    return run_snakemake(work, *args, cores="1", timeout=1800)


def test_builds_every_figure_then_nothing_to_do(workflow_build):
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    import yaml
    for scene in yaml.safe_load((work / "config" / "config.yaml").read_text())["scenes"]:
        for ext in ("pdf", "png"):
            assert (work / "figures" / f"{scene}.{ext}").stat().st_size > 0
    again = _snakemake(work, "-n")
    assert again.returncode == 0, again.stdout + again.stderr
    out = again.stdout + again.stderr
    assert "Nothing to be done" in out, "\n".join(l for l in out.splitlines() if "reason" in l)


def test_invalid_scene_fails_cleanly(tmp_path):
    work = _project(tmp_path)
    scene = work / "config" / "scenes" / "fig02_cases.yaml"
    scene.write_text(scene.read_text().replace("eps: 0.1", "eps: -0.1"))
    run = _snakemake(work, "results/fig02_cases.nc")
    assert run.returncode != 0
    assert "parameters.eps" in run.stdout + run.stderr
    assert not (work / "results" / "fig02_cases.nc").exists()
