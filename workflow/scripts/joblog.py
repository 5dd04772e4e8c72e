"""A workflow job's output, on the terminal as before and in its rule's log file.

Every script of the workflow starts with ``joblog.tee(snakemake)``: from then on what
the script writes to stdout and stderr -- progress lines (filippov.progress), the
benchmarks' tables, warnings, the one-line errors of ``sys.exit`` and tracebacks --
is also written to ``snakemake.log[0]`` (the rule's ``log:``, under ``logs/``). The
terminal shows the same as without it, so ``make figures`` keeps its progress; the log
holds one job's output on its own (jobs run in parallel, or on a cluster node).

Only what goes through Python's ``sys.stdout``/``sys.stderr`` is copied: a child
process's output is not (the benchmarks capture their children's output themselves).
It also hands the job's thread budget to the library: ``FILIPPOV_WORKERS`` is set to
the rule's ``threads:`` (1 unless a rule says otherwise), the default number of threads
of a batch of returns (filippov.fastmap.default_workers), so that jobs run side by side
by Snakemake do not oversubscribe the cores.

Imported from workflow/scripts, which Snakemake puts on the path of every script.
"""
from __future__ import annotations

import atexit
import os
import resource
import sys


class _Tee:
    """A text stream that writes to ``stream`` and to ``log``; everything else
    (fileno, isatty, encoding, ...) is the original stream's."""

    def __init__(self, stream, log):
        self._stream, self._log = stream, log

    def write(self, text):
        self._log.write(text)
        return self._stream.write(text)

    def writelines(self, lines):
        for line in lines:
            self.write(line)

    def flush(self):
        self._log.flush()
        self._stream.flush()

    def __getattr__(self, name):
        return getattr(self._stream, name)


def tee(smk) -> None:
    """Copy stdout and stderr into the job's first log file (none: nothing to do), and
    set the library's default number of threads to the job's (module docstring)."""
    os.environ["FILIPPOV_WORKERS"] = str(max(1, int(getattr(smk, "threads", 1) or 1)))
    if not smk.log:
        return
    # line-buffered: a job that is killed leaves every complete line in its log
    log = open(smk.log[0], "w", encoding="utf-8", buffering=1)
    sys.stdout = _Tee(sys.stdout, log)
    sys.stderr = _Tee(sys.stderr, log)
    atexit.register(_cpu_line, log, _cpu())


def _cpu() -> float:
    """CPU seconds (user + system) of this process and the children it waited for."""
    own, kids = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(
        resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + kids.ru_utime + kids.ru_stime


def _cpu_line(log, at_start: float) -> None:
    """The job's CPU, last line of its log (read by filippov_paper.benchmarks.build_cost):
    all of it, and the part before tee() (the interpreter and Snakemake's preamble)."""
    try:
        log.write(f"{CPU_TAG} {_cpu():.3f} s (before the script: {at_start:.3f} s)\n")
        log.flush()
    except (OSError, ValueError):
        pass  # a closed log: the job's output is complete without this line


#: how the CPU line of a job's log begins
CPU_TAG = "joblog: CPU"
