"""Parallel batches (compute_returns(workers=...)): the same results bit for bit for any
number of threads, every output array; the threads really split the batch; and the
default number of workers follows FILIPPOV_WORKERS."""
import threading
import time

import numpy as np
import pytest

from filippov import fastmap
from filippov.kernel import driver
from filippov.models import hopf

EPS, MU, OMEGA = 0.01, 1.0, 8 * np.pi
T_MAX = 4.0 * 2 * np.pi / OMEGA
M = 50  # starts in a batch


def starts(theta):
    # along the section around the cycle (theta < 0: some starts on the far side of
    # the grazing point x2 = 1, theta > 0: sliding returns)
    x2 = np.linspace(0.9, 1.1, M)
    return np.stack([np.zeros(M), x2, np.zeros(M)], axis=1)


@pytest.fixture
def split_small(monkeypatch):
    """Thread even a small batch (the default keeps a batch this small on one thread),
    and record which thread ran which slice of it."""
    monkeypatch.setattr(fastmap, "MIN_RETURNS_PER_SLICE", 1)
    calls, kernel, lock = [], fastmap.kernel, threading.Lock()

    def recording(derivatives=False):
        batch = kernel(derivatives)

        def call(*args):
            with lock:
                calls.append((threading.get_ident(), args[-3].shape[0]))
            # a slice of a few returns takes microseconds: without a pause the thread that
            # took the first slice could be done with it before the pool starts another
            # (ThreadPoolExecutor starts a thread per task only while none is idle), and
            # the batch ran on one thread however many were allowed (seen under load)
            time.sleep(0.01)
            return batch(*args)
        return call

    monkeypatch.setattr(fastmap, "kernel", recording)
    return calls


def assert_identical(a: fastmap.BatchReturns, b: fastmap.BatchReturns):
    for name, x in vars(a).items():
        y = getattr(b, name)
        if x is None:
            assert y is None, name
            continue
        assert x.dtype == y.dtype and x.shape == y.shape, name
        # bit for bit: NaN where NaN, and the same bytes elsewhere (-0.0 included)
        assert x.tobytes() == y.tobytes(), name


CASES = {
    "exact flows": dict(theta=-0.5, exact=True, options={}),
    "integrated flows": dict(theta=-0.5, exact=False, options={}),
    "sliding, integrated": dict(theta=0.5, exact=True, options={}),
    "jacobian": dict(theta=0.5, exact=True, options={"jacobian": True}),
    "iterations and keep": dict(theta=-0.5, exact=True,
                                options={"iterations": 7, "keep": 3, "jacobian": True}),
    "ages": dict(theta=0.5, exact=True, options={"iterations": 3, "keep": 2,
                                                 "start_age": np.linspace(0, 0.2, M)}),
}


@pytest.mark.parametrize("case", CASES)
def test_any_number_of_workers_gives_the_same_results(case, split_small):
    c = CASES[case]
    cm = hopf.compiled(EPS, c["theta"], MU, OMEGA, exact=c["exact"])
    z0 = starts(c["theta"])
    one = fastmap.compute_returns(cm, z0, T_MAX, workers=1, **c["options"])
    assert len(split_small) == 1  # one worker: the whole batch in one call
    assert np.count_nonzero(one.status == fastmap.OK) > M // 2  # a batch that returns
    if c["options"].get("jacobian"):
        assert np.isfinite(one.jacobian).any()
    if c["options"].get("keep"):
        assert np.isfinite(one.orbit).all(axis=(1, 2)).any()
    for workers in (2, 3):
        split_small.clear()
        many = fastmap.compute_returns(cm, z0, T_MAX, workers=workers, **c["options"])
        # the batch was cut into slices that cover it, run on more than one thread
        assert sum(size for _, size in split_small) == M
        assert len(split_small) > 1
        assert 1 < len({ident for ident, _ in split_small}) <= workers
        assert_identical(one, many)


def test_a_failing_start_fails_alone_whatever_the_slices(split_small):
    cm = hopf.compiled(EPS, -0.5, MU, OMEGA)
    z0 = starts(-0.5)
    z0[17] = [0.0, 1e6, 0.0]  # far out: no return within t_max
    z0[33] = [0.0, 1e150, 0.0]
    one = fastmap.compute_returns(cm, z0, T_MAX, workers=1, iterations=4, keep=2)
    assert one.status[17] != fastmap.OK and one.status[33] != fastmap.OK
    assert np.count_nonzero(one.status == fastmap.OK) == M - 2
    assert np.isnan(one.orbit[[17, 33]]).all()
    for workers in (2, 3):
        assert_identical(one, fastmap.compute_returns(cm, z0, T_MAX, workers=workers,
                                                      iterations=4, keep=2))


def test_a_slice_is_computed_as_in_the_whole_batch():
    # what the bit-for-bit results rest on: a start's outputs do not depend on the
    # starts before it in the same kernel call (no state carried between starts)
    cm = hopf.compiled(EPS, 0.5, MU, OMEGA)
    z0 = starts(0.5)
    whole = fastmap.compute_returns(cm, z0, T_MAX, workers=1, jacobian=True, iterations=2,
                                    keep=1)
    for lo in (1, 25, 49):
        part = fastmap.compute_returns(cm, z0[lo:], T_MAX, workers=1, jacobian=True,
                                       iterations=2, keep=1)
        for name, x in vars(whole).items():
            if x is not None:
                assert x[lo:].tobytes() == getattr(part, name).tobytes(), (lo, name)


@pytest.mark.parametrize("bad", [0, -1, 1.5, "2", True])
def test_workers_out_of_range_is_refused(bad):
    cm = hopf.compiled(EPS, -0.5, MU, OMEGA)
    with pytest.raises(ValueError, match="workers"):
        fastmap.compute_returns(cm, starts(-0.5)[:2], T_MAX, workers=bad)


def test_the_default_follows_the_environment(monkeypatch):
    monkeypatch.setenv("FILIPPOV_WORKERS", "3")
    assert fastmap.default_workers() == 3
    monkeypatch.setenv("FILIPPOV_WORKERS", "0")
    with pytest.raises(ValueError, match="FILIPPOV_WORKERS"):
        fastmap.default_workers()
    monkeypatch.delenv("FILIPPOV_WORKERS")
    assert 1 <= fastmap.default_workers() <= (__import__("os").cpu_count() or 1)


def test_slices():
    # small batches stay on the calling thread; a large one is cut into contiguous
    # slices covering it, a few per worker
    per = fastmap.MIN_RETURNS_PER_SLICE
    assert fastmap._slices(1, 1, 8) == [(0, 1)]
    assert fastmap._slices(per, 1, 8) == [(0, per)]
    assert fastmap._slices(10 * per, 1, 1) == [(0, 10 * per)]
    for m, iterations, workers in [(2 * per, 1, 2), (1000, 100, 3), (7, 10 * per, 2),
                                   (100_000, 1, 64)]:
        s = fastmap._slices(m, iterations, workers)
        assert s[0][0] == 0 and s[-1][1] == m
        assert all(a[1] == b[0] for a, b in zip(s, s[1:]))
        assert all(hi - lo >= 2 for lo, hi in s)
        assert 1 < len(s) <= fastmap.SLICES_PER_WORKER * workers
        assert all((hi - lo) * iterations >= per * 0.99 for lo, hi in s)


def test_the_kernel_releases_the_gil():
    # both builds: without it the threads would run one after another
    assert driver._batch.targetoptions.get("nogil") is True
    assert driver._batch_plain.targetoptions.get("nogil") is True
