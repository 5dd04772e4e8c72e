"""The models registry (filippov.models): every model discovered, named, and chosen by a
scene's ``model:`` key."""
from pathlib import Path

import pytest
import yaml

from filippov import models
from filippov_paper.config import SceneError, load_scene, model_names

ROOT = Path(__file__).resolve().parents[1]
SCENES = sorted((ROOT / "config" / "scenes").glob("*.yaml"))
SCHEMA = ROOT / "config" / "schema" / "scene.schema.json"


def test_every_model_module_is_registered_under_its_declared_name():
    found = models.names()
    assert {"hopf", "dry_friction", "pseudo_equilibrium", "planar_sketch", "s0_closed_form",
            "sgraph_closed_form"} <= set(found)
    for name in found:
        assert models.get(name).NAME == name
    # the scene check lists them without importing the library: the same list
    assert model_names() == found


def test_unknown_model_names_the_field_and_the_choices():
    with pytest.raises(ValueError, match=r"model: unknown model 'nope'; expected one of .*hopf"):
        models.get("nope")


@pytest.mark.parametrize("path", SCENES, ids=lambda p: p.stem)
def test_every_scene_model_resolves(path):
    from filippov_paper import scenes

    scene = load_scene(path, SCHEMA)
    assert models.get(scene["model"]).NAME == scene["model"]
    scenes.check(scene)     # and it is the model the scene's module computes with


def test_scene_with_unknown_model_is_refused(tmp_path):
    src = ROOT / "config" / "scenes" / "fig04_retmaps.yaml"
    data = yaml.safe_load(src.read_text())
    data["model"] = "hopff"
    bad = tmp_path / src.name
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(SceneError, match=r"model: unknown model 'hopff'; expected one of .*hopf"):
        load_scene(bad, SCHEMA)


def test_scene_module_computes_with_the_scene_model():
    """The dispatcher refuses a scene whose model is not the one its module computes with,
    and an unknown model, naming ``model``."""
    from filippov_paper import scenes

    scene = load_scene(ROOT / "config" / "scenes" / "fig10_dfo.yaml", SCHEMA)
    scenes.check(scene)        # dry_friction: the module's own
    with pytest.raises(SceneError, match=r"fig10_dfo: model: 'hopf', but the scene computes with dry_friction"):
        scenes.check(dict(scene, model="hopf"))
    with pytest.raises(SceneError, match=r"fig10_dfo: model: unknown model 'nope'"):
        scenes.check(dict(scene, model="nope"))
    # a module taking its model from the scene follows the key
    two = load_scene(ROOT / "config" / "scenes" / "fig02_cases.yaml", SCHEMA)
    scenes.check(two)
