"""Thin: run the work-precision benchmark, write results/bench_work_precision.nc."""
import filippov.benchmarks.work_precision as wp

wp.main(["--every", str(snakemake.params.every), "--out", snakemake.output[0]])  # noqa: F821
