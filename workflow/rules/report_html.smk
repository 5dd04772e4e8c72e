# Snakemake's HTML report (`snakemake --report report.html`, `make report-html`): the
# captions of the files the rules mark with report(...) and the report's rule graph.
# The values of the captions (workflow/report/*.rst) come from filippov_paper.report_html:
# escaped for reStructuredText, the paper cited by its printed numbers, a dataset's
# format read from the file.
#
# Each rule passes its caption as the param `caption`, built by a function that takes
# `output` (or `input`): Snakemake counts such a param as derived from the files and
# leaves it out of its params rerun trigger, so editing a caption, a template or
# paper/paper_labels.tex recomputes nothing. A Caption reads nothing before the report
# asks (when the workflow is planned the files need not exist).
from filippov_paper import report_html


def dataset_caption(wildcards, output):
    """A dataset: its scene (when it has one), its format and title from the file."""
    return report_html.Caption(wildcards.get("scene"), data=output[0])


def figure_caption(wildcards, input):
    """A figure: its scene (when it has one) and the dataset it is drawn from."""
    return report_html.Caption(wildcards.get("scene"), data=input.data)


def scene_caption(wildcards, output):
    """A scene file: the scene (`output` only makes the param a derived one)."""
    return report_html.Caption(wildcards.scene)


def dataset_labels(wildcards, output):
    """The report's labels of a dataset: what it is of, its format read from the file."""
    return {"dataset": wildcards.get("scene") or Path(output[0]).stem,
            "format": report_html.format_label(output[0])}


# One node per rule in the report's rule graph. Snakemake draws one node per rule and
# level of the job graph, and a chunked scene's figure is one level further down than
# an unsplit scene's (compute_chunk -> merge_chunks -> plot against compute -> plot),
# so `plot` stood there twice. report_html.rulegraph_spec returns the same structure
# with one node per rule; it replaces Snakemake's where the HTML reporter calls it.
try:
    import snakemake.report.html_reporter as _html_reporter
except ImportError:  # another Snakemake layout: its own rule graph stays
    _html_reporter = None
if callable(getattr(_html_reporter, "rulegraph_spec", None)):
    _html_reporter.rulegraph_spec = report_html.rulegraph_spec
