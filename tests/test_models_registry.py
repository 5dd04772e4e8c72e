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


def _scene(name: str) -> dict:
    return load_scene(ROOT / "config" / "scenes" / f"{name}.yaml", SCHEMA)


@pytest.mark.parametrize("scene_id, other, lacking", [
    ("fig10_dfo", "hopf", r"no friction_branches; .*no hopf_speed"),
    ("fig11_dfo_retmaps", "hopf", r"no REGION_PLUS; .*no slow_manifold_plus"),
    ("fig05_thetalt0mfs", "dry_friction", r"no slow_manifold_minus"),
    ("fig12_period_adding", "dry_friction", r"no L1"),
    ("fig14_atlas", "pseudo_equilibrium", r"no L1"),
    # same name, other arguments: the planar sketch's system takes a case
    ("fig01_slidesketch", "hopf", r"system does not take system\(case\)"),
    ("fig08_s0theta", "sgraph_closed_form", r"no s0_lambert"),
])
def test_scene_refuses_a_registered_model_without_what_it_needs(scene_id, other, lacking):
    """A scene's model is the one its ``model:`` key names; one lacking what the scene
    module's MODEL protocol lists is refused before computing, naming ``model``."""
    from filippov_paper import scenes

    scene = _scene(scene_id)
    scenes.check(scene)        # its own model fits
    with pytest.raises(SceneError, match=rf"^{scene_id}: model: '{other}' does not have what "
                                         rf"this scene needs of its model \(\w+\): .*{lacking}"):
        scenes.check(dict(scene, model=other))


def test_scene_refuses_an_unknown_model_naming_the_field(tmp_path):
    from filippov_paper import scenes

    scene = _scene("fig10_dfo")
    with pytest.raises(SceneError,
                       match=r"^fig10_dfo: model: unknown model 'nope'; expected one of"):
        scenes.check(dict(scene, model="nope"))
    # and when the scene file is read
    src = ROOT / "config" / "scenes" / "fig12_period_adding.yaml"
    data = yaml.safe_load(src.read_text())
    data["model"] = "hopf2"
    bad = tmp_path / src.name
    bad.write_text(yaml.safe_dump(data))
    with pytest.raises(SceneError, match=r"model: unknown model 'hopf2'"):
        load_scene(bad, SCHEMA)


def test_generic_scene_follows_the_model_key(tmp_path, monkeypatch):
    """A scene that needs only what several models have works with each: fig02 needs
    model(eps, theta), which hopf has too; the module it computes with is the one the
    YAML names (a registered stand-in module proves it is looked up, not imported)."""
    import types

    from filippov_paper import scenes
    from filippov_paper.scenes import common

    scene = _scene("fig02_cases")
    scenes.check(dict(scene, model="hopf"))
    called = []
    stand_in = types.ModuleType("filippov.models.stand_in")
    stand_in.NAME = "stand_in"

    def model(eps, theta):
        called.append((eps, theta))
        raise RuntimeError("the stand-in was asked")

    stand_in.model = model
    monkeypatch.setattr(models, "names", lambda: ["hopf", "stand_in"])
    monkeypatch.setitem(__import__("sys").modules, "filippov.models.stand_in", stand_in)
    assert common.registered_model(dict(scene, model="stand_in")) is stand_in
    with pytest.raises(RuntimeError, match="the stand-in was asked"):
        scenes.compute(dict(scene, model="stand_in"))
    assert called and called[0][0] == scene["parameters"]["eps"]


def test_model_problems_reads_members_and_arguments():
    from typing import Protocol
    import types

    from filippov_paper.scenes.common import model_problems

    class Needs(Protocol):
        L: dict

        def f(self, a, b, *, c): ...

    ok = types.SimpleNamespace(L={}, f=lambda a, b, c=1, d=2: None)
    assert model_problems(Needs, ok) == []
    assert model_problems(Needs, types.SimpleNamespace(f=ok.f)) == ["no L"]
    assert model_problems(Needs, types.SimpleNamespace(L={}, f=1)) == ["f is not a function"]
    assert model_problems(Needs, types.SimpleNamespace(L={}, f=lambda a: None)) == \
        ["f does not take f(a, b, c=)"]


def _model_imports(path: Path) -> list[str]:
    """The imports of a model module (filippov.models.<name>) in a source file."""
    import ast

    found = []
    names = set(models.names())
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name.startswith("filippov.models.")]
        elif isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if module.startswith("filippov.models."):
                found.append(module)
            elif module in ("filippov.models", "models") or (node.level and module == ""):
                found += [f"filippov.models.{a.name}" for a in node.names if a.name in names]
    return found


def test_no_scene_module_imports_a_model():
    """Scenes take their model from the scene (registered_model), never by import."""
    folder = ROOT / "workflow" / "filippov_paper" / "scenes"
    paths = sorted(folder.glob("*.py"))
    assert len(paths) > 14
    assert {p.name: _model_imports(p) for p in paths if _model_imports(p)} == {}
    # the check can fail: it sees each spelling of such an import
    assert _model_imports_of_text(
        "import filippov.models.hopf\nfrom filippov.models import dry_friction as df\n"
        "from filippov.models.hopf import L1\nfrom filippov import models\n") == \
        ["filippov.models.hopf", "filippov.models.dry_friction", "filippov.models.hopf"]


def _model_imports_of_text(text: str) -> list[str]:
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "m.py"
        path.write_text(text)
        return _model_imports(path)
