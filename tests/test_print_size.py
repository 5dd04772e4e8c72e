r"""Figures at the size they are printed (issue 31): no text of a figure prints below
7 pt in the report.

LaTeX scales a figure to the width it is included at, so a font of size f in a figure
drawn w inches wide and included w' inches wide prints at f * w'/w. The included widths
are read from paper/main.tex and the files it \inputs; the drawn widths and the fonts
come from figures drawn from the figure modules' synthetic datasets (tests/synthetic.py;
no pipeline) and from the PDFs of the suite's shared build (MediaBox and the font sizes
of their text).
"""
from __future__ import annotations

import functools
import re
import shutil
import subprocess
import zlib
from pathlib import Path

import matplotlib.text
import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg

import filippov_paper.plotting as plotting
import synthetic
from filippov_paper.plotting import style

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "paper"
MIN_PT = 7.0
#: the report's document class, from which style.TEXT_WIDTH (360pt) was read
DOCUMENTCLASS = r"\documentclass[preprint,11pt,a4paper]{elsarticle}"
TEX_PT_PER_IN = 72.27  # TeX points; PDF and matplotlib sizes are in big points (72/in)

#: every figure of the report: {id: its stand-in dataset's maker}
CASES = {fid: functools.partial(synthetic.dataset, fid) for fid in plotting.figure_ids()}


# --- how the report includes the figures -----------------------------------------------

def _tex(path: Path, seen=None) -> str:
    r"""A .tex file with the files it \inputs (or \includes) spliced in, comments dropped;
    inputs that do not exist (paper/generated/ on a clean checkout) are left out."""
    seen = set() if seen is None else seen
    if path in seen or not path.exists():
        return ""
    seen.add(path)
    text = re.sub(r"(?<!\\)%.*", "", path.read_text(encoding="utf-8"))

    def splice(m):
        name = m.group(1).strip()
        return _tex(PAPER / (name if name.endswith(".tex") else name + ".tex"), seen)

    return re.sub(r"\\(?:input|include)\{([^}]*)\}", splice, text)


LENGTHS = {"textwidth": 1.0, "linewidth": 1.0, "columnwidth": 1.0}  # one-column report
UNITS = {"in": 1.0, "cm": 1 / 2.54, "mm": 1 / 25.4, "pt": 1 / TEX_PT_PER_IN, "bp": 1 / 72}


def _printed(options: str, drawn_in: float | None = None):
    """Printed width in inches from \\includegraphics options (None: scale as drawn)."""
    opts = dict(o.split("=", 1) for o in (s.strip() for s in options.split(",")) if "=" in o)
    if "height" in opts or "totalheight" in opts:
        raise AssertionError(f"includegraphics[{options}]: scale by width, not height")
    if "width" in opts:
        m = re.fullmatch(r"([0-9.]*)\s*\\(\w+)", opts["width"].strip())
        if m and m.group(2) in LENGTHS:
            return float(m.group(1) or 1) * LENGTHS[m.group(2)] * style.TEXT_WIDTH
        m = re.fullmatch(r"([0-9.]+)\s*(in|cm|mm|pt|bp)", opts["width"].strip())
        assert m, f"includegraphics width={opts['width']!r}: not understood by this test"
        return float(m.group(1)) * UNITS[m.group(2)]
    scale = float(opts.get("scale", 1.0))
    return None if drawn_in is None else scale * drawn_in


def included() -> dict[str, str]:
    """figure id -> the options of its \\includegraphics in the report."""
    text = _tex(PAPER / "main.tex")
    found = {}
    for m in re.finditer(r"\\includegraphics\s*(?:\[([^\]]*)\])?\s*\{([^}]*)\}", text):
        fid = Path(m.group(2).strip()).stem
        assert fid not in found, f"{fid} is included twice"
        found[fid] = m.group(1) or ""
    return found


INCLUDED = included()


def printed_width(fid: str, drawn_in: float) -> float:
    width = _printed(INCLUDED[fid], drawn_in)
    return drawn_in if width is None else width


# --- the text width ------------------------------------------------------------------

def test_report_has_the_text_width_the_style_assumes():
    """style.TEXT_WIDTH is \\textwidth of this document class (360pt) and nothing in the
    report changes the page layout."""
    text = _tex(PAPER / "main.tex")
    assert DOCUMENTCLASS in text, "document class changed: re-derive style.TEXT_WIDTH"
    assert not re.search(r"\\usepackage(\[[^]]*\])?\{geometry\}|\\(setlength|addtolength)"
                         r"\s*\{?\\(textwidth|oddsidemargin|evensidemargin)", text)
    assert style.TEXT_WIDTH == pytest.approx(360.0 / TEX_PT_PER_IN, rel=1e-9)


@pytest.mark.skipif(shutil.which("pdflatex") is None, reason="needs pdflatex")
def test_text_width_from_latex(tmp_path):
    """A LaTeX run with the report's preamble prints \\the\\textwidth."""
    if subprocess.run(["kpsewhich", "elsarticle.cls"], capture_output=True).returncode:
        pytest.skip("needs elsarticle.cls")
    main = (PAPER / "main.tex").read_text(encoding="utf-8")
    preamble = main[:main.index(r"\begin{document}")]
    keep = [ln for ln in preamble.splitlines()
            if ln.startswith((r"\documentclass", r"\usepackage"))]
    (tmp_path / "tw.tex").write_text("\n".join(keep) + "\n\\begin{document}\n"
                                     "\\typeout{TEXTWIDTH=\\the\\textwidth}\nx\n\\end{document}\n")
    run = subprocess.run(["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "tw.tex"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    m = re.search(r"TEXTWIDTH=([0-9.]+)pt", run.stdout)
    assert m, run.stdout[-2000:]
    assert float(m.group(1)) / TEX_PT_PER_IN == pytest.approx(style.TEXT_WIDTH, rel=1e-9)


# --- figures built here ----------------------------------------------------------------

def test_every_included_figure_is_checked():
    assert INCLUDED, "no \\includegraphics found in paper/main.tex"
    assert set(INCLUDED) == set(CASES), (
        "every figure in the report, and only those, has a figure module (plotting.figure_ids)")


def drawn_fonts(fig, monkeypatch) -> list[tuple[float, str]]:
    """(size in pt, text) of every text the figure draws (tick labels in view, labels,
    titles, legends, annotations), recorded as they are drawn."""
    seen = []
    draw = matplotlib.text.Text.draw

    def record(self, renderer):
        if self.get_visible() and self.get_text().strip():
            seen.append((float(self.get_fontsize()), self.get_text()))
        return draw(self, renderer)

    monkeypatch.setattr(matplotlib.text.Text, "draw", record)
    with style.context():
        FigureCanvasAgg(fig).draw()
    monkeypatch.undo()
    return seen


@pytest.mark.parametrize("fid", sorted(CASES))
def test_fonts_print_at_7pt_or_more(fid, monkeypatch):
    fig = plotting.draw(fid, CASES[fid]())
    drawn = float(fig.get_size_inches()[0])
    scale = printed_width(fid, drawn) / drawn
    fonts = drawn_fonts(fig, monkeypatch)
    assert fonts
    small = sorted({(round(size * scale, 2), text) for size, text in fonts
                    if size * scale < MIN_PT - 1e-9})
    assert not small, (f"{fid}: drawn {drawn:.3f} in wide, printed at x{scale:.3f}; "
                       f"text below {MIN_PT} pt: {small[:8]}")


@pytest.mark.parametrize("fid", sorted(CASES))
def test_drawn_at_the_printed_width(fid):
    """Scale factor 1: the style draws each figure as wide as it is printed."""
    fig = plotting.draw(fid, CASES[fid]())
    drawn = float(fig.get_size_inches()[0])
    assert printed_width(fid, drawn) == pytest.approx(drawn, rel=1e-3), (
        f"{fid}: drawn {drawn:.3f} in, included as [{INCLUDED[fid]}]")


def test_no_font_size_below_the_minimum_in_the_code():
    """Also the branches the synthetic data do not reach: every literal font size in the
    plotting code and the style is at least style.FONT_MIN (figures print at scale 1)."""
    assert style.FONT_MIN >= MIN_PT
    for key, value in style.RC.items():
        if key == "font.size" or key.endswith(("labelsize", "titlesize", "fontsize")):
            assert isinstance(value, (int, float)) and value >= MIN_PT, (key, value)
    pattern = re.compile(r"\b(fontsize|labelsize|title_fontsize)\s*=\s*([^,)\s]+)")
    for path in sorted((ROOT / "workflow" / "filippov_paper" / "plotting").glob("*.py")):
        for m in pattern.finditer(path.read_text(encoding="utf-8")):
            where, value = f"{path.name}: {m.group(0)}", m.group(2)
            if value.startswith("st.") or value.startswith("style."):
                value = str(getattr(style, value.split(".", 1)[1]))
            assert re.fullmatch(r"[0-9.]+", value), f"{where}: give sizes in points"
            assert float(value) >= MIN_PT, where


# --- figures a build has left ----------------------------------------------------------

def pdf_text_sizes(pdf: Path) -> tuple[float, list[float]]:
    """MediaBox width (bp) and, per text object (BT ... ET), its font size: the largest
    Tf in it (a math text sets its sub- and superscripts smaller, as TeX does)."""
    data = pdf.read_bytes()
    box = re.search(rb"/MediaBox\s*\[\s*([-\d.]+)\s+[-\d.]+\s+([-\d.]+)", data)
    sizes = []
    for m in re.finditer(rb"stream\r?\n(.*?)endstream", data, re.S):
        try:
            content = zlib.decompress(m.group(1))
        except zlib.error:
            content = m.group(1)
        for block in re.findall(rb"\bBT\b(.*?)\bET\b", content, re.S):
            tf = [float(x) for x in re.findall(rb"/\S+\s+([0-9.]+)\s+Tf", block)]
            if tf:
                sizes.append(max(tf))
    return float(box.group(2)) - float(box.group(1)), sizes


@pytest.mark.parametrize("fid", sorted(INCLUDED))
def test_built_figure_prints_at_7pt_or_more(workflow_build, fid):
    # the suite's shared build (tests/conftest.py), not figures/ of this checkout: a clone
    # and CI have none there, and a stale one would be checked in place of this tree's
    run = workflow_build["run"]
    assert run.returncode == 0, run.stdout[-3000:] + run.stderr[-3000:]
    pdf = Path(workflow_build["work"]) / "figures" / f"{fid}.pdf"
    assert pdf.is_file(), f"the build made no figures/{fid}.pdf"
    width_bp, sizes = pdf_text_sizes(pdf)
    assert sizes, f"{pdf}: no text found"
    drawn = width_bp / 72
    scale = printed_width(fid, drawn) / drawn
    assert min(sizes) * scale >= MIN_PT - 1e-6, (
        f"figures/{fid}.pdf: {drawn:.3f} in wide, printed at x{scale:.3f}: smallest text "
        f"{min(sizes):g} pt prints at {min(sizes) * scale:.2f} pt ")
