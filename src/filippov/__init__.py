"""filippov: event-driven simulation of slow-fast Filippov systems.

The library knows numerics only: models, the event-driven solver, return maps,
the paper's closed forms, and datasets with provenance. It knows nothing of
Snakemake; the workflow calls it through thin scripts.
"""
import sys
import types
from importlib.metadata import PackageNotFoundError, version as _version

try:
    __version__ = _version("filippov")
except PackageNotFoundError:  # running from a source tree without install
    __version__ = "0.1.0"

# Every name is imported on first use, not by `import filippov`: a job that only reads a
# dataset (filippov.io) or draws one does not pay for scipy's integrators (0.4 s of CPU a
# process), nor for the compiled engine (numba) and the symbolic front-end (SymPy)
_LAZY = {
    "PiecewiseSystem": "system", "MINUS": "system", "PLUS": "system", "SLIDING": "system",
    "SlowFastModel": "model",
    "SurfacesSystem": "surfaces", "SurfacesError": "errors",
    "Section": "simulate", "SimulationError": "simulate",
    "ZenoError": "simulate", "EventLimitError": "simulate",
    "SystemContractError": "checks",
    "first_returns": "poincare", "fixed_points": "poincare",
    "monodromy": "continuation", "floquet_multipliers": "continuation",
    "ContinuationError": "continuation",
    "transition_matrix": "variational", "return_jacobian": "variational",
    "VariationalError": "variational",
    "periodic_orbit": "periodic", "PeriodicOrbit": "periodic",
    "PeriodicOrbitError": "periodic",
    "compile_system": "compiled_system", "with_section": "compiled_system",
    "FilippovSystem": "compiled_system",
    "SymbolicSystem": "symbolic", "SymbolicSlowFast": "symbolic",
    "CompiledModel": "abi", "compute_returns": "fastmap", "sweep_returns": "fastmap",
    "first_returns_compiled": "fastmap"}


def __getattr__(name):
    if name in _LAZY:
        import importlib

        value = getattr(importlib.import_module(f".{_LAZY[name]}", __name__), name)
        globals()[name] = value   # looked up once
        return value
    raise AttributeError(f"module 'filippov' has no attribute {name!r}")


# the public system types: FilippovSystem (one numeric definition, both engines) and
# its symbolic front-end SymbolicSystem (SymbolicSystem.slow_fast for a slow-fast model).
# What the engines run is built from them and stays importable, not exported:
# PiecewiseSystem (filippov.system, the reference driver's batch form, also written by
# hand for the reference engine alone), SlowFastModel (filippov.model), CompiledModel,
# compile_system and with_section (filippov.abi, filippov.compiled_system: the kernel's
# model with its section), SymbolicSlowFast (filippov.symbolic), SurfacesSystem
# (filippov.surfaces: several switching surfaces with NumPy pieces, the reference engine).
__all__ = [
    "FilippovSystem", "SymbolicSystem",
    "simulate", "Section", "first_returns", "fixed_points", "periodic_orbit", "PeriodicOrbit",
    "compute_returns", "sweep_returns",
    "transition_matrix", "return_jacobian", "monodromy", "floquet_multipliers",
    "SimulationError", "ZenoError", "EventLimitError", "SystemContractError",
    "ContinuationError", "VariationalError", "PeriodicOrbitError", "SurfacesError",
    "MINUS", "PLUS", "SLIDING", "__version__",
]


def __dir__():
    return sorted(set(globals()) | set(_LAZY) | {"simulate"})


class _Package(types.ModuleType):
    """The package, whose ``simulate`` is the function: the submodule of the same name,
    once imported, is bound here by the import system (which set it after ``from
    .simulate import simulate`` ran when that was eager); it stays in sys.modules."""

    @property
    def simulate(self):
        from .simulate import simulate

        return simulate

    @simulate.setter
    def simulate(self, value):
        pass


sys.modules[__name__].__class__ = _Package
