# Compute one scene's dataset. The schema and the script are inputs and the library's
# hash is a param (it covers the scene's own schema block, PARAMETERS_SCHEMA in its
# module), so editing any of them reruns the scene. A failed
# job leaves no results/<id>.nc: the library writes atomically and Snakemake
# removes outputs of failed jobs.
import functools
import re

import yaml

from filippov.config import (DEFAULT_RESOLUTION, SceneError, apply_resolution, check_limits,
                             limits)

RESOLUTION = config.get("resolution", DEFAULT_RESOLUTION)


@functools.lru_cache(maxsize=None)
def scene_resolution(scene):
    """The resolution scene `scene` is built at: the run's, if the scene file has a
    block of that name under `resolutions`, else the default -- so that asking for
    another resolution reruns only the scenes that have one."""
    try:
        data = yaml.safe_load(Path(f"config/scenes/{scene}.yaml").read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return DEFAULT_RESOLUTION
    if not isinstance(data, dict):
        return DEFAULT_RESOLUTION
    return apply_resolution(data, RESOLUTION).get("resolution", DEFAULT_RESOLUTION)


def scene_chunks():
    """{id: N} for the scene files with a top-level `chunks: N` (N >= 1).

    Read when the DAG is built, so the chunk jobs are known statically (no
    checkpoint). Each scene is checked against the size limits first (cheap,
    from its parameters), so that no oversized plan is ever built: a scene over
    a limit stops the run here with one line. A malformed file or `chunks`
    value is left to rule `compute`, whose job reports it (schema validation
    names the field).
    """
    found = {}
    try:
        lim = limits(config)
    except SceneError as exc:
        fail(exc)
    for path in sorted(Path("config/scenes").glob("*.yaml")):
        try:
            data = yaml.safe_load(path.read_text(encoding="utf-8"))
        except (OSError, UnicodeDecodeError, yaml.YAMLError):
            continue
        try:
            if isinstance(data, dict) and isinstance(data.get("parameters", {}), dict):
                data = apply_resolution(data, RESOLUTION)
                check_limits(data, lim, path)
        except SceneError as exc:
            fail(exc)
        except (TypeError, ValueError, AttributeError):
            pass  # malformed: the schema check of the job names the field
        n = data.get("chunks") if isinstance(data, dict) else None
        if isinstance(n, int) and not isinstance(n, bool) and n >= 1:
            found[path.stem] = n
    return found


CHUNKS = scene_chunks()
CHUNKED_SCENES = "|".join(re.escape(s) for s in CHUNKS) or "(?!)"  # (?!): matches nothing


rule compute:
    input:
        scene="config/scenes/{scene}.yaml",
        schema=config["schema"],
        script="workflow/scripts/compute_scene.py",
    output:
        report("results/{scene}.nc", caption="../report/dataset.rst", category="Datasets",
               labels={"scene": "{scene}", "format": "netCDF"}),
    params:
        code=library_hash(exclude=NOT_COMPUTE, strip_reports=True),  # see common.smk
        resolution=lambda wc: scene_resolution(wc.scene),  # --config resolution=full
        scene=lambda wc: scene_summary(wc.scene),  # for the HTML report's caption
    script:
        "../scripts/compute_scene.py"


# A scene with `chunks: N` is computed as N jobs, each on a contiguous part of
# the scene's grid (filippov.scenes.chunking), and merged into results/<id>.nc
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
    script:
        "../scripts/compute_chunk.py"


rule merge_chunks:
    input:
        scene="config/scenes/{scene}.yaml",
        schema=config["schema"],
        script="workflow/scripts/merge_chunks.py",
        chunks=lambda wc: [f"results/chunks/{wc.scene}/{i}.nc" for i in range(CHUNKS[wc.scene])],
    output:
        report("results/{scene}.nc", caption="../report/dataset.rst", category="Datasets",
               labels={"scene": "{scene}", "format": "netCDF"}),
    wildcard_constraints:
        scene=CHUNKED_SCENES,
    params:
        code=library_hash(exclude=NOT_COMPUTE, strip_reports=True),  # see common.smk
        resolution=lambda wc: scene_resolution(wc.scene),  # --config resolution=full
        scene=lambda wc: scene_summary(wc.scene),  # for the HTML report's caption
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
        scene=lambda wc: scene_summary(wc.scene),
    localrule: True
    shell:
        "cp {input:q} {output:q}"
