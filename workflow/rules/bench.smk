# Benchmarks: not part of `all` (they time things and take minutes). Run with
# `snakemake bench` or `make bench`. Timings vary between runs; the dataset
# records the machine-independent part (errors) next to the wall times.
rule bench_work_precision:
    output:
        "results/bench_work_precision.nc",
    params:
        code=library_hash(exclude=("plotting", "report.py", "manifest.py")),
        every=config.get("bench", {}).get("every", 10),
    script:
        "../scripts/bench_work_precision.py"


rule plot_bench:
    input:
        data="results/bench_work_precision.nc",
        script="workflow/scripts/plot_scene.py",
    output:
        pdf="figures/bench_work_precision.pdf",
        png="figures/bench_work_precision.png",
    params:
        code=library_hash("plotting"),
    script:
        "../scripts/plot_scene.py"


rule bench_effect_cost:
    output:
        "results/bench_effect_cost.nc",
    params:
        code=library_hash(exclude="plotting"),
    script:
        "../scripts/bench_effect_cost.py"


rule bench:
    input:
        rules.plot_bench.output,
        rules.bench_effect_cost.output,
