"""Thin: config hard_cases + chunk index -> filippov_paper.hard_cases.compute_part
-> results/chunks/hard_cases/<i>.nc (no numerics here)."""

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
    sys.exit(f"error: config/config.yaml: {exc}")  # a config mistake: one clear line
ds = hard_cases.compute_part(settings, int(snakemake.wildcards.i), progress=True)  # noqa: F821
filippov.io.write_dataset(ds, snakemake.output[0])  # noqa: F821
