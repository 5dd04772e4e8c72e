# Workflow entry point: scene (config/scenes/<id>.yaml) -> results/<id>.nc
# -> figures/<id>.{pdf,png}. The workflow knows files only; numerics live in
# src/filippov and are reached through the thin scripts in workflow/scripts.

configfile: "config/config.yaml"

# Scene ids look like fig02_cases; constraining the wildcard keeps stray
# targets (e.g. results/foo.nc) from matching the rules.
wildcard_constraints:
    scene="fig[0-9]{2}_[a-z0-9_]+",


include: "workflow/rules/common.smk"
include: "workflow/rules/compute.smk"
include: "workflow/rules/plot.smk"


rule all:
    input:
        expand("figures/{scene}.{ext}", scene=config["scenes"], ext=["pdf", "png"]),
