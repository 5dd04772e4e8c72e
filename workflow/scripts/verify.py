"""`make verify`: rebuild everything twice from scratch and check it.

1. Two fresh copies of the project (what a clone has: Snakefile, config/,
   workflow/, paper/*.tex) are built with `snakemake` (rule all: every figure,
   and the report when TeX is installed).
2. The two builds must be byte-identical: every file in results/, figures/ and
   paper/main.pdf. A wall-clock measurement (MEASURED: the work-precision
   sweep's times) differs between any two runs by nature: build b is given
   build a's measurement, so that everything made from it must match; the
   measurement's reproducible part (its errors) is checked by the manifest.
3. The first build is compared with the committed manifest
   (tests/reference/manifest.json, see filippov_paper.manifest).

``--first-build DIR`` builds the first copy in DIR and keeps it: CI hands it to the
test suite as its shared build (``FILIPPOV_TEST_BUILD=DIR``, tests/conftest.py) and to
`make cross-cpu` as its native build (``--native DIR``) instead of building the same
tree twice more.

Run by make, not by a Snakemake rule. tests/conftest.py reuses copy_project and
run_snakemake from here.
"""
from __future__ import annotations

import argparse
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUTPUTS = ("results", "figures", "paper/main.pdf")
#: outputs that hold wall-clock times (tolerance rule "measured")
MEASURED = ("results/work_precision.nc",)


def reuse_measured(src: Path, work: Path, only: list[str] | None = None) -> None:
    """``src``'s measured outputs (MEASURED) into the project copy ``work``, so that
    its build takes them instead of measuring again; ``only``: a partial build's
    datasets (one without the sweep gets no copy of it). The copies get a new mtime:
    snakemake runs a job again whose output is older than its script."""
    for rel in MEASURED:
        if (src / rel).is_file() and (only is None or Path(rel).stem in only):
            (work / rel).parent.mkdir(parents=True, exist_ok=True)
            shutil.copy(src / rel, work / rel)


def copy_project(dest: Path) -> Path:
    """What a fresh clone needs to run the workflow: Snakefile, config, workflow, paper."""
    dest.mkdir(parents=True, exist_ok=True)  # new, or an empty directory given to fill
    shutil.copy(ROOT / "Snakefile", dest / "Snakefile")
    for folder in ("config", "workflow"):
        shutil.copytree(ROOT / folder, dest / folder)
    if (ROOT / "paper").is_dir():
        (dest / "paper").mkdir()
        for tex in (ROOT / "paper").glob("*.tex"):
            shutil.copy(tex, dest / "paper" / tex.name)
    return dest


#: the HTML report's own stylesheet (``make report-html`` passes it too)
REPORT_STYLESHEET = "workflow/report/report.css"


def report_args(out) -> tuple:
    """The arguments that make Snakemake's HTML report at ``out``, as ``make report-html``
    makes it (with the project's stylesheet; paths relative to the project)."""
    return ("--report", str(out), "--report-stylesheet", REPORT_STYLESHEET)


def run_snakemake(work: Path, *args, cores: str = "1", timeout: float = 3000, capture=True,
                  env: dict | None = None):
    """`snakemake` in ``work`` with the project's library; ``env`` adds variables."""
    env = dict(os.environ, MPLBACKEND="Agg", SOURCE_DATE_EPOCH="0", **(env or {}))
    env["PYTHONPATH"] = os.pathsep.join(filter(None, [str(ROOT / "src"), str(ROOT / "workflow"),
                                                      env.get("PYTHONPATH")]))
    env["PATH"] = os.pathsep.join([str(Path(sys.executable).parent), env.get("PATH", "")])
    cmd = [sys.executable, "-m", "snakemake", "--cores", cores, "--directory", str(work), *args]
    return subprocess.run(cmd, cwd=work, env=env, capture_output=capture, text=True,
                          timeout=timeout)


def files(work: Path) -> dict[str, bytes]:
    out = {}
    for name in OUTPUTS:
        path = work / name
        paths = sorted(p for p in path.rglob("*") if p.is_file()) if path.is_dir() else \
            [path] if path.exists() else []
        for p in paths:
            out[p.relative_to(work).as_posix()] = p.read_bytes()
    return out


def identical(a: Path, b: Path) -> list[str]:
    fa, fb = files(a), files(b)
    diff = [f"{n}: only in one build" for n in sorted(set(fa) ^ set(fb))]
    diff += [f"{n}: bytes differ" for n in sorted(set(fa) & set(fb)) if fa[n] != fb[n]]
    return diff


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--keep", action="store_true", help="keep the build directories")
    ap.add_argument("--first-build", type=Path, metavar="DIR",
                    help="build the first copy in DIR (new or empty) and keep it")
    args = ap.parse_args(argv)
    first = args.first_build
    if first is not None and first.exists() and (not first.is_dir() or any(first.iterdir())):
        ap.error(f"--first-build: {first} exists and is not an empty directory")
    first_dir = first.resolve() if first is not None else None
    sys.path[:0] = [str(ROOT / "src"), str(ROOT / "workflow")]
    from filippov_paper import manifest

    tmp = Path(tempfile.mkdtemp(prefix="filippov-verify-"))
    try:
        builds = []
        for name in ("a", "b"):
            dest = tmp / name
            if name == "a" and first is not None:
                dest = first_dir  # new or empty: checked above
            work = copy_project(dest)
            if builds:  # build b reuses a's timings
                reuse_measured(builds[0], work)
            t0 = time.perf_counter()
            print(f"== clean build {name} in {work}", flush=True)
            run = run_snakemake(work, cores="all", capture=False)
            if run.returncode != 0:
                left = f"; its incomplete copy is left in {work}" if work == first_dir else ""
                print(f"verify: build {name} failed (exit {run.returncode}){left}",
                      file=sys.stderr)
                return 1
            print(f"== build {name}: {time.perf_counter() - t0:.0f} s", flush=True)
            builds.append(work)
        diff = identical(*builds)
        n = len(files(builds[0]))
        for line in diff:
            print(f"NOT REPRODUCIBLE {line}")
        print(f"two clean builds: {n} files, {'byte-identical' if not diff else f'{len(diff)} differ'}")
        man = manifest.json.loads(manifest.MANIFEST.read_text())
        problems = manifest.check(builds[0] / "results", builds[0] / "figures", man)
        for p in problems:
            print(f"MISMATCH {p}")
        same = man["environment"] == manifest.environment()
        print(f"manifest: {len(man['data'])} datasets, {len(man['figures'])} figures "
              f"({'hashes' if same else 'other environment: images'} compared): "
              f"{'OK' if not problems else f'{len(problems)} mismatches'}")
        return 1 if diff or problems else 0
    finally:
        if first is not None:
            print(f"first build kept in {first_dir}")
        if args.keep:
            print(f"builds kept in {tmp}")
        else:
            shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
