"""Thin: the default build's work-precision sweep, one problem set of the full
benchmark (a chunk job), or the merge."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import filippov_paper.benchmarks.work_precision as wp  # noqa: E402

if snakemake.rule == "work_precision":  # noqa: F821
    wp.main(["--preset", "build", "--out", snakemake.output[0]])  # noqa: F821
elif snakemake.rule == "bench_work_precision":  # noqa: F821
    wp.main(["--merge", *snakemake.input.parts, "--out", snakemake.output[0]])  # noqa: F821
else:
    wp.main(["--problems", snakemake.wildcards.problems, "--every",  # noqa: F821
             str(snakemake.params.every), "--out", snakemake.output[0]])  # noqa: F821
