"""What an engine runs for a system, and the engines' names: the views of a system
(:func:`reference_system`, :func:`compiled_model`), :func:`checked` and :func:`pick`
(a front door's choice among its own table of engines). Engine-free, at the bottom of
the library with :mod:`filippov.section` and :mod:`filippov.system`: the engines and the
front doors import it, it imports none of them (tests/test_import_graph.py)."""
from __future__ import annotations

import sys

from .contracts import CompiledView, ReferenceView, provides

#: the engines, by the name the front doors' ``engine=`` takes
REFERENCE, COMPILED = "reference", "compiled"
ENGINES = (REFERENCE, COMPILED)

#: why an engine lacks a front door's output (the front door's table holds None there)
LACKS = {
    ("simulate", COMPILED): (
        "the compiled engine has no trajectory output: it computes returns to a section "
        "(state, time, switches, sliding time), not the events, samples and dense output "
        "of a Trajectory; use engine='reference' for a trajectory, or "
        "first_returns(..., engine='compiled') for returns"),
}

_HOW_TO_COMPILE = (
    "build a filippov.FilippovSystem from plain functions of (z, p) (or a "
    "filippov.SymbolicSystem from SymPy expressions), which runs on both engines")


def checked(engine) -> str:
    """``engine`` if it names an engine, else a ValueError naming ``engine``."""
    if not (isinstance(engine, str) and engine in ENGINES):
        raise ValueError(f"engine must be one of {ENGINES}, got {engine!r}")
    return engine


def pick(table: dict, capability: str, engine):
    """The function of ``table`` (engine -> function, or None where the engine lacks
    ``capability``: the reason in :data:`LACKS`) that runs ``capability`` on ``engine``."""
    target = table[checked(engine)]
    if target is None:
        raise ValueError(f"engine={engine!r}: {capability} is not available on this "
                         f"engine: {LACKS[capability, engine]}")
    return target


def _is_compiled_model(system) -> bool:
    abi = sys.modules.get(f"{__package__}.abi")  # no CompiledModel without it imported
    return abi is not None and isinstance(system, abi.CompiledModel)


def reference_system(system, capability: str, several: bool = False):
    """The :class:`~filippov.system.PiecewiseSystem` the reference driver runs for
    ``system``: itself, or the ``python()`` view of a system defined once
    (:class:`~filippov.FilippovSystem`, :class:`~filippov.SymbolicSystem`); a
    :class:`~filippov.surfaces.SurfacesSystem` of one surface as one, of several as it
    is where the capability takes them (``several``), else refused by name."""
    from .surfaces import SurfacesSystem
    from .system import PiecewiseSystem

    if isinstance(system, PiecewiseSystem):
        return system
    if provides(system, ReferenceView) and not isinstance(system, SurfacesSystem):
        system = system.python()   # filippov.contracts; of several surfaces: checked below
    if isinstance(system, PiecewiseSystem):
        return system
    if isinstance(system, SurfacesSystem):
        if system.m == 1:
            return system.one_surface()
        if several:
            return system
        raise TypeError(f"system: {capability} does not take several switching surfaces "
                        f"yet (m = {system.m}); filippov.simulate runs them (engine="
                        "'reference')")
    if _is_compiled_model(system):
        raise TypeError(f"system: {capability}(engine='reference') cannot run a "
                        "CompiledModel (numba pieces for the compiled engine only); "
                        f"use engine='compiled', or {_HOW_TO_COMPILE}")
    raise TypeError(f"system: {capability} expected a PiecewiseSystem, a FilippovSystem, "
                    f"a SymbolicSystem or an object with python() (filippov.contracts."
                    f"ReferenceView), got {type(system).__name__}")


def compiled_model(system, capability: str, section=None, *, direction: int = 0,
                   where=None):
    """The :class:`~filippov.abi.CompiledModel` the compiled engine runs for ``system``
    with the section ``section(z, p) = 0`` (None: a CompiledModel's own section)."""
    from .surfaces import SurfacesSystem
    from .system import PiecewiseSystem

    if isinstance(system, SurfacesSystem):
        raise TypeError(f"system: {capability}(engine='compiled') cannot run a "
                        "SurfacesSystem: the compiled engine takes one switching surface; "
                        "filippov.simulate runs several (engine='reference')")
    if isinstance(system, PiecewiseSystem):
        raise TypeError(f"system: {capability}(engine='compiled') cannot run a "
                        "PiecewiseSystem (Python functions the compiled kernel cannot "
                        f"call); {_HOW_TO_COMPILE}, or use engine='reference'")
    if _is_compiled_model(system):
        if section is None:
            return system
        from .compiled_system import with_section

        return with_section(system, _section_function(section, capability),
                            direction=direction, where=where)
    if not provides(system, CompiledView):   # filippov.contracts
        raise TypeError(f"system: {capability}(engine='compiled') expected a "
                        f"FilippovSystem, a SymbolicSystem or a CompiledModel, got "
                        f"{type(system).__name__}")
    if section is None:
        raise TypeError(f"section: {capability}(engine='compiled') of a "
                        f"{type(system).__name__} needs a section s(z, p) -> float")
    return system.compiled(_section_function(section, capability), direction=direction,
                           where=where)


def _section_function(section, capability: str):
    from .section import Section

    if isinstance(section, Section):
        raise TypeError(f"section: {capability}(engine='compiled') takes the section as "
                        f"a function s(z, p) -> float (compiled with the system's "
                        f"pieces), not a Section of the reference driver")
    return section
