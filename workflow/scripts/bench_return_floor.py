"""Thin: the cost per return of the iterated Hopf map and its floor, write results/bench_return_floor.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.return_floor as rf  # noqa: E402

rf.main(["--out", snakemake.output[0]])  # noqa: F821
