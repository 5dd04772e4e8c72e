"""Thin: results/chunks/hard_cases/*.nc -> filippov.hard_cases.merge
-> results/hard_cases.nc (no numerics here)."""
import json
import sys

import filippov.io
from filippov import hard_cases

try:
    settings = hard_cases.check_config(json.loads(snakemake.params.settings))  # noqa: F821
except hard_cases.ConfigError as exc:
    sys.exit(f"error: config/config.yaml: {exc}")
try:
    parts = [filippov.io.read_dataset(path) for path in snakemake.input.parts]  # noqa: F821
except filippov.io.DatasetError as exc:
    sys.exit(f"error: {exc}")
filippov.io.write_dataset(hard_cases.merge(parts, settings), snakemake.output[0])  # noqa: F821
