"""The scripts in examples/: each agrees with its closed form and runs as a program.

Tolerances. The orbits are integrated by DOP853 at simulate's default rtol 1e-12
(atol 1e-14, states of size ~1) and events refined by Brent to 1e-15. DOP853's
global error over a period stays within a few rtol (<= 3 rtol on the orbits of
test_continuation.py, see floquet_multipliers), so a state is trusted to
TOL = 10 rtol, and an event time to TOL divided by the speed at which the event
function crosses zero there. Measured errors are 1e-12 or less (docs: Examples).
"""
import ast
import importlib.util
import os
import re
import subprocess
import sys

import numpy as np
import pytest
import scipy.linalg

import filippov
import filippov.surfaces
from conftest import ROOT

EXAMPLES = ROOT / "examples"
SCRIPTS = ("relay_feedback", "sliding_segment", "stick_slip", "belt_with_stop",
           "two_blocks_on_a_belt")
RTOL = 1e-12
TOL = 10 * RTOL


def load(name):
    spec = importlib.util.spec_from_file_location(f"examples_{name}", EXAMPLES / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_belt_with_stop_events_are_the_closed_form_s():
    """The stick carried across the stop, its release, and the slip back and forth across
    the stop (examples/belt_with_stop.py), against the closed form: states to TOL, times
    to TOL over the speed the event function crosses at (1 at the stick's crossing of
    h2, 0.43 at the slip's), the release (a fold: the speed 0, its time as the state's
    x to TOL over the stick's speed 0.5)."""
    ex = load("belt_with_stop")
    run, want = ex.computed(), ex.closed_form()
    got = [(e.kind, filippov.surfaces.mode_name(e.mode_after, 2)) for e in run.events]
    assert got == [(kind, mode) for kind, _, _, _, mode in want]
    for e, (_, t, x, dx, _) in zip(run.events, want):
        assert abs(e.t - t) <= TOL / 0.4
        np.testing.assert_allclose(e.state, [x, dx], rtol=0, atol=TOL)


def test_two_blocks_on_a_belt_events_are_the_closed_form_s():
    """Both blocks stick on the intersection of two surfaces, one is released (the slide
    on the intersection ends, on the other surface), then the other; both slip, and one
    sticks again (examples/two_blocks_on_a_belt.py), against the closed form (brentq on
    harmonic motions, a linear force, and the exponential of the slip of both). States to
    TOL; times to TOL over the rate the event function crosses at, the smallest 0.2 (the
    second stick); 5 time units of slip before it, so that one to 10 TOL."""
    ex = load("two_blocks_on_a_belt")
    run, want = ex.computed(), ex.closed_form()
    got = [(e.kind, filippov.surfaces.mode_name(e.mode_after, 2)) for e in run.events]
    assert got == [(kind, mode) for kind, _, _, mode in want]
    for e, (_, t, z, _) in zip(run.events, want):
        assert abs(e.t - t) <= 10 * TOL / 0.2, (e.kind, e.t - t)
        np.testing.assert_allclose(e.state, z, rtol=0, atol=10 * TOL)
    # the stay on the intersection: both carried at V, every choice of its field the same
    ts, zs, modes = run.sample(np.array([1.0]), include_events=False)
    assert filippov.surfaces.mode_name(modes[0], 2) == "00"
    np.testing.assert_allclose(zs[:, 0], ex.closed_form(orbit=True)(1.0), rtol=0, atol=TOL)


def test_relay_feedback_orbit_and_multipliers():
    ex = load("relay_feedback")
    assert ex.RTOL == RTOL
    got, want = ex.computed(), ex.closed_form()
    x0, M = want["x0"], want["monodromy"]
    # crossing times: c^T x crosses zero at speed x2 = 0.29 (> 0.25); the period is
    # the difference of two crossing times
    assert abs(got["half_period"] - want["half_period"]) <= 2 * TOL / 0.25
    assert abs(got["period"] - want["period"]) <= 2 * TOL / 0.25
    # the start state: a state of size ~0.3 after 20 periods (the transient has
    # decayed by 0.147^19 < 1e-15)
    np.testing.assert_allclose(got["x0"], x0, rtol=0, atol=TOL)
    # the variational equations are integrated at rtol 1e-12 too (exact Jacobian A):
    # an error of TOL |M| in M (|M| = 12) ...
    normM = np.linalg.norm(M, 2)
    np.testing.assert_allclose(got["monodromy"], M, rtol=0, atol=TOL * normM)
    # ... moves eigenvalue i by at most kappa_i TOL |M| (kappa_i = 1/|w_i^H v_i| <= 17)
    lam, wl, vr = scipy.linalg.eig(M, left=True, right=True)
    kappa = np.max(1 / np.abs(np.sum(wl.conj() * vr, axis=0)))
    np.testing.assert_allclose(got["multipliers"], want["multipliers"], rtol=0,
                               atol=kappa * TOL * normM)
    assert want["multipliers"][0] == pytest.approx(1.0, abs=1e-12)  # the closed form itself


@pytest.mark.parametrize("method", ["exact", "integrate"])
def test_sliding_segment_start_end_and_exit(method):
    ex = load("sliding_segment")
    got, want = ex.computed(method), ex.closed_form()
    # the slide starts at the end of the + arc, a straight line: the exact flow or
    # DOP853 (exact on it up to rounding), refined to 1e-15 by Brent
    assert abs(got["slide_start_t"] - want["slide_start_t"]) <= 1e-14
    assert abs(got["slide_start_x"] - want["slide_start_x"]) <= 1e-14
    # the slide (1.4 time units, integrated at rtol 1e-12) ends where a = 1 - x reaches
    # zero: x itself is refined to its root, and a falls at speed x' = 1 there
    assert abs(got["slide_end_x"] - want["slide_end_x"]) <= 1e-14
    assert abs(got["slide_end_t"] - want["slide_end_t"]) <= TOL / 1.0
    # the - arc after the exit is exact (or DOP853 on a quadratic): the exit time error
    # moves the end state by at most |(x', y')| = |(1, -s)| <= 1 + T_END times it
    for key in ("end_x", "end_y"):
        assert abs(got[key] - want[key]) <= TOL * (1 + ex.T_END)


def test_stick_slip_period_stick_time_and_multipliers():
    ex = load("stick_slip")
    got, want = ex.computed(), ex.closed_form()
    assert np.size(got["fixed_point"]) == 1  # the return map has one fixed point
    # the section point, x = 1.48: the end of 1.5 time units of DOP853 along the slip
    # arc from the release at x = F (a root of b = x - F, exact along the stick)
    assert abs(got["fixed_point"][0] - want["fixed_point"]) <= TOL * 1.5
    # the stick starts where x' = v is crossed at speed |x''| = F - x_r = 0.74, and
    # lasts (F - x_r)/v, v = 0.5: errors of at most TOL/0.74 + TOL/0.5 < 4 TOL
    assert abs(got["stick_time"][0] - want["stick_time"]) <= 4 * TOL
    assert abs(got["period"][0] - want["period"]) <= 4 * TOL
    # floquet_multipliers at its defaults (rtol 1e-10, atol 1e-12, central-difference
    # Jacobians): its own error estimate of M is (100 (rtol + atol) + 1e-8) max(1, |M|),
    # |M| = 1.6, and both eigenvalues have kappa = 1.6: < 3e-8. The multiplier 0 is
    # exact: the saltation matrix at the slide start projects onto x' = v.
    np.testing.assert_allclose(got["multipliers"], want["multipliers"], rtol=0, atol=3e-8)


@pytest.mark.parametrize("name", SCRIPTS)
def test_example_uses_the_public_api_only(name):
    source = (EXAMPLES / f"{name}.py").read_text()
    tree = ast.parse(source)
    assert ast.get_docstring(tree) and "Run: python examples/" in ast.get_docstring(tree)
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.module.startswith("filippov"):
            # filippov.surfaces too: a mode's name on several surfaces, and the
            # reference engine's hand-written SurfacesSystem
            public = {"filippov": filippov.__all__,
                      "filippov.surfaces": filippov.surfaces.__all__}
            assert node.module in public, f"{name}: imports from {node.module}"
            assert {a.name for a in node.names} <= set(public[node.module])
        if isinstance(node, ast.Import):
            assert not any(a.name.startswith("filippov") for a in node.names)
    # short and readable: the system, the closed form, the table and the figure
    assert len(source.splitlines()) <= 100


@pytest.mark.parametrize("name", SCRIPTS)
def test_example_docstring_writes_its_formulas_as_math(name):
    # the gallery renders the docstring as reStructuredText: formulas in :math: roles or
    # a math directive (MathJax), not as ASCII in literals
    doc = ast.get_docstring(ast.parse((EXAMPLES / f"{name}.py").read_text()))
    assert ":math:`" in doc and ".. math::" in doc
    assert "::\n" not in doc.replace(".. math::\n", "")   # no literal block of formulas
    assert not re.search(r"``[^`]*[=^][^`]*``", doc), "a formula in a literal"


@pytest.mark.parametrize("name", SCRIPTS)
def test_example_draws_its_orbit_against_the_closed_form(name, monkeypatch):
    # the gallery shows the figures a script leaves open: one, with labelled axes and
    # a legend naming the closed form and the solver's points
    import matplotlib.pyplot as plt

    monkeypatch.setattr(plt, "show", lambda *args, **kwargs: None)   # no window here
    plt.close("all")
    module = load(name)
    module.main()
    try:
        figures = [plt.figure(n) for n in plt.get_fignums()]
        assert len(figures) == 1, f"{name}: {len(figures)} figures"
        for ax in figures[0].axes:
            assert ax.get_xlabel() and ax.get_ylabel() and ax.get_title()
            legend = ax.get_legend()
            assert legend is not None
            texts = [t.get_text() for t in legend.get_texts()]
            assert "closed form" in texts and any("simulate" in t for t in texts), texts
            # the closed form is a drawn line, the solver's states are points on it
            assert any(len(line.get_xdata()) > 50 for line in ax.get_lines())
    finally:
        plt.close("all")


@pytest.mark.parametrize("name", SCRIPTS)
def test_example_runs_as_a_program(name):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "src"), str(ROOT / "workflow"),
                                                      env.get("PYTHONPATH")]))
    # the timeout guards against a hang only: how fast an example runs is not a test
    # (a wall-clock bound failed under load on a shared machine)
    run = subprocess.run([sys.executable, str(EXAMPLES / f"{name}.py")], cwd=ROOT, env=env,
                         capture_output=True, text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    assert "closed form" in run.stdout and run.stderr == ""
