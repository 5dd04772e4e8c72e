"""Parameter sweeps in one call (fastmap.sweep_returns, attractors.iterate_sweep): each
start under its own model gives what compute_returns gives for that model alone, bit for
bit, for any number of threads; models that differ in more than their parameter values
are refused, naming the field."""
import numpy as np
import pytest

from filippov import attractors, fastmap
from filippov.models import hopf

EPS, THETA, OMEGA = 0.01, -0.5, 8 * np.pi
T_MAX = 4.0 * 2 * np.pi / OMEGA
MUS = 1.0 + 0.01 * np.linspace(-0.6, 0.6, 12)


def models_and_starts(theta=THETA, sliding=False):
    cms = [hopf.compiled(EPS, theta, mu, OMEGA, sliding=sliding) for mu in MUS]
    starts = np.array([[0.0, np.sqrt(mu), 0.0] for mu in MUS])
    return cms, starts


def assert_row_identical(batch, i, alone):
    for name, value in vars(alone).items():
        other = getattr(batch, name)
        if value is None:
            assert other is None, name
            continue
        assert np.array_equal(other[i], value[0], equal_nan=True), (name, i, other[i], value[0])


@pytest.mark.parametrize("theta,sliding", [(-0.5, False), (0.5, True)])
@pytest.mark.parametrize("workers", [1, 3])
def test_a_sweep_gives_each_point_what_its_own_call_gives(monkeypatch, theta, sliding,
                                                          workers):
    monkeypatch.setattr(fastmap, "MIN_RETURNS_PER_SLICE", 1)  # thread even this batch
    cms, starts = models_and_starts(theta, sliding)
    ages = np.linspace(0.0, 0.3, len(cms))
    options = dict(iterations=20, keep=4, jacobian=True)
    sweep = fastmap.sweep_returns(cms, starts, T_MAX, start_age=ages, workers=workers,
                                  **options)
    assert np.all(sweep.status == fastmap.OK)
    assert np.unique(sweep.state[:, 1]).size == len(cms)  # the parameters did differ
    for i, (cm, z) in enumerate(zip(cms, starts)):
        alone = fastmap.compute_returns(cm, z[None], T_MAX, start_age=ages[i], workers=1,
                                        **options)
        assert_row_identical(sweep, i, alone)


def test_iterate_sweep_rows_are_iterate_and_settle_takes_them():
    cms, starts = models_and_starts()
    runs = attractors.iterate_sweep(cms, starts, transient=30, keep=8, t_max=T_MAX)
    sigma = EPS  # theta < 0: the attractor's scale is eps
    for i in (0, 5, 11):
        alone = attractors.iterate(cms[i], starts[i], transient=30, keep=8, t_max=T_MAX)
        assert_row_identical(runs, i, alone)
        kw = dict(coordinate=1, transient=30, keep=8, t_max=T_MAX, scale=sigma,
                  max_period=4, window=(0.9, 1.1))
        a = attractors.settle(cms[i], starts[i], **kw)
        b = attractors.settle(cms[i], starts[i], first=attractors.row(runs, i), **kw)
        assert a.period == b.period and a.status == b.status
        assert np.array_equal(a.values, b.values, equal_nan=True)
    with pytest.raises(ValueError, match="first: expected the run of one start with 30 \\+ 8"):
        attractors.settle(cms[0], starts[0], first=runs, **kw)  # every row, not one
    with pytest.raises(ValueError, match="with jacobian=True"):
        attractors.settle(cms[0], starts[0], first=attractors.row(runs, 0), lyapunov=True,
                          **kw)


def test_models_that_differ_beyond_their_parameters_are_refused():
    cms, starts = models_and_starts()
    other_eps = hopf.compiled(2 * EPS, THETA, 1.0, OMEGA, sliding=False)  # its sample_step
    with pytest.raises(ValueError, match=r"cmodels\[1\]\.sample_step .* parameter values only"):
        fastmap.sweep_returns([cms[0], other_eps], starts[:2], T_MAX)
    sliding = hopf.compiled(EPS, THETA, 1.0, OMEGA, sliding=True)
    with pytest.raises(ValueError, match=r"cmodels\[1\]\.sliding"):
        fastmap.sweep_returns([cms[0], sliding], starts[:2], T_MAX)


def test_bad_sweep_input_is_refused_naming_it():
    cms, starts = models_and_starts()
    with pytest.raises(ValueError, match="one start point per model"):
        fastmap.sweep_returns(cms, starts[:3], T_MAX)
    with pytest.raises(TypeError, match="non-empty sequence of CompiledModel"):
        fastmap.sweep_returns([], starts[:0], T_MAX)
    with pytest.raises(TypeError, match="unexpected options.*'iteration'"):
        fastmap.sweep_returns(cms, starts, T_MAX, iteration=3)
    with pytest.raises(ValueError, match="iterations must be an integer"):
        fastmap.sweep_returns(cms, starts, T_MAX, iterations=0)
    with pytest.raises(ValueError, match="need transient >= 0 and keep >= 1"):
        attractors.iterate_sweep(cms, starts, transient=3, keep=0, t_max=T_MAX)
