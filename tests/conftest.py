"""Shared paths and the one Snakemake build the workflow tests share.

Makes `src/` importable when the package is not installed.
"""
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src"
if str(SRC) not in sys.path:
    sys.path.insert(0, str(SRC))


def copy_project(dest: Path) -> Path:
    """What a fresh clone needs to run the workflow: Snakefile, config, workflow, paper."""
    dest.mkdir(parents=True)
    shutil.copy(ROOT / "Snakefile", dest / "Snakefile")
    for folder in ("config", "workflow"):
        shutil.copytree(ROOT / folder, dest / folder)
    if (ROOT / "paper").is_dir():
        (dest / "paper").mkdir()
        for tex in (ROOT / "paper").glob("*.tex"):
            shutil.copy(tex, dest / "paper" / tex.name)
    return dest


def run_snakemake(work: Path, *args, cores: str = "1", timeout: float = 3000):
    env = dict(os.environ, MPLBACKEND="Agg", SOURCE_DATE_EPOCH="0")
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(SRC), env.get("PYTHONPATH")]))
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    cmd = [sys.executable, "-m", "snakemake", "--cores", cores, "--directory", str(work), *args]
    return subprocess.run(cmd, cwd=work, env=env, capture_output=True, text=True,
                          timeout=timeout)


@pytest.fixture(scope="session")
def workflow_build(tmp_path_factory):
    """`snakemake` (rule all) once in a fresh copy of the project, as a clone would
    run it; every test that needs built results, figures or the report reads this
    build instead of computing the scenes again. Tests must not modify it."""
    work = copy_project(tmp_path_factory.mktemp("build") / "project")
    t0 = time.perf_counter()
    run = run_snakemake(work, cores="all")
    return {"work": work, "run": run, "seconds": time.perf_counter() - t0}
