"""Thin: results/chunks/<id>/*.nc -> filippov.scenes.merge -> results/<id>.nc (no numerics here)."""
import sys

import filippov.io
import filippov.scenes
from filippov.config import SceneError, limits, load_scene

try:
    scene = load_scene(snakemake.input.scene, snakemake.input.schema,  # noqa: F821
                       limits(snakemake.config),
                       resolution=snakemake.params.resolution)  # noqa: F821
    filippov.scenes.check(scene)  # the engine it asks for, the size of its grid
except SceneError as exc:
    sys.exit(f"error: {exc}")
try:
    parts = [filippov.io.read_dataset(path) for path in snakemake.input.chunks]  # noqa: F821
except filippov.io.DatasetError as exc:
    sys.exit(f"error: {exc}")
filippov.io.write_dataset(filippov.scenes.merge(scene, parts), snakemake.output[0])  # noqa: F821
