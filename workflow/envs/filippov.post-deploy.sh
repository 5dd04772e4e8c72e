#!/usr/bin/env bash
# Run by Snakemake once, in the new conda environment (filippov.yaml), from the
# directory Snakemake runs in (the project's root): the pinned packages and the
# library and the paper's pipeline (workflow/), as `make` installs them into .venv.
set -euo pipefail
python -m pip install -r requirements.lock
python -m pip install --no-deps -e . -e workflow
