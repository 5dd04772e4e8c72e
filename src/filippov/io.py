"""Datasets on disk: provenance attributes and byte-deterministic netCDF.

Files are written as NETCDF3_64BIT: unlike the HDF5-based formats it stores no
library versions or timestamps, so the same data gives the same bytes. Writes go
to a temporary file in the target folder and are renamed into place, so a failed
run never leaves a half-written dataset behind.

Every file carries a checksum of its contents (``checksum_sha256``: every
variable's name, dimensions, type and values, and every attribute), computed
from what a reader sees and checked by :func:`read_dataset`. netCDF-3 reads a
truncated file without complaint (the missing part as zeros); the checksum
refuses it, and any other damage, with one line naming the file.
"""
from __future__ import annotations

import hashlib
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
from .errors import DatasetError  # noqa: F401  (re-exported)

NETCDF_FORMAT = "NETCDF3_64BIT"
CHECKSUM_ATTR = "checksum_sha256"


@lru_cache(maxsize=1)
def code_version() -> str:
    """Git commit of the source tree (suffix '-dirty' for uncommitted changes)."""
    here = Path(__file__).resolve().parent
    commit = dirty = ""
    try:
        commit = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], check=True,
                                capture_output=True, text=True, timeout=10).stdout.strip()
        dirty = subprocess.run(["git", "-C", str(here), "status", "--porcelain", "--", "."],
                               check=True, capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        commit = ""  # not a (readable) git checkout
    if not commit:  # an installed copy, not a git checkout: its released version
        return f"filippov-{__version__} (installed)"
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


#: the paper every dataset reproduces a part of (CF attribute ``references``)
REFERENCE = ("J. Sieber, P. Kowalczyk, Small-scale instabilities in dynamical systems with "
             "sliding, Physica D 239 (2010) 44-57, doi:10.1016/j.physd.2009.10.001")


def provenance(scene: dict | None = None) -> dict:
    """The CF-1.8 global attributes (Conventions, source, history, references) and
    the code and scene a dataset comes from. No timestamps: the same inputs give the
    same bytes."""
    attrs = {"filippov_version": __version__, "code_version": code_version(),
             "Conventions": "CF-1.8",
             "source": "filippov reproduction of Sieber & Kowalczyk, Physica D (2010)",
             "history": f"computed by filippov {__version__} (code {code_version()})",
             "references": REFERENCE}
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


def _plain(value):
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return value


def _attrs_bytes(attrs) -> bytes:
    return json.dumps({k: _plain(v) for k, v in attrs.items()}, sort_keys=True,
                      default=str).encode()


def checksum(ds: xr.Dataset) -> str:
    """sha256 of a dataset as read from disk (its own checksum attribute excluded)."""
    h = hashlib.sha256()
    for name in sorted(ds.variables):
        var = ds[name]
        h.update(json.dumps([name, list(var.dims), str(var.dtype), list(var.shape)]).encode())
        values = np.asarray(var.values)
        h.update(json.dumps(values.tolist()).encode() if values.dtype.kind == "O"
                 else np.ascontiguousarray(values).tobytes())
        h.update(_attrs_bytes(var.attrs))
    h.update(_attrs_bytes({k: v for k, v in ds.attrs.items() if k != CHECKSUM_ATTR}))
    return h.hexdigest()


def _load(path) -> xr.Dataset:
    with xr.open_dataset(path, engine="netcdf4") as ds:
        return ds.load()


def write_dataset(ds: xr.Dataset, path) -> Path:
    """Write ``ds`` atomically, with the checksum of what a reader will see."""
    import netCDF4

    # CF: coordinates have no missing values, so no _FillValue on them
    encoding = {name: {"_FillValue": None} for name in ds.coords
                if ds[name].dtype.kind == "f"}
    with atomic_output(path) as tmp:
        ds.to_netcdf(tmp, format=NETCDF_FORMAT, engine="netcdf4", encoding=encoding)
        # the checksum of what a reader sees, added as a global attribute (which
        # the checksum leaves out, so adding it changes nothing it covers)
        with netCDF4.Dataset(tmp, "a") as nc:
            nc.setncattr(CHECKSUM_ATTR, checksum(_load(tmp)))
    return Path(path)


def read_dataset(path, scene_id: str | None = None) -> xr.Dataset:
    """The dataset in ``path``, checked against its checksum (and, with
    ``scene_id``, that it holds that scene); :class:`DatasetError` otherwise."""
    try:
        ds = _load(path)
    except Exception as exc:  # netCDF's own errors are many and terse
        raise DatasetError(f"{path}: not a readable netCDF dataset ({type(exc).__name__}: "
                           f"{exc}); recompute it") from None
    stored = ds.attrs.pop(CHECKSUM_ATTR, None)
    if stored is None:
        raise DatasetError(f"{path}: no checksum ({CHECKSUM_ATTR}): not written by "
                           f"filippov.io, or its header is damaged; recompute it")
    if checksum(ds) != stored:
        raise DatasetError(f"{path}: checksum mismatch: the file is damaged or truncated; "
                           f"recompute it")
    if scene_id is not None and ds.attrs.get("scene_id") != scene_id:
        raise DatasetError(f"{path}: holds scene {ds.attrs.get('scene_id')!r}, expected "
                           f"{scene_id!r}")
    return ds
