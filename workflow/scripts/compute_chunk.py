"""Thin: scene file + chunk index -> filippov_paper.scenes.compute_chunk -> results/chunks/<id>/<i>.nc."""

import joblog

joblog.tee(snakemake)  # noqa: F821  (stdout and stderr also to the rule's log, logs/)

import sys  # noqa: E402

import filippov.io  # noqa: E402
import filippov_paper.scenes  # noqa: E402
from filippov_paper.config import SceneError, limits, load_scene  # noqa: E402

try:
    scene = load_scene(snakemake.input.scene, snakemake.input.schema,  # noqa: F821
                       limits(snakemake.config),
                       resolution=snakemake.params.resolution)  # noqa: F821
    filippov_paper.scenes.check(scene)  # the engine it asks for, the size of its grid
except SceneError as exc:
    sys.exit(f"error: {exc}")
index = int(snakemake.wildcards.chunk)  # noqa: F821
count = int(snakemake.params.chunks)  # noqa: F821; the scene's `chunks`, capped by sweep_jobs
ds = filippov_paper.scenes.compute_chunk(scene, index, count, progress=True)
filippov.io.write_dataset(ds, snakemake.output[0])  # noqa: F821
