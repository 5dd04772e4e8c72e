"""Thin: results/chunks/<id>/*.nc -> filippov_paper.scenes.merge -> results/<id>.nc (no numerics here)."""

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
try:
    parts = [filippov.io.read_dataset(path) for path in snakemake.input.chunks]  # noqa: F821
except filippov.io.DatasetError as exc:
    sys.exit(f"error: {exc}")
filippov.io.write_dataset(filippov_paper.scenes.merge(scene, parts), snakemake.output[0])  # noqa: F821
