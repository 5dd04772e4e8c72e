"""The claims of the report's section on the small-scale instabilities (issue 60), each
checked against the data it is generated from.

Each claim has a checker that reads the sentence as the report prints it (the section's
text with the generated macros put in) and recomputes what it says from the dataset's
stored variables, independently of the scene's report code: where the chaos ends for
each theta (fig13), where theta = 1/2 has period one (fig13), which windows of the
cascade overlap and by how much for each eps (fig12). The checkers run on the built
datasets (``workflow_build``) and on small datasets with the patterns of the build,
where the text the report printed before is refused. Recomputations from the model
check the grid points the sentences turn on, and the Lyapunov exponent's standard
error is checked for coverage on independent segments of one chaotic orbit.
"""
from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

from filippov import attractors
from filippov.analytic import limit_map
from filippov.models import hopf
from filippov_paper import report
from filippov_paper.report import eps_tex, num, parse_num
from filippov_paper.scenes import fig12_period_adding as fig12
from filippov_paper.scenes import fig13_small_scale_chaos as fig13

ROOT = Path(__file__).resolve().parents[1]
SECTION = ROOT / "paper" / "sec_instabilities.tex"
OMEGA = 8 * np.pi
WORDS = ["zero", "one", "two", "three", "four", "five", "six", "seven", "eight", "nine",
         "ten", "eleven", "twelve"]


# ----------------------------------------------------------------------------- rendering
def _rendered(macros: dict, text: str | None = None) -> str:
    """The section as printed: each \\rpName{} or \\rpName replaced by its body (twice:
    a body may hold another macro), whitespace folded to single spaces."""
    text = SECTION.read_text() if text is None else text
    for _ in range(2):
        text = re.sub(r"\\(rp[A-Za-z]+)(\{\})?",
                      lambda mm: macros[mm.group(1)] if mm.group(1) in macros else mm.group(0),
                      text)
    return re.sub(r"\s+", " ", text)


def _macros(**datasets) -> dict:
    """{name: body} of the report hooks of the given scenes (fig12=..., fig13=...)."""
    m = report.Macros()
    mods = {"fig12": fig12, "fig13": fig13}
    for key, ds in datasets.items():
        mods[key].report(ds, m)
    return {name: body for name, (body, _src) in report.read_macros(m.tex()).items()}


def _sentences(text: str) -> list[str]:
    return re.split(r"(?<=\.)\s+(?=[A-Z\\])", text)


def _theta_values(sentence: str) -> list[float]:
    return [float(v) for v in re.findall(r"\\theta=([0-9.]+)\$", sentence)]


# ----------------------------------------------------------------------------- checkers
def _chaotic(ds) -> np.ndarray:
    """Chaotic as the section defines it: no period, no failed return, an exponent above
    LYAPUNOV_SIGMAS standard errors (written out here, not the scene's function)."""
    return ((ds.period.values == 0) & (ds.status.values == 0)
            & (ds.lyapunov.values > attractors.LYAPUNOV_SIGMAS * ds.lyapunov_err.values))


def _last_chaotic(ds) -> dict:
    """{theta: [largest chaotic s > 0 per eps]} for each theta chaotic at every eps."""
    s, ch = ds.s.values, _chaotic(ds)
    out = {}
    for i, t in enumerate(ds.theta.values):
        ends = [s[(s > 0) & ch[i, j]] for j in range(ds.eps.size)]
        if all(e.size for e in ends):
            out[round(float(t), 6)] = [float(e[-1]) for e in ends]
    return out


def check_chaos_ends(ds, text: str) -> None:
    """Every sentence that says the chaotic range shrinks faster than eps^2 names one
    theta, and for that theta the last chaotic grid point s falls as eps shrinks (never
    rises, lower at the smallest eps than at the largest); a sentence that says it does
    not names a theta where it does not fall. Each theta chaotic at every eps has its
    last chaotic s quoted, in the order of eps."""
    ends = _last_chaotic(ds)
    assert ends, "no theta is chaotic at every eps"
    falls = {t: bool(np.all(np.diff(e) <= 0) and e[-1] < e[0]) for t, e in ends.items()}
    claims = [x for x in _sentences(text) if "faster than $\\epsilon^2$" in x]
    assert claims, "the section says nothing about how the chaotic range scales"
    for sentence in claims:
        named = _theta_values(sentence)
        assert len(named) == 1, f"a claim on the chaotic range names no single theta: {sentence}"
        theta = round(named[0], 6)
        assert theta in ends, f"theta = {theta} is not chaotic at every eps: {sentence}"
        negated = "\\emph{not}" in sentence or " not " in sentence
        assert negated != falls[theta], (
            f"theta = {theta}: last chaotic s per eps {ends[theta]}, but: {sentence}")
        quoted = [parse_num(v) for v in
                  re.findall(r"\$(?:s=)?(-?[0-9.]+(?:\\times10\^\{-?\d+\})?)\$",
                             sentence.split("lies at")[1].split(" for ")[0])]
        assert quoted == [parse_num(num(v, 3)) for v in ends[theta]], (sentence, ends[theta])
    assert {round(_theta_values(x)[0], 6) for x in claims} == set(ends)


def _s_covered(sentence: str, value: float) -> bool:
    """``value`` is quoted in ``sentence``, alone or inside a range '$a\\le s\\le b$'."""
    if re.search(r"(?<![0-9.])" + re.escape(num(value, 3)) + r"(?![0-9])", sentence):
        return True
    for a, b in re.findall(r"\$(-?[0-9.]+)\\le s\\le(-?[0-9.]+)\$", sentence):
        if float(a) <= float(num(value, 3)) <= float(b):
            return True
    return False


def check_period_one(ds, text: str, theta: float = 0.5) -> None:
    """The sentence on ``theta`` (the one naming it as marginal) does not say it keeps its
    period-one orbit unless it has period one at every grid point past grazing at every
    eps; where it does not, the sentence names that eps and each such grid point, and
    what it says of 0 < s <= s_max holds."""
    i = int(np.flatnonzero(np.isclose(ds.theta.values, theta))[0])
    s = ds.s.values
    s_max = float(ds.attrs["s_max"])
    per, status = ds.period.values[i], ds.status.values[i]
    sentence = next(x for x in _sentences(text) if f"marginal $\\theta={num(theta, 3)}$" in x)
    everywhere = bool(np.all((per[:, s > 0] == 1) & (status[:, s > 0] == 0)))
    if "keeps its period-one orbit" in sentence and "on $0<s" not in sentence:
        assert everywhere, f"theta = {theta} does not have period one everywhere: {sentence}"
    for j, e in enumerate(ds.eps.values):
        off = s[(s > 0) & ((per[j] != 1) | (status[j] != 0))]
        if not off.size:
            continue
        clause = sentence.split(f"at $\\epsilon={eps_tex(float(e))}$ the grid")
        assert len(clause) == 2, f"eps = {e}: period != 1 at s = {off}, not said: {sentence}"
        part = clause[1].split("at $\\epsilon=")[0]
        for v in off:
            assert _s_covered(part, float(v)), f"eps = {e}, s = {v} (period {per[j]}) unsaid"
    near = (s > 0) & (s <= s_max + 1e-12)
    said = f"period one at every grid point of $0<s\\le{num(s_max, 3)}$ at every $\\epsilon$"
    if said in sentence:
        assert np.all(per[:, near] == 1), per[:, near]


def check_coexistence(ds, text: str) -> None:
    """For each eps the section says which neighbouring windows overlap and which are
    apart, each with its size: the sign and size of the right edge of the window of
    n + 1 minus the left edge of that of n (recomputed here from ``edge``)."""
    ns = [int(n) for n in ds.n.values]
    edge = ds.edge.values
    paragraph = text[text.index("Neighbouring windows need not meet"):]
    paragraph = paragraph[:paragraph.index("bars")]
    for j, e in enumerate(ds.eps.values):
        head = f"at $\\epsilon={eps_tex(float(e))}$ "
        assert head in paragraph, f"eps = {e}: no clause"
        clause = paragraph.split(head)[1].split("; at $\\epsilon=")[0]
        groups = clause.split(", those of periods")
        for m, n in enumerate(ns):
            if n + 1 not in ns:
                continue
            c = edge[j, ns.index(n + 1), 1] - edge[j, m, 0]
            pair = f"{WORDS[n + 1]} and {WORDS[n]}"
            if not np.isfinite(c):
                assert pair not in clause, (e, pair, clause)
                continue
            group = [g for g in groups if pair in g]
            assert len(group) == 1, f"eps = {e}: the windows of {n + 1} and {n} not named once"
            overlap = "overlap" in group[0]
            assert overlap != ("apart" in group[0])
            assert overlap == (c > 0), f"eps = {e}, {n + 1}|{n}: {c:+.3g} but: {clause}"
            size = re.match(r"(?: overlap by| are| by)? \$([^$]+)\$",
                            group[0].split(pair)[1]).group(1)
            assert parse_num(size) == parse_num(num(abs(c), 2)), (e, n, size, c)


# ----------------------------------------------------------------------------- the build
def _built(workflow_build, sid):
    path = Path(workflow_build["work"]) / "results" / f"{sid}.nc"
    assert workflow_build["run"].returncode == 0
    return xr.open_dataset(path)


def test_the_chaos_end_sentence_follows_the_data(workflow_build):
    ds = _built(workflow_build, "fig13_small_scale_chaos")
    check_chaos_ends(ds, _rendered(_macros(fig13=ds)))


def test_the_period_one_sentence_of_theta_one_half_follows_the_data(workflow_build):
    ds = _built(workflow_build, "fig13_small_scale_chaos")
    check_period_one(ds, _rendered(_macros(fig13=ds)))


def test_the_coexistence_sentence_follows_the_data(workflow_build):
    ds = _built(workflow_build, "fig12_period_adding")
    check_coexistence(ds, _rendered(_macros(fig12=ds)))


# ----------------------------------------------------------------------------- the patterns
# the grid and the types of the build the issue was raised on (fig13: s > 5 is the
# geometric grid; fig12: the edges of the windows of 2..5 at five eps)
S13 = np.array([-0.1, 2.0, 5.0, 9.696, 18.80, 36.46, 70.71, 137.1, 265.9, 515.7, 1000.0])
EPS13 = [1e-2, 1e-3, 1e-4, 1e-5]
# period per (theta, eps, s), 0: chaotic (lyapunov 0.3 +- 0.01)
P13 = {0.5: [[1, 1, 1, 2, 2, 0, 0, 2, 2, 1, 1]] + [[1] * 11] * 3,
       0.2: [[1, 0, 0, 0, 5, 0, 4, 3, 0, 2, 1], [1, 0, 0, 0, 0, 0, 0, 2, 2, 2, 1],
             [1, 0, 0, 0, 0, 2, 2, 2, 1, 1, 1], [1, 0, 0, 0, 2, 2, 2, 2, 1, 1, 1]],
       0.1: [[1, 0, 0, 6, 0, 5, 4, 3, 3, 2, 2], [1, 0, 0, 0, 0, 0, 3, 3, 0, 2, 2],
             [1, 0, 0, 0, 3, 3, 0, 2, 2, 2, 1], [1, 0, 0, 0, 3, 3, 0, 2, 2, 1, 1]]}


def _fig13_pattern() -> xr.Dataset:
    th = list(P13)
    per = np.array([P13[t] for t in th], dtype=np.int32)
    dims = ("theta", "eps", "s")
    return xr.Dataset(
        {"period": (dims, per), "status": (dims, np.zeros_like(per)),
         "lyapunov": (dims, np.where(per == 0, 0.3, -0.5)),
         "lyapunov_err": (dims, np.where(per == 0, 0.01, 0.0))},
        coords={"theta": th, "eps": EPS13, "s": S13}, attrs={"s_max": 5.0})


def _fig12_pattern() -> xr.Dataset:
    edge = np.array([
        [[np.nan, np.nan], [3.222, np.nan], [1.3966, 3.0635], [0.6266, 1.2826]],
        [[2.0622, np.nan], [0.9003, 2.2572], [0.4308, 0.9891], [0.2181, 0.4780]],
        [[1.1460, 2.7809], [0.5488, 1.1920], [0.2912, 0.5929], [0.1630, 0.3176]],
        [[1.0308, 1.9863], [0.5069, 0.9330], [0.27544, 0.49295], [0.15702, 0.27567]],
        [[1.0189, 1.7711], [0.5027, 0.8601], [0.2738, 0.4641], [0.1564, 0.2633]]])
    kind = np.where(np.isfinite(edge), 0, 2)
    kind[0, 0] = -9
    ns = [2, 3, 4, 5]
    return xr.Dataset({"edge": (("eps", "n", "side"), edge),
                       "edge_kind": (("eps", "n", "side"), kind),
                       "coexistence": (("eps", "n"), fig12._coexistence(ns, edge))},
                      coords={"eps": [1e-2, 1e-3, 1e-4, 1e-5, 1e-6], "n": ns})


#: what the section printed before (issue 60), its macros put in for the patterns above
OLD_CHAOS_END = (r"The range of $s$ that carries chaos is \emph{not} the same multiple of "
                 r"$\epsilon^2$ at every $\epsilon$: the last chaotic grid point lies at "
                 r"$s=266$ and $18.8$ at $\epsilon=0.01$ but at $s=9.7$ and $70.7$ at "
                 r"$\epsilon=10^{-5}$ ($5$ and $2$ steps of the geometric grid apart), so the "
                 r"chaotic range shrinks faster than $\epsilon^2$ at these $\epsilon$.")
OLD_HALF = (r"The marginal $\theta=0.5$ ($s=-1$, $\lambda s=-0.607$) keeps its period-one "
            r"orbit as well.")
OLD_COEXIST = (r"Neighbouring windows need not meet: at $\epsilon=0.001$, $10^{-4}$ and "
               r"$10^{-5}$ the orbits of periods $n+1$ and $n$ are both stable on an interval "
               r"of $s$ (up to $0.19$ long; $0.19$ for periods three and two at "
               r"$\epsilon=0.001$), where the attractor a run shows depends on its start, and "
               r"at the other $\epsilon$ a gap of up to $0.16$ separates them, filled by the "
               r"windows of other periods (bars).")


def test_the_chaos_end_sentence_says_what_each_theta_shows():
    ds = _fig13_pattern()
    text = re.sub(r"\s+", " ", fig13._report_chaos_end_sentence(ds))
    check_chaos_ends(ds, text)
    # theta = 0.2: 266 -> 9.7 (falls); theta = 0.1: 18.8 -> 266 -> 70.7 (not one way)
    assert "faster than $\\epsilon^2$, at these" in text.split("$\\theta=0.1$")[0]
    assert "\\emph{not} show" in text.split("$\\theta=0.1$")[1]
    with pytest.raises(AssertionError, match="names no single theta"):
        check_chaos_ends(ds, OLD_CHAOS_END)


def test_the_period_one_sentence_names_where_theta_one_half_leaves_period_one():
    ds = _fig13_pattern()
    sentence = (r"The marginal $\theta=0.5$ ($s=-1$) has "
                + fig13._report_period_one_sentence(ds, 0.5) + ".")
    check_period_one(ds, sentence)
    assert "at every grid point of $0<s\\le5$ at every $\\epsilon$" in sentence
    for v in ("9.7", "18.8", "36.5", "70.7", "137", "266"):
        assert v in sentence
    with pytest.raises(AssertionError, match="does not have period one everywhere"):
        check_period_one(ds, OLD_HALF)


def test_the_coexistence_sentence_says_each_pair_at_each_eps():
    ds = _fig12_pattern()
    text = ("Neighbouring windows need not meet: " + fig12._report_coexist_sentence(ds)
            + " (bars).")
    check_coexistence(ds, text)
    # eps = 1e-5: five and four overlap (by 2.3e-4), three and two, four and three do not
    clause = text.split("at $\\epsilon=10^{-5}$ ")[1].split("; at")[0]
    assert "five and four overlap by $2.3\\times10^{-4}$" in clause and "apart" in clause
    with pytest.raises(AssertionError, match="no clause"):
        check_coexistence(ds, OLD_COEXIST)


# ----------------------------------------------------------------------------- the model
def _settle(eps, theta, s):
    sigma = limit_map.scale(eps, theta)
    mu = 1.0 + s * sigma
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=True)
    return attractors.settle(cm, [0.0, np.sqrt(mu), 0.0], coordinate=1, transient=300,
                             keep=100, t_max=1.0, scale=sigma, max_period=50,
                             window=(0.8, 1.2), lyapunov=True)


def _is_chaotic(at) -> bool:
    return (at.period == 0 and not at.escaped
            and at.lyapunov > attractors.LYAPUNOV_SIGMAS * at.lyapunov_err)


def test_at_theta_one_tenth_the_chaos_reaches_further_at_smaller_eps():
    # fig13's geometric grid point s = 70.7 (and 137): at eps = 1e-2 the attractor there
    # is periodic (the chaos ended by s = 18.8), at eps = 1e-5 it is chaotic: the last
    # chaotic s does not fall as eps shrinks for theta = 0.1
    s = 70.71067811865474
    big = _settle(1e-2, 0.1, s)
    assert big.period > 0, (big.period, big.lyapunov, big.lyapunov_err)
    small = _settle(1e-5, 0.1, s)
    assert _is_chaotic(small), (small.period, small.lyapunov, small.lyapunov_err)


def test_at_theta_one_half_period_one_holds_near_grazing_not_on_the_whole_grid():
    # theta = 1/2 (s(theta,0,0) = -1): period one on 0 < s <= 5, but at eps = 1e-2 fig13's
    # geometric grid has period two at s = 9.70 and chaos at s = 36.5; at eps = 1e-3
    # period one there
    for s in (2.0, 5.0):
        assert _settle(1e-2, 0.5, s).period == 1
    assert _settle(1e-2, 0.5, 9.696155060244159).period == 2
    assert _is_chaotic(_settle(1e-2, 0.5, 36.46161388801942))
    assert _settle(1e-3, 0.5, 36.46161388801942).period == 1


# ----------------------------------------------------------------------------- the errors
def _coverage(J: np.ndarray, segments: int, length: int, blocks: int) -> float:
    """Share of ``segments`` consecutive segments of ``length`` returns whose exponent
    lies within two of its standard errors (batch means over ``blocks``) of the
    exponent over all of them."""
    whole = attractors.lyapunov_exponent(J[:segments * length], 1)
    hits = []
    for i in range(segments):
        lam, err = attractors.lyapunov_estimate(J[i * length:(i + 1) * length], 1, blocks)
        hits.append(abs(lam - whole) <= 2 * err)
    return float(np.mean(hits))


def test_the_lyapunov_errors_cover_independent_segments():
    # theta = 0.2, eps = 1e-2, s = 2 (chaotic, fig13's grid): 50 segments of 900 returns
    # (the fewest on which settle calls chaos: keep 100 and one extension of 800), each
    # with its exponent and standard error; the exponents lie within two standard
    # errors of the long run's exponent for about 95% of them. With five blocks (four
    # degrees of freedom) 82% did (measured); with LYAPUNOV_BLOCKS = 20, 96%
    eps, theta, s = 1e-2, 0.2, 2.0
    mu = 1.0 + s * eps * eps
    cm = hopf.compiled(eps, theta, mu, OMEGA, sliding=True)
    segments, length = 50, 900
    run = attractors.iterate(cm, [0.0, np.sqrt(mu), 0.0], transient=300,
                             keep=segments * length, t_max=1.0, jacobian=True)
    assert run.status[0] == 0
    J = run.orbit_jacobian[0]
    cover = _coverage(J, segments, length, attractors.LYAPUNOV_BLOCKS)
    assert 0.9 <= cover, cover
