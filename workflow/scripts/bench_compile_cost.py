"""Thin: time the compiled engine's compile and load, write results/bench_compile_cost.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.compile_cost as cc  # noqa: E402

cc.main(["--repeat", "1", "--out", snakemake.output[0]])  # noqa: F821
