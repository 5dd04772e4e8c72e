"""The library installs without the workflow engine, and knows its version."""
import ast
import tomllib
from pathlib import Path

import filippov
from filippov import io

ROOT = Path(__file__).resolve().parents[1]


def test_library_requirements_leave_out_snakemake():
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert not any(r.lower().startswith("snakemake") for r in project["dependencies"])
    assert any(r.startswith("snakemake") for r in project["optional-dependencies"]["workflow"])


def test_no_library_module_imports_snakemake():
    for path in (ROOT / "src" / "filippov").rglob("*.py"):
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else \
                [node.module or ""] if isinstance(node, ast.ImportFrom) else []
            assert not any(n.split(".")[0] == "snakemake" for n in names), path


def _imports(path):
    tree = ast.parse(path.read_text(), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            yield from (a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom) and node.level == 0:
            yield node.module or ""


def _packages(pyproject: Path):
    """The packages setuptools builds from a pyproject's packages.find (what `pip install`
    of that directory installs)."""
    from setuptools import find_packages

    find = tomllib.loads(pyproject.read_text())["tool"]["setuptools"]["packages"]["find"]
    return find_packages(where=str(pyproject.parent / find["where"][0]),
                         include=find.get("include", ("*",)))


def test_the_library_installs_without_the_paper_s_pipeline():
    """`pip install .` gives filippov alone; the pipeline (scenes, figures, report,
    manifest, tolerances, hard cases, benchmarks) is workflow/'s own distribution."""
    library = _packages(ROOT / "pyproject.toml")
    assert "filippov" in library and "filippov.kernel" in library
    assert all(p == "filippov" or p.startswith("filippov.") for p in library), library
    pipeline = _packages(ROOT / "workflow" / "pyproject.toml")
    assert {"filippov_paper", "filippov_paper.scenes", "filippov_paper.plotting",
            "filippov_paper.benchmarks"} <= set(pipeline)
    assert all(p.startswith("filippov_paper") for p in pipeline), pipeline


def test_the_library_never_imports_the_pipeline():
    for path in (ROOT / "src" / "filippov").rglob("*.py"):
        bad = [n for n in _imports(path) if n.split(".")[0] == "filippov_paper"]
        assert not bad, (path, bad)


_BLOCK_PIPELINE = """
import importlib, pkgutil, sys

class NoPipeline:
    def find_spec(self, name, path=None, target=None):
        if name.split(".")[0] == "filippov_paper":
            raise ImportError("the library imported the pipeline: " + name)

sys.meta_path.insert(0, NoPipeline())
import filippov
names = [m.name for m in pkgutil.walk_packages(filippov.__path__, "filippov.")]
for name in names:
    importlib.import_module(name)
print(len(names))
"""


def test_every_library_module_imports_without_the_pipeline(tmp_path):
    """Each module of filippov imports in a process where importing filippov_paper
    fails (a meta-path hook refuses it)."""
    import subprocess
    import sys

    res = subprocess.run([sys.executable, "-c", _BLOCK_PIPELINE], cwd=tmp_path,
                         capture_output=True, text=True, timeout=600)
    assert res.returncode == 0, res.stderr[-2000:]
    assert int(res.stdout.split()[-1]) > 30   # every module was imported


def test_an_installed_copy_reports_its_version(monkeypatch, tmp_path):
    # outside a git checkout (as in site-packages), code_version names the release
    monkeypatch.setattr(io, "__file__", str(tmp_path / "io.py"))
    io.code_version.cache_clear()
    try:
        assert io.code_version() == f"filippov-{filippov.__version__} (installed)"
    finally:
        io.code_version.cache_clear()


def test_licence_and_citation_are_there():
    # the software is cited as itself, the paper under references (tests/test_citation.py)
    assert "MIT License" in (ROOT / "LICENSE").read_text()
    cff = (ROOT / "CITATION.cff").read_text()
    assert "type: software" in cff and "references:" in cff and "Sieber" in cff
    assert "preferred-citation" not in cff and (ROOT / ".zenodo.json").is_file()


def test_progress_lines_name_the_chunk_and_the_time_left(capsys):
    from filippov.progress import Progress, context

    with context("chunk 2/4"):
        bar = Progress("fig99_test", 4, enabled=True, every=0.0)
    for _ in range(4):
        bar.step(note="x")
    lines = capsys.readouterr().err.splitlines()
    assert lines[0].startswith("[fig99_test chunk 2/4] 1/4 ( 25.0%)") and " eta " in lines[0]
    assert lines[-1].split()[6] == "done"   # [label chunk k/n] 4/4 (100.0%) t done x
