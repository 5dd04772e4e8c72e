"""What a build cost, job by job: the CPU each workflow job used, read from its log.

Run ``python -m filippov_paper.benchmarks.build_cost [LOGS]`` after a build (``make
figures``; LOGS defaults to ``logs/``). Every workflow script starts with
``joblog.tee(snakemake)``, which ends the job's log with its CPU time (user + system, of
the job's process and the children it waited for) and the part of it spent before the
script began (the interpreter, Snakemake's preamble). The table sums them per rule: the
jobs, their CPU, and the CPU per job; the last line is the build's total. A clean build
(``rm -rf results figures .snakemake logs`` first) measures the cold build of issue 33:
its jobs' CPU, compiles and imports included, Snakemake's own scheduling not (it runs
in the process that calls the jobs). Not part of ``make bench``: it reads a build, it
does not make one.
"""
from __future__ import annotations

import argparse
import re
from collections import defaultdict
from pathlib import Path

_LINE = re.compile(r"^joblog: CPU ([0-9.]+) s \(before the script: ([0-9.]+) s\)$", re.M)


def job_cpu(text: str) -> tuple[float, float]:
    """(CPU of the job, the part before its script) from a job's log text; ValueError
    if the log has no CPU line (a job killed before it ended, or an older build)."""
    found = _LINE.findall(text)
    if not found:
        raise ValueError("no 'joblog: CPU' line")
    total, before = found[-1]
    return float(total), float(before)


def rule_of(log: Path, logs: Path) -> str:
    """The rule a log belongs to: its first path component under logs/, without the
    wildcards' part (logs/<rule>/<wildcards>.log or logs/<rule>.log)."""
    rel = log.relative_to(logs)
    return rel.parts[0] if len(rel.parts) > 1 else rel.stem.split(".")[0]


def table(logs: Path) -> list[tuple[str, int, float, float]]:
    """(rule, jobs, CPU s, CPU before the scripts s) per rule, most CPU first; jobs
    without a CPU line are counted under '(no CPU line)'."""
    rows = defaultdict(lambda: [0, 0.0, 0.0])
    for log in sorted(logs.rglob("*.log")):
        try:
            total, before = job_cpu(log.read_text(encoding="utf-8", errors="replace"))
        except ValueError:
            rows["(no CPU line)"][0] += 1
            continue
        row = rows[rule_of(log, logs)]
        row[0] += 1
        row[1] += total
        row[2] += before
    return sorted(((k, *v) for k, v in rows.items()), key=lambda r: -r[2])


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("logs", nargs="?", default="logs", help="the build's log directory")
    logs = Path(ap.parse_args(argv).logs)
    if not logs.is_dir():
        raise SystemExit(f"error: logs: {logs} is not a directory (run a build first)")
    rows = table(logs)
    print(f"{'rule':28s} {'jobs':>5s} {'CPU s':>9s} {'s/job':>7s} {'before script s':>16s}")
    for rule, jobs, cpu, before in rows:
        per = f"{cpu / jobs:7.2f}" if jobs and cpu else f"{'':7s}"
        print(f"{rule:28s} {jobs:5d} {cpu:9.2f} {per} {before:16.2f}")
    jobs = sum(r[1] for r in rows)
    cpu = sum(r[2] for r in rows)
    print(f"{'total':28s} {jobs:5d} {cpu:9.2f} {'':7s} {sum(r[3] for r in rows):16.2f}")


if __name__ == "__main__":
    main()
