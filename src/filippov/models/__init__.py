"""The paper's systems, each a factory returning a model or a piecewise system.

A new system is a new module here; neither the solver nor the workflow changes.
"""
from . import hopf, planar_sketch, pseudo_equilibrium

REGISTRY = {
    "hopf": hopf,
    "planar_sketch": planar_sketch,
    "pseudo_equilibrium": pseudo_equilibrium,
}


def get(name: str):
    try:
        return REGISTRY[name]
    except KeyError:
        raise ValueError(f"unknown model {name!r}; known models: {', '.join(sorted(REGISTRY))}") from None
