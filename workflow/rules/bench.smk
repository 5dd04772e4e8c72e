# The default build's work-precision sweep (part of `all`, about a minute): the
# fig04 and fig11 maps on subgrids, the project's modes against solve_ivp RK45 and
# DOP853 (preset "build" of filippov_paper.benchmarks.work_precision). Its wall times
# differ between any two runs (tolerance rule "measured"); its errors are
# reproducible.
rule work_precision:
    output:
        report("results/work_precision.nc", caption="../report/work_precision.rst",
               category="Datasets", labels=dataset_labels),
    params:
        code=library_hash(exclude=("plotting", "report.py", "report_html.py", "manifest.py"),
                          strip_reports=True),
        caption=dataset_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    log:
        "logs/work_precision.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_work_precision.py"


rule plot_work_precision:
    input:
        data="results/work_precision.nc",
        script="workflow/scripts/plot_scene.py",
    output:
        pdf=report("figures/work_precision.pdf", caption="../report/work_precision_figure.rst",
                   category="Figures", subcategory="work_precision",
                   labels={"figure": "work_precision", "format": "PDF (vector)"}),
        png=report("figures/work_precision.png", caption="../report/work_precision_figure.rst",
                   category="Figures", subcategory="work_precision",
                   labels={"figure": "work_precision", "format": "PNG"}),
    params:
        code=library_hash("plotting"),
        caption=figure_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    log:
        "logs/plot_work_precision.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/plot_scene.py"


# Benchmarks: not part of `all` (they time things and take minutes). Run with
# `snakemake bench` or `make bench`. Timings vary between runs; the dataset
# records the machine-independent part (errors) next to the wall times.
# One job per problem set (fig04: both theta; fig11: both panels), merged: on a
# cluster the sets run on different nodes.
BENCH_SETS = ["fig04", "fig11"]


rule bench_work_precision_part:
    output:
        temp("results/bench/work_precision_{problems}.nc"),
    wildcard_constraints:
        problems="|".join(BENCH_SETS),
    params:
        code=library_hash(exclude=("plotting", "report.py", "report_html.py", "manifest.py"),
                          strip_reports=True),
        every=config.get("bench", {}).get("every", 10),
    log:
        "logs/bench_work_precision_part/{problems}.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_work_precision.py"


rule bench_work_precision:
    input:
        parts=expand("results/bench/work_precision_{problems}.nc", problems=BENCH_SETS),
        script="workflow/scripts/bench_work_precision.py",
    output:
        "results/bench_work_precision.nc",
    log:
        "logs/bench_work_precision.log",
    conda:
        "../envs/filippov.yaml"
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
    log:
        "logs/plot_bench.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/plot_scene.py"


rule bench_effect_cost:
    output:
        "results/bench_effect_cost.nc",
    params:
        code=library_hash(exclude="plotting"),
    log:
        "logs/bench_effect_cost.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_effect_cost.py"


# The cost of one return of the iterated Hopf map (the instability scenes' kernel):
# median wall time per return, printed as a table.
rule bench_attractor_cost:
    output:
        "results/bench_attractor_cost.nc",
    params:
        code=library_hash(exclude="plotting"),
    log:
        "logs/bench_attractor_cost.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_attractor_cost.py"


# Where one return of the iterated Hopf map goes: CPU time per return, the model
# evaluations it makes (counted) and their cost alone (the floor), printed as a table.
rule bench_return_floor:
    output:
        "results/bench_return_floor.nc",
    params:
        code=library_hash(exclude="plotting"),
    log:
        "logs/bench_return_floor.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_return_floor.py"


# The cost of one stiff sliding return of the Hopf example per eps (reference
# driver, Radau IIA with 3 and 5 stages), printed as a table.
rule bench_sliding_cost:
    output:
        "results/bench_sliding_cost.nc",
    params:
        code=library_hash(exclude="plotting"),
    log:
        "logs/bench_sliding_cost.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_sliding_cost.py"


# What the compiled engine costs before its first return: the kernel's compile on empty
# caches and its load afterwards (fresh processes), printed as a table.
rule bench_compile_cost:
    output:
        "results/bench_compile_cost.nc",
    params:
        code=library_hash(exclude="plotting"),
    log:
        "logs/bench_compile_cost.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_compile_cost.py"


# Returns per second of a batch of iterated Hopf returns with 1, 2, ... workers up to the
# cores (compute_returns(workers=)), with CPU times and the load average, printed as a
# table. It takes every core (threads), so no other job runs beside it.
rule bench_parallel_scaling:
    output:
        "results/bench_parallel_scaling.nc",
    params:
        code=library_hash(exclude="plotting"),
    threads: workflow.cores
    log:
        "logs/bench_parallel_scaling.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/bench_parallel_scaling.py"


rule bench:
    input:
        rules.plot_bench.output,
        rules.bench_effect_cost.output,
        rules.bench_attractor_cost.output,
        rules.bench_return_floor.output,
        rules.bench_sliding_cost.output,
        rules.bench_compile_cost.output,
        rules.bench_parallel_scaling.output,
