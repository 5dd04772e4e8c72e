"""A caption's colour words name colours its figure draws (issue 31).

Every figure of the report (a ``figure`` environment of paper/*.tex) is found by the
file its ``\\includegraphics`` names, drawn by its plotting module from the synthetic
dataset of tests/synthetic.py (no pipeline), and every colour it draws -- lines,
markers, line strokes, patches, collections, colour-mesh cells, annotations, legend
keys -- is named with filippov_paper.plotting.style.colour_name. Each colour word of the
caption must be one of those names; where the caption puts a colour in parentheses
after a legend label ("slow-fast (black)"), the legend key of that label must have it.
"""
from __future__ import annotations

import re
from pathlib import Path

import matplotlib.patheffects as pe
import numpy as np
import pytest
from matplotlib.artist import Artist
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.collections import Collection
from matplotlib.colors import to_hex, to_rgba
from matplotlib.lines import Line2D
from matplotlib.patches import Patch
from matplotlib.text import Annotation

import filippov_paper.plotting as plotting
import synthetic
from filippov_paper.plotting import style

ROOT = Path(__file__).resolve().parents[1]
PAPER = ROOT / "paper"
PLOTTING = ROOT / "workflow" / "filippov_paper" / "plotting"

#: words a caption could use for a colour ("gray" is read as "grey")
COLOUR_WORDS = {"black", "white", "grey", "gray", "red", "orange", "yellow", "green", "blue",
                "purple", "violet", "pink", "magenta", "cyan", "teal", "brown", "dark"}
WORD = re.compile(r"\b(" + "|".join(sorted(COLOUR_WORDS)) + r")\b", re.I)


def _word(w: str) -> str:
    w = w.lower()
    return "grey" if w == "gray" else w


# --- the captions -------------------------------------------------------------------------

def _braced(text: str, start: int) -> str:
    """The argument of the brace group that opens at text[start]."""
    assert text[start] == "{"
    depth = 0
    for k in range(start, len(text)):
        if text[k] == "{" and text[k - 1] != "\\":
            depth += 1
        elif text[k] == "}" and text[k - 1] != "\\":
            depth -= 1
            if depth == 0:
                return text[start + 1:k]
    raise AssertionError(f"unbalanced braces after {text[start:start + 60]!r}")


def figure_captions() -> dict[str, str]:
    """figure id (the \\includegraphics file's stem) -> the caption of its figure."""
    found = {}
    for tex in sorted(PAPER.glob("*.tex")):
        text = re.sub(r"(?<!\\)%.*", "", tex.read_text(encoding="utf-8"))
        for env in re.findall(r"\\begin\{figure\*?\}(.*?)\\end\{figure\*?\}", text, re.S):
            files = re.findall(r"\\includegraphics\s*(?:\[[^\]]*\])?\s*\{([^}]*)\}", env)
            at = env.find(r"\caption{")
            if not files or at < 0:
                continue
            assert len(files) == 1, f"{tex.name}: a figure with several graphics: {files}"
            fid = Path(files[0].strip()).stem
            assert fid not in found, f"{fid} is included twice"
            found[fid] = _braced(env, at + len(r"\caption"))
    return found


CAPTIONS = figure_captions()


def colour_words(caption: str) -> list[str]:
    """The colour words of a caption's text (not of the labels it cites: eq:red)."""
    text = re.sub(r"\\paperfig\{[^}]*\}\{[^}]*\}", "", caption)
    text = re.sub(r"\\(?:pref|pnum|ref|eqref|label|cite|texttt)\{[^}]*\}", "", text)
    return [_word(w) for w in WORD.findall(text)]


# --- the colours a figure draws ------------------------------------------------------------

def dataset(fid: str):
    return synthetic.dataset(fid)


def _rgba(colours) -> list:
    """Visible colours (alpha > 0) of one colour or an array of them."""
    if colours is None or (isinstance(colours, str) and colours.lower() == "none"):
        return []
    arr = np.asarray(colours, dtype=object)
    if arr.ndim == 2 or (arr.ndim == 1 and arr.size and not isinstance(arr[0], (int, float))
                         and not isinstance(colours, (str, tuple))):
        out = []
        for c in colours:
            out += _rgba(c)
        return out
    rgba = to_rgba(colours)
    return [rgba] if rgba[3] > 0 else []


def _stroke_colours(artist: Artist) -> list:
    """Colours of the strokes a path effect draws under an artist (e.g. a dark edge)."""
    out = []
    for effect in artist.get_path_effects() or []:
        if isinstance(effect, pe.Stroke):
            out += _rgba(effect._gc.get("foreground"))
    return out


def artist_colours(artist: Artist) -> list:
    if isinstance(artist, Line2D):
        found = _rgba(artist.get_color())
        if artist.get_marker() not in (None, "None", "none", ""):
            found += _rgba(artist.get_markerfacecolor()) + _rgba(artist.get_markeredgecolor())
        return found + _stroke_colours(artist)
    if isinstance(artist, (Patch, Collection)):
        return (_rgba(artist.get_facecolor()) + _rgba(artist.get_edgecolor())
                + _stroke_colours(artist))
    if isinstance(artist, Annotation):
        arrow = artist.arrow_patch
        return _rgba(artist.get_color()) + (artist_colours(arrow) if arrow else [])
    return _rgba(artist.get_color()) if hasattr(artist, "get_color") else []


def drawn(fig) -> list[Artist]:
    """What a figure draws: each axes' data artists (not its frame, ticks or labels)
    and every legend's keys."""
    FigureCanvasAgg(fig).draw()  # maps colour-mesh values to colours
    artists = list(fig.texts)
    legends = list(fig.legends)
    for ax in fig.axes:
        artists += [*ax.lines, *ax.collections, *ax.patches, *ax.texts, *ax.images]
        if ax.get_legend() is not None:
            legends.append(ax.get_legend())
    for leg in legends:
        artists += [h for h in leg.legend_handles if h is not None]
    return artists


def drawn_names(fig) -> set[str]:
    names = set()
    for artist in drawn(fig):
        for c in artist_colours(artist):
            name = style.colour_name(c)
            if name is not None:
                names.add(name)
    return names


# --- the tests -----------------------------------------------------------------------------

def test_every_style_colour_has_a_name():
    consts = {k: v for k, v in vars(style).items() if re.fullmatch(r"C_[A-Z]+", k)}
    assert consts
    for name, colour in consts.items():
        assert style.colour_name(colour) in set(style.COLOUR_NAMES.values()), name
    assert style.colour_name(style.C_PLUS) == "blue"
    assert style.colour_name(style.C_MINUS) == "orange"
    assert style.colour_name(style.C_SLIDE) == "green"
    assert style.colour_name(style.C_AUX) == "grey"
    assert style.colour_name("k") == style.colour_name("black") == "black"
    assert style.colour_name("white") == "white"
    assert style.colour_name("0.88") == style.colour_name("#dddddd") == "grey"


def test_every_hue_in_the_plotting_code_has_a_name():
    """A hue typed into a figure module (a hex colour) is named in style.COLOUR_NAMES,
    so a caption can say what it is."""
    unnamed = []
    for path in sorted(PLOTTING.glob("*.py")):
        for hexcode in re.findall(r"[\"'](#[0-9A-Fa-f]{6})[\"']", path.read_text()):
            if style.colour_name(hexcode) is None:
                unnamed.append(f"{path.name}: {hexcode}")
    assert not unnamed, f"colours without a name in style.COLOUR_NAMES: {unnamed}"


def test_captions_are_found():
    assert len(CAPTIONS) >= 14, sorted(CAPTIONS)
    assert {"fig12_period_adding", "fig13_small_scale_chaos", "fig14_atlas"} <= set(CAPTIONS)


def test_colour_words_are_read():
    assert colour_words(r"Grey: the line; (black) and limit map (Orange), gray, dark") == [
        "grey", "black", "orange", "grey", "dark"]
    assert colour_words(r"reduced, blueprint, greyish, \pref{eq:red}, \ref{fig:blue}") == []


@pytest.mark.parametrize("fid", sorted(CAPTIONS))
def test_caption_colour_words_name_drawn_colours(fid):
    words = set(colour_words(CAPTIONS[fid]))
    if not words:
        return
    assert "dark" not in words, (f"{fid}: 'dark' names no colour; say which "
                                 f"({CAPTIONS[fid][:80]}...)")
    fig = plotting.draw(fid, dataset(fid))
    names = drawn_names(fig)
    wrong = sorted(words - names)
    assert not wrong, f"{fid}: the caption says {wrong}; the figure draws {sorted(names)}"


def _key_name(handle) -> set[str]:
    return {style.colour_name(c) for c in artist_colours(handle)} - {None}


@pytest.mark.parametrize("fid", sorted(CAPTIONS))
def test_a_labelled_colour_is_its_legend_key(fid):
    """'slow-fast (black)': the legend key labelled slow-fast is black."""
    caption = CAPTIONS[fid]
    if not colour_words(caption):
        return
    fig = plotting.draw(fid, dataset(fid))
    drawn(fig)
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend()]
    checked = []
    for leg in legends:
        for handle, text in zip(leg.legend_handles, leg.get_texts()):
            label = text.get_text().strip()
            if not label or handle is None:
                continue
            m = re.search(re.escape(label) + r"[^();]{0,120}?\((\w+)\)", caption)
            if m and _word(m.group(1)) in COLOUR_WORDS:
                word = _word(m.group(1))
                assert word in _key_name(handle), (
                    f"{fid}: the caption says {label!r} is {word}; its legend key is "
                    f"{sorted(_key_name(handle))}")
                checked.append(label)
    if fid in ("fig12_period_adding", "fig13_small_scale_chaos"):
        assert {"slow-fast", "limit map"} <= set(checked), checked


# --- fig14: the boundary lines are white, edged in black --------------------------------------

def _boundary_look(line: Line2D):
    strokes = [to_hex(c) for c in _stroke_colours(line)]
    return to_hex(line.get_color()), tuple(strokes)


def test_atlas_boundary_lines_look_the_same_in_the_legend():
    fig = plotting.draw("fig14_atlas", synthetic.dataset("fig14_atlas"))
    drawn(fig)
    on_axes = {_boundary_look(ln) for ax in fig.axes for ln in ax.lines
               if ln.get_path_effects() and len(ln.get_xdata())}
    keys = {_boundary_look(h) for leg in fig.legends for h in leg.legend_handles
            if isinstance(h, Line2D)}
    white_edged = ("#ffffff", ("#000000",))
    assert on_axes == {white_edged}, on_axes
    assert keys == {white_edged}, keys


def test_atlas_caption_does_not_call_the_boundary_lines_dark():
    caption = CAPTIONS["fig14_atlas"]
    for word in ("dark", "black"):
        for m in re.finditer(rf"\b{word}\b", caption, re.I):
            near = caption[max(0, m.start() - 60):m.end() + 60]
            assert not re.search(r"dash|dott|line|circle|bound", near, re.I), (
                f"fig14: the boundary lines are white with a black edge, not {word}: "
                f"...{near}...")
