"""Thin: results/*.nc -> filippov_paper.report.generate -> paper/generated/*.tex."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import sys  # noqa: E402
from pathlib import Path  # noqa: E402

import filippov.io  # noqa: E402
import filippov_paper.report  # noqa: E402

datasets = {}
# the scenes' datasets, the hard-case sweep and the benchmarks' datasets of the default
# build (inputs), and those of `make bench` when it made them; each checked against its
# checksum
try:
    for path in [*snakemake.input.data, snakemake.input.hard_cases,  # noqa: F821
                 *snakemake.input.benchmarks,  # noqa: F821
                 *[p for p in snakemake.params.bench if p.endswith(".nc")]]:  # noqa: F821
        datasets[Path(path).stem] = filippov.io.read_dataset(path)
except filippov.io.DatasetError as exc:
    sys.exit(f"error: {exc}")
texts = filippov_paper.report.generate(datasets)
for out in snakemake.output:  # noqa: F821
    out = Path(out)
    tmp = out.with_suffix(".tmp")
    tmp.write_text(texts[out.name])
    tmp.replace(out)  # atomic: no half-written table
