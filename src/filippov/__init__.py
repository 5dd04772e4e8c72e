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


# the public system types: FilippovSystem (one numeric definition, both engines) and
# its symbolic front-end SymbolicSystem (SymbolicSystem.slow_fast for a slow-fast model).
# What the engines run is built from them and stays importable, not exported:
# PiecewiseSystem (filippov.system, the reference driver's batch form, also written by
# hand for the reference engine alone), SlowFastModel (filippov.model), CompiledModel,
# compile_system and with_section (filippov.abi, filippov.compiled_system: the kernel's
# model with its section), SymbolicSlowFast (filippov.symbolic).
__all__ = [
    "FilippovSystem", "SymbolicSystem",
    "simulate", "Section", "first_returns", "fixed_points", "periodic_orbit", "PeriodicOrbit",
    "compute_returns", "sweep_returns",
    "transition_matrix", "return_jacobian", "monodromy", "floquet_multipliers",
    "SimulationError", "ZenoError", "EventLimitError", "SystemContractError",
    "ContinuationError", "VariationalError", "PeriodicOrbitError",
    "MINUS", "PLUS", "SLIDING", "__version__",
]
