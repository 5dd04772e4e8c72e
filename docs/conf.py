"""Sphinx configuration of the filippov documentation (built by `make docs`).

The site is built from this tree's sources: the pages in this folder (MyST Markdown),
the API reference from the docstrings (autodoc, autosummary, napoleon for the NumPy
style sections), and the scripts in ../examples run and rendered by sphinx-gallery.
"""
import os
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
# the solver's numbers beside closed forms, which the gallery shows under the code
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
                      "fixed_sidebar": True}
html_static_path = []
html_last_updated_fmt = None
