"""The workflow through the SLURM executor on a single-node SLURM on localhost.

Starts munged, slurmctld and slurmd (Debian packages slurm-wlm and munge; this
test installs nothing) as child processes in the foreground, runs
`snakemake --profile workflow/profiles/slurm` on a couple of small targets (one of
them a chunked scene) in a scratch copy of the project, and checks that the
results are identical to the same targets built locally. The daemons are
stopped by PID afterwards and /etc/slurm/slurm.conf, which it has to write (the
executor's job step drops SLURM_CONF before srun), is removed again.

Skipped (with the reason) when the SLURM/munge binaries or the executor plugin
are missing, when not root, or when a SLURM configuration of someone else is in
/etc/slurm; with CI=true and SLURM_TEST=1 these are failures instead.
"""
import os
import secrets
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import pytest

from conftest import copy_project, run_snakemake

CONF = Path("/etc/slurm/slurm.conf")
MARKER = "# filippov tests/test_slurm.py: temporary single-node SLURM (removed after the test)"
BINARIES = ("munged", "slurmctld", "slurmd", "sbatch", "sinfo", "squeue", "scancel")
REQUIRED = os.environ.get("CI") == "true" and os.environ.get("SLURM_TEST") == "1"
TARGETS = ("results/fig08_s0theta.nc", "results/fig04_retmaps.nc")


def _unavailable(reason: str):
    if REQUIRED:
        pytest.fail(f"SLURM test required (CI=true, SLURM_TEST=1) but {reason}")
    pytest.skip(reason)


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _node_line() -> str:
    """This machine as slurmd sees it (`slurmd -C`), reachable on 127.0.0.1."""
    out = subprocess.run(["slurmd", "-C"], capture_output=True, text=True, timeout=30,
                         check=True).stdout
    line = next(l for l in out.splitlines() if l.startswith("NodeName="))
    return f"{line} NodeAddr=127.0.0.1 State=UNKNOWN"


def _slurm_conf(tmp: Path, munge_socket: Path) -> str:
    host = socket.gethostname().split(".")[0]
    return "\n".join([
        MARKER,
        "ClusterName=filippovtest",
        f"SlurmctldHost={host}(127.0.0.1)",
        f"SlurmctldPort={_free_port()}",
        f"SlurmdPort={_free_port()}",
        "SlurmUser=root",
        "SlurmdUser=root",
        "AuthType=auth/munge",
        "CredType=cred/munge",
        f"AuthInfo=socket={munge_socket}",
        "ProctrackType=proctrack/linuxproc",
        "TaskPlugin=task/none",
        "SelectType=select/cons_tres",
        "SelectTypeParameters=CR_CPU",
        "SchedulerType=sched/backfill",
        "SwitchType=switch/none",
        "MpiDefault=none",
        "AccountingStorageType=accounting_storage/none",
        "JobAcctGatherType=jobacct_gather/none",
        "JobCompType=jobcomp/none",
        "ReturnToService=2",
        "MinJobAge=600",  # finished jobs stay visible to squeue (the status command)
        "InactiveLimit=0",
        "KillWait=5",
        f"StateSaveLocation={tmp / 'state'}",
        f"SlurmdSpoolDir={tmp / 'spool'}",
        f"SlurmctldPidFile={tmp / 'slurmctld.pid'}",
        f"SlurmdPidFile={tmp / 'slurmd.pid'}",
        f"SlurmctldLogFile={tmp / 'slurmctld.log'}",
        f"SlurmdLogFile={tmp / 'slurmd.log'}",
        _node_line(),
        "PartitionName=debug Nodes=ALL Default=YES MaxTime=INFINITE State=UP",
        "",
    ])


def _logs(tmp: Path) -> str:
    text = []
    for name in ("munged.log", "slurmctld.log", "slurmd.log", "slurmctld.out", "slurmd.out"):
        path = tmp / name
        if path.exists():
            text.append(f"--- {name}\n" + path.read_text(errors="replace")[-3000:])
    return "\n".join(text)


def _stop(proc: subprocess.Popen) -> None:
    """SIGTERM to this PID, SIGKILL if it has not ended after 20 s."""
    if proc.poll() is not None:
        return
    proc.send_signal(signal.SIGTERM)
    try:
        proc.wait(timeout=20)
    except subprocess.TimeoutExpired:
        proc.kill()
        proc.wait(timeout=10)


@pytest.fixture
def slurm_cluster(tmp_path_factory):
    """munged + slurmctld + slurmd on localhost; yields the daemons' folder."""
    missing = [b for b in BINARIES if shutil.which(b) is None]
    if missing:
        _unavailable(f"SLURM/munge not installed (missing {', '.join(missing)}; Debian: "
                     f"apt-get install slurm-wlm munge)")
    try:
        import snakemake_executor_plugin_slurm  # noqa: F401
    except ImportError:
        _unavailable("snakemake-executor-plugin-slurm is not installed")
    if os.geteuid() != 0:
        _unavailable("needs root: writes /etc/slurm/slurm.conf and runs the SLURM daemons")
    if CONF.exists() and not CONF.read_text(errors="replace").startswith(MARKER):
        _unavailable(f"{CONF} exists (a real SLURM installation?); not touching it")

    tmp = tmp_path_factory.mktemp("slurm")
    for sub in ("state", "spool"):
        (tmp / sub).mkdir()
    key = tmp / "munge.key"
    key.write_bytes(secrets.token_bytes(1024))
    key.chmod(0o400)
    munge_socket = tmp / "munge.socket"
    CONF.parent.mkdir(parents=True, exist_ok=True)
    conf_created = not CONF.exists()
    CONF.write_text(_slurm_conf(tmp, munge_socket))
    procs = []

    def start(name, *args):
        out = open(tmp / f"{name}.out", "wb")
        procs.append(subprocess.Popen([name, *args], stdout=out, stderr=subprocess.STDOUT,
                                      stdin=subprocess.DEVNULL))
        out.close()
        return procs[-1]

    try:
        start("munged", "--foreground", "--force", f"--key-file={key}",
              f"--socket={munge_socket}", f"--pid-file={tmp / 'munged.pid'}",
              f"--log-file={tmp / 'munged.log'}", f"--seed-file={tmp / 'munged.seed'}")
        _wait(lambda: munge_socket.exists(), 20, "munged socket", procs, tmp)
        start("slurmctld", "-D", "-f", str(CONF))
        start("slurmd", "-D", "-f", str(CONF))

        def idle():
            run = subprocess.run(["sinfo", "-h", "-o", "%T"], capture_output=True, text=True,
                                 timeout=20)
            return run.returncode == 0 and run.stdout.strip() == "idle"
        _wait(idle, 60, "the node to be idle (sinfo)", procs, tmp)
        yield tmp
    finally:
        try:  # jobs of this private controller only (e.g. after a failure)
            ids = subprocess.run(["squeue", "-h", "-o", "%i"], capture_output=True, text=True,
                                 timeout=20).stdout.split()
            if ids:
                subprocess.run(["scancel", *ids], capture_output=True, timeout=20)
        except (OSError, subprocess.SubprocessError):
            pass
        for proc in reversed(procs):  # slurmd, slurmctld, munged: by PID
            _stop(proc)
        if conf_created or CONF.read_text(errors="replace").startswith(MARKER):
            CONF.unlink(missing_ok=True)


def _wait(ready, timeout, what, procs, tmp):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        dead = [p.args[0] for p in procs if p.poll() is not None]
        if dead:
            pytest.fail(f"{', '.join(dead)} exited while waiting for {what}\n{_logs(tmp)}")
        if ready():
            return
        time.sleep(0.5)
    pytest.fail(f"timed out after {timeout} s waiting for {what}\n{_logs(tmp)}")


def _small_project(path: Path) -> Path:
    """The project with fig04 on a short x2 grid, split into 2 chunks."""
    work = copy_project(path)
    scene = work / "config" / "scenes" / "fig04_retmaps.yaml"
    lines = [l for l in scene.read_text().splitlines() if not l.startswith("chunks:")]
    lines = [("  n_uniform: 21" if l.strip().startswith("n_uniform:") else
              "  n_geometric: 6" if l.strip().startswith("n_geometric:") else l) for l in lines]
    scene.write_text("\n".join(lines + ["chunks: 2", ""]))
    return work


def test_workflow_through_slurm_matches_local_run(slurm_cluster, tmp_path):
    import filippov.io

    cluster = _small_project(tmp_path / "cluster")
    local = _small_project(tmp_path / "local")
    t0 = time.perf_counter()
    run = run_snakemake(cluster, "--profile", "workflow/profiles/slurm",
                        "--slurm-status-command", "squeue",
                        "--slurm-init-seconds-before-status-checks", "2",
                        "--slurm-no-account", "--latency-wait", "10", "--jobs", "4",
                        *TARGETS, timeout=600)
    seconds = time.perf_counter() - t0
    logs = "\n".join(p.read_text(errors="replace")[-2000:]
                     for p in sorted((cluster / ".snakemake" / "slurm_logs").rglob("*.log")))
    assert run.returncode == 0, (run.stdout[-3000:] + run.stderr[-5000:] + "\n" + logs + "\n"
                                 + _logs(slurm_cluster))
    out = run.stdout + run.stderr
    submitted = [l for l in out.splitlines() if "submitted" in l.lower() and "slurm" in l.lower()]
    assert len(submitted) >= 3, out[-3000:]  # fig08 + the two fig04 chunks went through sbatch
    print(f"SLURM run: {seconds:.1f} s")

    here = run_snakemake(local, *TARGETS, cores="2", timeout=600)
    assert here.returncode == 0, here.stderr[-4000:]
    for target in TARGETS:
        a = filippov.io.read_dataset(cluster / target)
        b = filippov.io.read_dataset(local / target)
        assert a.identical(b), target
        assert (cluster / target).read_bytes() == (local / target).read_bytes(), target
    assert not list((cluster / "results" / "chunks").rglob("*.nc"))  # temporary: merged away
