"""Workflow conventions: `snakemake --lint` finds nothing, every rule logs under logs/
and names its software (workflow/envs), and every script copies its output into that
log while still printing it.

The lint needs no results: it reads the workflow in a fresh copy of the project.
(`snakemake --lint json` prints the text report in Snakemake 9.27, so the text report
and the exit code are what is checked.)
"""
import importlib
import os
import re
import subprocess
import sys
from pathlib import Path

from conftest import copy_project, run_snakemake

ROOT = Path(__file__).resolve().parents[1]
SCRIPTS = ROOT / "workflow" / "scripts"


def test_snakemake_lint_finds_nothing(tmp_path):
    work = copy_project(tmp_path / "project")
    run = run_snakemake(work, "--lint", timeout=300)
    out = run.stdout + run.stderr
    assert "Lints for" not in out, out[-6000:]
    assert run.returncode == 0, out[-6000:]
    assert "Congratulations, your workflow is in a good condition!" in out


def _rules(text: str):
    """(rule name, its body) for each `rule NAME:` of a .smk file."""
    parts = re.split(r"^rule (\w+):\n", text, flags=re.M)
    return [(parts[i], parts[i + 1].split("\n\n\n")[0]) for i in range(1, len(parts), 2)]


def test_every_rule_that_runs_logs_under_logs_and_names_its_software():
    rules = []
    for smk in sorted((ROOT / "workflow" / "rules").glob("*.smk")):
        rules += _rules(smk.read_text())
    assert len(rules) >= 14
    for name, body in rules:
        if not re.search(r"^    (script|shell):", body, re.M):
            continue  # a target-only rule (all, bench) runs nothing
        log = re.search(r'^    log:\n        "([^"]+)"', body, re.M)
        assert log, f"rule {name} has no log"
        assert log.group(1).startswith(f"logs/{name}"), (name, log.group(1))
        # the software it runs with under --software-deployment-method conda
        env = re.search(r'^    conda:\n        "([^"]+)"', body, re.M)
        assert env and (ROOT / "workflow" / "rules" / env.group(1)).resolve().is_file(), name
        # a wildcard rule logs per job, with the wildcards of its output
        output = body.split("    log:")[0].split("    output:")[-1]
        output = re.sub(r'f"[^"]*"', "", output)  # {name} of an f-string is no wildcard
        assert set(re.findall(r"{(\w+)}", log.group(1))) == \
            set(re.findall(r"{(\w+)}", output)), (name, log.group(1))


def test_generated_rules_log_under_logs_and_name_their_software():
    # rules made in a loop (bench.smk: one per benchmark module) name themselves with
    # an f-string: their log is logs/<that name>.log
    found = 0
    for smk in sorted((ROOT / "workflow" / "rules").glob("*.smk")):
        for body in re.split(r"^ +rule:\n", smk.read_text(), flags=re.M)[1:]:
            body = body.split("\n\n\n")[0]
            name = re.search(r'name:\n +(f"[^"]+")', body)
            assert name, f"{smk.name}: a rule without a name"
            log = 'f"logs/' + name.group(1)[2:-1] + '.log"'
            assert re.search(r"log:\n +" + re.escape(log), body), \
                (smk.name, name.group(1))
            assert re.search(r'conda:\n +"\.\./envs/[a-z]+\.yaml"', body), name.group(1)
            found += 1
    assert found >= 1


def test_every_script_tees_its_output_into_the_log():
    for script in sorted(SCRIPTS.glob("*.py")):
        if script.name in ("joblog.py", "verify.py"):  # the helper; verify runs from make
            continue
        text = script.read_text()
        assert "joblog.tee(snakemake)" in text, script.name
        # before anything else runs (an import error is logged too)
        body = text.split('"""', 2)[2]
        first = [l for l in body.splitlines() if l.strip() and not l.startswith("#")][:2]
        assert first[0] == "import joblog", script.name
        assert first[1].startswith("joblog.tee(snakemake)"), script.name


def test_joblog_prints_and_logs_progress_and_errors(tmp_path):
    """What a job prints reaches the terminal as before and its log file: progress
    lines, stdout, and the one-line error of sys.exit."""
    log = tmp_path / "logs" / "job.log"
    log.parent.mkdir()
    child = f"""
import sys
sys.path.insert(0, {str(SCRIPTS)!r})
import joblog
class Smk:
    log = [{str(log)!r}]
joblog.tee(Smk)
from filippov.progress import Progress
bar = Progress("fig99_test", 2, enabled=True, every=0.0)
bar.step(); bar.step()
print("a table line")
sys.exit("error: fig99_test: something wrong")
"""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT / "src"), str(ROOT / "workflow")]))
    run = subprocess.run([sys.executable, "-c", child], capture_output=True, text=True,
                         timeout=300, env=env)
    assert run.returncode == 1
    logged = log.read_text()
    for line in ("[fig99_test] 1/2", "[fig99_test] 2/2", "error: fig99_test: something wrong"):
        assert line in run.stderr and line in logged, (line, run.stderr, logged)
    assert "a table line" in run.stdout and "a table line" in logged
    # the job's CPU, last line of the log only (filippov_paper.benchmarks.build_cost)
    last = logged.rstrip("\n").splitlines()[-1]
    assert last.startswith("joblog: CPU ") and "joblog: CPU" not in run.stderr + run.stdout
    from filippov_paper.benchmarks.build_cost import job_cpu
    total, before = job_cpu(logged)
    assert 0.0 < before < total


def test_joblog_without_a_log_changes_nothing():
    class NoLog:
        log = []

    sys.path.insert(0, str(SCRIPTS))
    try:
        joblog = importlib.import_module("joblog")
        before = sys.stdout, sys.stderr
        joblog.tee(NoLog)
        assert (sys.stdout, sys.stderr) == before
    finally:
        sys.path.remove(str(SCRIPTS))
