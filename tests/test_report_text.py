"""Words the report generates (issue 31): counts said as prose says them ("no
configuration failed", "one untimed run", "four of the five eps values"), and the
formulas of the datasets' plain-text attributes in the paper's notation."""
from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import synthetic
from filippov_paper import report

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize("n, text", [(0, "no configuration"), (1, "one configuration"),
                                     (2, "two configurations"), (12, "twelve configurations"),
                                     (16, "16 configurations")])
def test_count_phrase(n, text):
    assert report.count_phrase(n, "configuration") == text
    assert report.count_phrase(n, "configuration", capital=True) == text[0].upper() + text[1:]


def test_count_phrase_irregular_plural_and_bad_counts():
    assert report.count_phrase(3, "matrix", "matrices") == "three matrices"
    assert report.count_phrase(1, "matrix", "matrices") == "one matrix"
    assert report.count_phrase(np.int64(0), "value") == "no value"
    with pytest.raises(ValueError):
        report.count_phrase(-1, "value")


def test_range_phrase():
    assert report.range_phrase(3, 250, "run") == "3 to 250 runs"
    assert report.range_phrase(3, 5, "run") == "three to five runs"
    assert report.range_phrase(1, 1, "run") == "one run"
    assert report.range_phrase(4, 4, "run") == "four runs"


def test_share_phrase():
    v = r"$\epsilon$ value"
    assert report.share_phrase(0, 5, v) == r"none of the $\epsilon$ values"
    assert report.share_phrase(0, 2, v) == r"neither of the $\epsilon$ values"
    assert report.share_phrase(1, 5, v) == r"one of the five $\epsilon$ values"
    assert report.share_phrase(4, 5, v) == r"four of the five $\epsilon$ values"
    assert report.share_phrase(5, 5, v) == r"all five $\epsilon$ values"
    assert report.share_phrase(2, 2, v) == r"both $\epsilon$ values"
    assert report.share_phrase(1, 1, v) == r"the only $\epsilon$ value"
    with pytest.raises(ValueError):
        report.share_phrase(3, 2, v)


def test_failed_sentence_says_zero_naturally():
    from filippov_paper.benchmarks.work_precision import _report_failed_sentence as sentence
    assert sentence(0) == "No configuration failed outright on any map."
    one, many = sentence(1), sentence(16)
    assert one.startswith("One configuration failed outright") and "cells marked" in one
    assert many.startswith("16 configurations failed outright")
    for text in (sentence(n) for n in range(0, 20)):
        assert not re.search(r"\b0 \w+s\b", text) and not re.search(r"\b1 \w+s\b", text)


def _bench_dataset(failed: int):
    ds = synthetic.dataset("work_precision")
    status = np.full(ds.status.shape, "ok", dtype=object)
    status.flat[:failed] = "failed: step size underflow"
    return ds.assign(status=(ds.status.dims, status),
                     missed_switches=(ds.error_map.dims, np.zeros(ds.error_map.shape, int)),
                     speedup_vs_rk45=("problem", [10.0, 20.0]),
                     runs=(ds.error_map.dims, np.full(ds.error_map.shape, 3)))\
        .assign_attrs(timing_statistic="median", timing_warmup=1, timing_min_rounds=3,
                      timing_min_time=0.2)


@pytest.mark.parametrize("failed, start", [(0, "No configuration failed"),
                                           (1, "One configuration failed"),
                                           (3, "Three configurations failed")])
def test_bench_macros_count_in_words(failed, start):
    from filippov_paper.benchmarks import work_precision
    m = report.Macros()
    work_precision.report(_bench_dataset(failed), m)
    got = {name: body for name, _, _, body in m.items}
    assert got["rpBenchFailedSentence"].startswith(start)
    assert got["rpBenchWarmupRuns"] == "one untimed run"
    assert got["rpBenchMinRoundsRuns"] == "three timed runs"
    assert got["rpBenchRoundsRange"] == "three runs"
    # the blocks of `make bench` are the other benchmarks' report parts
    assert "rpHaveEffects" not in m.flags and "rpHaveReturnCost" not in m.flags
    # the numbers stay quotable (and checked against the dataset) as before
    assert m.values()["rpBenchFailed"][0] == failed


def test_no_count_macro_stands_before_a_noun_in_the_text():
    """A count the report prints with its noun comes from a phrase macro, so that zero and
    one read right: no '\\rpBenchFailed{} configurations' in the text."""
    for name in ("rpBenchFailed", "rpBenchWarmup", "rpBenchMinRounds", "rpHardN",
                 "rpHardReturnStiffN"):
        for tex in sorted((ROOT / "paper").glob("sec_*.tex")):
            text = tex.read_text()
            assert not re.search(rf"\\{name}(\{{\}})?\$?[~ ]+(of the )?[a-z$]", text), (
                f"{tex.name}: \\{name} before its noun; use its phrase macro")


@pytest.mark.parametrize("plain, tex", [
    ("f_- = (1, 1 + x1/2), f_+ = (1, 1/2)", r"$f_-(x)=(1,\,1+x_1/2)$ and $f_+(x)=(1,\,1/2)$"),
    ("f_- = (1, 1), f_+ = (1, -1 - x1^2/4)", r"$f_-(x)=(1,\,1)$ and $f_+(x)=(1,\,-1-x_1^2/4)$"),
    ("h = x2", r"$h(x)=x_2$"),
    ("h = exp(-x1)*theta", r"$h(x)=\exp (-x_1)\,\theta$"),
    ("g = 2*x12^10 + y, k = x1, m = x2", r"$g(x)=2\,x_{12}^{10}+y$, $k(x)=x_1$ and $m(x)=x_2$"),
])
def test_formulas_in_the_papers_notation(plain, tex):
    assert report.formulas_tex(plain) == tex


@pytest.mark.parametrize("bad", ["f_- = (1, import os)", "x1 + 1", "", "f = {1}",
                                 "h = x1^(1/2)", "h = \\input{x}"])
def test_formulas_refuse_what_they_cannot_read(bad):
    with pytest.raises(ValueError):
        report.formulas_tex(bad)


def test_fig01_fields_are_math_not_code():
    from filippov_paper.scenes import fig01_slidesketch
    ds = synthetic.dataset("fig01_slidesketch").assign_attrs(
        crossing_fields="f_- = (1, 1 + x1/2), f_+ = (1, 1/2)",
        sliding_fields="f_- = (1, 1), f_+ = (1, -1 - x1^2/4)", switching_function="h = x2")
    m = report.Macros()
    fig01_slidesketch.report(ds, m)
    got = {name: body for name, _, _, body in m.items}
    for name in ("rpOneFieldsCross", "rpOneFieldsSlide", "rpOneSwitching"):
        assert r"\texttt" not in got[name] and got[name].startswith("$f" if "Fields" in name
                                                                   else "$h(x)")
    text = (ROOT / "paper" / "sec_figures.tex").read_text()
    assert r"\rpOneSwitching" in text and r"\rpOneFieldsCross" in text


def test_the_extension_budget_in_the_text_is_the_code_s():
    # sec_instabilities says in words how far an undecided run is extended
    from filippov import attractors

    words = {8: "eight", 12: "twelve"}
    text = " ".join((ROOT / "paper" / "sec_instabilities.tex").read_text().split())
    assert f"goes on for {words[attractors.EXTEND]} times as many returns" in text
    assert f"up to {words[attractors.MAX_EXTENSIONS]} times" in text


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs TeX (the report's tests)")
def test_the_bench_table_fits_the_line_whatever_the_timings(tmp_path):
    """The table of measured times prints numbers as wide as the machine was slow (a run
    under load: 12 s a cell, 1.2x10^4 ms): it must still fit the report's line width (an
    overfull box of 23 pt was seen when the suite built the report under load)."""
    ds = _bench_dataset(0)
    # two problems of one figure side by side, the longest method name, every cell 12 s
    # (with the spread beside each time: the quartiles, as wide as the time itself)
    slow = ds.assign(wall_time=ds.wall_time * 0 + 12.3456, error_map=ds.error_map * 0 + 1.23e-12,
                     wall_time_q1=ds.wall_time * 0 + 11.2345,
                     wall_time_q3=ds.wall_time * 0 + 98.7654)
    slow = slow.assign_coords(problem=["fig04 theta=-0.5", "fig04 theta=0.5"])
    slow["method"] = ("config", ["compiled, exact flows"] * slow.sizes["config"])
    from filippov_paper.benchmarks import work_precision
    m = report.Macros()
    table = work_precision.report(slow, m)
    assert table.count(report.FIT_BEGIN) == table.count(r"\begin{tabular}") >= 1
    assert rf"${report.num(11234.5, 2)}$--${report.num(98765.4, 2)}$" in table
    (tmp_path / "t.tex").write_text(
        "\\documentclass[preprint,11pt,a4paper]{elsarticle}\n\\usepackage{amsmath,booktabs}\n"
        "\\usepackage[export]{adjustbox}\n\\begin{document}\n\\begin{table}\n"
        "\\centering\\footnotesize\\setlength{\\tabcolsep}{4pt}\n" + table +
        "\\end{table}\n\\end{document}\n")
    subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "t.tex"],
                   cwd=tmp_path, capture_output=True, check=True, timeout=300)
    log = (tmp_path / "t.log").read_text(errors="replace")
    assert "Overfull \\hbox" not in log, re.findall(r"Overfull \\hbox \([\d.]+pt too wide\)", log)
