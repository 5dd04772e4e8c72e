"""Thin: results/chunks/<id>/*.nc -> filippov.scenes.merge -> results/<id>.nc (no numerics here)."""
import sys

import filippov.io
import filippov.scenes
from filippov.config import SceneError, load_scene

try:
    scene = load_scene(snakemake.input.scene, snakemake.input.schema)  # noqa: F821
except SceneError as exc:
    sys.exit(f"error: {exc}")
parts = [filippov.io.read_dataset(path) for path in snakemake.input.chunks]  # noqa: F821
filippov.io.write_dataset(filippov.scenes.merge(scene, parts), snakemake.output[0])  # noqa: F821
