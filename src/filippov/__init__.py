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

__all__ = [
    "PiecewiseSystem", "SlowFastModel", "simulate", "Section",
    "SimulationError", "ZenoError", "EventLimitError", "SystemContractError",
    "first_returns", "fixed_points", "monodromy", "floquet_multipliers", "ContinuationError",
    "transition_matrix", "return_jacobian", "VariationalError",
    "MINUS", "PLUS", "SLIDING", "__version__",
]
