"""filippov: event-driven simulation of slow-fast Filippov systems.

The library knows numerics only: models, the event-driven solver, return maps,
the paper's closed forms, and datasets with provenance. It knows nothing of
Snakemake; the workflow calls it through thin scripts.
"""
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("filippov")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.1.0"

from .system import PiecewiseSystem, MINUS, PLUS, SLIDING
from .model import SlowFastModel
from .simulate import simulate, Section, SimulationError, ZenoError, EventLimitError
from .checks import SystemContractError
from .poincare import first_returns, fixed_points
from .continuation import monodromy, floquet_multipliers, ContinuationError
from .variational import transition_matrix, return_jacobian, VariationalError
from .periodic import periodic_orbit, PeriodicOrbit, PeriodicOrbitError

# the compiled engine (numba) and the symbolic front-end (sympy) are imported on first
# use, not by `import filippov`
_COMPILED = {"compile_system": "compiled_system", "with_section": "compiled_system",
             "FilippovSystem": "compiled_system",
             "SymbolicSystem": "symbolic", "SymbolicSlowFast": "symbolic",
             "CompiledModel": "abi", "compute_returns": "fastmap", "sweep_returns": "fastmap",
             "first_returns_compiled": "fastmap"}


def __getattr__(name):
    if name in _COMPILED:
        import importlib

        return getattr(importlib.import_module(f".{_COMPILED[name]}", __name__), name)
    raise AttributeError(f"module 'filippov' has no attribute {name!r}")


# the public system types: PiecewiseSystem (the reference engine's own), FilippovSystem
# (one numeric definition for both engines) and its symbolic front-ends. SlowFastModel
# (filippov.model) and CompiledModel (filippov.abi) are what a symbolic slow-fast model
# and FilippovSystem.compiled() build for an engine: still importable, not exported.
__all__ = [
    "PiecewiseSystem", "simulate", "Section",
    "SimulationError", "ZenoError", "EventLimitError", "SystemContractError",
    "first_returns", "fixed_points", "monodromy", "floquet_multipliers", "ContinuationError",
    "transition_matrix", "return_jacobian", "VariationalError",
    "periodic_orbit", "PeriodicOrbit", "PeriodicOrbitError",
    "FilippovSystem", "SymbolicSystem", "SymbolicSlowFast", "compile_system", "with_section",
    "compute_returns", "sweep_returns",
    "first_returns_compiled", "MINUS", "PLUS", "SLIDING", "__version__",
]
