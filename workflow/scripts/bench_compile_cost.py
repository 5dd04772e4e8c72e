"""Thin: time the compiled engine's compile and load, write results/bench_compile_cost.nc."""
import filippov.benchmarks.compile_cost as cc

cc.main(["--repeat", "1", "--out", snakemake.output[0]])  # noqa: F821
