"""Small helpers shared by scene modules: solver options and ingredient checks."""
from __future__ import annotations

SOLVER_DEFAULTS = {"rtol": 1e-12, "atol": 1e-14}


def solver_options(scene: dict) -> dict:
    opts = dict(SOLVER_DEFAULTS)
    opts.update(scene.get("solver", {}))
    opts["method"] = "exact" if scene["ingredients"]["flow"] == "exact" else "integrate"
    return opts


def require(scene: dict, field: str, allowed) -> str:
    """The ingredient ``field``; a scene asking for something this figure cannot do fails."""
    value = scene["ingredients"][field]
    if value not in allowed:
        raise ValueError(f"{scene['id']}: ingredients.{field}: {value!r} not supported here; "
                         f"expected one of {sorted(map(str, allowed))}")
    return value
