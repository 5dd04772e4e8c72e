"""Snakemake's HTML report (report.html, `make report-html`; filippov_paper.report_html,
workflow/rules/report_html.smk, the caption templates workflow/report/*.rst).

What the report must do: no docutils error ("System Message") in any caption; every
dataset (results/*.nc) and every figure of the build attached; the paper cited by the
numbers it prints ("Eq. (18)"), never by its LaTeX labels (``eq:ymm``); each
dataset's format as read from the file; each rule once in the rule graph.

Three levels, cheapest first: the pieces (escaping, label mapping, format, rule graph)
and the templates rendered as Snakemake renders them; the report of a placeholder
build (every output of rule `all` as a small placeholder file, so `snakemake --report`
runs in seconds on a clean checkout); the report of the shared real build
(the `workflow_build` fixture of conftest.py, as tests/test_report.py uses it).
"""
import ast
import html
import json
import pickle
import re
import shutil
import textwrap
from pathlib import Path
from types import SimpleNamespace

import netCDF4
import numpy as np
import pytest
import yaml
from docutils.core import publish_parts
from jinja2 import Environment

from conftest import ROOT, copy_project, report_args, run_snakemake
from filippov_paper import report_html
from filippov_paper.config import scene_files
from filippov_paper.paper_labels import read_tex

REPORT = ROOT / "workflow" / "report"
LABELS = ROOT / "paper" / "paper_labels.tex"
PRINTED = {k: v.replace("~", " ") for k, v in read_tex(LABELS.read_text()).items()}
SCENES = scene_files(ROOT / "config" / "scenes")


# ----------------------------------------------------------------------------- helpers
def render(template: str, caption, wildcards=None) -> str:
    """A caption template as Snakemake renders it (snakemake.report.FileRecord.render):
    Jinja2 with trim_blocks/lstrip_blocks, its link targets appended, docutils' HTML body."""
    links = textwrap.dedent("""

    .. _Workflow: javascript:show_panel('workflow')
    .. _Statistics: javascript:show_panel('statistics')
    .. _Figures: javascript:app.showCategory('Figures')
    .. _fig05_thetalt0mfs.nc: javascript:app.showResultInfo('results%2Ffig05_thetalt0mfs.nc')
    """)
    env = Environment(trim_blocks=True, lstrip_blocks=True)
    snakemake = SimpleNamespace(params=SimpleNamespace(caption=caption),
                                wildcards=SimpleNamespace(**(wildcards or {})))
    text = env.from_string((REPORT / template).read_text() + links).render(snakemake=snakemake)
    return publish_parts(text, writer="html")["body"]


def no_system_message(body: str) -> bool:
    return "System Message" not in body and "system-message" not in body \
        and "problematic" not in body


def write_nc(path: Path, title: str, fmt: str = "NETCDF3_64BIT_OFFSET") -> Path:
    """A small dataset in format ``fmt`` (netCDF4.Dataset's names)."""
    with netCDF4.Dataset(str(path), "w", format=fmt) as nc:
        nc.title, nc.Conventions = title, "CF-1.8"
        nc.createDimension("n", 3)
        var = nc.createVariable("x", "f8", ("n",))
        var.long_name, var.units = "a number", "1"
        var[:] = np.arange(3.0)
    return path


def labels_left(text: str) -> list[str]:
    return [m.group(0) for m in report_html.INTERNAL_LABEL.finditer(text)]


# ----------------------------------------------------------------------------- pieces
@pytest.mark.parametrize("text", [
    "grazing periodic orbit in M_+ = {y = x1}", "P_DM and H_s", "x_ y__ `a` *b* **c** |d|",
    "(a) eps = 0.1; (b) eps = 0.01", "- not a list", "1. not a list either", "#. no",
    "http://example.org/x_", "a\\b", "E+ -> E- -> E+", ".. not a comment", "[1]_ [#]_",
    ":math:`x` and :ref:", "trailing_", "O(eps^2) ~ 1e-3"])
def test_escaped_text_renders_as_itself(text):
    body = publish_parts(report_html.rst_text(text), writer="html")["body"]
    assert no_system_message(body), body
    shown = re.sub(r"<[^>]+>", "", body).strip()
    assert html.unescape(shown) == text, body


def test_labels_become_the_numbers_the_paper_prints():
    cite = lambda s: report_html.cite(s, PRINTED)  # noqa: E731
    assert cite("the O(eps) expansion eq:ymm)") == f"the O(eps) expansion {PRINTED['eq:ymm']})"
    assert PRINTED["eq:ymm"].startswith("Eq. (") and PRINTED["fig:thetalt0mfs"] == "Fig. 5"
    # a word the printed text repeats goes; other words stay
    assert cite("(lemma thm:pdm, case theta > 0)") == f"({PRINTED['thm:pdm']}, case theta > 0)"
    assert cite("Fig. fig:retmaps") == PRINTED["fig:retmaps"]
    assert cite("example eq:red for mu") == f"example {PRINTED['eq:red']} for mu"
    # the longest label wins, a colon before a blank ends one, punctuation is kept
    assert cite("oscillator eq:dfo1 (M = K = 1)") == f"oscillator {PRINTED['eq:dfo1']} (M = K = 1)"
    assert cite("oscillator eq:dfo-sf: (a)") == f"oscillator {PRINTED['eq:dfo-sf']}: (a)"
    assert cite("eq:p:xi14t2 and eq:p:pdm.") == f"{PRINTED['eq:p:xi14t2']} and {PRINTED['eq:p:pdm']}."
    assert cite("(eq:exslow2/eq:exfast2)") == f"({PRINTED['eq:exslow2']}/{PRINTED['eq:exfast2']})"
    # not a label of the paper, or part of a longer word: left alone
    assert cite("eq:nosuchlabel, xeq:red, eq:redx") == "eq:nosuchlabel, xeq:red, eq:redx"
    assert report_html.printed_labels(LABELS)["eq:ymm"] == PRINTED["eq:ymm"]
    assert report_html.printed_labels(ROOT / "no" / "such.tex") == {}


def test_the_scene_files_cite_the_paper_by_its_printed_numbers():
    # a scene's description goes into its dataset (scene_config): it cites the paper as
    # printed ("Eq. (18)"), never by a LaTeX label of its source; only paper_figure is a
    # label (the key the captions look the printed number up by), which the dataset's
    # scene_config holds as printed ("Fig. 4"; scenes.printed)
    label = re.compile(r"(?<![A-Za-z0-9_])(?:%s)(?![A-Za-z0-9_\-])"
                       % "|".join(re.escape(k) for k in sorted(PRINTED, key=len, reverse=True)))
    for scene in SCENES:
        data = yaml.safe_load((ROOT / "config" / "scenes" / f"{scene}.yaml").read_text())
        text = " ".join(str(data.get("description", "")).split())
        assert not label.findall(text), (scene, label.findall(text))
        assert report_html.cite(text, PRINTED) == text, scene
        if "paper_figure" in data:
            assert data["paper_figure"] in PRINTED, scene


@pytest.mark.parametrize("fmt,name", [("NETCDF3_64BIT_OFFSET", "netCDF-3 64-bit offset"),
                                      ("NETCDF3_CLASSIC", "netCDF-3 classic"),
                                      ("NETCDF4", "netCDF-4 (HDF5)"),
                                      ("NETCDF4_CLASSIC", "netCDF-4 classic model (HDF5)")])
def test_the_format_is_read_from_the_file(tmp_path, fmt, name):
    path = write_nc(tmp_path / "d.nc", "a title", fmt)
    assert report_html.format_label(path) == name
    text = report_html.describe_dataset(report_html.netcdf_summary(path))
    assert text.startswith(report_html.rst_text(name) + " file") and f"``{fmt}``" in text
    if fmt.startswith("NETCDF3"):
        assert "netCDF4" not in text and "netCDF-4" not in text and "HDF5" not in text


def test_the_caption_says_only_what_the_dataset_has(tmp_path):
    path = write_nc(tmp_path / "d.nc", "a title")
    with netCDF4.Dataset(str(path), "a") as nc:
        nc.createVariable("y", "f8", ("n",))  # no long_name, units, tolerance
        nc.createVariable("s", "S1", ("n",)).long_name = "text"
        nc.checksum_sha256 = "0" * 64
    text = report_html.describe_dataset(report_html.netcdf_summary(path))
    assert "2 of 3 variables with ``long_name``" in text
    assert "1 of 2 numeric variables with ``units``" in text
    assert "0 of 2 numeric variables with its cross-machine tolerance" in text
    assert "checksum" in text and "scene_config" not in text and "code_version" not in text


@pytest.mark.parametrize("scene", SCENES)
def test_scene_captions_render_without_errors_or_labels(scene, tmp_path):
    data = yaml.safe_load((ROOT / "config" / "scenes" / f"{scene}.yaml").read_text())
    nc = write_nc(tmp_path / f"{scene}.nc", "placeholder eq:ymm (fig:thetalt0mfs), M_+ and P_DM")
    caption = report_html.Caption(scene, data=str(nc), scenes=ROOT / "config" / "scenes",
                                  labels=LABELS)
    for template in ("figure.rst", "dataset.rst", "scene.rst"):
        body = render(template, caption, {"scene": scene})
        assert no_system_message(body), (template, body)
        assert not labels_left(body), (template, labels_left(body))
    figure, dataset = render("figure.rst", caption, {"scene": scene}), \
        render("dataset.rst", caption, {"scene": scene})
    if "paper_figure" in data:
        assert f"<strong>{PRINTED[data['paper_figure']]}</strong>" in figure
    else:
        assert "Beyond the paper" in figure
    # the template says where a figure stands; the scene's description does not repeat it
    assert len(re.findall(r"Beyond the (paper|figures)", figure)) <= 1, figure
    assert "netCDF-3 64-bit offset" in dataset and "netCDF4" not in dataset
    assert f"{PRINTED['eq:ymm']} (Fig. 5), M_+ and P_DM" in dataset
    shown = re.sub(r"<[^>]+>", "", figure)  # docutils splits a literal at "-" into spans
    for key, value in data["parameters"].items():
        if isinstance(value, (int, float)):
            assert f"{key} = {value}" in shown, key


@pytest.mark.parametrize("template", ["hard_cases.rst", "work_precision.rst",
                                      "work_precision_figure.rst"])
def test_sweep_captions_render_without_errors_or_labels(template, tmp_path):
    nc = write_nc(tmp_path / "sweep.nc", "a sweep with eq:red and x_1", "NETCDF4")
    body = render(template, report_html.Caption(data=str(nc), labels=LABELS))
    assert no_system_message(body) and not labels_left(body), body
    assert PRINTED["eq:red"] in body


def test_a_caption_is_read_late_and_passes_to_the_jobs(tmp_path):
    # built while the workflow is planned (the files need not exist yet), pickled into
    # each script job's preamble, read when the report is built
    caption = report_html.Caption("fig05_thetalt0mfs", data=str(tmp_path / "later.nc"))
    again = pickle.loads(pickle.dumps(caption))
    assert repr(again) == "<caption of scene fig05_thetalt0mfs>"
    write_nc(tmp_path / "later.nc", "made after planning")
    assert again.title == report_html.rst_text("made after planning")


def test_captions_are_no_rerun_trigger():
    # every rule passes its caption through a function of report_html.smk that takes
    # `output` or `input`: Snakemake counts such a param as derived from the files and
    # leaves it out of its params trigger (editing a caption recomputes nothing)
    tree = ast.parse((ROOT / "workflow" / "rules" / "report_html.smk").read_text())
    takes = {f.name: {a.arg for a in f.args.args} for f in tree.body
             if isinstance(f, ast.FunctionDef)}
    used = set()
    for smk in (ROOT / "workflow" / "rules").glob("*.smk"):
        used |= set(re.findall(r"^\s+caption=(\w+),", smk.read_text(), re.M))
        assert "scene_summary" not in smk.read_text(), smk.name
    assert used == {"dataset_caption", "figure_caption", "scene_caption"}
    for name in used:
        assert takes[name] & {"input", "output"}, name


class _Job:
    def __init__(self, rule, name):
        self.rule, self.name = SimpleNamespace(name=rule), name

    def __repr__(self):
        return self.name


def test_the_rule_graph_has_each_rule_once():
    # an unsplit scene: compute -> plot; a split one: compute_chunk -> merge_chunks ->
    # plot, one level further down. Snakemake's own graph drew `plot` twice.
    c, k, m = _Job("compute", "c"), _Job("compute_chunk", "k"), _Job("merge_chunks", "m")
    p1, p2, a = _Job("plot", "p1"), _Job("plot", "p2"), _Job("all", "a")
    deps = {c: set(), k: set(), m: {k}, p1: {c}, p2: {m}, a: {p1, p2}}
    levels = [[c, k], [m, p1], [p2], [a]]
    dag = SimpleNamespace(jobs=list(deps), dependencies=deps, toposorted=lambda: levels)
    spec, _, ymax = report_html.rulegraph_spec(dag)
    rules = [n["rule"] for n in spec["nodes"]]
    assert sorted(rules) == sorted(set(rules)) == ["all", "compute", "compute_chunk",
                                                   "merge_chunks", "plot"]
    links = spec["links"] + spec["links_direct"]
    pairs = {(x["sourcerule"], x["targetrule"]) for x in links}
    assert pairs == {("compute", "plot"), ("compute_chunk", "merge_chunks"),
                     ("merge_chunks", "plot"), ("plot", "all")} and len(pairs) == len(links)
    for x in links:  # every arrow points down, its ends are the named rules
        assert x["source"] < x["target"]
        assert (rules[x["source"]], rules[x["target"]]) == (x["sourcerule"], x["targetrule"])
        assert (x in spec["links_direct"]) == (x["target"] - x["source"] == 1)
    assert ymax == 50 * (len(rules) - 1)


# ----------------------------------------------------------------------------- the report
def report_parts(path: Path) -> dict:
    """The data report.html embeds (results, categories, rule graph, the workflow text)."""
    text = path.read_text(errors="replace")
    decoder = json.JSONDecoder()
    parts = {}
    for name in ("results", "categories", "rulegraph_spec", "workflow_desc"):
        m = re.search(rf"var {name} = (?=[{{\"\[])", text)
        assert m, f"report.html: no {name}"
        parts[name] = decoder.raw_decode(text, m.end())[0]
    parts["html"] = text
    return parts


def visible_text(parts: dict) -> str:
    """What a reader sees as text: the workflow description, captions, labels, job
    properties and category names (not the attached files, not the page's code)."""
    out = [parts["workflow_desc"], json.dumps(parts["categories"])]
    for res in parts["results"].values():
        out += [res["caption"], json.dumps(res["labels"]), json.dumps(res["job_properties"])]
    return "\n".join(out)


def check_report(path: Path, work: Path, outputs: dict[str, str]):
    """The checks of the module docstring on report.html of the build in ``work``;
    ``outputs``: {output file: rule} of every job of the build."""
    parts = report_parts(path)
    results = parts["results"]
    # every dataset and figure of the build is attached (and the reproduction report)
    wanted = {f for f in outputs if re.fullmatch(r"results/[^/]+\.nc|figures/[^/]+\.(pdf|png)"
                                                 r"|results/scenes/[^/]+\.yaml|paper/main\.pdf", f)}
    assert wanted >= {"results/hard_cases.nc", "results/work_precision.nc",
                      "figures/work_precision.pdf", "figures/work_precision.png"}
    assert not wanted - set(results), f"not in the report: {sorted(wanted - set(results))}"
    on_disk = {p.relative_to(work).as_posix() for p in (work / "results").glob("*.nc")}
    on_disk |= {p.relative_to(work).as_posix() for p in (work / "figures").glob("*.p[dn][fg]")}
    assert not on_disk - set(results), f"not in the report: {sorted(on_disk - set(results))}"
    # no docutils error anywhere, no internal label in what a reader sees
    assert "System Message" not in parts["html"] and "system-message" not in parts["html"]
    seen = visible_text(parts)
    assert not labels_left(seen), sorted(set(labels_left(seen)))
    # each dataset's format as the file says (the label and the caption)
    for name, res in results.items():
        if name.endswith(".nc"):
            with netCDF4.Dataset(str(work / name)) as nc:
                model = nc.data_model
            assert res["labels"]["format"] == report_html.format_label(work / name), name
            assert f"{report_html.format_name(model)} file" in res["caption"], name
            assert f">{model}<" in res["caption"], name
            if model.startswith("NETCDF3"):
                assert "netCDF4" not in res["caption"] and "netCDF-4" not in res["caption"], name
    # each rule once in the rule graph, and every rule of the build there
    nodes = [n["rule"] for d in parts["rulegraph_spec"]["data"] if d["name"] == "node-data"
             for n in d["values"]]
    assert len(nodes) == len(set(nodes)), f"rules drawn twice: {nodes}"
    assert set(outputs.values()) <= set(nodes)
    return parts


def summary(work: Path) -> dict[str, str]:
    """{output file: rule} of every job of rule `all` (`snakemake --summary`)."""
    run = run_snakemake(work, "--summary", timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    rows = [line.split("\t") for line in run.stdout.splitlines()[1:] if "\t" in line]
    return {row[0]: row[2] for row in rows}


@pytest.fixture(scope="module")
def placeholder_build(tmp_path_factory):
    """A copy of the project with every output of rule `all` as a placeholder (small
    netCDF-3 datasets whose titles cite the paper by label, empty figures), and its
    report: what `snakemake --report` makes of the workflow, in seconds."""
    work = copy_project(tmp_path_factory.mktemp("report_html") / "project")
    outputs = summary(work)
    for name in outputs:
        path = work / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if name.endswith(".nc"):
            write_nc(path, f"placeholder of {path.stem}: eq:red (fig:retmaps), M_+ = {{y = x1}}")
        elif name.startswith("results/scenes/"):
            shutil.copy(work / "config" / "scenes" / path.name, path)
        else:
            path.write_bytes(b"")
    out = work / "report.html"
    run = run_snakemake(work, *report_args(out), timeout=600)
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    return {"work": work, "outputs": outputs, "report": out, "log": run.stderr}


def test_placeholder_report_attaches_everything_cleanly(placeholder_build):
    b = placeholder_build
    parts = check_report(b["report"], b["work"], b["outputs"])
    assert "ERROR/" not in b["log"] and "Unknown target name" not in b["log"], b["log"][-2000:]
    results = parts["results"]
    # the placeholder titles, with the paper's printed numbers
    title = f"{PRINTED['eq:red']} ({PRINTED['fig:retmaps']}), M_+ = {{y = x1}}"
    for name in ("results/fig05_thetalt0mfs.nc", "results/hard_cases.nc",
                 "results/work_precision.nc"):
        assert title in results[name]["caption"], name
    # the caption of fig05, where `M_+` was read as a reference
    fig05 = results["figures/fig05_thetalt0mfs.png"]["caption"]
    assert "M_+ = {y = x1}" in fig05 and f"expansion {PRINTED['eq:ymm']})" in fig05
    assert f"<strong>{PRINTED['fig:thetalt0mfs']}</strong>" in fig05
    # the job's params show the caption by name, not its text
    params = results["figures/fig05_thetalt0mfs.png"]["job_properties"]["params"]
    assert params.endswith("caption=<caption of scene fig05_thetalt0mfs>"), params
    assert parts["categories"]["Figures"]["work_precision"] == ["figures/work_precision.pdf",
                                                                "figures/work_precision.png"]


def test_html_report_of_the_build(workflow_build, tmp_path):
    """The same checks on the report of the shared real build."""
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    out = tmp_path / "report.html"
    rep = run_snakemake(work, *report_args(out), timeout=600)
    assert rep.returncode == 0, rep.stdout[-3000:] + rep.stderr[-3000:]
    assert "ERROR/" not in rep.stderr, rep.stderr[-3000:]
    check_report(out, work, summary(work))


def test_a_dataset_names_the_paper_s_numbers_not_its_labels():
    # scenes.printed: what a reader of the netCDF file sees in titles and long names
    import xarray as xr

    from filippov_paper.scenes import printed

    ds = xr.Dataset({"image": ((), 1.0, {"long_name": "s from eq:xi1r", "equation": "eq:xi1r",
                                         "units": "1"})},
                    attrs={"title": "graph from eq:xi1r (fig:p:xi12)",
                           "scene_config": '{"description": "eq:xi1r", "id": "fig06_sgraph", '
                                           '"paper_figure": "fig:p:xi12", "x": 1.5}'})
    out = printed(ds, {"eq:xi1r": "Eq. (23)", "fig:p:xi12": "Fig. 6"})
    assert out.attrs["title"] == "graph from Eq. (23) (Fig. 6)"
    assert out["image"].attrs["long_name"] == "s from Eq. (23)"
    assert out["image"].attrs["equation"] == "Eq. (23)"
    # the scene as computed: its paper figure and description as printed, the rest as given
    assert out.attrs["scene_config"] == ('{"description": "Eq. (23)", "id": "fig06_sgraph", '
                                         '"paper_figure": "Fig. 6", "x": 1.5}')


def test_no_dataset_attribute_holds_a_latex_label(workflow_build):
    """The datasets of the shared build, as a reader of the netCDF files meets them: no
    attribute (global or of a variable, coordinates included: netCDF stores them as
    variables; the scene as computed in ``scene_config`` included) names one of the paper's LaTeX labels (``fig:retmaps``); a scene that
    reproduces a figure of the paper says which by its printed number ("Fig. 4")."""
    work, run = workflow_build["work"], workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    paths = sorted((work / "results").glob("*.nc"))
    assert paths
    labelled = []
    for path in paths:
        with netCDF4.Dataset(path) as nc:
            owners = [("", nc)] + [(name, var) for name, var in nc.variables.items()]
            for owner, obj in owners:
                for attr in obj.ncattrs():
                    value = obj.getncattr(attr)
                    found = report_html.INTERNAL_LABEL.search(value) \
                        if isinstance(value, str) else None
                    if found:
                        where = f"{owner}.{attr}" if owner else attr
                        labelled.append(f"{path.name}:{where}: "
                                        f"...{value[found.start():found.start() + 30]}")
    assert not labelled, "attributes with the paper's LaTeX labels:\n" + "\n".join(labelled)
    for scene in scene_files(work / "config" / "scenes"):
        data = yaml.safe_load((work / "config" / "scenes" / f"{scene}.yaml").read_text())
        if "paper_figure" not in data:
            continue
        with netCDF4.Dataset(work / "results" / f"{scene}.nc") as nc:
            computed = json.loads(nc.getncattr("scene_config"))
        assert computed["paper_figure"] == PRINTED[data["paper_figure"]], scene


# ----------------------------------------------------------------------------- the code's text
#: attributes whose value a reader of a dataset meets as text (CF's and ours)
ATTRIBUTE_TEXT = {"title", "long_name", "description", "comment", "references", "equation",
                  "source", "history", "summary", "caption"}
#: a whole label as written (INTERNAL_LABEL finds only its start)
WHOLE_LABEL = re.compile(report_html.INTERNAL_LABEL.pattern + r"[A-Za-z0-9:_-]*")
#: the code that writes datasets, draws figures and prints messages; paper_labels.py
#: writes the LaTeX that defines the labels' printed numbers, so it names labels
SPEAKING_CODE = sorted(
    set((ROOT / "src" / "filippov").rglob("*.py")) | set((ROOT / "workflow").rglob("*.py"))
    - {ROOT / "workflow" / "filippov_paper" / "paper_labels.py"})


def _docstrings(tree) -> set[int]:
    # the API's text, which tests/test_docs.py checks
    kinds = (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)
    return {id(node.body[0].value) for node in ast.walk(tree)
            if isinstance(node, kinds) and node.body and isinstance(node.body[0], ast.Expr)
            and isinstance(node.body[0].value, ast.Constant)}


def _given_as(node, parents) -> str | None:
    """The attribute a string literal is given as: {"long_name": s}, f(title=s),
    ds.attrs["title"] = s; None for any other place."""
    parent = parents.get(id(node))
    if isinstance(parent, ast.keyword):
        return parent.arg
    if isinstance(parent, ast.Dict):
        return next((key.value for key, value in zip(parent.keys, parent.values)
                     if value is node and isinstance(key, ast.Constant)), None)
    if isinstance(parent, ast.Assign) and parent.value is node:
        return next((target.slice.value for target in parent.targets
                     if isinstance(target, ast.Subscript)
                     and isinstance(target.slice, ast.Constant)), None)
    return None


def label_literals(source: str, name: str) -> list[str]:
    """The string literals of ``source`` that would show a reader one of the paper's
    LaTeX labels: text with a label in it (a title, a long name, a message), and a bare
    label given as a text attribute. A bare label anywhere else is a key the printed
    number is looked up by."""
    tree = ast.parse(source)
    parents = {id(child): node for node in ast.walk(tree) for child in ast.iter_child_nodes(node)}
    docs = _docstrings(tree)
    found = []
    for node in ast.walk(tree):
        if not (isinstance(node, ast.Constant) and isinstance(node.value, str)) \
                or id(node) in docs or not report_html.INTERNAL_LABEL.search(node.value):
            continue
        if WHOLE_LABEL.fullmatch(node.value.strip()) \
                and _given_as(node, parents) not in ATTRIBUTE_TEXT:
            continue
        found.append((node.lineno, node.col_offset, node.value))
    return [f"{name}:{line}: {text[:70]!r}" for line, _, text in sorted(found)]


def test_the_label_finder_tells_text_from_keys():
    source = textwrap.dedent('''
        """Module fig:retmaps (a docstring: tests/test_docs.py)."""
        ds["x"] = (d, v, {"long_name": "M_-: expansion eq:ymm", "units": "1"})
        ds["y"] = (d, v, {"equation": "eq:xi1r"})
        ds.attrs["title"] = "fig:retmaps"
        finalize(ds, scene, title="return map (fig:retmaps)")
        VARIABLE_ATTRS = {"r": ("left side of eq:s0def", "1")}
        log(f"solving eq:red for {mu}")
        number = labels["fig:retmaps"]
        KEYS = {"eq:ymm": "Eq. (18)"}
        ds["z"] = (d, v, {"long_name": "Eq. (18) as printed", "equation": "Eq. (23)"})
        ''')
    found = [hit.split(": ", 1)[1] for hit in label_literals(source, "m.py")]
    assert found == [repr(s) for s in [
        "M_-: expansion eq:ymm", "eq:xi1r", "fig:retmaps", "return map (fig:retmaps)",
        "left side of eq:s0def", "solving eq:red for "]], found


def _descriptions(node):
    """The ``description`` texts of a JSON schema, at any depth."""
    if isinstance(node, dict):
        for key, value in node.items():
            if key == "description" and isinstance(value, str):
                yield value
            else:   # a property named "description" holds a schema, not text
                yield from _descriptions(value)
    elif isinstance(node, list):
        for item in node:
            yield from _descriptions(item)


def test_no_code_gives_a_reader_a_latex_label():
    """Without a build: the text the code gives datasets (every attribute of every
    variable, coordinate and dataset), figures and messages cites the paper by the
    numbers it prints ("Eq. (18)", "Fig. 4"), never by its LaTeX labels. (scenes.printed
    maps labels when a dataset is written, but only in some attributes, and only when
    it finds paper/paper_labels.tex; the text itself has none.)"""
    assert len(SPEAKING_CODE) > 50
    leaks = [hit for path in SPEAKING_CODE
             for hit in label_literals(path.read_text(encoding="utf-8"),
                                       str(path.relative_to(ROOT)))]
    # the schemas' descriptions document the scene files (their parameters too: the
    # scene modules' PARAMETERS_SCHEMA, which the literals above cover)
    leaks += [f"{path.relative_to(ROOT)}: {text[:70]!r}"
              for path in sorted((ROOT / "config" / "schema").glob("*.json"))
              for text in _descriptions(json.loads(path.read_text(encoding="utf-8")))
              if report_html.INTERNAL_LABEL.search(text)]
    assert not leaks, "the paper's LaTeX labels in text for readers:\n" + "\n".join(leaks)
