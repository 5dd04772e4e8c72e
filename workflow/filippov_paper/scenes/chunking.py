"""Splitting one scene's sweep into chunks that run as separate jobs, and merging
them back into exactly the dataset :func:`filippov_paper.scenes.compute` returns.

A scene opts in with the top-level key ``chunks: N`` in its YAML. A scene module
that supports chunking provides

* ``CHUNK_AXIS``: the name of the grid dimension that is split;
* ``chunk_grid(scene)``: that whole grid (a 1-D array);
* ``sweep(scene, grid_part, progress=...)``: the solver's raw results on part of
  the grid, a Dataset with ``CHUNK_AXIS`` as a dimension and coordinate (each
  grid point is computed on its own, so parts of the grid give parts of the
  arrays, bit for bit);
* ``assemble(scene, raw)``: the figure's dataset from the raw results on the
  whole grid -- whatever is derived from the whole grid (fixed points, errors,
  rates) is computed here; ``compute(scene)`` is ``assemble(sweep(whole grid))``.

Chunk ``i`` of ``n`` holds the contiguous grid points ``bounds(size, i, n)``
(the split of ``numpy.array_split``). :func:`merge` puts the chunks back in
order, checks that they belong together and cover the grid, and assembles.
``chunks`` is a layout choice, not data: it is removed from the scene before
anything is computed, so the dataset (its ``scene_config`` attribute included)
does not depend on how the work was split.
"""
from __future__ import annotations

import json

import numpy as np
import xarray as xr

from filippov.io import finalize
from filippov.progress import context as progress_context

LAYOUT_KEYS = ("chunks",)


def without_layout(scene: dict) -> dict:
    """The scene without the keys that only say how to run it (``chunks``)."""
    return {k: v for k, v in scene.items() if k not in LAYOUT_KEYS}


def n_chunks(scene: dict) -> int:
    """``chunks`` of the scene (1 when absent)."""
    n = scene.get("chunks", 1)
    if isinstance(n, bool) or not isinstance(n, int) or n < 1:
        raise ValueError(f"{scene.get('id')}: chunks: must be an integer >= 1, got {n!r}")
    return n


def bounds(size: int, i: int, n: int) -> tuple[int, int]:
    """[start, stop) of chunk ``i`` of ``n`` over ``size`` points (as numpy.array_split)."""
    if not 1 <= n <= size:
        raise ValueError(f"chunks: {n} chunks for a grid of {size} points; need 1 <= chunks <= "
                         f"{size}")
    if not 0 <= i < n:
        raise ValueError(f"chunk index {i} out of range for {n} chunks")
    base, extra = divmod(size, n)
    start = i * base + min(i, extra)
    return start, start + base + (1 if i < extra else 0)


def supports_chunks(module) -> bool:
    """Whether the scene module has the four chunk hooks (filippov_paper.product)."""
    from filippov_paper import product

    return product.chunkable(module)


def compute_chunk(module, scene: dict, i: int, n: int, *, progress: bool = False) -> xr.Dataset:
    """Chunk ``i`` (0-based) of ``n``: the raw sweep on its part of the grid, with
    attributes naming the scene and the chunk (checked by :func:`merge`)."""
    scene = without_layout(scene)
    grid = np.asarray(module.chunk_grid(scene))
    start, stop = bounds(grid.size, i, n)
    with progress_context(f"chunk {i + 1}/{n}"):
        raw = module.sweep(scene, grid[start:stop], progress=progress)
    return finalize(raw, scene, chunk_index=i, chunk_count=n, chunk_axis=module.CHUNK_AXIS,
                    chunk_start=start, chunk_stop=stop, grid_size=grid.size,
                    title=f"chunk {i + 1} of {n} of {scene.get('id')} (raw; see results/"
                          f"{scene.get('id')}.nc)")


def _equal(a: np.ndarray, b: np.ndarray) -> bool:
    return a.dtype == b.dtype and a.shape == b.shape and np.array_equal(
        a, b, equal_nan=a.dtype.kind in "fc")


def merge(module, scene: dict, parts) -> xr.Dataset:
    """The scene's dataset from all its chunks (Datasets of :func:`compute_chunk`, in any order)."""
    scene = without_layout(scene)
    sid = scene.get("id")
    axis = module.CHUNK_AXIS
    parts = list(parts)
    if not parts:
        raise ValueError(f"{sid}: no chunks to merge")
    config = json.dumps(scene, sort_keys=True)
    n = int(parts[0].attrs.get("chunk_count", -1))
    for part in parts:
        if part.attrs.get("scene_config") != config:
            raise ValueError(f"{sid}: a chunk was computed from a different scene "
                             f"({part.attrs.get('scene_id')!r}, other parameters); recompute it")
        if part.attrs.get("chunk_axis") != axis or int(part.attrs.get("chunk_count", -1)) != n:
            raise ValueError(f"{sid}: chunks of different splits cannot be merged")
    parts = sorted(parts, key=lambda p: int(p.attrs["chunk_index"]))
    found = [int(p.attrs["chunk_index"]) for p in parts]
    if found != list(range(n)):
        raise ValueError(f"{sid}: need chunks 0..{n - 1} exactly once, got {found}")
    first = parts[0]
    data, coords = {}, {}
    for name, var in first.variables.items():
        if axis in var.dims:
            values = np.concatenate([p[name].values for p in parts], axis=var.dims.index(axis))
        else:
            values = var.values
            if not all(_equal(p[name].values, values) for p in parts[1:]):
                raise ValueError(f"{sid}: chunks disagree on {name!r}, which is not split")
        (coords if name in first.coords else data)[name] = (var.dims, values)
    merged = xr.Dataset(data, coords=coords)
    grid = np.asarray(module.chunk_grid(scene))
    if not _equal(merged[axis].values, grid):
        raise ValueError(f"{sid}: the chunks do not cover the {axis} grid of the scene")
    return module.assemble(scene, merged)
