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
does not make one. With ``--cores 2 64``, after a full-resolution build (docs/pipeline.md),
it also projects the chunked scenes' wall time on that many cores (or SLURM jobs) from
their chunks' measured CPU: what the README's full-resolution table quotes.
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


def _list_schedule(jobs, free: list[float]) -> list[float]:
    """Run ``jobs`` ((ready time, duration), in the order given) each on the core that
    frees first, not before it is ready; ``free`` (the cores' free times) is updated;
    the jobs' end times are returned."""
    ends = []
    for ready, duration in jobs:
        core = free.index(min(free))
        free[core] = max(free[core], ready) + duration
        ends.append(free[core])
    return ends


def _cores(cores) -> list[float]:
    """The free times of ``cores`` idle cores (all 0); refuses a count that is not an
    integer >= 1."""
    if not (isinstance(cores, int) and cores >= 1):
        raise ValueError(f"cores: must be an integer >= 1, got {cores!r}")
    return [0.0] * cores


def makespan(durations, cores: int) -> float:
    """The wall time of independent jobs of the given durations on ``cores`` cores, each
    job on one core, the longest started first, each on the core that frees first
    (list scheduling, as Snakemake runs ready jobs; within 4/3 of the best order)."""
    free = _cores(cores)
    _list_schedule([(0.0, d) for d in sorted(durations, reverse=True)], free)
    return max(free)


def chunked_projection(logs: Path, cores: int) -> tuple[float, dict]:
    """A projected wall time for the chunked scenes a build's ``logs`` hold, on ``cores``
    cores (or SLURM jobs) with no queue waits: all their chunk jobs scheduled together,
    longest first (:func:`makespan`), then each scene's merge job once its chunks are
    done. Also each scene's (chunks, chunk CPU s, longest chunk s, merge CPU s)."""
    def cpu_of(log: Path) -> float:
        try:
            return job_cpu(log.read_text(encoding="utf-8", errors="replace"))[0]
        except (OSError, ValueError) as exc:  # an unfinished build: say which job
            raise ValueError(f"{log}: {exc}") from None

    free = _cores(cores)
    chunks = {}
    for log in sorted((logs / "compute_chunk").glob("*/*.log")):
        chunks.setdefault(log.parent.name, []).append(cpu_of(log))
    merges = {s: cpu_of(logs / "merge_chunks" / f"{s}.log") for s in chunks}
    order = sorted(((d, s) for s, ds in chunks.items() for d in ds), reverse=True)
    ends = _list_schedule([(0.0, d) for d, _ in order], free)
    done = {}
    for (_, scene), end in zip(order, ends):
        done[scene] = max(done.get(scene, 0.0), end)
    merge_jobs = sorted((done[s], merges[s]) for s in chunks)
    wall = max(_list_schedule(merge_jobs, free), default=0.0)
    return wall, {s: (len(c), sum(c), max(c), merges[s]) for s, c in chunks.items()}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("logs", nargs="?", default="logs", help="the build's log directory")
    ap.add_argument("--cores", type=int, nargs="+", metavar="N",
                    help="also project the chunked scenes' wall time on N cores")
    args = ap.parse_args(argv)
    logs = Path(args.logs)
    if not logs.is_dir():
        raise SystemExit(f"error: logs: {logs} is not a directory (run a build first)")
    if args.cores:
        try:
            _print_projection(logs, args.cores)
        except ValueError as exc:
            raise SystemExit(f"error: --cores: {exc}") from None
    rows = table(logs)
    print(f"{'rule':28s} {'jobs':>5s} {'CPU s':>9s} {'s/job':>7s} {'before script s':>16s}")
    for rule, jobs, cpu, before in rows:
        per = f"{cpu / jobs:7.2f}" if jobs and cpu else f"{'':7s}"
        print(f"{rule:28s} {jobs:5d} {cpu:9.2f} {per} {before:16.2f}")
    jobs = sum(r[1] for r in rows)
    cpu = sum(r[2] for r in rows)
    print(f"{'total':28s} {jobs:5d} {cpu:9.2f} {'':7s} {sum(r[3] for r in rows):16.2f}")



def _print_projection(logs: Path, cores: list[int]) -> None:
    _, scenes = chunked_projection(logs, 1)
    print(f"{'chunked scene':28s} {'chunks':>6s} {'CPU s':>9s} {'longest s':>10s} {'merge s':>8s}")
    for scene, (n, cpu, longest, merge) in scenes.items():
        print(f"{scene:28s} {n:6d} {cpu:9.1f} {longest:10.1f} {merge:8.1f}")
    for n in cores:
        print(f"projected wall on {n} cores: {chunked_projection(logs, n)[0]:.0f} s")
    print()


if __name__ == "__main__":
    main()
