"""Small helpers shared by scene modules: solver options and ingredient checks."""
from __future__ import annotations

SOLVER_DEFAULTS = {"rtol": 1e-12, "atol": 1e-14}


def solver_options(scene: dict) -> dict:
    """Options for :func:`filippov.simulate.simulate`: tolerances and the method
    the scene's ``flow`` ingredient asks for (the engine is chosen separately)."""
    opts = dict(SOLVER_DEFAULTS)
    opts.update({k: v for k, v in scene.get("solver", {}).items() if k != "engine"})
    opts["method"] = "exact" if scene["ingredients"]["flow"] == "exact" else "integrate"
    return opts


def engine(scene: dict) -> str:
    """``solver.engine``: "reference" (the reference driver, default) or "compiled"
    (the numba kernel of :mod:`filippov.fastmap`: exact flows where the scene
    asks for them, DOP853 inside the kernel where it asks for integration).
    Only scene modules that list "compiled" in their ``ENGINES`` accept it
    (checked by :func:`filippov_paper.scenes.compute`)."""
    return scene.get("solver", {}).get("engine", "reference")


def require(scene: dict, field: str, allowed) -> str:
    """The ingredient ``field``; a scene asking for something this figure cannot do fails."""
    value = scene["ingredients"][field]
    if value not in allowed:
        raise ValueError(f"{scene['id']}: ingredients.{field}: {value!r} not supported here; "
                         f"expected one of {sorted(map(str, allowed))}")
    return value


def registered_model(scene: dict):
    """The scene's model, from the registry by its ``model`` key (:func:`filippov.models.get`;
    an unknown name raises ValueError naming ``model`` and the choices)."""
    from filippov import models

    return models.get(scene["model"])
