"""Thin: time the iterated Hopf return map, write results/bench_attractor_cost.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.attractor_cost as ac  # noqa: E402

ac.main(["--out", snakemake.output[0]])  # noqa: F821
