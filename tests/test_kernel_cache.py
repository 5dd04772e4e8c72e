"""The compiled kernel's on-disk cache is dropped when any file whose code the kernel
contains has changed (filippov.kernel.driver.KERNEL_SOURCES): numba itself checks only the
file of each cached function, so an edit of the rule book (rules.py) would otherwise
leave the kernel running the old rules while the reference driver runs the new ones."""
import os
import subprocess
import sys
from pathlib import Path

import pytest

SRC = str(Path(__file__).resolve().parents[1] / "src")

# compiles one small helper of the kernel into the cache, after the check (compiled for
# its signature: the kernel's helpers have no CPython wrapper to call from here)
_RUN = """
from numba import types
from filippov.kernel import base, driver
index = lambda: len(base._dot._cache._cache_file._load_index())
before = index()
driver._fresh_cache()
after = index()
base._dot.compile((types.float64[::1], types.float64[::1]))
print(before, after, index())
"""


def _run(cache_dir):
    env = dict(os.environ, NUMBA_CACHE_DIR=str(cache_dir),
               PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    out = subprocess.run([sys.executable, "-c", _RUN], env=env, capture_output=True,
                         text=True, check=True)
    return tuple(int(x) for x in out.stdout.split())


def test_a_cache_written_from_other_sources_is_dropped(tmp_path):
    from filippov.kernel import driver

    assert _run(tmp_path) == (0, 0, 1)           # a fresh cache: compiled and stored
    stamps = list(tmp_path.rglob("kernel.sha256"))
    assert len(stamps) == 1 and stamps[0].read_text() == driver._kernel_stamp()
    assert _run(tmp_path) == (1, 1, 1)           # same sources: the cache is kept
    stamps[0].write_text("written by other sources")
    assert _run(tmp_path) == (1, 0, 1)           # dropped, compiled again, restamped
    assert stamps[0].read_text() == driver._kernel_stamp()


def test_the_kernel_can_be_cached():
    # A runtime address compiled into the kernel (numba's "dynamic globals": e.g. a
    # compiled function handed to another as a value) makes it uncacheable, and every
    # process would compile it again (~20 s; seen with a rule taking the event function
    # as an argument). Loaded from the cache, it was cached; compiled here, it must be
    # free of such addresses.
    from filippov.kernel import driver
    for derivatives in (False, True):
        if not driver.compile_kernel(derivatives):
            batch = driver.kernel(derivatives)
            assert not batch.overloads[batch.signatures[0]].library.has_dynamic_globals


# a process that compiles the plain kernel or loads it from the cache, then reports which,
# and (when it compiled) what it compiled: every helper once, none of the dP/dz code
_COLD = """
import sys
from filippov.fastmap import compile_kernel
from filippov.kernel import derivative
hit = compile_kernel(False)
kernel = [m for name, m in sys.modules.items() if name.startswith("filippov.kernel.")]
twice = sorted(f"{m.__name__}.{k}" for m in kernel for k, f in vars(m).items()
               if len(getattr(f, "signatures", ())) > 1)
print(hit)
print("compiled more than once:", *twice)
print(sum(len(f.signatures) for f in vars(derivative).values()
          if getattr(getattr(f, "py_func", None), "__module__", None) == derivative.__name__))
"""


@pytest.fixture(scope="module")
def cold_pair(tmp_path_factory):
    """Two processes started together on an empty numba cache, each running _COLD: one
    compile of the plain kernel (about 90 s on CI's machines) that the tests below share."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path_factory.mktemp("numba")),
               PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    procs = [subprocess.Popen([sys.executable, "-c", _COLD], env=env, stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True) for _ in range(2)]
    outs = [p.communicate(timeout=900) for p in procs]
    for p, (_, err) in zip(procs, outs):
        assert p.returncode == 0, err
    return sorted((out.splitlines() for out, _ in outs), key=lambda lines: lines[0])


def test_processes_that_start_together_compile_the_kernel_once(cold_pair):
    """Jobs that start at once (a workflow's first jobs, one per core) share one compile:
    the one that takes the compile lock compiles and caches, the others wait and load
    (without the lock each compiled the same kernel: 19-40 s of CPU each)."""
    assert [lines[0] for lines in cold_pair] == ["False", "True"]  # compiled, then loaded


def test_the_plain_kernel_does_not_compile_the_derivative_code(cold_pair):
    # the event's dP/dz hooks are built again for the plain build (kernel.driver.
    # _without_derivatives), where numba prunes them: returns without dP/dz never wait
    # for the derivative code to compile
    compiled = cold_pair[0]
    assert compiled[0] == "False" and compiled[-1] == "0"
    # and every helper of the plain build is compiled once: a literal argument (a Python
    # int constant) would compile one specialization per value
    # (docs/decisions.md#kernel-codes-are-numpy-integers)
    assert compiled[-2] == "compiled more than once:"


# the plain build's copies are dispatchers of their own (driver._PLAIN), not module names:
# a copy compiled as a call (_begin) has a cache that must be dropped with the rest
_PLAIN_RUN = """
from pathlib import Path
from filippov.kernel import driver
stamp = Path(driver._batch._cache.cache_path) / "kernel.sha256"
stamp.parent.mkdir(parents=True, exist_ok=True)
stamp.write_text("written by other sources")
flushed = []
for name, obj in driver._PLAIN.items():
    if hasattr(obj, "_cache"):
        obj._cache.flush = lambda name=name: flushed.append(name)
driver._fresh_cache()
print(" ".join(sorted(flushed)))
"""


def test_the_plain_builds_own_copies_are_dropped_too(tmp_path):
    from filippov.kernel import driver

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path),
               PYTHONPATH=SRC + os.pathsep + os.environ.get("PYTHONPATH", ""))
    out = subprocess.run([sys.executable, "-c", _PLAIN_RUN], env=env, capture_output=True,
                         text=True, check=True)
    assert set(out.stdout.split()) == set(driver._PLAIN)   # _begin among them


def test_the_loops_pieces_compiled_inside_a_factory_are_dropped_with_the_kernel():
    """The event search's refinement and root of a leave function are compiled by the
    kernel inside loop.interval.make_window_event (no module's attribute): a stale cache
    of theirs is flushed with the kernel's, reached through the closures (an index that
    names a type since removed would fail to unpickle before numba checks its stamp)."""
    from filippov.kernel import driver, scan

    names = {f.py_func.__name__ for f in driver._compiled([scan._window_event])}
    assert {"window_event", "refine", "leave_root"} <= names
