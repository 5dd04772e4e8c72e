"""Datasets on disk: provenance attributes and byte-deterministic netCDF.

Files are written as NETCDF3_64BIT: unlike the HDF5-based formats it stores no
library versions or timestamps, so the same data gives the same bytes. Writes go
to a temporary file in the target folder and are renamed into place, so a failed
run never leaves a half-written dataset behind.
"""
from __future__ import annotations

import json
import os
import subprocess
import tempfile
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path

import numpy as np
import xarray as xr

from . import __version__

NETCDF_FORMAT = "NETCDF3_64BIT"


@lru_cache(maxsize=1)
def code_version() -> str:
    """Git commit of the source tree (suffix '-dirty' for uncommitted changes)."""
    here = Path(__file__).resolve().parent
    try:
        commit = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], check=True,
                                capture_output=True, text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--", "."],
                               check=True, capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return commit + ("-dirty" if dirty else "")


def _attr(value):
    """netCDF attributes hold numbers, strings and 1-D numeric arrays only."""
    if isinstance(value, (bool, np.bool_)):
        return int(value)
    if isinstance(value, (list, tuple)) and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
        return np.asarray(value, dtype=float)
    if isinstance(value, (dict, list, tuple)):
        return json.dumps(value, sort_keys=True)
    if value is None:
        return "none"
    return value


def provenance(scene: dict | None = None) -> dict:
    attrs = {"filippov_version": __version__, "code_version": code_version(),
             "source": "filippov reproduction of Sieber & Kowalczyk, Physica D (2010)"}
    if scene is not None:
        attrs["scene_id"] = scene.get("id", "")
        attrs["scene_config"] = json.dumps(scene, sort_keys=True)
        for key, val in scene.get("ingredients", {}).items():
            attrs[f"ingredient_{key}"] = _attr(val)
    return attrs


def finalize(ds: xr.Dataset, scene: dict | None = None, **attrs) -> xr.Dataset:
    """Attach provenance, parameters and extra attributes, all netCDF-safe."""
    ds = ds.copy()
    merged = dict(ds.attrs)
    merged.update(provenance(scene))
    if scene is not None:
        for key, val in scene.get("parameters", {}).items():
            merged.setdefault(key, _attr(val))
    merged.update(attrs)
    ds.attrs = {k: _attr(v) for k, v in sorted(merged.items())}
    for name in ds.variables:
        ds[name].attrs = {k: _attr(v) for k, v in ds[name].attrs.items()}
    return ds


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


@contextmanager
def atomic_output(path):
    """Yield a temporary path next to ``path``; rename it into place on success.

    Readers never see half a file and a failure leaves nothing behind.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    os.close(fd)
    os.chmod(tmp, 0o666 & ~_umask())  # mkstemp makes 0600; give the usual mode
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)


def write_dataset(ds: xr.Dataset, path) -> Path:
    with atomic_output(path) as tmp:
        ds.to_netcdf(tmp, format=NETCDF_FORMAT, engine="netcdf4")
    return Path(path)


def read_dataset(path) -> xr.Dataset:
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()
