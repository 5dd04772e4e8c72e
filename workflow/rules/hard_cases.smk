# The hard-case sweep over eps (filippov_paper.hard_cases): config["hard_cases"] lists
# the eps values and how many jobs share them (`chunks`). Each job measures a
# contiguous part of the list (results/chunks/hard_cases/<i>.nc, temporary); one
# local job merges them into results/hard_cases.nc, byte-identical to a sweep in
# one process. The settings and the library's hash are params, so editing
# either reruns the sweep (see common.smk); scenes do not import hard_cases.py,
# so editing it reruns the sweep only.
# (hard_cases_chunks: common.smk) The jobs run is hard_cases.chunks capped by
# config["sweep_jobs"] (one on a local build; config/config.yaml): a param of both rules,
# since the sweep's block itself is checked as written.
import json

HARD_CASES_SETTINGS = json.dumps(config.get("hard_cases"), sort_keys=True)
# the compute code (as for the scenes) and workflow/filippov_paper/hard_cases.py itself
HARD_CASES_CODE = library_hash(exclude=[e for e in NOT_COMPUTE if e != "hard_cases.py"],
                               strip_reports=True)


rule hard_cases_part:
    input:
        script="workflow/scripts/hard_cases_part.py",
    output:
        temp("results/chunks/hard_cases/{i}.nc"),
    wildcard_constraints:
        i="[0-9]+",
    params:
        settings=HARD_CASES_SETTINGS,
        jobs=hard_cases_chunks(),
        code=HARD_CASES_CODE,  # see common.smk
    log:
        "logs/hard_cases_part/{i}.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/hard_cases_part.py"


rule hard_cases:
    input:
        script="workflow/scripts/hard_cases_merge.py",
        parts=[f"results/chunks/hard_cases/{i}.nc" for i in range(hard_cases_chunks())],
    output:
        report("results/hard_cases.nc", caption="../report/hard_cases.rst", category="Datasets",
               labels=dataset_labels),
    params:
        settings=HARD_CASES_SETTINGS,
        jobs=hard_cases_chunks(),
        code=HARD_CASES_CODE,  # see common.smk
        caption=dataset_caption,  # the HTML report's (report_html.smk; no rerun trigger)
    log:
        "logs/hard_cases.log",
    conda:
        "../envs/filippov.yaml"
    script:
        "../scripts/hard_cases_merge.py"


# the merge is cheap: on a cluster it runs on the submitting host
localrules: hard_cases
