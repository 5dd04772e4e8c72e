"""The product protocol (filippov_paper.product): every scene, figure, benchmark and the
hard-case sweep conforms; hook names are looked up in one place only; and a new figure
needs its three files and nothing under tests/."""
import importlib
import re
import types
from pathlib import Path

import pytest

from filippov_paper import plotting, product
from filippov_paper.scenes import known_scenes

from conftest import ROOT


def _products():
    mods = [f"filippov_paper.scenes.{sid}" for sid in known_scenes()]
    mods += [plotting.module(fid).__name__ for fid in plotting.figure_ids()]
    mods += [f"filippov_paper.benchmarks.{name}" for name in product.benchmarks()]
    return sorted(set(mods)) + ["filippov_paper.hard_cases"]


@pytest.mark.parametrize("name", _products())
def test_every_product_conforms(name):
    assert product.problems(importlib.import_module(name)) == []


def test_every_kind_is_found():
    kinds = {product.kind_of(name) for name in _products()}
    assert kinds == set(product.HOOKS)
    assert {"effect_cost", "work_precision", "parallel_scaling"} <= set(product.benchmarks())
    assert "timing" not in product.benchmarks()  # a helper: no main


def _fake(kind_module: str, source: str, tmp_path) -> types.ModuleType:
    path = tmp_path / "fake.py"
    path.write_text(source)
    module = types.ModuleType(kind_module)
    module.__file__ = str(path)
    exec(compile(source, str(path), "exec"), vars(module))
    return module


def test_the_check_names_what_is_wrong(tmp_path):
    source = ("def compute(scene, *, progress=False): pass\n"
              "def report(ds, m): pass\n"
              "ENGINES = 'compiled'\n"           # a str, not a tuple
              "CHUNK_AXIS = 'x2'\n"              # chunking half declared
              "def chunk_grid(scene): pass\n"
              "VARIABLE_ATTR = {}\n"             # misspelt VARIABLE_ATTRS
              "TEST_PERTURBED = 'eps'\n")        # no such knob; TEST_PERTURB missing
    got = "\n".join(product.problems(_fake("filippov_paper.scenes.fig99_fake", source,
                                           tmp_path)))
    assert "required hook 'TEST_PERTURB' missing" in got
    assert "ENGINES must be a value" in got and "got str" in got
    assert "chunking needs all of CHUNK_AXIS, chunk_grid, sweep, assemble" in got
    assert "'VARIABLE_ATTR' looks like a misspelt hook 'VARIABLE_ATTRS'" in got
    assert "'TEST_PERTURBED' looks like a test knob" in got
    assert "'compute'" not in got and "'report'" not in got


def test_a_lookup_of_a_name_that_is_no_hook_fails(tmp_path):
    module = _fake("filippov_paper.scenes.fig99_fake", "X = 1\n", tmp_path)
    with pytest.raises(product.ProtocolError, match="'ENGINE' is not a hook of a scene"):
        product.hook(module, "ENGINE", ("reference",))
    with pytest.raises(product.ProtocolError, match="fig99_fake: defines no 'TEST_PERTURB'"):
        product.hook(module, "TEST_PERTURB")
    assert product.hook(module, "ENGINES", ("reference",)) == ("reference",)
    with pytest.raises(product.ProtocolError, match="not a product module"):
        product.kind_of("filippov_paper.config")


#: where product modules are asked for hooks
LOOKUP_PLACES = ["workflow/filippov_paper", "workflow/scripts", "workflow/rules", "tests",
                 "Snakefile"]


def test_hooks_are_looked_up_through_product_only():
    names = "|".join(sorted({h.name for hooks in product.HOOKS.values() for h in hooks}))
    pattern = re.compile(r"\b(?:getattr|hasattr)\([^)]*['\"](?:" + names + r")['\"]")
    found = []
    for place in LOOKUP_PLACES:
        path = ROOT / place
        files = [path] if path.is_file() else sorted(path.rglob("*.py")) + \
            sorted(path.rglob("*.smk"))
        for f in files:
            if f.name == "product.py" or f == Path(__file__):
                continue
            for no, line in enumerate(f.read_text(encoding="utf-8").splitlines(), 1):
                if pattern.search(line):
                    found.append(f"{f.relative_to(ROOT)}:{no}: {line.strip()}")
    assert not found, "look hooks up with filippov_paper.product.hook/has:\n" + "\n".join(found)


def test_a_new_figure_is_three_files():
    # nothing under tests/ names a figure in a list of every figure: the per-figure
    # knobs are the modules' hooks. So the files of a figure are its YAML, its scene
    # module and its figure module -- and each figure has exactly those.
    for sid in known_scenes():
        files = [ROOT / "config" / "scenes" / f"{sid}.yaml",
                 ROOT / "workflow" / "filippov_paper" / "scenes" / f"{sid}.py",
                 ROOT / "workflow" / "filippov_paper" / "plotting" / f"{sid}.py"]
        assert all(f.exists() for f in files), sid
    # a dictionary keyed by every scene id would be a fourth file: none is left in tests/
    every = set(known_scenes())
    for f in sorted((ROOT / "tests").glob("*.py")):
        text = f.read_text(encoding="utf-8")
        named = {sid for sid in every if f'"{sid}"' in text or f"'{sid}'" in text}
        assert named != every, f"{f.name} names every scene: a per-figure list to keep"


def test_make_bench_rules_come_from_the_benchmark_modules(monkeypatch, tmp_path):
    declared = product.workflow_benchmarks()
    # the benchmarks of `make bench` besides work-precision (which has its own rules): at
    # least these; a new one is its module alone (no list here to extend)
    assert {"attractor_cost", "compile_cost", "effect_cost", "parallel_scaling",
            "return_floor", "sliding_cost", "sweep_cost"} <= set(declared)
    assert "work_precision" not in declared
    assert declared["parallel_scaling"]["threads"] == "all"
    assert declared["sweep_cost"]["threads"] == "all"
    assert declared["compile_cost"]["args"] == ["--repeat", "1"]
    # a malformed declaration names its file and the expected form
    (tmp_path / "benchmarks").mkdir()
    (tmp_path / "benchmarks" / "odd.py").write_text(
        "WORKFLOW = {'args': [], 'threads': 'many'}\ndef main(argv=None): pass\n")
    monkeypatch.setattr(product, "PACKAGE", tmp_path)
    with pytest.raises(ValueError, match=r"odd.py: WORKFLOW: expected .*'many'"):
        product.workflow_benchmarks()


def test_test_knobs_are_not_part_of_the_compute_hash():
    # editing a test knob reruns no computation: the compute jobs hash the scene module
    # without them (filippov_paper.config.without_report_part)
    from filippov_paper.config import without_report_part

    path = ROOT / "workflow" / "filippov_paper" / "scenes" / "fig14_atlas.py"
    source = path.read_text(encoding="utf-8")
    edited = source.replace('TEST_PERTURB = "theta"', 'TEST_PERTURB = "eps"')
    edited = edited.replace('"n_mu": 7,', '"n_mu": 9,')
    assert edited.count("TEST_") == source.count("TEST_") and edited != source
    assert without_report_part(edited) == without_report_part(source)
    assert "TEST_SMALL" not in without_report_part(source)
    # a change of what is computed still shows
    assert without_report_part(source.replace("def ", "def x", 1)) != \
        without_report_part(source)


def test_the_report_parts_of_the_benchmarks_come_from_their_modules(monkeypatch, tmp_path):
    declared = product.report_benchmarks()
    # in the order of the generated macros.tex: the compile times, the sweep, its blocks
    assert list(declared) == ["compile_cost", "work_precision", "effect_cost",
                              "attractor_cost"]
    assert declared["work_precision"] == {"dataset": "work_precision",
                                          "table": "tab_bench.tex", "order": 20}
    assert declared["compile_cost"]["table"] is None
    # REPORT without report, and a malformed REPORT, name the file
    (tmp_path / "benchmarks").mkdir()
    odd = tmp_path / "benchmarks" / "odd.py"
    odd.write_text("REPORT = {'dataset': 'bench_odd', 'order': 1}\ndef main(argv=None): pass\n")
    monkeypatch.setattr(product, "PACKAGE", tmp_path)
    with pytest.raises(ValueError, match=r"odd.py: REPORT without a report\(ds, macros\)"):
        product.report_benchmarks()
    odd.write_text("REPORT = {'dataset': 'bench_odd', 'order': '1'}\n"
                   "def main(argv=None): pass\ndef report(ds, m): pass\n")
    with pytest.raises(ValueError, match=r"odd.py: REPORT: expected .*'order': '1'"):
        product.report_benchmarks()
    got = product.problems(_fake("filippov_paper.benchmarks.odd",
                                 "def main(argv=None): pass\ndef report(ds, m): pass\n",
                                 tmp_path))
    assert got == ["filippov_paper.benchmarks.odd: a report part needs both REPORT and report"]


#: a benchmark dropped into a copy of the project: its module and its figure module, and
#: no other file edited (test_a_new_benchmark_is_one_or_two_files)
TOY_BENCHMARK = '''"""A throwaway benchmark: one number, written to --out."""
import argparse

import xarray as xr

from filippov.io import write_dataset
from filippov_paper.report import Macros, var

WORKFLOW = {"args": ["--value", "2.5"]}


def main(argv=None) -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--value", type=float, default=1.0)
    ap.add_argument("--out", required=True)
    args = ap.parse_args(argv)
    write_dataset(xr.Dataset({"value": ((), args.value)}), args.out)


REPORT = {"dataset": "bench_toy", "table": "tab_toy.tex", "order": 50}


def report(ds, m: Macros):
    m.flag("rpHaveToy", ds is not None)
    if ds is None:
        return None
    var(m, "rpToyValue", ds, REPORT["dataset"], "value")
    return "toy block\\n"
'''
TOY_FIGURE = '''"""The throwaway benchmark's figure."""
import xarray as xr
from matplotlib.figure import Figure


def draw(ds):
    fig = Figure()
    fig.add_subplot().bar([0], [float(ds.value)])
    return fig


def synthetic_dataset():
    return xr.Dataset({"value": ((), 1.0)})
'''


def test_a_new_benchmark_is_one_or_two_files(tmp_path):
    """A benchmark module (WORKFLOW, REPORT, report) and a figure module dropped into a
    copy of the project, nothing else edited: `make bench` plans its rule and its figure's,
    the report writes its table, and report.generate calls its report part."""
    import os
    import subprocess
    import sys

    from conftest import copy_project

    work = copy_project(tmp_path / "project")
    package = work / "workflow" / "filippov_paper"
    (package / "benchmarks" / "toy.py").write_text(TOY_BENCHMARK)
    (package / "plotting" / "bench_toy.py").write_text(TOY_FIGURE)
    # the copy's pipeline package, not this tree's, is the one imported
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(work / "workflow"), str(ROOT / "src")]),
               PATH=os.pathsep.join([str(Path(sys.executable).parent), os.environ["PATH"]]),
               MPLBACKEND="Agg")
    run = subprocess.run([sys.executable, "-m", "snakemake", "--dry-run", "--cores", "1",
                          "--directory", str(work), "bench", "paper/generated/macros.tex"],
                         cwd=work, env=env, capture_output=True, text=True, timeout=600)
    out = run.stdout + run.stderr
    assert run.returncode == 0, out[-3000:]
    planned = re.findall(r"^(?:local)?rule (\w+):", out, re.M)
    assert {"bench_toy", "plot_bench_toy", "report_tables"} <= set(planned), planned
    assert "results/bench_toy.nc" in out and "figures/bench_toy.pdf" in out
    assert "paper/generated/tab_toy.tex" in out  # its table is an output of the report
    # and it runs: its rule writes its dataset, its figure rule draws it
    run = subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1", "--directory",
                          str(work), "figures/bench_toy.pdf"], cwd=work, env=env,
                         capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, (run.stdout + run.stderr)[-3000:]
    assert (work / "figures" / "bench_toy.png").stat().st_size > 0
    assert (work / "logs" / "bench_toy.log").exists()
    # its report part, found by the copy's report.generate machinery
    check = ("import xarray as xr\n"
             "from filippov_paper import product, report\n"
             "import filippov_paper.benchmarks.toy as toy\n"
             "assert product.problems(toy) == [], product.problems(toy)\n"
             "m = report.Macros()\n"
             "tables = report.benchmark_parts({'bench_toy': xr.Dataset({'value': ((), 2.5)})}, m)\n"
             "assert tables['tab_toy.tex'] == 'toy block\\n', tables\n"
             "assert m.flags['rpHaveToy'] and m.values()['rpToyValue'][0] == 2.5\n"
             "assert list(m.flags)[-1] == 'rpHaveToy'  # order 50: after the others\n"
             "m = report.Macros()\n"
             "assert report.benchmark_parts({}, m)['tab_toy.tex'] == '% tab_toy.tex: no table\\n'\n"
             "print('toy ok')\n")
    run = subprocess.run([sys.executable, "-c", check], cwd=work, env=env, capture_output=True,
                         text=True, timeout=300)
    assert run.returncode == 0 and "toy ok" in run.stdout, run.stdout + run.stderr
    # and nothing else of the copy differs from this tree
    changed = sorted(str(p.relative_to(work)) for p in (work / "workflow").rglob("*.py")
                     if "__pycache__" not in p.parts
                     and p.read_bytes() != _bytes_or_none(ROOT / p.relative_to(work)))
    assert changed == ["workflow/filippov_paper/benchmarks/toy.py",
                       "workflow/filippov_paper/plotting/bench_toy.py"], changed


def _bytes_or_none(path: Path):
    return path.read_bytes() if path.exists() else None
