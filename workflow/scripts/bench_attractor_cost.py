"""Thin: time the iterated Hopf return map, write results/bench_attractor_cost.nc."""
import filippov.benchmarks.attractor_cost as ac

ac.main(["--out", snakemake.output[0]])  # noqa: F821
