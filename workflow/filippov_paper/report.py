"""Numbers for the reproduction report (paper/): datasets in, LaTeX out.

Every number the report quotes from a computation comes from here, never from the
prose. :func:`generate` takes the loaded datasets (``results/<id>.nc``; missing
ones are ``None``) and returns ``{file name: LaTeX text}`` for
``paper/generated/``:

* ``macros.tex`` -- one ``\\newcommand`` per quoted number, each preceded by a
  ``%% source:`` comment naming the dataset and variable it comes from (the
  tests re-read that variable and compare), plus ``\\newif`` switches saying
  which optional results (dry friction, work--precision sweep) exist;
* ``<scene id>.tex`` for every scene -- the table its scene module's ``report``
  returns (e.g. convergence over eps), a "not yet computed" sentence for an
  optional scene without data, or a comment when the scene has no table;
* ``tab_bench.tex`` (and any other table a benchmark names) -- the blocks of the
  benchmarks' report parts: the work--precision sweep (or "not yet computed"), then what
  `make bench` measured when it has;
* ``tab_hard_cases.tex``, ``tab_hard_return.tex`` -- the hard-case eps sweep
  (``results/hard_cases.nc``), one row per eps: the tables of the report part of
  :mod:`filippov_paper.hard_cases` (its ``REPORT`` and ``report``).

The scenes declare their own part: each scene module ``filippov_paper.scenes.<id>`` defines
``report(ds, macros)`` (adds its macros, returns its table or None) and, when the
report can do without its data, ``REPORT_OPTIONAL = True`` (then ``ds`` may be
None). There is no list of scenes here, and none of benchmarks: a benchmark module
``filippov_paper.benchmarks.<name>`` with a report part declares ``REPORT`` (the dataset
it reads, the table its block goes into, its place among the benchmarks) and
``report(ds, macros)`` (:mod:`filippov_paper.product`). A scene's or benchmark's report
part (those names and its ``_report_*`` helpers, :func:`filippov_paper.config.is_report_part`)
is left out of the code hash of the jobs that compute its data and is not in the plotting
code: editing it rebuilds the report tables only.

No Snakemake inside; ``workflow/scripts/report_tables.py`` is the thin caller.
"""
from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Mapping, Optional

import numpy as np
import xarray as xr

from filippov_paper import product

NOT_YET = "not yet computed"


# ----------------------------------------------------------------------------- formatting
def num(x, sig: int = 3) -> str:
    """A float as LaTeX math text (no dollars): 0.00874 -> 8.74\\times10^{-3}."""
    x = float(x)
    if math.isnan(x):
        return r"\mathrm{NaN}"
    if math.isinf(x):
        return r"-\infty" if x < 0 else r"\infty"
    if x == 0:
        return "0"
    if x == int(x) and abs(x) < 1e6:
        return str(int(x))
    exp = math.floor(math.log10(abs(x)))
    if -3 <= exp < 4:
        decimals = max(sig - 1 - exp, 0)
        text = f"{x:.{decimals}f}"
        return text if decimals == 0 else text.rstrip("0").rstrip(".")
    mant = f"{x / 10 ** exp:.{sig - 1}f}".rstrip("0").rstrip(".")
    if mant in ("10", "-10"):  # rounding carried into the next decade
        mant, exp = mant[:-1], exp + 1
    if mant in ("1", "-1"):
        return ("-" if mant == "-1" else "") + rf"10^{{{exp}}}"
    return rf"{mant}\times10^{{{exp}}}"


def num_range(lo, hi, sig: int = 3) -> str:
    """A range of two measured numbers as a table cell, '$0.52$--$0.81$': the spread of a
    time (first to third quartile) or the range of a ratio of two times."""
    return f"${num(lo, sig)}$--${num(hi, sig)}$"


def parse_num(text: str) -> float:
    """Inverse of :func:`num` (used by the tests to read macros back)."""
    t = text.replace(r"\ensuremath", "").replace("{", "").replace("}", "").replace(" ", "")
    t = t.replace(r"\mathrm", "")
    m = re.fullmatch(r"(-?[0-9.]+)?(?:\\times)?(?:(-)?10\^(-?[0-9]+))?", t)
    if not m or (m.group(1) is None and m.group(3) is None):
        raise ValueError(f"not a number macro: {text!r}")
    mant = float(m.group(1)) if m.group(1) not in (None, "") else 1.0
    if m.group(2):
        mant = -mant
    return mant * (10.0 ** int(m.group(3)) if m.group(3) else 1.0)


def tex_escape(text: str) -> str:
    repl = {"\\": r"\textbackslash{}", "_": r"\_", "%": r"\%", "&": r"\&", "#": r"\#",
            "$": r"\$", "{": r"\{", "}": r"\}", "^": r"\^{}", "~": r"\~{}"}
    return "".join(repl.get(c, c) for c in str(text))


#: names a plain-text formula may use besides one-letter variables (x, x1, y)
MATH_NAMES = {"exp": r"\exp", "log": r"\log", "sin": r"\sin", "cos": r"\cos",
              "tanh": r"\tanh", "theta": r"\theta", "eps": r"\epsilon", "mu": r"\mu",
              "omega": r"\omega"}


def plain_math_tex(expr: str) -> str:
    """A formula typed in plain text, as the datasets' attributes hold them, as LaTeX
    math without dollars: '-1 - x1^2/4' -> '-1-x_1^2/4' (an indexed variable gets its
    subscript, spaces go, '*' is a thin space; a name other than a one-letter variable
    or one of MATH_NAMES is refused)."""
    s = str(expr).replace(" ", "")
    if not re.fullmatch(r"[0-9A-Za-z+\-*/^().]+", s) or re.search(r"\^[^0-9A-Za-z]", s):
        raise ValueError(f"not a plain formula: {expr!r}")

    def name(m):
        letters, index = m.group(1), m.group(2)
        if letters in MATH_NAMES and not index:
            return MATH_NAMES[letters] + " "
        if len(letters) != 1:
            raise ValueError(f"unknown name {letters + index!r} in the formula {expr!r}")
        return letters + ("" if not index else f"_{index}" if len(index) == 1
                          else f"_{{{index}}}")
    s = re.sub(r"([A-Za-z]+)([0-9]*)", name, s)
    s = re.sub(r"\^([0-9]{2,})", r"^{\1}", s)
    return s.replace("*", r"\,").strip()


def _split_top(text: str) -> list[str]:
    """``text`` split at the commas outside parentheses."""
    parts, depth, cur = [], 0, ""
    for c in text:
        depth += (c == "(") - (c == ")")
        if c == "," and depth == 0:
            parts.append(cur)
            cur = ""
        else:
            cur += c
    return [p.strip() for p in parts + [cur] if p.strip()]


def formulas_tex(text: str, argument: str = "x") -> str:
    """Definitions typed in plain text, 'f_- = (1, 1 + x1/2), f_+ = (1, 1/2)' or
    'h = x2', as the paper writes them: '$f_-(x)=(1,\\,1+x_1/2)$ and
    $f_+(x)=(1,\\,1/2)$', '$h(x)=x_2$' (each a function of ``argument``)."""
    out = []
    for part in _split_top(text):
        name, eq, rhs = part.partition("=")
        name, rhs = name.strip(), rhs.strip()
        if not eq or not re.fullmatch(r"[A-Za-z]+(_[-+A-Za-z0-9])?", name):
            raise ValueError(f"not a definition 'name = value': {part!r}")
        if rhs.startswith("(") and rhs.endswith(")"):
            value = "(" + r",\,".join(plain_math_tex(c) for c in _split_top(rhs[1:-1])) + ")"
        else:
            value = plain_math_tex(rhs)
        out.append(f"${name}({argument})={value}$")
    if not out:
        raise ValueError(f"no definition in {text!r}")
    return ", ".join(out[:-1]) + (" and " if len(out) > 1 else "") + out[-1]


NUMBER_WORDS = ("no", "one", "two", "three", "four", "five", "six", "seven", "eight",
                "nine", "ten", "eleven", "twelve")


def count_word(n) -> str:
    """A count as prose writes it: a word up to twelve ('no' for zero), digits above."""
    n = int(n)
    if n < 0:
        raise ValueError(f"a count is not negative: {n}")
    return NUMBER_WORDS[n] if n < len(NUMBER_WORDS) else str(n)


def _capital(text: str, capital: bool) -> str:
    return text[0].upper() + text[1:] if capital else text


def count_phrase(n, singular: str, plural: Optional[str] = None, *,
                 capital: bool = False) -> str:
    """A count with its noun: 'no configuration', 'one configuration', 'three
    configurations', '16 configurations' (``plural`` defaults to ``singular`` + 's';
    ``capital`` for the start of a sentence)."""
    n = int(n)
    noun = singular if n in (0, 1) else (plural or singular + "s")
    return _capital(f"{count_word(n)} {noun}", capital)


def range_phrase(lo, hi, singular: str, plural: Optional[str] = None) -> str:
    """From ``lo`` to ``hi`` of a noun: '3 to 250 runs' (digits for both ends when one
    is above twelve), 'three to five runs', or one count when they agree ('one run')."""
    lo, hi = int(lo), int(hi)
    if lo == hi:
        return count_phrase(lo, singular, plural)
    a, b = (count_word(lo), count_word(hi)) if hi < len(NUMBER_WORDS) else (str(lo), str(hi))
    return f"{a} to {b} {plural or singular + 's'}"


def share_phrase(k, n, singular: str, plural: Optional[str] = None) -> str:
    """``k`` of ``n`` things with their noun: 'none of the values', 'one of the five
    values', 'four of the five values', 'both values', 'all five values' ('the only
    value' for one of one)."""
    k, n = int(k), int(n)
    if not 0 <= k <= n:
        raise ValueError(f"{k} of {n}")
    nouns = plural or singular + "s"
    if k == 0:
        return f"{'neither' if n == 2 else 'none'} of the {nouns}"
    if k == n:
        return (f"the only {singular}" if n == 1 else f"both {nouns}" if n == 2
                else f"all {count_word(n)} {nouns}")
    return f"{count_word(k)} of the {count_word(n)} {nouns}"


_NAME = re.compile(r"[A-Za-z]+")


@dataclass
class Macros:
    """Ordered collection of ``\\newcommand`` macros with their sources."""
    items: list = field(default_factory=list)
    flags: dict = field(default_factory=dict)

    def add(self, name: str, value, source: str, sig: int = 3, text: Optional[str] = None):
        if not _NAME.fullmatch(name):
            raise ValueError(f"macro names are letters only: {name!r}")
        body = text if text is not None else num(value, sig)
        self.items.append((name, None if value is None else float(value),
                           source if value is None else f"{source} | digits={sig}", body))

    def flag(self, name: str, on: bool):
        self.flags[name] = bool(on)

    def tex(self) -> str:
        out = ["% Generated by filippov_paper.report from results/*.nc -- do not edit.",
               "% Each macro names its source as  dataset:variable[selection]  (or derived:).", ""]
        for name, on in self.flags.items():
            out.append(rf"\newif\if{name}\{name}{'true' if on else 'false'}")
        out.append("")
        for name, value, source, body in self.items:
            out.append(f"% source: {source}")
            if value is not None:
                body = r"\ensuremath{" + body + "}"
            out.append(rf"\newcommand{{\{name}}}{{{body}}}")
        return "\n".join(out) + "\n"

    def values(self) -> dict:
        return {name: (value, source) for name, value, source, _ in self.items}


def value(ds, var, **sel) -> float:
    v = ds[var]
    if sel:
        v = v.sel(**sel)
    return float(v.values)


def source(sid, var, **sel) -> str:
    s = ",".join(f"{k}={v!r}" for k, v in sel.items())
    return f"{sid}:{var}" + (f"[{s}]" if s else "")


def var(m: Macros, name, ds, sid, var, sig=3, **sel):
    m.add(name, value(ds, var, **sel), source(sid, var, **sel), sig)


def eps_tex(e):
    return num(e, 2)


# ----------------------------------------------------------------------------- optional data
def tabular(cols, head, rows) -> str:
    return "\n".join([rf"\begin{{tabular}}{{@{{}}{cols}@{{}}}}", r"\toprule", *head,
                      r"\midrule", *rows, r"\bottomrule", r"\end{tabular}"]) + "\n"


def head(*cells: str) -> str:
    """A header row; a cell with a line break ``//`` is set on two lines (the tables
    keep to the text width at the body font size instead of being shrunk)."""
    def stack(cell):
        if "//" not in cell:
            return cell
        return r"\begin{tabular}[b]{@{}c@{}}" + cell.replace("//", r"\\") + r"\end{tabular}"
    return " & ".join(stack(c) for c in cells) + r" \\"


def per_eps_rows(ds, cells) -> list[str]:
    """One table row per eps of ``ds``: ``cells(d)`` gives the cells after the eps
    column for the selection ``d`` at that eps."""
    rows = []
    for e in ds.eps.values:
        rows.append(" & ".join([f"${eps_tex(e)}$", *cells(ds.sel(eps=e))]) + r" \\")
    return rows


def rate_cell(rate: float, sig: int) -> str:
    """A convergence rate, or a dash where there is none (the first eps)."""
    return "--" if math.isnan(rate) else f"${num(rate, sig)}$"


def absent(m: "Macros", flag: str, ds, what: str, path: str) -> Optional[str]:
    """For an optional scene: sets the report's switch ``flag``; the "not yet
    computed" text when ``ds`` is None, else None."""
    m.flag(flag, ds is not None)
    return not_yet(what, path) if ds is None else None


def not_yet(what: str, path: str) -> str:
    return (rf"\emph{{{what}: {NOT_YET}}} (\texttt{{{tex_escape(path)}}} is absent; the table "
            r"fills in when the workflow is rerun after it has been produced).") + "\n"


def _cell(v) -> str:
    if isinstance(v, (bytes, str)):
        return r"\texttt{" + tex_escape(v if isinstance(v, str) else v.decode()) + "}"
    try:
        f = float(v)
    except (TypeError, ValueError):
        return tex_escape(str(v))
    return f"${num(f)}$"


def scalar_table(ds: xr.Dataset, max_rows: int = 40) -> str:
    """Name, meaning and value of every scalar variable of a dataset (a generic
    table for datasets whose contract is still growing)."""
    rows = []
    for name, var in ds.data_vars.items():
        if var.ndim != 0:
            continue
        # a typeset meaning where the scene gives one, else the plain long_name
        meaning = var.attrs.get("long_name_tex") or tex_escape(var.attrs.get("long_name", ""))
        rows.append(rf"\texttt{{{tex_escape(name)}}} & {meaning} & {_cell(var.values)} \\")
        if len(rows) >= max_rows:
            break
    if not rows:
        return r"\emph{(the dataset holds no scalar variables)}" + "\n"
    return tabular("lp{0.5\\textwidth}r", [r"variable & meaning & value \\"], rows)


def table_frame(ds: xr.Dataset, max_rows: int = 30) -> str:
    """A work--precision style table: the largest group of variables sharing
    dimensions, one row per coordinate combination (at most ``max_rows``)."""
    groups: dict = {}
    for name, var in ds.data_vars.items():
        if var.ndim >= 1:
            groups.setdefault(var.dims, []).append(name)
    if not groups:
        return scalar_table(ds)
    dims = max(groups, key=lambda k: (len(groups[k]), -len(k)))
    names = groups[dims][:6]
    df = ds[names].to_dataframe().reset_index()
    cols = [*dims, *names]
    head = " & ".join(r"\texttt{" + tex_escape(c) + "}" for c in cols) + r" \\"
    rows = [" & ".join(_cell(r[c]) for c in cols) + r" \\" for _, r in df.head(max_rows).iterrows()]
    if len(df) > max_rows:
        more = count_phrase(len(df) - max_rows, "more row")
        rows.append(rf"\multicolumn{{{len(cols)}}}{{l}}{{\emph{{\dots\ {more} in the dataset}}}} \\")
    return tabular("l" * len(dims) + "r" * len(names), [head], rows)


#: around each table of measured times: the widths of their numbers follow the machine's
#: speed and load (a slow run's "12345" ms), so a table is shrunk to the line width where
#: it would overrun it (adjustbox's max width; a table that fits is left as it is)
FIT_BEGIN, FIT_END = r"\begin{adjustbox}{max width=\linewidth}", r"\end{adjustbox}"


# ----------------------------------------------------------------------------- entry point
def _scene_modules() -> list:
    """(id, report part) of every scene, in id order (the order of the macros)."""
    import importlib

    from filippov_paper.scenes import known_scenes

    return [(sid, importlib.import_module(f".scenes.{sid}", __package__))
            for sid in known_scenes()]


def _benchmark_modules() -> list:
    """(name, REPORT, module) of every benchmark with a report part, in REPORT's order
    (filippov_paper.product.report_benchmarks: no list of benchmarks here)."""
    import importlib

    return [(name, place, importlib.import_module(f".benchmarks.{name}", __package__))
            for name, place in product.report_benchmarks().items()]


def benchmark_parts(datasets, m: Macros) -> dict[str, str]:
    """{table file: text} of the benchmarks' report parts: each adds its flags and macros
    and gives its block (or None); the blocks of one table, in REPORT's order, joined."""
    blocks: dict[str, list] = {}
    for name, place, mod in _benchmark_modules():
        try:
            block = product.hook(mod, "report")(datasets.get(place["dataset"]), m)
        except KeyError as exc:
            raise KeyError(f"{name}: the report reads {exc} but the dataset "
                           f"{place['dataset']} lacks it") from None
        if place["table"]:
            blocks.setdefault(place["table"], [])
            if block is not None:
                blocks[place["table"]].append(block)
        elif block is not None:
            raise ValueError(f"benchmark {name}: report returned a table but REPORT names "
                             "no 'table' to put it in")
    return {table: "\n".join(parts) if parts else f"% {table}: no table\n"
            for table, parts in blocks.items()}


def generate(datasets: Mapping[str, Optional[xr.Dataset]]) -> dict[str, str]:
    """All generated LaTeX files, keyed by file name. The datasets of scenes that do
    not declare ``REPORT_OPTIONAL`` are required; a benchmark's report part says what
    it does without its dataset."""
    modules = _scene_modules()
    missing = [sid for sid, mod in modules
               if datasets.get(sid) is None and not product.hook(mod, "REPORT_OPTIONAL", False)]
    if missing:
        raise ValueError(f"report needs the datasets of {', '.join(missing)}")
    m = Macros()
    texts = {}
    for sid, mod in modules:
        try:
            table = mod.report(datasets.get(sid), m)
        except KeyError as exc:
            raise KeyError(f"{sid}: the report reads {exc} but the dataset lacks it") from None
        texts[f"{sid}.tex"] = table if table is not None else f"% {sid}: no table\n"
    texts.update(benchmark_parts(datasets, m))
    texts.update(hard_case_parts(datasets, m))
    return {"macros.tex": m.tex(), **texts}


def hard_case_parts(datasets, m: Macros) -> dict[str, str]:
    """{table file: text} of the hard-case sweep's report part (its REPORT["tables"])."""
    import importlib

    hard = importlib.import_module(".hard_cases", __package__)
    sid = product.hook(hard, "DATASET_ID")
    try:
        tables = product.hook(hard, "report")(datasets.get(sid), m)
    except KeyError as exc:
        raise KeyError(f"{sid}: the report reads {exc} but the dataset lacks it") from None
    names = product.hook(hard, "REPORT")["tables"]
    if len(tables) != len(names):
        raise ValueError(f"{sid}: report gave {len(tables)} tables for REPORT {names}")
    return dict(zip(names, tables))


def read_macros(text: str) -> dict:
    """{name: (body, source)} from a generated macros.tex (for the tests)."""
    out, source = {}, None
    for line in text.splitlines():
        if line.startswith("% source: "):
            source = line[len("% source: "):]
        mm = re.match(r"\\newcommand\{\\([A-Za-z]+)\}\{(.*)\}$", line)
        if mm:
            body = mm.group(2)
            if body.startswith(r"\ensuremath{") and body.endswith("}"):
                body = body[len(r"\ensuremath{"):-1]
            out[mm.group(1)] = (body, source)
            source = None
    return out
