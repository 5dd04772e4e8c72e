"""The reproduction report paper/main.pdf, built by the Snakemake rule `paper` in a
scratch copy of the project.

The copy reuses results/ and figures/ of the working tree when every scene of
the report is there (a quick build: tables + LaTeX only); otherwise (a fresh
clone, as in CI) Snakemake computes them first. Without TeX the build tests skip
locally, but fail when CI=true: CI must install TeX (.ci/run does).
"""
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from conftest import report_args, run_snakemake
from filippov_paper import report, scenes
from filippov_paper.config import scene_files

ROOT = Path(__file__).resolve().parents[1]
TEX_PACKAGES = ("texlive-publishers texlive-latex-extra texlive-latex-recommended "
                "texlive-fonts-recommended latexmk")


# ----------------------------------------------------------------------------- no TeX needed
def test_number_formatting_round_trips():
    for x in (0.0, 1.0, -0.5, 0.874217, 8.74e-3, 2.2e-13, -1.9e-22, 315.83, 25000.0, 1e-8,
              1.2e-8, 9.99e-4, 3979.0, -0.9936):
        text = report.num(x)
        assert report.parse_num(text) == pytest.approx(x, rel=5e-3, abs=0), (x, text)
    assert report.num(8.74e-4) == r"8.74\times10^{-4}" and report.num(8.74e-3) == "0.00874"
    assert report.num(1e-6) == "10^{-6}"
    assert report.num(0.999999e-3, 2) == "10^{-3}"


def test_absent_optional_results_say_not_yet_computed():
    from filippov_paper.benchmarks import work_precision
    from filippov_paper.scenes import fig10_dfo, fig11_dfo_retmaps
    m = report.Macros()
    t10, t11 = fig10_dfo.report(None, m), fig11_dfo_retmaps.report(None, m)
    tb = work_precision.report(None, m)
    for name in ("compile_cost", "effect_cost", "attractor_cost"):  # `make bench` only
        assert _bench_module(name).report(None, m) is None
    from filippov_paper import hard_cases
    th, tr = hard_cases.report(None, m)
    for text in (t10, t11, tb, th, tr):
        assert report.NOT_YET in text
    assert m.flags == {"rpHaveTen": False, "rpHaveEleven": False, "rpHaveBench": False,
                       "rpHaveBenchTiming": False, "rpHaveBenchSpread": False,
                       "rpHaveBenchPasses": False, "rpHaveBenchMachine": False,
                       "rpHaveHardCases": False,
                       "rpHaveCompileCost": False, "rpHaveCompileSpread": False,
                       "rpHaveEffects": False,
                       "rpHaveReturnCost": False}
    assert m.items == []


def _bench_module(name):
    import importlib
    return importlib.import_module(f"filippov_paper.benchmarks.{name}")


def test_the_compile_cost_is_quoted_when_measured():
    from filippov_paper.benchmarks import compile_cost
    names = [s for s, _ in compile_cost.STAGES]
    cc = xr.Dataset({"cold": ("stage", [0.9, 13.0, 1.9, 0.01, 11.6]),
                     "warm": ("stage", [0.7, 0.04, 0.48, 0.0, 0.05])}, coords={"stage": names})
    m = report.Macros()
    compile_cost.report(cc, m)
    got = m.values()
    assert m.flags["rpHaveCompileCost"] is True
    assert got["rpCompileKernelCold"][0] == 13.0
    assert got["rpCompileKernelCold"][1].startswith("bench_compile_cost:cold[stage='kernel']")
    assert got["rpCompileKernelDpdzCold"][0] == 11.6
    assert got["rpCompileModelWarm"][0] == 0.48
    # a dataset of an older benchmark without a quoted stage: not quoted at all
    m = report.Macros()
    compile_cost.report(cc.isel(stage=slice(0, 4)), m)
    assert m.flags["rpHaveCompileCost"] is False and m.items == []


def test_optional_tables_show_whatever_the_datasets_hold():
    ds = xr.Dataset({"v_hopf": ((), 2.5, {"long_name": "Hopf point"}),
                     "v_gs": ((), 3.25, {"long_name": "grazing-sliding point"})})
    from filippov_paper.scenes import fig10_dfo
    m = report.Macros()
    t10 = fig10_dfo.report(ds, m)
    assert "v\\_hopf" in t10 and "2.5" in t10 and report.NOT_YET not in t10
    assert m.values()["rpTenVGS"][0] == 3.25
    bench = xr.Dataset({"error": (("method", "tol"), [[1e-3, 1e-6]]),
                        "seconds": (("method", "tol"), [[0.1, 0.4]])},
                       coords={"method": ["exact"], "tol": [1e-6, 1e-10]})
    text = _bench_module("work_precision").report(bench, m)
    assert r"\texttt{method}" in text and r"\texttt{exact}" in text and "$0.001$" in text
    assert m.flags["rpHaveBench"]


def _check_bench_table(tab: str, ds, macros: dict) -> int:
    """The work-precision table ``tab`` (generated/tab_bench.tex) against its dataset:
    every time printed is the statistic the sweep says it shows (the variable whose
    ``statistic`` attribute is the dataset's ``timing_statistic``), as stored, and next
    to it the spread, its first to third quartile; the speed-ups over RK45 are quoted
    as ranges (low, high) of the stored ends, never as one number; the machine is
    named. ``macros``: {name: (body, source)}. Returns the time cells checked."""
    stat = ds.attrs["timing_statistic"]
    shown = [v for v in ds.data_vars if v.startswith("wall_time") and ds[v].dims ==
             ("problem", "config") and ds[v].attrs.get("statistic") == stat]
    assert len(shown) == 1, shown
    spread = [[v for v in ds.data_vars if v.startswith("wall_time")
               and ds[v].attrs.get("statistic") == q] for q in ("q1", "q3")]
    assert all(len(v) == 1 for v in spread), f"the sweep stores no spread: {spread}"
    (q1,), (q3,) = spread

    def ms(x):
        return f"${report.num(1e3 * float(x), 2)}$"

    blocks = [b.split(r"\midrule")[1] for b in tab.split(r"\begin{tabular}")[1:]]
    names = [str(p) for p in ds.problem.values]
    prefixes = [pre for pre in ("fig04", "fig11") if any(n.startswith(pre) for n in names)]
    assert len(blocks) >= len(prefixes)   # (then the blocks of `make bench`, if measured)
    checked = 0
    for block, prefix in zip(blocks, prefixes):
        probs = [i for i, n in enumerate(names) if n.startswith(prefix)]
        configs = [j for j in range(ds.sizes["config"])
                   if any(str(ds.status.values[i, j]) != "n/a" for i in probs)]
        rows = [r for r in block.split(r"\bottomrule")[0].strip().splitlines() if r.strip()]
        assert len(rows) == len(configs), (prefix, rows)
        for row, j in zip(rows, configs):
            cells = [c.strip() for c in row.rstrip().removesuffix(r"\\").split("&")]
            cells = cells[2:]                        # method, rtol
            for i in probs:
                if str(ds.status.values[i, j]) != "ok":
                    assert cells.pop(0).startswith(r"\multicolumn{4}"), (row, i)
                    continue
                err, t, spread, missed = cells[:4]
                del cells[:4]
                assert t == ms(ds[shown[0]].values[i, j]), (row, i, shown[0])
                assert spread == f"{ms(ds[q1].values[i, j])}--{ms(ds[q3].values[i, j])}", \
                    (row, i)
                assert int(missed) == int(ds.missed_switches.values[i, j])
                checked += 1
            assert not cells, row
    for key in "ABCD"[:ds.sizes["problem"]]:
        assert f"rpBenchSpeedup{key}" not in macros      # no single number
        lo, hi = (macros[f"rpBenchSpeedup{end}{key}"] for end in ("Low", "High"))
        i = "ABCD".index(key)
        for (body, src), var in ((lo, "speedup_vs_rk45_low"), (hi, "speedup_vs_rk45_high")):
            assert src.startswith(f"work_precision:{var}[{i}]"), src
            if np.isfinite(ds[var].values[i]):
                assert report.parse_num(body) == pytest.approx(float(ds[var].values[i]),
                                                               rel=0.051)
    assert macros["rpBenchCPU"][0] == report.tex_escape(ds.attrs["machine_cpu"])
    for name, attr in (("rpBenchLoadBefore", "load_average_before"),
                       ("rpBenchLoadAfter", "load_average_after"), ("rpBenchCores", "cpus")):
        assert report.parse_num(macros[name][0]) == pytest.approx(float(ds.attrs[attr]),
                                                                  rel=0.0051, abs=0.0051)
    return checked


def _bench_sweep():
    """A sweep as run() writes it (the synthetic stand-in with the spread, the machine and
    the timing attributes), its times far enough apart that a cell printing another
    statistic (min, a quartile, max) than the stored one would show."""
    import synthetic
    from filippov_paper.benchmarks import timing

    ds = synthetic.dataset("work_precision")
    wall = ds.wall_time.values
    status = np.array(ds.status.values, dtype=object)
    status[1, 0] = "failed: step size underflow"
    attrs = {**timing.describe(min_rounds=3, min_time=0.2, passes=3), **timing.machine_attrs(),
             **timing.load_attrs((2.5, 0, 0), (3.25, 0, 0)), "target_error": 1e-8}
    return ds.assign(
        wall_time=(ds.wall_time.dims, wall, {"statistic": "median"}),
        wall_time_min=(ds.wall_time.dims, 0.5 * wall, {"statistic": "min"}),
        wall_time_q1=(ds.wall_time.dims, 0.7 * wall, {"statistic": "q1"}),
        wall_time_q3=(ds.wall_time.dims, 1.6 * wall, {"statistic": "q3"}),
        wall_time_max=(ds.wall_time.dims, 4.0 * wall, {"statistic": "max"}),
        status=(ds.status.dims, status),
        missed_switches=(ds.error_map.dims, np.arange(wall.size).reshape(wall.shape)),
        runs=(ds.error_map.dims, np.full(wall.shape, 3)),
        speedup_vs_rk45=("problem", [100.0, 20.0]),
        speedup_vs_rk45_low=("problem", [44.0, 8.7]),
        speedup_vs_rk45_high=("problem", [230.0, 46.0])).assign_attrs(attrs)


def test_the_bench_table_prints_the_stored_statistic_and_its_spread():
    """The time in each cell of the work-precision table is the statistic the sweep says
    it shows, as stored (not the min, not a quartile), the spread beside it (first to
    third quartile) and the speed-ups as ranges; on a sweep made like run()'s (the same
    check runs on the shared build: test_the_built_bench_table_...)."""
    from filippov_paper.benchmarks import work_precision

    ds = _bench_sweep()
    m = report.Macros()
    tab = work_precision.report(ds, m)
    macros = report.read_macros(m.tex())
    assert _check_bench_table(tab, ds, macros) == 2 * 6 - 1  # one cell failed
    assert m.flags["rpHaveBenchSpread"] and m.flags["rpHaveBenchMachine"]
    assert macros["rpBenchPasses"][0] == "three passes"
    # the text quotes the ranges and the machine, never a single speed-up
    text = (ROOT / "paper" / "sec_bench.tex").read_text()
    assert not re.search(r"\\rpBenchSpeedup[A-D]\b", text)
    for name in ("rpBenchSpeedupLowA", "rpBenchSpeedupHighD", "rpBenchCPU", "rpBenchLoadBefore",
                 "rpBenchLoadAfter", "rpBenchCoresPhrase", "rpBenchPython", "rpBenchNumpy",
                 "rpBenchScipy", "rpBenchNumba", "rpBenchPasses"):
        assert "\\" + name + "{}" in text, name


def test_every_test_named_in_the_report_exists():
    named = set()
    for tex in (ROOT / "paper").glob("*.tex"):
        named |= set(re.findall(r"\\testref\{([A-Za-z0-9_]+)\}", tex.read_text()))
    assert len(named) > 40
    defined = set()
    for py in (ROOT / "tests").glob("test_*.py"):
        defined |= set(re.findall(r"^def (test_[A-Za-z0-9_]+)\(", py.read_text(), re.M))
    assert not named - defined, f"the report names tests that do not exist: {sorted(named - defined)}"


def test_no_number_typed_in_the_figure_prose():
    # numbers in the text come from macros; digits left in the prose are labels,
    # equation constants and the paper's own parameters (listed here)
    allowed = {"0", "1", "2", "3", "4", "8", "12", "-12", "-1", "-4", "0.5", "10", "60", "-0.5",
               "0.1", "0.01", "3.32", "3.1", "-2", "0.3", "2.5", "10^{-10}",
               "10^{-2}", "10^{-3}", "10^{-4}",  # parameters of named tests
               "-3"}  # exponent of the jump estimate e^{-3 pi mu/omega}
    allowed |= {"10^{-6}"}  # sec_instabilities: the hard-case eps of named tests
    # sec_dryfriction: a named test's threshold; sec_bench: the references' rtol and the
    # manifest's floors (filippov_paper.benchmarks.work_precision.tolerances)
    allowed |= {"10^{-9}", "10^{-13}", "10^{-8}"}
    for name in ("sec_figures.tex", "sec_pdm.tex", "sec_hardcases.tex", "sec_instabilities.tex",
                 "sec_dryfriction.tex", "sec_bench.tex"):
        text = (ROOT / "paper" / name).read_text()
        text = re.sub(r"\\paperfig\{[^}]*\}\{[^}]*\}", "", text)
        text = re.sub(r"\\(pref|pnum|testref|label|ref|figref|eqref|includegraphics|input)(\[[^]]*\])?\{[^}]*\}",
                      "", text)
        text = re.sub(r"\\[A-Za-z]+", "", text)   # macro names (rpTwoPeriod, ...)
        found = set(re.findall(r"(?<![A-Za-z_0-9.])-?\d+(?:\.\d+)?(?:\^\{-?\d+\})?", text))
        assert not found - allowed, f"{name}: numbers typed by hand: {sorted(found - allowed)}"


def test_the_paper_is_cited_by_its_printed_numbers():
    # every citation of the paper goes through paper/paper_labels.tex (derived from the
    # paper's source by filippov_paper.paper_labels): no raw label text, no unknown label
    from filippov_paper.paper_labels import read_tex

    known = read_tex((ROOT / "paper" / "paper_labels.tex").read_text())
    cited = set()
    for tex in sorted((ROOT / "paper").glob("sec_*.tex")) + [ROOT / "paper" / "main.tex"]:
        text = tex.read_text()
        assert "\\plabel" not in text, f"{tex.name}: cites a raw label"
        cited |= set(re.findall(r"\\(?:pref|pnum)\{([^}]*)\}", text))
        cited |= set(re.findall(r"\\paperfig\{([^}]*)\}", text))
    cited.discard("#1")  # main.tex's definitions of \paperfig and the bookmark text
    assert len(cited) > 30
    assert not cited - set(known), f"labels the paper does not have: {sorted(cited - set(known))}"
    # each of the eleven figures is captioned with the paper figure it reproduces
    captions = "".join((ROOT / "paper" / n).read_text()
                       for n in ("sec_figures.tex", "sec_pdm.tex", "sec_dryfriction.tex"))
    ids = re.findall(r"\\paperfig\{fig:[^}]*\}\{(fig\d\d)", captions)
    assert sorted(ids) == [f"fig{k:02d}" for k in range(1, 12)]


def test_every_figure_reference_records_its_page():
    # \figref is \ref that also writes the page it is printed on into main.aux, which
    # test_every_figure_is_printed_near_its_first_mention_before_the_references reads;
    # a plain \ref to a figure would go unseen there
    for tex in sorted((ROOT / "paper").glob("*.tex")):
        plain = re.findall(r"\\ref\{(fig:[^}]*)\}", tex.read_text())
        assert not plain, f"{tex.name}: \\ref to a figure, use \\figref: {plain}"


def test_the_lyapunov_table_heads_each_group_of_eps_columns():
    # two groups of one column per eps: each says what it holds and that its columns
    # are eps values, under a rule of its own (booktabs \cmidrule)
    from filippov_paper.scenes.fig13_small_scale_chaos import _report_table

    eps, s, theta = [1e-2, 1e-3, 1e-4], np.linspace(-1.0, 5.0, 7), [0.7, 0.2]
    shape = (len(theta), len(eps), len(s))
    ds = xr.Dataset({"lyapunov": (("theta", "eps", "s"), -np.ones(shape)),
                     "lyapunov_limit": (("theta", "eps", "s"), -np.ones(shape)),
                     "slope_pdm": ("theta", [-0.43, -4.0])},
                    coords={"theta": theta, "eps": eps, "s": s}, attrs={"s_max": 5.0})
    text = _report_table(ds)
    head = text.split(r"\midrule")[0]
    groups = re.findall(r"\\multicolumn\{3\}\{c\}\{([^}]*\$[^$]*\$)\}", head)
    assert len(groups) == 2 and all(r"\epsilon=" in g for g in groups), head
    assert r"\cmidrule(lr){3-5}" in head and r"\cmidrule(l){6-8}" in head, head
    # the rules stand between the group heads and the row of eps values
    assert head.index("cmidrule") < head.index(r"$\theta$"), head


# ----------------------------------------------------------------------------- the build
def _tex_available():
    if not all(shutil.which(t) for t in ("latexmk", "pdflatex", "kpsewhich")):
        return False
    found = subprocess.run(["kpsewhich", "elsarticle.cls"], capture_output=True, text=True)
    return found.returncode == 0 and bool(found.stdout.strip())


def _require_tex():
    if _tex_available():
        return
    msg = ("TeX is not installed (need latexmk, pdflatex, elsarticle.cls); install with: "
           f"apt-get install -y --no-install-recommends {TEX_PACKAGES}")
    if os.environ.get("CI", "").lower() in ("true", "1", "yes"):
        pytest.fail("CI=true but " + msg)
    pytest.skip(msg)


def _snakemake(work, *args, cores="1", timeout=3000):
    return run_snakemake(work, *args, cores=cores, timeout=timeout)


@pytest.fixture(scope="module")
def built(workflow_build):
    """The shared build of rule `all`, which includes paper/main.pdf when TeX is there."""
    _require_tex()
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-4000:] + run.stderr[-4000:]
    scenes = scene_files(work / "config" / "scenes")
    return {"work": work, "scenes": scenes, "run": run, "seconds": workflow_build["seconds"]}


def test_pdf_is_built_with_every_figure(built):
    work = built["work"]
    pdf = work / "paper" / "main.pdf"
    assert pdf.read_bytes().startswith(b"%PDF") and pdf.stat().st_size > 100_000
    fls = (work / "paper" / "main.fls").read_text()
    inputs = {os.path.normpath(p) for p in re.findall(r"^INPUT (.+)$", fls, re.M)}
    for s in built["scenes"]:
        if s in scenes.known_scenes():
            assert f"../figures/{s}.pdf" in inputs, f"figure {s} not included"
    log = (work / "paper" / "main.log").read_text(errors="replace")
    pages = int(re.search(r"Output written on \S+ \((\d+) pages?", log).group(1))
    assert pages >= 10, pages


def test_log_has_no_overfull_box_over_five_points(built):
    log = (built["work"] / "paper" / "main.log").read_text(errors="replace")
    widths = [float(w) for w in re.findall(r"Overfull \\hbox \(([\d.]+)pt too wide\)", log)]
    assert all(w <= 5.0 for w in widths), f"overfull boxes: {sorted(widths)[::-1][:5]} pt"


def _aux_pages(aux: str):
    """From main.aux (rule `paper` keeps it): {figure label: (number, page)} of every
    figure, {figure label: page of its first \figref} and, in the order the pages were
    shipped out, the labels of the figures and of the references (rp:references)."""
    labels = re.findall(r"^\\newlabel\{((?:fig|rp):[^}]*)\}\{\{([^}]*)\}\{(\d+)\}", aux, re.M)
    figures = {lab: (int(num), int(page)) for lab, num, page in labels if lab.startswith("fig:")}
    first = {}
    for lab, page in re.findall(r"^\\rpfigmention\{([^}]*)\}\{(\d+)\}", aux, re.M):
        first[lab] = min(first.get(lab, int(page)), int(page))
    return figures, first, [lab for lab, _, _ in labels]


def test_every_figure_is_printed_near_its_first_mention_before_the_references(built):
    """Where the figures land in the PDF: every figure before the references (its label
    written out on an earlier page, or higher up on the same one: the aux file is
    written in the order the pages are shipped out) and at most two pages from the
    first page that refers to it (\figref)."""
    work = built["work"]
    aux = (work / "paper" / "main.aux").read_text(errors="replace")
    figures, first, order = _aux_pages(aux)
    log = (work / "paper" / "main.log").read_text(errors="replace")
    pages = int(re.search(r"Output written on \S+ \((\d+) pages?", log).group(1))
    numbers = sorted(n for n, _ in figures.values())
    assert numbers == list(range(1, len(numbers) + 1)), numbers
    assert len(numbers) >= len([s for s in built["scenes"] if s in scenes.known_scenes()])
    assert "rp:references" in order, "no rp:references label in main.aux"
    after = order[order.index("rp:references") + 1:]
    assert not after, f"figures printed after the references: {after}"
    where = {lab: (num, page, first.get(lab)) for lab, (num, page) in figures.items()}
    never = sorted(f"Fig. {n} ({lab})" for lab, (n, _, m) in where.items() if m is None)
    assert not never, f"figures the text never refers to (\\figref): {never}"
    far = sorted((n, lab, page, m) for lab, (n, page, m) in where.items() if abs(page - m) > 2)
    assert not far, ("figures more than two pages from their first mention (number, label, "
                     f"page, first mention; {pages} pages): {far}")


def test_log_has_no_undefined_references_or_missing_files(built):
    log = (built["work"] / "paper" / "main.log").read_text(errors="replace")
    for bad in ("undefined references", "There were undefined", "Reference `",
                "Citation `", "multiply defined", "not found", "Undefined control sequence",
                "Rerun to get"):
        assert bad not in log, f"main.log contains {bad!r}"


def _value(ds_dir: Path, source: str):
    """Re-read `dataset:variable[sel]` or `dataset:attrs.name` (None for derived)."""
    m = re.fullmatch(r"(fig\d\d_[a-z0-9_]+|hard_cases|work_precision):([A-Za-z0-9_]+)(?:\.([A-Za-z0-9_]+))?"
                     r"(\[(.*)\])?", source)
    if not m or source.startswith("derived"):
        return None
    sid, var, attr, _, sel = m.groups()
    with xr.open_dataset(ds_dir / f"{sid}.nc") as ds:
        if var == "attrs":
            v = ds.attrs[attr]
            return float(np.atleast_1d(v)[int(sel)] if sel is not None else v)
        if sel is None:
            return float(ds[var].values)
        if re.fullmatch(r"-?\d+", sel):
            return float(ds[var].values[int(sel)])
        kw = dict(re.findall(r"(\w+)=('[^']*'|[^,]+)", sel))
        kw = {k: (v.strip("'") if v.startswith("'") else float(v)) for k, v in kw.items()}
        pos = {k: int(v) for k, v in kw.items() if k not in ds.coords}
        lab = {k: v for k, v in kw.items() if k in ds.coords}
        return float(ds[var].isel(**pos).sel(**lab).values)


def test_macros_match_their_source_variables(built):
    work = built["work"]
    macros = report.read_macros((work / "paper/generated/macros.tex").read_text())
    assert len(macros) > 100
    checked = 0
    for name, (body, source) in macros.items():
        if " | digits=" not in source:  # a text macro (a word, a formula, a sentence)
            continue
        source, digits = source.rsplit(" | digits=", 1)
        value = _value(work / "results", source)
        if value is None:
            continue
        got = report.parse_num(body)
        rel = 0.51 * 10.0 ** (1 - int(digits))  # rounding to that many digits
        assert got == pytest.approx(value, rel=rel, abs=1e-300), (name, body, source, value)
        checked += 1
    assert checked > 60


def test_derived_macros_match_the_datasets(built):
    work = built["work"]
    macros = report.read_macros((work / "paper/generated/macros.tex").read_text())
    val = {k: report.parse_num(b) for k, (b, s) in macros.items() if " | digits=" in s}
    with xr.open_dataset(work / "results/fig04_retmaps.nc") as ds:
        x2 = ds.x2.values
        P = ds.P.sel(theta=-0.5).values
        j = np.where(x2 > 1)[0][0]
        assert val["rpFourJump"] == pytest.approx(1 - P[j], rel=1e-3)
        assert val["rpFourJumpOverEps"] == pytest.approx((1 - P[j]) / ds.attrs["eps"], rel=1e-2)
        assert val["rpFourSlopeSmooth"] == pytest.approx(np.exp(-4 * np.pi / (8 * np.pi)), rel=1e-3)
    with xr.open_dataset(work / "results/fig11_dfo_retmaps.nc") as ds, \
            xr.open_dataset(work / "results/fig10_dfo.nc") as d10:
        # "both above the reduced model's grazing-sliding point, by ... eps"
        for k, key in enumerate("AB"):
            shift = (float(ds.v0_sn[k]) - float(d10.v_gs)) / float(ds.eps[k])
            assert shift > 0 and val[f"rpElevenSNShift{key}"] == pytest.approx(shift, rel=6e-3)
    with xr.open_dataset(work / "results/fig02_cases.nc") as ds:
        assert val["rpTwoPeriodOverEps"] == pytest.approx(float(ds.period) / ds.attrs["eps"], rel=1e-2)
    with xr.open_dataset(work / "results/fig07_pdm_theta_neg.nc") as ds:
        tab = (work / "paper/generated/fig07_pdm_theta_neg.tex").read_text()
        rows = [r for r in tab.splitlines() if r.startswith("$") and "epsilon" not in r]
        assert len(rows) == ds.sizes["eps"]
        for row, e in zip(rows, ds.eps.values):
            cells = [c.strip().strip("$") for c in row[:-2].split("&")]
            assert report.parse_num(cells[0]) == pytest.approx(e, rel=1e-6)
            assert report.parse_num(cells[3]) == pytest.approx(float(ds.error_printed.sel(eps=e)), rel=6e-3)
            assert report.parse_num(cells[5]) == pytest.approx(float(ds.error_first_order.sel(eps=e)), rel=6e-3)
    with xr.open_dataset(work / "results/hard_cases.nc") as ds:
        assert val["rpHardSlopeMin"] == pytest.approx(float(ds.slope.min()), rel=6e-3)
        assert val["rpHardSlopeMax"] == pytest.approx(float(ds.slope.max()), rel=6e-3)
        assert val["rpHardPeriodDev"] == pytest.approx(
            float(ds.chatter_period_max_rel_dev.max()), rel=6e-2)
        assert val["rpHardKernelFinal"] == pytest.approx(float(ds.kernel_final_abs_x.max()),
                                                         rel=6e-2)
        tab = (work / "paper/generated/tab_hard_cases.tex").read_text()
        rows = [r for r in tab.splitlines() if r.startswith("$") and "epsilon" not in r]
        assert len(rows) == 2 * ds.sizes["eps"]  # return maps, then pseudo-equilibrium
        for row, e in zip(rows[:ds.sizes["eps"]], ds.eps.values):
            cells = [c.strip().strip("$") for c in row[:-2].split("&")]
            assert report.parse_num(cells[0]) == pytest.approx(e, rel=1e-6)
            assert report.parse_num(cells[1]) == pytest.approx(
                float(ds.jump_over_eps.sel(eps=e)), rel=6e-6)
            assert report.parse_num(cells[2]) == pytest.approx(float(ds.slope.sel(eps=e)),
                                                               rel=6e-4)
    with xr.open_dataset(work / "results/fig09_pdm_theta_pos.nc") as ds:
        tab = (work / "paper/generated/fig09_pdm_theta_pos.tex").read_text()
        rows = [r for r in tab.splitlines() if r.startswith("$") and "epsilon" not in r]
        for row, e in zip(rows, ds.eps.values):
            cells = [c.strip().strip("$") for c in row[:-2].split("&")]
            assert report.parse_num(cells[4]) == pytest.approx(float(ds.error_core.sel(eps=e)), rel=6e-3)


def test_the_built_bench_table_prints_the_stored_statistic_and_its_spread(built):
    """The shared build's work-precision table against its sweep: each time printed is the
    stored statistic with its spread (test_the_bench_table_prints_the_stored_statistic_...
    on a made-up sweep, without TeX)."""
    work = built["work"]
    macros = report.read_macros((work / "paper/generated/macros.tex").read_text())
    tab = (work / "paper/generated/tab_bench.tex").read_text()
    with xr.open_dataset(work / "results/work_precision.nc") as ds:
        assert _check_bench_table(tab, ds.load(), macros) > 10


def test_optional_sections_follow_the_results(built):
    work = built["work"]
    macros = (work / "paper/generated/macros.tex").read_text()
    for sid, flag, tab in (("fig10_dfo", "rpHaveTen", "fig10_dfo.tex"),
                           ("fig11_dfo_retmaps", "rpHaveEleven", "fig11_dfo_retmaps.tex"),
                           ("work_precision", "rpHaveBench", "tab_bench.tex"),
                           ("hard_cases", "rpHaveHardCases", "tab_hard_cases.tex")):
        present = (work / f"results/{sid}.nc").exists()
        assert f"\\{flag}{'true' if present else 'false'}" in macros
        assert (report.NOT_YET in (work / "paper/generated" / tab).read_text()) != present


def test_failed_build_leaves_no_pdf(built, tmp_path):
    # a copy (timestamps kept, so only the report is out of date): the shared build
    # stays untouched for the other tests
    work = tmp_path / "project"
    shutil.copytree(built["work"], work, symlinks=True)
    sec = work / "paper" / "sec_bench.tex"
    good = sec.read_text()
    try:
        sec.write_text(good + "\n\\thiscommanddoesnotexist\n")
        run = _snakemake(work, "paper/main.pdf")
        assert run.returncode != 0
        assert not (work / "paper" / "main.pdf").exists()
        assert not list((work / "paper").glob(".build.*"))
        assert "thiscommanddoesnotexist" in (work / "paper" / "main.log").read_text(errors="replace")
    finally:
        sec.write_text(good)


def test_html_report_links_every_figure_to_its_rule(workflow_build, tmp_path):
    """`snakemake --report` on a finished build: every figure, with the rule that drew it."""
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    out = tmp_path / "report.html"
    rep = _snakemake(work, *report_args(out))
    assert rep.returncode == 0, rep.stdout[-3000:] + rep.stderr[-3000:]
    html = out.read_text(errors="replace")
    scenes = scene_files(work / "config" / "scenes")
    for scene in scenes:
        assert f"{scene}.pdf" in html and f"{scene}.png" in html, scene
        # the dataset and the scene file are attached too
        assert f"{scene}.nc" in html and f"{scene}.yaml" in html, scene
    for rule in ("compute", "plot"):
        assert rule in html
    # captions from the scene: the paper's printed figure number, the description,
    # the physical parameters (not only a code hash)
    from html import escape as html_escape

    from filippov_paper.paper_labels import read_tex
    from filippov_paper.report_html import cite, printed_labels

    printed = read_tex((ROOT / "paper" / "paper_labels.tex").read_text())
    # the text a reader sees (docutils splits a literal such as ``eps = 1e-13`` at "-")
    shown = re.sub(r"<[^>]+>", "", html)
    for scene in scenes:
        data = yaml.safe_load((work / "config" / "scenes" / f"{scene}.yaml").read_text())
        if "paper_figure" in data:
            number = printed[data["paper_figure"]].replace("~", " ")
            assert f"<strong>{number}</strong>" in html, (scene, number)
        else:  # the instability scenes go beyond the paper's figures
            assert "Beyond the paper" in html, scene
        # (the paper's labels in it replaced by its printed numbers: tests/test_report_html.py)
        description = " ".join(str(data.get("description", "")).split())
        first = cite(description, printed_labels(ROOT / "paper" / "paper_labels.tex"))[:40]
        assert html_escape(first) in html, (scene, first)
        for key, value in data["parameters"].items():
            if isinstance(value, (int, float)):
                assert f"{key} = {value}" in shown, (scene, key)


def test_every_scene_declares_its_report_part():
    # no list of scenes in filippov_paper.report: each report part brings its own, and
    # the report refuses to go on without a scene that does not declare itself optional
    import importlib
    for sid in scenes.known_scenes():
        module = importlib.import_module(f"filippov_paper.scenes.{sid}")
        assert callable(module.report), sid
    with pytest.raises(ValueError, match="report needs the datasets of fig01_slidesketch"):
        report.generate({})
