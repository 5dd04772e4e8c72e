"""Small helpers shared by scene modules: solver options and ingredient checks."""
from __future__ import annotations

import inspect

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


def model_problems(protocol: type, model) -> list[str]:
    """What the model module ``model`` lacks of ``protocol`` (a :class:`typing.Protocol`
    a scene module declares as ``MODEL``: the names it uses of its model): each member
    missing, not a function, or a function that does not take the protocol's arguments
    (bound as the protocol writes them: positional, then keyword-only). Empty: it fits."""
    problems = []
    for name, wanted in _protocol_members(protocol).items():
        have = getattr(model, name, _ABSENT)
        if have is _ABSENT:
            problems.append(f"no {name}")
        elif inspect.isfunction(wanted) and not callable(have):
            problems.append(f"{name} is not a function")
        elif inspect.isfunction(wanted) and not _takes(have, wanted):
            problems.append(f"{name} does not take {name}{_arguments(wanted)}")
    return problems


_ABSENT = object()


def _protocol_members(protocol: type) -> dict:
    """{name: the protocol's function, or None for a declared value} over its bases."""
    members = {}
    for cls in reversed(protocol.__mro__):
        if cls is object or cls.__module__ == "typing":
            continue
        members.update({n: None for n in vars(cls).get("__annotations__", {})})
        members.update({n: v for n, v in vars(cls).items() if inspect.isfunction(v)})
    return {n: v for n, v in members.items() if not n.startswith("_")}


def _parameters(wanted):
    return list(inspect.signature(wanted).parameters.values())[1:]   # without self


def _arguments(wanted) -> str:
    """The protocol function's arguments as the error names them: ``(a, b, c=)``."""
    names = (p.name + "=" if p.kind == p.KEYWORD_ONLY else p.name for p in _parameters(wanted))
    return f"({', '.join(names)})"


def _takes(function, wanted) -> bool:
    params = _parameters(wanted)
    args = [p.name for p in params if p.kind in (p.POSITIONAL_ONLY, p.POSITIONAL_OR_KEYWORD)]
    kwargs = {p.name: None for p in params if p.kind == p.KEYWORD_ONLY}
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):   # no signature to read (a builtin): trust the name
        return True
    try:
        signature.bind(*args, **kwargs)
    except TypeError:
        return False
    return True
