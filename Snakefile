# Workflow entry point: scene (config/scenes/<id>.yaml) -> results/<id>.nc
# -> figures/<id>.{pdf,png}. The workflow knows files only; numerics live in the
# library (src/filippov), the paper's scenes, figures and report in the pipeline package
# (workflow/filippov_paper), both reached through the thin scripts in workflow/scripts.

import sys

from filippov_paper.config import SceneError, load_workflow_config

# config/config.yaml, validated against its schema (one line naming the file and
# line/column or field when it is malformed); --config values on the command
# line take precedence. Loaded here rather than with `configfile:` so that the
# error is ours, not a traceback.
try:
    config.update(load_workflow_config("config/config.yaml", "config/schema/config.schema.json",
                                       overrides=config))
except SceneError as exc:
    print(f"error: {exc}", file=sys.stderr)
    sys.exit(1)

# Scene ids look like fig02_cases; constraining the wildcard keeps stray
# targets (e.g. results/foo.nc) from matching the rules.
wildcard_constraints:
    scene="fig[0-9]{2}_[a-z0-9_]+",


include: "workflow/rules/common.smk"
include: "workflow/rules/report_html.smk"  # the HTML report's captions and rule graph
include: "workflow/rules/compute.smk"
include: "workflow/rules/hard_cases.smk"
include: "workflow/rules/plot.smk"
include: "workflow/rules/report.smk"

# The reproduction report paper/main.pdf is part of `all` only when TeX is
# installed (and paper/ is present); otherwise say how to get it.
REPORT_PDF = []
if Path("paper/main.tex").exists():
    if tex_available():
        REPORT_PDF = ["paper/main.pdf"]
    else:
        print("note: TeX not found, so paper/main.pdf (the reproduction report) is skipped.\n"
              f"      Install it with:  sudo apt-get install -y --no-install-recommends {TEX_PACKAGES}",
              file=sys.stderr)
include: "workflow/rules/bench.smk"


rule all:
    default_target: True
    input:
        expand("figures/{scene}.{ext}", scene=config["scenes"], ext=["pdf", "png"]),
        expand("results/scenes/{scene}.yaml", scene=config["scenes"]),  # for the HTML report
        "results/hard_cases.nc",  # the eps sweep of the hard cases (seconds)
        "figures/work_precision.pdf",  # what accuracy costs: errors and times (seconds)
        REPORT_PDF,
