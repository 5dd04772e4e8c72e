"""The paper's systems, one module each, discovered like the paper's scenes.

A model is a module of this package that declares ``NAME`` (equal to its module
name); a new system is a new module here, with no list to update: :func:`names`
finds the modules without importing them (cheap enough for checking a scene
file), :func:`get` imports the one asked for. A scene's ``model:`` key names one.
"""
from __future__ import annotations

import importlib
import pkgutil


def names() -> list[str]:
    """Every model's name (the modules of this package), sorted."""
    return sorted(m.name for m in pkgutil.iter_modules(__path__) if not m.name.startswith("_"))


def get(name: str):
    """The model module ``name``; an unknown name raises ValueError naming the ``model``
    field and the choices."""
    known = names()
    if name not in known:
        raise ValueError(f"model: unknown model {name!r}; expected one of {', '.join(known)}")
    module = importlib.import_module(f".{name}", __name__)
    if getattr(module, "NAME", None) != name:
        raise ValueError(f"model: the module filippov.models.{name} declares NAME = "
                         f"{getattr(module, 'NAME', None)!r}, not {name!r}")
    return module
