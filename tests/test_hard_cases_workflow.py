"""The hard-case eps sweep as a workflow product (filippov_paper.hard_cases,
workflow/rules/hard_cases.smk): chunks merged give the unsplit sweep byte for
byte, the merge refuses chunks that do not belong together, a bad `hard_cases:`
block fails with the field named, and the workflow plans one job per chunk."""
import random
import re

import numpy as np
import pytest
import xarray as xr
import yaml

import filippov.io
from filippov_paper import hard_cases

from conftest import ROOT, copy_project, run_snakemake

SMALL = {"eps": [1e-2, 1e-3, 1e-4], "chunks": 3}   # cheap: the small eps cost most


def _configured() -> dict:
    return yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["hard_cases"]


def _bytes(ds, path) -> bytes:
    return filippov.io.write_dataset(ds, path).read_bytes()


def _parts(config, tmp_path, tag="p"):
    """Every chunk of ``config``, written and read back as the workflow does."""
    n = hard_cases.check_config(config)["chunks"]
    out = []
    for i in range(n):
        path = filippov.io.write_dataset(hard_cases.compute_part(config, i),
                                         tmp_path / f"{tag}{i}.nc")
        out.append(filippov.io.read_dataset(path))
    return out


def test_configured_sweep_is_valid_with_one_job_per_eps():
    cfg = hard_cases.check_config(_configured())
    assert cfg["eps"] == [1e-2, 1e-3, 1e-4, 1e-5, 1e-6]
    assert cfg["chunks"] == len(cfg["eps"])   # the report says: one job per value on a cluster


@pytest.mark.parametrize("config", [None, {"eps": [1e-2, 1e-3, 1e-4], "chunks": 2}],
                         ids=["configured-one-per-eps", "uneven-split"])
def test_merged_chunks_equal_the_unsplit_sweep_byte_for_byte(config, tmp_path):
    config = config or _configured()
    eps = hard_cases.check_config(config)["eps"]
    whole = hard_cases.sweep(eps)
    parts = _parts(config, tmp_path)
    for part in parts:   # a chunk holds its contiguous part of the grid, nothing else
        i, n = int(part.attrs["chunk_index"]), int(part.attrs["chunk_count"])
        start, stop = hard_cases.bounds(len(eps), i, n)
        np.testing.assert_array_equal(part.eps.values, eps[start:stop])
    random.Random(0).shuffle(parts)   # the order the files come in does not matter
    merged = hard_cases.merge(parts, config)
    assert merged.identical(whole)
    assert "chunk_index" not in merged.attrs
    assert _bytes(merged, tmp_path / "merged.nc") == _bytes(whole, tmp_path / "whole.nc")
    # without the config: the one recorded in the chunks
    assert _bytes(hard_cases.merge(parts), tmp_path / "m2.nc") == _bytes(whole, tmp_path / "w2.nc")


def test_every_variable_has_long_name_and_units_and_provenance():
    ds = hard_cases.sweep([1e-2])
    for name in ds.variables:
        assert ds[name].attrs.get("long_name") and ds[name].attrs.get("units"), name
        assert ds[name].dims == ("eps",), name
    assert set(ds.data_vars) == set(hard_cases.VARIABLES)
    assert ds.attrs["scene_id"] == "hard_cases" and ds.attrs["code_version"]
    assert '"eps": [0.01]' in ds.attrs["scene_config"] and "chunks" not in ds.attrs["scene_config"]


@pytest.fixture(scope="module")
def small_parts(tmp_path_factory):
    return _parts(SMALL, tmp_path_factory.mktemp("hard_parts"))


def test_merge_rejects_missing_duplicated_and_foreign_chunks(small_parts, tmp_path):
    p0, p1, p2 = small_parts
    with pytest.raises(ValueError, match=r"hard_cases: no chunks to merge"):
        hard_cases.merge([], SMALL)
    with pytest.raises(ValueError, match=r"hard_cases: chunk 1 of 0\.\.2 missing"):
        hard_cases.merge([p0, p2], SMALL)
    with pytest.raises(ValueError, match=r"hard_cases: chunk 1 given 2 times"):
        hard_cases.merge([p0, p1, p1, p2], SMALL)
    # computed from another eps list: its configuration differs
    other = hard_cases.compute_part({"eps": [1e-2, 2e-3, 1e-4], "chunks": 3}, 1)
    with pytest.raises(ValueError, match=r"hard_cases: chunk 1 was computed for a different "
                                         r"configuration"):
        hard_cases.merge([p0, other, p2], SMALL)
    # from another split of the same list
    half = hard_cases.compute_part({"eps": SMALL["eps"], "chunks": 2}, 1)
    with pytest.raises(ValueError, match=r"chunk 1 belongs to a split into 2 chunks, the "
                                         r"configuration asks for 3"):
        hard_cases.merge([p0, half, p2], SMALL)
    # not a hard-case chunk at all (a scene's dataset, or the merged sweep itself)
    scene = filippov.io.finalize(xr.Dataset({"P": ("x2", [1.0])}), {"id": "fig04_retmaps"})
    merged = hard_cases.merge([p0, p1, p2], SMALL)
    for foreign in (scene, merged):
        with pytest.raises(ValueError, match=r"hard_cases: input 1 is not a chunk of the "
                                             r"hard-case sweep"):
            hard_cases.merge([p0, foreign, p2], SMALL)
    # a chunk whose grid was altered after it was written
    moved = p1.assign_coords(eps=p1.eps.values * 2)
    with pytest.raises(ValueError, match=r"chunk 1 does not hold eps\[1:2\]"):
        hard_cases.merge([p0, moved, p2], SMALL)
    # the merge does not alter what it is given
    assert hard_cases.merge([p2, p0, p1], SMALL).identical(merged)


@pytest.mark.parametrize("block,field", [
    (None, r"hard_cases: missing from config/config\.yaml"),
    ([1e-2], r"hard_cases: must be a mapping"),
    ({"eps": [1e-2], "chunk": 1}, r"hard_cases\.chunk: unknown key"),
    ({"chunks": 1}, r"hard_cases\.eps: required"),
    ({"eps": [], "chunks": 1}, r"hard_cases\.eps: must be a non-empty list"),
    ({"eps": 1e-3, "chunks": 1}, r"hard_cases\.eps: must be a non-empty list"),
    ({"eps": [1e-2, -1e-3], "chunks": 1}, r"hard_cases\.eps\[1\]: must be a positive finite"),
    ({"eps": [1e-2, 0.0], "chunks": 1}, r"hard_cases\.eps\[1\]: must be a positive finite"),
    ({"eps": [float("nan")], "chunks": 1}, r"hard_cases\.eps\[0\]: must be a positive finite"),
    ({"eps": [float("inf")], "chunks": 1}, r"hard_cases\.eps\[0\]: must be a positive finite"),
    ({"eps": ["1e-3"], "chunks": 1}, r"hard_cases\.eps\[0\]: must be a number, got the string "
                                     r"'1e-3' \(YAML reads 1e-3 as text; write 1\.0e-3\)"),
    ({"eps": [True], "chunks": 1}, r"hard_cases\.eps\[0\]: must be a number"),
    ({"eps": [1e-2, 1e-3, 1e-2], "chunks": 1}, r"hard_cases\.eps\[2\]: 0\.01 is listed twice"),
    ({"eps": [1e-2, 1e-3], "chunks": 0}, r"hard_cases\.chunks: must be an integer from 1 to 2"),
    ({"eps": [1e-2, 1e-3], "chunks": 3}, r"hard_cases\.chunks: must be an integer from 1 to 2"),
    ({"eps": [1e-2, 1e-3], "chunks": 2.0}, r"hard_cases\.chunks: must be an integer"),
    ({"eps": [1e-2, 1e-3], "chunks": True}, r"hard_cases\.chunks: must be an integer"),
    ({"eps": [1e-2, 1e-3], "chunks": "2"}, r"hard_cases\.chunks: must be an integer"),
])
def test_bad_config_names_the_field(block, field):
    with pytest.raises(hard_cases.ConfigError, match=field):
        hard_cases.check_config(block)
    with pytest.raises(hard_cases.ConfigError, match=field):   # before any computation
        hard_cases.compute_part(block, 0)


def test_sweep_rejects_bad_eps_values():
    with pytest.raises(ValueError, match=r"eps\[1\]: must be a positive finite"):
        hard_cases.sweep([1e-2, -1.0])


# ----------------------------------------------------------------------------- the workflow
def _planned_rules(out: str) -> list[str]:
    return re.findall(r"^(?:local)?rule (\w+):", out, re.M)


@pytest.mark.parametrize("sweep_jobs", [None, "scene", 2])
def test_workflow_plans_one_job_per_chunk_and_a_local_merge(sweep_jobs, tmp_path):
    """hard_cases.chunks jobs (a cluster: sweep_jobs=scene), at most sweep_jobs of them
    (config/config.yaml's value for a local build when not given)."""
    work = copy_project(tmp_path / "project")
    extra = () if sweep_jobs is None else ("--config", f"sweep_jobs={sweep_jobs}")
    run = run_snakemake(work, "-n", "results/hard_cases.nc", *extra, timeout=600)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out
    rules = _planned_rules(out)
    n = hard_cases.check_config(_configured())["chunks"]
    if sweep_jobs != "scene":
        cap = sweep_jobs or yaml.safe_load((ROOT / "config" / "config.yaml").read_text())[
            "sweep_jobs"]
        n = min(n, cap)
    assert sorted(rules) == sorted(["hard_cases_part"] * n + ["hard_cases"]), rules
    # the merge runs on the submitting host (a dry run with local cores prints no marker)
    smk = (work / "workflow" / "rules" / "hard_cases.smk").read_text()
    assert re.search(r"^localrules: hard_cases$", smk, re.M)
    for i in range(n):
        assert f"results/chunks/hard_cases/{i}.nc" in out


def test_workflow_fails_on_a_bad_config_value_naming_the_field(tmp_path):
    work = copy_project(tmp_path / "project")
    config = work / "config" / "config.yaml"
    text = config.read_text()
    assert "eps: [1.0e-2, 1.0e-3," in text
    config.write_text(text.replace("eps: [1.0e-2, 1.0e-3,", "eps: [1.0e-2, -1.0e-3,"))
    run = run_snakemake(work, "results/hard_cases.nc", cores="1", timeout=600)
    out = run.stdout + run.stderr
    assert run.returncode != 0, out
    assert "hard_cases.eps[1]: must be a positive finite number, got -0.001" in out, out[-3000:]
    assert not (work / "results" / "hard_cases.nc").exists()
    assert not list((work / "results").glob("chunks/hard_cases/*.nc"))
