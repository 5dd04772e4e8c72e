"""The benchmarks' timing convention (filippov_paper.benchmarks.timing): a warm-up call that
is not timed, at least ``min_rounds`` timed rounds, the median shown and the min kept.

No absolute time is asserted (machines are shared and noisy): the helper is tested on
a fake clock, and the work-precision sweep against a repeat of itself.
"""
import itertools
from pathlib import Path

import numpy as np
import pytest

from filippov_paper.benchmarks import timing, work_precision as wp

ROOT = Path(__file__).resolve().parents[1]


class FakeClock:
    """A clock that a call of ``fn`` advances by the next of ``durations``."""

    def __init__(self, durations):
        self.now, self.durations, self.calls = 0.0, iter(durations), 0

    def __call__(self):
        return self.now

    def fn(self):
        self.calls += 1
        self.now += next(self.durations)
        return self.calls


def test_measure_warms_up_untimed_then_times_at_least_min_rounds():
    # the warm-up call takes 8 s (a compile), the timed rounds 3, 1, 2 s
    clock = FakeClock([8.0, 3.0, 1.0, 2.0])
    t = timing.measure(clock.fn, warmup=1, min_rounds=3, min_time=0.0, clock=clock)
    assert clock.calls == 4                      # one warm-up call + three rounds
    assert (t.rounds, t.warmup) == (3, 1)
    assert (t.median, t.min, t.total) == (2.0, 1.0, 6.0)   # the 8 s are in none of them
    assert t.value == 4 and t.shown == t.median  # the last round's result; the median shown
    # no warm-up: the first call is a round like the others
    clock = FakeClock([8.0, 3.0, 1.0])
    t = timing.measure(clock.fn, warmup=0, min_rounds=3, min_time=0.0, clock=clock)
    assert clock.calls == 3 and t.median == 3.0 and t.min == 1.0


def test_measure_times_more_rounds_until_min_time_within_max_rounds():
    clock = FakeClock(itertools.repeat(0.0625))  # exact in binary: the sum is too
    t = timing.measure(clock.fn, min_rounds=3, min_time=0.5, clock=clock)
    assert t.rounds == 8 and clock.calls == 1 + 8 and t.total == 0.5
    # a slow call: min_rounds still holds, whatever min_time says
    clock = FakeClock(itertools.repeat(10.0))
    assert timing.measure(clock.fn, min_rounds=3, min_time=0.5, clock=clock).rounds == 3
    # a call too fast to reach min_time: capped at max_rounds
    clock = FakeClock(itertools.repeat(0.0))
    t = timing.measure(clock.fn, min_rounds=3, min_time=1.0, max_rounds=50, clock=clock)
    assert t.rounds == 50 and clock.calls == 51
    for bad in ({"min_rounds": 0}, {"warmup": -1}, {"min_rounds": 5, "max_rounds": 4},
                {"min_time": float("nan")}):
        with pytest.raises(ValueError):
            timing.measure(clock.fn, **bad)


def test_measure_lets_a_failure_through():
    def fail():
        raise RuntimeError("no return")
    with pytest.raises(RuntimeError, match="no return"):
        timing.measure(fail)


def test_the_report_names_the_statistic_the_benchmarks_show():
    # the captions of the work-precision table and figure say "median" in words: the
    # statistic of filippov_paper.benchmarks.timing (the sentence with numbers uses macros)
    assert timing.STATISTIC == "median"
    attrs = timing.describe(min_rounds=4, min_time=0.5)
    assert attrs["timing_statistic"] == "median" and attrs["timing_min_rounds"] == 4
    text = (ROOT / "paper" / "sec_bench.tex").read_text()
    timed = [c.replace("\n", " ").split(r"\label")[0] for c in text.split(r"\caption{")[1:]
             if "wall time" in c.replace("\n", " ")]
    assert len(timed) >= 2 and all(f"{timing.STATISTIC} wall time" in c for c in timed)
    assert r"\rpBenchStatistic" in text


def test_first_cell_of_a_family_is_no_outlier_against_a_repeat(tmp_path, monkeypatch):
    # the compiled DOP853 pieces of the Hopf model generated and compiled afresh (an
    # empty cache, as in a fresh clone): the first call of the family pays ~1 s for it,
    # every later call ~1 ms. The sweep's first cell of the family must not contain that
    # (it did: with the default build's settings it was timed once, 866 ms against 3 ms).
    from filippov import codegen

    monkeypatch.setenv("FILIPPOV_CACHE_DIR", str(tmp_path / "cache"))
    monkeypatch.setattr(codegen, "_LOADED", {})
    prob = wp.fig04_problems(every=97)[0].subset([0, 5, -1])
    fams = [("project compiled DOP853", [1e-6, 1e-8])]
    settings = {"repeat": wp.BUILD["repeat"], "time_cap": wp.BUILD["time_cap"],
                "min_time": 0.05}
    first = wp.run([prob], fams, log=lambda s: None, **settings)
    again = wp.run([prob], fams, log=lambda s: None, **settings)  # everything warm now
    assert np.all(first.status.values == "ok") and np.all(again.status.values == "ok")
    for ds in (first, again):
        assert np.all(ds.runs.values >= settings["repeat"])
        assert np.all(ds.wall_time_min.values <= ds.wall_time.values)
        assert ds.attrs["timing_statistic"] == "median" and ds.attrs["timing_warmup"] == 1
    t_first, t_again = float(first.wall_time[0, 0]), float(again.wall_time[0, 0])
    assert t_first <= 5 * t_again, (t_first, t_again)


def test_quartiles_are_numpy_s_and_the_timing_keeps_the_spread():
    for times in ([3.0], [3.0, 1.0], [3.0, 1.0, 2.0], [5.0, 1.0, 2.0, 9.0, 4.0, 7.0]):
        q1, med, q3 = timing.quartiles(times)
        assert (q1, med, q3) == tuple(np.percentile(times, [25, 50, 75]))
    t = timing.of_rounds([5.0, 1.0, 2.0, 9.0], warmup=1, value="last")
    assert (t.min, t.q1, t.median, t.q3, t.max) == (1.0, 1.75, 3.5, 6.0, 9.0)
    assert (t.rounds, t.warmup, t.total, t.value) == (4, 1, 17.0, "last")
    with pytest.raises(ValueError):
        timing.quartiles([])


def test_measure_interleaved_takes_the_rounds_of_all_in_passes():
    """Round k of every function before round k+1 of any (asv's rounds), each function's
    warm-up just before its first round, and in the end the rounds `measure` would take."""
    order = []
    now = [0.0]

    def clock():
        return now[0]

    def make(name, seconds):
        def fn():
            order.append(name)
            now[0] += seconds
            return name
        return fn

    # a slow function (1 s a call: min_rounds decide) and a fast one (0.0625 s: min_time)
    fns = [make("slow", 1.0), make("fast", 0.0625)]
    out = timing.measure_interleaved(fns, warmup=lambda k: 1, min_rounds=3, min_time=0.5,
                                     clock=clock)
    assert [t.rounds for t in out] == [3, 8] and [t.warmup for t in out] == [1, 1]
    assert out[1].total == 0.5 and out[0].value == "slow"
    # pass 1: slow's warm-up and round 1, fast's warm-up and rounds up to a third of
    # min_time; pass 2: each to two thirds; pass 3: the rest
    assert order == (["slow", "slow"] + ["fast"] * 4 + ["slow"] + ["fast"] * 3
                     + ["slow"] + ["fast"] * 2)
    # the same rule as measure(): a repeat of it with one function in one pass
    now[0], order[:] = 0.0, []
    alone = timing.measure_interleaved([fns[1]], warmup=1, min_rounds=3, min_time=0.5,
                                       passes=1, clock=clock)[0]
    now[0] = 0.0
    assert alone.rounds == timing.measure(fns[1], warmup=1, min_rounds=3, min_time=0.5,
                                          clock=clock).rounds


def test_measure_interleaved_drops_a_function_that_fails_and_goes_on():
    calls = []

    def ok():
        calls.append("ok")

    def bad():
        calls.append("bad")
        raise RuntimeError("no return")

    out = timing.measure_interleaved([bad, ok], warmup=0, min_rounds=3, min_time=0.0)
    assert isinstance(out[0], RuntimeError) and out[1].rounds == 3
    assert calls == ["bad", "ok", "ok", "ok"]   # bad is not called in the later passes
    with pytest.raises(ValueError):
        timing.measure_interleaved([ok], passes=0)


def test_machine_attrs_name_the_machine_and_the_versions():
    import platform

    import numpy
    import scipy

    attrs = timing.machine_attrs()
    assert attrs["machine_cpu"] and attrs["cpus"] >= 1
    assert attrs["python_version"] == platform.python_version()
    assert (attrs["numpy_version"], attrs["scipy_version"]) == (numpy.__version__,
                                                                scipy.__version__)
    assert "numba_version" in attrs
