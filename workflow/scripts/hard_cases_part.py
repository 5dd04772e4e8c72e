"""Thin: config hard_cases + chunk index -> filippov.hard_cases.compute_part
-> results/chunks/hard_cases/<i>.nc (no numerics here)."""
import json
import sys

import filippov.io
from filippov import hard_cases

try:
    settings = hard_cases.check_config(json.loads(snakemake.params.settings))  # noqa: F821
except hard_cases.ConfigError as exc:
    sys.exit(f"error: config/config.yaml: {exc}")  # a config mistake: one clear line
ds = hard_cases.compute_part(settings, int(snakemake.wildcards.i), progress=True)  # noqa: F821
filippov.io.write_dataset(ds, snakemake.output[0])  # noqa: F821
