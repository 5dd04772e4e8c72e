"""Thin: time every scene with each ingredient switched, write results/bench_effect_cost.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.effect_cost as ec  # noqa: E402

ec.main(["--out", snakemake.output[0]])  # noqa: F821
