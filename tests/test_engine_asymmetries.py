"""The differences that remain between the two engines, each pinned (the list with the
reasons: the docstring of :mod:`filippov.engines`). A test here fails when an engine
changes the behaviour its entry describes -- then the entry is out of date too."""
import inspect
import re
from pathlib import Path

import numpy as np
import pytest

from filippov import (EventLimitError, FilippovSystem, PeriodicOrbitError, Section,
                      compute_returns, first_returns, first_returns_compiled, periodic_orbit,
                      rules, simulate)
from filippov.fastmap import OK
from filippov.kernel import base as kernel_base
from filippov.models import hopf

ROOT = Path(__file__).resolve().parents[1]


def _clocked(field_minus, field_plus, switch, grad):
    """A system with a clock w (w' = 1) as its last variable: the section w = T is
    reached at t = T whatever else happens."""
    return FilippovSystem(("x", "y", "w"), field_minus, field_plus, switch=switch,
                          switch_grad=grad)


def _at_time(t):
    return lambda z, p: z[2] - t


# ------------------------------------------------------------------ budgets: projections
def test_the_event_budget_is_projected_by_the_reference_engine_only():
    # chatter of the pseudo-equilibrium example (eps = 1e-3): 74 switches up to the
    # section at t = 0.2, at a rate that would exceed max_events = 1000 long before
    # t_max = 100. The reference stops at the 64th switch (the Zeno ring's rate,
    # projected to t_max); the compiled engine runs on to the section.
    eps = 1e-3
    system = _clocked(lambda z, p: np.array([1.0, (z[0] - z[1]) / eps, 1.0]),
                      lambda z, p: np.array([-1.0, (z[0] - z[1]) / eps, 1.0]),
                      lambda z, p: -0.5 * z[0] + 1.5 * z[1],
                      lambda z, p: np.array([-0.5, 1.5, 0.0]))
    start, opts = [0.01, 0.0, 0.0], dict(max_events=1000)
    with pytest.raises(EventLimitError, match="switching every .* exceed max_events"):
        first_returns(system.python(), [start], Section("w", lambda z: z[2] - 0.2, 1), 100.0,
                      method="integrate", **opts)
    out = compute_returns(system.compiled(_at_time(0.2), direction=1), [start], 100.0, **opts)
    assert out.status[0] == OK and out.time[0] == pytest.approx(0.2, rel=1e-12)
    assert 64 <= out.n_switches[0] < 1000


def test_the_step_budget_is_projected_by_the_reference_engine_only():
    # 1500 steps of max_step = 1e-3 to the section at t = 1.5, within max_steps = 5000;
    # after PROJECT_AFTER steps the reference projects the mean step to t_max = 100
    # (~1e5 steps) and stops, the compiled engine runs on to the section
    one = lambda z, p: np.array([1.0, 0.0, 1.0])  # noqa: E731
    system = _clocked(one, one, lambda z, p: z[0] - 1e9, lambda z, p: np.array([1.0, 0.0, 0.0]))
    start, opts = [0.0, 0.0, 0.0], dict(max_steps=5000, max_step=1e-3)
    with pytest.raises(EventLimitError, match="exceed max_steps"):
        first_returns(system.python(), [start], Section("w", lambda z: z[2] - 1.5, 1), 100.0,
                      method="integrate", **opts)
    out = compute_returns(system.compiled(_at_time(1.5), direction=1), [start], 100.0, **opts)
    assert out.status[0] == OK and out.time[0] == pytest.approx(1.5, rel=1e-12)


# ------------------------------------------------------------------ sampling
def test_the_compiled_engine_scans_exact_flows_once_per_sample_step():
    # samples_per_step counts samples per integration step only: on exact flows (no
    # slide on the way: theta = -0.5) the returns do not depend on it, bit for bit
    cm = hopf.compiled(1e-2, -0.5)
    starts = [[0.0, x2, 0.0] for x2 in (0.97, 1.0, 1.03)]
    coarse = compute_returns(cm, starts, 2.0, samples_per_step=1)
    fine = compute_returns(cm, starts, 2.0, samples_per_step=8)
    assert np.all(coarse.status == OK) and np.all(coarse.sliding_time == 0.0)
    np.testing.assert_array_equal(coarse.state, fine.state)
    np.testing.assert_array_equal(coarse.time, fine.time)


# ------------------------------------------------------------------ what the compiled engine lacks
def test_the_compiled_engine_has_no_stiff_switch():
    # the reference continues a stiff integrated stay with Radau IIA (stiff=True); the
    # kernel has DOP853 only, so the option does not exist there
    assert "stiff" in inspect.signature(simulate).parameters
    assert "stiff" not in inspect.signature(compute_returns).parameters
    with pytest.raises(TypeError):
        compute_returns(hopf.compiled(1e-2, -0.5), [[0.0, 1.0, 0.0]], 1.0, stiff=True)


def test_the_compiled_model_has_no_sliding_flow():
    # the reference uses flows[SLIDING] under method="exact" where a system has one
    from filippov.abi import PIECES

    names = [name for name, _ in PIECES]
    assert [n for n in names if n.startswith("flow")] == [
        "flow_plus", "flow_minus", "flow_jacobian_plus", "flow_jacobian_minus"]
    assert not [n for n in names if "slid" in n]


# ------------------------------------------------------------------ root finding
def test_both_engines_give_brent_the_same_iteration_bound():
    # the bracket of an event and of a hidden extremum: the kernel's extremum bound was
    # 100 (scipy's default) while the reference's _brent allowed 200
    assert rules.BRENT_MAXITER == 200
    assert kernel_base._MAXITER_EVENT == rules.BRENT_MAXITER
    assert kernel_base._MAXITER_EXTREMUM == rules.BRENT_MAXITER
    src = (ROOT / "src/filippov/simulate.py").read_text()
    assert "maxiter=200" not in src and src.count("maxiter=rules.BRENT_MAXITER") == 3


# ------------------------------------------------------------------ bookkeeping
@pytest.mark.parametrize("engine", ["compiled", "reference"])
def test_a_start_that_slides_counts_its_first_slide_on_both_engines(engine):
    # f_- = (1, 1), f_+ = (1, x1), h = x2: from (-1, 0) on H (a = 1, b = -1) the orbit
    # slides to x1 = 0 (t = 1), leaves into region +, and meets x1 = 1 at t = 2
    system = FilippovSystem(("x1", "x2"), lambda z, p: np.array([1.0, 1.0]),
                            lambda z, p: np.array([1.0, z[0]]), switch=lambda z, p: z[1],
                            switch_grad=lambda z, p: np.array([0.0, 1.0]))
    if engine == "reference":
        out = first_returns(system.python(), [[-1.0, 0.0]],
                            Section("s", lambda z: z[0] - 1.0, 1), 5.0, method="integrate")
    else:
        out = first_returns_compiled(system.compiled(lambda z, p: z[0] - 1.0, direction=1),
                                     [[-1.0, 0.0]], 5.0)
    assert out.time[0] == pytest.approx(2.0, rel=1e-12)
    assert out.sliding_time[0] == pytest.approx(1.0, rel=1e-10)


def test_dpdz_of_a_return_that_starts_sliding_is_the_reference_engine_s_only():
    # sliding on the unit circle h = x^2 + y^2 - 1: inside F_- = x (1, 1) + w (-y, x), outside
    # F_+ = -(1 - 2y/r) (x, y) + w (-y, x); theta' = w in every mode, so the orbit (a slide
    # for y < 1/2, the excursion outside, back onto the circle) has period 2 pi / w, and
    # z' = -lam z + x is slaved: multipliers 1 (the flow), exp(-lam T), 0 (the slide
    # collapses the radial perturbation). The section y = 0 (x > 0) lies on the slide.
    w, lam = 2.0, 0.7

    def outside(z, p):
        r = np.sqrt(z[0] ** 2 + z[1] ** 2)
        return np.array([-(1 - 2 * z[1] / r) * z[0] - w * z[1],
                         -(1 - 2 * z[1] / r) * z[1] + w * z[0], -lam * z[2] + z[0]])

    system = FilippovSystem(
        ("x", "y", "z"), lambda z, p: np.array([z[0] - w * z[1], z[1] + w * z[0],
                                                -lam * z[2] + z[0]]), outside,
        switch=lambda z, p: z[0] ** 2 + z[1] ** 2 - 1,
        switch_grad=lambda z, p: np.array([2 * z[0], 2 * z[1], 0.0]))
    kw = dict(direction=1, where=lambda z, p: z[0] > 0, t_max=10.0)
    section = lambda z, p: z[1]  # noqa: E731
    po = periodic_orbit(system, [1.0, 0.0, 0.3], section, engine="reference", **kw)
    T = 2 * np.pi / w
    assert po.period == pytest.approx(T, rel=1e-9)
    assert np.sort(po.multipliers)[::-1] == pytest.approx([1.0, np.exp(-lam * T), 0.0],
                                                          abs=1e-8)
    # from the guess, on H (h = 0 exactly: a start that slides), the kernel makes the
    # return and leaves its derivative NaN
    out = compute_returns(system.compiled(section, direction=1, where=kw["where"]),
                          [[1.0, 0.0, 0.3]], 10.0, jacobian=True)
    assert out.status[0] == OK and out.time[0] == pytest.approx(T, rel=1e-9)
    assert np.isnan(out.jacobian[0]).all()
    with pytest.raises(PeriodicOrbitError, match=r"dP/dz is not finite .*item 11"):
        periodic_orbit(system, [1.0, 0.0, 0.3], section, engine="compiled", **kw)


# ------------------------------------------------------------------ the list and the comments
def test_every_python_twin_named_in_the_kernel_exists():
    """Kernel comments point at their reference twins (simulate.<name>, simulate._Run.<m>):
    each must exist in simulate.py, or the pointer is stale."""
    import importlib

    sim = importlib.import_module("filippov.simulate")  # the module, not the function

    names = set()
    for path in sorted((ROOT / "src/filippov/kernel").glob("*.py")):
        names |= set(re.findall(r"simulate\.(_?[A-Za-z]\w*(?:\.\w+)?)", path.read_text()))
    assert names, "no pointers found: the pattern is out of date"
    missing = []
    for name in sorted(names):
        obj = sim
        for part in name.split("."):
            obj = getattr(obj, part, None)
        if obj is None:
            missing.append(name)
    assert not missing, f"kernel comments name simulate twins that do not exist: {missing}"


def test_the_list_of_asymmetries_names_tests_that_exist():
    """Each entry of filippov.engines.ASYMMETRIES (data: the table its documentation
    renders) names its tests as file::name; each must exist, and the table shows every
    entry."""
    import filippov.engines as engines

    entries = engines.ASYMMETRIES
    assert [a.number for a in entries] == list(range(1, len(entries) + 1))
    assert {a.verdict for a in entries} <= {"deliberate", "defect, fixed"}
    refs = [tuple(t.split("::")) for a in entries for t in a.tests]
    assert len(refs) >= 12 and all(a.tests for a in entries)
    assert all(f"**{a.title}**" in engines.__doc__ for a in entries)
    for path, name in refs:
        text = (ROOT / path).read_text()
        assert re.search(rf"^def {name}\(", text, re.M), f"{path}::{name} not found"
    tutorial = (ROOT / "docs/tutorial.md").read_text()
    assert "engines" in tutorial and "filippov.engines" in tutorial


def test_the_reference_measures_the_rounding_a_function_carries():
    """engines.py asymmetry 12: samples of a = (x - y) / eps whose scatter is the state's
    rounding times 1/eps fail the rule at 64 ulps of the samples (the compiled engine's
    judgement), and pass above the rounding the reference measures (simulate._rounding:
    64 ulps of each component carried through a); a smooth feature far above it does not."""
    from filippov import rules
    from filippov.kernel import base as kernel
    from filippov.simulate import _rounding

    eps = 1e-9
    a = lambda zz: (zz[0] - zz[1]) / eps  # noqa: E731
    z = np.array([[-1.0, -1.0 - 5e-10]]).T
    floor = _rounding(a, z)
    u = np.finfo(float).eps
    # 64 ulps of each of x and y, times 1/eps, to a few ulps of the probes' own rounding
    assert floor == pytest.approx(64 * u * 2 / eps, rel=0.3)
    ts = np.arange(5) * 1e-4
    v = 0.5 + 2e-7 * np.array([1.0, -1.0, 0.5, 1.0, -0.5])   # rounding-sized scatter
    compiled = kernel.compiled_rule("resolves")
    assert not compiled(v, v, ts, 5, False, 0.0)
    assert not rules.resolves(v, v, ts, 5, False, 0.0)
    assert rules.resolves(v, v, ts, 5, False, floor)
    wiggle = 0.5 + 1e-3 * np.array([1.0, -1.0, 0.5, 1.0, -0.5])  # far above the rounding
    assert not rules.resolves(wiggle, wiggle, ts, 5, False, floor)
    assert _rounding(lambda zz: np.full(zz.shape[1], np.nan), z) == 0.0
    # the smallest over the samples: a sample where a is steep does not lift another's
    two = np.array([[-1.0, 3.0], [-1.0 - 5e-10, 3.0]])
    b = lambda zz: np.where(zz[0] > 0.0, 1e6 * zz[0], (zz[0] - zz[1]) / eps)  # noqa: E731
    assert _rounding(b, two) == pytest.approx(min(floor, 64 * u * 3.0 * 1e6), rel=0.3)
