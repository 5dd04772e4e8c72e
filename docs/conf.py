"""Sphinx configuration of the filippov documentation (built by `make docs`).

The site is built from this tree's sources: the pages in this folder (MyST Markdown),
the API reference from the docstrings (autodoc, autosummary, napoleon for the NumPy
style sections), and the scripts in ../examples run and rendered by sphinx-gallery.
"""
import importlib.util
import os
import shutil
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path[:0] = [str(ROOT / "src"), str(ROOT / "workflow")]   # this tree's sources, installed or not
os.environ.setdefault("MPLBACKEND", "Agg")

import filippov  # noqa: E402

project = "filippov"
author = "The filippov developers"
copyright = "the filippov developers (MIT licence)"
release = version = filippov.__version__

extensions = [
    "myst_parser",
    "sphinx.ext.autodoc",
    "sphinx.ext.autosummary",
    "sphinx.ext.napoleon",
    "sphinx.ext.mathjax",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "**/sg_execution_times.rst"]
myst_enable_extensions = ["dollarmath"]
myst_heading_anchors = 3

autosummary_generate = True
# module pages (_templates/autosummary/module.rst) document each member once: the names
# `import filippov` gives are documented as filippov.<name>, not again in their module
autosummary_context = {"public_api": [n for n in filippov.__all__ if n[0] != "_"]}
templates_path = ["_templates"]
autodoc_default_options = {"members": True, "show-inheritance": False}
autodoc_member_order = "bysource"
autodoc_typehints = "none"          # the signatures show the defaults, the text the types
napoleon_google_docstring = False
napoleon_numpy_docstring = True

# the examples: plain scripts, each run once per build (a few seconds each); they print
# the solver's numbers beside closed forms and draw one figure, both of which the
# gallery shows under the code (the figure is also the example's thumbnail)
sphinx_gallery_conf = {
    "examples_dirs": str(ROOT / "examples"),
    "gallery_dirs": "auto_examples",
    "filename_pattern": r"\.py$",       # run every script, not only plot_*.py
    "download_all_examples": False,
    "remove_config_comments": True,
    "within_subsection_order": "FileNameSortKey",
    "write_computation_times": False,
    "show_signature": False,
}

html_theme = "alabaster"
html_title = f"filippov {release}"
html_theme_options = {"description": "Filippov systems with sliding: two engines and a "
                                     "reproducible paper pipeline",
                      "fixed_sidebar": True,
                      # wide enough for the examples' tables (docs/_static/custom.css)
                      "page_width": "1240px", "body_max_width": "none"}
html_static_path = ["_static"]
# a code or output block wider than the body scrolls instead of being cut (custom.css)
html_css_files = ["custom.css"]
html_last_updated_fmt = None
# the site's own icon: without one every browser asks the server for /favicon.ico (a 404
# in the console of tests/test_docs_browser.py)
html_favicon = "_static/favicon.svg"

# Math is typeset by MathJax served from the site itself, not from a CDN: offline every
# formula would show its raw TeX. MathJax 3.2.2 comes from the package
# django-static-mathjax (pinned in requirements.lock; its files only, Django is not
# needed); its es5 build (the one combined script tex-chtml.js, the CommonHTML fonts and
# the components it loads on demand) is copied into _static/mathjax after the build.
_spec = importlib.util.find_spec("mathjax")
MATHJAX = Path(_spec.submodule_search_locations[0]) / "static" / "mathjax" if _spec else None
if MATHJAX is None or not (MATHJAX / "es5" / "tex-chtml.js").is_file():
    raise ImportError("the docs serve MathJax from the package django-static-mathjax "
                      "(pinned in requirements.lock): pip install -r requirements.lock")
del _spec
mathjax_path = "mathjax/tex-chtml.js"      # relative to _static
# the other combined scripts and the SVG output are not used by the site
_MATHJAX_SKIP = shutil.ignore_patterns("tex-mml-*", "tex-svg*", "mml-*", "tex-chtml-*",
                                       "node-main.js", "svg")


def _copy_mathjax(app, exc):
    if exc is None and app.builder.format == "html":
        out = Path(app.outdir) / "_static" / "mathjax"
        shutil.copytree(MATHJAX / "es5", out, ignore=_MATHJAX_SKIP, dirs_exist_ok=True)
        shutil.copy2(MATHJAX / "LICENSE", out / "LICENSE")   # Apache-2.0: ships with it


def setup(app):
    app.connect("build-finished", _copy_mathjax)
