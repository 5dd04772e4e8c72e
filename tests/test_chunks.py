"""Chunked sweeps (filippov_paper.scenes.chunking): chunks computed apart and merged give
exactly the dataset of one unsplit compute -- xarray-identical and the same bytes
on disk -- for the return maps (fig04, split over x2), the discontinuity maps
(fig07, fig09, split over xi1), the dry-friction bifurcation diagram (fig10,
split over tasks: the two continuation directions and the stick-slip orbits) and the
orbit diagrams of the instabilities (fig12, fig13, split over the scaled mu).
Small grids keep it quick."""
import importlib
import random

import numpy as np
import pytest

pytest.importorskip("filippov_paper.scenes", reason="compute code (filippov_paper.scenes) not importable yet")

import filippov.io
import filippov_paper.scenes
from filippov_paper import product
from filippov_paper.config import SceneError, load_scene
from filippov_paper.scenes import chunking

from conftest import ROOT

SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"

def _module(sid: str):
    return importlib.import_module(f"filippov_paper.scenes.{sid}")


#: every scene that can be split into chunks (its module has the chunk hooks)
CHUNKED = tuple(sid for sid in filippov_paper.scenes.known_scenes()
                if product.chunkable(_module(sid)))


def small_scene(sid: str) -> dict:
    """The scene file on the short grid its module declares (TEST_SMALL)."""
    scene = load_scene(ROOT / "config" / "scenes" / f"{sid}.yaml", SCHEMA)
    scene["parameters"].update(product.hook(_module(sid), "TEST_SMALL"))
    return scene


def test_the_chunked_scenes_are_found():
    # the return maps, both discontinuity maps, dry friction and the instabilities
    assert {"fig04_retmaps", "fig07_pdm_theta_neg", "fig10_dfo", "fig14_atlas"} <= set(CHUNKED)
    assert "fig08_s0theta" not in CHUNKED


def roundtrip(ds, path):
    """Through a netCDF file, as between the workflow's chunk and merge jobs."""
    filippov.io.write_dataset(ds, path)
    return filippov.io.read_dataset(path)


@pytest.mark.parametrize("size,n", [(1, 1), (7, 1), (7, 3), (10, 4), (31, 31), (1001, 8)])
def test_bounds_partition_the_grid_like_array_split(size, n):
    pieces = [chunking.bounds(size, i, n) for i in range(n)]
    expected = np.array_split(np.arange(size), n)
    assert [list(range(a, b)) for a, b in pieces] == [e.tolist() for e in expected]


@pytest.mark.parametrize("sid", CHUNKED)
def test_merged_chunks_identical_to_compute(sid, tmp_path):
    scene = small_scene(sid)
    whole = filippov_paper.scenes.compute(scene)
    n = 3
    parts = [roundtrip(filippov_paper.scenes.compute_chunk(scene, i, n), tmp_path / f"{i}.nc")
             for i in range(n)]
    axis = parts[0].attrs["chunk_axis"]
    sizes = [p[axis].size for p in parts]
    assert len(set(sizes)) <= 2 and min(sizes) >= 1  # a real split
    random.Random(0).shuffle(parts)  # merge orders them itself
    merged = filippov_paper.scenes.merge(scene, parts)
    assert merged.identical(whole)
    filippov.io.write_dataset(whole, tmp_path / "whole.nc")
    filippov.io.write_dataset(merged, tmp_path / "merged.nc")
    assert (tmp_path / "merged.nc").read_bytes() == (tmp_path / "whole.nc").read_bytes()


def test_chunks_key_is_layout_not_data(tmp_path):
    """`chunks` does not enter the dataset: with or without it, same result."""
    scene = small_scene("fig07_pdm_theta_neg")
    with_key = dict(scene, chunks=2)
    whole = filippov_paper.scenes.compute(scene)
    assert filippov_paper.scenes.compute(with_key).identical(whole)
    parts = [roundtrip(filippov_paper.scenes.compute_chunk(with_key, i), tmp_path / f"{i}.nc")
             for i in range(2)]  # n from the scene's `chunks`
    assert filippov_paper.scenes.merge(with_key, parts).identical(whole)
    assert "chunks" not in whole.attrs["scene_config"]


def test_merge_rejects_incomplete_or_foreign_chunks():
    scene = small_scene("fig07_pdm_theta_neg")
    parts = [filippov_paper.scenes.compute_chunk(scene, i, 3) for i in range(3)]
    with pytest.raises(ValueError, match="chunks 0..2"):
        filippov_paper.scenes.merge(scene, parts[:2])
    with pytest.raises(ValueError, match="chunks 0..2"):
        filippov_paper.scenes.merge(scene, [parts[0], parts[0], parts[2]])
    other = small_scene("fig07_pdm_theta_neg")
    other["parameters"]["n_uniform"] = 11
    with pytest.raises(ValueError, match="different scene"):
        filippov_paper.scenes.merge(other, parts)
    two = [filippov_paper.scenes.compute_chunk(scene, i, 2) for i in range(2)]
    with pytest.raises(ValueError, match="different splits"):
        filippov_paper.scenes.merge(scene, [parts[0], two[1]])


def test_bad_chunk_requests_fail_clearly():
    scene = small_scene("fig07_pdm_theta_neg")
    n_points = filippov_paper.scenes._module(scene).chunk_grid(scene).size
    with pytest.raises(ValueError, match="need 1 <= chunks"):
        filippov_paper.scenes.compute_chunk(scene, 0, n_points + 1)
    with pytest.raises(ValueError, match="out of range"):
        filippov_paper.scenes.compute_chunk(scene, 3, 3)
    sketch = load_scene(ROOT / "config" / "scenes" / "fig08_s0theta.yaml", SCHEMA)
    with pytest.raises(ValueError, match="cannot be split"):
        filippov_paper.scenes.compute_chunk(sketch, 0, 2)
    with pytest.raises(ValueError, match="integer >= 1"):
        chunking.n_chunks({"id": "x", "chunks": 0})


def test_schema_accepts_chunks_and_rejects_bad_values(tmp_path):
    text = (ROOT / "config" / "scenes" / "fig07_pdm_theta_neg.yaml").read_text()
    text = "\n".join(l for l in text.splitlines() if not l.startswith("chunks:"))
    path = tmp_path / "fig07_pdm_theta_neg.yaml"
    path.write_text(text + "\nchunks: 4\n")
    assert load_scene(path, SCHEMA)["chunks"] == 4
    path.write_text(text + "\nchunks: 0\n")
    with pytest.raises(SceneError, match="chunks"):
        load_scene(path, SCHEMA)
