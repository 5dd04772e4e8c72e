"""Loading and validating scene files (config/scenes/<id>.yaml).

A scene is data; a bad scene must fail before any numerics run, with a message
that names the file and the offending field (e.g. ``parameters.eps``).
No Snakemake here: the workflow's scripts call `load_scene`.
"""
from __future__ import annotations

import ast
import importlib.util
import json
import math
import pkgutil
import re
from pathlib import Path

import yaml
from jsonschema import Draft202012Validator
from jsonschema.exceptions import best_match, by_relevance


class SceneError(ValueError):
    """A scene file is unreadable, violates the schema or exceeds a limit."""


#: what one scene may ask for unless the run raises the limit explicitly
#: (snakemake --config max_points=1000000): the sweep's size (start points,
#: grid points), the samples stored, the jobs it is split into, the simulated time
LIMITS = {"max_points": 200_000, "max_samples": 20_000_000, "max_chunks": 512,
          "max_t_end": 1.0e4}


def limits(overrides=None) -> dict:
    """:data:`LIMITS` with the run's overrides (any mapping holding some of its keys,
    e.g. Snakemake's ``config``); a malformed override is a :class:`SceneError`."""
    out = dict(LIMITS)
    for key in LIMITS:
        if overrides is None or key not in overrides:
            continue
        value = overrides[key]
        try:
            value = float(value)
        except (TypeError, ValueError):
            value = math.nan
        if not (math.isfinite(value) and value > 0):
            raise SceneError(f"--config {key}: must be a positive number, got {overrides[key]!r}")
        out[key] = value
    return out


def _is_time(key: str) -> bool:
    return key == "t_end" or key.endswith("_t_end") or key == "t_max"


def sweep_size(scene: dict) -> dict:
    """A cheap upper estimate of what a scene computes, from its parameters alone:
    ``points`` = (sum of the counts ``n_*``) x (product of the lengths of its lists),
    ``samples`` likewise with ``n_samples`` alone, and the longest simulated time."""
    params = scene.get("parameters", {})
    counts = [v for k, v in params.items() if k.startswith("n_") and isinstance(v, int)]
    lists = [len(v) for v in params.values() if isinstance(v, list)]
    factor = math.prod(lists) if lists else 1
    t_end = [float(v) for k, v in params.items()
             if _is_time(k) and isinstance(v, (int, float)) and not isinstance(v, bool)]
    return {"points": max(sum(counts), 1) * factor,
            "samples": int(params.get("n_samples", 0) or 0) * factor,
            "t_end": max(t_end, default=0.0)}


def check_limits(scene: dict, lim: dict | None = None, path="scene") -> None:
    """Refuse a scene that asks for more than the limits allow, naming the field and
    the limit (and how to raise it). Cheap: runs while Snakemake plans the jobs."""
    lim = limits() if lim is None else lim
    size = sweep_size(scene)
    params = scene.get("parameters", {})
    raise_it = "raise it with snakemake --config {key}=<value> for a real large run"
    if size["points"] > lim["max_points"]:
        biggest = max((k for k in params if k.startswith("n_") and isinstance(params[k], int)),
                      key=lambda k: params[k], default="n_*")
        raise SceneError(f"{path}: parameters.{biggest}: the sweep has ~{size['points']:.3g} "
                         f"points, over the limit max_points = {lim['max_points']:.6g}; "
                         + raise_it.format(key="max_points"))
    if size["samples"] > lim["max_samples"]:
        raise SceneError(f"{path}: parameters.n_samples: ~{size['samples']:.3g} samples, over "
                         f"the limit max_samples = {lim['max_samples']:.6g}; "
                         + raise_it.format(key="max_samples"))
    if size["t_end"] > lim["max_t_end"]:
        key = next(k for k in params if _is_time(k) and params[k] == size["t_end"])
        raise SceneError(f"{path}: parameters.{key}: {size['t_end']:g} over the limit "
                         f"max_t_end = {lim['max_t_end']:g}; " + raise_it.format(key="max_t_end"))
    chunks = scene.get("chunks")
    if isinstance(chunks, int) and not isinstance(chunks, bool):
        if chunks > lim["max_chunks"]:
            raise SceneError(f"{path}: chunks: {chunks} jobs, over the limit max_chunks = "
                             f"{lim['max_chunks']:.6g}; " + raise_it.format(key="max_chunks"))
        if chunks > size["points"]:
            raise SceneError(f"{path}: chunks: {chunks} chunks for a sweep of at most "
                             f"{size['points']} points; need chunks <= the grid size")


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
_BY_RELEVANCE = by_relevance(strong=frozenset({"additionalProperties"}))


def _RELEVANCE(error):
    """jsonschema's relevance, with a name a block does not allow (``additionalProperties``
    or ``propertyNames``: the latter reports as the ``enum`` it descends into) first: a
    misspelt key is named rather than the required key it stands in for."""
    *head, strong, matches_type = _BY_RELEVANCE(error)
    return (*head, strong or "propertyNames" in error.schema_path, matches_type)


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


def load_workflow_config(path, schema_path, overrides=None) -> dict:
    """config/config.yaml, validated against its schema, with the command line's
    ``--config`` values (``overrides``) taking precedence. A malformed file or
    value is a :class:`SceneError` naming the file and line/column or field."""
    path = Path(path)
    try:
        with path.open(encoding="utf-8") as stream:
            data = yaml.load(stream, Loader=_Loader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = f"line {mark.line + 1}, column {mark.column + 1}: " if mark else ""
        problem = getattr(exc, "problem", None) or str(exc)
        raise SceneError(f"{path}: {where}{problem}") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise SceneError(f"{path}: cannot read: {exc}") from None
    if not isinstance(data, dict):
        raise SceneError(f"{path}: must be a YAML mapping")
    merged = {**data, **dict(overrides or {})}
    schema = json.loads(Path(schema_path).read_text(encoding="utf-8"))
    error = best_match(Draft202012Validator(schema).iter_errors(merged), key=_RELEVANCE)
    if error is not None:
        raise SceneError(f"{path}: {_field(error.absolute_path)}: {error.message}")
    # the scenes are the files in scenes/ beside the config (a new figure is its file;
    # no list to update); `scenes:` in the config or on the command line picks some
    found = scene_files(path.parent / "scenes")
    if "scenes" not in merged:
        merged["scenes"] = found
    missing = [s for s in merged["scenes"] if s not in found]
    if missing:
        raise SceneError(f"{path}: scenes: no scene file {path.parent / 'scenes' / missing[0]}.yaml")
    return merged


def scene_files(folder) -> list[str]:
    """The scene ids of the ``<id>.yaml`` files in ``folder``, sorted."""
    return sorted(p.stem for p in Path(folder).glob("*.yaml"))


#: a scene id (the schema's pattern for ``id``): figNN_name
SCENE_ID = re.compile(r"fig[0-9]{2}_[a-z0-9_]+")


#: where the scene modules live: each may declare its block of the scene schema
SCENE_MODULES = Path(__file__).parent / "scenes"


def scene_schema_block(scene_id: str) -> dict | None:
    """The schema of a scene's own parameters: ``PARAMETERS_SCHEMA`` of its module
    ``filippov_paper.scenes.<id>`` (None when it has none: a scene whose model block says it
    all), read from the module's source without importing it (no numerics load to
    check a scene file). It is one more ``allOf`` entry of the scene schema, so
    ``#/$defs/...`` refer there."""
    from filippov_paper.product import literal

    path = SCENE_MODULES / f"{scene_id}.py"
    try:
        block = literal(path, "PARAMETERS_SCHEMA")
    except FileNotFoundError:
        return None  # an unknown id: filippov_paper.scenes names the known ones
    except (OSError, UnicodeDecodeError, SyntaxError) as exc:
        raise SceneError(f"{path}: cannot read the scene module: {exc}") from exc
    except ValueError as exc:  # names file and line
        raise SceneError(str(exc)) from None
    return block


def is_test_knob(name: str) -> bool:
    """A top-level name of a scene module that only the tests read (``TEST_*``, see
    :mod:`filippov_paper.product`): left out of the compute jobs' code hash too."""
    return name.startswith("TEST_")


def is_report_part(name: str) -> bool:
    """A top-level name of a scene or benchmark module that belongs to its report part
    (``report``, ``REPORT_OPTIONAL``, ``REPORT``, ``_report_*``, ``_REPORT_*``): what the
    reproduction report reads, and nothing a computation uses."""
    return name in ("report", "REPORT_OPTIONAL", "REPORT") or \
        name.startswith(("_report", "_REPORT"))


def without_report_part(source: str) -> str:
    """A scene module's source with the statements that define its report part (see
    :func:`is_report_part`), its test knobs (:func:`is_test_knob`) and blank lines taken
    out: what the workflow hashes for the compute jobs, so that editing the report
    rebuilds the report only, and editing a test knob nothing."""
    tree = ast.parse(source)
    lines = source.splitlines(keepends=True)
    drop = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names = [node.name]
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            names = [t.id for t in targets if isinstance(t, ast.Name)]
            if len(names) != len(targets):
                continue
        else:
            continue
        if names and all(is_report_part(n) or is_test_knob(n) for n in names):
            first = min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])])
            drop.update(range(first - 1, node.end_lineno))
    # blank lines go too: those between two parts taken out would otherwise remain
    return "".join(line for i, line in enumerate(lines) if i not in drop and line.strip())


#: the resolution a run asks for when it names none (snakemake --config resolution=full)
DEFAULT_RESOLUTION = "default"


def apply_resolution(scene: dict, resolution: str | None) -> dict:
    """The scene at ``resolution``: its ``resolutions.<name>`` block (``parameters``
    overrides, ``chunks``) applied, the ``resolutions`` key removed, and the name kept as
    ``resolution`` when it is not the default. A scene without a block for that name
    runs at its default (most figures have one resolution). Works on the raw mapping:
    no validation here (see :func:`load_scene`)."""
    out = {k: v for k, v in scene.items() if k != "resolutions"}
    name = resolution or DEFAULT_RESOLUTION
    blocks = scene.get("resolutions") if isinstance(scene.get("resolutions"), dict) else {}
    block = blocks.get(name) if name != DEFAULT_RESOLUTION else None
    if isinstance(block, dict):
        params = dict(out.get("parameters") or {})
        params.update(block.get("parameters") or {})
        out["parameters"] = params
        if "chunks" in block:
            out["chunks"] = block["chunks"]
        out["resolution"] = name
    return out


def model_names() -> list[str]:
    """The models of the registry :mod:`filippov.models` (its modules, as
    ``filippov.models.names()`` lists them), found without importing the library: checking
    a scene file loads no numerics."""
    spec = importlib.util.find_spec("filippov")
    if spec is None or not spec.submodule_search_locations:
        raise SceneError("model: the library filippov is not installed; cannot list its models")
    folder = Path(list(spec.submodule_search_locations)[0]) / "models"
    return sorted(m.name for m in pkgutil.iter_modules([str(folder)]) if not m.name.startswith("_"))


def check_model(scene: dict, path) -> None:
    """The scene's ``model`` names a registered model (else SceneError naming the field
    and the choices); a missing key is the schema's to report."""
    if "model" not in scene:
        return
    known = model_names()
    if scene["model"] not in known:
        raise SceneError(f"{path}: model: unknown model {scene['model']!r}; expected one of "
                         f"{', '.join(known)}")


def load_scene(path, schema_path, lim: dict | None = None,
               resolution: str | None = None) -> dict:
    """Read a scene, validate it against the JSON schema and the limits (``lim``,
    default :data:`LIMITS`) and return it as a dict, at ``resolution`` (its
    ``resolutions`` block of that name applied and validated again; see
    :func:`apply_resolution`)."""
    path = Path(path)
    try:
        with path.open(encoding="utf-8") as stream:  # a stream: YAML errors then cite the file
            scene = yaml.load(stream, Loader=_Loader)
    except (OSError, UnicodeDecodeError, yaml.YAMLError) as exc:
        raise SceneError(f"{path}: cannot read scene: {exc}") from exc
    if not isinstance(scene, dict):
        got = "an empty file" if scene is None else f"a {type(scene).__name__}"
        raise SceneError(f"{path}: a scene must be a YAML mapping, got {got}")

    check_model(scene, path)
    schema = json.loads(Path(schema_path).read_text(encoding="utf-8"))
    sid = scene.get("id")
    if isinstance(sid, str) and SCENE_ID.fullmatch(sid):  # the scene's own block, if any
        block = scene_schema_block(sid)
        if block is not None:
            schema["allOf"] = [*schema.get("allOf", []), block]
    error = best_match(Draft202012Validator(schema).iter_errors(scene), key=_RELEVANCE)
    if error is not None:
        raise SceneError(f"{path}: {_field(error.absolute_path)}: {error.message}")
    scene = apply_resolution(scene, resolution)
    if "resolution" in scene:  # the overrides must make a valid scene too
        error = best_match(Draft202012Validator(schema).iter_errors(scene), key=_RELEVANCE)
        if error is not None:
            raise SceneError(f"{path}: resolutions.{scene['resolution']}: "
                             f"{_field(error.absolute_path)}: {error.message}")

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
    check_limits(scene, lim, path)
    return scene
