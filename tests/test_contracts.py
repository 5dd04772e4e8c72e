"""The contracts between the library's parts as types (issue 58; filippov.contracts): every
implementation in the library keeps the Protocol it is run through, member by member and
parameter by parameter, and a class that breaks one is named with what it lacks."""
import numpy as np
import pytest

from filippov import FilippovSystem, SymbolicSystem
from filippov.contracts import (CompiledView, DefinedOnce, ModelModule, ReferenceSystem,
                                ReferenceView, WithJacobians, missing, provides)
from filippov.models import dry_friction, hopf, pseudo_equilibrium


def _defined_once():
    f = lambda z, p: -z  # noqa: E731
    return FilippovSystem(("x",), f, f, lambda z, p: z[0], lambda z, p: np.ones(1))


def _generated():
    import sympy as sp

    x = sp.Symbol("x")
    return SymbolicSystem([x], [-x], [-x], x).system()


def _symbolic():
    import sympy as sp

    x = sp.Symbol("x")
    return SymbolicSystem([x], [-x], [-x], x)


@pytest.mark.parametrize("build", [_defined_once, _generated, _symbolic,
                                   lambda: hopf.system(1e-2, 0.2),
                                   lambda: dry_friction.system(1e-2, 1.5)],
                         ids=["FilippovSystem", "SymbolicSystem.system", "SymbolicSystem",
                              "hopf", "dry_friction"])
def test_every_system_defined_once_keeps_its_contract(build):
    system = build()
    assert missing(system, DefinedOnce) == [] and missing(system, WithJacobians) == []
    assert isinstance(system, DefinedOnce) and provides(system, DefinedOnce)
    view = system.python()
    assert missing(view, ReferenceSystem) == [] and isinstance(view, ReferenceSystem)


@pytest.mark.parametrize("module", [hopf, dry_friction, pseudo_equilibrium],
                         ids=lambda m: m.__name__)
def test_every_model_module_keeps_its_contract(module):
    assert missing(module, ModelModule) == [] and isinstance(module, ModelModule)


def test_a_system_that_breaks_the_contract_is_named_with_what_it_lacks():
    class Half:
        names = ("x",)

        def python(self):
            return None

        def python_section(self, section, *, direction=1, where=None, name="section"):
            return None

        def compiled(self, section, direction=0, where=None):
            return None

    got = missing(Half(), DefinedOnce)
    assert "python_section: no parameter 'min_time'" in got
    assert "python_section: parameter 'direction' defaults to 1, the contract to 0" in got
    assert any(m.startswith("compiled: parameter 'direction' is positional or keyword")
               for m in got)
    assert missing(Half(), WithJacobians) == ["has_jacobians: missing", "jacobian: missing"]
    assert missing(Half(), ReferenceView) == []   # python() alone is a reference view
    assert not isinstance(object(), CompiledView) and not provides(object(), CompiledView)


def test_the_front_doors_take_a_system_by_its_views():
    # a class of the user's own with python() alone runs on the reference engine, and so
    # does a proxy that delegates through __getattr__ (which isinstance on a Protocol
    # does not see from Python 3.12 on); a SymbolicSystem runs as it is
    from filippov import monodromy, simulate

    inner = _defined_once()

    class Wrapped:
        def python(self):
            return inner.python()

    class Proxy:
        def __getattr__(self, name):
            return getattr(inner, name)

    for system in (Wrapped(), Proxy(), _symbolic()):
        assert provides(system, ReferenceView)
        traj = simulate(system, [1.0], 1.0)
        assert traj.z[0] == pytest.approx(np.exp(-1.0), rel=1e-12)
    M, _ = monodromy(Proxy(), simulate(Proxy(), [1.0], 1.0))
    assert M[0, 0] == pytest.approx(np.exp(-1.0), rel=1e-8)


def test_several_switching_functions_are_refused_by_name():
    # issue 59 builds several surfaces; until then a vector of switching functions is
    # refused as such, not with numba's error about a vector where a scalar goes
    import sympy as sp

    from filippov import PiecewiseSystem, simulate
    from filippov.checks import SystemContractError

    f = lambda z, p: np.array([1.0, 1.0])  # noqa: E731
    with pytest.raises(ValueError, match=r"switch: returned 2 values .*several switching "
                                         r"surfaces .* not supported"):
        FilippovSystem(("x", "y"), f, f, lambda z, p: np.array([z[0], z[1]]),
                       lambda z, p: np.eye(2))
    x, y = sp.symbols("x y")
    with pytest.raises(ValueError, match=r"switch: 2 expressions: .*several switching"):
        SymbolicSystem([x, y], [1, 1], [1, 1], [x, y])
    assert SymbolicSystem([x, y], [1, 1], [1, 1], [x]).switch == x   # a list of one is one
    g = lambda z: np.ones_like(z)  # noqa: E731
    piecewise = PiecewiseSystem(("x", "y"), g, g, lambda z: np.asarray(z)[:2],
                                lambda z: np.ones_like(z))
    with pytest.raises(SystemContractError, match=r"switch returned 2 values .*several"):
        simulate(piecewise, [-1.0, -0.5], 1.0)
