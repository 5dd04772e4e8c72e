# Compute one scene's dataset. The schema and the script are inputs and the library's
# hash is a param (it covers the scene's own schema block, PARAMETERS_SCHEMA in its
# module), so editing any of them reruns the scene. A failed
# job leaves no results/<id>.nc: the library writes atomically and Snakemake
# removes outputs of failed jobs.
# The scene helpers (RESOLUTION, scene_resolution, scene_chunks) are in common.smk.
import re

CHUNKS = scene_chunks()
CHUNKED_SCENES = "|".join(re.escape(s) for s in CHUNKS) or "(?!)"  # (?!): matches nothing


rule compute:
    input:
        scene="config/scenes/{scene}.yaml",
        schema=config["schema"],
        script="workflow/scripts/compute_scene.py",
        labels="paper/paper_labels.tex",  # the paper's numbers in titles (scenes.printed)
    output:
        report("results/{scene}.nc", caption="../report/dataset.rst", category="Datasets",
               labels=dataset_labels),
    params:
        code=library_hash(exclude=NOT_COMPUTE, strip_reports=True),  # see common.smk
        resolution=lambda wc: scene_resolution(wc.scene),  # --config resolution=full
        caption=dataset_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    log:
        "logs/compute/{scene}.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/compute_scene.py"


# A scene with `chunks: N` is computed as N jobs, each on a contiguous part of
# the scene's grid (filippov_paper.scenes.chunking), and merged into results/<id>.nc
# by one job that also computes what depends on the whole grid (fixed points,
# errors, rates). The merged file is byte-identical to the one rule `compute`
# writes. The chunk files are temporary: removed once the merge has succeeded.
rule compute_chunk:
    input:
        scene="config/scenes/{scene}.yaml",
        schema=config["schema"],
        script="workflow/scripts/compute_chunk.py",
    output:
        temp("results/chunks/{scene}/{chunk}.nc"),
    wildcard_constraints:
        scene=CHUNKED_SCENES,
        chunk="[0-9]+",
    params:
        code=library_hash(exclude=NOT_COMPUTE, strip_reports=True),  # see common.smk
        resolution=lambda wc: scene_resolution(wc.scene),  # --config resolution=full
        chunks=lambda wc: CHUNKS[wc.scene],  # the scene's `chunks`, capped by sweep_jobs
    log:
        "logs/compute_chunk/{scene}/{chunk}.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/compute_chunk.py"


rule merge_chunks:
    input:
        scene="config/scenes/{scene}.yaml",
        schema=config["schema"],
        script="workflow/scripts/merge_chunks.py",
        labels="paper/paper_labels.tex",  # the paper's numbers in titles (scenes.printed)
        chunks=lambda wc: [f"results/chunks/{wc.scene}/{i}.nc" for i in range(CHUNKS[wc.scene])],
    output:
        report("results/{scene}.nc", caption="../report/dataset.rst", category="Datasets",
               labels=dataset_labels),
    wildcard_constraints:
        scene=CHUNKED_SCENES,
    params:
        code=library_hash(exclude=NOT_COMPUTE, strip_reports=True),  # see common.smk
        resolution=lambda wc: scene_resolution(wc.scene),  # --config resolution=full
        caption=dataset_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    log:
        "logs/merge_chunks/{scene}.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/merge_chunks.py"


# results/<id>.nc of a chunked scene comes from the merge (rule compute does
# not apply to it); the merge is cheap, so on a cluster it runs on the
# submitting host instead of waiting in the queue.
ruleorder: merge_chunks > compute
localrules: merge_chunks


# The scene file next to its dataset and figure in the HTML report (a copy:
# Snakemake's report attaches outputs only).
rule publish_scene:
    input:
        "config/scenes/{scene}.yaml",
    output:
        report("results/scenes/{scene}.yaml", caption="../report/scene.rst",
               category="Scene files", labels={"scene": "{scene}", "format": "YAML"}),
    params:
        caption=scene_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    localrule: True
    log:
        "logs/publish_scene/{scene}.log",
    conda:
        "../envs/filippov.yaml"
    shell:
        "cp {input:q} {output:q} 2>&1 | tee {log:q}"
