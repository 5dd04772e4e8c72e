# The hard-case sweep over eps (filippov.hard_cases): config["hard_cases"] lists
# the eps values and how many jobs share them (`chunks`). Each job measures a
# contiguous part of the list (results/chunks/hard_cases/<i>.nc, temporary); one
# local job merges them into results/hard_cases.nc, byte-identical to a sweep in
# one process. The settings and the library's hash are params, so editing
# either reruns the sweep (see common.smk); scenes do not import hard_cases.py,
# so editing it reruns the sweep only.
import json


def hard_cases_chunks():
    """`chunks` of config["hard_cases"], read when the DAG is built. A malformed
    block is left to the jobs, which report it naming the field (as rule
    `compute` does for scenes), so one job is planned for it."""
    block = config.get("hard_cases")
    n = block.get("chunks", 1) if isinstance(block, dict) else 1
    return n if isinstance(n, int) and not isinstance(n, bool) and n >= 1 else 1


HARD_CASES_SETTINGS = json.dumps(config.get("hard_cases"), sort_keys=True)
# the compute code (as for the scenes) and filippov/hard_cases.py itself
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
        code=HARD_CASES_CODE,  # see common.smk
    script:
        "../scripts/hard_cases_part.py"


rule hard_cases:
    input:
        script="workflow/scripts/hard_cases_merge.py",
        parts=[f"results/chunks/hard_cases/{i}.nc" for i in range(hard_cases_chunks())],
    output:
        "results/hard_cases.nc",
    params:
        settings=HARD_CASES_SETTINGS,
        code=HARD_CASES_CODE,  # see common.smk
    script:
        "../scripts/hard_cases_merge.py"


# the merge is cheap: on a cluster it runs on the submitting host
localrules: hard_cases
