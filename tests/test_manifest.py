"""The reproducibility manifest: it catches changed data, changed figures and
missing or extra outputs, tolerates last-bit noise, and the shared fresh build
agrees with the committed manifest."""
import json
import shutil

import numpy as np
import xarray as xr

from filippov_paper import manifest, tolerance
from filippov.io import write_dataset


def _dataset(path, scale=1.0):
    x = np.linspace(0.0, 1.0, 500)
    ds = xr.Dataset({"P": ("x", np.sin(7 * x) * scale), "n": ("x", np.arange(500)),
                     "label": ((), "text is not compared")}, coords={"x": x})
    write_dataset(tolerance.annotate(ds, {}), path)
    return path


def test_data_within_tolerance_passes_and_beyond_fails(tmp_path):
    ref = manifest.summarize(_dataset(tmp_path / "a.nc"))
    assert set(ref) == {"P", "n", "x"}
    near = manifest.summarize(_dataset(tmp_path / "b.nc", scale=1 + 1e-13))
    assert manifest.compare_data(near, ref) == []
    far = manifest.summarize(_dataset(tmp_path / "c.nc", scale=1 + 1e-6))
    problems = manifest.compare_data(far, ref)
    assert len(problems) == 1 and problems[0].startswith("P: differs by up to")


def test_shape_and_missing_variables_are_reported(tmp_path):
    ref = manifest.summarize(_dataset(tmp_path / "a.nc"))
    got = dict(ref)
    del got["n"]
    got["extra"] = ref["P"]
    problems = manifest.compare_data(got, ref)
    assert "n: missing" in problems and "extra: not in the manifest" in problems


def _figure(path, box=False):
    from matplotlib.figure import Figure

    fig = Figure(figsize=(3, 2))
    ax = fig.subplots()
    ax.plot([0, 1], [0, 1])
    if box:
        ax.fill_between([0.1, 0.9], 0.1, 0.9, color="black")
    fig.savefig(path, dpi=200, metadata={"Software": None})
    return path


def test_image_comparison_tolerates_equal_and_catches_changes(tmp_path):
    png = _figure(tmp_path / "f.png")
    manifest.write_thumbnail(png, tmp_path / "ref" / "f.png")
    assert manifest.compare_image(png, tmp_path / "ref" / "f.png") is None
    changed = _figure(tmp_path / "g.png", box=True)
    assert "image differs" in manifest.compare_image(changed, tmp_path / "ref" / "f.png")


def test_check_in_another_environment_compares_images(tmp_path):
    res, figs = tmp_path / "results", tmp_path / "figures"
    res.mkdir(), figs.mkdir()
    _dataset(res / "fig99_test.nc")
    _figure(figs / "fig99_test.png")
    _figure(figs / "fig99_test.pdf")
    man = manifest.build_manifest(res, figs)
    thumbs = tmp_path / "reference" / "figures"
    manifest.write_thumbnail(figs / "fig99_test.png", thumbs / "fig99_test.png")
    assert manifest.check(res, figs, man, thumbs) == []
    # a different environment: the PDF's hash no longer matters, the image does
    man["environment"] = "elsewhere"
    (figs / "fig99_test.pdf").write_bytes(b"%PDF other bytes")
    assert manifest.check(res, figs, man, thumbs) == []
    _figure(figs / "fig99_test.png", box=True)
    assert any("image differs" in p for p in manifest.check(res, figs, man, thumbs))
    # the manifest's environment: hashes are compared exactly
    man["environment"] = manifest.environment()
    assert any("hash differs" in p for p in manifest.check(res, figs, man, thumbs))
    # missing and unlisted outputs
    shutil.copy(res / "fig99_test.nc", res / "fig98_new.nc")
    (res / "fig99_test.nc").unlink()
    problems = manifest.check(res, figs, man, thumbs)
    assert "results/fig99_test.nc: missing" in problems
    assert any("fig98_new.nc: not in the manifest" in p for p in problems)


def test_figures_are_hashed_only_for_the_same_environment_and_data(tmp_path):
    res, figs = tmp_path / "results", tmp_path / "figures"
    res.mkdir(), figs.mkdir()
    _dataset(res / "fig99_test.nc")
    _figure(figs / "fig99_test.png"), _figure(figs / "fig99_test.pdf")
    man = manifest.build_manifest(res, figs)
    thumbs = tmp_path / "reference" / "figures"
    manifest.write_thumbnail(figs / "fig99_test.png", thumbs / "fig99_test.png")
    (figs / "fig99_test.pdf").write_bytes(b"%PDF other bytes")
    assert any("hash differs" in p for p in manifest.check(res, figs, man, thumbs))
    # data within its tolerance but not bit-identical (another CPU): a figure's
    # bytes may differ too, so it is compared as an image
    _dataset(res / "fig99_test.nc", scale=1 + 1e-13)
    assert manifest.check(res, figs, man, thumbs) == []


def test_an_unreadable_dataset_is_listed_and_the_check_goes_on(tmp_path):
    res, figs = tmp_path / "results", tmp_path / "figures"
    res.mkdir(), figs.mkdir()
    _dataset(res / "fig98_a.nc"), _dataset(res / "fig99_b.nc")
    man = manifest.build_manifest(res, figs)
    (res / "fig98_a.nc").write_bytes(b"CDF\x02 not a dataset")
    _dataset(res / "fig99_b.nc", scale=2.0)
    problems = manifest.check(res, figs, man)
    assert any(p.startswith("results/fig98_a.nc: unreadable") for p in problems)
    assert any(p.startswith("results/fig99_b.nc: P: differs") for p in problems)


def test_update_prints_what_changed(tmp_path, capsys):
    res, figs = tmp_path / "results", tmp_path / "figures"
    res.mkdir(), figs.mkdir()
    _dataset(res / "fig99_test.nc")
    _figure(figs / "fig99_test.png"), _figure(figs / "fig99_test.pdf")
    path = tmp_path / "ref" / "manifest.json"
    args = ["update", "--results", str(res), "--figures", str(figs), "--manifest", str(path)]
    assert manifest.main(args) == 0
    assert "+ results/fig99_test.nc (new)" in capsys.readouterr().out
    _dataset(res / "fig99_test.nc", scale=2.0)
    assert manifest.main(args) == 0
    out = capsys.readouterr().out
    assert "~ results/fig99_test.nc: P: differs" in out
    assert manifest.main(["check", "--results", str(res), "--figures", str(figs),
                          "--manifest", str(path)]) == 0
    saved = json.loads(path.read_text())["data"]["fig99_test"]["variables"]["P"]["tolerance"]
    assert saved["rtol"] == 1e-9 and saved["why"] == tolerance.DEFAULT.why


def test_fresh_build_agrees_with_the_committed_manifest(workflow_build):
    """The reproducibility check of CI: a clean build of every scene against the
    committed reference values (data: tolerance; figures: hash or image)."""
    run = workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    work = workflow_build["work"]
    man = json.loads(manifest.MANIFEST.read_text())
    problems = manifest.check(work / "results", work / "figures", man)
    assert problems == [], "\n".join(problems)


def test_a_figure_of_chaotic_orbits_declares_a_wider_image_tolerance(tmp_path):
    # fig13 scatters chaotic orbits (another machine: another orbit on the attractor);
    # every other figure keeps the default, and the declared limit is the one applied
    assert manifest.image_tolerance("fig13_small_scale_chaos") > manifest.IMAGE_RMS
    assert manifest.image_tolerance("fig04_retmaps") == manifest.IMAGE_RMS
    png = _figure(tmp_path / "f.png")
    manifest.write_thumbnail(png, tmp_path / "ref" / "f.png")
    changed = _figure(tmp_path / "g.png", box=True)
    assert "image differs" in manifest.compare_image(changed, tmp_path / "ref" / "f.png")
    assert manifest.compare_image(changed, tmp_path / "ref" / "f.png", limit=1.0) is None


def _declared(path, atol):
    ds = xr.Dataset({"rate": ("k", np.array([1.0, 1.02, 0.98]))})
    tol = tolerance.Tolerance(1e-9, atol, "log-log slope of errors >= 1e-3 known to 1e-9: "
                                          "2 delta/(e ln 10)")
    return manifest.summarize(write_dataset(tolerance.annotate(ds, {"rate": tol}), path))


def test_a_declaration_is_compared_as_a_formulas_value(tmp_path):
    # fig07's rate tolerance 2 delta/(e ln 10): another libm rounds ln 10 differently by
    # an ulp or two; the declaration is the same, the data are the same -- only the
    # tolerance's last bits differ, and the check must accept that
    delta, e = 1e-9, 1e-3
    ln10 = np.log(10.0)
    ref = _declared(tmp_path / "ref.nc", 2 * delta / (e * ln10))
    for ulps in (-4, -2, -1, 1, 2, 4):
        moved = ln10 + ulps * np.spacing(ln10)
        atol = 2 * delta / (e * moved)
        assert atol != ref["rate"]["tolerance"]["atol"], ulps   # the bits do differ
        got = _declared(tmp_path / f"moved{ulps}.nc", atol)
        assert manifest.compare_data(got, ref) == [], ulps
        assert tolerance.same_declaration(got["rate"]["tolerance"], ref["rate"]["tolerance"])
    # a different declaration is still one: another error floor (3e-3, fig09's), a
    # relative change of 1e-12 (far beyond any rounding of the formula), another rule
    for atol in (2 * delta / (3e-3 * ln10), 2 * delta / (e * ln10) * (1 + 1e-12)):
        got = _declared(tmp_path / "other.nc", atol)
        problems = manifest.compare_data(got, ref)
        assert len(problems) == 1 and problems[0].startswith("rate: the data declares "
                                                             "tolerance"), problems
    want = ref["rate"]["tolerance"]
    assert not tolerance.same_declaration(dict(want, rule="trace"), want)
    assert not tolerance.same_declaration(dict(want, why="another reason"), want)
    assert not tolerance.same_declaration(dict(want, rtol=0.0), want)
    assert tolerance.same_declaration(dict(want, rtol=0.0), dict(want, rtol=0.0))


def test_update_keeps_a_spread_measured_against_the_same_declaration(tmp_path):
    path = _dataset(tmp_path / "results" / "fig99_test.nc")
    old = {"data": {"fig99_test": {"variables": manifest.summarize(path)}}}
    tol = old["data"]["fig99_test"]["variables"]["P"]["tolerance"]
    old["data"]["fig99_test"]["variables"]["P"]["spread"] = {"margin": 50.0}
    # the same declaration, its last bits rounded elsewhere: the spread stays ...
    tol["rtol"] = float(np.nextafter(tol["rtol"], 1.0))
    new = manifest.build_manifest(tmp_path / "results", tmp_path / "figures", old)
    assert new["data"]["fig99_test"]["variables"]["P"]["spread"] == {"margin": 50.0}
    # ... another declaration: it was not measured against this one
    tol["rtol"] = 2e-9
    new = manifest.build_manifest(tmp_path / "results", tmp_path / "figures", old)
    assert "spread" not in new["data"]["fig99_test"]["variables"]["P"]
