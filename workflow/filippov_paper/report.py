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
* ``tab_bench.tex`` -- the work--precision sweep, or "not yet computed";
* ``tab_hard_cases.tex``, ``tab_hard_return.tex`` -- the hard-case eps sweep
  (``results/hard_cases.nc``, :mod:`filippov_paper.hard_cases`), one row per eps.

The scenes declare their own part: each scene module ``filippov_paper.scenes.<id>`` defines
``report(ds, macros)`` (adds its macros, returns its table or None) and, when the
report can do without its data, ``REPORT_OPTIONAL = True`` (then ``ds`` may be
None). There is no list of scenes here. A scene's report part (those names and its
``_report_*`` helpers, :func:`filippov_paper.config.is_report_part`) is left out of the code
hash of the compute jobs and is not in the plotting code: editing it rebuilds the
report tables only.

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


#: the methods as the work-precision table names them (short: the table fits the page)
METHOD_TEX = {"project compiled exact": "compiled, exact flows",
              "project python exact": "Python, exact flows",
              "project compiled DOP853": "compiled DOP853",
              "project DOP853": "Python DOP853",
              "solve_ivp RK45": "scipy RK45",
              "solve_ivp DOP853": "scipy DOP853",
              "solve_ivp Radau": "scipy Radau",
              "solve_ivp LSODA": "scipy LSODA"}


#: around each table of measured times: the widths of their numbers follow the machine's
#: speed and load (a slow run's "12345" ms), so a table is shrunk to the line width where
#: it would overrun it (adjustbox's max width; a table that fits is left as it is)
FIT_BEGIN, FIT_END = r"\begin{adjustbox}{max width=\linewidth}", r"\end{adjustbox}"


def _bench_tabular(ds, probs: list[int]) -> list[str]:
    """One tabular: a row per method and tolerance, error / time / missed switches
    for each problem in ``probs``; a configuration that failed says so in its cells."""
    head = " & ".join(rf"\multicolumn{{3}}{{c}}{{{_problem_tex(str(ds.problem.values[i]))}}}"
                      for i in probs)
    rules = "".join(rf"\cmidrule(lr){{{3 + 3 * k}-{5 + 3 * k}}}" for k in range(len(probs)))
    sub = " & ".join(["error & ms & missed"] * len(probs))
    lines = [FIT_BEGIN, r"\begin{tabular}{@{}ll" + "rrr" * len(probs) + "@{}}", r"\toprule",
             rf"method & rtol & {head} \\", rules, rf" & & {sub} \\", r"\midrule"]
    rows = [j for j in range(ds.sizes["config"])
            if any(str(ds.status.values[i, j]) != "n/a" for i in probs)]
    for j in rows:
        fam = str(ds.method.values[j])
        cells = [METHOD_TEX.get(fam, tex_escape(fam)), f"${num(float(ds.tolerance.values[j]), 2)}$"]
        for i in probs:
            status = str(ds.status.values[i, j])
            if status != "ok":
                cells.append(r"\multicolumn{3}{c}{\emph{" + tex_escape(status.split(":")[0]) + "}}")
                continue
            cells += [f"${num(float(ds.error_map.values[i, j]), 2)}$",
                      f"${num(1e3 * float(ds.wall_time.values[i, j]), 2)}$",
                      str(int(ds.missed_switches.values[i, j]))]
        lines.append(" & ".join(cells) + r" \\")
    return lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""]


def _problem_tex(name: str) -> str:
    """'fig04 theta=-0.5' -> the paper's symbols ('$\theta=-0.5$')."""
    parts = name.split()
    rest = " ".join(parts[1:])
    for key, sym in (("theta", r"\theta"), ("eps", r"\epsilon")):
        rest = re.sub(rf"{key}=(\S+)", lambda mm: f"${sym}={mm.group(1)}$", rest)
    return rest


def _bench_timing(ds, m: Macros) -> None:
    """How the sweep's times were measured (filippov_paper.benchmarks.timing): the statistic
    shown, the warm-up runs, the least rounds and seconds asked for, and the rounds the
    shown cells took. A sweep measured before the convention (no ``timing_statistic``)
    sets ``rpHaveBenchTiming`` false and quotes nothing."""
    have = "timing_statistic" in ds.attrs and "runs" in ds
    m.flag("rpHaveBenchTiming", have)
    if not have:
        return
    sid = "work_precision"
    stat = str(ds.attrs["timing_statistic"])
    m.add("rpBenchStatistic", None, f"{sid}:attrs.timing_statistic",
          text=r"\text{" + tex_escape(stat) + "}")
    for name, attr, sig in (("rpBenchWarmup", "timing_warmup", 4),
                            ("rpBenchMinRounds", "timing_min_rounds", 4),
                            ("rpBenchMinTime", "timing_min_time", 3)):
        m.add(name, float(ds.attrs[attr]), f"{sid}:attrs.{attr}", sig)
    # the counts as the prose says them ("one untimed run", "3 to 250 runs")
    m.add("rpBenchWarmupRuns", None, f"{sid}:attrs.timing_warmup",
          text=count_phrase(ds.attrs["timing_warmup"], "untimed run"))
    m.add("rpBenchMinRoundsRuns", None, f"{sid}:attrs.timing_min_rounds",
          text=count_phrase(ds.attrs["timing_min_rounds"], "timed run"))
    timed = np.asarray(ds.runs.values)[np.asarray(ds.status.values).astype(str) == "ok"]
    m.add("rpBenchRoundsLeast", float(timed.min()) if timed.size else math.nan,
          "derived: min of work_precision:runs over the configurations that ran", 4)
    m.add("rpBenchRoundsMost", float(timed.max()) if timed.size else math.nan,
          "derived: max of work_precision:runs over the configurations that ran", 4)
    m.add("rpBenchRoundsRange", None,
          "derived: min to max of work_precision:runs over the configurations that ran",
          text=range_phrase(timed.min(), timed.max(), "run") if timed.size else "no runs")


def failed_sentence(n: int) -> str:
    """The sentence of the work-precision text on the configurations that failed."""
    if n == 0:
        return "No configuration failed outright on any map."
    return (count_phrase(n, "configuration", capital=True)
            + r" failed outright over all maps (cells marked \emph{failed}; the dataset's "
            r"\texttt{status} says why).")


def bench(ds, m: Macros, effects=None, returns=None, compile_cost=None) -> str:
    """The work-precision tables of the default build's sweep (results/work_precision.nc):
    per problem set (fig04, fig11), one row per method and tolerance, error / time /
    missed switches per problem; the speed-up at the target error and what the
    scipy solvers a user reaches for first get wrong; the cost of each model
    ingredient when results/bench_effect_cost.nc is there and the cost of one iterated
    return when results/bench_attractor_cost.nc is (`make bench`); the compile and load
    times of the compiled engine (macros only) when results/bench_compile_cost.nc is."""
    _compile_cost_macros(m, compile_cost)
    missing = absent(m, "rpHaveBench", ds, "Work--precision sweep", "results/work_precision.nc")
    m.flag("rpHaveBenchTiming", False)  # set by _bench_timing when the sweep says how it timed
    # the blocks of `make bench` (set below when measured): defined for every build, as
    # the table's caption asks for them
    m.flag("rpHaveEffects", False)
    m.flag("rpHaveReturnCost", False)
    if missing:
        return missing
    if "method" not in ds.coords or "problem" not in ds.dims:
        return table_frame(ds)
    names = [str(p) for p in ds.problem.values]
    lines = []
    for prefix in ("fig04", "fig11"):
        probs = [i for i, p in enumerate(names) if p.startswith(prefix)]
        if probs:
            lines += ([r"\medskip", ""] if lines else []) + _bench_tabular(ds, probs)
    _bench_problem_macros(ds, m, names)
    _bench_timing(ds, m)
    m.flag("rpHaveEffects", effects is not None)
    if effects is not None:
        lines += _effects_tabular(effects)
    m.flag("rpHaveReturnCost", returns is not None)
    if returns is not None:
        lines += _return_cost_tabular(returns)
    return "\n".join(lines)


def _compile_cost_macros(m: Macros, compile_cost) -> None:
    """The compiled engine's cold and warm compile/load times of the quoted stages."""
    quoted = (("kernel", "Kernel"), ("kernel_dpdz", "KernelDpdz"), ("model", "Model"))
    if compile_cost is not None and not {s for s, _ in quoted} <= set(compile_cost.stage.values):
        compile_cost = None  # measured by an older benchmark: measured again by make bench
    m.flag("rpHaveCompileCost", compile_cost is not None)
    if compile_cost is not None:
        for stage, tag in quoted:
            for kind in ("cold", "warm"):
                var(m, f"rpCompile{tag}{kind.title()}", compile_cost, "bench_compile_cost",
                    kind, sig=2, stage=stage)


def _bench_problem_macros(ds, m: Macros, names) -> None:
    """Per problem (the first four: A-D) the speed-up, the reference floor, the points,
    and what solve_ivp's RK45 and DOP853 miss; then the failed configurations."""
    sid = "work_precision"
    fam = np.array([str(f) for f in ds.method.values])
    for i, p in enumerate(names[:4]):
        key = "ABCD"[i]
        m.add(f"rpBenchSpeedup{key}", float(ds.speedup_vs_rk45.values[i]),
              source(sid, f"speedup_vs_rk45[{i}]"), 2)
        m.add(f"rpBenchFloor{key}", float(ds.reference_check.values[i]),
              source(sid, f"reference_check[{i}]"), 2)
        m.add(f"rpBenchPoints{key}", float(ds.n_points.values[i]),
              source(sid, f"n_points[{i}]"), 4)
        ok = ds.status.values[i] == "ok"
        for tag, family in (("RK", "solve_ivp RK45"), ("DOP", "solve_ivp DOP853")):
            sel = (fam == family) & ok
            m.add(f"rpBenchMissed{tag}{key}",
                  float(ds.missed_switches.values[i, sel].max()) if sel.any() else 0.0,
                  f"derived: max of work_precision:missed_switches[{i}] over {family}", 4)
            m.add(f"rpBenchBest{tag}{key}",
                  float(np.nanmin(ds.error_map.values[i, sel])) if sel.any() else math.nan,
                  f"derived: min of work_precision:error_map[{i}] over {family}", 2)
    failed = int(np.count_nonzero(np.char.startswith(ds.status.values.astype(str), "failed")))
    m.add("rpBenchFailed", float(failed),
          "derived: configurations of work_precision:status that failed", 4)
    m.add("rpBenchFailedSentence", None,
          "derived: configurations of work_precision:status that failed",
          text=failed_sentence(failed))
    m.add("rpBenchConfigs", float(ds.sizes["config"]), "work_precision:config (size)", 4)


def _effects_tabular(effects) -> list[str]:
    """The cost of each model ingredient (results/bench_effect_cost.nc)."""
    lines = [r"\medskip", "", FIT_BEGIN, r"\begin{tabular}{llrrl}", r"\toprule",
             r"scene & ingredient switched & time [s] & $\times$ declared & outcome \\",
             r"\midrule"]
    for k in range(effects.sizes["variant"]):
        status = str(effects.status.values[k])
        outcome = "ok" if status == "ok" else status.split(":")[0]
        lines.append(" & ".join([
            r"\texttt{" + tex_escape(str(effects.scene.values[k])) + "}",
            tex_escape(str(effects.change.values[k])).replace("->", r"$\to$"),
            f"${num(float(effects.seconds.values[k]), 3)}$",
            f"${num(float(effects.relative.values[k]), 3)}$",
            r"\emph{" + tex_escape(outcome) + "}"]) + r" \\")
    return lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""]


def _return_cost_tabular(returns) -> list[str]:
    """The cost of one iterated return (results/bench_attractor_cost.nc)."""
    lines = [r"\medskip", "", FIT_BEGIN, r"\begin{tabular}{rrrrrr}", r"\toprule",
             r"$\theta$ & $\epsilon$ & $s$ & $\mu$s/return & with $DP$ & "
             r"switches/return \\", r"\midrule"]
    for k in range(returns.sizes["case"]):
        lines.append(" & ".join([
            f"${num(float(returns.theta.values[k]), 2)}$",
            f"${num(float(returns.eps.values[k]), 1)}$",
            f"${num(float(returns.s.values[k]), 2)}$",
            f"${num(1e6 * float(returns.time_per_return.values[k]), 3)}$",
            f"${num(1e6 * float(returns.time_per_return_jacobian.values[k]), 3)}$",
            f"${num(float(returns.switches_per_return.values[k]), 3)}$"]) + r" \\")
    return lines + [r"\bottomrule", r"\end{tabular}", FIT_END, ""]


def hard_cases(ds, m: Macros) -> str:
    """Macros and the per-eps table of the hard-case sweep (results/hard_cases.nc):
    jump/eps (theta < 0), one-sided slope (theta > 0), chatter period, slide-in."""
    m.flag("rpHaveHardCases", ds is not None)
    if ds is None:
        return (not_yet("Hard-case eps sweep", "results/hard_cases.nc"),
                not_yet("Sliding return sweep", "results/hard_cases.nc"))
    sid = "hard_cases"
    eps = [float(e) for e in ds.eps.values]
    kmax, kmin = int(np.argmax(eps)), int(np.argmin(eps))
    m.add("rpHardN", len(eps), f"{sid}:eps (size)")
    m.add("rpHardNValues", None, f"{sid}:eps (size)", text=count_phrase(len(eps), "value"))
    m.add("rpHardEpsMax", eps[kmax], f"{sid}:eps[{kmax}]")
    m.add("rpHardEpsMin", eps[kmin], f"{sid}:eps[{kmin}]")
    for attr, name, sig in (("jump_theta", "JumpTheta", 3), ("jump_x2_offset", "JumpOffset", 3),
                            ("slope_theta", "SlopeTheta", 3), ("slope_probe_factor", "ProbeFactor", 3),
                            ("slope_probe_floor", "ProbeFloor", 3),
                            ("chatter_theta", "ChatterTheta", 3),
                            ("chatter_periods", "ChatterPeriods", 4),
                            ("slide_theta", "SlideTheta", 3),
                            ("slide_start_over_eps", "SlideStart", 3),
                            ("kernel_start", "KernelStart", 3)):
        m.add(f"rpHard{name}", float(ds.attrs[attr]), f"{sid}:attrs.{attr}", sig)
    var(m, "rpHardJumpFirst", ds, sid, "jump_over_eps", sig=5, eps=eps[kmax])
    var(m, "rpHardJumpLast", ds, sid, "jump_over_eps", sig=5, eps=eps[kmin])
    from filippov.analytic.s0 import s0_lambert
    mu, omega = float(ds.attrs["mu"]), float(ds.attrs["omega"])
    pred = float(s0_lambert(np.array([float(ds.attrs["jump_theta"])]))[0]) \
        * math.exp(-3 * math.pi * mu / omega)
    m.add("rpHardJumpPred", pred, "derived: s0(jump_theta) exp(-3 pi mu/omega)", 5)
    if len(eps) > 1:
        m.add("rpHardJumpDiffLast", abs(value(ds, "jump_over_eps", eps=eps[kmin])
                                        - value(ds, "jump_over_eps", eps=sorted(eps)[1])),
              "derived: |difference of jump_over_eps| between the two smallest eps", 2)
    m.add("rpHardSlopeMin", float(ds.slope.min()), "derived: min slope over eps", 3)
    m.add("rpHardSlopeMax", float(ds.slope.max()), "derived: max slope over eps", 3)
    var(m, "rpHardPeriodOverEps", ds, sid, "chatter_period_over_eps", sig=6, eps=eps[kmin])
    m.add("rpHardPeriodDev", float(ds.chatter_period_max_rel_dev.max()),
          "derived: max chatter_period_max_rel_dev over eps", 2)
    m.add("rpHardSlideOffset", float(np.abs(ds.slide_start_offset).max()),
          "derived: max |slide_start_offset| over eps", 2)
    m.add("rpHardSlideFinal", float(ds.slide_final_abs_x.max()),
          "derived: max slide_final_abs_x over eps", 2)
    m.add("rpHardKernelFinal", float(ds.kernel_final_abs_x.max()),
          "derived: max kernel_final_abs_x over eps", 2)
    maps = per_eps_rows(ds, lambda d: [
        f"${num(float(d.jump_over_eps), 6)}$", f"${num(float(d.slope), 4)}$",
        f"${num(float(d.slope_probe), 2)}$"])
    chatter = per_eps_rows(ds, lambda d: [
        f"${num(float(d.chatter_period_over_eps), 6)}$",
        f"${num(float(d.chatter_period_max_rel_dev), 2)}$",
        f"${num(float(d.slide_start_offset), 2)}$", f"${num(float(d.slide_final_abs_x), 2)}$",
        f"${num(float(d.kernel_final_abs_x), 2)}$"])
    # the return maps, then the pseudo-equilibrium (two tabulars: one would not fit)
    table = tabular("rrrr", [head(r"$\epsilon$", r"jump$/\epsilon$", "slope", "$x_2-1$")],
                     maps) + "\n\\medskip\n\n" + tabular("rrrrrr", [head(
                         r"$\epsilon$", r"period//$/\epsilon$", "period//dev.",
                         r"slide start//$+(1-\theta)\epsilon$", "final//$|x|$",
                         "final $|x|$,//kernel")], chatter)
    return table, _hard_return(ds, m, eps)


def _hard_return(ds, m: Macros, eps: list) -> str:
    """The theta > 0 sliding return per eps: 1 - P against eps^2, sliding time, cost."""
    sid = "hard_cases"
    m.add("rpHardReturnTheta", float(ds.attrs["return_theta"]), f"{sid}:attrs.return_theta", 3)
    m.add("rpHardReturnXtwo", float(ds.attrs["return_x2"]), f"{sid}:attrs.return_x2", 3)
    gap = np.abs(ds.return_P_reduced.values - ds.return_P.values)
    scaled = gap / ds.eps.values ** 2
    small = [k for k, e in enumerate(eps) if e <= 1e-3] or list(range(len(eps)))
    m.add("rpHardReturnScaledMin", float(scaled[small].min()),
          "derived: min |P_reduced - P|/eps^2 over eps <= 1e-3", 3)
    m.add("rpHardReturnScaledMax", float(scaled[small].max()),
          "derived: max |P_reduced - P|/eps^2 over eps <= 1e-3", 3)
    steps = ds.return_steps.values
    m.add("rpHardReturnStepsMin", int(steps.min()), "derived: min return_steps over eps")
    m.add("rpHardReturnStepsMax", int(steps.max()), "derived: max return_steps over eps")
    m.add("rpHardReturnStiffN", int(ds.return_stiff.values.sum()),
          "derived: eps values whose sliding was finished by Radau IIA")
    m.add("rpHardReturnStiffShare", None,
          "derived: eps values whose sliding was finished by Radau IIA, of all",
          text=share_phrase(ds.return_stiff.values.sum(), len(eps), r"$\epsilon$ value"))
    rows = per_eps_rows(ds.assign(gap=("eps", gap), scaled=("eps", scaled)), lambda d: [
        f"${num(float(d.gap), 3)}$", f"${num(float(d.scaled), 4)}$",
        f"${num(float(d.return_sliding_time), 5)}$", f"${int(d.return_steps)}$",
        "Radau IIA" if int(d.return_stiff) else "DOP853"])
    return tabular("rrrrrl", [
        r"$\epsilon$ & $|P_0-P|$ & $|P_0-P|/\epsilon^2$ & sliding time & steps & "
        r"sliding by \\"], rows)


# ----------------------------------------------------------------------------- entry point
def _scene_modules() -> list:
    """(id, report part) of every scene, in id order (the order of the macros)."""
    import importlib

    from filippov_paper.scenes import known_scenes

    return [(sid, importlib.import_module(f".scenes.{sid}", __package__))
            for sid in known_scenes()]


def generate(datasets: Mapping[str, Optional[xr.Dataset]]) -> dict[str, str]:
    """All generated LaTeX files, keyed by file name. The datasets of scenes that do
    not declare ``REPORT_OPTIONAL`` are required."""
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
    tab_bench = bench(datasets.get("work_precision"), m, datasets.get("bench_effect_cost"),
                      datasets.get("bench_attractor_cost"), datasets.get("bench_compile_cost"))
    try:
        tab_hard, tab_return = hard_cases(datasets.get("hard_cases"), m)
    except KeyError as exc:
        raise KeyError(f"hard_cases: the report reads {exc} but the dataset lacks it") from None
    return {"macros.tex": m.tex(), **texts, "tab_bench.tex": tab_bench,
            "tab_hard_cases.tex": tab_hard, "tab_hard_return.tex": tab_return}


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
