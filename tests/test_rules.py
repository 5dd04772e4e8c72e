"""The decisions of the event-driven method are written once (filippov.rules):
the reference driver calls them, the compiled engine compiles the same functions."""
import ast
import inspect
import itertools
from pathlib import Path

import numba
import numpy as np
import pytest

from filippov import rules
from filippov.kernel import base as kernel  # the rules as the kernel compiles them
from filippov.system import MINUS, PLUS, SLIDING

SPEEDS = (-1.0, -0.0, 0.0, 1e-300, 2.0)


def _sample_args(rule):
    """Arguments a rule compiles for: a scalar of each annotated type, a 3-vector for
    each unannotated parameter (a state, a field, a ring; or elementwise samples)."""
    kinds = {"int": 1, "float": 0.5, "bool": True}
    return tuple(np.ones(3) if p.annotation is inspect.Parameter.empty
                 else kinds[p.annotation] for p in inspect.signature(rule).parameters.values())


@pytest.mark.parametrize("name", sorted(kernel.rule_book()))
def test_every_rule_compiles_as_it_is(name):
    """Every public rule of the book compiles with numba as it stands, the rules it calls
    included (kernel.base registers the whole book: a new rule needs no entry there), and
    gives what Python gives."""
    rule = kernel.rule_book()[name]
    compiled = numba.njit(rule)
    got, want = compiled(*_sample_args(rule)), rule(*_sample_args(rule))
    # (nan, nan) is geometric_accumulation's "no": equal to itself here
    assert np.array_equal(got, want) or np.array_equal(np.asarray(got, dtype=float),
                                                       np.asarray(want, dtype=float),
                                                       equal_nan=True)


def _src_files():
    return sorted((Path(rules.__file__).parent).rglob("*.py"))


def test_a_rule_is_only_ever_called():
    """No rule is handed around as a value (a factory's argument, a record's field, an
    alias): the loop, the kernel and the reference driver call ``rules.<name>(...)``, so
    a new rule touches the book, the orchestration that asks it and its test only."""
    book = set(kernel.rule_book())
    passed = []
    for path in _src_files():
        tree = ast.parse(path.read_text())
        called = {id(node.func) for node in ast.walk(tree) if isinstance(node, ast.Call)}
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and node.attr in book
                    and isinstance(node.value, ast.Name) and node.value.id == "rules"
                    and id(node) not in called):
                passed.append(f"{path.name}:{node.lineno} rules.{node.attr}")
            if isinstance(node, ast.ImportFrom) and (node.module or "").endswith("rules"):
                passed += [f"{path.name}:{node.lineno} imports {a.name}"
                           for a in node.names if a.name in book]
    assert passed == []


def _noise_of(values):
    noise = 0.0
    for j in range(2, len(values)):
        noise = rules.section_noise(noise, values[j - 2], values[j - 1], values[j])
    return noise


def test_the_section_s_rounding_is_measured_not_assumed():
    """A section with terms of 22 against a state of 1 rounds in units of ulp(22): the
    probes about a start see those steps (a straight line leaves nothing), and a start
    whose value is within START_ULPS of them is on the section; a start 1e-12 off is not."""
    z0 = np.array([0.125, -0.375, 1.0])
    e = np.array([0.0874, 0.6989, 0.7098])
    d = 22.2
    s = lambda z: (e @ z + d) - (d + e @ z0)  # noqa: E731  (0 at z0 in exact arithmetic)
    zr = z0 + 1.5e-14 * e
    probe = np.empty(3)
    values = []
    for j in range(-rules.SECTION_PROBES, rules.SECTION_PROBES + 1):
        assert rules.section_probe(z0, zr, j, probe)
        values.append(s(probe))
    noise = _noise_of(values)
    ulp22 = np.spacing(22.2 + 0.6)
    assert 0.25 * ulp22 <= noise <= 2 * ulp22
    assert rules.on_section_by_value(-ulp22, noise)
    assert not rules.on_section_by_value(-1e-12, noise)
    # an exactly straight section measures no rounding
    assert _noise_of([0.5 * j for j in range(17)]) == 0.0
    # a crossing beyond the reach is never explained by rounding; NaN is no evidence
    assert not rules.section_probe(z0, z0 + 1e-3, 1, probe)
    nan = _noise_of([0.0, 1.0, np.nan, 1.0, 0.0])
    assert np.isnan(nan) and not rules.on_section_by_value(0.0, nan)


def test_an_age_is_carried_only_where_the_region_is_unambiguous():
    for f in (rules.carried_age, kernel.compiled_rule("carried_age")):
        assert f(0.3, 1e-15, 2.5) == 2.5 and f(-0.3, 1e-15, 2.5) == 2.5
        assert f(1e-15, 1e-15, 2.5) == 0.0 and f(0.0, 1e-15, 2.5) == 0.0


@pytest.mark.parametrize("mode", [PLUS, MINUS, SLIDING])
def test_compiled_and_python_decide_alike(mode):
    for ended, a, b in itertools.product((rules.SWITCH, rules.EXIT_MINUS, rules.EXIT_PLUS),
                                         SPEEDS, SPEEDS):
        if mode == SLIDING and ended == rules.SWITCH:
            continue
        assert (kernel.compiled_rule("next_mode")(mode, ended, a, b)
                == rules.next_mode(mode, ended, a, b))
    for H, a, b in itertools.product((-1e-17, 0.0, 1e-17), SPEEDS, SPEEDS):
        for sliding in (True, False):
            assert (kernel.compiled_rule("start_on_switch")(H, a, b, sliding)
                    == rules.start_on_switch(H, a, b, sliding))


def test_filippov_decision_table():
    # from region +: F_- points back up (a > 0) -> slide, else cross into -
    assert rules.next_mode(PLUS, rules.SWITCH, 1.0, -1.0) == SLIDING
    assert rules.next_mode(PLUS, rules.SWITCH, -1.0, -1.0) == MINUS
    # from region -: F_+ points back down (b < 0) -> slide, else cross into +
    assert rules.next_mode(MINUS, rules.SWITCH, 1.0, -1.0) == SLIDING
    assert rules.next_mode(MINUS, rules.SWITCH, 1.0, 1.0) == PLUS
    assert rules.next_mode(SLIDING, rules.EXIT_PLUS, 1.0, 0.0) == PLUS
    assert rules.next_mode(SLIDING, rules.EXIT_MINUS, 0.0, -1.0) == MINUS
    # a start on H: sliding attracts, repels (either side; + is taken), or one side
    assert rules.start_on_switch(0.0, 1.0, -1.0, True) == (SLIDING, False)
    assert rules.start_on_switch(0.0, 1.0, -1.0, False) == (PLUS, False)
    assert rules.start_on_switch(0.0, -1.0, 1.0, True) == (PLUS, True)
    assert rules.start_on_switch(-1e-17, 0.0, 0.0, True) == (MINUS, False)
    assert rules.start_side(2e-15, 1e-15) == PLUS and rules.start_side(-5e-16, 1e-15) == SLIDING


def test_exit_shift_only_takes_up_rounding_on_the_wrong_side():
    tol = 1e-15
    assert rules.exit_shift(PLUS, -2.2e-16, tol, False) == -2.2e-16     # wrong side, rounding
    assert rules.exit_shift(PLUS, 3e-16, tol, False) == 0.0             # right side
    assert rules.exit_shift(PLUS, -1e-12, tol, False) == 0.0            # beyond rounding
    assert rules.exit_shift(MINUS, 2.2e-16, tol, False) == 2.2e-16
    assert rules.exit_shift(MINUS, -1e-16, tol, False) == 0.0
    assert kernel.compiled_rule("exit_shift")(PLUS, -2.2e-16, tol, False) == -2.2e-16
    # after the exit was moved onto H, what is left is rounding, whatever its size
    assert rules.exit_shift(PLUS, -1.8e-15, tol, True) == -1.8e-15
    assert rules.exit_shift(PLUS, 1.8e-15, tol, True) == 0.0


def test_only_a_drift_beyond_rounding_on_the_wrong_side_is_projected():
    tol = 1e-15
    z, grad = np.array([-1.0, 1e-6, -1.0]), np.array([0.5, 0.0, 0.5])   # Hopf's H at an exit
    for drift in (rules.exit_drift, kernel.compiled_rule("exit_drift")):
        assert drift(PLUS, -5.7e-14, z, grad, tol) and drift(MINUS, 5.7e-14, z, grad, tol)
        assert not drift(PLUS, -5e-16, z, grad, tol)       # rounding: exit_shift's
        assert not drift(PLUS, 5.7e-14, z, grad, tol)      # the right side: left alone
        assert not drift(MINUS, -5.7e-14, z, grad, tol)
        # the dry-friction model's H = w - g1 x2 at w ~ 3.1: -3.6e-15 is its rounding
        assert not drift(PLUS, -3.6e-15, np.array([4.0, 0.0, 3.1]), np.array([0.0, -3.0, 1.0]),
                         tol)


@pytest.mark.parametrize("project", [rules.onto_switch, kernel.compiled_rule("onto_switch")])
def test_a_sliding_exit_is_moved_onto_the_switching_surface(project):
    # H = theta x1 + (1 - theta) y + 1 of the Hopf example: linear, so one step lands on it
    theta = 0.5
    grad = np.array([theta, 0.0, 1 - theta])
    z = np.array([-1.0 - 4e-14, 1.25e-6, -1.0 - 7e-14])     # drifted: H = -5.5e-14
    h = lambda zz: theta * zz[0] + (1 - theta) * zz[2] + 1.0
    before = z.copy()
    project(z, h(z), grad)
    assert abs(h(z)) <= 2.3e-16 < abs(h(before))
    assert z[1] == before[1]                                  # only along grad H
    np.testing.assert_allclose(z - before, -h(before) * grad / (grad @ grad), rtol=1e-6)
    flat = np.array([1.0, 2.0, 3.0])
    project(flat, 1e-3, np.zeros(3))                          # no gradient: left alone
    assert flat.tolist() == [1.0, 2.0, 3.0]


def test_zeno_span_is_relative_beyond_t_of_one():
    assert rules.accumulates(0.0, 1e-10, 1e-10)
    assert not rules.accumulates(0.0, 2e-10, 1e-10)
    assert rules.accumulates(1e6 - 1e-5, 1e6, 1e-10)     # 1e-5 <= 1e-10 * 1e6
    assert not np.isnan(rules.same_instant(1e-15, 1.0))


@pytest.mark.parametrize("first", (rules.section_first, kernel.compiled_rule("section_first")))
def test_a_section_hit_comes_first_before_or_at_the_instant_of_a_switch(first):
    """rules.section_first, in Python and as the kernel compiles it (which calls the
    compiled same_instant): a hit before min_time never counts; with no event so far (inf)
    every other hit does; against a switch the hit wins up to same_instant after it, not
    beyond; against another section's hit only a strictly earlier one wins."""
    xtol, t = 1e-15, 2.0
    tie = rules.same_instant(xtol, t)
    assert first(1.0, 0.0, np.inf, False, xtol)
    assert not first(1.0, 1.5, np.inf, False, xtol)          # before min_time
    assert first(1.5, 1.5, np.inf, False, xtol)              # at min_time
    assert first(t - 1e-9, 0.0, t, False, xtol)              # before the switch
    assert first(t + 0.5 * tie, 0.0, t, False, xtol)         # at its instant: the section
    assert first(t + tie, 0.0, t, False, xtol)
    assert not first(t + 2.0 * tie, 0.0, t, False, xtol)     # after it
    assert first(t - 1e-9, 0.0, t, True, xtol)               # before another section's hit
    assert not first(t, 0.0, t, True, xtol)                  # at it: the first found stays
    assert not first(t + 0.5 * tie, 0.0, t, True, xtol)
    assert not first(np.nan, 0.0, np.inf, False, xtol)       # no root: no hit


def test_crossing_predicates_are_the_same_on_scalars_arrays_and_compiled():
    values = np.array([-1.0, -_TINY, -0.0, 0.0, _TINY, 1.0])
    v0, v1 = np.meshgrid(values, values, indexing="ij")
    for pred in (rules.TO_NEG, rules.TO_NONNEG, rules.TO_NONPOS, rules.EITHER):
        table = rules.crosses(pred, v0, v1)  # numpy, elementwise (the Python driver)
        for i, j in np.ndindex(table.shape):
            assert bool(rules.crosses(pred, v0[i, j], v1[i, j])) == table[i, j]
            assert kernel.compiled_rule("crosses")(pred, v0[i, j], v1[i, j]) == table[i, j]
    # leaving region +: from H >= 0 to H < 0; region -: from H < 0 to H >= 0
    assert rules.crosses(rules.TO_NEG, 0.0, -1e-300) and not rules.crosses(rules.TO_NEG, -1.0, -2.0)
    assert rules.crosses(rules.TO_NONNEG, -1e-300, 0.0)
    assert rules.clamp(rules.TO_NEG, -1e-17) == 0.0 and rules.clamp(rules.TO_NONNEG, 0.0) < 0.0
    assert rules.far_side(rules.EITHER, 0.5) == rules.TO_NONPOS
    assert rules.section_pred(-1) == rules.TO_NONPOS and rules.section_pred(0) == rules.EITHER


_TINY = np.finfo(float).tiny


def test_hidden_extremum_and_graze():
    # region +: dH/dt from < 0 to >= 0 is a minimum of H; beyond touch_tol below 0 it
    # is a crossing, within it a touch
    assert rules.extremum_between(PLUS, -1.0, 0.0) and not rules.extremum_between(PLUS, 1.0, -1.0)
    assert rules.extremum_between(MINUS, 1.0, 0.0)
    assert rules.graze(PLUS, -2e-15, 1e-15) == rules.GRAZE_CROSSES
    assert rules.graze(PLUS, -5e-16, 1e-15) == rules.GRAZE_TOUCHES
    assert rules.graze(PLUS, 1e-3, 1e-15) == rules.GRAZE_NONE
    assert rules.graze(MINUS, 2e-15, 1e-15) == rules.GRAZE_CROSSES
    assert kernel.compiled_rule("graze")(MINUS, 2e-15, 1e-15) == rules.GRAZE_CROSSES
    assert rules.central_step(1.0, 0.0) == 0.0 and rules.central_step(1.0, np.nan) == 0.0
    assert not rules.slides_in_section(0.0, 0.0, 1.0, 1.0, 0.0)
    assert rules.slides_in_section(0.0, 1e-5, 1.0, -1.0, 0.0)
    assert not rules.slides_in_section(0.0, 1e-5, 1.0, -1.0, 0.5)


def test_no_model_imports_the_engine():
    # models hand the compiled engine a CompiledModel with filippov.abi's signatures;
    # the engine (fastmap and its kernel) may change its insides without a model noticing
    import ast
    from pathlib import Path
    models = Path(rules.__file__).parent / "models"
    for path in models.glob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.ImportFrom):
                mod = (node.module or "").split(".")[0]
                assert mod not in ("fastmap", "simulate", "kernel"), (path.name, node.module)


def test_a_dip_after_the_entry_moves_the_bracket_beyond_it():
    # leaving H into the region (dH/dt away from H) and heading back by the interval's
    # end: only then is the crossing back refined from the extremum
    for f in (rules.dips_and_returns, kernel.compiled_rule("dips_and_returns")):
        assert f(MINUS, -3.5e-3, 1e-2) and f(PLUS, 3.5e-3, -1e-2)
        assert not f(MINUS, 3.5e-3, 1e-2) and not f(MINUS, -1.0, -0.5)
        assert not f(PLUS, -3.5e-3, -1e-2) and not f(PLUS, 1.0, 0.5)


def test_exact_windows_grow_with_the_time_since_the_entry_during_the_transient():
    # h (the eps scale) at first, then as long as the time gone by, capped at h_slow,
    # and h_slow once the transient has passed -- on both engines
    for f in (rules.exact_window, kernel.compiled_rule("exact_window")):
        assert f(0.0, 1.0, 16.0, 40.0) == 1.0
        assert f(1.0, 1.0, 16.0, 40.0) == 1.0
        assert f(4.0, 1.0, 16.0, 40.0) == 4.0
        assert f(32.0, 1.0, 16.0, 40.0) == 16.0
        assert f(40.0, 1.0, 16.0, 40.0) == 16.0
        assert f(0.0, 1.0, 16.0, 0.0) == 16.0


def test_a_refined_root_walks_to_the_first_probe_past_the_crossing():
    # probes r, r + 2 ulp, r + 6 ulp, r + 14 ulp, ... (capped at tb) until one is past;
    # the compiled rule walks the same
    r0 = 1.0
    ulp = np.spacing(r0)
    for probe in (rules.far_side_probe, kernel.compiled_rule("far_side_probe")):
        def walk(flip, tb):
            done, r, step, seen = False, r0, 0.0, []
            while not done:
                seen.append(r)
                done, r, step = probe(r, step, tb, r >= flip)
            return r, seen
        r, seen = walk(r0 + 10 * ulp, 2.0)
        assert r == r0 + 14 * ulp and seen == [r0 + k * ulp for k in (0, 2, 6, 14)]
        assert walk(r0, 2.0)[0] == r0                         # already past
        assert walk(3.0, r0 + 5 * ulp)[0] == r0 + 5 * ulp     # none past before tb


def test_a_leave_crossing_ends_the_stay_into_the_region_next_mode_takes():
    """rules.ended_by names what a leave function's sign change ends a stay with, and
    next_mode takes the stay on from there: h in a region switches; while sliding a
    reaching 0 leaves into region -, b into region +."""
    assert rules.ended_by(PLUS, 0) == rules.ended_by(MINUS, 0) == rules.SWITCH
    assert rules.ended_by(SLIDING, 0) == rules.EXIT_MINUS
    assert rules.ended_by(SLIDING, 1) == rules.EXIT_PLUS
    for q, region in ((0, MINUS), (1, PLUS)):
        for a, b in itertools.product(SPEEDS, SPEEDS):
            assert rules.next_mode(SLIDING, rules.ended_by(SLIDING, q), a, b) == region


def _sine_samples(w_dt, phase, n=5):
    ts = np.arange(n) * 0.5
    w = w_dt / 0.5
    return np.sin(w * ts + phase), w * np.cos(w * ts + phase), ts


@pytest.mark.parametrize("slopes", [False, True])
def test_samples_resolve_a_sine_when_dense_and_not_when_sparse(slopes):
    """rules.resolves on sin(w t) at every phase: resolved at w dt <= 0.8 (both with the
    slopes and from the values alone), not at w dt >= 2 (where two extrema fit between
    samples at w dt >= pi); the compiled rule decides as Python does."""
    compiled = kernel.compiled_rule("resolves")
    for phase in np.linspace(0.0, 2.0 * np.pi, 61):
        for w_dt, expected in ((0.1, True), (0.5, True), (0.8, True), (2.0, False),
                               (3.0, False), (3.8, False)):
            v, d, ts = _sine_samples(w_dt, phase, n=9)
            got = rules.resolves(v, d, ts, 9, slopes, 0.0)
            assert got == expected, (w_dt, phase)
            assert compiled(v, d, ts, 9, slopes, 0.0) == got


def test_slopes_give_away_samples_that_alias_a_fast_function():
    """Samples 5 periods less 0.18 rad apart look like a slow sine from their values; the
    slopes sampled with them do not agree with it (Simpson's rule on them)."""
    w_dt = 5 * 2 * np.pi - 0.18
    found = {True: 0, False: 0}
    for phase in np.linspace(0.0, 2.0 * np.pi, 61):
        v, d, ts = _sine_samples(w_dt, phase)
        assert not rules.resolves(v, d, ts, 5, True, 0.0)
        found[rules.resolves(v, d, ts, 5, False, 0.0)] += 1
    assert found[True] > 0  # values alone cannot tell (sections: docs/tutorial.md)


def test_rounding_and_short_windows_are_resolved():
    ts = np.arange(5) * 0.25
    noisy = 1.0 + np.array([0.0, 2.2e-16, -2.2e-16, 4.4e-16, 0.0])
    assert rules.resolves(noisy, np.zeros(5), ts, 5, True, 0.0)
    assert rules.resolves(np.zeros(5), np.zeros(5), ts, 5, True, 0.0)   # constant
    assert rules.resolves(np.array([0.0, 5.0, -3.0, 1.0]), np.zeros(4), ts, 4, True, 0.0)  # < 5


def test_a_cut_window_is_judged_only_with_five_samples_kept():
    # kept samples of a window of n cut at one not finite (-1: not cut); a window of
    # fewer than five is never judged (samples_per_step < 4), cut or not
    assert rules.cut_resolves(-1, 17)
    assert [rules.cut_resolves(k, 17) for k in range(2, 7)] == [False] * 3 + [True] * 2
    assert rules.cut_resolves(2, 4) and rules.cut_resolves(3, 4)


def test_the_last_run_of_five_is_judged_too():
    """Runs of five from sample 0 at a stride of 4, and the last five: with 7 samples a
    wiggle in samples 4..6 is seen."""
    ts = np.arange(7) * 0.1
    v = 0.1 * ts
    assert rules.resolves(v, np.full(7, 0.1), ts, 7, True, 0.0)
    v2 = v.copy()
    v2[5] += 1.0
    assert not rules.resolves(v2, np.full(7, 0.1), ts, 7, False, 0.0)
