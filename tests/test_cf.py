"""CF-1.8 attributes on every dataset a build writes, as the project reads them
(tests/test_cf_compliance.py runs the real checker, compliance-checker, on the same
build)."""
import numpy as np
import pytest
import xarray as xr

from filippov.io import REFERENCE
from filippov_paper.manifest import data_files


@pytest.fixture(scope="module")
def datasets(workflow_build):
    files = data_files(workflow_build["work"] / "results")
    assert len(files) >= 12
    return files


def test_global_attributes(datasets):
    for path in datasets:
        with xr.open_dataset(path) as ds:
            assert ds.attrs["Conventions"] == "CF-1.8", path.name
            assert ds.attrs["references"] == REFERENCE
            assert ds.attrs["history"].startswith("computed by filippov")
            assert ds.attrs["title"] and ds.attrs["source"]


def test_every_variable_has_long_name_and_units(datasets):
    for path in datasets:
        with xr.open_dataset(path) as ds:
            for name in ds.variables:
                attrs = ds[name].attrs
                assert attrs.get("long_name"), f"{path.name}:{name} has no long_name"
                if ds[name].dtype.kind in "fiub":
                    assert "units" in attrs, f"{path.name}:{name} has no units"


def test_no_fill_value_on_coordinates(datasets):
    for path in datasets:
        with xr.open_dataset(path, decode_cf=False) as ds:
            for name in ds.coords:
                assert "_FillValue" not in ds[name].attrs, f"{path.name}:{name}"
                assert np.all(np.isfinite(ds[name].values)) if ds[name].dtype.kind == "f" else True
