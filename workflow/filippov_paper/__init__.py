"""filippov_paper: the pipeline that reproduces Sieber & Kowalczyk (Physica D 2010).

Scenes (one module per figure: scene file in, dataset out), figures, the reproduction
report, the manifest and its tolerances, the paper's printed labels, the hard-case
sweep and the benchmarks. It imports the library (``filippov``) and the library never
imports it: ``pip install .`` at the top of the repository gives the library alone;
this package is its own distribution (``workflow/pyproject.toml``), installed beside the
library by ``make``.
"""
