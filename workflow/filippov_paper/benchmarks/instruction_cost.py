"""What one return costs in machine instructions, counted by valgrind (callgrind).

Run ``python -m filippov_paper.benchmarks.instruction_cost`` (part of ``make bench``).
Wall-clock tables on a shared machine cannot resolve a change of a few per cent (one
tree's two rounds of :mod:`~filippov_paper.benchmarks.attractor_cost` differ by up to
1.7x here); an instruction count under ``valgrind --tool=callgrind`` is the same on every
run of the same code and inputs, whatever else the machine does. For each case of
:data:`attractor_cost.CASES` and each build (plain, with dP/dz) one process iterates the
Hopf map ``--returns`` and then ``2 x --returns`` times from the cycle's point, in one
:func:`filippov.fastmap.compute_returns` call each; callgrind dumps its counters before
every call of ``getresgid`` (``--dump-before=getresgid``: the probe calls
``os.getresgid()`` between its phases; :data:`MARK` says why that one), so a return
costs (I(2N) - I(N)) / N instructions, the import, the warm-up and the loading
cancelled out.

The kernel is compiled natively first, for numba's generic x86-64 CPU
(``NUMBA_CPU_NAME=generic``), into a cache of its own: valgrind's CPU reports other
features than the host's, so with the host's CPU numba would compile again under valgrind
(about 40 minutes); with the generic CPU both processes key the cache alike and valgrind
loads it (checked: the run is refused if it compiled). The counts are therefore of the
generic build, not of the host-tuned one a user runs: they compare two trees, not seconds.
``--cold 1`` counts the cold compile too (the import with the plain kernel, then the
dP/dz build; a fresh cache under valgrind, about 40 minutes).
"""
from __future__ import annotations

import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import xarray as xr

from filippov.io import finalize
from filippov_paper.benchmarks import command_line
from filippov_paper.benchmarks.attractor_cost import CASES, OMEGA, case_coords

BUILDS = ("plain", "dpdz")

#: the C function whose every call ends a phase of a probe (callgrind's --dump-before).
#: Not getppid, the first choice: a cold compile at 81afc72 entered getppid once more,
#: from no probe line (a fourth dump, 23 G instructions into the plain build); no shared
#: library of the environment imports getresgid (nm -D), and no Python code here calls it
MARK = "getresgid"

#: the probe: per case and build, a warm-up, then N and 2N returns, each phase ended by
#: os.getresgid() (a callgrind dump); prints whether the kernel's builds came from the cache
_PROBE = """
import json, os, sys
import numpy as np
from filippov.analytic import limit_map
from filippov.fastmap import OK, compile_kernel, compute_returns
from filippov.models import hopf
cases, n, omega = json.loads(sys.argv[1]), int(sys.argv[2]), float(sys.argv[3])
loaded = [compile_kernel(), compile_kernel(derivatives=True)]
for th, eps, s in cases:
    mu = 1.0 + s * limit_map.scale(eps, th)
    cm = hopf.compiled(eps, th, mu, omega, sliding=th > 0)
    start = np.array([[0.0, np.sqrt(mu), 0.0]])
    for jac in (False, True):
        compute_returns(cm, start, 1.0, iterations=2, keep=1, jacobian=jac)
        os.getresgid()
        for k in (n, 2 * n):
            out = compute_returns(cm, start, 1.0, iterations=k, keep=1, jacobian=jac)
            if out.status[0] != OK:
                sys.exit(f"theta={th}, eps={eps}: return status {out.status[0]}")
            os.getresgid()
print(json.dumps({"loaded": [bool(x) for x in loaded]}))
"""

#: the cold compile: import, the plain kernel, the dP/dz build, each ended by a dump
_COMPILE_PROBE = """
import os
from filippov.fastmap import compile_kernel
os.getresgid()
compile_kernel()
os.getresgid()
compile_kernel(derivatives=True)
os.getresgid()
"""


def dump_counts(out_file: str) -> list[int]:
    """The instruction totals of callgrind's numbered dumps of ``out_file`` (the file
    given to --callgrind-out-file), in order: each dump's 'summary:' line, the counts
    since the dump before."""
    dumps = sorted(Path(out_file).parent.glob(Path(out_file).name + ".*"),
                   key=lambda p: int(p.suffix[1:]))
    counts = []
    for p in dumps:
        m = re.search(r"^summary: (\d+)", p.read_text(), re.M)
        if m is None:
            raise ValueError(f"{p}: no 'summary:' line (not a callgrind dump?)")
        counts.append(int(m.group(1)))
    return counts


def per_return(counts: list[int], n: int, cases: int) -> np.ndarray:
    """(case, build) instructions per return from the probe's dumps: per case and build
    the dumps (warm-up, N returns, 2N returns); (I(2N) - I(N)) / N."""
    if len(counts) != 3 * len(BUILDS) * cases:
        raise ValueError(f"expected {3 * len(BUILDS) * cases} callgrind dumps (3 per case "
                         f"and build), got {len(counts)}: did something else call {MARK}?")
    c = np.asarray(counts, dtype=float).reshape(cases, len(BUILDS), 3)
    return (c[:, :, 2] - c[:, :, 1]) / n


def _valgrind() -> str:
    path = shutil.which("valgrind")
    if path is None:
        raise RuntimeError("instruction_cost needs valgrind (callgrind) on PATH: install "
                           "Debian's valgrind package")
    return path


def _run(cmd: list[str], env: dict, what: str) -> str:
    run = subprocess.run(cmd, env=env, capture_output=True, text=True, check=False)
    if run.returncode != 0:
        raise RuntimeError(f"instruction_cost: {what} failed:\n{run.stderr[-3000:]}")
    return run.stdout


def _callgrind(script: str, args: list[str], env: dict, where: str) -> tuple[list[int], str]:
    """Runs ``script`` under callgrind: (its dumps' counts, its standard output)."""
    os.makedirs(where, exist_ok=True)
    out = os.path.join(where, "cg.out")
    stdout = _run([_valgrind(), "--tool=callgrind", "--dump-instr=no",
                   f"--dump-before={MARK}", f"--callgrind-out-file={out}", sys.executable,
                   "-c", script, *args], env, "the probe under valgrind")
    return dump_counts(out), stdout


def measure(returns: int, compile_too: bool, log=print) -> dict:
    """{"per_return": (case, build) instructions, "compile": [import, plain kernel, dP/dz
    build] (with compile_too)}."""
    with tempfile.TemporaryDirectory(prefix="filippov-instruction-cost-") as where:
        env = dict(os.environ, NUMBA_CPU_NAME="generic", PYTHONHASHSEED="0",
                   NUMBA_CACHE_DIR=os.path.join(where, "numba"),
                   FILIPPOV_CACHE_DIR=os.path.join(where, "generated"))
        log("  compiling the kernel natively (generic CPU) ...", flush=True)
        _run([sys.executable, "-c", _PROBE, json.dumps(CASES), "2", repr(OMEGA)], env,
             "the native warm-up")
        log(f"  {len(CASES)} cases x {len(BUILDS)} builds under valgrind ...", flush=True)
        counts, stdout = _callgrind(_PROBE, [json.dumps(CASES), str(returns), repr(OMEGA)],
                                    env, os.path.join(where, "returns"))
        if not all(json.loads(stdout.strip().splitlines()[-1])["loaded"]):
            raise RuntimeError("instruction_cost: the kernel was compiled under valgrind, "
                               "not loaded from the native run's cache (numba keyed them "
                               "apart): the counts would include the compile")
        result = {"per_return": per_return(counts, returns, len(CASES))}
        if compile_too:
            log("  the cold compile under valgrind (about 40 minutes) ...", flush=True)
            env.update(NUMBA_CACHE_DIR=os.path.join(where, "cold"),
                       FILIPPOV_CACHE_DIR=os.path.join(where, "cold-generated"))
            result["compile"], _ = _callgrind(_COMPILE_PROBE, [], env,
                                              os.path.join(where, "compile"))
    return result


#: the cold compile's dumps, in _COMPILE_PROBE's order
COMPILE_STAGES = ("import", "kernel", "kernel_dpdz")


def run(returns: int = 200, cold: int = 0, log=print) -> xr.Dataset:
    m = measure(returns, bool(cold), log)
    pr = m["per_return"]
    data = {"instructions": (("case", "build"), pr,
                             {"long_name": "instructions per return (generic x86-64 build)",
                              "units": "1"})}
    coords = dict(case_coords(CASES), build=("build", list(BUILDS)))
    if cold:
        if len(m["compile"]) != len(COMPILE_STAGES):
            raise ValueError(f"expected {len(COMPILE_STAGES)} dumps of the cold compile, "
                             f"got {len(m['compile'])}")
        data["compile_instructions"] = ("stage", np.asarray(m["compile"], dtype=float),
                                        {"long_name": "instructions of each stage of a cold "
                                         "start under valgrind", "units": "1"})
        coords["stage"] = ("stage", list(COMPILE_STAGES))
    log(f"{'theta':>6s} {'eps':>7s} {'s':>4s} {'plain':>10s} {'dP/dz':>10s}"
        "  instructions/return")
    for (t, e, s), row in zip(CASES, pr):
        log(f"{t:6.2f} {e:7.0e} {s:4.1f} {row[0]:10.0f} {row[1]:10.0f}")
    for stage, n in zip(COMPILE_STAGES, m.get("compile", [])):
        log(f"cold {stage:12s} {n / 1e9:10.2f} G instructions")
    return finalize(xr.Dataset(data, coords=coords), None, returns=returns,
                    numba_cpu="generic", counter="valgrind --tool=callgrind",
                    title="instructions per return of the compiled engine")


#: part of `make bench` (filippov_paper.product): rule bench_instruction_cost runs main(args + ['--out', 'results/bench_instruction_cost.nc'])
WORKFLOW = {"args": []}  # per return only: the cold compile (--cold 1) takes ~40 min


def main(argv=None) -> None:
    command_line(__doc__, run, argv, returns=200, cold=0)


if __name__ == "__main__":
    main()
