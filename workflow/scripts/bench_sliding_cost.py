"""Thin: time one stiff sliding return per eps, write results/bench_sliding_cost.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.sliding_cost as sc  # noqa: E402

sc.main(["--out", snakemake.output[0]])  # noqa: F821
