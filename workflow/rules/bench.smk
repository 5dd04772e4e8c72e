# The default build's work-precision sweep (part of `all`, about a minute): the
# fig04 and fig11 maps on subgrids, the project's modes against solve_ivp RK45 and
# DOP853 (preset "build" of filippov_paper.benchmarks.work_precision). Its wall times
# differ between any two runs (tolerance rule "measured"); its errors are
# reproducible.
rule work_precision:
    # the longest job of a build: started first, it runs its Python and solve_ivp part
    # while another job compiles the kernel (filippov_paper.benchmarks.work_precision.run)
    priority: 10
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


# The other benchmarks of `make bench`, one rule each, generated from the benchmark modules
# that declare WORKFLOW (filippov_paper.product.workflow_benchmarks, read from their source):
# rule bench_<name> runs the module's main(WORKFLOW["args"] + --out) through the one script
# workflow/scripts/bench.py and writes results/bench_<name>.nc; "threads": "all" takes every
# core (parallel_scaling: no other job beside it). A new benchmark is its module.
# What each measures is its module's docstring (and the table it prints).
BENCHMARKS = workflow_benchmarks()

for _name, _spec in BENCHMARKS.items():

    rule:
        name:
            f"bench_{_name}"
        output:
            f"results/bench_{_name}.nc",
        params:
            code=library_hash(exclude="plotting"),
            benchmark=_name,
            args=_spec["args"],
        threads: workflow.cores if _spec["threads"] == "all" else 1
        log:
            f"logs/bench_{_name}.log",
        conda:
            "../envs/filippov.yaml"
        script:
            "../scripts/bench.py"


# The figures of `make bench`, one rule each, generated from the figure modules
# filippov_paper.plotting.bench_<name> (filippov_paper.product.benchmark_figures): rule
# plot_bench_<name> draws results/bench_<name>.nc into figures/bench_<name>.{pdf,png}. A new
# benchmark with a figure is its module and its figure module.
BENCH_FIGURES = benchmark_figures()

for _name in BENCH_FIGURES:

    rule:
        name:
            f"plot_bench_{_name}"
        input:
            data=f"results/bench_{_name}.nc",
            script="workflow/scripts/plot_scene.py",
        output:
            pdf=f"figures/bench_{_name}.pdf",
            png=f"figures/bench_{_name}.png",
        params:
            code=library_hash("plotting"),
        log:
            f"logs/plot_bench_{_name}.log",
        conda:
            "../envs/filippov.yaml"
        script:
            "../scripts/plot_scene.py"


rule bench:
    input:
        expand("figures/bench_{name}.{ext}", name=BENCH_FIGURES, ext=["pdf", "png"]),
        expand("results/bench_{name}.nc", name=BENCHMARKS),
