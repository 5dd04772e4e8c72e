"""The README says how to build and test first, what comes out, and where to read more.

The user guide (and its code, run by tests/test_docs.py) lives in the documentation site,
docs/; the README keeps the two commands at its top, exactly as a newcomer types them.
"""
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
TEXT = (ROOT / "README.md").read_text()

TWO_COMMANDS = (
    "make figures   # builds every figure into figures/ and the report paper/main.pdf "
    "(data in results/)\n"
    "make test      # runs the test suite\n")


def test_the_two_commands_come_first():
    first = re.search(r"```(\w*)\n(.*?)```", TEXT, re.S)
    assert first.group(1) == "sh" and first.group(2) == TWO_COMMANDS
    assert TEXT.index("```") < TEXT.index("\n## ")   # before any section
    assert "Both create `.venv` from `requirements.lock` on first use" in TEXT


def test_the_readme_says_what_comes_out_and_where_to_read_more():
    for heading in ("## What comes out", "## Read more"):
        assert heading in TEXT
    for path in ("results/", "figures/", "paper/main.pdf"):
        assert path in TEXT
    # every link points to a file or folder of the repository
    for target in re.findall(r"\]\(([^)#]+)\)", TEXT):
        assert (ROOT / target).exists(), target


def _short(x: float) -> str:
    """1e-09 -> 1e-9: a power of ten as the README writes it."""
    mantissa, exponent = f"{x:.0e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def test_the_readme_s_property_suite_numbers_are_the_suite_s():
    """The README quotes the property suite's tolerances and deep sample size: they are
    the constants the suite runs with (tests/test_properties.py, tests/conftest.py)."""
    import test_properties as tp
    from hypothesis import settings

    text = " ".join((Path(__file__).resolve().parents[1] / "README.md").read_text().split())
    assert (f"times to {_short(tp.TOL['exact'])} (exact flows) and "
            f"{_short(tp.TOL['integrate'])} (integrated)") in text
    assert f"dP/dz to {_short(tp.TOL_JAC)} relative" in text
    deep = settings.get_profile("deep").max_examples
    assert re.search(rf"`make test-deep` {deep} random systems per test", text)


def test_the_code_map_names_what_is_there():
    """Every name the README's code map quotes is a path of the repository, a module or
    package of the library or of the pipeline, or a name the library exports."""
    import filippov

    section = TEXT.split("## Where the code lives")[1].split("\n## ")[0]
    names = [n for n in re.findall(r"`([^`]+)`", section) if not n.startswith("pip ")]
    assert len(names) >= 15
    homes = (ROOT, ROOT / "src" / "filippov", ROOT / "workflow" / "filippov_paper")
    for name in names:
        bare = name.rstrip("/")
        assert (any((home / bare).exists() or (home / f"{bare}.py").exists() for home in homes)
                or bare in filippov.__all__), name
