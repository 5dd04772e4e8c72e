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

ROOT = Path(__file__).resolve().parents[1]


def _project(tmp_path) -> Path:
    work = tmp_path / "project"
    work.mkdir()
    shutil.copy(ROOT / "Snakefile", work / "Snakefile")
    shutil.copytree(ROOT / "config", work / "config")
    shutil.copytree(ROOT / "workflow", work / "workflow")
    return work


def _snakemake(work: Path, *args):
    env = dict(os.environ, MPLBACKEND="Agg")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "src"), env.get("PYTHONPATH")]))
    cmd = [sys.executable, "-m", "snakemake", "--cores", "1", "--directory", str(work), *args]
    return subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True, timeout=1800)


def test_builds_every_figure_then_nothing_to_do(tmp_path):
    work = _project(tmp_path)
    run = _snakemake(work)
    assert run.returncode == 0, run.stdout + run.stderr
    import yaml
    for scene in yaml.safe_load((work / "config" / "config.yaml").read_text())["scenes"]:
        for ext in ("pdf", "png"):
            assert (work / "figures" / f"{scene}.{ext}").stat().st_size > 0
    again = _snakemake(work, "-n")
    assert again.returncode == 0, again.stdout + again.stderr
    assert "Nothing to be done" in again.stdout + again.stderr


def test_invalid_scene_fails_cleanly(tmp_path):
    work = _project(tmp_path)
    scene = work / "config" / "scenes" / "fig02_cases.yaml"
    scene.write_text(scene.read_text().replace("eps: 0.1", "eps: -0.1"))
    run = _snakemake(work, "results/fig02_cases.nc")
    assert run.returncode != 0
    assert "parameters.eps" in run.stdout + run.stderr
    assert not (work / "results" / "fig02_cases.nc").exists()
