"""Thin: one benchmark of `make bench` (rule bench_<name>, generated in bench.smk from the
benchmark modules that declare WORKFLOW): its main(args + --out results/bench_<name>.nc)."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import importlib  # noqa: E402

from filippov_paper import product  # noqa: E402

module = importlib.import_module(f"filippov_paper.benchmarks.{snakemake.params.benchmark}")  # noqa: F821
product.hook(module, "main")([*snakemake.params.args, "--out", snakemake.output[0]])  # noqa: F821
