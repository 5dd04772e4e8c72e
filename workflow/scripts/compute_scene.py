"""Thin: scene file -> filippov_paper.scenes.compute -> results/<id>.nc (no numerics here)."""

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
    sys.exit(f"error: {exc}")  # a config mistake: one clear line, no traceback
ds = filippov_paper.scenes.compute(scene, progress=True)
filippov.io.write_dataset(ds, snakemake.output[0])  # noqa: F821
