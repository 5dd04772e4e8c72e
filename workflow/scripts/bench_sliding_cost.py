"""Thin: time one stiff sliding return per eps, write results/bench_sliding_cost.nc."""
import filippov.benchmarks.sliding_cost as sc

sc.main(["--out", snakemake.output[0]])  # noqa: F821
