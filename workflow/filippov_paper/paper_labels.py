"""The original paper's equation, figure, section and lemma numbers, as printed.

The report cites Sieber & Kowalczyk (Physica D 2010) by the numbers a reader
sees in the paper ("Eq. (B.18)", "Fig. 4", "Appendix C", "Lemma 2"), not by the
paper's LaTeX labels. Typing those numbers by hand goes stale silently, so they
are derived: the paper's LaTeX source is compiled with its own class (elsart,
which numbers appendix equations and figures A.1, B.2, ...) and the numbers are
read from the .aux file; the kind of each label (equation, figure, lemma,
section ...) comes from the environment around the ``\\label`` in the source.

``python -m filippov_paper.paper_labels SOURCE [--cls-dir DIR]`` writes
``paper/paper_labels.tex``; ``--check`` re-derives it and fails when the
committed file differs. In LaTeX, ``\\pref{eq:xi14}`` prints "Eq.~(B.18)" and
``\\pnum{eq:xi14}`` only "B.18"; an unknown label is a LaTeX error.
"""
from __future__ import annotations

import argparse
import difflib
import hashlib
import os
import re
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
OUT = ROOT / "paper" / "paper_labels.tex"
CLS_URL = ("elsart.cls (Elsevier, LPPL; not in TeX Live any more), e.g. from the "
           "GitHub repository MIT-LCP/mimic-code-paper, file elsart.cls")

# replaces every \includegraphics: the paper's figures are empty file names
NO_GRAPHICS = r"\AtBeginDocument{\renewcommand{\includegraphics}[2][]{\fbox{graphic}}}"

# environments whose rows/bodies carry equation numbers; the multi-row ones number
# every row that has no \nonumber / \notag
EQ_SINGLE = {"equation", "multline"}
EQ_MULTI = {"align", "eqnarray", "gather", "flalign", "alignat", "xalignat"}
EQ_UNNUMBERED = {"displaymath", "math"}
EQ_ALL = EQ_SINGLE | EQ_MULTI | EQ_UNNUMBERED
FLOATS = {"figure": "Fig.", "subfigure": "Fig.", "table": "Table", "subtable": "Table"}
# environments that do not step a counter: a \label inside refers to the enclosing one
TRANSPARENT = {
    "center", "flushleft", "flushright", "minipage", "cases", "split", "aligned",
    "alignedat", "gathered", "array", "matrix", "pmatrix", "bmatrix", "Bmatrix",
    "vmatrix", "Vmatrix", "smallmatrix", "itemize", "description", "quote",
    "quotation", "small", "footnotesize", "tabular",
}
SECTIONS = {"part", "chapter", "section", "subsection", "subsubsection", "paragraph",
            "subparagraph"}
PAREN_KINDS = {"Eq.", "Item"}   # printed with their number in parentheses

_CS = re.compile(r"\\(?:([A-Za-z@]+)[ \t]*(\*?)|(.))", re.S)
_NEWTHEOREM = re.compile(
    r"\\newtheorem(\*?)\s*\{([^{}]+)\}\s*(?:\[[^\]]*\]\s*)?\{([^{}]+)\}")


# ----------------------------------------------------------------------------- scanning
def strip_comments(text: str) -> str:
    """The text without TeX comments; line breaks stay, so positions keep their line."""
    out = []
    for line in text.splitlines(keepends=True):
        i, n = 0, len(line)
        while i < n:
            if line[i] == "\\":
                i += 2
                continue
            if line[i] == "%":
                line = line[:i] + ("\n" if line.endswith("\n") else "")
                break
            i += 1
        out.append(line)
    return "".join(out)


def _group(text: str, i: int, open_: str = "{", close: str = "}") -> tuple[str, int] | None:
    """The balanced group starting at text[i] (after blanks) and the index after it.
    For [...] only brackets outside braces count."""
    while i < len(text) and text[i] in " \t\n":
        i += 1
    if i >= len(text) or text[i] != open_:
        return None
    depth, brace, j = 0, 0, i
    while j < len(text):
        c = text[j]
        if c == "\\":
            j += 2
            continue
        if open_ != "{" and c in "{}":
            brace += 1 if c == "{" else -1
        elif brace == 0 and c == open_:
            depth += 1
        elif brace == 0 and c == close:
            depth -= 1
            if depth == 0:
                return text[i + 1:j], j + 1
        j += 1
    raise ValueError(f"unbalanced {open_}{close} group at offset {i}")


@dataclass
class _Env:
    name: str
    line: int
    captioned: bool = False          # floats: a \caption came before
    itemed: bool = False             # enumerate: an \item came before
    row: list = field(default_factory=list)   # equations: labels of the current row
    nonumber: bool = False
    tag: bool = False

    @property
    def base(self) -> str:
        return self.name.rstrip("*")

    @property
    def starred(self) -> bool:
        return self.name.endswith("*")


def theorem_names(source_text: str) -> dict[str, str | None]:
    """Theorem-like environments declared with \\newtheorem: name -> printed title
    (None for \\newtheorem*, which is unnumbered)."""
    text = strip_comments(source_text)
    return {m[2].strip(): (None if m[1] else m[3].strip()) for m in _NEWTHEOREM.finditer(text)}


def kinds(source_text: str) -> dict[str, str]:
    """label -> the kind word it is cited with ("Eq.", "Fig.", "Sec.", "Appendix",
    "Lemma", "Item" ...), from the environment open at each \\label; a sectioning
    label after \\appendix is "Appendix" at every level, as the paper cites them.

    A label whose printed number would not be what its place suggests (in a
    \\nonumber row, an unnumbered display, a figure before its caption, after a
    \\section*, in an unknown environment) or that is defined twice raises
    ValueError naming it: the numbers are only trusted where the kind is certain.
    """
    return _LabelScan(source_text).run()



class _LabelScan:
    """One pass over the source's control sequences from \\begin{document}: the open
    environments, the current sectioning command and every \\label's kind (or the
    reason it has none)."""

    def __init__(self, source_text: str):
        self.theorems = theorem_names(source_text)
        self.text = strip_comments(source_text)
        self.has_chapters = re.search(r"\\chapter\b", self.text) is not None
        self.result: dict[str, str] = {}
        self.errors: list[str] = []
        self.seen: dict[str, int] = {}
        self.stack: list[_Env] = []
        self.section: tuple[str, bool, bool] | None = None  # (command, starred, in appendix)
        self.appendix = False
        self.subfig_end = -1        # inside \subfigure[...]{...} up to here

    def run(self) -> dict[str, str]:
        start = self.text.find(r"\begin{document}")
        pos = 0 if start < 0 else start
        while (m := _CS.search(self.text, pos)) is not None:
            pos = self._command(m)
            if pos is None:       # \end{document}: what follows is not printed
                break
        if self.errors:
            raise ValueError("paper labels whose printed kind cannot be decided: "
                             + "; ".join(self.errors))
        return self.result

    # -- helpers
    def _line_of(self, pos: int) -> int:
        return self.text.count("\n", 0, pos) + 1

    def _nearest(self, names) -> _Env | None:
        return next((e for e in reversed(self.stack) if e.base in names), None)

    # -- one control sequence: the position to scan on from, None at \end{document}
    def _command(self, m: re.Match) -> int | None:
        pos = m.end()
        word, star, symbol = m[1], m[2], m[3]
        if symbol is not None:
            self._symbol(symbol, m.start())
        elif word in ("begin", "end"):
            return self._begin_end(word, m)
        elif word == "label":
            return self._label(m)
        elif word in ("subfigure", "subfloat"):
            self._subfigure(pos)
        else:
            self._marker(word, star)
        return pos

    def _symbol(self, symbol: str, at: int) -> None:
        """\\\\ ends a row of a multi-row display; \\[ ... \\] is an unnumbered display."""
        if symbol == "\\" and self.stack and self.stack[-1].base in EQ_MULTI:
            self._close_row(self.stack[-1])
        elif symbol == "[":
            self.stack.append(_Env("displaymath", self._line_of(at)))
        elif symbol == "]" and self.stack and self.stack[-1].name == "displaymath":
            self._close_row(self.stack.pop())

    def _begin_end(self, word: str, m: re.Match) -> int | None:
        g = _group(self.text, m.end())
        if g is None:
            return m.end()
        name, pos = g[0].strip(), g[1]
        if word == "begin":
            self.stack.append(_Env(name, self._line_of(m.start())))
            return pos
        if not self.stack or self.stack[-1].name != name:
            top = self.stack[-1] if self.stack else None
            open_ = f"\\begin{{{top.name}}} of line {top.line}" if top else "nothing"
            raise ValueError(f"cannot follow the environments: \\end{{{name}}} on line "
                             f"{self._line_of(m.start())} closes {open_}")
        env = self.stack.pop()
        if env.base in EQ_ALL:
            self._close_row(env)
        return None if name == "document" else pos

    def _label(self, m: re.Match) -> int:
        g = _group(self.text, m.end())
        if g is None:
            return m.end()
        self._decide(g[0].strip(), m.start())
        return g[1]

    def _subfigure(self, pos: int) -> None:
        """A \\subfigure[...]{...} panel: labels up to its closing brace are figures."""
        j = pos
        while (g := _group(self.text, j, "[", "]")) is not None:
            j = g[1]
        g = _group(self.text, j)
        self.subfig_end = max(self.subfig_end, g[1] if g else j)

    def _marker(self, word: str, star: str) -> None:
        """Commands that change how a later \\label is counted."""
        if word in SECTIONS:
            self.section = (word, bool(star), self.appendix)
        elif word == "appendix":
            self.appendix = True
        elif word == "caption":
            env = self._nearest(FLOATS)
            if env is not None:
                env.captioned = True
        elif word == "item":
            if self.stack and self.stack[-1].base == "enumerate":
                self.stack[-1].itemed = True
        elif word in ("nonumber", "notag", "tag"):
            env = self._nearest(EQ_ALL)
            if env is not None:
                setattr(env, "tag" if word == "tag" else "nonumber", True)

    # -- deciding a label's kind
    def _close_row(self, env: _Env) -> None:
        """The labels of a finished display row: numbered unless the row or the
        display is unnumbered (a \\tag numbers it anyway)."""
        for label, line in env.row:
            if env.starred or env.base in EQ_UNNUMBERED:
                if env.tag:
                    self.result[label] = "Eq."
                else:
                    self.errors.append(f"{label} (line {line}): in the unnumbered {env.name}")
            elif env.nonumber and not env.tag:
                self.errors.append(f"{label} (line {line}): in a \\nonumber row of {env.name}")
            else:
                self.result[label] = "Eq."
        env.row, env.nonumber, env.tag = [], False, False

    def _decide(self, label: str, pos: int) -> None:
        line = self._line_of(pos)
        if label in self.seen:
            self.errors.append(f"{label} (line {line}): defined twice "
                               f"(also line {self.seen[label]})")
            return
        self.seen[label] = line
        if pos < self.subfig_end:
            self.result[label] = "Fig."
            return
        env = self._counting_env()
        if env is None:
            self._in_section(label, line)
        else:
            self._in_env(env, label, line)

    def _counting_env(self) -> _Env | None:
        """The innermost environment that steps a counter; None in the document's body."""
        for env in reversed(self.stack):
            if env.base in TRANSPARENT:
                continue
            return None if env.base == "document" else env
        return None

    def _in_env(self, env: _Env, label: str, line: int) -> None:
        b = env.base
        if b in EQ_ALL:
            env.row.append((label, line))   # decided when the row closes
        elif b in FLOATS:
            if env.captioned:
                self.result[label] = FLOATS[b]
            else:
                self.errors.append(f"{label} (line {line}): in {env.name} before its \\caption")
        elif b == "enumerate":
            if env.itemed:
                self.result[label] = "Item"
            else:
                self.errors.append(f"{label} (line {line}): in enumerate before its first \\item")
        elif b in self.theorems:
            if self.theorems[b] is None:
                self.errors.append(f"{label} (line {line}): in the unnumbered {b}")
            else:
                self.result[label] = self.theorems[b]
        else:
            self.errors.append(f"{label} (line {line}): in environment {env.name}, "
                               "kind unknown")

    def _in_section(self, label: str, line: int) -> None:
        if self.section is None:
            self.errors.append(f"{label} (line {line}): no sectioning command before it")
            return
        command, starred, in_appendix = self.section
        if starred:
            self.errors.append(f"{label} (line {line}): after the unnumbered \\{command}*")
        # after \appendix every sectioning label is cited "Appendix B.1", as the
        # paper itself does (Elsevier style), not "Sec. B.1"
        elif in_appendix and (not self.has_chapters or command == "chapter"):
            self.result[label] = "Appendix"
        elif command == "chapter":
            self.result[label] = "Chapter"
        elif command == "part":
            self.result[label] = "Part"
        else:
            self.result[label] = "Sec."


# ----------------------------------------------------------------------------- compiling
def read_aux(aux_text: str) -> dict[str, str]:
    """label -> printed number from the \\newlabel lines of a .aux file (braces nested)."""
    numbers = {}
    for m in re.finditer(r"\\newlabel\s*\{", aux_text):
        key = _group(aux_text, m.end() - 1)
        value = key and _group(aux_text, key[1])
        number = value and _group(value[0], 0)
        if number:
            numbers[key[0]] = number[0].strip()
    return numbers


def _find_class(source_text: str, cls_dir: Path | None) -> str:
    """The document class's name; raises when pdflatex would not find its .cls."""
    m = re.search(r"\\documentclass\s*(?:\[[^\]]*\])?\s*\{([^{}]+)\}", strip_comments(source_text))
    if m is None:
        raise ValueError("the source has no \\documentclass")
    cls = m[1].strip()
    if cls_dir is not None:
        if not (Path(cls_dir) / f"{cls}.cls").is_file():
            raise FileNotFoundError(f"{cls}.cls is not in {cls_dir}"
                                    + (f"; get {CLS_URL}" if cls == "elsart" else ""))
        return cls
    if shutil.which("kpsewhich") is None or not subprocess.run(
            ["kpsewhich", f"{cls}.cls"], capture_output=True, text=True).stdout.strip():
        raise FileNotFoundError(
            f"{cls}.cls not found by kpsewhich; pass --cls-dir DIR (or set TEXINPUTS)"
            + (f"; get {CLS_URL}" if cls == "elsart" else ""))
    return cls


def compile_aux(source: Path, cls_dir: Path | None = None) -> str:
    """The .aux text of the source compiled twice with pdflatex, graphics replaced by
    boxes (the paper's figure files are absent)."""
    text = source.read_text(encoding="utf-8")
    _find_class(text, cls_dir)
    if shutil.which("pdflatex") is None:
        raise FileNotFoundError("pdflatex not found (install TeX Live)")
    m = re.search(r"\\documentclass[^\n]*\n", text)
    text = text[:m.end()] + NO_GRAPHICS + "\n" + text[m.end():]
    env = dict(os.environ)
    if cls_dir is not None:
        env["TEXINPUTS"] = f"{Path(cls_dir).resolve()}{os.pathsep}{env.get('TEXINPUTS', '')}"
    with tempfile.TemporaryDirectory(prefix="paper-labels-") as tmp:
        (Path(tmp) / "paper.tex").write_text(text, encoding="utf-8")
        for _ in range(2):
            run = subprocess.run(["pdflatex", "-interaction=batchmode", "-no-shell-escape",
                                  "paper.tex"], cwd=tmp, env=env, capture_output=True,
                                 text=True, timeout=600)
        aux = Path(tmp) / "paper.aux"
        if run.returncode != 0 or not aux.is_file():
            log = Path(tmp) / "paper.log"
            errors = [ln for ln in (log.read_text(errors="replace").splitlines()
                                    if log.is_file() else []) if ln.startswith("!")]
            raise RuntimeError(f"pdflatex failed on {source} (exit {run.returncode}): "
                               + ("; ".join(errors[:5]) or run.stdout[-2000:]))
        return aux.read_text(encoding="utf-8", errors="replace")


def text_of(kind: str, number: str) -> str:
    """How the paper's number is cited: "Eq.~(14)", "Fig.~B.1", "Appendix~C"."""
    return f"{kind}~({number})" if kind in PAREN_KINDS else f"{kind}~{number}"


def number_of(text: str) -> str:
    """The bare number of a cited text: "Eq.~(B.18)" -> "B.18", "Fig.~4" -> "4"."""
    kind, _, number = text.partition("~")
    if kind in PAREN_KINDS and number.startswith("(") and number.endswith(")"):
        return number[1:-1]
    return number


def derive(source: Path, cls_dir: Path | None = None) -> dict[str, str]:
    """{label: printed reference text} for every \\label of the paper's source."""
    source = Path(source)
    label_kinds = kinds(source.read_text(encoding="utf-8"))
    numbers = read_aux(compile_aux(source, cls_dir))
    missing = sorted(set(label_kinds) - set(numbers))
    if missing:
        raise ValueError(f"labels of the source missing from the .aux: {', '.join(missing)}")
    odd = [k for k in label_kinds if "\\" in numbers[k] or not numbers[k]]
    if odd:
        raise ValueError("labels with a number that is not plain text: "
                         + ", ".join(f"{k}={numbers[k]!r}" for k in odd))
    return {k: text_of(label_kinds[k], numbers[k]) for k in sorted(label_kinds)}


# ----------------------------------------------------------------------------- the .tex file
PREAMBLE = r"""\edef\pnumrestoreat{\catcode64=\the\catcode64\relax}\catcode64=11
\providecommand{\pnumdef}[2]{\expandafter\def\csname pnum@#1\endcsname{#2}}
\providecommand{\pnumnumdef}[2]{\expandafter\def\csname pnumn@#1\endcsname{#2}}
\providecommand{\pnum@get}[2]{\@ifundefined{#1@#2}{\PackageError{paper_labels}%
  {paper label `#2' undefined}{paper/paper_labels.tex has no label `#2'. Cite a
  label of the paper's source, or regenerate the file with
  python -m filippov_paper.paper_labels.}\textbf{??}}{\csname #1@#2\endcsname}}
% \pref{eq:xi14} -> Eq.~(B.18);  \pnum{eq:xi14} -> B.18
\DeclareRobustCommand{\pref}[1]{\pnum@get{pnum}{#1}}
\DeclareRobustCommand{\pnum}[1]{\pnum@get{pnumn}{#1}}
\pnumrestoreat
"""


def to_tex(mapping: dict[str, str], source_name: str, sha256: str) -> str:
    """The generated LaTeX file: a header saying where it comes from, the commands,
    then one line per label (sorted) with the cited text and the bare number."""
    lines = [
        "% paper_labels.tex -- GENERATED by `python -m filippov_paper.paper_labels`; do not edit by hand.",
        f"% Source: {source_name} (sha256 {sha256}),",
        "% compiled with pdflatex and its document class; numbers from its .aux,",
        "% kinds from the environment around each \\label.",
        "% Check: python -m filippov_paper.paper_labels SOURCE --cls-dir DIR --check",
        PREAMBLE.rstrip("\n"),
    ]
    for label in sorted(mapping):
        text = mapping[label]
        lines.append(f"\\pnumdef{{{label}}}{{{text}}}\\pnumnumdef{{{label}}}{{{number_of(text)}}}")
    return "\n".join(lines) + "\n"


def read_tex(text: str) -> dict[str, str]:
    """{label: cited text} of a generated file (its \\pnumdef lines); the bare numbers
    (\\pnumnumdef) must agree with the texts."""
    mapping = {}
    for m in re.finditer(r"^\\pnumdef(?=\{)", text, re.M):
        label = _group(text, m.end())
        value = _group(text, label[1])
        mapping[label[0]] = value[0]
        num = re.match(r"\\pnumnumdef(?=\{)", text[value[1]:])
        if num:
            nlabel = _group(text, value[1] + num.end())
            nvalue = _group(text, nlabel[1])
            if nlabel[0] != label[0] or nvalue[0] != number_of(value[0]):
                raise ValueError(f"paper_labels: number of {label[0]} disagrees with its text")
    return mapping


def main(argv: list[str] | None = None) -> int:
    """Write (or with --check compare) paper/paper_labels.tex."""
    ap = argparse.ArgumentParser(prog="python -m filippov_paper.paper_labels",
                                 description=__doc__.splitlines()[0])
    ap.add_argument("source", type=Path, help="the paper's LaTeX source")
    ap.add_argument("--cls-dir", type=Path, default=None,
                    help="directory with the document class (elsart.cls)")
    ap.add_argument("--out", type=Path, default=OUT, help=f"default {OUT}")
    ap.add_argument("--check", action="store_true",
                    help="re-derive; exit 1 and print the differences if --out differs")
    args = ap.parse_args(argv)
    sha = hashlib.sha256(args.source.read_bytes()).hexdigest()
    try:
        new = to_tex(derive(args.source, args.cls_dir), args.source.name, sha)
    except (FileNotFoundError, ValueError, RuntimeError) as err:
        print(f"paper_labels: {err}", file=sys.stderr)
        return 2
    if args.check:
        old = args.out.read_text(encoding="utf-8") if args.out.is_file() else ""
        if old == new:
            print(f"{args.out}: up to date")
            return 0
        sys.stdout.writelines(difflib.unified_diff(
            old.splitlines(keepends=True), new.splitlines(keepends=True),
            f"{args.out} (committed)", f"{args.out} (derived)"))
        return 1
    args.out.write_text(new, encoding="utf-8")
    print(f"{args.out}: {len(new.splitlines())} lines, labels from {args.source.name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
