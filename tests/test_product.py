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
