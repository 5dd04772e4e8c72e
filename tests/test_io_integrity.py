"""Damaged, truncated or foreign datasets are refused with one line naming the
file, by the library and by every workflow step that reads one."""
import shutil
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from filippov.io import CHECKSUM_ATTR, DatasetError, read_dataset, write_dataset

ROOT = Path(__file__).resolve().parents[1]


def _write(path, n=2000, **attrs):
    ds = xr.Dataset({"P": ("x", np.sin(np.linspace(0, 9, n))), "k": ("x", np.arange(n))},
                    coords={"x": np.linspace(0, 1, n)}, attrs=dict(scene_id="fig99_test", **attrs))
    return write_dataset(ds, path)


def test_written_datasets_carry_a_checksum_and_read_back(tmp_path):
    path = _write(tmp_path / "a.nc")
    with xr.open_dataset(path) as raw:
        assert len(raw.attrs[CHECKSUM_ATTR]) == 64
    ds = read_dataset(path)
    assert CHECKSUM_ATTR not in ds.attrs and ds.attrs["scene_id"] == "fig99_test"
    # deterministic: the same data gives the same bytes
    assert path.read_bytes() == _write(tmp_path / "b.nc").read_bytes()


def test_a_truncated_file_is_refused(tmp_path):
    path = _write(tmp_path / "a.nc")
    data = path.read_bytes()
    path.write_bytes(data[: len(data) // 2])
    with xr.open_dataset(path) as raw:  # netCDF itself reads the missing part as zeros
        raw.load()
    with pytest.raises(DatasetError, match=r"a\.nc: .*(damaged|truncated)"):
        read_dataset(path)


def test_a_flipped_byte_is_refused(tmp_path):
    path = _write(tmp_path / "a.nc")
    data = bytearray(path.read_bytes())
    data[-100] ^= 0x40
    path.write_bytes(bytes(data))
    with pytest.raises(DatasetError, match="checksum"):
        read_dataset(path)


def test_an_unreadable_header_and_a_foreign_file_are_refused(tmp_path):
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"this is no netCDF file")
    with pytest.raises(DatasetError, match="bad.nc: not a readable netCDF"):
        read_dataset(bad)
    header = tmp_path / "header.nc"   # netCDF opens this as an empty dataset
    header.write_bytes(b"CDF\x02 garbage")
    with pytest.raises(DatasetError, match="header.nc: no checksum"):
        read_dataset(header)
    foreign = tmp_path / "foreign.nc"
    xr.Dataset({"v": ("i", [1.0, 2.0])}).to_netcdf(foreign, format="NETCDF3_64BIT")
    with pytest.raises(DatasetError, match="foreign.nc: no checksum"):
        read_dataset(foreign)


def test_a_dataset_of_another_scene_is_refused(tmp_path):
    path = _write(tmp_path / "a.nc")
    assert read_dataset(path, scene_id="fig99_test").attrs["scene_id"] == "fig99_test"
    with pytest.raises(DatasetError, match="holds scene 'fig99_test', expected 'fig08_s0theta'"):
        read_dataset(path, scene_id="fig08_s0theta")


def test_the_plot_step_refuses_a_truncated_dataset(tmp_path):
    """The workflow's plot job on a damaged results/<id>.nc: one line, no figure."""
    sys.path.insert(0, str(ROOT / "workflow" / "scripts"))
    from verify import copy_project, run_snakemake

    work = copy_project(tmp_path / "p")
    synthetic = tmp_path / "s.nc"
    from synthetic import dataset  # a small, valid dataset of the scene

    write_dataset(dataset("fig08_s0theta").assign_attrs(scene_id="fig08_s0theta"), synthetic)
    (work / "results").mkdir()
    data = synthetic.read_bytes()
    (work / "results" / "fig08_s0theta.nc").write_bytes(data[: len(data) // 2])
    run = run_snakemake(work, "figures/fig08_s0theta.pdf", "--touch")  # mark up to date
    assert run.returncode == 0, run.stderr[-2000:]
    run = run_snakemake(work, "--force", "figures/fig08_s0theta.pdf")
    assert run.returncode != 0
    assert "fig08_s0theta.nc: checksum mismatch" in run.stdout + run.stderr
    assert not (work / "figures" / "fig08_s0theta.pdf").exists()
    shutil.rmtree(work)
