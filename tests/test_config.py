"""Scene files: valid ones load; each kind of mistake names the file and field."""
from pathlib import Path

import pytest

from filippov.config import SceneError, load_scene

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


def test_a_scene_brings_its_own_parameter_block(tmp_path):
    # fig04's parameters are closed by config/schema/scenes/fig04_retmaps.schema.json,
    # not by a block in the shared schema: a typo there is named, and a broken block
    # file is named as such
    import shutil
    text = (ROOT / "config" / "scenes" / "fig04_retmaps.yaml").read_text()
    assert "closest:" in text
    path = _write(tmp_path, text.replace("closest:", "closets:"), "fig04_retmaps")
    with pytest.raises(SceneError, match=r"fig04_retmaps.yaml: parameters: .*closets"):
        load_scene(path, SCHEMA)
    schema_dir = tmp_path / "schema"
    shutil.copytree(SCHEMA.parent, schema_dir)
    (schema_dir / "scenes" / "fig04_retmaps.schema.json").write_text("{not json")
    with pytest.raises(SceneError, match=r"fig04_retmaps.schema.json: cannot read"):
        load_scene(_write(tmp_path, text, "fig04_retmaps"), schema_dir / "scene.schema.json")


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
    (tmp_path / "scenes").mkdir()
    own = ROOT / "config" / "schema" / "scenes" / "fig12_period_adding.schema.json"
    schema_dir = tmp_path / "schema"
    (schema_dir / "scenes").mkdir(parents=True)
    (schema_dir / "scene.schema.json").write_text(SCHEMA.read_text())
    (schema_dir / "scenes" / own.name).write_text(own.read_text())
    load_scene(bad, schema_dir / "scene.schema.json")  # the default is untouched
    with pytest.raises(SceneError, match=r"resolutions\.full: parameters\.n_mu"):
        load_scene(bad, schema_dir / "scene.schema.json", resolution="full")
