"""docs/decisions.md keeps why the code is as it is where the reason is a measurement or
an incident (issue 32, item 7); the code keeps a one-line pointer. Every pointer names
an entry, every entry is pointed at, and the library's comments and docstrings hold no
incident logs of their own."""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "decisions.md"
POINTER = re.compile(r"docs/decisions\.md#([a-z0-9-]+)")
#: how an incident log or a measurement reads: these belong on the decisions page
MARKERS = re.compile(r"[Ff]ound by tests/|\d s of a \d+ s|ms a call|\d+-\d+% slower|"
                     r"[Mm]easured on one|seconds at eps|\d+ steps, [\d.]+ s\b")


def _sources():
    for top in ("src", "workflow"):
        yield from (p for p in (ROOT / top).rglob("*.py") if "__pycache__" not in p.parts)


def test_every_pointer_names_an_entry_and_every_entry_is_pointed_at():
    anchors = set(re.findall(r"^\(([a-z0-9-]+)\)=$", PAGE.read_text(), re.M))
    assert len(anchors) >= 10
    pointed = {}
    for path in _sources():
        for name in POINTER.findall(path.read_text()):
            pointed.setdefault(name, []).append(path.relative_to(ROOT))
    assert set(pointed) - anchors == set(), {k: pointed[k] for k in set(pointed) - anchors}
    assert anchors - set(pointed) == set()


def test_the_library_holds_no_incident_logs():
    found = []
    for path in (ROOT / "src" / "filippov").rglob("*.py"):
        for i, line in enumerate(path.read_text().splitlines(), 1):
            if MARKERS.search(line):
                found.append(f"{path.relative_to(ROOT)}:{i}: {line.strip()}")
    assert not found, "\n".join(found)


def test_the_page_is_in_the_site():
    assert "\ndecisions\n" in (ROOT / "docs" / "index.md").read_text()
