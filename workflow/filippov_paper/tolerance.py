"""How closely a variable's values must agree between two machines.

The same code on another CPU rounds exp, log, sin, ... differently in the last
bit; how far that moves a result depends on the result: a well-conditioned
output of a solve at rtol 1e-12 moves by a few ulps, a quantity in coordinates
scaled by 1/eps^2 moves by an ulp of the unscaled state times 1/eps^2, a count
decided at a tangency can change by one crossing pair. Each scene module
declares, next to the data it computes, a :class:`Tolerance` with a one-line
reason for every variable that needs more than :data:`DEFAULT`; the tolerance
travels with the variable as attributes (``repro_*``) into the netCDF file and
from there into the manifest (:mod:`filippov_paper.manifest`).

Rules:

* ``close``: same shape and NaN positions count; values within
  ``atol + rtol * |value|``;
* ``tangency``: an output decided at a tangency (whether an orbit started on
  the onset of sticking slides, and so its number of switches and its sliding
  length): ``close``, except at most ``changed`` entries, which may differ by up
  to ``jump`` (a count by one crossing pair, a length by its square-root law);
* ``trace``: an iteration history (secant steps), not a result: only the last
  finite value along the last axis (the converged value) is compared,
  ``close``-style; the number of steps may differ;
* ``measured``: a wall-clock measurement (a time, a repeat count decided by
  time): it differs between any two runs, so only its shape is compared;
* ``attractor``: the last axis holds points of an attractor (returns kept after a
  transient). On a chaotic attractor a last-bit change is amplified by e^(lambda n)
  over n returns, so the points themselves are not a result, only where they lie:
  each row is compared by its extent (min and max over the last axis), within
  ``atol + rtol |value|`` plus ``jump`` times the row's reference width (0 for a
  periodic row, which must agree closely; a fraction of the width for a chaotic one,
  whose extent is sampled by a different orbit).
* ``order``: a magnitude whose value is not a result, only its order is: the error
  of an approximate method, decided by its step sequence, which a last-bit change
  re-draws (cancellations of local errors make any value below the error's envelope
  possible). Magnitudes below ``atol`` (the floor) count as ``atol``; above it the
  two must agree within a factor ``rtol`` (>= 1) either way. Unlike ``close``, whose
  ``atol + rtol |reference|`` is asymmetric (with rtol 10 it lets a value fall to 0
  but rise only 11-fold), the rule is symmetric: which of two builds wrote the
  manifest does not decide whether they agree.

Every rule but ``order`` measures a difference against its reference value; with
``rtol`` << 1 (all ``close`` tolerances that are not counts) the asymmetry is of
order rtol and does not matter.
"""
from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import xarray as xr

RULES = ("close", "tangency", "trace", "measured", "attractor", "order")
PREFIX = "repro_"


@dataclass(frozen=True)
class Tolerance:
    rtol: float
    atol: float
    why: str
    rule: str = "close"
    changed: int = 0   # tangency rule: how many entries may leave the close tolerance ...
    jump: float = 0.0  # ... and by how much at most

    def __post_init__(self):
        if self.rule not in RULES:
            raise ValueError(f"tolerance rule {self.rule!r}: expected one of {RULES}")
        if not (self.rtol >= 0 and self.atol >= 0 and self.jump >= 0
                and np.isfinite(self.rtol + self.atol + self.jump)):
            raise ValueError(f"tolerance: rtol, atol and jump must be finite and >= 0, got "
                             f"{self.rtol}, {self.atol}, {self.jump}")
        if (self.rule == "tangency") != (self.changed > 0):
            raise ValueError("tolerance: `changed` > 0 goes with rule 'tangency' (and only there)")
        if not self.why.strip():
            raise ValueError("tolerance: a reason (why) is required")
        if self.rule == "order" and not (self.rtol >= 1 and self.atol > 0):
            raise ValueError("tolerance rule 'order': rtol is a factor (>= 1) and atol a "
                             f"floor (> 0), got {self.rtol}, {self.atol}")

    def attrs(self) -> dict:
        return {PREFIX + k: v for k, v in asdict(self).items()}

    @classmethod
    def from_attrs(cls, attrs) -> "Tolerance":
        if PREFIX + "rule" not in attrs:
            return DEFAULT
        return cls(rtol=float(attrs[PREFIX + "rtol"]), atol=float(attrs[PREFIX + "atol"]),
                   why=str(attrs[PREFIX + "why"]), rule=str(attrs[PREFIX + "rule"]),
                   changed=int(attrs[PREFIX + "changed"]), jump=float(attrs[PREFIX + "jump"]))

    def allowed(self, reference: np.ndarray) -> np.ndarray:
        """The admissible difference at each entry of ``reference``."""
        return self.atol + self.rtol * np.abs(reference)

    def factor(self, a, b) -> np.ndarray:
        """Rule ``order``: how many times larger the larger of ``|a|`` and ``|b|`` is
        than the smaller, each raised to the floor ``atol`` (1 where they agree);
        symmetric in ``a`` and ``b``."""
        a = np.maximum(np.abs(np.asarray(a, dtype=float)), self.atol)
        b = np.maximum(np.abs(np.asarray(b, dtype=float)), self.atol)
        return np.maximum(a, b) / np.minimum(a, b)

    def agree(self, reference, other) -> np.ndarray:
        """Whether ``other`` is within this tolerance of ``reference``, entry by entry
        (``close``-style: the difference against :meth:`allowed`; ``order``: the
        factor against ``rtol``)."""
        if self.rule == "order":
            return self.factor(reference, other) <= self.rtol
        return np.abs(np.asarray(other, dtype=float) - np.asarray(reference, dtype=float)) \
            <= self.allowed(reference)


#: exact inputs, grids and well-conditioned outputs of solves at rtol <= 1e-12:
#: a last-bit change moves them by a few ulps (~1e-15 relative); 1e-9 leaves a
#: factor 1e6 for accumulation over thousands of events and still catches any
#: change of model, parameter or method
DEFAULT = Tolerance(1e-9, 1e-12, "well-conditioned: a few ulps per last-bit change, "
                                 "1e6 of room for accumulation")


#: a wall-clock time, or a count decided by one (repeats until a time budget)
MEASURED = Tolerance(0.0, 0.0, "wall-clock measurement: differs between any two runs; "
                               "only its shape is compared", rule="measured")


#: one ulp of 1 (a last-bit change of an O(1) number), and the unit roundoff
ULP = float(np.finfo(float).eps)
U = ULP / 2

#: an O(1) state after located events: two events, each placed to 1e-15 + 4u t
#: in time at speeds ``|f| <= 8 pi`` (the Hopf example), ~1e-13; x10
EVENT_STATE = 1e-12


#: a declared tolerance is often a formula's value (2 delta/(e ln 10), u/(2 sqrt(offset))):
#: on another machine the transcendental functions in it round differently, by up to a
#: few ulps each (and the arithmetic after them by half an ulp per operation), so the
#: numbers of two declarations are the same declaration when they agree to this many
#: ulps relative (3.6e-15): room for a formula of a few such functions, each a few ulps
#: off; any real change of a declaration (a parameter, a factor) is many orders larger
DECLARATION_ULPS = 16


def same_declaration(a, b) -> bool:
    """Whether two declared tolerances (:class:`Tolerance` or its ``asdict``, as the
    manifest stores it) are the same declaration: rule, count and reason equal, rtol,
    atol and jump equal to :data:`DECLARATION_ULPS` ulps relative."""
    a, b = (asdict(t) if isinstance(t, Tolerance) else dict(t) for t in (a, b))
    if set(a) != set(b):
        return False
    for key in a:
        x, y = a[key], b[key]
        if key in ("rtol", "atol", "jump"):
            x, y = float(x), float(y)
            if not abs(x - y) <= DECLARATION_ULPS * ULP * max(abs(x), abs(y)):
                return False
        elif x != y:
            return False
    return True


def sqrt_law(offset: float, factor: float = 1.0) -> float:
    """Spread of a quantity that varies as sqrt(distance to a tangency) at the
    smallest distance ``offset``: a last-bit change u of the distance moves it by
    u / (2 sqrt(offset)), times ``factor``."""
    return factor * U / (2.0 * np.sqrt(offset))


def annotate(ds: xr.Dataset, tolerances: dict[str, Tolerance]) -> xr.Dataset:
    """``ds`` with the tolerance of every numeric variable in its attributes
    (:data:`DEFAULT` where ``tolerances`` names none). A name that is not a
    variable of ``ds`` is an error: a renamed variable must not lose its tolerance."""
    unknown = sorted(set(tolerances) - set(ds.variables))
    if unknown:
        raise ValueError(f"tolerances declared for variables the dataset does not have: "
                         f"{', '.join(unknown)}")
    ds = ds.copy()
    for name in ds.variables:
        if ds[name].dtype.kind in "fiub":
            ds[name].attrs.update(tolerances.get(name, DEFAULT).attrs())
    return ds


def final_values(values: np.ndarray) -> np.ndarray:
    """The last finite value along the last axis (NaN where a row has none)."""
    values = np.atleast_1d(np.asarray(values, dtype=float))
    rows = values.reshape(-1, values.shape[-1]) if values.size else values.reshape(0, 1)
    out = np.full(rows.shape[0], np.nan)
    for i, row in enumerate(rows):
        finite = np.flatnonzero(np.isfinite(row))
        if finite.size:
            out[i] = row[finite[-1]]
    return out


def extents(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per row (all axes but the last) the min and max of its finite values (NaN where
    a row has none)."""
    values = np.atleast_1d(np.asarray(values, dtype=float))
    rows = values.reshape(-1, values.shape[-1])
    lo, hi = np.full(rows.shape[0], np.nan), np.full(rows.shape[0], np.nan)
    some = np.isfinite(rows).any(axis=1)
    lo[some], hi[some] = np.nanmin(rows[some], axis=1), np.nanmax(rows[some], axis=1)
    return lo, hi


def attractor_allowed(tol: "Tolerance", lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """Admissible change of each row's min and max: close-style plus jump x width."""
    width = np.abs(hi - lo)
    return np.concatenate([tol.allowed(lo), tol.allowed(hi)]) + tol.jump * np.concatenate(
        [width, width])


def spread(reference: xr.DataArray, other: xr.DataArray) -> dict:
    """How far ``other`` is from ``reference`` (full arrays), against the tolerance
    declared on ``reference``: max_abs, max_rel, changed (entries that differ at
    all), margin (smallest tolerance / difference; inf when equal; for the
    entries the tangency rule exempts, jump / difference; for the order rule,
    rtol / factor), ok, and worst: the [reference, other] values at the entry that
    sets the margin (None when nothing moved)."""
    tol = Tolerance.from_attrs(reference.attrs)
    a, b = np.asarray(reference.values, dtype=float), np.asarray(other.values, dtype=float)
    allowed = tol.allowed
    if tol.rule == "trace":
        a, b = final_values(a), final_values(b)
    if tol.rule == "attractor" and a.shape == b.shape:
        (lo_a, hi_a), (lo_b, hi_b) = extents(a), extents(b)
        limit = attractor_allowed(tol, lo_a, hi_a)
        a, b = np.concatenate([lo_a, hi_a]), np.concatenate([lo_b, hi_b])
        limit = limit[~np.isnan(a)]  # the entries compared below (NaN rows dropped)
        allowed = lambda ref: limit  # noqa: E731
    bad = {"max_abs": np.inf, "max_rel": np.inf, "changed": max(a.size, b.size),
           "margin": 0.0, "ok": False, "rule": tol.rule, "worst": None}
    if a.shape != b.shape:
        return bad
    if tol.rule == "measured":  # a timing: no two runs agree, only the shape is a result
        return {"max_abs": 0.0, "max_rel": 0.0, "changed": 0, "margin": np.inf, "ok": True,
                "rule": tol.rule, "worst": None}
    nan_a, nan_b = np.isnan(a), np.isnan(b)
    if np.any(nan_a != nan_b):
        return dict(bad, changed=int(np.count_nonzero(nan_a != nan_b)))
    a, b = a[~nan_a], b[~nan_a]
    diff = np.abs(a - b)
    if tol.rule == "order":   # tolerance / spread as factors: rtol / (max / min)
        factor = tol.factor(a, b)
        ratio = np.where(factor > 1.0, tol.rtol / factor, np.inf)
    else:
        ratio = np.where(diff > 0, allowed(a) / np.where(diff > 0, diff, 1.0), np.inf)
    ok = bool(np.all(ratio >= 1.0))
    at = int(np.argmin(ratio)) if ratio.size and np.isfinite(ratio.min()) else None
    if tol.rule == "tangency":
        # the `changed` worst entries are exempt from the close tolerance, not from `jump`
        worst = np.argsort(ratio)[:tol.changed]
        exempt = worst[ratio[worst] < 1.0]
        ok = bool(np.all(diff[exempt] <= tol.jump)) and \
            bool(np.all(np.delete(ratio, exempt) >= 1.0))
        jumps = tol.jump / diff[exempt] if tol.jump > 0 else np.zeros(exempt.size)
        keep = np.delete(np.arange(ratio.size), exempt)
        ratio = np.concatenate([ratio[keep], jumps])
        order = np.concatenate([keep, exempt])
        at = int(order[np.argmin(ratio)]) if ratio.size and np.isfinite(ratio.min()) else None
    nonzero = (diff > 0) & (a != 0)   # relative spread where the reference is not 0
    rel = diff[nonzero] / np.abs(a[nonzero])
    return {"max_abs": float(diff.max()) if diff.size else 0.0,
            "max_rel": float(rel.max()) if rel.size else 0.0,
            "changed": int(np.count_nonzero(diff)),
            "margin": float(ratio.min()) if ratio.size else np.inf, "ok": ok, "rule": tol.rule,
            "worst": None if at is None else [float(a[at]), float(b[at])]}
