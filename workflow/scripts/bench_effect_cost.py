"""Thin: time every scene with each ingredient switched, write results/bench_effect_cost.nc."""
import filippov.benchmarks.effect_cost as ec

ec.main(["--out", snakemake.output[0]])  # noqa: F821
