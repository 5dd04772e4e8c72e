"""Scene computations: a validated scene dict in, an xarray Dataset out.

One module per figure. Each reads only the ingredients its scene declares (the
system kind, exact or integrated flows, sliding) and builds nothing else.
"""
from __future__ import annotations

import contextlib
import importlib
import json
import pkgutil

from filippov_paper import product, tolerance
from filippov_paper.config import SCENE_ID, SceneError
from filippov.errors import SlidingNotBuiltError
from filippov_paper.scenes import chunking
from filippov_paper.scenes.common import model_problems, registered_model



def known_scenes() -> list[str]:
    """The scene ids: every module of this package named like one (``figNN_name``).
    A new figure is a new module here; there is no registry to update."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if SCENE_ID.fullmatch(m.name))


def _module(scene: dict):
    sid = scene.get("id")
    known = known_scenes()
    if sid not in known:
        raise SceneError(f"id: unknown scene {sid!r}; known scenes: {', '.join(known)}")
    module = importlib.import_module(f".{sid}", __name__)
    _check_model(scene, module)
    # solver.engine: a scene runs on the engines its module lists (default: the reference driver)
    name = scene.get("solver", {}).get("engine", "reference")
    available = product.hook(module, "ENGINES", ("reference",))
    if name not in available:
        raise SceneError(f"{sid}: solver.engine: {name!r} not available for this scene; "
                         f"expected one of {list(available)}")
    return module


def _check_model(scene: dict, module) -> None:
    """The scene's ``model`` is a registered model (:func:`filippov.models.get`) that has
    what the scene module needs of it: the members of its ``MODEL`` protocol (see
    :func:`~filippov_paper.scenes.common.model_problems`). Scene modules take their model
    from the scene (:func:`~filippov_paper.scenes.common.registered_model`), never by
    importing one."""
    if "model" not in scene:   # a partial scene (the schema requires one of every scene file)
        return
    try:
        chosen = registered_model(scene)
    except ValueError as exc:
        raise SceneError(f"{scene.get('id')}: {exc}") from None
    protocol = product.hook(module, "MODEL")
    problems = model_problems(protocol, chosen)
    if problems:
        raise SceneError(f"{scene.get('id')}: model: {scene['model']!r} does not have what "
                         f"this scene needs of its model ({protocol.__name__}): "
                         f"{'; '.join(problems)}")


def check(scene: dict) -> None:
    """What only the scene's module can tell, before anything is computed: that it
    offers the engine the scene asks for, and that ``chunks`` does not exceed its
    grid. Raises :class:`~filippov_paper.config.SceneError` naming the field."""
    module = _module(scene)
    if product.has(module, "validate"):
        module.validate(chunking.without_layout(scene))
    if scene.get("chunks") is None:
        return
    module = _chunkable(scene)
    size = len(module.chunk_grid(chunking.without_layout(scene)))
    try:
        chunking.bounds(size, 0, chunking.n_chunks(scene))
    except ValueError as exc:
        raise SceneError(f"{scene.get('id')}: {exc}") from None


def _declared(module, scene, ds):
    """``ds`` with what the module declares about its variables: names and units
    (``VARIABLE_ATTRS``, {name: (long_name, units or None)}: every variable must
    end up with a long_name, every numeric one with units) and cross-machine
    tolerances (``tolerances(scene)`` when they follow the scene's eps or grid,
    else ``TOLERANCES``; see :mod:`filippov_paper.tolerance`)."""
    ds = describe(ds, product.hook(module, "VARIABLE_ATTRS", {}),
                  product.hook(module, "LATEX_NAMES", {}))
    declared = module.tolerances(scene) if product.has(module, "tolerances") else \
        product.hook(module, "TOLERANCES", {})
    return printed(tolerance.annotate(ds, declared))


#: attributes whose text is for readers (the paper's labels in them are replaced)
READER_ATTRS = ("title", "long_name", "equation", "comment", "description")
#: the keys of the scene file that ``scene_config`` (the scene as JSON) holds for readers:
#: the paper's figure the scene reproduces (a label in the scene file, the key the
#: captions look it up by) and the description; every other key stays as given
READER_SCENE_KEYS = ("paper_figure", "description")


def printed(ds, labels: dict | None = None):
    """``ds`` with the paper's LaTeX labels (``eq:ymm``, ``fig:retmaps``) in its
    titles, long names and equation attributes, and in the ``paper_figure`` and
    ``description`` of its ``scene_config``, replaced by the numbers the paper prints
    ("Eq. (18)", "Fig. 4"; paper/paper_labels.tex, :mod:`filippov_paper.paper_labels`):
    a reader of the netCDF file has the paper, not its source. (Chunks are not
    printed: :func:`chunking.merge` compares their ``scene_config`` with the scene file.)"""
    from filippov_paper.paper_labels import OUT
    from filippov_paper.report_html import cite, printed_labels

    labels = printed_labels(OUT) if labels is None else labels
    if not labels:
        return ds

    def scene_config(text):
        try:
            scene = json.loads(text)
        except ValueError:
            return text
        if not isinstance(scene, dict):
            return text
        for key in READER_SCENE_KEYS:
            if isinstance(scene.get(key), str):
                scene[key] = cite(scene[key], labels)
        return json.dumps(scene, sort_keys=True)

    def fix(attrs):
        out = {k: cite(v, labels) if k in READER_ATTRS and isinstance(v, str) else v
               for k, v in attrs.items()}
        if isinstance(out.get("scene_config"), str):
            out["scene_config"] = scene_config(out["scene_config"])
        return out

    ds = ds.copy()
    ds.attrs = fix(ds.attrs)
    for name in ds.variables:
        ds[name].attrs = fix(ds[name].attrs)
    return ds


def describe(ds, attrs: dict, latex: dict | None = None):
    """``ds`` with long_name/units from ``attrs`` and typeset meanings from ``latex``
    (``long_name_tex``, for the report); every variable must have a long_name and
    every numeric variable units afterwards (CF-1.8), or this is an error."""
    ds = ds.copy()
    for name, tex in (latex or {}).items():
        if name not in ds.variables:
            raise ValueError(f"LATEX_NAMES names {name!r}, which the dataset lacks")
        ds[name].attrs["long_name_tex"] = tex
    for name, (long_name, units) in attrs.items():
        if name not in ds.variables:
            raise ValueError(f"VARIABLE_ATTRS names {name!r}, which the dataset lacks")
        ds[name].attrs["long_name"] = long_name
        if units is not None:
            ds[name].attrs["units"] = units
    lacking = sorted(n for n in ds.variables if "long_name" not in ds[n].attrs
                     or (ds[n].dtype.kind in "fiub" and "units" not in ds[n].attrs))
    if lacking:
        raise ValueError(f"variables without long_name or units: {', '.join(lacking)}")
    return ds


@contextlib.contextmanager
def _in_scene_terms(scene: dict):
    """A system built without sliding that reached it, told also in the scene's words."""
    try:
        yield
    except SlidingNotBuiltError as exc:
        if scene.get("ingredients", {}).get("sliding") is False:
            raise type(exc)(f"{scene.get('id')}: {exc} (the scene sets ingredients.sliding: "
                            "false; set it to true to follow sliding)") from exc
        raise


def compute(scene: dict, *, progress: bool = False):
    # `chunks` (how to split the work, see .chunking) is not part of the result
    module = _module(scene)
    scene = chunking.without_layout(scene)
    with _in_scene_terms(scene):
        return _declared(module, scene, module.compute(scene, progress=progress))


def _chunkable(scene: dict):
    module = _module(scene)
    if not chunking.supports_chunks(module):
        raise SceneError(f"{scene.get('id')}: chunks: this scene cannot be split into chunks")
    return module


def compute_chunk(scene: dict, i: int, n: int | None = None, *, progress: bool = False):
    """Chunk ``i`` (0-based) of ``n`` (default: the scene's ``chunks``): raw results
    on part of the scene's grid; :func:`merge` of all chunks equals :func:`compute`."""
    n = chunking.n_chunks(scene) if n is None else n
    with _in_scene_terms(scene):
        return chunking.compute_chunk(_chunkable(scene), scene, i, n, progress=progress)


def merge(scene: dict, parts):
    """The scene's dataset from all its chunks (identical to :func:`compute`)."""
    module = _chunkable(scene)
    return _declared(module, scene, chunking.merge(module, scene, parts))
