"""The library imports scipy only through its public names (issue 58): a private module
(scipy.integrate._ivp.base) may move in any release. The DOP853 tableau is the one
exception, copied once into filippov.dop853_tableau and checked against scipy there."""
import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "filippov"


def test_no_module_imports_a_private_scipy_module():
    found = []
    for path in SRC.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([node.module or ""] if isinstance(node, ast.ImportFrom)
                     else [a.name for a in node.names] if isinstance(node, ast.Import) else [])
            for name in names:
                if name.startswith("scipy") and any(p.startswith("_") for p in name.split(".")):
                    found.append(f"{path.relative_to(SRC)}: {name}")
    assert not found, found
