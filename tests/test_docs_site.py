"""The built documentation site (docs/_build/html, `make docs`), read as files: the
pages cite the paper by its printed numbers, work offline (MathJax is served by the
site, no script from the web), the gallery has a figure per example, and long code
and output lines scroll instead of being cut.

The site is built once per run by the ``docs_site`` fixture (tests/conftest.py: sphinx
with warnings as errors, as `make docs`, from a copy of docs/ and examples/; about half
a minute), or read from ``FILIPPOV_DOCS_BUILD=DIR`` (e.g. docs/_build/html after `make
docs`). tests/test_docs_browser.py loads the same site in a headless browser.
"""
import html
import re
from html.parser import HTMLParser
from pathlib import Path
from urllib.parse import urlsplit

import pytest

from conftest import ROOT
from filippov_paper.paper_labels import read_tex
from filippov_paper.report_html import INTERNAL_LABEL

#: a LaTeX label as written (INTERNAL_LABEL finds its start): eq:sgfilipslow, fig:p:xi12
LABEL = re.compile(INTERNAL_LABEL.pattern + r"[A-Za-z0-9:_-]*")

LABELS = sorted(read_tex((ROOT / "paper" / "paper_labels.tex").read_text()), key=len,
                reverse=True)
EXAMPLES = sorted(p.stem for p in (ROOT / "examples").glob("*.py"))


class _Page(HTMLParser):
    """The text of a page (no scripts or styles) and the resources it loads."""

    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.text, self.scripts, self.styles, self.images, self._skip = [], [], [], [], 0

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag in ("script", "style"):
            self._skip += 1
        if tag == "script" and attrs.get("src"):
            self.scripts.append(attrs["src"])
        if tag == "link" and "stylesheet" in (attrs.get("rel") or ""):
            self.styles.append(attrs.get("href", ""))
        if tag == "img":
            self.images.append(attrs.get("src", ""))

    def handle_endtag(self, tag):
        if tag in ("script", "style"):
            self._skip -= 1

    def handle_data(self, data):
        if not self._skip:
            self.text.append(data)


def read_page(path: Path) -> _Page:
    page = _Page()
    page.feed(path.read_text(encoding="utf-8"))
    page.text = html.unescape(" ".join(page.text))
    return page


def local_file(page: Path, url: str) -> Path:
    return (page.parent / urlsplit(url).path).resolve()


@pytest.fixture(scope="module")
def pages(docs_site):
    found = sorted(docs_site.rglob("*.html"))
    assert len(found) > 20, f"{docs_site}: {len(found)} pages"
    return {p: read_page(p) for p in found}


def test_no_page_cites_a_latex_label_of_the_paper(pages, docs_site):
    # the API pages come from the docstrings: they cite "Eq. (9)", "Fig. 4", not eq:atSl
    leaks = {}
    for path, page in pages.items():
        found = {m.group(0) for m in LABEL.finditer(page.text)}
        found |= {label for label in LABELS if label in page.text}
        if found:
            leaks[path.relative_to(docs_site).as_posix()] = sorted(found)
    assert not leaks, leaks


def test_no_page_shows_where_the_site_was_built(pages, docs_site):
    # a module constant's value rendered by autodoc showed the build's checkout folder
    # (filippov_paper.product.PACKAGE = PosixPath('/tmp/ci-.../workflow/...')): a page
    # that changes with the machine and says nothing to a reader
    folders = (str(ROOT), str(docs_site.parent), "PosixPath(")  # the tree, the build's copy
    shown = {p.relative_to(docs_site).as_posix(): [f for f in folders if f in p.read_text()]
             for p in pages}
    assert not any(shown.values()), {k: v for k, v in shown.items() if v}


def test_no_page_loads_a_script_or_style_from_the_web(pages, docs_site):
    # offline, a script from a CDN (MathJax's default) does not load: every formula would
    # show its raw TeX. Every script and stylesheet is a file of the site.
    for path, page in pages.items():
        for url in page.scripts + page.styles:
            assert not urlsplit(url).scheme and not url.startswith("//"), (path, url)
            assert local_file(path, url).is_file(), (path, url)


def test_the_pages_with_math_load_mathjax_from_the_site(pages, docs_site):
    with_math = {p: page for p, page in pages.items()
                 if 'class="math' in p.read_text(encoding="utf-8")}
    names = {p.relative_to(docs_site).as_posix() for p in with_math}
    # the tutorial's formulas and every example's docstring (written in math)
    assert {"tutorial.html"} | {f"auto_examples/{n}.html" for n in EXAMPLES} <= names
    mathjax = docs_site / "_static" / "mathjax"
    for path, page in with_math.items():
        scripts = [local_file(path, s) for s in page.scripts]
        assert mathjax / "tex-chtml.js" in scripts, (path, page.scripts)
    # the one combined script, the fonts CommonHTML asks for, the components MathJax
    # loads on demand (the menu, the TeX extensions), and MathJax's licence
    assert (mathjax / "tex-chtml.js").stat().st_size > 500_000
    assert re.search(r"MathJax|mathjax", (mathjax / "tex-chtml.js").read_text()[:100_000])
    assert len(list((mathjax / "output" / "chtml" / "fonts" / "woff-v2").glob("*.woff"))) > 10
    assert (mathjax / "input" / "tex" / "extensions" / "ams.js").is_file()
    assert (mathjax / "ui" / "menu.js").is_file()
    assert "Apache License" in (mathjax / "LICENSE").read_text()


def test_mathjax_comes_from_a_pinned_package():
    lock = (ROOT / "requirements.lock").read_text()
    assert re.search(r"^django-static-mathjax==3\.2\.2\.\d+$", lock, re.M)
    makefile = (ROOT / "Makefile").read_text()
    lock_pkgs = re.search(r"^LOCK_PKGS = (.*?[^\\])$", makefile, re.M | re.S).group(1)
    assert "django-static-mathjax" in lock_pkgs.split()


@pytest.mark.parametrize("name", EXAMPLES)
def test_each_example_page_shows_its_figure(pages, docs_site, name):
    path = docs_site / "auto_examples" / f"{name}.html"
    images = [local_file(path, s) for s in pages[path].images]
    figure = docs_site / "_images" / f"sphx_glr_{name}_001.png"
    assert figure in images, pages[path].images
    assert figure.read_bytes().startswith(b"\x89PNG") and figure.stat().st_size > 10_000


def test_the_gallery_thumbnails_are_the_figures(pages, docs_site):
    # sphinx-gallery's placeholder when a script draws nothing: one image for all three
    path = docs_site / "auto_examples" / "index.html"
    thumbs = [local_file(path, s) for s in pages[path].images]
    assert len(thumbs) == len(EXAMPLES), thumbs
    assert {t.name for t in thumbs} == {f"sphx_glr_{n}_thumb.png" for n in EXAMPLES}
    contents = {t.read_bytes() for t in thumbs}
    assert len(contents) == len(EXAMPLES)   # three different pictures


def test_long_lines_scroll_instead_of_being_cut(pages, docs_site):
    # alabaster's pre blocks clip what does not fit (the examples' tables are 70-80
    # columns with the |difference| column last): every page loads custom.css, which
    # gives every pre block a horizontal scroll bar, and the body is widened
    css = docs_site / "_static" / "custom.css"
    for path, page in pages.items():
        if path.parent.name == "_sources":
            continue
        assert css in [local_file(path, s) for s in page.styles], path
    rules = re.sub(r"/\*.*?\*/", "", css.read_text(), flags=re.S)
    pre = re.search(r"(?:^|\})\s*pre\s*\{([^}]*)\}", rules)
    assert pre and re.search(r"overflow-x:\s*auto", pre.group(1)), rules
    theme = (docs_site / "_static" / "alabaster.css").read_text()
    width = re.search(r"div\.document\s*\{\s*width:\s*(\d+)px", theme)
    assert width and int(width.group(1)) >= 1200, "the page is alabaster's 940 px"
