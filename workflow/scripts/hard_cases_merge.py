"""Thin: results/chunks/hard_cases/*.nc -> filippov_paper.hard_cases.merge
-> results/hard_cases.nc (no numerics here)."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import json  # noqa: E402
import sys  # noqa: E402

import filippov.io  # noqa: E402
from filippov_paper import hard_cases  # noqa: E402

try:
    settings = hard_cases.check_config(json.loads(snakemake.params.settings))  # noqa: F821
    # the jobs this run splits it into: its `chunks`, capped by config["sweep_jobs"]
    settings["chunks"] = int(snakemake.params.jobs)  # noqa: F821
except hard_cases.ConfigError as exc:
    sys.exit(f"error: config/config.yaml: {exc}")
try:
    parts = [filippov.io.read_dataset(path) for path in snakemake.input.parts]  # noqa: F821
except filippov.io.DatasetError as exc:
    sys.exit(f"error: {exc}")
filippov.io.write_dataset(hard_cases.merge(parts, settings), snakemake.output[0])  # noqa: F821
