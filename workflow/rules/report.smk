# The reproduction report: results/*.nc -> paper/generated/*.tex (numbers and
# tables, never typed by hand) and figures/*.pdf + paper/*.tex -> paper/main.pdf.
# Optional inputs: the dry-friction scenes (fig10_dfo, fig11_dfo_retmaps) are
# used when they are listed in config["scenes"]; the datasets of `make bench` that a
# benchmark's report part reads (results/bench_<name>.nc) when they exist. The other
# datasets of the benchmarks' report parts -- the work-precision sweep of the default
# build (results/work_precision.nc, rule work_precision; seconds) -- are inputs. The
# report says "not yet computed" for whatever is absent. Rule `all` asks for paper/main.pdf only when
# TeX is installed (see TEX_OK in the Snakefile). The hard-case eps sweep
# (results/hard_cases.nc, rule hard_cases) is an input: it takes seconds.
# The helpers (tex_available, report_data, report_figures, report_bench_datasets,
# report_bench_tables, hard_case_tables, bench_stamps) are in common.smk.
from filippov_paper.config import scene_files

report: "../report/workflow.rst"

# One generated table per scene (paper/generated/<id>.tex, written by that scene's
# module; a comment when it has none), for every scene file in config/scenes, so
# that a scene left out of config["scenes"] gets its "not yet computed" text
# instead of a stale table. Which scenes the report cannot do without is the
# scenes' own declaration (REPORT_OPTIONAL in filippov_paper.scenes.<id>).
SCENE_FILES = scene_files("config/scenes")
# The benchmarks' tables (tab_bench.tex) are those their report parts name (REPORT), the
# hard-case sweep's those of its REPORT.
REPORT_GENERATED = ["macros.tex", *[f"{s}.tex" for s in SCENE_FILES], *report_bench_tables(),
                    *hard_case_tables()]
TEX_PACKAGES = ("texlive-publishers texlive-latex-extra texlive-latex-recommended "
                "texlive-fonts-recommended latexmk")


rule report_tables:
    input:
        data=report_data,
        hard_cases="results/hard_cases.nc",  # the eps sweep (rule hard_cases; cheap)
        benchmarks=report_bench_datasets(optional=False),  # rule work_precision (seconds)
        script="workflow/scripts/report_tables.py",
    output:
        [f"paper/generated/{name}" for name in REPORT_GENERATED],
    params:
        code=library_hash(exclude="plotting"),  # filippov_paper.report, the scenes' report parts, ...
        bench=bench_stamps(),
    log:
        "logs/report_tables.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/report_tables.py"


# latexmk builds in a fresh directory under paper/; only a complete PDF is moved
# onto paper/main.pdf (same file system: atomic). latexmk's output is kept in
# logs/paper.log (and the TeX log, recorder and aux files in paper/main.{log,fls,aux})
# even on failure; tests/test_report.py reads the figures' pages from main.aux.
rule paper:
    input:
        tex=sorted(str(p) for p in Path("paper").glob("*.tex")),
        generated=[f"paper/generated/{name}" for name in REPORT_GENERATED],
        figures=report_figures,
        work_precision="figures/work_precision.pdf",
    params:
        bench=bench_stamps(),
    output:
        report("paper/main.pdf", category="Reproduction report",
               caption="../report/paper.rst"),
    log:
        "logs/paper.log",
    conda:
        "../envs/filippov.yaml"
    shell:
        r"""
        set -u
        build=$(mktemp -d paper/.build.XXXXXX)
        trap 'rm -rf "$build"' EXIT
        rc=0
        ( cd paper && SOURCE_DATE_EPOCH=0 FORCE_SOURCE_DATE=1 \
            latexmk -pdf -interaction=nonstopmode -halt-on-error -file-line-error \
                    -recorder -outdir="${{build#paper/}}" main.tex ) > {log:q} 2>&1 || rc=$?
        for ext in log fls aux; do
            if [ -f "$build/main.$ext" ]; then cp "$build/main.$ext" "paper/main.$ext"; fi
        done
        if [ "$rc" -ne 0 ]; then
            echo "latexmk failed (exit $rc); see {log} and paper/main.log" >&2
            grep -n -A3 '^!\|:[0-9]*: ' paper/main.log >&2 || true
            exit "$rc"
        fi
        mv "$build/main.pdf" {output:q}
        """
