"""What Snakemake's HTML report (``make report-html``, report.html) says about each file.

The captions are reStructuredText templates (workflow/report/*.rst) that Snakemake
fills in with Jinja2 and renders with docutils. Their values come from a
:class:`Caption`, which a rule passes as its ``caption`` param; every text it gives
is ready for reStructuredText:

* free text (a scene's description, a dataset's ``title``) is escaped, so that
  docutils reads no markup in it (``M_+`` is text, not a reference to a target
  ``M``, which docutils reports in a "System Message" block), and the paper's
  LaTeX labels in it (``eq:ymm``, ``fig:thetalt0mfs``) are replaced by the numbers
  printed in the paper ("Eq. (18)", "Fig. 5"; paper/paper_labels.tex, written by
  :mod:`filippov_paper.paper_labels`);
* what a dataset is (its format: netCDF-3 or netCDF-4 and which variant, its
  conventions, which attributes it carries) is read from the file, not assumed.

A caption is read when the report is built, not when the workflow is planned: a
:class:`Caption` only holds paths until a template asks. The rules build it with a
param function that takes ``output`` (or ``input``): Snakemake counts such a param
as derived from the files and leaves it out of its params rerun trigger, so editing
a caption (or paper/paper_labels.tex) recomputes nothing.

:func:`rulegraph_spec` replaces Snakemake's rule graph of the report, which draws a
rule once per level of the job graph: ``plot`` stood there twice, because the
figure of a scene split into chunks is drawn one level further down (after
``merge_chunks``) than that of a scene computed in one job (after ``compute``).

No Snakemake here (workflow/rules/report_html.smk is the caller).
"""
from __future__ import annotations

import functools
import re
from pathlib import Path

#: an internal LaTeX label of the paper (``eq:ymm``, ``fig:p:xi12``, ``thm:pdm``);
#: none may be left in the report's text
INTERNAL_LABEL = re.compile(r"(?<![A-Za-z0-9_])(?:app|cond|eq|fig|lem|sec|tab|thm):[A-Za-z0-9]")

# the words that may stand before a label in our prose and that the printed text
# already says ("lemma thm:pdm" -> "Lemma 3", not "lemma Lemma 3")
_KIND_WORDS = {"eq": {"eq", "eqs", "eqn", "equation"}, "fig": {"fig", "figs", "figure"},
               "sec": {"sec", "section"}, "lemma": {"lemma"}, "appendix": {"app", "appendix"},
               "item": {"item"}}

# every ASCII punctuation character: a backslash before any of them makes docutils
# read it as that character, whatever it would otherwise start (a reference `_`,
# emphasis `*`, a literal `` ` ``, a substitution `|`, a list item `-` or `(a)`, ...)
_RST_SPECIAL = re.compile(r"""([!"#$%&'()*+,\-./:;<=>?@\[\\\]^_`{|}~])""")

#: netCDF data models as netCDF4.Dataset.data_model names them -> what they are
NETCDF_MODELS = {
    "NETCDF3_CLASSIC": "netCDF-3 classic",
    "NETCDF3_64BIT_OFFSET": "netCDF-3 64-bit offset",
    "NETCDF3_64BIT_DATA": "netCDF-3 64-bit data (CDF-5)",
    "NETCDF4_CLASSIC": "netCDF-4 classic model (HDF5)",
    "NETCDF4": "netCDF-4 (HDF5)",
}


# ----------------------------------------------------------------------------- text
def rst_text(text: str) -> str:
    """``text`` as reStructuredText that renders as exactly that text."""
    return _RST_SPECIAL.sub(r"\\\1", " ".join(str(text).split()))


def rst_literal(text: str) -> str:
    """``text`` as an inline literal (escaped text when it cannot be one)."""
    text = " ".join(str(text).split())
    if not text or "`" in text or "\\" in text:
        return rst_text(text)
    return f"``{text}``"


@functools.lru_cache(maxsize=None)
def _read_labels(path: str, mtime_ns: int) -> dict[str, str]:
    from filippov_paper.paper_labels import read_tex

    return {label: printed.replace("~", " ")
            for label, printed in read_tex(Path(path).read_text(encoding="utf-8")).items()}


def printed_labels(path="paper/paper_labels.tex") -> dict[str, str]:
    """{label: the text the paper prints for it} ("eq:ymm" -> "Eq. (18)"), from
    paper/paper_labels.tex; {} when there is no such file."""
    path = Path(path)
    if not path.is_file():
        return {}
    return _read_labels(str(path.resolve()), path.stat().st_mtime_ns)


@functools.lru_cache(maxsize=None)
def _label_pattern(labels: tuple[str, ...]) -> re.Pattern:
    # longest first, so that eq:dfo1 is not read as eq:dfo; a label ends where no
    # label character follows (a colon ends it when a blank follows: "eq:dfo-sf: ...")
    alternatives = "|".join(re.escape(k) for k in sorted(labels, key=len, reverse=True))
    return re.compile(r"(?:(?P<word>\b[A-Za-z]+)\.?\s+)?"
                      rf"(?<![A-Za-z0-9_:\-])(?P<label>{alternatives})"
                      r"(?![A-Za-z0-9_\-]|:[A-Za-z0-9])")


def cite(text: str, labels: dict[str, str]) -> str:
    """``text`` with each of the paper's labels replaced by what the paper prints for
    it (``labels``, see :func:`printed_labels`); a word before the label that the
    printed text repeats goes ("lemma thm:pdm" -> "Lemma 3")."""
    if not labels or not text:
        return text

    def replace(m: re.Match) -> str:
        printed = labels[m.group("label")]
        word = m.group("word")
        if word is None:
            return printed
        kind = printed.split(" ")[0].rstrip(".").lower()
        if word.lower() in _KIND_WORDS.get(kind, {kind}):
            return printed
        return m.group(0)[:m.start("label") - m.start(0)] + printed

    return _label_pattern(tuple(labels)).sub(replace, text)


# ----------------------------------------------------------------------------- files
def netcdf_summary(path) -> dict:
    """What a netCDF file is, read from the file: its data model (``model``, e.g.
    NETCDF3_64BIT_OFFSET), ``conventions``, ``title``, the names of its global
    attributes (``attrs``) and, per variable, (its attribute names, holds numbers)."""
    import netCDF4
    import numpy as np

    with netCDF4.Dataset(str(path)) as nc:
        return {"model": nc.data_model,
                "conventions": str(getattr(nc, "Conventions", "")),
                "title": str(getattr(nc, "title", "")),
                "attrs": set(nc.ncattrs()),
                "variables": {name: (set(var.ncattrs()),
                                     isinstance(var.dtype, np.dtype) and var.dtype.kind in "iuf")
                              for name, var in nc.variables.items()}}


def format_name(model: str) -> str:
    """"netCDF-3 64-bit offset" for NETCDF3_64BIT_OFFSET (the name itself when unknown)."""
    return NETCDF_MODELS.get(model, model)


def _every(n: int, of: int, what: str) -> str:
    return f"every {what}" if n == of else f"{n} of {of} {what}s"


def describe_dataset(summary: dict) -> str:
    """One paragraph (reStructuredText) on a dataset file from :func:`netcdf_summary`:
    its format, conventions, what its variables carry and its global attributes --
    only what the file has."""
    first = (f"{rst_text(format_name(summary['model']))} file "
             f"({rst_literal(summary['model'])}, read from the file)")
    if summary["conventions"]:
        first += f" with {rst_text(summary['conventions'])} attributes"
    parts = [first]
    variables = list(summary["variables"].values())
    numeric = [attrs for attrs, is_number in variables if is_number]
    said = []
    if variables:
        said.append(_every(sum("long_name" in a for a, _ in variables), len(variables),
                           "variable") + " with ``long_name``")
    if numeric:
        units = sum("units" in a for a in numeric)
        repro = sum(any(k.startswith("repro_") for k in a) for a in numeric)
        tolerance = "its cross-machine tolerance (``repro_*``)"
        if units == repro:
            said.append(_every(units, len(numeric), "numeric variable")
                        + f" with ``units`` and {tolerance}")
        else:
            said.append(_every(units, len(numeric), "numeric variable") + " with ``units``")
            said.append(_every(repro, len(numeric), "numeric variable") + f" with {tolerance}")
    if said:
        parts.append(", ".join(said))
    known = (("scene_config", "the settings it was computed with (``scene_config``)"),
             ("code_version", "the code version (``code_version``)"),
             ("checksum_sha256", "a SHA-256 checksum of the data (``checksum_sha256``)"))
    found = [text for key, text in known if key in summary["attrs"]]
    if found:
        parts.append("global attributes: " + ", ".join(found))
    return "; ".join(parts) + "."


# ----------------------------------------------------------------------------- captions
class Caption:
    """The values a caption template shows for one file, read when first asked.

    ``scene``: the scene id (its file ``<scenes>/<scene>.yaml`` gives the
    description, the paper figure, the model and the parameters); ``data``: the
    dataset the file is (or is drawn from), for its format and title; ``labels``:
    paper/paper_labels.tex. Paths are relative to the workflow's directory.
    Every value is reStructuredText, escaped, with the paper's printed numbers."""

    def __init__(self, scene: str | None = None, data: str | None = None,
                 scenes: str = "config/scenes", labels: str = "paper/paper_labels.tex"):
        self.scene_id, self.data = scene, data
        self.scenes, self.labels = str(scenes), str(labels)

    def __repr__(self):  # what the report shows among the job's params
        what = f"scene {self.scene_id}" if self.scene_id else f"{self.data}"
        return f"<caption of {what}>"

    __str__ = __repr__

    # the scene file
    @functools.cached_property
    def _scene(self) -> dict:
        import yaml

        if not self.scene_id:
            return {}
        path = Path(self.scenes) / f"{self.scene_id}.yaml"
        if not path.exists():
            return {}
        return yaml.safe_load(path.read_text(encoding="utf-8")) or {}

    @functools.cached_property
    def _labels(self) -> dict[str, str]:
        return printed_labels(self.labels)

    def text(self, raw: str) -> str:
        """Free text as reStructuredText, with the paper's printed numbers."""
        return rst_text(cite(" ".join(str(raw).split()), self._labels))

    @property
    def scene(self) -> str:
        return rst_literal(self.scene_id or "")

    @property
    def paper_figure(self) -> str:
        """The paper figure the scene reproduces as printed ("Fig. 5"); "" for none."""
        label = str(self._scene.get("paper_figure", ""))
        return rst_text(self._labels.get(label, label)) if label else ""

    @property
    def paper_ref(self) -> str:
        return (f"{self.paper_figure} of the paper" if self.paper_figure
                else rst_text("beyond the paper's figures"))

    @property
    def description(self) -> str:
        return self.text(self._scene.get("description", ""))

    @property
    def model(self) -> str:
        return rst_literal(self._scene.get("model", ""))

    @property
    def ingredients(self) -> str:
        return self.text(", ".join(f"{k}: {v}" for k, v in
                                   (self._scene.get("ingredients") or {}).items()))

    @property
    def parameters(self) -> str:
        """The physical parameters, each an inline literal, comma-separated."""
        return ", ".join(rst_literal(f"{k} = {v}") for k, v in
                         (self._scene.get("parameters") or {}).items())

    # the dataset
    @functools.cached_property
    def _dataset(self) -> dict:
        if not self.data:
            raise ValueError(f"{self!r}: no dataset given")
        return netcdf_summary(self.data)

    @property
    def format(self) -> str:
        """The dataset's format as read from the file ("netCDF-3 64-bit offset")."""
        return rst_text(format_name(self._dataset["model"]))

    @property
    def title(self) -> str:
        """The dataset's ``title`` attribute, with the paper's printed numbers."""
        return self.text(self._dataset["title"])

    @property
    def dataset(self) -> str:
        """A paragraph on the dataset file (:func:`describe_dataset`)."""
        return describe_dataset(self._dataset)


def format_label(path) -> str:
    """The report's "format" label of a dataset: its format, read from the file."""
    return format_name(netcdf_summary(path)["model"])


# ----------------------------------------------------------------------------- rule graph
def rulegraph_spec(dag):
    """The rule graph of the HTML report with one node per rule.

    Snakemake's own (snakemake.report.rulegraph_spec) keeps one job per rule and
    level of the job graph, so a rule whose jobs sit at two depths is drawn twice.
    Here the rules are ordered topologically by the rule graph (ties: the first
    level a rule's jobs reach, then the name), with one link per pair of rules.
    Same return value: ({"nodes", "links", "links_direct"}, xmax, ymax); a link to
    the next node is "direct" (drawn straight), any other an arc."""
    first_level: dict[str, int] = {}
    for i, level in enumerate(dag.toposorted()):
        for job in level:
            first_level.setdefault(job.rule.name, i)
    edges = set()
    for job in dag.jobs:
        first_level.setdefault(job.rule.name, len(first_level))
        for dep in dag.dependencies[job]:
            if dep.rule.name != job.rule.name:
                edges.add((dep.rule.name, job.rule.name))
    order = toposort_rules(first_level, edges)
    idx = {rule: i for i, rule in enumerate(order)}
    nodes = [{"rule": rule, "fx": 10, "fy": i * 50} for i, rule in enumerate(order)]
    links, direct = [], []
    for a, b in sorted(edges, key=lambda e: (idx[e[1]], idx[e[0]])):
        link = {"target": idx[b], "source": idx[a], "sourcerule": a, "targetrule": b,
                "value": 1}
        (direct if idx[b] - idx[a] == 1 else links).append(link)
    ymax = max((n["fy"] for n in nodes), default=0)
    return {"nodes": nodes, "links": links, "links_direct": direct}, 100, ymax


def toposort_rules(rank: dict[str, int], edges: set[tuple[str, str]]) -> list[str]:
    """The rules of ``rank`` in an order where every edge (a, b) has a before b; ties
    (and rules on a cycle, appended last) by (rank, name)."""
    preds = {rule: set() for rule in rank}
    for a, b in edges:
        preds.setdefault(b, set()).add(a)
        preds.setdefault(a, set())
    key = lambda r: (rank.get(r, len(rank)), r)  # noqa: E731
    order, done = [], set()
    while len(order) < len(preds):
        ready = sorted((r for r in preds if r not in done and preds[r] <= done), key=key)
        if not ready:  # a cycle: take the rest as ranked
            ready = sorted((r for r in preds if r not in done), key=key)
        order.append(ready[0])
        done.add(ready[0])
    return order
