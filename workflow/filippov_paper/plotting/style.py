"""One publication style for every figure, in the paper's notation.

Fonts are matplotlib's bundled STIX (Times-like, as in the elsart paper), so
the output does not depend on which fonts a machine happens to have.
"""
from __future__ import annotations

import contextlib

import matplotlib as mpl
import numpy as np

from filippov_paper.plotting import ticks

# Figures are drawn at the size they are printed (scale factor 1), so every size below
# is a size on paper. The report, paper/main.tex, is \documentclass[preprint,11pt,
# a4paper]{elsarticle} without a geometry package: \textwidth = 360pt (a LaTeX run
# printing \the\textwidth says 360.0pt; TeX has 72.27 pt to the inch), 4.98 in. A figure
# included with \includegraphics[width=f\textwidth] is drawn f * TEXT_WIDTH wide
# (tests/test_print_size.py reads the widths from paper/*.tex and checks the fonts).
TEXT_WIDTH = 360.0 / 72.27  # inches
FONT_MIN = 7  # pt: nothing is printed smaller (tick labels, legends, notes)

# The paper's symbols, so every module labels things the same way. Sub-
# scripts +/- are braced: mathtext spaces a bare `_+` like a binary operator.
X1, X2 = r"$x_1$", r"$x_2$"
X, Y = r"$x$", r"$y$"
EPS, THETA = r"$\varepsilon$", r"$\theta$"
H_S = r"$\mathcal{H}_s$"
M_0, M_PLUS, M_MINUS = r"$\mathcal{M}_0$", r"$\mathcal{M}_{+}$", r"$\mathcal{M}_{-}$"
M_PM = r"$\mathcal{M}_{\pm}$"
F_PLUS, F_MINUS = r"$f_{+}$", r"$f_{-}$"
S0 = r"$s_0(\theta)$"

# Colours (colour-blind safe pair) and line widths shared by the figures.
C_PLUS, C_MINUS, C_SLIDE = "#0072B2", "#D55E00", "#009E73"
C_AUX = "0.55"  # grey for reference lines (manifolds, asymptotes)
LW_THIN, LW, LW_BOLD = 0.6, 1.0, 1.8

#: The word a caption uses for each colour the figures draw: the style's colours and
#: the other hues the figure modules use. Greys, black and white are named by
#: colour_name from their lightness. A caption's colour words must name colours its
#: figure draws (tests/test_caption_colours.py).
COLOUR_NAMES = {
    C_PLUS: "blue",        # Okabe-Ito blue
    C_MINUS: "orange",     # Okabe-Ito vermillion, a red-orange
    C_SLIDE: "green",      # Okabe-Ito bluish green
    C_AUX: "grey",
    "#CC79A7": "pink",     # Okabe-Ito reddish purple (fig14: period 5)
    "#E69F00": "yellow",   # Okabe-Ito orange, a golden yellow beside C_MINUS (fig14)
    "#e7298a": "magenta",  # work_precision: compiled DOP853
    "#7b3294": "purple",   # work_precision: solve_ivp DOP853
    "#1b9e77": "green",    # work_precision: solve_ivp Radau
    "#d95f02": "orange",   # work_precision: solve_ivp LSODA
}


def colour_name(colour) -> str | None:
    """The word for a matplotlib colour: "black", "grey" or "white" for a colour without
    hue, the COLOUR_NAMES word for a named hue, None for any other (a colour map's)."""
    from matplotlib.colors import to_hex, to_rgb

    r, g, b = to_rgb(colour)
    if max(r, g, b) - min(r, g, b) < 0.04:  # no hue: by lightness
        light = (r + g + b) / 3
        return "black" if light < 0.15 else "white" if light > 0.97 else "grey"
    named = {to_hex(c): word for c, word in COLOUR_NAMES.items()}
    return named.get(to_hex((r, g, b)))

RC = {
    "font.family": "serif",
    "font.serif": ["STIXGeneral", "DejaVu Serif"],
    "mathtext.fontset": "stix",
    "font.size": 8,
    "axes.labelsize": 8,
    "axes.titlesize": 8,
    "figure.titlesize": 8,
    "legend.fontsize": FONT_MIN,
    "legend.title_fontsize": FONT_MIN,
    "xtick.labelsize": FONT_MIN,
    "ytick.labelsize": FONT_MIN,
    "axes.linewidth": 0.6,
    "lines.linewidth": LW,
    "xtick.direction": "in",
    "ytick.direction": "in",
    "xtick.major.width": 0.6,
    "ytick.major.width": 0.6,
    "legend.frameon": False,
    "figure.dpi": 100,
    "savefig.dpi": 200,
    # Determinism: embedded TrueType fonts, fixed SVG id salt.
    "pdf.fonttype": 42,
    "ps.fonttype": 42,
    "svg.hashsalt": "filippov",
    "path.simplify": False,  # keep every computed point
}


@contextlib.contextmanager
def context():
    """rc context used both to build figures and to save them: some rcParams
    (tick fonts, font embedding) are read only at draw time, and so are the ticks,
    laid here at steps no machine's libm can flip (plotting/ticks.py)."""
    with mpl.rc_context(RC), ticks.exact_scale():
        yield


def panel_label(ax, text: str) -> None:
    """Panel tag like '(a) crossing' above the axes, left-aligned as in the paper."""
    ax.set_title(text, loc="left")


def legend_below(ax, *args, **kw):
    """A legend of one panel under its x label, off the data; constrained layout makes
    room for it (it belongs to the axes' tight box), so it must not be wider than the
    panel (the layout would narrow the axes). Arguments as for ax.legend."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.transforms import ScaledTranslation

    rc = mpl.rcParams
    tick = FontProperties(size=rc["xtick.labelsize"]).get_size_in_points()
    label = FontProperties(size=rc["axes.labelsize"]).get_size_in_points()
    # tick pad, tick labels, label pad and the x label (room for sub- and superscripts)
    drop = rc["xtick.major.pad"] + 1.4 * tick + rc["axes.labelpad"] + 1.6 * label
    where = ax.transAxes + ScaledTranslation(0, -drop / 72, ax.figure.dpi_scale_trans)
    kw.setdefault("loc", "upper center")
    return ax.legend(*args, bbox_to_anchor=(0.5, 0.0), bbox_transform=where, borderaxespad=0.0,
                     **kw)


def eps_value(e: float) -> str:
    """An eps for math text (no dollars): 10^{k} for a power of ten, else 2 digits."""
    k = np.log10(e)
    if abs(k - round(k)) < 1e-9:
        return f"10^{{{int(round(k))}}}"
    return f"{e:.2g}"


def orbit_diagram(ax, s, u, **kw):
    """An orbit diagram: every kept return u[i, :] as a pixel dot at parameter s[i]."""
    ax.plot(np.repeat(s, u.shape[-1]), u.reshape(-1), ",", **kw)


def new_figure(width: float, height: float):
    """A pyplot-free Figure: no GUI backend, no global figure registry to leak."""
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), layout="constrained")


def require(ds, scene_id: str, names) -> None:
    """Fail with the dataset contract's names, not a deep KeyError from a plot call."""
    missing = [n for n in names if n not in ds.variables]
    if missing:
        raise KeyError(f"{scene_id}: dataset lacks {', '.join(missing)} "
                       f"(has: {', '.join(sorted(map(str, ds.variables)))})")
