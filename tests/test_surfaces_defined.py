"""Several switching surfaces defined once (issue 59): a FilippovSystem given ``fields=``
(filippov.surfaces_defined) runs on the reference engine as the SurfacesSystem of the
same functions, against closed forms; m = 1 is today's one-surface system bit for bit
on both engines; its Jacobians (given per region, derived for a slide) agree with
central differences; what it cannot do is refused by name."""
import importlib.util

import numpy as np
import pytest

import filippov
from conftest import ROOT
from filippov import FilippovSystem, Section, simulate
from filippov.checks import SystemContractError
from filippov.surfaces import mode_name

#: event times and states against closed forms (rtol 1e-12 over t <= 10, O(1) states):
#: as tests/test_several_surfaces.py
TOL = 1e-10


def _example(name):
    spec = importlib.util.spec_from_file_location(name, ROOT / "examples" / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _belt(ex, **kw):
    """examples/belt_with_stop.py as plain functions of (z, p): one field f(sigma, z, p),
    the switches and gradients as one vector and one matrix each."""
    def field(sigma, z, p):
        stop = p[3] * (z[0] - p[2]) if sigma[1] > 0 else 0.0
        return np.array([z[1], -z[0] - stop + p[0] * sigma[0]])

    return FilippovSystem(("x", "x'"), fields=field,
                          switch=lambda z, p: np.array([p[1] - z[1], z[0] - p[2]]),
                          switch_grad=lambda z, p: np.array([[0.0, -1.0], [1.0, 0.0]]),
                          params=(ex.F, ex.V, ex.D, ex.S), **kw)


def test_the_belt_with_a_stop_defined_once_is_its_closed_form():
    ex = _example("belt_with_stop")
    system = _belt(ex)
    assert system.m == 2 and isinstance(system.python(), filippov.SurfacesSystem)
    want = ex.closed_form()
    run = simulate(system, [0.0, ex.V], want[-1][1] + 0.1, method="integrate")
    got = [(e.kind, mode_name(e.mode_after, 2)) for e in run.events]
    assert got == [(k, m) for k, _, _, _, m in want]
    for e, (kind, t, x, dx, _) in zip(run.events, want):
        assert abs(e.t - t) <= TOL and np.max(np.abs(e.state - [x, dx])) <= TOL, kind
    # the same run as the example's own SurfacesSystem (numpy pieces): the same events to
    # the rounding of the two evaluations (numba's and numpy's), propagated over t ~ 4
    ref = ex.computed()
    assert len(ref.events) == len(run.events)
    for a, b in zip(ref.events, run.events):
        assert a.kind == b.kind and a.mode_after == b.mode_after
        assert abs(a.t - b.t) <= 1e-12 and np.max(np.abs(a.state - b.state)) <= 1e-12


def _relay(jacobians: bool):
    """examples/relay_feedback.py's relay x' = A x - b sign(x1), written with a second,
    spectator surface x2 = 0 (the same fields on both sides): fields as a mapping,
    switches and gradients as tuples."""
    relay = _example("relay_feedback")
    A, b = relay.A, relay.b
    fields = {s: (lambda z, p, c=(-1.0 if s[0] > 0 else 1.0): A @ z + c * b)
              for s in ((-1, -1), (-1, 1), (1, -1), (1, 1))}
    jac = {s: (lambda z, p: A.copy()) for s in fields} if jacobians else None
    return relay, FilippovSystem(
        ("x1", "x2", "x3"), fields=fields, switch=(lambda z, p: z[0], lambda z, p: z[1]),
        switch_grad=(lambda z, p: np.array([1.0, 0.0, 0.0]),
                     lambda z, p: np.array([0.0, 1.0, 0.0])), jacobians=jac)


@pytest.mark.parametrize("jacobians", [True, False])
def test_a_periodic_orbit_of_two_surfaces_defined_once_is_the_relay_s_closed_form(jacobians):
    # periodic_orbit(engine="reference") with the caller's section s(z, p): Newton on P,
    # dP/dz through both surfaces' saltation matrices, with the regions' Jacobians given
    # (checked against differences of their fields) or by differences
    relay, system = _relay(jacobians)
    assert system.has_jacobians is jacobians
    want = relay.closed_form()
    x0 = want["x0"] if want["x0"][1] > 0 else -want["x0"]
    po = filippov.periodic_orbit(system, x0 + [0.0, 0.01, -0.01], lambda z, p: z[0],
                                 direction=1, engine="reference", t_max=10.0,
                                 method="integrate")
    assert abs(po.period - want["period"]) <= TOL
    assert np.max(np.abs(po.point - x0)) <= TOL
    np.testing.assert_allclose(po.multipliers, want["multipliers"], rtol=0, atol=1e-8)


def _sliding_planar(jacobians=True):
    """tests/test_several_surfaces.py's dP/dz system (a slide on y = 0 that ends at a
    fold, a crossing of x = 2), fields linear in the state, with their Jacobians."""
    F = {(1, -1): (lambda z, p: np.array([1 + 0.1 * z[1], -1 - 0.2 * z[0]]),
                   np.array([[0.0, 0.1], [-0.2, 0.0]])),
         (-1, -1): (lambda z, p: np.array([1 + 0.3 * z[1], 1 - z[0] + 0.2 * z[1]]),
                    np.array([[0.0, 0.3], [-1.0, 0.2]])),
         (-1, 1): (lambda z, p: np.array([1.2 + 0.1 * z[1], 0.25 + 0.1 * z[0]]),
                   np.array([[0.0, 0.1], [0.1, 0.0]])),
         (1, 1): (lambda z, p: np.array([1.0, -0.1]), np.zeros((2, 2)))}
    jac = {s: (lambda z, p, J=J: J.copy()) for s, (_, J) in F.items()} if jacobians else None
    return FilippovSystem(("x", "y"), fields={s: f for s, (f, _) in F.items()},
                          switch=(lambda z, p: z[1], lambda z, p: z[0] - 2.0),
                          switch_grad=lambda z, p: np.array([[0.0, 1.0], [1.0, 0.0]]),
                          jacobians=jac)


def test_the_jacobians_of_a_slide_and_the_return_s_dpdz_agree_with_differences():
    system = _sliding_planar()
    sec = Section("x=3", lambda z: z[0] - 3.0, direction=1, terminal=1)
    z0 = np.array([0.0, 0.3])
    tr = simulate(system, z0, 20.0, method="integrate", sections=[sec])
    assert [e.kind for e in tr.events] == ["start", "slide_start", "slide_end", "crossing",
                                           "section"]
    # the slide's Jacobian (Filippov's formula from the two regions' Jacobians) against
    # central differences of its field (step 1e-6: error ~1e-10 for these fields)
    S, slide = system.python(), tr.events[1].mode_after
    z = np.array([0.5, 0.0])
    fd = filippov.variational.fd_jacobian(lambda zz: S.mode_field(slide, zz), z, 1e-6)
    assert np.max(np.abs(system.jacobian(slide, z) - fd)) <= 1e-8
    # dP/dz with the system's Jacobians against central differences of P (step 1e-6:
    # truncation ~1e-12, the returns' error 1e-12 over the step) and against the
    # same system's dP/dz by differences of its fields
    J = filippov.return_jacobian(system, tr, sec, section_grad=lambda z: np.array([1.0, 0.0]))
    J_fd = filippov.return_jacobian(_sliding_planar(False), tr, sec,
                                    section_grad=lambda z: np.array([1.0, 0.0]))
    fd = np.empty((2, 2))
    for k, e in enumerate(np.eye(2) * 1e-6):
        up, down = (filippov.first_returns(system, (z0 + sgn * e)[None], sec, 20.0,
                                           method="integrate").state[0] for sgn in (1, -1))
        fd[:, k] = (up - down) / 2e-6
    assert np.max(np.abs(J - fd)) <= 1e-5 and np.max(np.abs(J - J_fd)) <= 1e-6


def _one_surface_pair():
    """The relay oscillator of tests/test_several_surfaces.py, written today's way and
    with fields= of one surface."""
    fm = lambda z, p: np.array([z[1] + 0.3, -z[0] + 0.7])  # noqa: E731
    fp = lambda z, p: np.array([z[1] + 0.3, -z[0] - 0.7])  # noqa: E731
    h, g = (lambda z, p: z[1]), (lambda z, p: np.array([0.0, 1.0]))
    today = FilippovSystem(("x", "y"), fm, fp, h, g)
    defined = FilippovSystem(("x", "y"), fields={(-1,): fm, (1,): fp},
                             switch=lambda z, p: np.array([z[1]]),
                             switch_grad=lambda z, p: np.array([[0.0, 1.0]]))
    return today, defined


@pytest.mark.parametrize("engine", ["reference", "compiled"])
def test_one_surface_given_as_fields_is_today_s_system_bit_for_bit(engine):
    today, defined = _one_surface_pair()
    assert defined.m == 1 and isinstance(defined.python(), filippov.PiecewiseSystem)
    starts = np.array([[1.5, 0.4], [-2.0, 0.1], [0.2, 1.0]])
    a, b = (filippov.first_returns(s, starts, lambda z, p: z[0] - 0.5, 30.0, direction=-1,
                                   engine=engine) for s in (today, defined))
    for name in ("state", "time"):
        assert np.array_equal(getattr(a, name), getattr(b, name), equal_nan=True), name
    if engine == "reference":
        x, y = (simulate(s, [1.5, 0.4], 10.0) for s in (today, defined))
        assert [(e.kind, e.t) for e in x.events] == [(e.kind, e.t) for e in y.events]
        assert np.array_equal(x.z, y.z)


def _python_helper(z):
    return z   # a plain Python function: numba cannot compile a piece that calls it


def test_what_a_definition_of_several_surfaces_cannot_do_is_refused_by_name():
    ex = _example("belt_with_stop")
    system = _belt(ex)
    with pytest.raises(TypeError, match=r"the compiled engine takes one switching surface.*"
                                        r"m = 2"):
        filippov.first_returns(system, np.array([[0.0, ex.V]]), lambda z, p: z[0] - 2.0,
                               10.0, engine="compiled")
    f = lambda z, p: z  # noqa: E731
    two = dict(switch=(lambda z, p: z[0], lambda z, p: z[1]),
               switch_grad=lambda z, p: np.eye(2))
    fields = {s: f for s in ((-1, -1), (-1, 1), (1, -1), (1, 1))}
    cases = [
        (dict(fields=fields, **two, field_minus=f), TypeError, r"fields: give either"),
        (dict(fields=fields, **two, flow_minus=f, flow_plus=f), ValueError,
         r"flow_minus, flow_plus: exact flows take one switching surface"),
        (dict(fields={s: f for s in list(fields)[:3]}, **two), ValueError,
         r"fields: no field for region \(1, 1\)"),
        (dict(fields={(1, 2): f}, **two), ValueError, r"fields: \(1, 2\) is not a sign vector"),
        (dict(fields=fields, switch=(f, f, f), switch_grad=two["switch_grad"]), ValueError,
         r"switch: 3 switching functions, but fields has sign vectors of 2"),
        (dict(fields=fields, **two, intersection="nearest"), ValueError, r"intersection:"),
        (dict(fields=fields, switch=two["switch"]), TypeError, r"switch_grad: missing"),
        (dict(fields={**fields, (1, 1): lambda z, p: z / 0.0}, **two), SystemContractError,
         r"fields\[\(1, 1\)\] must return 2 finite values"),
        (dict(fields=fields, **two, jacobians={(1, 3): f}), ValueError,
         r"jacobians: \(1, 3\) is not a sign vector"),
        (dict(fields=fields, **two, jacobians={"plus": f}), ValueError,
         r"jacobians: 'plus' is not a sign vector"),
        (dict(fields={**fields, (1.5, -1): f}, **two), ValueError,
         r"fields: \(1.5, -1\) is not a sign vector"),
        (dict(fields={**fields, (1, 1): lambda z, p: _python_helper(z)}, **two), ValueError,
         r"fields\[\(1, 1\)\]: numba cannot compile it \(Untyped global name "
         r"'_python_helper'"),
        (dict(field_minus=f, field_plus=f, switch=two["switch"][0]), TypeError,
         r"switch_grad: missing"),
    ]
    for kwargs, error, match in cases:
        with pytest.raises(error, match=match):
            FilippovSystem(("x", "y"), probe=[0.5, 0.5], **kwargs)
    # a Jacobian of the wrong shape, or wrong, refused naming it when first asked
    bad = FilippovSystem(("x", "y"), fields=fields, **two,
                         jacobians={s: (lambda z, p: np.ones(3)) for s in fields})
    with pytest.raises(SystemContractError, match=r"jacobians\[\(-1, -1\)\]: returned shape"):
        bad.jacobian(-4, np.array([-0.5, -0.5]))
    wrong = FilippovSystem(("x", "y"), fields=fields, **two,
                           jacobians={s: (lambda z, p: 2.0 * np.eye(2)) for s in fields})
    with pytest.raises(SystemContractError, match=r"jacobians\[\(-1, -1\)\]: at z="):
        wrong.jacobian(-4, np.array([-0.5, -0.5]))
    # one surface's switch that gives two values, without fields=, says what to give
    with pytest.raises(ValueError, match=r"switch: returned 2 values .*fields="):
        FilippovSystem(("x", "y"), f, f, lambda z, p: np.array([z[0], z[1]]),
                       lambda z, p: np.eye(2))


def _symbolic_belt(ex, **kw):
    import sympy as sp

    x, v, F, V, D, S = sp.symbols("x v F V D S")

    def fields(sigma):
        stop = S * (x - D) if sigma[1] > 0 else 0
        return [v, -x - stop + F * sigma[0]]
    return (x, v), filippov.SymbolicSystem([x, v], switch=[V - v, x - D], fields=fields,
                                           params={F: ex.F, V: ex.V, D: ex.D, S: ex.S}, **kw)


def test_the_belt_with_a_stop_in_sympy_is_its_closed_form_with_exact_jacobians():
    import sympy as sp

    ex = _example("belt_with_stop")
    (x, v), sym = _symbolic_belt(ex)
    assert sym.m == 2 and sym.switch_grad == ((0, -1), (1, 0)) and sym.has_jacobians
    assert sym.jacobians[(1, 1)] == sp.Matrix([[0, 1], [-1 - sp.Symbol("S"), 0]])
    want = ex.closed_form()
    run = simulate(sym, [0.0, ex.V], want[-1][1] + 0.1, method="integrate")
    assert [(e.kind, mode_name(e.mode_after, 2)) for e in run.events] == [
        (k, m) for k, _, _, _, m in want]
    for e, (kind, t, x0, dx, _) in zip(run.events, want):
        assert abs(e.t - t) <= TOL and np.max(np.abs(e.state - [x0, dx])) <= TOL, kind
    # the generated pieces give what the hand-written ones give, to the rounding of
    # two evaluations propagated over t ~ 4 (as above)
    hand = simulate(_belt(ex), [0.0, ex.V], want[-1][1] + 0.1, method="integrate")
    for a, b in zip(hand.events, run.events):
        assert a.kind == b.kind and abs(a.t - b.t) <= 1e-12
    # each mode's Jacobian (a region's generated; the stick's, on h1 beyond the stop,
    # Filippov's formula) against central differences of the mode's field
    S = sym.python()
    for digits_ in ((1, 1), (-1, 1), (0, 1), (0, -1)):
        mode, z = filippov.surfaces.mode_of(digits_), np.array([0.6, 0.45])
        fd = filippov.variational.fd_jacobian(lambda zz: S.mode_field(mode, zz), z, 1e-6)
        assert np.max(np.abs(sym.jacobian(mode, z) - fd)) <= 1e-8, digits_


def test_one_surface_given_as_fields_in_sympy_generates_today_s_source():
    import sympy as sp

    x, y, c = sp.symbols("x y c")
    fm, fp = [y + c, -x + 0.7], [y + c, -x - 0.7]
    today = filippov.SymbolicSystem([x, y], fm, fp, y, params={c: 0.3})
    fields = filippov.SymbolicSystem([x, y], switch=[y], fields={(-1,): fm, (1,): fp},
                                     params={c: 0.3})
    assert fields.m == 1 and fields.source() == today.source()


def test_what_a_sympy_definition_of_several_surfaces_cannot_do_is_refused_by_name():
    import sympy as sp

    from filippov.symbolic import SymbolicError

    x, y, t = sp.symbols("x y t")
    f = {s: [1, 1] for s in ((-1, -1), (-1, 1), (1, -1), (1, 1))}
    cases = [(dict(fields=f, switch=[x, y], field_minus=[1, 1]), r"fields: give either"),
             (dict(fields=f, switch=[x, y], time=t, flows={"minus": [x, y], "plus": [x, y]}),
              r"flows: exact flows take one switching surface"),
             (dict(fields={s: f[s] for s in list(f)[:3]}, switch=[x, y]),
              r"fields: no field for region \(1, 1\)"),
             (dict(fields=f, switch=[x, y, x + y]),
              r"fields: .* is not a sign vector \(a tuple of 3"),
             (dict(fields={(-1,): [1, 1], (1,): [1, 1]}, switch=[x], intersection="bilinear"),
              r"intersection: one switching surface has no intersection"),
             (dict(fields={**f, (1, 1): [t, 1]}, switch=[x, y]), r"fields\[\(1, 1\)\]"),
             (dict(fields=f, switch=[x, y], intersection="nearest"), r"intersection:")]
    for kwargs, match in cases:
        with pytest.raises(SymbolicError, match=match):
            filippov.SymbolicSystem([x, y], **kwargs)
    sym = filippov.SymbolicSystem([x, y], fields=f, switch=[x, y], intersection="bilinear")
    assert sym.python().intersection == "bilinear"
    with pytest.raises(TypeError, match=r"the compiled engine takes one switching surface"):
        filippov.first_returns(sym, np.array([[-1.0, -1.0]]), x - 1, 5.0, engine="compiled")


def test_a_value_numba_compiled_in_that_changes_is_refused_not_used_stale():
    # the pieces of several surfaces are compiled (and run once) when the system is
    # built: what they read from globals is noted before, and a change refused at the next
    # run (the one-surface rule, filippov.frozen), for m = 2 and for m = 1 given as fields
    shift = np.array([0.0])
    fm = lambda z, p: np.array([1.0, 1.0])  # noqa: E731
    fp = lambda z, p: np.array([1.0, 0.5])  # noqa: E731
    two = FilippovSystem(("x", "y"), fields={(-1, -1): fm, (-1, 1): fm, (1, -1): fp,
                                             (1, 1): fp},
                         switch=(lambda z, p: z[1] - shift[0], lambda z, p: z[0] + 10.0),
                         switch_grad=lambda z, p: np.array([[0.0, 1.0], [1.0, 0.0]]))
    one = FilippovSystem(("x", "y"), fields={(-1,): fm, (1,): fp},
                         switch=lambda z, p: np.array([z[1] - shift[0]]),
                         switch_grad=lambda z, p: np.array([[0.0, 1.0]]))
    shift[0] = 0.5
    for system in (two, one):
        with pytest.raises(SystemContractError, match=r"switch.*'shift'.*\[0\.\]"):
            simulate(system, [0.0, -1.0], 3.0)


def test_one_surface_given_as_fields_takes_a_scalar_switch_and_a_gradient_vector():
    today, _ = _one_surface_pair()
    plain = FilippovSystem(("x", "y"), fields={(-1,): today._pieces["field_minus"],
                                               (1,): today._pieces["field_plus"]},
                           switch=lambda z, p: z[1], switch_grad=lambda z, p: np.array([0.0, 1.0]))
    a, b = (simulate(s, [1.5, 0.4], 10.0) for s in (today, plain))
    assert [(e.kind, e.t) for e in a.events] == [(e.kind, e.t) for e in b.events]
    assert np.array_equal(a.z, b.z)


def test_the_monodromy_of_a_period_that_starts_on_a_surface_closes_with_its_switch():
    # the relay's orbit from its point on x1 = 0 (a start on the surface, the period
    # closed by the switch from the end mode to the start's): its multipliers
    relay, system = _relay(False)
    want = relay.closed_form()
    x0 = want["x0"] if want["x0"][1] > 0 else -want["x0"]
    po = filippov.periodic_orbit(system, x0, lambda z, p: z[0], direction=1,
                                 engine="reference", t_max=10.0, method="integrate")
    orbit = simulate(system, po.point, po.period, method="integrate")
    _, mult = filippov.monodromy(system, orbit)
    np.testing.assert_allclose(np.sort(np.abs(mult))[::-1], np.sort(np.abs(
        want["multipliers"]))[::-1], rtol=0, atol=1e-7)


def test_a_non_finite_field_is_blamed_on_its_region():
    # the view a stay runs names its fields field_minus and field_plus; the error names
    # the region whose field it is (filippov.checks.blamed)
    f = lambda z, p: np.array([1.0, 1.0])  # noqa: E731
    two = FilippovSystem(("x", "y"), fields={(-1, -1): f, (-1, 1): f, (1, -1): f,
                                             (1, 1): lambda z, p: np.array([1.0, np.log(1.6 - z[0])])},
                         switch=(lambda z, p: z[0] - 1.0, lambda z, p: z[1] + 10.0),
                         switch_grad=lambda z, p: np.array([[1.0, 0.0], [0.0, 1.0]]))
    with pytest.raises(filippov.SimulationError, match=r"t=1\.6.*the field of region \(1, 1\) "
                                                       r"returned a non-finite value"):
        simulate(two, [0.0, 0.0], 3.0)
