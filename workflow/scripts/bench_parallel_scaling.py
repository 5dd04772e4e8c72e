"""Thin: time batches of returns with 1..N workers, write results/bench_parallel_scaling.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.parallel_scaling as ps  # noqa: E402

ps.main(["--out", snakemake.output[0]])  # noqa: F821
