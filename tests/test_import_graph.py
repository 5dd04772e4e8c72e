"""The library's import graph (issue 58: one problem definition at the bottom, no import
circle). Module-level imports must form no cycle: a module that needs one above it
imports it inside the function that uses it, and the test below keeps that so. Imports
inside functions close none either: the views of a system and the section are at the
bottom (filippov.views, filippov.section), each front door picks its engine from a table
of its own, and filippov.engines, which gathers those tables, is imported by nothing."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1] / "src"


def _modules():
    out = {}
    for path in (ROOT / "filippov").rglob("*.py"):
        parts = path.relative_to(ROOT).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        out[name] = path
    return out


def _imported(name, path, node, mods):
    """The library modules an import statement of module ``name`` names."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name in mods]
    pkg = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
    for _ in range(node.level - 1):
        pkg = pkg.rsplit(".", 1)[0]
    base = (f"{pkg}.{node.module}" if node.module else pkg) if node.level else node.module
    found = []
    for a in node.names:
        target = f"{base}.{a.name}"
        found.append(target if target in mods else base)
    return [m for m in found if m in mods]


def graph(top_level_only: bool) -> dict:
    mods = _modules()
    edges = {}
    for name, path in mods.items():
        tree = ast.parse(path.read_text())
        nodes = tree.body if top_level_only else ast.walk(tree)
        edges[name] = {m for n in nodes if isinstance(n, (ast.Import, ast.ImportFrom))
                       for m in _imported(name, path, n, mods) if m != name}
    return edges


def cycles(edges: dict) -> list:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on, found = {}, {}, [], set(), []

    def visit(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in sorted(edges[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    for v in sorted(edges):
        if v not in index:
            visit(v)
    return found


def test_the_module_level_imports_form_no_cycle():
    edges = graph(top_level_only=True)
    assert len(edges) > 40 and "filippov.scale" in edges["filippov.simulate"]
    assert cycles(edges) == []


def test_a_cycle_is_found_where_there_is_one():
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]
    assert cycles({"a": {"b"}, "b": set()}) == []


def test_the_imports_inside_functions_close_no_circle_either():
    # the front doors' dispatch (filippov.engines) used to share a module with the views
    # of a system (now filippov.views, at the bottom): seven modules imported each other
    # through it, inside functions
    edges = graph(top_level_only=False)
    assert {"filippov.views", "filippov.section"} <= set(edges)
    assert cycles(edges) == []
    # nothing in the library imports the module that gathers the front doors' tables
    assert not [m for m, to in edges.items() if "filippov.engines" in to]
