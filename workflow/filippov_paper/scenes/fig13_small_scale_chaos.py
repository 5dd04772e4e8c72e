"""Small-scale chaos (theta > 0): the attractor of the return map to L1 of the slow-fast
Hopf example across mu = 1 for several theta and eps, with its largest Lyapunov
exponent and width, beside the limit map.

Orbit diagrams in s = (mu - 1)/eps^2, u = (x2 - 1)/eps^2 (attractor_common), on a
uniform grid around grazing and a geometric one beyond it (where the attractor ends).
On top of the shared sweep:

* the one-sided slope of P_DM at grazing, s(theta, 0, 0) = (theta - 1)/theta (the
  paper's chaos condition is s < -1), and the slope of the whole return there,
  lambda s (lambda the cycle's multiplier per turn): the fixed point on the sliding
  branch loses stability where lambda s < -1;
* the Lyapunov exponent of the limit map along its attractor (central differences of
  the map), beside the slow-fast one;
* the width in x2 (width u times eps^2) and its scaling exponent k per (theta, s):
  the least-squares slope of log width against log eps over eps <= ``fit_eps_max``,
  where the attractor is not a point at any of them.
"""
from __future__ import annotations

import numpy as np
import xarray as xr

from filippov import attractors
from filippov_paper import tolerance
from filippov.analytic import limit_map
from filippov.io import finalize
from filippov_paper.tolerance import Tolerance
from filippov_paper.scenes.attractor_common import (CHUNK_AXIS, ENGINES, HopfReturns as MODEL, chunk_grid, T_RETURN,  # noqa: F401
                               VARIABLE_ATTRS as _COMMON_ATTRS, chaos_tolerances, width_tolerance,
                               common_dataset, eps_list, lyapunov_limit, s_grid, sweep, thetas)
from filippov_paper.scenes.attractor_common import validate as _validate_common
from filippov_paper.config import SceneError
from filippov_paper.report import Macros, count_phrase, count_word, eps_tex, head, num, source, tabular, value

#: this scene's block of the scene schema: filippov_paper.config.load_scene adds it to
#: config/schema/scene.schema.json for this id (#/$defs/... refer there), reading it
#: from this file without importing it (a literal: JSON with Python's True/False/None)
PARAMETERS_SCHEMA = {
  "properties": {
    "parameters": {
      "required": ["eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_geo", "s_geo_max",
                   "n_transient", "n_keep", "max_period", "window", "lyapunov", "fit_eps_max"],
      "$ref": "#/$defs/attractor_sweep",
      "propertyNames": {"enum": [
        "eps", "theta", "omega", "s_min", "s_max", "n_mu", "n_geo", "s_geo_max", "n_transient",
        "n_keep", "max_period", "window", "lyapunov", "fit_eps_max"
      ]},
      "properties": {
        "eps": {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0, "maximum": 0.1}},
        "theta": {"type": "array", "minItems": 1, "items": {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1}},
        "s_max": {"type": "number", "exclusiveMinimum": 0},
        "n_geo": {"type": "integer", "minimum": 0},
        "s_geo_max": {"type": "number", "exclusiveMinimum": 0},
        "fit_eps_max": {"type": "number", "exclusiveMinimum": 0}
      }
    }
  }
}

VARIABLE_ATTRS = dict(_COMMON_ATTRS)
VARIABLE_ATTRS.update({
    "slope_pdm": ("one-sided slope s(theta,0,0) = (theta - 1)/theta of P_DM at grazing", "1"),
    "slope_return": ("lambda s(theta,0,0): slope of the return map on the sliding side", "1"),
    "lyapunov_limit": ("Lyapunov exponent of the limit map along its attractor", "1"),
    "width_x2": ("width of the attractor in x2 (width times eps^2)", "1"),
    "width_exponent": ("k of width_x2 ~ eps^k: least-squares slope of log width against "
                       "log eps over eps <= fit_eps_max (three or more), where the attractor "
                       "is chaotic at each of them (NaN elsewhere)", "1"),
    "width_exponent_err": ("standard error of width_exponent (residuals, n - 2 degrees of "
                           "freedom)", "1"),
    "chaotic": ("1: chaotic (no confirmed period, exponent above three standard errors)", "1"),
})


def tolerances(scene: dict) -> dict:
    """attractor_common.chaos_tolerances, and for the derived widths: width_x2 as the
    width (attractor_common.width_tolerance: its two ends' sampling errors); the width
    exponent, a log10 ratio of two widths a decade of eps apart, to log10(1.5/0.5) ~ 0.5."""
    out = chaos_tolerances(scene)
    stat = "a sampled statistic of a chaotic orbit (another orbit on another machine)"
    # width_x2 = width eps^2 (x2 coordinates): the width's rule, its atol that of two
    # event-located x2 (the ends)
    out["width_x2"] = width_tolerance(out["u"], stat, atol=2 * tolerance.EVENT_STATE)
    out["width_exponent"] = Tolerance(0.0, 0.5, f"{stat}: least-squares slope of log10 "
                                      "width over three or more eps a decade apart, each "
                                      "width within a factor 3 either way (measured: 0.28 of "
                                      "itself at most, +-2 ulps); log10 3 = 0.48 at both ends, "
                                      "opposite ways, moves the slope by at most 0.48")
    out["width_exponent_err"] = Tolerance(0.0, 0.5, f"{stat}: residuals of the same fit")
    out["chaotic"] = out["period"]   # a classification, as the period
    return out


def validate(scene: dict) -> None:
    _validate_common(scene)
    if any(not 0 < t < 1 for t in thetas(scene["parameters"])):
        raise SceneError(f"{scene['id']}: parameters.theta: each theta must lie in (0, 1) "
                         "(the sliding case)")


def compute(scene: dict, *, progress: bool = False) -> xr.Dataset:
    return assemble(scene, sweep(scene, chunk_grid(scene), progress=progress))


def chaotic(ds) -> np.ndarray:
    """1 where the attractor is chaotic: no confirmed period and a Lyapunov exponent
    above attractors.LYAPUNOV_SIGMAS standard errors (0 elsewhere)."""
    return ((ds.period.values == 0) & (ds.status.values == 0) &
            (ds.lyapunov.values > attractors.LYAPUNOV_SIGMAS * ds.lyapunov_err.values)
            ).astype(np.int32)


def width_exponents(wx: np.ndarray, chaos: np.ndarray, fitted: np.ndarray, eps: np.ndarray):
    """k and its standard error per (theta, s): the least-squares slope of log width
    against log eps over the ``fitted`` eps (at least three), where the attractor is
    chaotic at every one of them (a periodic attractor's width is its orbit's extent,
    which need not scale like a chaotic band's); NaN elsewhere. The error is the slope's
    standard error from the residuals (n - 2 degrees of freedom)."""
    le = np.log(eps[fitted])
    n = le.size
    k, err = np.full(wx.shape[::2], np.nan), np.full(wx.shape[::2], np.nan)
    if n < 3:
        return k, err
    sxx = float(np.sum((le - le.mean()) ** 2))
    for i in range(wx.shape[0]):
        for m in range(wx.shape[2]):
            w = wx[i, fitted, m]
            if not (np.all(chaos[i, fitted, m] == 1) and np.all(np.isfinite(w) & (w > 0))):
                continue
            slope, icpt = np.polyfit(le, np.log(w), 1)
            res = np.log(w) - (icpt + slope * le)
            k[i, m] = slope
            err[i, m] = float(np.sqrt(np.sum(res ** 2) / (n - 2) / sxx))
    return k, err


def assemble(scene: dict, raw: xr.Dataset) -> xr.Dataset:
    p = scene["parameters"]
    ds = common_dataset(scene, raw)
    th, eps = np.array(thetas(p)), np.array(eps_list(p))
    lam = limit_map.multiplier(1.0, float(p["omega"]))
    ds["slope_pdm"] = ("theta", (th - 1.0) / th)
    ds["slope_return"] = ("theta", lam * (th - 1.0) / th)
    ds["lyapunov_limit"] = (("theta", "eps", "s"), lyapunov_limit(ds, float(p["omega"])))
    wx = ds.width.values * (eps ** 2)[None, :, None]
    ds["width_x2"] = (("theta", "eps", "s"), wx)
    ds["chaotic"] = (("theta", "eps", "s"), chaotic(ds))
    k, k_err = width_exponents(wx, ds.chaotic.values, eps <= float(p["fit_eps_max"]), eps)
    ds["width_exponent"] = (("theta", "s"), k)
    ds["width_exponent_err"] = (("theta", "s"), k_err)
    return finalize(ds, scene, engine="compiled", method="exact",
                    title="small-scale chaos of the slow-fast Hopf example, theta > 0")


# ============================================================================= report
# What the reproduction report quotes from this scene's dataset (filippov_paper.report calls
# `report`). This part -- report, REPORT_OPTIONAL and the _report_* / _REPORT_* names --
# is left out of the code hash of the compute jobs: editing it rebuilds the report only.
_REPORT_WORD = {0.7: "Seven", 0.5: "Half", 0.4: "Four", 0.3: "Three", 0.2: "Two", 0.1: "One"}


def _report_near(s, ds) -> np.ndarray:
    """The uniform grid's part above grazing: 0 < s <= s_max."""
    return (s > 0) & (s <= float(ds.attrs["s_max"]) + 1e-12)


def _report_table(ds) -> str:
    """Per theta: the largest Lyapunov exponent on 0 < s <= s_max at each eps, and its
    median distance to the limit map's at each eps."""
    s = ds.s.values
    near = _report_near(s, ds)
    eps = [float(e) for e in ds.eps.values]
    rows = []
    for i, t in enumerate(ds.theta.values):
        ly = ds.lyapunov.values[i][:, near]
        gap = np.abs(ly - ds.lyapunov_limit.values[i][:, near])
        cells = [f"${float(t):g}$", f"${num(float(ds.slope_pdm.values[i]), 3)}$"]
        cells += [f"${num(float(np.max(r)), 2)}$" for r in ly]
        cells += [f"${num(float(np.median(g)), 1)}$" for g in gap]
        rows.append(" & ".join(cells) + r" \\")
    n = len(eps)
    e_head = [f"${eps_tex(e)}$" for e in eps]
    # two groups of one column per eps, each group headed by what it holds and by the
    # parameter of its columns ("eps =" over the values), under a rule of its own
    top = " & ".join(["", "", rf"\multicolumn{{{n}}}{{c}}{{largest exponent, $\epsilon={{}}$}}",
                      rf"\multicolumn{{{n}}}{{c}}{{gap to the limit map, $\epsilon={{}}$}}"]) + r" \\"
    rules = rf"\cmidrule(lr){{3-{2 + n}}}\cmidrule(l){{{3 + n}-{2 + 2 * n}}}"
    # two columns per eps: narrower column gaps keep four eps within the text width
    return r"\setlength{\tabcolsep}{3.5pt}" + "\n" + tabular(
        "rr" + "r" * 2 * n,
        [top, rules, head(r"$\theta$", r"$s(\theta,0,0)$", *e_head, *e_head)], rows)


def _report_join(items: list) -> str:
    """'a', 'a and b', 'a, b and c' (text mode)."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def _report_s_list(values) -> str:
    """'$s=a$', '$s=a$ and $b$', '$s=a$, $b$ and $c$'."""
    items = [f"${num(float(v), 3)}$" for v in values]
    return "$s=" + _report_join(items)[1:]


def _report_s_run(values) -> str:
    """Consecutive grid points: listed up to two, else '$a\\le s\\le b$'."""
    if len(values) <= 2:
        return _report_s_list(values)
    return rf"${num(float(values[0]), 3)}\le s\le{num(float(values[-1]), 3)}$"


def _report_chaotic_mask(ds) -> np.ndarray:
    """chaotic == 1 recomputed from period, status, lyapunov and lyapunov_err (the
    stored variable, where it is there)."""
    return chaotic(ds) == 1


def _report_chaos_ends(ds) -> dict:
    """Per theta whose attractor is chaotic somewhere past grazing at every eps: the
    largest grid s > 0 where it is chaotic, one per eps (the dataset's eps order)."""
    s, ch = ds.s.values, _report_chaotic_mask(ds)
    out = {}
    for i, t in enumerate(ds.theta.values):
        ends = [s[(s > 0) & ch[i, j]] for j in range(ds.eps.size)]
        if all(e.size for e in ends):
            out[float(t)] = np.array([float(e[-1]) for e in ends])
    return out


def _report_trend(ends: np.ndarray) -> str:
    """How the last chaotic s moves as eps shrinks (``ends`` from the largest eps to the
    smallest): 'falls' (never up, lower at the end), 'rises' (never down, higher at the
    end), 'stays' or 'mixed'."""
    d = np.diff(ends)
    if np.all(d <= 0) and ends[-1] < ends[0]:
        return "falls"
    if np.all(d >= 0) and ends[-1] > ends[0]:
        return "rises"
    return "stays" if np.all(d == 0) else "mixed"


def _report_interrupted(ds) -> list:
    """(theta, eps) where a grid point s > 0 that is not chaotic lies between two chaotic
    ones: the chaos past grazing is not one interval of the grid."""
    s, ch = ds.s.values, _report_chaotic_mask(ds)
    out = []
    for i, t in enumerate(ds.theta.values):
        for j, e in enumerate(ds.eps.values):
            k = np.flatnonzero((s > 0) & ch[i, j])
            if k.size and not np.all(ch[i, j, k[0]:k[-1] + 1]):
                out.append((float(t), float(e)))
    return out


def _report_chaos_end_sentence(ds) -> str:
    """Where the chaos ends past grazing, per theta chaotic at every eps, and what that
    says of the range in s = (mu - 1)/eps^2 as eps shrinks (generated from the data:
    'shrinks faster than eps^2' only where the last chaotic s falls with eps)."""
    s = ds.s.values
    eps = [float(e) for e in ds.eps.values]
    e_first, e_last = eps_tex(eps[0]), eps_tex(eps[-1])
    out = []
    for t, ends in _report_chaos_ends(ds).items():
        idx = [int(np.flatnonzero(s == v)[0]) for v in ends]
        head_ = (rf"For $\theta={num(t, 3)}$ the last chaotic grid point lies at "
                 rf"{_report_s_list(ends)} for $\epsilon={e_first}$ to ${e_last}$")
        trend = _report_trend(ends)
        if trend == "falls":
            tail = (rf": it falls by {count_phrase(idx[0] - idx[-1], 'step')} of the grid, so at "
                    r"this $\theta$ the range of $s$ that carries chaos shrinks, and the "
                    r"chaotic range in $\mu$ faster than $\epsilon^2$, at these $\epsilon$")
        elif trend == "rises":
            tail = (rf": it rises by {count_phrase(idx[-1] - idx[0], 'step')} of the grid, so at "
                    r"this $\theta$ the chaotic range in $\mu$ does \emph{not} shrink faster "
                    r"than $\epsilon^2$")
        elif trend == "stays":
            tail = r": the same grid point, as for a range proportional to $\epsilon^2$"
        else:
            hi = "higher" if ends[-1] > ends[0] else ("lower" if ends[-1] < ends[0]
                                                     else "the same")
            tail = (r": it does not move one way as $\epsilon$ shrinks (it lies "
                    rf"{hi}{'' if hi == 'the same' else ' at'} $\epsilon={e_last}$ "
                    rf"{'as' if hi == 'the same' else 'than'} at $\epsilon={e_first}$), so at this "
                    r"$\theta$ the data do \emph{not} show the chaotic range shrinking faster "
                    r"than $\epsilon^2$")
        out.append(head_ + tail + ".")
    gaps = _report_interrupted(ds)
    if gaps:
        pairs = _report_join([rf"$({num(t, 3)},{eps_tex(e)})$" for t, e in gaps])
        out.append(r"Nor is the chaos one interval of $s$: a periodic attractor lies between "
                   rf"chaotic grid points at $(\theta,\epsilon)=" + pairs[1:] + ".")
    return " ".join(out)


_REPORT_TYPE = {0: "chaos", -1: "an aperiodic attractor without a positive exponent",
                -2: "an escape"}


def _report_type(ds, i, j) -> np.ndarray:
    """Per s: the period (> 0), 0 chaotic, -1 aperiodic without a clearly positive
    exponent, -2 escaped."""
    per = ds.period.values[i, j].astype(int)
    out = np.where(per > 0, per, -1)
    out[_report_chaotic_mask(ds)[i, j]] = 0
    out[ds.status.values[i, j] != 0] = -2
    return out


def _report_runs_phrase(s, kind) -> str:
    """'period two at s = a and b, chaos at s = c, ...': consecutive grid points of one
    type grouped, in the order of s."""
    parts, k = [], 0
    while k < s.size:
        m = k
        while m + 1 < s.size and kind[m + 1] == kind[k]:
            m += 1
        what = (f"period {count_word(int(kind[k]))}" if kind[k] > 0
                else _REPORT_TYPE[int(kind[k])])
        parts.append(f"{what} at {_report_s_run(s[k:m + 1])}")
        k = m + 1
    return "; ".join(parts) if len(parts) > 2 else _report_join(parts)


def _report_period_one_sentence(ds, theta: float) -> str:
    """Where the attractor of ``theta`` has period one past grazing: on 0 < s <= s_max at
    which eps, and on the geometric grid beyond it at which eps, with what it is
    instead where it is not (generated from the data)."""
    i = int(np.flatnonzero(np.isclose(ds.theta.values, theta))[0])
    s = ds.s.values
    near, far = _report_near(s, ds), s > float(ds.attrs["s_max"]) + 1e-12
    eps = [float(e) for e in ds.eps.values]
    kinds = [_report_type(ds, i, j) for j in range(len(eps))]
    one_near = [j for j in range(len(eps)) if np.all(kinds[j][near] == 1)]
    one_far = [j for j in one_near if np.all(kinds[j][far] == 1)]
    s_max, s_end = num(float(ds.attrs["s_max"]), 3), num(float(s[-1]), 3)

    def eps_phrase(js):
        if len(js) == len(eps):
            return r"at every $\epsilon$"
        return r"at $\epsilon=" + _report_join([f"${eps_tex(eps[j])}$" for j in js])[1:]
    out = []
    if one_near:
        out.append(rf"period one at every grid point of $0<s\le{s_max}$ "
                   + eps_phrase(one_near))
    else:
        out.append(rf"period one on all of $0<s\le{s_max}$ at no $\epsilon$")
    if one_far:
        out.append(rf"on the whole grid up to $s={s_end}$ {eps_phrase(one_far)}")
    sentence = ", ".join(out) if len(out) > 1 else out[0]
    rest = []
    for j in range(len(eps)):
        if j in one_far:
            continue
        mask = far if j in one_near else (s > 0)
        where = "beyond" if j in one_near else "past grazing"
        rest.append(rf"at $\epsilon={eps_tex(eps[j])}$ the grid {where}"
                    rf"{' $s=' + s_max + '$' if where == 'beyond' else ''} shows "
                    + _report_runs_phrase(s[mask], kinds[j][mask]))
    if rest:
        sentence += "; " + "; ".join(rest)
    return sentence


def report(ds, m: Macros) -> str | None:
    sid = "fig13_small_scale_chaos"
    eps = [float(e) for e in ds.eps.values]
    s = ds.s.values
    near = _report_near(s, ds)
    m.add("rpThirteenEpsMax", eps[0], f"{sid}:eps[0]")
    m.add("rpThirteenEpsMin", eps[-1], f"{sid}:eps[-1]")
    m.add("rpThirteenSMin", float(ds.attrs["s_min"]), f"{sid}:attrs.s_min")
    m.add("rpThirteenSMax", float(ds.attrs["s_max"]), f"{sid}:attrs.s_max")
    m.add("rpThirteenSGeoMax", float(ds.attrs["s_geo_max"]), f"{sid}:attrs.s_geo_max")
    m.add("rpThirteenFitEpsMax", float(ds.attrs["fit_eps_max"]), f"{sid}:attrs.fit_eps_max", 1)
    lam = value(ds, "multiplier")
    m.add("rpThirteenMultiplier", lam, source(sid, "multiplier"), 4)
    m.add("rpThirteenThetaCrit", lam / (1.0 + lam), "derived: lambda/(1 + lambda), where "
          "lambda s(theta,0,0) = -1", 3)
    j = len(eps) - 1
    for i, t in enumerate(ds.theta.values):
        w = _REPORT_WORD.get(round(float(t), 6))
        if not w:
            continue
        m.add(f"rpThirteenTheta{w}", float(t), source(sid, "theta", theta=float(t)))
        m.add(f"rpThirteenSlope{w}", float(ds.slope_pdm.values[i]),
              source(sid, "slope_pdm", theta=float(t)), 3)
        m.add(f"rpThirteenSlopeReturn{w}", float(ds.slope_return.values[i]),
              source(sid, "slope_return", theta=float(t)), 3)
        ly = ds.lyapunov.values[i][:, near]
        small = np.array(eps) <= float(ds.attrs["fit_eps_max"])
        m.add(f"rpThirteenLyapMax{w}", float(np.max(ly[small])),
              "derived: max lyapunov over eps <= fit_eps_max and 0 < s <= s_max", 2)
        m.add(f"rpThirteenLyapMaxAll{w}", float(np.max(ly)),
              "derived: max lyapunov over all eps and 0 < s <= s_max", 2)
        m.add(f"rpThirteenLyapMin{w}", float(np.min(ly)),
              "derived: min lyapunov over all eps and 0 < s <= s_max", 2)
        per = ds.period.values[i, j]
        k = ds.width_exponent.values[i][near]
        if np.isfinite(k).any():
            m.add(f"rpThirteenK{w}", float(np.nanmedian(k)),
                  "derived: median width_exponent over 0 < s <= s_max", 3)
            m.add(f"rpThirteenKMax{w}", float(np.nanmax(np.abs(k - 2.0))),
                  "derived: max |width_exponent - 2| over 0 < s <= s_max", 2)
            ke = ds.width_exponent_err.values[i][near]
            m.add(f"rpThirteenKErr{w}", float(np.nanmedian(ke)),
                  "derived: median width_exponent_err over 0 < s <= s_max", 2)
            m.add(f"rpThirteenKN{w}", float(np.isfinite(k).sum()),
                  "derived: number of s in 0 < s <= s_max with a width exponent", 2)
        m.add(f"rpThirteenPeriodTwoShare{w}", float(np.mean(per[near] == 2)),
              "derived: share of 0 < s <= s_max with period == 2 at the smallest eps", 2)
        m.add(f"rpThirteenPeriodOne{w}", float(np.all(per[near] == 1)),
              "derived: 1 if period == 1 on 0 < s <= s_max at the smallest eps", 1)
        m.add(f"rpThirteenPeriodOneWhere{w}", None, "derived: grid points where period == 1 "
              "(chaotic, period, status) per eps, on 0 < s <= s_max and beyond",
              text=_report_period_one_sentence(ds, float(t)))
    m.add("rpThirteenChaosEndSentence", None, "derived: largest s > 0 where chaotic per "
          "theta and eps, and its trend as eps shrinks", text=_report_chaos_end_sentence(ds))
    m.add("rpLyapunovBlocks", None, "derived: filippov.attractors.LYAPUNOV_BLOCKS",
          text=count_word(attractors.LYAPUNOV_BLOCKS))
    return _report_table(ds)


# ----------------------------------------------------------------------------- test knobs
# (filippov_paper.product; left out of the compute jobs' code hash)
#: a physical parameter whose 1% change the manifest must notice (tests/test_cross_cpu.py)
TEST_PERTURB = "theta"
#: parameters for a grid small enough that computing it in chunks takes seconds
#: (tests/test_chunks.py)
TEST_SMALL = {"eps": [0.01, 0.001], "theta": [0.7, 0.2, 0.1], "n_mu": 7, "n_geo": 2,
              "n_transient": 40, "n_keep": 20, "max_period": 10}
