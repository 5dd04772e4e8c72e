"""The documentation site (docs/, built by `make docs`): its code runs, its numbers hold,
and the README points to it instead of carrying the user guide itself.

Every ```python block of every page in docs/ is run, the blocks of one page in order in
one namespace (a page is a walk-through: later blocks use earlier names). The tutorial's
numbers are checked against the closed form of examples/relay_feedback.py. The build
itself (sphinx, warnings as errors) is `make docs`, which CI runs after `make test`.
"""
import contextlib
import importlib.util
import io
import re

import numpy as np
import pytest

from conftest import ROOT

DOCS = ROOT / "docs"
PAGES = sorted(p for p in DOCS.glob("*.md"))
README_MAX_LINES = 80


def python_blocks(page):
    return re.findall(r"^```python\n(.*?)^```", page.read_text(), re.S | re.M)


def run_page(page):
    """(namespace, stdout) after running every python block of the page in order."""
    scope, out = {"__name__": f"docs_{page.stem}"}, io.StringIO()
    with contextlib.redirect_stdout(out):
        for i, code in enumerate(python_blocks(page)):
            exec(compile(code, f"{page.relative_to(ROOT)} (block {i + 1})", "exec"), scope)
    return scope, out.getvalue()


@pytest.fixture(scope="module")
def tutorial():
    return run_page(DOCS / "tutorial.md")


@pytest.fixture(scope="module")
def relay():
    spec = importlib.util.spec_from_file_location("relay", ROOT / "examples" / "relay_feedback.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_the_site_has_its_configuration_and_pages():
    assert (DOCS / "conf.py").is_file()
    index = (DOCS / "index.md").read_text()
    for page in ("getting_started", "tutorial", "pipeline", "api", "auto_examples/index"):
        assert re.search(rf"^{re.escape(page)}$", index, re.M), f"{page} not in the toctree"
        assert page.startswith("auto_") or (DOCS / f"{page}.md").is_file() or \
            (DOCS / f"{page}.rst").is_file()
    assert (ROOT / "examples" / "GALLERY_HEADER.rst").is_file()   # the gallery's index


def test_the_readme_is_short_and_points_to_the_docs():
    text = (ROOT / "README.md").read_text()
    assert len(text.splitlines()) <= README_MAX_LINES, "the user guide belongs in docs/"
    assert "make docs" in text and "docs/_build/html/index.html" in text
    for page in ("getting_started", "tutorial", "pipeline", "api"):
        assert f"docs/{page}." in text, f"the README does not link docs/{page}"
    assert "```python" not in text   # the code lives in the tutorial, where it is tested


def test_make_docs_is_a_target_and_runs_in_ci():
    makefile = (ROOT / "Makefile").read_text()
    assert re.search(r"^docs:", makefile, re.M)
    assert re.search(r"-W\b.*--keep-going|--keep-going.*-W\b", makefile)
    ci = (ROOT / ".ci" / "run").read_text()
    # verify's first build is the suite's shared build and cross-cpu's native one
    assert (ci.index("make verify") < ci.index('FILIPPOV_TEST_BUILD="$native" make test')
            < ci.index("make docs") < ci.index("make cross-cpu"))
    lock = (ROOT / "requirements.lock").read_text()
    for pkg in ("sphinx", "myst-parser", "sphinx-gallery"):
        assert re.search(rf"^{pkg}==", lock, re.M | re.I), f"{pkg} is not pinned"


@pytest.mark.parametrize("page", [p.name for p in PAGES])
def test_every_python_block_of_the_page_runs(page, tutorial):
    if page == "tutorial.md":   # already run once by the fixture
        assert tutorial[1]
        return
    _, out = run_page(DOCS / page)
    if page == "getting_started.md":   # the numbers the page quotes
        assert "slide_start 2.0 True" in out and "`slide_start 2.0 True`" in \
            (DOCS / page).read_text()


def test_the_tutorial_has_the_blocks_it_describes():
    codes = python_blocks(DOCS / "tutorial.md")
    assert len(codes) == 8
    assert len(codes[0].strip().splitlines()) <= 30   # the first system fits a screen


def test_the_reference_driver_finds_the_relay_orbit(tutorial, relay):
    scope, out = tutorial
    want = relay.closed_form()
    assert abs(scope["orbit"].t - want["period"]) < 1e-10
    got = np.sort(np.abs(np.linalg.eigvals(
        scope["return_jacobian"](scope["relay"], scope["orbit"], scope["up"],
                                 jacobian=lambda mode, z: relay.A))))[::-1]
    # dP/dz has the nontrivial multipliers and a 0 (the section direction)
    np.testing.assert_allclose(got[:2], want["multipliers"][1:], rtol=1e-6)
    assert "Floquet multipliers" in out
    # the numbers the page quotes
    text = (DOCS / "tutorial.md").read_text()
    assert f"{scope['orbit'].t:.15g}" in text and f"{want['period']:.15g}" in text
    assert "switch_grad does not match a finite difference of switch" in out


def test_the_tutorial_s_several_surfaces_follow_their_closed_form(tutorial):
    """The section on several surfaces: the events the page describes, at the times of
    the closed form (slide at 0.3, exit at x = 1, across x = 2 at y = -1/2, slide at 4)."""
    scope, out = tutorial
    events = scope["run"].events
    assert [e.kind for e in events] == ["start", "slide_start", "slide_end", "crossing",
                                       "slide_start"]
    np.testing.assert_allclose([e.t for e in events], [0.0, 0.3, 1.0, 2.0, 4.0], atol=1e-10)
    assert abs(events[3].state[1] + 0.5) <= 1e-10
    assert "crossing     -- -> -+" in out
    # the same system defined once (FilippovSystem, fields=): the same events, to the
    # rounding of numba's evaluation against NumPy's propagated over t <= 4
    again = scope["again"].events
    assert [e.kind for e in again] == [e.kind for e in events]
    assert max(abs(a.t - b.t) for a, b in zip(events, again)) <= 1e-12


def test_the_compiled_engine_agrees_with_the_reference_driver(tutorial):
    scope, _ = tutorial
    ret = scope["returns"]
    assert ret.state.shape == (2, 3) and np.all(ret.time > 0)
    np.testing.assert_allclose(ret.state[:, 0], 0.0, atol=1e-14)   # on the section x1 = 0
    ref = scope["return_jacobian"](scope["relay"], scope["orbit"], scope["up"],
                                   jacobian=lambda mode, z: scope["A"])
    np.testing.assert_allclose(scope["J"], ref, rtol=0, atol=1e-8)


def test_one_definition_and_the_symbolic_system_find_the_orbit_on_both_engines(tutorial,
                                                                                relay):
    scope, out = tutorial
    want = relay.closed_form()
    assert abs(scope["po"].period - want["period"]) < 1e-12       # the last engine: reference
    np.testing.assert_allclose(scope["po"].multipliers, want["multipliers"], atol=1e-9)
    assert np.array_equal(np.asarray(scope["relay_sym"].jacobians["plus"], dtype=float),
                          relay.A)
    assert out.count("compiled 3.67975067086") == 2 and out.count("reference 3.67975067086") == 2


def test_no_docstring_cites_a_latex_label_of_the_paper():
    # the API reference is made from the docstrings: a paper's equation, figure or
    # section is cited by the number the paper prints ("Eq. (9)", "Fig. 4", "Appendix C";
    # paper/paper_labels.tex), not by its LaTeX label (eq:atSl, fig:retmaps, sec:dfo1).
    # Every module of the library, and the pipeline's modules on the API pages.
    from filippov_paper.report_html import INTERNAL_LABEL

    modules = sorted((ROOT / "src" / "filippov").rglob("*.py"))
    documented = re.findall(r"^\s+(filippov_paper\.[\w.]+)$",
                            (DOCS / "modules.rst").read_text(), re.M)
    assert documented
    modules += [ROOT / "workflow" / (name.replace(".", "/") + ".py") for name in documented]
    leaks = [f"{path.relative_to(ROOT)}:{text[:m.start()].count(chr(10)) + 1}: {m.group(0)}"
             for path in modules for text in [path.read_text()]
             for m in re.finditer(INTERNAL_LABEL.pattern + r"[A-Za-z0-9:_-]*", text)]
    assert not leaks, leaks
