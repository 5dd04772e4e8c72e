# Build/bootstrap for the filippov project.
#
#   make figures   build every figure (and the report) with Snakemake
#   make test      run the test suite
#   make test-deep the property-based tests (tests/test_properties.py) with the
#                  hypothesis profile "deep": many more generated systems, randomized
#   make verify    two clean builds in a temporary directory: byte-identical,
#                  and in agreement with tests/reference/manifest.json
#                  (VERIFY_ARGS="--first-build DIR" keeps the first: CI's test suite
#                  reads it, FILIPPOV_TEST_BUILD=DIR, and so does cross-cpu --native)
#   make manifest  rewrite the manifest from results/ and figures/ (prints changes)
#   make cross-cpu emulate another CPU's last bits (libm, numpy SIMD, numba) and check
#                  every scene against the manifest: results moved by up to 2 ulps
#                  (CROSS_CPU_ARGS="--ulps N"), three seeds and one build where every
#                  result moves; CROSS_CPU_ARGS="--record" stores the measured spread
#                  next to each tolerance, "--scenes ID ..." checks only some datasets
#   make report    the reproduction report paper/main.pdf (needs TeX)
#   make report-html  snakemake's HTML report (report.html): figures captioned with the
#                  paper's number, description and parameters; every dataset, the
#                  work-precision figure, scene files
#   make archive   one tarball of code, results, figures and report, with its sha256
#                  (CITATION.cff and .zenodo.json in it: ready to deposit for a DOI)
#   make archive-files  the file list of that tarball
#   make docs      the documentation site (docs/: getting started, tutorial, examples,
#                  pipeline guide, API reference) into docs/_build/html; warnings are errors
#   make help      this list
#   make lock      re-resolve requirements.lock in a throw-away venv
#   make clean     remove workflow outputs (keeps .venv)
#   make bench        work-precision sweep, cost of each model ingredient, scaling
#                     of a batch of returns with its threads
#                     (results/bench_*.nc, figures/bench_work_precision.pdf)
#   make bench-fig04  time the fig04 return maps against scipy solve_ivp
#
# The first target that needs Python creates $(VENV) from requirements.lock.

SHELL := /bin/bash
.SHELLFLAGS := -eu -o pipefail -c
.DELETE_ON_ERROR:

PYTHON ?= python3
VENV ?= .venv
PY = $(VENV)/bin/python
SNAKEFLAGS ?=
PYTEST_ARGS ?=
# Set to 1 to treat "no tests collected" (pytest exit 5) as success.
ALLOW_NO_TESTS ?=

# Top-level packages resolved by `make lock` (everything else is transitive).
LOCK_PKGS = numpy scipy xarray netCDF4 matplotlib "snakemake>=8,<10" \
            pyyaml jsonschema numba threadpoolctl sympy pytest pytest-xdist hypothesis pygments snakemake-executor-plugin-slurm \
            compliance-checker sphinx myst-parser sphinx-gallery django-static-mathjax selenium

export MPLBACKEND = Agg
export SOURCE_DATE_EPOCH = 0
export PIP_DISABLE_PIP_VERSION_CHECK = 1
export DEBIAN_FRONTEND = noninteractive

# Recipes that run tools from the venv also see it first on PATH, so that
# `python` inside Snakemake shell rules is the venv's interpreter.
VENV_PATH = PATH="$(abspath $(VENV))/bin:$$PATH" VIRTUAL_ENV="$(abspath $(VENV))"

.PHONY: all help archive archive-files venv figures test test-deep docs verify cross-cpu manifest report report-html bench bench-fig04 lock clean distclean check-python

all: figures

# The target list: the comment block at the top of this file.
help:
	@sed -n '/^#   make /,/^# *$$/p' $(firstword $(MAKEFILE_LIST)) | sed 's/^# \{0,3\}//' | sed '/^$$/d'

# One tarball of what a reader needs: the code, the results, the figures and the
# report, with its sha256 beside it (a tracked file list: no venv, no caches, no logs).
# The licence and the citation metadata are listed by name as well (a deposit reads
# CITATION.cff or .zenodo.json), so that they are in it even before they are committed.
ARCHIVE ?= filippov-$(shell git describe --always --dirty 2>/dev/null || echo snapshot).tar.gz
ARCHIVE_META = LICENSE README.md CITATION.cff .zenodo.json
ARCHIVE_FILES = { git ls-files; ls $(ARCHIVE_META); \
                  ls results/*.nc figures/*.pdf figures/*.png paper/main.pdf 2>/dev/null || true; } | sort -u
archive-files:
	@$(ARCHIVE_FILES)

archive: figures
	@test -d results && test -n "$$(ls figures/*.pdf 2>/dev/null)" || { echo "error: no build to archive" >&2; exit 1; }
	tmp=$$(mktemp); trap 'rm -f "$$tmp"' EXIT; \
	$(ARCHIVE_FILES) > "$$tmp"; \
	tar --sort=name --mtime='@0' --owner=0 --group=0 --numeric-owner -czf $(ARCHIVE).tmp -T "$$tmp"; \
	mv $(ARCHIVE).tmp $(ARCHIVE); sha256sum $(ARCHIVE) > $(ARCHIVE).sha256; \
	echo "wrote $(ARCHIVE) ($$(wc -l < "$$tmp") files) and $(ARCHIVE).sha256"

check-python:
	@$(PYTHON) -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || \
	  { echo "error: $(PYTHON) must be Python >= 3.11 (found: $$($(PYTHON) --version 2>&1))" >&2; exit 1; }

# Create the venv with `python3 -m venv`. On Debian without ensurepip that
# fails (or leaves a venv without pip): then install python3-venv and retry.
define make_venv
if ! "$(1)/bin/python" -m pip --version >/dev/null 2>&1; then \
  rm -rf "$(1)"; \
  if ! $(PYTHON) -m venv "$(1)"; then \
    echo "python3 -m venv failed; installing python3-venv with apt-get" >&2; \
    rm -rf "$(1)"; \
    SUDO=; [ "$$(id -u)" = 0 ] || SUDO=sudo; \
    $$SUDO apt-get update -q && $$SUDO apt-get install -y -q python3-venv </dev/null; \
    $(PYTHON) -m venv "$(1)"; \
  fi; \
fi
endef

$(VENV)/.done: requirements.lock pyproject.toml workflow/pyproject.toml | check-python
	@echo "== setting up $(VENV) from requirements.lock"
	@$(call make_venv,$(VENV))
	$(PY) -m pip install -r requirements.lock
	# the library (src/filippov) and the paper's pipeline (workflow/filippov_paper): two
	# distributions, both editable
	$(PY) -m pip install --no-deps -e . -e workflow
	touch $@

venv: $(VENV)/.done

figures: $(VENV)/.done
	$(VENV_PATH) $(VENV)/bin/snakemake --cores all $(SNAKEFLAGS)

# pytest-xdist: one worker per core (PYTEST_WORKERS=0: all in one process); a test
# file stays on one worker (--dist loadfile), so its module fixtures are computed once
PYTEST_WORKERS ?= auto
test: $(VENV)/.done
	@rc=0; $(VENV_PATH) $(PY) -m pytest -n $(PYTEST_WORKERS) --dist loadfile $(PYTEST_ARGS) || rc=$$?; \
	if [ $$rc -eq 5 ] && [ -n "$(ALLOW_NO_TESTS)" ]; then \
	  echo "warning: pytest collected no tests (exit 5); accepted because ALLOW_NO_TESTS is set" >&2; rc=0; \
	fi; \
	exit $$rc

# the property suite with many more examples (HYPOTHESIS_PROFILE: tests/conftest.py)
test-deep: $(VENV)/.done
	HYPOTHESIS_PROFILE=deep $(VENV_PATH) $(PY) -m pytest tests/test_properties.py $(PYTEST_ARGS)

# The documentation site: the pages in docs/, the API reference from the docstrings, the
# scripts in examples/ run by sphinx-gallery (a few seconds each). -W --keep-going: every
# warning is reported, and any fails the build.
docs: $(VENV)/.done
	# autosummary's pages are regenerated each build: stale ones of moved modules would fail -W
	rm -rf docs/generated
	$(VENV_PATH) $(PY) -m sphinx -W --keep-going -q -b html -d docs/_build/doctrees docs docs/_build/html
	@echo "wrote docs/_build/html/index.html"

VERIFY_ARGS ?=
verify: $(VENV)/.done
	$(VENV_PATH) $(PY) workflow/scripts/verify.py $(VERIFY_ARGS)

CROSS_CPU_ARGS ?=
cross-cpu: $(VENV)/.done
	$(VENV_PATH) $(PY) tests/crosscpu/cross_cpu.py $(CROSS_CPU_ARGS)

manifest: figures
	$(VENV_PATH) $(PY) -m filippov_paper.manifest update

TEX_INSTALL = apt-get install -y --no-install-recommends texlive-publishers texlive-latex-extra texlive-latex-recommended texlive-fonts-recommended latexmk
report: $(VENV)/.done
	@command -v latexmk >/dev/null && command -v pdflatex >/dev/null && kpsewhich elsarticle.cls >/dev/null || \
	  { echo "error: the report needs TeX (latexmk, pdflatex, elsarticle.cls); install it with: sudo $(TEX_INSTALL)" >&2; exit 1; }
	$(VENV_PATH) $(VENV)/bin/snakemake --cores all $(SNAKEFLAGS) paper/main.pdf

report-html: $(VENV)/.done
	$(VENV_PATH) $(VENV)/bin/snakemake --cores all $(SNAKEFLAGS)
	$(VENV_PATH) $(VENV)/bin/snakemake --cores 1 --report report.html --report-stylesheet workflow/report/report.css

# Work-precision of every method on the fig04 maps, and what each ingredient costs.
bench: $(VENV)/.done
	$(VENV_PATH) $(VENV)/bin/snakemake --cores 1 bench $(SNAKEFLAGS)

# Speed and accuracy of the fig04 return maps against scipy (prints a table;
# BENCH_ARGS="--every 10" for a quick run).
BENCH_ARGS ?=
bench-fig04: $(VENV)/.done
	$(VENV_PATH) $(PY) -m filippov_paper.benchmarks.fig04_speed $(BENCH_ARGS)

lock: | check-python
	tmp=$$(mktemp -d); trap 'rm -rf "$$tmp"' EXIT; \
	$(call make_venv,$$tmp/venv); \
	"$$tmp/venv/bin/python" -m pip install $(LOCK_PKGS); \
	MPLBACKEND=Agg "$$tmp/venv/bin/python" -c 'import numba, snakemake, netCDF4, xarray, matplotlib, scipy'; \
	"$$tmp/venv/bin/snakemake" --version >/dev/null; \
	{ \
	  echo "# requirements.lock: exact pins (with every transitive dependency) for filippov."; \
	  echo "# Generated file, do not edit by hand. Regenerate with:  make lock"; \
	  echo "# (a throw-away 'python3 -m venv', 'pip install' of the Makefile's LOCK_PKGS:"; \
	  echo "#  $(subst ",,$(LOCK_PKGS))"; \
	  echo "#  then 'pip freeze'.) Installed by 'make' into $(VENV) with 'pip install -r'."; \
	  echo "# Resolved with $$("$$tmp/venv/bin/python" -c 'import platform as p; print("Python", p.python_version(), "on", p.system(), p.machine())')."; \
	  "$$tmp/venv/bin/python" -m pip freeze --exclude-editable --exclude filippov --exclude filippov-paper; \
	} > requirements.lock.tmp; \
	mv requirements.lock.tmp requirements.lock; \
	echo "wrote requirements.lock ($$(grep -c '==' requirements.lock) pins)"

clean:
	rm -rf results/ .snakemake/ logs/ paper/generated paper/.build.* report.html
	rm -f figures/*.pdf figures/*.png
	rm -f paper/main.pdf paper/main.log paper/main.fls paper/main.aux paper/main.build.log
	rm -rf docs/_build docs/generated docs/auto_examples

distclean: clean
	rm -rf $(VENV)
