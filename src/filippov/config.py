"""Loading and validating scene files (config/scenes/<id>.yaml).

A scene is data; a bad scene must fail before any numerics run, with a message
that names the file and the offending field (e.g. ``parameters.eps``).
No Snakemake here: the workflow's scripts call `load_scene`.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path

import yaml
from jsonschema import Draft202012Validator
from jsonschema.exceptions import best_match, by_relevance


class SceneError(ValueError):
    """A scene file is unreadable or violates the schema."""


class _Loader(yaml.SafeLoader):
    """SafeLoader that (i) rejects duplicate keys, which PyYAML would silently
    overwrite, and (ii) reads `1e-12` as a float (YAML 1.1 wants `1.0e-12`)."""


def _no_duplicates(loader, node, deep=False):
    seen = set()
    for key_node, _ in node.value:
        key = loader.construct_object(key_node, deep=deep)
        if key in seen:
            raise yaml.constructor.ConstructorError(
                None, None, f"duplicate key {key!r}", key_node.start_mark)
        seen.add(key)
    return loader.construct_mapping(node, deep=deep)


_Loader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _no_duplicates)
_Loader.add_implicit_resolver(
    "tag:yaml.org,2002:float",
    re.compile(r"^[-+]?(?:[0-9][0-9_]*)(?:\.[0-9_]*)?[eE][-+]?[0-9]+$"),
    list("-+0123456789"))

# When a typo'd key also makes a required key "missing", report the typo.
_RELEVANCE = by_relevance(strong=frozenset({"additionalProperties"}))


def _field(path) -> str:
    return ".".join(str(p) for p in path) or "(top level)"


def _non_finite(node, path=()):
    """First path to a NaN/inf: the schema's bounds do not reject them."""
    if isinstance(node, float) and not math.isfinite(node):
        return path
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, val in items:
        hit = _non_finite(val, path + (key,))
        if hit is not None:
            return hit
    return None


def load_scene(path, schema_path) -> dict:
    """Read a scene, validate it against the JSON schema and return it as a dict."""
    path = Path(path)
    try:
        with path.open(encoding="utf-8") as stream:  # a stream: YAML errors then cite the file
            scene = yaml.load(stream, Loader=_Loader)
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise SceneError(f"{path}: cannot read scene: {exc}") from exc
    if not isinstance(scene, dict):
        got = "an empty file" if scene is None else f"a {type(scene).__name__}"
        raise SceneError(f"{path}: a scene must be a YAML mapping, got {got}")

    schema = json.loads(Path(schema_path).read_text(encoding="utf-8"))
    error = best_match(Draft202012Validator(schema).iter_errors(scene), key=_RELEVANCE)
    if error is not None:
        raise SceneError(f"{path}: {_field(error.absolute_path)}: {error.message}")

    bad = _non_finite(scene)
    if bad is not None:
        raise SceneError(f"{path}: {_field(bad)}: must be finite")
    # Cross-field checks a JSON schema cannot express.
    if scene["id"] != path.stem:
        raise SceneError(f"{path}: id: {scene['id']!r} does not match the file name {path.stem!r}")
    params = scene["parameters"]
    if scene["model"] == "s0_closed_form" and not params["theta_min"] < params["theta_max"]:
        raise SceneError(f"{path}: parameters.theta_min: must be less than theta_max "
                         f"({params['theta_min']} >= {params['theta_max']})")
    return scene
