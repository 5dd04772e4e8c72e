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
