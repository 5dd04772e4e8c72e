"""Scene files: valid ones load; each kind of mistake names the file and field."""
from pathlib import Path

import pytest

from filippov_paper.config import SceneError, load_scene

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"
SCENES = sorted((ROOT / "config" / "scenes").glob("*.yaml"))
FIG02 = (ROOT / "config" / "scenes" / "fig02_cases.yaml").read_text()


def _write(tmp_path, text, name="fig02_cases"):
    path = tmp_path / f"{name}.yaml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("path", SCENES, ids=[p.stem for p in SCENES])
def test_shipped_scenes_are_valid(path):
    scene = load_scene(path, SCHEMA)
    assert scene["id"] == path.stem


def test_valid_scene_loads(tmp_path):
    scene = load_scene(_write(tmp_path, FIG02), SCHEMA)
    assert scene["parameters"]["eps"] == 0.1
    assert scene["parameters"]["theta"] == [0.5, -0.5]
    assert scene["solver"]["rtol"] == 1e-12


@pytest.mark.parametrize("old, new, field", [
    ("eps: 0.1", "eps: -0.1", "parameters.eps"),
    ("theta: [0.5, -0.5]", "theta: [1.0]", "parameters.theta"),
    ("model: pseudo_equilibrium", "model: pseudo_equilibrum", "model"),
    ("eps: 0.1", "epsilon: 0.1", "parameters"),
    ("eps: 0.1", "eps: .nan", "parameters.eps"),
    ("rtol: 1.0e-12", "rtol: 0.5", "solver.rtol"),
    ("sliding: true", "sliding: true, flux: exact", "ingredients"),
], ids=["negative-eps", "theta-1", "unknown-model", "unknown-key", "nan", "rtol", "ingredient"])
def test_bad_scene_names_field(tmp_path, old, new, field):
    assert old in FIG02
    path = _write(tmp_path, FIG02.replace(old, new))
    with pytest.raises(SceneError) as info:
        load_scene(path, SCHEMA)
    msg = str(info.value)
    assert msg.startswith(f"{path}: {field}"), msg
    if new.startswith("epsilon"):
        assert "'epsilon' was unexpected" in msg


def test_negative_eps_message_is_exact(tmp_path):
    path = _write(tmp_path, FIG02.replace("eps: 0.1", "eps: -0.1"))
    with pytest.raises(SceneError, match=r"parameters\.eps: -0\.1 is less than or equal to the minimum of 0"):
        load_scene(path, SCHEMA)


@pytest.mark.parametrize("text", ["id: [unclosed\n", "- a list\n", "", "id: a\nid: b\n"],
                         ids=["malformed", "list", "empty", "duplicate-key"])
def test_unreadable_yaml_names_file(tmp_path, text):
    path = _write(tmp_path, text)
    with pytest.raises(SceneError, match=str(path)):
        load_scene(path, SCHEMA)


def test_id_must_match_file_name(tmp_path):
    path = _write(tmp_path, FIG02, name="fig02_other")
    with pytest.raises(SceneError, match="id: 'fig02_cases' does not match"):
        load_scene(path, SCHEMA)


def test_s0_range_must_be_ordered(tmp_path):
    text = (ROOT / "config" / "scenes" / "fig08_s0theta.yaml").read_text()
    path = _write(tmp_path, text.replace("theta_min: -5.0", "theta_min: -0.0005"), "fig08_s0theta")
    with pytest.raises(SceneError, match="parameters.theta_min"):
        load_scene(path, SCHEMA)


def test_a_scene_brings_its_own_parameter_block(tmp_path, monkeypatch):
    # fig04's parameters are closed by PARAMETERS_SCHEMA in its module
    # (filippov_paper.scenes.fig04_retmaps), not by a block in the shared schema: a typo there
    # is named, and a block that is not a literal is named as such
    import filippov_paper.config as config
    text = (ROOT / "config" / "scenes" / "fig04_retmaps.yaml").read_text()
    assert "closest:" in text
    path = _write(tmp_path, text.replace("closest:", "closets:"), "fig04_retmaps")
    with pytest.raises(SceneError, match=r"fig04_retmaps.yaml: parameters: .*closets"):
        load_scene(path, SCHEMA)
    modules = tmp_path / "modules"
    modules.mkdir()
    (modules / "fig04_retmaps.py").write_text("PARAMETERS_SCHEMA = dict(properties={})\n")
    monkeypatch.setattr(config, "SCENE_MODULES", modules)
    with pytest.raises(SceneError, match=r"fig04_retmaps.py: PARAMETERS_SCHEMA \(line 1\): "
                                         "must be a literal dict"):
        load_scene(_write(tmp_path, text, "fig04_retmaps"), SCHEMA)
    # a scene module without a block: only the shared schema checks the parameters
    (modules / "fig04_retmaps.py").write_text("X = 1\n")
    path = _write(tmp_path, text.replace("closest:", "closets:"), "fig04_retmaps")
    assert "closets" in load_scene(path, SCHEMA)["parameters"]


def test_every_scene_module_declares_a_readable_block():
    # read without importing (config.scene_schema_block) and equal to what the
    # imported module holds
    import importlib

    from filippov_paper import product
    from filippov_paper.config import scene_schema_block
    from filippov_paper.scenes import known_scenes
    blocks = 0
    for sid in known_scenes():
        block = scene_schema_block(sid)
        module = importlib.import_module(f"filippov_paper.scenes.{sid}")
        assert block == product.hook(module, "PARAMETERS_SCHEMA", None), sid
        blocks += block is not None
    assert blocks >= 10


def test_a_named_resolution_overrides_parameters_and_chunks(tmp_path):
    # --config resolution=full: the scene's resolutions.full block applied (and checked);
    # a scene without that block builds its default; the default drops the blocks
    path = ROOT / "config" / "scenes" / "fig12_period_adding.yaml"
    default = load_scene(path, SCHEMA)
    full = load_scene(path, SCHEMA, resolution="full")
    assert "resolutions" not in default and "resolution" not in default
    assert full["resolution"] == "full" and full["chunks"] > default["chunks"]
    assert full["parameters"]["n_mu"] > default["parameters"]["n_mu"]
    assert full["parameters"]["eps"] == default["parameters"]["eps"]
    plain = ROOT / "config" / "scenes" / "fig08_s0theta.yaml"
    assert load_scene(plain, SCHEMA, resolution="full") == load_scene(plain, SCHEMA)
    bad = tmp_path / "fig12_period_adding.yaml"
    bad.write_text(path.read_text().replace("n_mu: 1801", "n_mu: 1"))
    load_scene(bad, SCHEMA)  # the default is untouched
    with pytest.raises(SceneError, match=r"resolutions\.full: parameters\.n_mu"):
        load_scene(bad, SCHEMA, resolution="full")


def test_the_compute_hash_leaves_out_exactly_the_report_part():
    # the workflow hashes each scene module without its report part for the compute jobs
    # (workflow/rules/common.smk, strip_reports): editing the report changes nothing
    # there, editing the computation does, and the computation uses no report name (or
    # the hash would miss code it runs)
    import ast

    from filippov_paper.config import SCENE_MODULES, is_report_part, without_report_part
    from filippov_paper.scenes import known_scenes
    for sid in known_scenes():
        text = (SCENE_MODULES / f"{sid}.py").read_text()
        kept = without_report_part(text)
        tree = ast.parse(kept)
        defined = {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
        assert "report" not in defined and "def report(" in text, sid
        used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        assert not {u for u in used if is_report_part(u)}, sid
        edited = text.replace("def report(ds, m: Macros)", "def report(ds, m: Macros):  # x\n"
                              "    pass\n\n\ndef _report_unused(ds, m: Macros)")
        assert edited != text and without_report_part(edited) == kept, sid
        assert without_report_part(text + "\nX_NEW = 1\n") != kept, sid
    rules = (ROOT / "workflow" / "rules" / "compute.smk").read_text()
    assert rules.count("library_hash(exclude=NOT_COMPUTE, strip_reports=True)") == 3


def test_the_benchmark_hash_leaves_out_exactly_the_report_part():
    # the same for a benchmark's report part (REPORT, report, _report_*): the jobs that
    # run the benchmark hash its module without it (strip_reports covers benchmarks/), so
    # editing the work-precision table does not rerun the sweep of the default build
    import ast

    from filippov_paper import product
    from filippov_paper.config import is_report_part, without_report_part
    folder = ROOT / "workflow" / "filippov_paper" / "benchmarks"
    assert product.report_benchmarks()
    for name in product.report_benchmarks():
        text = (folder / f"{name}.py").read_text()
        kept = without_report_part(text)
        tree = ast.parse(kept)
        defined = {t.id for n in tree.body if isinstance(n, ast.Assign) for t in n.targets
                   if isinstance(t, ast.Name)}
        defined |= {n.name for n in tree.body if isinstance(n, ast.FunctionDef)}
        assert "report" not in defined and "REPORT" not in defined and "main" in defined, name
        used = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
        assert not {u for u in used if is_report_part(u)}, name
        edited = text.replace("def report(ds, m: Macros)", "def report(ds, m: Macros):  # x\n"
                              "    pass\n\n\ndef _report_unused(ds, m: Macros)")
        assert edited != text and without_report_part(edited) == kept, name
    rules = (ROOT / "workflow" / "rules" / "common.smk").read_text()
    assert 'rel.startswith(("scenes/", "benchmarks/"))' in rules
    assert 'rel == "hard_cases.py"' in rules
    # and the hard-case sweep's (REPORT, report, _report_*)
    text = (ROOT / "workflow" / "filippov_paper" / "hard_cases.py").read_text()
    kept = without_report_part(text)
    names = {n.id for n in ast.walk(ast.parse(kept)) if isinstance(n, ast.Name)}
    names |= {n.name for n in ast.parse(kept).body if isinstance(n, ast.FunctionDef)}
    assert "def report(" in text and "sweep" in names
    assert not {u for u in names if is_report_part(u)}, names


# the parameters that several scenes share are declared once in the scene schema's $defs
# (attractor_sweep, pdm_sweep, friction_law) and referenced by each scene's block; a name
# a block does not list is refused by its propertyNames
@pytest.mark.parametrize("sid,old,new,message", [
    ("fig12_period_adding", "  n_mu: 181", "  n_muu: 181", r"parameters: 'n_muu' is not one of"),
    ("fig14_atlas", "  n_keep: 40", "  n_keep: 1",
     r"parameters\.n_keep: 1 is less than the minimum of 2"),
    ("fig11_dfo_retmaps", "  gamma: 2.0", "  gama: 2.0", r"parameters: 'gama' is not one of"),
    ("fig10_dfo", "  fv: 0.3", "  fv: -0.3", r"parameters\.fv: -0\.3 is less than the minimum of 0"),
    ("fig07_pdm_theta_neg", "  closest: 1.0e-8", "  closest: 0.0",
     r"parameters\.closest: 0\.0 is less than or equal to the minimum of 0"),
    ("fig09_pdm_theta_pos", "  closest: 1.0e-3", "  closest: 1.0e-3\n  extra: 1",
     r"parameters: 'extra' is not one of"),
], ids=["fig12-misspelt", "fig14-shared-bound", "fig11-misspelt", "fig10-shared-bound",
        "fig07-shared-bound", "fig09-unknown"])
def test_shared_parameters_are_checked_and_named(tmp_path, sid, old, new, message):
    text = (ROOT / "config" / "scenes" / f"{sid}.yaml").read_text()
    assert old in text
    path = _write(tmp_path, text.replace(old, new, 1), name=sid)
    with pytest.raises(SceneError, match=rf"^{path}: {message}"):
        load_scene(path, SCHEMA)


def test_the_documented_full_resolution_command_passes_the_limits():
    # docs/pipeline.md gives the command for the fine grids; every scene must load at
    # resolution=full within the limits that command sets (fig14's atlas is over the
    # default max_points: without the raise the documented command stops at planning)
    import re
    import shlex

    from filippov_paper.config import limits
    doc = (ROOT / "docs" / "pipeline.md").read_text(encoding="utf-8")
    line = next(ln for ln in doc.splitlines() if "--config resolution=full" in ln)
    words = shlex.split(line.split("#")[0])
    pairs = words[words.index("--config") + 1:]
    overrides = dict(w.split("=", 1) for w in pairs if re.fullmatch(r"\w+=\S+", w))
    assert overrides.pop("resolution") == "full"
    # a local build runs each split sweep as one job (config.yaml sweep_jobs: 1): the
    # fine grids are only spread over the cores with their scenes' chunks
    assert overrides.pop("sweep_jobs") == "scene"
    lim = limits(overrides)
    for path in SCENES:
        scene = load_scene(path, SCHEMA, lim, resolution="full")
        assert scene["id"] == path.stem
    with pytest.raises(SceneError, match="max_points"):  # and the raise is needed
        load_scene(ROOT / "config" / "scenes" / "fig14_atlas.yaml", SCHEMA, resolution="full")
